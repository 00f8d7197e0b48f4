"""Uncertainty budget of the rigid-ring values written into a ``.tir`` file.

The statistical standard errors of :func:`~tyredamp.tyremodel.rigid_ring_from_modes`
(from the modal fit's noise) leave out what usually dominates:

* **calibration** -- the mass-normalised shapes come from a drive-point
  accelerance ``H = a / F``; relative sensitivity errors ``e_a`` of the
  accelerometer and ``e_f`` of the force transducer scale the squared
  shapes by ``s = (1 + e_a) / (1 + e_f)``, to first order with standard
  deviation ``u_s = sqrt(u_a^2 + u_f^2)``. ``BELT_MASS = (1 - m_a phi_d^2) / A^2``
  scales as ``1 / s`` (``FREQ_LONG`` and ``DAMP_LONG`` only through the
  attachment correction).
* **attachment mass** ``m_a`` and **attachment damping** ``c_a`` -- known
  only to some relative accuracy; ``DAMP_LONG`` depends on the assumed
  damper directly (the value without it is reported beside it).
* **rigid translation** -- the rigid-ring model takes the ``n = 1`` mode as
  a rigid translation of the belt: the share of the shape that is not the
  ``n = 1`` harmonic (``1 - fraction``) bounds the relative error of
  ``BELT_MASS``, and when both members of the pair are identified, half
  their difference is the spread the single ring cannot represent.

Each term is the half difference of the value at the input plus and minus
its standard uncertainty (a central-difference sensitivity coefficient times
the input uncertainty, JCGM 100:2008 *Guide to the expression of
uncertainty in measurement*, 5.1.3 and eq. (10)); the terms are taken as
uncorrelated and combined in quadrature (eq. (10)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..modal.model import ModalModel
from .rigid import RigidRingParameters, rigid_ring_from_modes
from .wavenumber import WaveNumberAnalysis

__all__ = ["Assumptions", "UncertaintyBudget", "rigid_ring_budget"]

#: The ``.tir`` keys the rigid ring gives, with the attribute names of their values.
KEYS = {"BELT_MASS": "belt_mass", "FREQ_LONG": "freq_long", "DAMP_LONG": "damp_long"}
_UNITS = {
    "BELT_MASS": "kg",
    "FREQ_LONG": "Hz",
    "DAMP_LONG": "",
    "BELT_IYY": "kg m^2",
    "FREQ_WINDUP": "Hz",
    "DAMP_WINDUP": "",
}


@dataclass(frozen=True)
class Assumptions:
    """Relative standard uncertainties (1 sigma, fractions) of the test's inputs.

    Attributes
    ----------
    force_sensitivity, acceleration_sensitivity : float
        Calibration of the force transducer and the accelerometers (typical
        1-2 % each; default 0.01).
    attachment_mass : float
        Of the given attachment mass (default 0.1).
    attachment_damping : float
        Of the given attachment damping (default 0.5: such a damper is
        rarely measured).
    """

    force_sensitivity: float = 0.01
    acceleration_sensitivity: float = 0.01
    attachment_mass: float = 0.1
    attachment_damping: float = 0.5

    def __post_init__(self) -> None:
        for name in ("force_sensitivity", "acceleration_sensitivity", "attachment_mass"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 <= v <= 0.5):
                raise InputError(f"{name} uncertainty: expected a fraction 0 to 0.5, got {v!r}")
        v = self.attachment_damping
        if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 <= v <= 1):
            raise InputError(f"attachment_damping uncertainty: expected 0 to 1, got {v!r}")

    @property
    def calibration(self) -> float:
        """``u_s = sqrt(u_f^2 + u_a^2)``, relative (module docstring)."""
        return math.hypot(self.force_sensitivity, self.acceleration_sensitivity)


@dataclass(frozen=True)
class UncertaintyBudget:
    """Standard uncertainty of each written value by source (module docstring).

    Attributes
    ----------
    terms : dict of str to dict of str to float
        ``{key: {source: standard uncertainty}}`` in the key's unit; sources
        ``statistical``, ``calibration``, ``attachment mass``,
        ``attachment damping``, ``rigid translation``.
    total : dict of str to float
        Root sum of squares of the terms.
    assumptions : dict of str to str
        ``{key: what the value assumes}``, in words.
    without_attachment_damping : float or None
        ``DAMP_LONG`` with no attachment damper removed (when one was given).
    """

    terms: dict[str, dict[str, float]]
    total: dict[str, float]
    assumptions: dict[str, str]
    without_attachment_damping: float | None = None
    inputs: dict[str, float] = field(default_factory=dict)

    def comment(self, key: str) -> str:
        """``+- total (1 sigma: term value, ...); assumes ...`` for a ``.tir`` comment."""
        unit = f" {_UNITS[key]}" if _UNITS[key] else ""
        parts = ", ".join(f"{k} {v:.2g}" for k, v in self.terms[key].items() if v > 0)
        text = f"+- {self.total[key]:.3g}{unit} (1 sigma: {parts or 'no term'})"
        if self.assumptions.get(key):
            text += f"; assumes {self.assumptions[key]}"
        return text

    def joined(self, other: UncertaintyBudget) -> UncertaintyBudget:
        """This budget with the keys of ``other`` added (e.g. the wind-up's)."""
        return UncertaintyBudget(
            terms={**self.terms, **other.terms},
            total={**self.total, **other.total},
            assumptions={**self.assumptions, **other.assumptions},
            without_attachment_damping=self.without_attachment_damping,
            inputs=self.inputs,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "terms": self.terms,
            "total": self.total,
            "assumptions": self.assumptions,
            "without_attachment_damping": self.without_attachment_damping,
            "inputs": self.inputs,
        }


def _half_difference(lo: RigidRingParameters, hi: RigidRingParameters) -> dict[str, float]:
    return {k: abs(getattr(hi, a) - getattr(lo, a)) / 2 for k, a in KEYS.items()}


def rigid_ring_budget(
    model: ModalModel,
    rigid: RigidRingParameters,
    *,
    analysis: WaveNumberAnalysis,
    attachment_mass: float,
    attachment_damping: float,
    assumptions: Assumptions | None = None,
) -> UncertaintyBudget:
    """The uncertainty budget of ``rigid``'s ``BELT_MASS``, ``FREQ_LONG``, ``DAMP_LONG``.

    Parameters
    ----------
    model : ModalModel
        The modes ``rigid`` came from.
    rigid : RigidRingParameters
        From :func:`~tyredamp.tyremodel.rigid_ring_from_modes` with the same
        ``model``, ``analysis`` and attachment values.
    analysis : WaveNumberAnalysis
    attachment_mass, attachment_damping : float
        As given to :func:`~tyredamp.tyremodel.rigid_ring_from_modes` (kg, N s/m).
    assumptions : Assumptions, optional
        Input uncertainties (default :class:`Assumptions`).

    Returns
    -------
    UncertaintyBudget
    """
    a = assumptions or Assumptions()

    def again(**kw: float) -> RigidRingParameters:
        args = {"attachment_mass": attachment_mass, "attachment_damping": attachment_damping}
        args.update(kw)
        return rigid_ring_from_modes(model, analysis=analysis, **args)

    zero = dict.fromkeys(KEYS, 0.0)
    stat = {"BELT_MASS": rigid.belt_mass_std, "FREQ_LONG": rigid.freq_long_std}
    stat["DAMP_LONG"] = rigid.damp_long_std
    u = a.calibration
    cal = _half_difference(again(shape_scale=1 - u), again(shape_scale=1 + u)) if u else zero
    um = a.attachment_mass * attachment_mass
    mass = (
        _half_difference(
            again(attachment_mass=attachment_mass - um),
            again(attachment_mass=attachment_mass + um),
        )
        if um
        else zero
    )
    uc = a.attachment_damping * attachment_damping
    damp = (
        _half_difference(
            again(attachment_damping=attachment_damping - uc),
            again(attachment_damping=attachment_damping + uc),
        )
        if uc
        else zero
    )
    rigid_t = _rigid_translation(rigid, analysis)
    terms: dict[str, dict[str, float]] = {}
    for k in KEYS:
        terms[k] = {
            "statistical": float(stat[k]) if math.isfinite(stat[k]) else 0.0,
            "calibration": cal[k],
            "attachment mass": mass[k],
            "attachment damping": damp[k],
            "rigid translation": rigid_t[k],
        }
    total = {k: math.sqrt(sum(v**2 for v in t.values())) for k, t in terms.items()}
    without = again(attachment_damping=0.0).damp_long if attachment_damping > 0 else None
    return UncertaintyBudget(
        terms=terms,
        total=total,
        assumptions=_assumption_text(attachment_mass, attachment_damping, a, without),
        without_attachment_damping=without,
        inputs={
            "force_sensitivity": a.force_sensitivity,
            "acceleration_sensitivity": a.acceleration_sensitivity,
            "attachment_mass_kg": attachment_mass,
            "attachment_mass_relative": a.attachment_mass,
            "attachment_damping_N_s_per_m": attachment_damping,
            "attachment_damping_relative": a.attachment_damping,
        },
    )


def _rigid_translation(rigid: RigidRingParameters, wa: WaveNumberAnalysis) -> dict[str, float]:
    """Model terms of the rigid-ring idealisation (module docstring)."""
    by_index = {m.index: m for m in wa.modes}
    fr = [by_index[int(r["index"])].fraction for r in rigid.members if int(r["index"]) in by_index]
    impurity = float(np.clip(1.0 - np.mean(fr), 0.0, 1.0)) if fr else 0.0
    out = {"BELT_MASS": impurity * rigid.belt_mass, "FREQ_LONG": 0.0, "DAMP_LONG": 0.0}
    if len(rigid.members) == 2:
        m0, m1 = rigid.members
        spread = {
            "BELT_MASS": abs(float(m1["belt_mass"]) - float(m0["belt_mass"])) / 2,
            "FREQ_LONG": abs(float(m1["frequency_hz"]) - float(m0["frequency_hz"])) / 2,
            "DAMP_LONG": abs(float(m1["damping_ratio"]) - float(m0["damping_ratio"])) / 2,
        }
        out = {k: math.hypot(out[k], spread[k]) for k in out}
    return out


def _assumption_text(
    m_a: float, c_a: float, a: Assumptions, without: float | None
) -> dict[str, str]:
    cal = (
        f"force and acceleration sensitivities within {100 * a.force_sensitivity:.3g} % and "
        f"{100 * a.acceleration_sensitivity:.3g} %"
    )
    rigid = "the n = 1 mode is a rigid translation of the belt"
    att = (
        f"attachment mass {m_a:.4g} kg +- {100 * a.attachment_mass:.3g} %"
        if m_a > 0
        else "no mass attached at the drive point"
    )
    if c_a > 0 and without is not None:
        damp = (
            f"attachment damping {c_a:.4g} N s/m +- {100 * a.attachment_damping:.3g} % removed "
            f"({without:.4g} without removing it)"
        )
    else:
        damp = "no attachment damper removed (every loss at the drive point counted as the tyre's)"
    return {
        "BELT_MASS": f"{cal}; {att}; {rigid}",
        "FREQ_LONG": f"{att}; {rigid}",
        "DAMP_LONG": f"{damp}; {att}; {rigid}",
    }
