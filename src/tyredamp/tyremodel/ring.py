"""Flexible-ring model updating: ring parameters from identified modes at one or more pressures.

Model
-----
The inextensible inflated ring on an elastic foundation (spec
``virtual-tyre.md``; Kung, Soedel & Yang 1986; Pacejka, *Tire and Vehicle
Dynamics*, ch. 9; Gong 1993) has, for wave number ``n >= 1``,

``omega_n^2 = [EI n^2 (n^2-1)^2/R^4 + T0 n^2 (n^2-1)/R^2 + k_r n^2 + k_t]
/ [rho A (1 + n^2)]``                                                    (1)

(the same formula as :func:`tyredamp.tyre.analytic_ring_frequencies`), and
its mass-normalised radial shape ``A cos n(theta - theta_0)`` has

``A^2 = n^2 / (pi R rho A (1 + n^2))``                                     (2)

(modal mass ``pi R rho A A^2 (1 + n^2)/n^2`` of ``w = A cos n theta``,
``v = -(A/n) sin n theta``). Frequencies alone fix only the ratios of the
stiffnesses to ``rho A``; the mass-normalised shape amplitudes of the
identified modes (drive-point scaling) fix ``rho A`` through (2). A known
point mass ``m_a`` at the drive point(s) (transducer and drive-rod tip) is
taken into account exactly in the Rayleigh sense with the measured
drive-point value ``phi_d`` of each mass-normalised shape: the ring's share
of the modal mass is ``1 - m_a phi_d^2``, so (1) and (2) are multiplied by
it. Across pressures the tension follows the inflation pressure and the
foundation may stiffen with it:

``T0(p) = p R b + T_c``, ``k_r(p) = k_r0 + k_rp p``, ``k_t(p) = k_t0 + k_tp p``

(``b`` the effective belt width, ``T_c`` a pressure-independent part;
``foundation_law="constant"`` drops ``k_rp``, ``k_tp``). At one pressure the
parameters are ``EI, T0, k_r, k_t, rho A``.

Damping: modal viscous damping of the ring with radial and tangential
foundation dampers ``c_r``, ``c_t`` (N s/m^2), a band loss on the bending
stiffness only (``eta_b K_bend``, ``eta_b = eta / omega_ref`` in s) and a
local radial damper ``c_d`` (N s/m) at the drive point(s), as in the virtual
tyre (:class:`tyredamp.tyre.RingTyreParameters`):

``2 zeta_n omega_n = [c_r n^2 + c_t + eta_b EI n^2 (n^2-1)^2/R^4] (1 - m_a phi_d^2)
/ [rho A (1 + n^2)] + c_d phi_d^2``                                      (3)

Fit
---
Stiffness and mass parameters: weighted least squares
(:func:`scipy.optimize.least_squares`) of the residuals
``(f_model - f)/sigma_f`` and ``(A_model - A)/sigma_A`` with the modal
standard errors (``ModalModel.std``) as ``sigma``; without them, relative
weights (``sigma = f``, ``sigma = A``) and the covariance scaled by the
residual variance. The parameters are scaled by their "contribution scale"
(``T_c`` by the mean tension, ``k_rp`` by ``k_r(p_mean)/p_mean`` ...), so the
scaled Jacobian compares like with like. Damping: weighted linear least
squares of (3) with ``sigma = 2 omega sigma_zeta``, given the fitted ``EI``
and ``rho A``.

Uncertainty and identifiability: ``cov = (J^T J)^-1`` of the weighted
residuals (scaled by the reduced chi-square ``RSS/dof`` when it is
significantly above 1, p < 0.01, i.e. when the model error dominates the
measurement error, or when there were no standard errors); correlations
from ``cov``. Verdict per parameter from its standard error relative to its
value, floored at 1 % of its contribution scale (``T_c`` against the
tension itself; ``<= 0.1`` identified, ``<= 0.5`` poorly identified, else
not identifiable from these modes) and from the scaled Jacobian's
singular values (collinearity index of Brun et al. 2001 above 100: the
parameters of that near-null direction are confounded whatever the noise,
e.g. ``c_r`` and ``c_d`` when only the driven member of each pair is
measured, whose ``phi_d^2 = A^2`` follows ``n^2/(1+n^2)`` like the ``c_r``
term), with
the parameters it is correlated with (``|rho| > 0.95``). For example ``k_t``
enters (1) with weight 1 against ``n^2`` for ``k_r``: radial modes alone
determine it poorly, and its pressure slope usually not at all.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.stats import chi2

from .._validate import as_frequency, check_positive
from ..exceptions import ConvergenceError, InputError, PhysicsError
from ..frf import FRF, Channel, FRFKind
from ..modal.model import ModalModel
from .wavenumber import WaveNumberAnalysis, wave_number_analysis

__all__ = [
    "RingFit",
    "RingObservation",
    "fit_ring",
    "ring_amplitude",
    "ring_frequency",
    "ring_observations",
]

FoundationLaw = Literal["linear", "constant"]
#: Relative standard error (against the contribution scale) up to which a parameter is identified.
IDENTIFIED = 0.1
#: ... up to which it is poorly identified; above it, not identifiable from these modes.
POORLY = 0.5
#: Correlation above which two parameters are reported as correlated.
CORRELATED = 0.95
#: Collinearity index (Brun et al. 2001) above which a parameter combination is confounded: a
#: change of the combination is seen 100 times weaker than a change of one parameter, so with
#: model and data agreeing to about 1 % (modal damping, shape amplitudes, model error) it is
#: undetermined. Brun et al. call 10-15 critical for percent-level environmental data; modal
#: frequencies are more precise, and the standard-error verdict covers the noise itself.
COLLINEARITY = 100.0
_BAR = 1e5


def ring_frequency(
    n: ArrayLike,
    *,
    radius: float,
    bending_stiffness: ArrayLike,
    tension: ArrayLike,
    radial_stiffness: ArrayLike,
    tangential_stiffness: ArrayLike,
    mass_per_length: ArrayLike,
) -> NDArray[np.float64]:
    """Natural frequency (Hz) of wave number ``n`` of the inextensible ring, eq. (1).

    Parameters
    ----------
    n : array_like of int
        Wave numbers >= 0 (``n = 0``: rigid rotation ``k_t / rho A``).
    radius : float
        Belt radius ``R`` in m.
    bending_stiffness, tension, radial_stiffness, tangential_stiffness, mass_per_length :
        ``EI`` (N m^2), ``T0`` (N), ``k_r``, ``k_t`` (N/m^2), ``rho A`` (kg/m);
        broadcast against ``n``.

    Returns
    -------
    ndarray
        Frequencies in Hz (0 where the bracket is negative: a buckled ring).
    """
    nn = np.asarray(n, dtype=float)
    n2 = nn**2
    r = float(radius)
    num = (
        np.asarray(bending_stiffness) * n2 * (n2 - 1) ** 2 / r**4
        + np.asarray(tension) * n2 * (n2 - 1) / r**2
        + np.asarray(radial_stiffness) * n2
        + np.asarray(tangential_stiffness)
    )
    w2 = num / (np.asarray(mass_per_length) * (1 + n2))
    return np.asarray(np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi), dtype=np.float64)


def ring_amplitude(
    n: ArrayLike, *, radius: float, mass_per_length: ArrayLike
) -> NDArray[np.float64]:
    """Radial amplitude ``A`` (1/sqrt(kg)) of the mass-normalised ring mode ``n >= 1``, eq. (2)."""
    nn = np.asarray(n, dtype=float)
    if np.any(nn < 1):
        raise InputError("n: the radial amplitude of eq. (2) needs n >= 1")
    return np.asarray(
        np.sqrt(nn**2 / (np.pi * radius * np.asarray(mass_per_length) * (1 + nn**2))),
        dtype=np.float64,
    )


# --------------------------------------------------------------------------- observations
@dataclass(frozen=True)
class RingObservation:
    """One identified mode as the ring fit uses it.

    Attributes
    ----------
    pressure : float
        Inflation pressure in Pa.
    n : int
        Wave number (from :func:`~tyredamp.tyremodel.wave_number_analysis`).
    member : str
        ``"cos"``, ``"sin"`` or ``"single"``.
    frequency_hz, frequency_std : float, float or None
        Natural frequency and its standard error (Hz).
    damping_ratio, damping_std : float, float or None
    amplitude, amplitude_std : float, float or None
        Mass-normalised radial amplitude ``A`` (1/sqrt(kg)) and standard error.
    use_amplitude : bool
        False where the amplitude is not the ring amplitude (the Nyquist wave
        number, whose sampled amplitude depends on the orientation).
    drive_phi2 : float
        ``sum over drive points of |phi_d|^2`` (1/kg) of the mass-normalised shape.
    mode_index : int
        Index in its :class:`ModalModel`.
    """

    pressure: float
    n: int
    member: str
    frequency_hz: float
    frequency_std: float | None
    damping_ratio: float
    damping_std: float | None
    amplitude: float
    amplitude_std: float | None
    use_amplitude: bool
    drive_phi2: float
    mode_index: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (pressure also in bar)."""
        return {
            "pressure_pa": self.pressure,
            "pressure_bar": self.pressure / _BAR,
            "n": self.n,
            "member": self.member,
            "frequency_hz": self.frequency_hz,
            "frequency_std": self.frequency_std,
            "damping_ratio": self.damping_ratio,
            "damping_std": self.damping_std,
            "amplitude": self.amplitude,
            "amplitude_std": self.amplitude_std,
            "use_amplitude": self.use_amplitude,
            "drive_phi2": self.drive_phi2,
            "mode_index": self.mode_index,
        }


def ring_observations(
    model: ModalModel,
    pressure: float,
    *,
    analysis: WaveNumberAnalysis | None = None,
    angles_deg: ArrayLike | None = None,
) -> tuple[list[RingObservation], list[str]]:
    """The modes of ``model`` that the flexural ring model describes, with their labels.

    Modes flagged as aliased or not a single harmonic and ``n = 0`` modes
    (the ring's rotation has no radial motion; a radial ``n = 0`` mode is
    the extensional breathing mode, outside the inextensible model) are left
    out, each with a reason.

    Parameters
    ----------
    model : ModalModel
        Identified modes (radial outputs with angles, drive-point scaling).
    pressure : float
        Inflation pressure of the test in Pa (>= 0).
    analysis : WaveNumberAnalysis, optional
        Precomputed labels (default :func:`wave_number_analysis`).
    angles_deg : array_like, optional
        Output angles when the channels carry none.

    Returns
    -------
    observations : list of RingObservation
    skipped : list of str
        One sentence per mode left out.
    """
    p = check_positive(pressure, "pressure", allow_zero=True)
    wa = analysis if analysis is not None else wave_number_analysis(model, angles_deg=angles_deg)
    if len(wa.modes) != model.n_modes:
        raise InputError("analysis: expected the wave-number analysis of this model")
    sf = model.std.get("frequency_hz")
    sz = model.std.get("damping_ratio")
    omega = model.poles.imag
    phi_d2 = np.sum(np.abs(model.psi_in) ** 2, axis=0) * 2.0 * omega
    nyq = wa.n_resolved + 1
    obs: list[RingObservation] = []
    skipped: list[str] = []
    for m in wa.modes:
        where = f"{p / _BAR:g} bar, mode {m.index + 1} ({m.frequency_hz:.2f} Hz)"
        if m.aliased:
            skipped.append(f"{where}: flagged as spatially aliased")
            continue
        if not m.single_harmonic:
            skipped.append(f"{where}: shape is not a single harmonic ({m.fraction:.2f})")
            continue
        if m.n == 0:
            skipped.append(f"{where}: n = 0 is outside the inextensible flexural ring model")
            continue
        k = m.index
        obs.append(
            RingObservation(
                pressure=p,
                n=m.n,
                member=m.member,
                frequency_hz=m.frequency_hz,
                frequency_std=None if sf is None else float(sf[k]),
                damping_ratio=m.damping_ratio,
                damping_std=None if sz is None else float(sz[k]),
                amplitude=m.amplitude,
                amplitude_std=m.amplitude_std,
                use_amplitude=m.n < nyq,
                drive_phi2=float(phi_d2[k]),
                mode_index=k,
            )
        )
    return obs, skipped


# --------------------------------------------------------------------------------- result
def _verdict(rel: float) -> str:
    if not math.isfinite(rel) or rel > POORLY:
        return "not identifiable from these modes"
    if rel > IDENTIFIED:
        return "poorly identified"
    return "identified"


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
        Contribution scale of each parameter (module docstring).
    verdicts : dict of str to dict
        Per parameter: ``verdict``, ``relative_se`` (SE / verdict scale, module docstring),
        ``correlated_with``.
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
                f"pressure: a fit at one pressure ({self.pressures[0] / _BAR:g} bar) gives no "
                f"pressure law; cannot evaluate at {p / _BAR:g} bar"
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
        cols = _damping_columns(
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
            meta={"source": f"updated flexible ring at {pressure / _BAR:g} bar"},
        )
        return rec.to(kind)

    def to_ring_parameters(self, pressure: float, membrane_stiffness: float = 2.0e9) -> Any:
        """The updated ring at ``pressure`` as :class:`tyredamp.tyre.RingTyreParameters`.

        ``T0``, ``k_r``, ``k_t`` are evaluated at ``pressure`` (the width is
        ``T0 / (p R)``, the foundation pressure slopes zero), damping as fitted
        (``c_d`` is a property of the test, not of the ring, and is dropped).
        ``membrane_stiffness`` (N) is large: the fitted model is inextensible.
        For simulating the updated ring with the finite-difference ring.
        """
        from ..virtual.parameters import RingTyreParameters

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
                    "pressure_bar": float(p / _BAR),
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


# ------------------------------------------------------------------------------------ fit
def _damping_columns(
    n: NDArray[np.float64],
    phi2: NDArray[np.float64],
    ei: float,
    rho_a: float,
    radius: float,
    m_a: float,
    with_cd: bool,
) -> NDArray[np.float64]:
    """Design matrix of eq. (3) for ``2 zeta omega`` in ``c_r, c_t, eta_b (, c_d)``."""
    n2 = n**2
    fac = (1.0 - m_a * phi2) / (rho_a * (1 + n2))
    cols = [n2 * fac, fac, ei * n2 * (n2 - 1) ** 2 / radius**4 * fac]
    if with_cd:
        cols.append(phi2)
    return np.column_stack(cols)


class _Layout:
    """Parameter layout and the model of eqs. (1)-(2) for one fit."""

    def __init__(self, pressures: NDArray[np.float64], law: FoundationLaw, fit_mass: bool):
        self.multi = np.unique(pressures).size >= 2
        if self.multi:
            names = ["EI", "b", "T_c"]
            units = ["N m^2", "m", "N"]
            if law == "linear":
                names += ["k_r0", "k_rp", "k_t0", "k_tp"]
                units += ["N/m^2", "1", "N/m^2", "1"]
            else:
                names += ["k_r", "k_t"]
                units += ["N/m^2", "N/m^2"]
        else:
            names = ["EI", "T0", "k_r", "k_t"]
            units = ["N m^2", "N", "N/m^2", "N/m^2"]
        if fit_mass:
            names.append("rhoA")
            units.append("kg/m")
        self.names = tuple(names)
        self.units = tuple(units)

    def unpack(self, theta: NDArray[np.float64], p: NDArray[np.float64], r: float) -> Any:
        d = dict(zip(self.names, theta, strict=True))
        t0 = d["b"] * p * r + d["T_c"] if self.multi else np.full(p.shape, d["T0"])
        kr = d["k_r0"] + d["k_rp"] * p if "k_r0" in d else np.full(p.shape, d["k_r"])
        kt = d["k_t0"] + d["k_tp"] * p if "k_t0" in d else np.full(p.shape, d["k_t"])
        return d["EI"], t0, kr, kt, d.get("rhoA")


def fit_ring(
    data: Sequence[tuple[float, ModalModel]] | Sequence[RingObservation],
    *,
    radius: float,
    attachment_mass: float = 0.0,
    mass_per_length: float | None = None,
    foundation_law: FoundationLaw = "linear",
    drive_point_damper: bool = True,
    attachment_damping: float | None = None,
    band_loss_frequency: float = 200.0,
) -> RingFit:
    """Update the flexible ring to identified modes at one or several pressures.

    Parameters
    ----------
    data : sequence of (pressure, ModalModel) or of RingObservation
        Identified modes with the test pressure in Pa (labelled with
        :func:`ring_observations`), or ready observations.
    radius : float
        Belt radius ``R`` in m (geometry, not fitted).
    attachment_mass : float
        Known point mass at each drive point in kg (default 0).
    mass_per_length : float, optional
        Known ``rho A`` in kg/m; default: fitted from the mass-normalised
        shape amplitudes, eq. (2).
    foundation_law : {"linear", "constant"}
        Pressure dependence of ``k_r`` and ``k_t`` across pressures.
    drive_point_damper : bool
        Fit the local damper ``c_d`` at the drive point(s) (eq. (3)) when
        ``attachment_damping`` is not given.
    attachment_damping : float, optional
        Known local radial damper at each drive point in N s/m; then ``c_d``
        is fixed to it instead of fitted.
    band_loss_frequency : float
        ``omega_ref / 2 pi`` in Hz for the reported band loss factor.

    Returns
    -------
    RingFit

    Raises
    ------
    InputError
        Too few usable modes for the parameters, bad options.
    ConvergenceError
        The least-squares fit did not converge.
    """
    t_start = time.perf_counter()
    r = check_positive(radius, "radius")
    m_a = check_positive(attachment_mass, "attachment_mass", allow_zero=True)
    if foundation_law not in ("linear", "constant"):
        raise InputError(f"foundation_law: expected 'linear' or 'constant', got {foundation_law!r}")
    check_positive(band_loss_frequency, "band_loss_frequency")
    items: list[Any] = list(data)
    if not items:
        raise InputError("data: expected at least one (pressure, ModalModel)")
    obs: list[RingObservation] = []
    skipped: list[str] = []
    for i, it in enumerate(items):
        if isinstance(it, RingObservation):
            obs.append(it)
            continue
        try:
            pr, mdl = it
        except (TypeError, ValueError):
            raise InputError(
                f"data[{i}]: expected (pressure, ModalModel) or RingObservation"
            ) from None
        if not isinstance(mdl, ModalModel):
            raise InputError(f"data[{i}]: expected a ModalModel, got {type(mdl).__name__}")
        o, s = ring_observations(mdl, float(pr))
        obs += o
        skipped += s
    if not obs:
        raise InputError("data: no mode usable by the ring model (see the wave-number analysis)")
    for i, ob in enumerate(obs):
        vals = (ob.pressure, ob.frequency_hz, ob.amplitude, ob.damping_ratio, ob.drive_phi2)
        if not all(math.isfinite(v) for v in vals):
            raise InputError(f"observations[{i}]: expected finite values, got {ob}")
        if ob.frequency_hz <= 0 or ob.n < 1 or ob.pressure < 0 or ob.drive_phi2 < 0:
            raise InputError(
                f"observations[{i}]: expected n >= 1, frequency > 0, pressure >= 0 and "
                f"drive_phi2 >= 0, got n = {ob.n}, f = {ob.frequency_hz}, p = {ob.pressure}"
            )
    n = np.array([o.n for o in obs], dtype=float)
    p = np.array([o.pressure for o in obs])
    f = np.array([o.frequency_hz for o in obs])
    phi2 = np.array([o.drive_phi2 for o in obs])
    amp = np.array([o.amplitude for o in obs])
    use_a = np.array([o.use_amplitude for o in obs])
    if np.any(m_a * phi2 >= 1):
        raise PhysicsError(
            "attachment_mass: m_a phi_d^2 >= 1 for some mode; the attachment mass exceeds the "
            "modal mass (check the mass and the shape scaling)"
        )
    fit_mass = mass_per_length is None
    if not fit_mass:
        rho_fixed = check_positive(mass_per_length, "mass_per_length")  # type: ignore[arg-type]
    lay = _Layout(p, foundation_law, fit_mass)
    if fit_mass and not np.any(use_a):
        raise InputError("data: no mode amplitude to fix rho A; give mass_per_length")
    sf_list = [o.frequency_std for o in obs]
    sa_list = [o.amplitude_std for o in obs]
    have_std = all(s is not None and s > 0 for s in sf_list) and (
        not fit_mass
        or all(s is not None and s > 0 for s, u in zip(sa_list, use_a, strict=True) if u)
    )
    sig_f = np.array(sf_list, dtype=float) if have_std else f.copy()
    sig_a = (
        np.array([s if s is not None else np.nan for s in sa_list], dtype=float)
        if have_std
        else amp.copy()
    )
    n_res = n.size + (int(use_a.sum()) if fit_mass else 0)
    if n_res <= len(lay.names):
        raise InputError(
            f"data: {n_res} usable values (frequencies and amplitudes) for {len(lay.names)} "
            f"parameters {list(lay.names)}; identify more modes or fix parameters"
        )
    share = 1.0 - m_a * phi2
    # ---- starting values: rho A from eq. (2), then linear least squares of eq. (1)
    if fit_mass:
        rho_i = n[use_a] ** 2 * share[use_a] / (np.pi * r * (1 + n[use_a] ** 2) * amp[use_a] ** 2)
        rho0 = float(np.median(rho_i))
    else:
        rho0 = rho_fixed
    y = rho0 * (1 + n**2) * (2 * np.pi * f) ** 2 / share
    n2 = n**2
    g_ei = n2 * (n2 - 1) ** 2 / r**4
    g_t = n2 * (n2 - 1) / r**2
    cols: dict[str, NDArray[np.float64]] = {"EI": g_ei}
    if lay.multi:
        cols["b"] = g_t * p * r
        cols["T_c"] = g_t
    else:
        cols["T0"] = g_t
    if "k_r0" in lay.names:
        cols.update({"k_r0": n2, "k_rp": n2 * p, "k_t0": np.ones_like(n), "k_tp": p})
    else:
        cols.update({"k_r": n2, "k_t": np.ones_like(n)})
    lin_names = [nm for nm in lay.names if nm != "rhoA"]
    x_design = np.column_stack([cols[nm] for nm in lin_names])
    wrow = 1.0 / y
    sol, *_ = np.linalg.lstsq(x_design * wrow[:, None], y * wrow, rcond=None)
    theta0 = np.concatenate([sol, [rho0]]) if fit_mass else sol.copy()
    # contribution scales
    p_mean = float(np.mean(np.unique(p)))
    d0 = dict(zip(lay.names, theta0, strict=True))
    t_mean = abs(d0["b"] * p_mean * r + d0["T_c"]) if lay.multi else abs(d0["T0"])
    kr_mean = abs(d0["k_r0"] + d0["k_rp"] * p_mean) if "k_r0" in d0 else abs(d0["k_r"])
    kt_mean = abs(d0["k_t0"] + d0["k_tp"] * p_mean) if "k_t0" in d0 else abs(d0["k_t"])
    kt_mean = max(kt_mean, 1e-3 * kr_mean)
    sc = {
        "EI": abs(d0["EI"]),
        "T0": t_mean,
        "b": t_mean / (p_mean * r) if p_mean > 0 else 1.0,
        "T_c": t_mean,
        "k_r": kr_mean,
        "k_r0": kr_mean,
        "k_rp": kr_mean / p_mean if p_mean > 0 else 1.0,
        "k_t": kt_mean,
        "k_t0": kt_mean,
        "k_tp": kt_mean / p_mean if p_mean > 0 else 1.0,
        "rhoA": rho0,
    }
    scales = np.array([sc[nm] if sc[nm] > 0 else 1.0 for nm in lay.names])

    def model(theta: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        ei, t0, kr, kt, rho = lay.unpack(theta, p, r)
        rho = rho if rho is not None else rho_fixed
        fm = ring_frequency(
            n,
            radius=r,
            bending_stiffness=ei,
            tension=t0,
            radial_stiffness=kr,
            tangential_stiffness=kt,
            mass_per_length=rho,
        ) * np.sqrt(share)
        am = np.sqrt(n2 * share / (np.pi * r * rho * (1 + n2)))
        return fm, am

    def residual(u: NDArray[np.float64]) -> NDArray[np.float64]:
        fm, am = model(u * scales)
        parts = [(fm - f) / sig_f]
        if fit_mass:
            parts.append(((am - amp) / sig_a)[use_a])
        return np.concatenate(parts)

    u0 = theta0 / scales
    res = least_squares(residual, u0, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    if res.status <= 0 or not np.all(np.isfinite(res.x)):
        raise ConvergenceError(f"fit_ring: the least-squares fit did not converge ({res.message})")
    u = np.asarray(res.x, dtype=float)
    rvec = residual(u)
    rss = float(rvec @ rvec)
    jac = _central_jacobian(residual, u)
    dof = n_res - u.size
    sv, _ = _collinearity(jac)
    cov_u = np.linalg.pinv(jac.T @ jac, rcond=1e-12)
    pval: float | None = None
    scaled = False
    if have_std:
        pval = float(chi2.sf(rss, dof))
        if pval < 0.01:
            scaled = True
    else:
        scaled = True
    if scaled:
        cov_u = cov_u * (rss / dof)
    theta = u * scales
    cov = np.asarray(cov_u * np.outer(scales, scales), dtype=np.float64)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    corr = _correlation(cov)
    # verdict scale: the parameter itself, floored at 1 % of its contribution scale (a term
    # that is zero to within 1 % of what it modifies is determined); the tension offset T_c
    # is judged against the tension itself
    vscale = np.maximum(np.abs(theta), 0.01 * scales)
    if "T_c" in lay.names:
        vscale[lay.names.index("T_c")] = scales[lay.names.index("T_c")]
    verdicts = _verdicts(lay.names, se / vscale, corr, jac)
    fm, am = model(theta)
    # ---- damping, eq. (3), given EI and rho A
    ei_hat = float(theta[lay.names.index("EI")])
    rho_hat = float(theta[lay.names.index("rhoA")]) if fit_mass else rho_fixed
    zeta = np.array([o.damping_ratio for o in obs])
    omega = 2 * np.pi * f
    yd = 2 * zeta * omega
    sz_list = [o.damping_std for o in obs]
    have_zstd = all(s is not None and s > 0 for s in sz_list)
    sig_d = 2 * omega * np.array(sz_list, dtype=float) if have_zstd else yd.copy()
    c_known = None
    if attachment_damping is not None:
        c_known = check_positive(attachment_damping, "attachment_damping", allow_zero=True)
        yd = yd - c_known * phi2
    with_cd = c_known is None and bool(drive_point_damper) and np.ptp(phi2) > 0
    dmat = _damping_columns(n, phi2, ei_hat, rho_hat, r, m_a, with_cd)
    d_names = ("c_r", "c_t", "eta_b", "c_d")[: dmat.shape[1]]
    d_units = ("N s/m^2", "N s/m^2", "s", "N s/m")[: dmat.shape[1]]
    dw = dmat / sig_d[:, None]
    # columns differ by ~1e9 in scale (eta_b against c_r): solve and invert normalised
    cn = np.linalg.norm(dw, axis=0)
    cn = np.where(cn > 0, cn, 1.0)
    dsol_n, *_ = np.linalg.lstsq(dw / cn, yd / sig_d, rcond=None)
    dsol = dsol_n / cn
    dres = yd / sig_d - dw @ dsol
    drss = float(dres @ dres)
    ddof = max(n.size - dsol.size, 1)
    dwn = dw / cn
    dcov = np.asarray(np.linalg.pinv(dwn.T @ dwn, rcond=1e-12) / np.outer(cn, cn), dtype=float)
    if not have_zstd or chi2.sf(drss, ddof) < 0.01:
        dcov = dcov * (drss / ddof)
    dse = np.sqrt(np.clip(np.diag(dcov), 0.0, None))
    # verdict scale of each damping term: its value, floored at 1 % of the value that alone
    # would carry the mean measured 2 zeta omega
    colmean = np.mean(np.abs(dmat), axis=0)
    dscale = float(np.mean(np.abs(yd))) / np.where(colmean > 0, colmean, 1.0)
    dscale = np.maximum(np.abs(dsol), 0.01 * dscale)
    dverd = _verdicts(d_names, dse / dscale, _correlation(dcov), dw)
    zeta_model = (dmat @ dsol + (c_known or 0.0) * phi2) / (2 * omega)
    return RingFit(
        names=lay.names,
        units=lay.units,
        values=theta,
        stderr=se,
        correlation=corr,
        covariance=cov,
        scales=scales,
        verdicts=verdicts,
        singular_values=sv,
        damping_names=d_names,
        damping_units=d_units,
        damping_values=np.asarray(dsol, dtype=float),
        damping_stderr=dse,
        damping_verdicts=dverd,
        radius=r,
        attachment_mass=m_a,
        attachment_damping=c_known,
        mass_per_length_fixed=None if fit_mass else rho_fixed,
        pressures=np.unique(p),
        observations=tuple(obs),
        fitted_frequency_hz=fm,
        fitted_amplitude=am,
        fitted_damping_ratio=zeta_model,
        chi2=rss,
        dof=int(dof),
        p_value=pval,
        scaled_covariance=scaled,
        weights="modal standard errors" if have_std else "relative (no standard errors)",
        skipped=tuple(skipped),
        fit_time_s=time.perf_counter() - t_start,
        band_loss_frequency=float(band_loss_frequency),
        foundation_law=foundation_law,
    )


def _central_jacobian(fun: Any, x: NDArray[np.float64]) -> NDArray[np.float64]:
    f0 = fun(x)
    jac = np.empty((f0.size, x.size))
    for k in range(x.size):
        h = 1e-6 * max(1.0, abs(float(x[k])))
        xp = x.copy()
        xm = x.copy()
        xp[k] += h
        xm[k] -= h
        jac[:, k] = (fun(xp) - fun(xm)) / (2 * h)
    return jac


def _correlation(cov: NDArray[np.float64]) -> NDArray[np.float64]:
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    d = np.where(sd > 0, sd, 1.0)
    return np.asarray(np.clip(cov / np.outer(d, d), -1.0, 1.0), dtype=np.float64)


def _collinearity(jac: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Singular values and right vectors of the column-normalised Jacobian (Brun et al. 2001)."""
    norms = np.linalg.norm(jac, axis=0)
    s_tilde = jac / np.where(norms > 0, norms, 1.0)
    _, sv, vt = np.linalg.svd(s_tilde, full_matrices=False)
    return np.asarray(sv, dtype=np.float64), np.asarray(vt, dtype=np.float64)


def _verdicts(
    names: Sequence[str],
    rel_se: NDArray[np.float64],
    corr: NDArray[np.float64],
    jac: NDArray[np.float64],
) -> dict[str, dict[str, Any]]:
    """Per-parameter verdicts (module docstring).

    Besides the relative standard error, the collinearity index of Brun,
    Reichert & Kuensch (Water Resour. Res. 37(4), 2001) is used: with the
    column-normalised Jacobian ``S~`` (each parameter's sensitivity scaled to
    unit length), a singular value ``s_k < 1/COLLINEARITY`` means that a
    combination of parameters can change by a factor ``COLLINEARITY`` more
    than the data resolve; the parameters carrying that combination (its
    singular vector's entries above 0.3 of the largest) are not separately
    identifiable, whatever the noise level.
    """
    out: dict[str, dict[str, Any]] = {}
    confounded: dict[int, set[int]] = {}
    sv, vt = _collinearity(jac)
    for k in np.flatnonzero(sv < 1.0 / COLLINEARITY):
        v = np.abs(vt[k])
        members = {int(j) for j in np.flatnonzero(v > 0.3 * v.max())}
        for j in members:
            confounded.setdefault(j, set()).update(members - {j})
    for i, nm in enumerate(names):
        rel = float(rel_se[i])
        partners = [
            names[j] for j in range(len(names)) if j != i and abs(float(corr[i, j])) > CORRELATED
        ]
        verdict = _verdict(rel)
        if i in confounded:
            others = ", ".join(names[j] for j in sorted(confounded[i])) or "itself"
            verdict = f"not separately identifiable (confounded with {others})"
        out[nm] = {"verdict": verdict, "relative_se": rel, "correlated_with": partners}
    return out
