"""The result of the flexible-ring fit: parameters, uncertainty, predictions, documents."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..._validate import as_frequency, check_positive
from ...exceptions import InputError
from ...frf import FRF, Channel, FRFKind
from .model import BAR, FoundationLaw, damping_columns, ring_amplitude, ring_frequency
from .observations import RingObservation

__all__ = ["RingFit"]


@dataclass(frozen=True, eq=False)
class RingFit:
    """Result of :func:`fit_ring` (all SI).

    Attributes
    ----------
    names : tuple of str
        Stiffness/mass parameters: one pressure ``EI, T0, k_r, k_t, rhoA``;
        several ``EI, b, T_c, k_r0, k_rp, k_t0, k_tp, rhoA`` (``k_r, k_t`` with
        ``foundation_law="constant"``); ``rhoA`` absent when given.
    units : tuple of str
    values, stderr : ndarray, shape (P,)
    correlation : ndarray, shape (P, P)
    covariance : ndarray, shape (P, P)
    scales : ndarray, shape (P,)
        Contribution scale of each parameter (:mod:`~tyredamp.tyremodel.ring.fit`).
    verdicts : dict of str to dict
        Per parameter: ``verdict``, ``relative_se`` (SE / verdict scale,
        :mod:`~tyredamp.tyremodel.ring.identifiability`), ``correlated_with``.
    singular_values : ndarray
        Of the column-normalised weighted Jacobian (descending); the
        collinearity index is ``1 / min``.
    damping_names, damping_units : tuple of str
        ``c_r, c_t, eta_b`` (+ ``c_d``).
    damping_values, damping_stderr : ndarray
    damping_verdicts : dict of str to dict
    radius : float
        ``R`` in m.
    attachment_mass : float
        ``m_a`` in kg.
    attachment_damping : float or None
        Known local damper ``c_d`` in N s/m (None: fitted or absent).
    mass_per_length_fixed : float or None
        ``rho A`` when given rather than fitted.
    pressures : ndarray
        Distinct test pressures in Pa.
    observations : tuple of RingObservation
    fitted_frequency_hz, fitted_amplitude, fitted_damping_ratio : ndarray
        Model values at the observations.
    chi2, dof, p_value : float, int, float or None
        Of the stiffness/mass fit (``p_value`` None without standard errors).
    scaled_covariance : bool
        Whether the covariance was scaled by ``RSS/dof``.
    weights : str
        ``"modal standard errors"`` or ``"relative (no standard errors)"``.
    skipped : tuple of str
        Modes left out and why.
    fit_time_s : float
    band_loss_frequency : float
        ``omega_ref / 2 pi`` (Hz) for the band loss factor ``eta = eta_b omega_ref``.
    foundation_law : {"linear", "constant"}
        Pressure law of ``k_r``, ``k_t`` used (several pressures).
    discrepancy_chi2 : float or None
        The larger of the whole fit's and the frequencies' reduced chi-square.
    extension : Extension or None
        The test of the inextensible ring against the extensible one
        (:mod:`~tyredamp.tyremodel.ring.extension`; None without standard errors).
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    values: NDArray[np.float64]
    stderr: NDArray[np.float64]
    correlation: NDArray[np.float64]
    covariance: NDArray[np.float64]
    scales: NDArray[np.float64]
    verdicts: dict[str, dict[str, Any]]
    singular_values: NDArray[np.float64]
    damping_names: tuple[str, ...]
    damping_units: tuple[str, ...]
    damping_values: NDArray[np.float64]
    damping_stderr: NDArray[np.float64]
    damping_verdicts: dict[str, dict[str, Any]]
    radius: float
    attachment_mass: float
    attachment_damping: float | None
    mass_per_length_fixed: float | None
    pressures: NDArray[np.float64]
    observations: tuple[RingObservation, ...]
    fitted_frequency_hz: NDArray[np.float64]
    fitted_amplitude: NDArray[np.float64]
    fitted_damping_ratio: NDArray[np.float64]
    chi2: float
    dof: int
    p_value: float | None
    scaled_covariance: bool
    weights: str
    skipped: tuple[str, ...] = ()
    fit_time_s: float = 0.0
    band_loss_frequency: float = 200.0
    foundation_law: FoundationLaw = "linear"
    discrepancy_chi2: float | None = None
    extension: Any = None

    # ------------------------------------------------------------ parameters
    def param(self, name: str) -> tuple[float, float]:
        """Value and standard error of a stiffness/mass or damping parameter."""
        if name in self.names:
            i = self.names.index(name)
            return float(self.values[i]), float(self.stderr[i])
        if name in self.damping_names:
            i = self.damping_names.index(name)
            return float(self.damping_values[i]), float(self.damping_stderr[i])
        raise InputError(f"name: expected one of {self.names + self.damping_names}, got {name!r}")

    @property
    def mass_per_length(self) -> float:
        """``rho A`` in kg/m (fitted or given)."""
        if self.mass_per_length_fixed is not None:
            return self.mass_per_length_fixed
        return self.param("rhoA")[0]

    @property
    def multi_pressure(self) -> bool:
        """True when the pressure laws were fitted (two or more pressures)."""
        return "b" in self.names

    def _linear(self, coeffs: dict[str, float]) -> tuple[float, float]:
        g = np.array([coeffs.get(n, 0.0) for n in self.names])
        return float(g @ self.values), float(math.sqrt(max(float(g @ self.covariance @ g), 0.0)))

    def _check_pressure(self, pressure: float) -> float:
        p = check_positive(pressure, "pressure", allow_zero=True)
        if not self.multi_pressure and not np.isclose(p, self.pressures[0], rtol=1e-9):
            raise InputError(
                f"pressure: a fit at one pressure ({self.pressures[0] / BAR:g} bar) gives no "
                f"pressure law; cannot evaluate at {p / BAR:g} bar"
            )
        return p

    def tension(self, pressure: float) -> tuple[float, float]:
        """``T0(p)`` (N) and its standard error."""
        p = self._check_pressure(pressure)
        if not self.multi_pressure:
            return self.param("T0")
        return self._linear({"b": p * self.radius, "T_c": 1.0})

    def radial_stiffness(self, pressure: float) -> tuple[float, float]:
        """``k_r(p)`` (N/m^2) and its standard error."""
        p = self._check_pressure(pressure)
        if "k_r" in self.names:
            return self.param("k_r")
        return self._linear({"k_r0": 1.0, "k_rp": p})

    def tangential_stiffness(self, pressure: float) -> tuple[float, float]:
        """``k_t(p)`` (N/m^2) and its standard error."""
        p = self._check_pressure(pressure)
        if "k_t" in self.names:
            return self.param("k_t")
        return self._linear({"k_t0": 1.0, "k_tp": p})

    # ------------------------------------------------------------ predictions
    def predict(
        self, pressure: float, n: ArrayLike, *, drive_phi2: ArrayLike = 0.0
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Frequencies (Hz) and damping ratios of wave numbers ``n`` at ``pressure`` (Pa).

        ``drive_phi2`` is the mass-normalised drive-point ``phi_d^2`` (1/kg) of
        each mode: 0 for the bare ring (the member with a node at the drive
        point), :meth:`drive_member_phi2` for the member with an antinode there.
        """
        p = self._check_pressure(pressure)
        nn = np.atleast_1d(np.asarray(n, dtype=float))
        if np.any(nn < 1) or np.any(nn != np.round(nn)):
            raise InputError(f"n: expected integer wave numbers >= 1, got {nn.tolist()}")
        ph = np.broadcast_to(np.asarray(drive_phi2, dtype=float), nn.shape)
        ei = self.param("EI")[0]
        ra = self.mass_per_length
        f = ring_frequency(
            nn,
            radius=self.radius,
            bending_stiffness=ei,
            tension=self.tension(p)[0],
            radial_stiffness=self.radial_stiffness(p)[0],
            tangential_stiffness=self.tangential_stiffness(p)[0],
            mass_per_length=ra,
        ) * np.sqrt(1.0 - self.attachment_mass * ph)
        zeta = self._two_zeta_omega(nn, ph, ei, ra) / (4 * np.pi * f)
        return f, zeta

    def drive_member_phi2(self, n: ArrayLike) -> NDArray[np.float64]:
        """``phi_d^2`` (1/kg) of the member with an antinode at one drive point, with ``m_a``.

        Solves ``A^2 = n^2 (1 - m_a A^2) / (pi R rho A (1 + n^2))`` (eq. (2)).
        """
        nn = np.atleast_1d(np.asarray(n, dtype=float))
        base = ring_amplitude(nn, radius=self.radius, mass_per_length=self.mass_per_length) ** 2
        return np.asarray(base / (1.0 + self.attachment_mass * base), dtype=np.float64)

    def _two_zeta_omega(
        self, n: NDArray[np.float64], phi2: NDArray[np.float64], ei: float, rho_a: float
    ) -> NDArray[np.float64]:
        """``2 zeta omega`` (1/s) of eq. (3) with the fitted (and any known) dampers."""
        cols = damping_columns(
            n, phi2, ei, rho_a, self.radius, self.attachment_mass, "c_d" in self.damping_names
        )
        known = (self.attachment_damping or 0.0) * phi2
        return np.asarray(cols @ self.damping_values + known, dtype=np.float64)

    def frf(
        self,
        pressure: float,
        frequency: ArrayLike,
        outputs: Sequence[Channel],
        inputs: Sequence[Channel],
        *,
        n_max: int = 10,
        kind: FRFKind = "receptance",
    ) -> FRF:
        """FRFs of the updated ring at the measured points (modal sum of the ring modes).

        For each drive point ``theta_k`` the responding member of every
        ``n = 1..n_max`` has its antinode there (the other member has a node
        and is not excited):
        ``H_jk = sum_n A_n^2 cos n(theta_j - theta_k) / D_n`` with
        ``D_n = omega_n^2 - omega^2 + 2 i zeta_n omega_n omega``
        with ``A_n^2`` from eq. (2) including ``m_a`` (receptance, m/N), then
        converted to ``kind``. Radial points only; every channel needs an angle.
        """
        f = as_frequency(frequency)
        for c in (*outputs, *inputs):
            if c.angle_deg is None:
                raise InputError(f"outputs/inputs: channel {c.label} has no angle_deg")
        th_o = np.deg2rad([float(c.angle_deg) for c in outputs])  # type: ignore[arg-type]
        th_i = np.deg2rad([float(c.angle_deg) for c in inputs])  # type: ignore[arg-type]
        nn = np.arange(1, int(n_max) + 1, dtype=float)
        a2 = self.drive_member_phi2(nn)
        fn, zn = self.predict(pressure, nn, drive_phi2=a2)
        wn = 2 * np.pi * fn
        w = 2 * np.pi * f
        den = wn[:, None] ** 2 - w[None, :] ** 2 + 2j * zn[:, None] * wn[:, None] * w[None, :]
        shape = np.cos(nn[None, None, :] * (th_o[:, None, None] - th_i[None, :, None]))
        h = np.einsum("jkn,n,nf->jkf", shape, a2, 1.0 / den)
        rec = FRF(
            f,
            h,
            kind="receptance",
            outputs=tuple(outputs),
            inputs=tuple(inputs),
            meta={"source": f"updated flexible ring at {pressure / BAR:g} bar"},
        )
        return rec.to(kind)

    def to_ring_parameters(self, pressure: float, membrane_stiffness: float = 2.0e9) -> Any:
        """The updated ring at ``pressure`` as :class:`tyredamp.virtual.RingTyreParameters`.

        ``T0``, ``k_r``, ``k_t`` are evaluated at ``pressure`` (the width is
        ``T0 / (p R)``, the foundation pressure slopes zero), damping as fitted
        (``c_d`` is a property of the test, not of the ring, and is dropped).
        ``membrane_stiffness`` (N) is large: the fitted model is inextensible.
        For simulating the updated ring with the finite-difference ring.
        """
        from ...virtual.parameters import RingTyreParameters

        p = self._check_pressure(pressure)
        if p <= 0:
            raise InputError("pressure: expected > 0 to express T0 as p b R")
        d = dict(zip(self.damping_names, self.damping_values, strict=True))
        return RingTyreParameters(
            radius=self.radius,
            width=self.tension(p)[0] / (p * self.radius),
            pressure=p,
            mass_per_length=self.mass_per_length,
            bending_stiffness=self.param("EI")[0],
            membrane_stiffness=membrane_stiffness,
            radial_stiffness_base=self.radial_stiffness(p)[0],
            radial_stiffness_per_pressure=0.0,
            tangential_stiffness_base=self.tangential_stiffness(p)[0],
            tangential_stiffness_per_pressure=0.0,
            radial_damping=max(float(d["c_r"]), 0.0),
            tangential_damping=max(float(d["c_t"]), 0.0),
            band_loss_factor=max(float(d["eta_b"]) * 2 * np.pi * self.band_loss_frequency, 0.0),
            band_loss_frequency=self.band_loss_frequency,
        )

    def model_discrepancy(self) -> dict[str, Any]:
        """The misfit beyond the noise: reduced chi-square and relative frequency scatter.

        ``chi2_per_dof`` (the larger of the whole fit's and the frequencies'
        own reduced chi-square; None without measurement standard errors), whether
        it makes the parameters model-limited (above
        :data:`~tyredamp.tyremodel.ring.identifiability.MODEL_LIMITED`), and
        the RMS of ``(f_model - f_measured) / f_measured``: the accuracy to
        which the ring describes the modes, whatever their noise.
        """
        from .identifiability import MODEL_LIMITED

        f = np.array([o.frequency_hz for o in self.observations], dtype=float)
        rel = (self.fitted_frequency_hz - f) / f
        c = self.discrepancy_chi2
        return {
            "chi2_per_dof": c,
            "model_limited": bool(c is not None and c > MODEL_LIMITED),
            "frequency_rms_relative": float(np.sqrt(np.mean(rel**2))) if rel.size else 0.0,
        }

    # ------------------------------------------------------------ output
    def table(self) -> list[dict[str, Any]]:
        """One row per parameter: name, unit, value, stderr, verdict, correlated_with."""
        rows = []
        for i, n in enumerate(self.names):
            v = self.verdicts[n]
            rows.append(
                {
                    "name": n,
                    "unit": self.units[i],
                    "value": float(self.values[i]),
                    "stderr": float(self.stderr[i]),
                    "model_error": _model_error(float(self.stderr[i]), v),
                    **v,
                }
            )
        for i, n in enumerate(self.damping_names):
            v = self.damping_verdicts[n]
            rows.append(
                {
                    "name": n,
                    "unit": self.damping_units[i],
                    "value": float(self.damping_values[i]),
                    "stderr": float(self.damping_stderr[i]),
                    "model_error": _model_error(float(self.damping_stderr[i]), v),
                    **v,
                }
            )
        return rows

    def format_table(self) -> str:
        """The parameter table as text."""
        lines = [f"{'parameter':>10} {'value':>12} {'+- 1 sigma':>11} {'unit':>8}  verdict"]
        for r in self.table():
            cw = (
                f" (correlated with {', '.join(r['correlated_with'])})"
                if r["correlated_with"]
                else ""
            )
            lines.append(
                f"{r['name']:>10} {r['value']:>12.5g} {r['stderr']:>11.3g} {r['unit']:>8}  "
                f"{r['verdict']}{cw}"
            )
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (parameters, per-pressure quantities, observations)."""
        per_p = []
        for p in self.pressures:
            t0, st0 = self.tension(p)
            kr, skr = self.radial_stiffness(p)
            kt, skt = self.tangential_stiffness(p)
            per_p.append(
                {
                    "pressure_pa": float(p),
                    "pressure_bar": float(p / BAR),
                    "T0": t0,
                    "T0_stderr": st0,
                    "k_r": kr,
                    "k_r_stderr": skr,
                    "k_t": kt,
                    "k_t_stderr": skt,
                }
            )
        return {
            "model": "inextensible ring on an elastic foundation (spec virtual-tyre.md)",
            "radius_m": self.radius,
            "attachment_mass_kg": self.attachment_mass,
            "attachment_damping_ns_m": self.attachment_damping,
            "mass_per_length_fixed": self.mass_per_length_fixed,
            "band_loss_frequency_hz": self.band_loss_frequency,
            "foundation_law": self.foundation_law,
            "parameters": self.table(),
            "correlation": {"names": list(self.names), "matrix": self.correlation.tolist()},
            "singular_values": self.singular_values.tolist(),
            "per_pressure": per_p,
            "chi2": self.chi2,
            "dof": self.dof,
            "p_value": self.p_value,
            "scaled_covariance": self.scaled_covariance,
            "model_discrepancy": self.model_discrepancy(),
            "extensibility": self.extension.to_dict() if self.extension is not None else None,
            "weights": self.weights,
            "observations": [
                {
                    **o.to_dict(),
                    "model_frequency_hz": float(self.fitted_frequency_hz[i]),
                    "model_amplitude": float(self.fitted_amplitude[i]),
                    "model_damping_ratio": float(self.fitted_damping_ratio[i]),
                }
                for i, o in enumerate(self.observations)
            ],
            "skipped": list(self.skipped),
            "fit_time_s": self.fit_time_s,
        }


def _model_error(stderr: float, verdict: dict[str, Any]) -> float:
    """The model-error term in the parameter's unit (0 when none).

    The root sum of squares of the misfit bound ``se sqrt(dof)``
    (:func:`~tyredamp.tyremodel.ring.identifiability.admit_model_error`) and
    the extensible ring's term ``sqrt(q^2 + var q)``
    (:mod:`~tyredamp.tyremodel.ring.extension`).
    """
    rel, bound = float(verdict.get("relative_se", 0.0)), verdict.get("model_error_bound", 0.0)
    misfit = stderr * float(bound) / rel if rel > 0 and bound else 0.0
    return math.hypot(misfit, float(verdict.get("extension_error", 0.0)))
