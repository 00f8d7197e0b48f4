"""The belt's wind-up (``FREQ_WINDUP``, ``DAMP_WINDUP``, ``BELT_IYY``) from a tangential test.

The rigid-ring model (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed. 2012,
sec. 9.2, the rotational belt-rim spring and damper; Zegelaar, PhD thesis
TU Delft 1998, ch. 4; MF-Swift) gives the belt a rotation ``theta`` about
the axle with inertia ``I_by`` (``BELT_IYY``) on a rotational spring
``k_theta`` and damper ``c_theta`` to the rim. With the rim held, its free
motion is the ring's ``n = 0`` rotation mode, whose frequency and damping
ratio are ``FREQ_WINDUP`` and ``DAMP_WINDUP``:

``k_theta = I_by omega_0^2``,  ``c_theta = 2 zeta_0 I_by omega_0``.

Detection
---------
The mode is found from its shape, not its frequency: the circumferential
harmonic content of every identified shape at the measured angles
(:func:`~tyredamp.tyremodel.wave_number_analysis`); a rotation moves every
point of the tread by the same tangential amount, a single harmonic
``n = 0``. Among the modes labelled ``n = 0`` whose single-harmonic energy
fraction reaches ``min_fraction``, the one with the largest mass-normalised
amplitude (the smallest modal inertia: the belt's rotation, which the
drive moves most) is used; with the rim held a tyre has one such mode in the
band of a modal test, so a second one (a fit that split the resonance into
two poles) is combined with it: the poles within three half-power
bandwidths of it have their residues summed (notes say so).

``BELT_IYY`` from the mass-normalised shape
-------------------------------------------
Let the mass-normalised mode (``phi^T M phi = 1``, ``phi^T K phi =
omega^2``, ``phi^T C phi = 2 zeta omega``) have the uniform tangential
amplitude ``A_t`` (1/sqrt(kg)) at the measured points, on radius ``R``. A
rigid rotation moves those points by ``v = R theta``, so the mode is the
rotation ``theta = A_t / R`` of the belt plus the motion ``phi_d`` of a
known point mass ``m_a`` at the drive point (the shaker's drive-rod tip).
The modal mass is then

``1 = I_by (A_t / R)^2 + m_a phi_d^2``  =>  ``I_by = (1 - m_a phi_d^2) R^2 / A_t^2``

(with ``m_a = 0``: ``I_by = R^2 / A_t^2``, the rotational analogue of
``BELT_MASS = 1 / A^2`` from the ``n = 1`` radial amplitude,
:mod:`~tyredamp.tyremodel.rigid`). The stiffness ``omega^2 = k_theta (A_t /
R)^2`` gives the bare-belt frequency ``omega_0 = omega / sqrt(1 - m_a
phi_d^2)``, and the damping ``2 zeta omega = c_theta (A_t / R)^2 + c_a
phi_d^2`` (``c_a`` a known tangential damper at the drive point) gives
``zeta_0 = (2 zeta omega - c_a phi_d^2) / (2 omega sqrt(1 - m_a phi_d^2))``.
``phi_d^2`` is the drive-point residue ``2 Omega |psi_d|^2`` of the
identified mode. ``R`` is the radius of the tangential accelerometers (the
belt radius when they sit on the belt's centre line).

Standard errors propagate the modal ones (frequency, damping ratio, shape
amplitude) to first order, taken as independent; :func:`windup_budget`
adds calibration, attachment and model terms
(:mod:`~tyredamp.tyremodel.budget`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validate import check_positive
from ..exceptions import InputError, PhysicsError
from ..modal.model import ModalModel
from ..virtual.tangential import TANGENTIAL_DIRECTION
from .budget import Assumptions, UncertaintyBudget
from .wavenumber import ModeWaveNumber, WaveNumberAnalysis, wave_number_analysis

__all__ = [
    "WINDUP_KEYS",
    "WindupParameters",
    "check_tangential",
    "windup_budget",
    "windup_from_modes",
]

#: The ``.tir`` keys of the wind-up, with the attribute names of their values.
WINDUP_KEYS = {"BELT_IYY": "belt_iyy", "FREQ_WINDUP": "freq_windup", "DAMP_WINDUP": "damp_windup"}
_DIRECTION_WORDS = {1: "tangential (+X)", 2: "lateral (+Y)", 3: "radial (+Z)"}


@dataclass(frozen=True)
class WindupParameters:
    """The belt's wind-up from a tangential test (module docstring; SI).

    Attributes
    ----------
    pressure : float or None
        Test pressure in Pa.
    freq_windup, freq_windup_std : float
        ``FREQ_WINDUP`` in Hz (bare belt, attachment mass removed).
    damp_windup, damp_windup_std : float
        ``DAMP_WINDUP`` (dimensionless).
    belt_iyy, belt_iyy_std : float
        ``BELT_IYY`` in kg m^2.
    k_windup, k_windup_std : float
        ``k_theta = I omega_0^2`` in N m/rad.
    c_windup, c_windup_std : float
        ``c_theta = 2 zeta_0 I omega_0`` in N m s/rad.
    index : int
        The mode used (index in the model).
    fraction : float
        Its ``n = 0`` single-harmonic energy fraction.
    radius : float
        Radius of the tangential points in m.
    notes : list of str
    """

    pressure: float | None
    freq_windup: float
    freq_windup_std: float
    damp_windup: float
    damp_windup_std: float
    belt_iyy: float
    belt_iyy_std: float
    k_windup: float
    k_windup_std: float
    c_windup: float
    c_windup_std: float
    index: int
    fraction: float
    radius: float
    notes: list[str] = field(default_factory=list)

    def tir_values(self) -> dict[str, dict[str, float]]:
        """The ``.tir`` fields this test gives, by section (MF-Swift names, SI)."""
        return {
            "INERTIA": {"BELT_IYY": self.belt_iyy},
            "STRUCTURAL": {"FREQ_WINDUP": self.freq_windup, "DAMP_WINDUP": self.damp_windup},
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary with units."""
        return {
            "pressure_pa": self.pressure,
            "BELT_IYY": {"value": self.belt_iyy, "stderr": self.belt_iyy_std, "unit": "kg m^2"},
            "FREQ_WINDUP": {
                "value": self.freq_windup,
                "stderr": self.freq_windup_std,
                "unit": "Hz",
            },
            "DAMP_WINDUP": {"value": self.damp_windup, "stderr": self.damp_windup_std, "unit": "1"},
            "k_windup": {"value": self.k_windup, "stderr": self.k_windup_std, "unit": "N m/rad"},
            "c_windup": {"value": self.c_windup, "stderr": self.c_windup_std, "unit": "N m s/rad"},
            "mode_index": self.index,
            "n0_fraction": self.fraction,
            "radius_m": self.radius,
            "notes": self.notes,
        }


def check_tangential(model: ModalModel, source: str = "model") -> None:
    """Refuse a model whose response channels are not tangential (direction code 1).

    Raises
    ------
    InputError
        Naming the directions found (radial, lateral, ...).
    """
    dirs = sorted({abs(int(c.direction)) for c in model.outputs})
    if dirs != [TANGENTIAL_DIRECTION]:
        words = ", ".join(_DIRECTION_WORDS.get(d, f"direction code {d}") for d in dirs)
        raise InputError(
            f"{source}: the response channels are {words}; the wind-up needs a tangential test "
            f"(accelerations along the circumference, UFF direction code {TANGENTIAL_DIRECTION})"
        )


def _found(wa: WaveNumberAnalysis) -> str:
    return ", ".join(f"{m.label} at {m.frequency_hz:.4g} Hz" for m in wa.modes) or "no modes"


def _rotation_mode(
    wa: WaveNumberAnalysis, min_fraction: float, source: str
) -> tuple[ModeWaveNumber, list[ModeWaveNumber]]:
    """The single-harmonic ``n = 0`` mode of largest amplitude and the others (docstring)."""
    cands = [m for m in wa.modes if m.n == 0 and m.fraction >= min_fraction and m.amplitude > 0]
    if not cands:
        raise InputError(
            f"{source}: no n = 0 (uniform rotation) mode with an n = 0 share of at least "
            f"{min_fraction:g} among the identified modes (found: {_found(wa)}); the wind-up "
            "needs it"
        )
    cands.sort(key=lambda m: -m.amplitude)
    return cands[0], cands[1:]


def windup_from_modes(
    model: ModalModel,
    *,
    radius: float,
    pressure: float | None = None,
    analysis: WaveNumberAnalysis | None = None,
    attachment_mass: float = 0.0,
    attachment_damping: float = 0.0,
    shape_scale: float = 1.0,
    min_fraction: float = 0.9,
    source: str = "model",
) -> WindupParameters:
    """``FREQ_WINDUP``, ``DAMP_WINDUP`` and ``BELT_IYY`` from a tangential test's modes.

    Parameters
    ----------
    model : ModalModel
        Identified modes with mass-normalised shapes (drive-point scaling) at
        tangential outputs with their angles.
    radius : float
        Radius of the tangential points in m (module docstring).
    pressure : float, optional
        Test pressure in Pa (reported only).
    analysis : WaveNumberAnalysis, optional
        Precomputed wave numbers of ``model``.
    attachment_mass : float
        Known point mass at each drive point in kg (removed from the belt).
    attachment_damping : float
        Known tangential damper at each drive point in N s/m (removed).
    shape_scale : float
        Factor on the squared shapes (calibration, as in
        :func:`~tyredamp.tyremodel.rigid_ring_from_modes`); 1 = as measured.
    min_fraction : float
        Least ``n = 0`` energy fraction of the rotation shape (default 0.9).
    source : str
        Name of the test in messages.

    Raises
    ------
    InputError
        Not tangential channels, or no ``n = 0`` mode (saying what was found).
    PhysicsError
        An attachment mass above the mode's modal mass.
    """
    check_tangential(model, source)
    r = check_positive(radius, "radius")
    m_a = check_positive(attachment_mass, "attachment_mass", allow_zero=True)
    c_a = check_positive(attachment_damping, "attachment_damping", allow_zero=True)
    scale = check_positive(shape_scale, "shape_scale")
    wa = analysis if analysis is not None else wave_number_analysis(model)
    m, others = _rotation_mode(wa, min_fraction, source)
    members, apart = _split_members(m, others)
    c = _combined(model, members, scale)
    share = 1.0 - m_a * c["phi_d2"]
    if share <= 0:
        raise PhysicsError(
            f"{source}: attachment_mass exceeds the modal mass of the wind-up mode (check the mass)"
        )
    iyy = share * r**2 / c["a2"]
    w_meas = 2 * math.pi * c["f"]
    f0 = c["f"] / math.sqrt(share)
    z0 = (2 * c["z"] * w_meas - c_a * c["phi_d2"]) / (2 * w_meas * math.sqrt(share))
    sf0 = c["sf"] / math.sqrt(share)
    sz0 = c["sz"] / math.sqrt(share)
    si = 2.0 * c["rel_a"] * iyy
    w0, sw0 = 2 * math.pi * f0, 2 * math.pi * sf0
    kk = iyy * w0**2
    skk = kk * math.hypot(si / iyy, 2 * sw0 / w0)
    cc = 2 * z0 * iyy * w0
    scc = abs(cc) * math.sqrt((sz0 / z0) ** 2 + (si / iyy) ** 2 + (sw0 / w0) ** 2) if z0 else 0.0
    notes = []
    if len(members) > 1:
        notes.append(
            f"the fit split the rotation into {len(members)} poles at "
            + ", ".join(f"{o.frequency_hz:.4g}" for o in members)
            + " Hz (within three half-power bandwidths): their residues are summed and "
            "frequency and damping averaged with the residues as weights (more averages "
            "usually give one pole)"
        )
    if apart:
        notes.append(
            "other uniform-rotation (n = 0) modes at "
            + ", ".join(f"{o.frequency_hz:.4g}" for o in apart)
            + f" Hz are not used: the one of largest amplitude ({m.frequency_hz:.4g} Hz) is the "
            "belt's rotation on the held rim"
        )
    if si == 0:
        notes.append("no shape standard errors in the modes: BELT_IYY without uncertainty")
    if c_a == 0:
        notes.append(
            "DAMP_WINDUP includes every loss of the test set-up at the drive point (shaker "
            "attachment); give the attachment damping to remove a known local damper"
        )
    return WindupParameters(
        pressure=None if pressure is None else float(pressure),
        freq_windup=f0,
        freq_windup_std=sf0,
        damp_windup=z0,
        damp_windup_std=sz0,
        belt_iyy=iyy,
        belt_iyy_std=si,
        k_windup=kk,
        k_windup_std=skk,
        c_windup=cc,
        c_windup_std=scc,
        index=m.index,
        fraction=min(o.fraction for o in members),
        radius=r,
        notes=notes,
    )


def _split_members(
    main: ModeWaveNumber, others: list[ModeWaveNumber]
) -> tuple[list[ModeWaveNumber], list[ModeWaveNumber]]:
    """The ``n = 0`` poles of the main one's resonance (a split fit) and those apart.

    A pole within three half-power bandwidths ``2 zeta f`` of the main one
    belongs to its resonance.
    """
    width = 3 * 2 * max(main.damping_ratio, 1e-4) * main.frequency_hz
    near = [o for o in others if abs(o.frequency_hz - main.frequency_hz) <= width]
    return [main, *near], [o for o in others if o not in near]


def _combined(model: ModalModel, members: list[ModeWaveNumber], scale: float) -> dict[str, float]:
    """Squared amplitude, drive-point ``phi_d^2``, frequency, damping of the rotation's poles.

    One pole: ``A_t^2`` and ``phi_d^2 = 2 Omega sum_i |psi_d,i|^2``. Poles of a
    split fit: their residues add up to the resonance's, so ``A_t^2 = |sum_k
    a_k^2|`` (``a_k`` the complex ``n = 0`` coefficient of the second-order
    shape) and ``phi_d^2 = |sum_k 2 i Omega_k sum_i psi_d,ik^2|``; frequency,
    damping and standard errors are the means weighted by ``|a_k|^2``.
    """
    sf = model.std.get("frequency_hz")
    sz = model.std.get("damping_ratio")
    om = model.poles.imag
    if len(members) == 1:
        m = members[0]
        k = m.index
        rows = [m]
        a2 = m.amplitude**2
        phi_d2 = float(np.sum(np.abs(model.psi_in[:, k]) ** 2)) * 2.0 * float(om[k])
    else:
        rows = members
        cplx = []
        for o in members:
            mean = complex(np.mean(model.psi_out[:, o.index] * np.sqrt(2j * om[o.index])))
            cplx.append(o.amplitude**2 * np.exp(2j * np.angle(mean)))
        a2 = abs(sum(cplx))
        phi_d2 = abs(sum(2j * om[o.index] * np.sum(model.psi_in[:, o.index] ** 2) for o in rows))
    wts = np.array([o.amplitude**2 for o in rows])
    wts = wts / wts.sum()

    def wmean(vals: list[float]) -> float:
        return float(np.dot(wts, vals))

    def wstd(vals: list[float]) -> float:
        return float(np.sqrt(np.sum((wts * np.asarray(vals)) ** 2)))

    return {
        "a2": scale * a2,
        "phi_d2": scale * phi_d2,
        "f": wmean([o.frequency_hz for o in rows]),
        "z": wmean([o.damping_ratio for o in rows]),
        "sf": wstd([_finite(None if sf is None else float(sf[o.index])) for o in rows]),
        "sz": wstd([_finite(None if sz is None else float(sz[o.index])) for o in rows]),
        "rel_a": wstd([_finite(o.amplitude_std) / o.amplitude for o in rows]),
    }


def _finite(x: float | None) -> float:
    return 0.0 if x is None or not math.isfinite(x) else float(x)


def windup_budget(
    model: ModalModel,
    windup: WindupParameters,
    *,
    analysis: WaveNumberAnalysis,
    attachment_mass: float,
    attachment_damping: float,
    assumptions: Assumptions | None = None,
) -> UncertaintyBudget:
    """The uncertainty budget of the wind-up values (terms as in :mod:`.budget`).

    Calibration scales the squared shapes (``BELT_IYY ~ 1 / s``), the
    attachment mass and damping enter through ``phi_d^2``, and the
    ``rigid rotation`` term is the share of the shape that is not ``n = 0``
    (``1 - fraction``) times ``BELT_IYY``; each term is a central difference
    (JCGM 100:2008, 5.1.3), combined in quadrature (eq. (10)).
    """
    a = assumptions or Assumptions()

    def again(**kw: float) -> WindupParameters:
        args: dict[str, Any] = {
            "radius": windup.radius,
            "attachment_mass": attachment_mass,
            "attachment_damping": attachment_damping,
            "analysis": analysis,
        }
        args.update(kw)
        return windup_from_modes(model, **args)

    def half(lo: WindupParameters, hi: WindupParameters) -> dict[str, float]:
        return {k: abs(getattr(hi, v) - getattr(lo, v)) / 2 for k, v in WINDUP_KEYS.items()}

    zero = dict.fromkeys(WINDUP_KEYS, 0.0)
    u, um = a.calibration, a.attachment_mass * attachment_mass
    uc = a.attachment_damping * attachment_damping
    cal = half(again(shape_scale=1 - u), again(shape_scale=1 + u)) if u else zero
    mass = (
        half(
            again(attachment_mass=attachment_mass - um), again(attachment_mass=attachment_mass + um)
        )
        if um
        else zero
    )
    damp = (
        half(
            again(attachment_damping=attachment_damping - uc),
            again(attachment_damping=attachment_damping + uc),
        )
        if uc
        else zero
    )
    impurity = float(np.clip(1.0 - windup.fraction, 0.0, 1.0))
    stat = {
        "BELT_IYY": windup.belt_iyy_std,
        "FREQ_WINDUP": windup.freq_windup_std,
        "DAMP_WINDUP": windup.damp_windup_std,
    }
    terms = {
        k: {
            "statistical": stat[k],
            "calibration": cal[k],
            "attachment mass": mass[k],
            "attachment damping": damp[k],
            "rigid rotation": impurity * windup.belt_iyy if k == "BELT_IYY" else 0.0,
        }
        for k in WINDUP_KEYS
    }
    total = {k: math.sqrt(sum(v**2 for v in t.values())) for k, t in terms.items()}
    cal_text = (
        f"force and acceleration sensitivities within {100 * a.force_sensitivity:.3g} % and "
        f"{100 * a.acceleration_sensitivity:.3g} %"
    )
    att = (
        f"attachment mass {attachment_mass:.4g} kg +- {100 * a.attachment_mass:.3g} %"
        if attachment_mass > 0
        else "no mass attached at the drive point"
    )
    rigid = f"the n = 0 mode is a rigid rotation of the belt seen at radius {windup.radius:.4g} m"
    if attachment_damping > 0:
        without = again(attachment_damping=0.0).damp_windup
        damp_text = (
            f"attachment damping {attachment_damping:.4g} N s/m +- "
            f"{100 * a.attachment_damping:.3g} % removed ({without:.4g} without removing it)"
        )
    else:
        damp_text = (
            "no attachment damper removed (every loss at the drive point counted as the tyre's)"
        )
    return UncertaintyBudget(
        terms=terms,
        total=total,
        assumptions={
            "BELT_IYY": f"{cal_text}; {att}; {rigid}",
            "FREQ_WINDUP": f"{att}; {rigid}",
            "DAMP_WINDUP": f"{damp_text}; {att}; {rigid}",
        },
    )
