"""Rigid-ring (MF-Swift) in-plane parameters from the identified modes.

The rigid-ring model (Pacejka, *Tire and Vehicle Dynamics*, ch. 9; Zegelaar
1998; MF-Swift) treats the belt as a rigid ring of mass ``m_b`` and inertia
``I_by`` on the rim, with translational and rotational (wind-up)
spring-dampers. The belt-on-fixed-rim modes that define them are the ring's
``n = 1`` mode (translation: fore/aft and vertical, ``FREQ_LONG``,
``DAMP_LONG``) and its ``n = 0`` rotation (``FREQ_WINDUP``,
``DAMP_WINDUP``), and

``k = m_b omega^2``, ``c = 2 zeta m_b omega`` (translation),
``k_theta = I_by omega_0^2``, ``c_theta = 2 zeta_0 I_by omega_0`` (wind-up).

What a radial modal test gives
------------------------------
* ``FREQ_LONG``, ``DAMP_LONG``: frequency and damping ratio of the ``n = 1``
  modes (both members when an imperfection splits them: their mean, with the
  splitting reported).
* ``BELT_MASS``: the mass-normalised radial amplitude ``A`` of the ``n = 1``
  shape. A rigid translation ``X`` of the belt has radial motion
  ``X cos(theta - theta_0)`` and mass ``m_b`` (its tangential motion is part of
  the same rigid motion), so ``m_b X^2 = 1`` gives ``m_b = 1 / A^2``; with a
  known point mass ``m_a`` at the drive point, ``m_b = (1 - m_a phi_d^2)/A^2``
  and the bare-belt frequency is ``omega / sqrt(1 - m_a phi_d^2)``. This
  assumes that the ``n = 1`` mode is a rigid translation of the belt (the
  rigid-ring assumption itself).
* Not given: the wind-up mode (``n = 0``) is a tangential rotation of the
  belt with no radial motion, so radial accelerometers cannot see it:
  ``FREQ_WINDUP``, ``DAMP_WINDUP`` and ``BELT_IYY`` need tangential
  (circumferential) measurement (``BELT_IYY`` of a thin ring would be
  ``m_b R^2``, an assumption reported as such, not a measurement); a
  tangential test gives them (:mod:`~tyredamp.tyremodel.windup`). Lateral and
  yaw modes, the overall (footprint) stiffnesses and the tyre mass need other
  tests.

Standard errors propagate the modal ones (frequency, damping ratio, shape
amplitude) to first order, taken as independent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validate import check_positive
from ..exceptions import InputError, PhysicsError
from ..modal.model import ModalModel
from .wavenumber import WaveNumberAnalysis, wave_number_analysis

__all__ = ["NOT_FROM_RADIAL_TEST", "RigidRingParameters", "rigid_ring_from_modes"]

#: ``.tir`` fields of the in-plane rigid ring that a radial modal test cannot give, and why.
NOT_FROM_RADIAL_TEST: dict[str, str] = {
    "FREQ_WINDUP": "wind-up (n = 0 rotation) has no radial motion: needs a tangential test "
    "(--tangential)",
    "DAMP_WINDUP": "wind-up (n = 0 rotation) has no radial motion: needs a tangential test "
    "(--tangential)",
    "BELT_IYY": "needs the wind-up mode of a tangential test (--tangential); a thin ring would "
    "give m_b R^2",
    "BELT_IXX": "out-of-plane (lateral/camber) test",
    "FREQ_LAT": "out-of-plane (lateral) test",
    "DAMP_LAT": "out-of-plane (lateral) test",
    "FREQ_YAW": "out-of-plane (yaw/camber) test",
    "DAMP_YAW": "out-of-plane (yaw/camber) test",
    "MASS": "weighing the tyre",
    "IXX": "tyre inertia test",
    "IYY": "tyre inertia test",
    "LONGITUDINAL_STIFFNESS": "loaded tyre on the ground (footprint), not a free modal test",
    "LATERAL_STIFFNESS": "loaded tyre on the ground (footprint), not a free modal test",
    "YAW_STIFFNESS": "loaded tyre on the ground (footprint), not a free modal test",
}


@dataclass(frozen=True)
class RigidRingParameters:
    """In-plane rigid-ring parameters at one pressure (SI; module docstring).

    Attributes
    ----------
    pressure : float or None
        Test pressure in Pa.
    belt_mass, belt_mass_std : float
        ``BELT_MASS`` in kg.
    freq_long, freq_long_std : float
        ``FREQ_LONG`` in Hz (bare belt, attachment mass removed).
    damp_long, damp_long_std : float
        ``DAMP_LONG`` (dimensionless).
    k_long, k_long_std : float
        ``m_b omega^2`` in N/m.
    c_long, c_long_std : float
        ``2 zeta m_b omega`` in N s/m.
    members : list of dict
        The ``n = 1`` modes used (index, member, frequency, damping, mass).
    splitting_hz : float or None
        Frequency difference of the two members, when both were identified.
    thin_ring_iyy : float or None
        ``m_b R^2`` (kg m^2) when the radius is given: an assumption, not a
        measurement (``BELT_IYY`` is not written from it).
    not_given : dict of str to str
        Fields the test cannot give, with the reason.
    notes : list of str
    """

    pressure: float | None
    belt_mass: float
    belt_mass_std: float
    freq_long: float
    freq_long_std: float
    damp_long: float
    damp_long_std: float
    k_long: float
    k_long_std: float
    c_long: float
    c_long_std: float
    members: list[dict[str, Any]] = field(default_factory=list)
    splitting_hz: float | None = None
    thin_ring_iyy: float | None = None
    not_given: dict[str, str] = field(default_factory=lambda: dict(NOT_FROM_RADIAL_TEST))
    notes: list[str] = field(default_factory=list)

    def tir_values(self) -> dict[str, dict[str, float]]:
        """The ``.tir`` fields this test gives, by section (MF-Swift names, SI)."""
        return {
            "INERTIA": {"BELT_MASS": self.belt_mass},
            "STRUCTURAL": {"FREQ_LONG": self.freq_long, "DAMP_LONG": self.damp_long},
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary with units."""
        return {
            "pressure_pa": self.pressure,
            "pressure_bar": None if self.pressure is None else self.pressure / 1e5,
            "BELT_MASS": {"value": self.belt_mass, "stderr": self.belt_mass_std, "unit": "kg"},
            "FREQ_LONG": {"value": self.freq_long, "stderr": self.freq_long_std, "unit": "Hz"},
            "DAMP_LONG": {"value": self.damp_long, "stderr": self.damp_long_std, "unit": "1"},
            "k_long": {"value": self.k_long, "stderr": self.k_long_std, "unit": "N/m"},
            "c_long": {"value": self.c_long, "stderr": self.c_long_std, "unit": "N s/m"},
            "members": self.members,
            "splitting_hz": self.splitting_hz,
            "thin_ring_iyy_assumed": self.thin_ring_iyy,
            "not_given": self.not_given,
            "notes": self.notes,
        }


def _nan_to(x: float | None) -> float:
    return 0.0 if x is None or not math.isfinite(x) else float(x)


def rigid_ring_from_modes(
    model: ModalModel,
    *,
    pressure: float | None = None,
    analysis: WaveNumberAnalysis | None = None,
    attachment_mass: float = 0.0,
    attachment_damping: float = 0.0,
    radius: float | None = None,
    shape_scale: float = 1.0,
) -> RigidRingParameters:
    """In-plane rigid-ring parameters from the ``n = 1`` modes of ``model``.

    Parameters
    ----------
    model : ModalModel
        Identified modes with mass-normalised shapes (drive-point scaling) at
        radial outputs with angles.
    pressure : float, optional
        Test pressure in Pa (reported only).
    analysis : WaveNumberAnalysis, optional
        Precomputed wave numbers (default :func:`wave_number_analysis`).
    attachment_mass : float
        Known point mass at each drive point in kg (removed from the belt).
    attachment_damping : float
        Known local radial damper at each drive point in N s/m (removed from
        the damping: ``2 zeta omega - c_a phi_d^2``, default 0 = kept).
    radius : float, optional
        Belt radius in m, for the thin-ring ``m_b R^2`` reported as an assumption.
    shape_scale : float
        Factor on the squared mass-normalised shapes (the drive-point residue),
        as a calibration error of the response over the force transducer
        ``(1 + e_a) / (1 + e_f)`` would give; 1 = as measured (used by
        :mod:`~tyredamp.tyremodel.budget`).

    Raises
    ------
    InputError
        No usable ``n = 1`` mode.
    """
    m_a = check_positive(attachment_mass, "attachment_mass", allow_zero=True)
    c_a = check_positive(attachment_damping, "attachment_damping", allow_zero=True)
    wa = analysis if analysis is not None else wave_number_analysis(model)
    rows = _n1_members(model, wa, m_a, c_a, check_positive(shape_scale, "shape_scale"))
    if not rows:
        raise InputError(
            "model: no n = 1 mode (belt translation) among the identified modes; the rigid-ring "
            "in-plane parameters need it"
        )
    rows = sorted(rows, key=lambda r: float(r["frequency_hz"]))[:2]
    f, sf_ = _mean(rows, "frequency_hz", "frequency_std")
    z, sz_ = _mean(rows, "damping_ratio", "damping_std")
    mb, smb = _mean(rows, "belt_mass", "belt_mass_std")
    w = 2 * math.pi * f
    sw = 2 * math.pi * sf_
    kk = mb * w**2
    skk = kk * math.sqrt((smb / mb) ** 2 + (2 * sw / w) ** 2)
    cc = 2 * z * mb * w
    scc = cc * math.sqrt((sz_ / z) ** 2 + (smb / mb) ** 2 + (sw / w) ** 2) if z > 0 else math.nan
    split = None
    if len(rows) == 2:
        split = float(rows[1]["frequency_hz"]) - float(rows[0]["frequency_hz"])
    iyy = None
    if radius is not None:
        iyy = mb * check_positive(radius, "radius") ** 2
    return RigidRingParameters(
        pressure=None if pressure is None else float(pressure),
        belt_mass=mb,
        belt_mass_std=smb,
        freq_long=f,
        freq_long_std=sf_,
        damp_long=z,
        damp_long_std=sz_,
        k_long=kk,
        k_long_std=skk,
        c_long=cc,
        c_long_std=scc,
        members=rows,
        splitting_hz=split,
        thin_ring_iyy=iyy,
        notes=_notes(rows, c_a),
    )


def _n1_members(
    model: ModalModel, wa: WaveNumberAnalysis, m_a: float, c_a: float, scale: float = 1.0
) -> list[dict[str, Any]]:
    """The usable ``n = 1`` modes as bare-belt quantities (module docstring).

    One dictionary per mode: index, member, frequency and damping ratio of the
    bare belt (attachment mass and known damper removed) with standard errors,
    belt mass ``(1 - m_a phi_d^2) / A^2`` (kg) with its standard error, and
    the amplitude ``A``.
    """
    sf = model.std.get("frequency_hz")
    sz = model.std.get("damping_ratio")
    omega_d = model.poles.imag
    phi_d2 = scale * np.sum(np.abs(model.psi_in) ** 2, axis=0) * 2.0 * omega_d
    rows: list[dict[str, Any]] = []
    for m in wa.modes:
        if m.n != 1 or m.aliased or not m.single_harmonic:
            continue
        k = m.index
        share = 1.0 - m_a * float(phi_d2[k])
        if share <= 0:
            raise PhysicsError(
                "attachment_mass: exceeds the modal mass of the n = 1 mode (check the mass)"
            )
        a = m.amplitude * math.sqrt(scale)
        if not a > 0:
            continue
        mass = share / a**2
        f = m.frequency_hz / math.sqrt(share)
        # 2 zeta omega of the measured mode minus the known local damper, per bare belt
        w_meas = 2 * math.pi * m.frequency_hz
        zeta = (2 * m.damping_ratio * w_meas - c_a * float(phi_d2[k])) / (
            2 * w_meas * math.sqrt(share)
        )
        rel_a = _nan_to(m.amplitude_std) / a
        rows.append(
            {
                "index": k,
                "member": m.member,
                "frequency_hz": f,
                "frequency_std": _nan_to(None if sf is None else float(sf[k])) / math.sqrt(share),
                "damping_ratio": zeta,
                "damping_std": _nan_to(None if sz is None else float(sz[k])) / math.sqrt(share),
                "belt_mass": mass,
                "belt_mass_std": 2.0 * rel_a * mass,
                "amplitude": a,
            }
        )
    return rows


def _mean(rows: list[dict[str, Any]], key: str, std_key: str) -> tuple[float, float]:
    """Mean of ``key`` over the members and its standard error (independent members)."""
    v = float(np.mean([float(r[key]) for r in rows]))
    s = math.sqrt(sum(float(r[std_key]) ** 2 for r in rows)) / len(rows)
    return v, s


def _notes(rows: list[dict[str, Any]], c_a: float) -> list[str]:
    """Plain-language remarks on what the members and the options leave open."""
    notes = []
    if len(rows) == 1:
        notes.append(
            f"one n = 1 member identified ({rows[0]['member']}); with one drive point the other "
            "member of a perfect ring has a node there and is not excited"
        )
    if any(r["belt_mass_std"] == 0 for r in rows):
        notes.append("no shape standard errors in the modes: BELT_MASS without uncertainty")
    if c_a == 0:
        notes.append(
            "DAMP_LONG includes every loss of the test set-up at the drive point (shaker "
            "attachment); give attachment_damping to remove a known local damper"
        )
    return notes
