"""The tangential (circumferential) modal test of the ring tyre and its wind-up truth.

A radial test cannot see the belt's rotation on the rim (the ``n = 0``
wind-up mode has no radial motion). The tangential test drives the tread
along the circumference and measures the circumferential accelerations at
the points of the layout: :func:`tangential_tyre` gives the tyre as that
test sees it, and ``run_modal_test(tyre, direction="tangential")`` uses it.

Set-up
------
The ring's tangential DOFs sit at the mid-points ``(i + 1/2) 360/N`` deg of
the staggered grid (:mod:`~tyredamp.virtual.ring`), so the tangential
accelerometer of point ``k`` sits at the mid-point just ahead of the node of
point ``k`` (half a node spacing, 2.8 deg for the default 64 nodes), and the
shaker of a drive point drives that same mid-point (drive point and response
collocated). ``Channel.angle_deg`` records these angles and
``Channel.direction`` is :data:`TANGENTIAL_DIRECTION` (UFF ``+X`` of the
local frame whose ``+Z`` is the outward radial direction of the radial test
and ``+X`` the direction of increasing angle). The layout's attachment mass
and damper (the shaker's drive-rod tip) act along the drive: in this test
they load the tangential DOF of the drive point instead of the radial one.

Truth of the wind-up mode
-------------------------
For the axisymmetric ring the uniform tangential motion ``v = const``,
``w = 0`` has no membrane strain (``v' + w = 0``) and no change of
curvature (``v' - w'' = 0``), and the pre-stress term vanishes with it, so
only the tangential foundation ``k_t`` resists it (module docstring of
:mod:`~tyredamp.virtual.ring`): the rotation mode of the bare ring is at

``omega_0^2 = k_t / (rho A)``, with ``zeta_0 = c_t / (2 rho A omega_0)``

(``c_t`` the tangential sidewall dashpot per length; the band losses act on
the strains and add nothing), and the belt's inertia about the axle is
``I = rho A 2 pi R^3`` -- the rigid-ring (MF-Swift) rotational
spring ``k_theta = I omega_0^2 = 2 pi R^3 k_t`` (Pacejka, *Tire and Vehicle
Dynamics*, 3rd ed., 2012, sec. 9.2; Zegelaar, PhD thesis TU Delft 1998,
ch. 4). The staggered differences of a constant vanish exactly, so the
discretised bare ring has the same frequency. :func:`windup_truth` gives the
exact rotation mode of any ring tyre (attachments, imperfections, cavity).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import PhysicsError
from ..frf import Channel
from ..mechanics import MCKSystem, proportional_part
from .parameters import RingTyreParameters
from .ring import RingTyre
from .truth import wave_numbers

__all__ = [
    "TANGENTIAL_DIRECTION",
    "WindupTruth",
    "bare_ring_windup",
    "tangential_tyre",
    "windup_truth",
]

#: UFF direction code of the tangential (circumferential) channels: local ``+X``.
TANGENTIAL_DIRECTION = 1


class _TangentialRingTyre(RingTyre):
    """A :class:`RingTyre` measured and driven tangentially (module docstring).

    Built by :func:`tangential_tyre` from a radial one; only the measured
    DOFs, the channels and the drive-point attachment differ.
    """

    measured_direction = "tangential"

    @property
    def point_dofs(self) -> NDArray[np.intp]:
        """DOF index of the tangential displacement at each point, shape (n_points,)."""
        return (self.n_ring + self._point_nodes).astype(np.intp)

    @property
    def drive_dofs(self) -> NDArray[np.intp]:
        """DOF index of the tangential displacement at each drive point, shape (n_drive,)."""
        return (self.n_ring + self._drive_nodes).astype(np.intp)

    @property
    def point_angles_deg(self) -> NDArray[np.float64]:
        """Angles of the tangential accelerometers in deg (mid-points), shape (n_points,)."""
        return self.tangential_angles_deg[self._point_nodes]

    @property
    def output_channels(self) -> tuple[Channel, ...]:
        """Tangential acceleration channels ``A<k>`` (direction :data:`TANGENTIAL_DIRECTION`)."""
        return tuple(
            Channel(
                node=k + 1, direction=TANGENTIAL_DIRECTION, angle_deg=float(a), name=f"A{k + 1}"
            )
            for k, a in enumerate(self.point_angles_deg)
        )

    @property
    def input_channels(self) -> tuple[Channel, ...]:
        """Tangential force channels ``F<k>`` at the drive points."""
        ang = self.point_angles_deg
        return tuple(
            Channel(
                node=dp, direction=TANGENTIAL_DIRECTION, angle_deg=float(ang[dp - 1]), name=f"F{dp}"
            )
            for dp in self.layout.drive_points
        )

    def __repr__(self) -> str:
        return "tangential " + super().__repr__()


def tangential_tyre(tyre: RingTyre) -> RingTyre:
    """The tyre as the tangential test sees it (module docstring).

    Parameters
    ----------
    tyre : RingTyre
        The tyre with its layout (the radial test's).

    Returns
    -------
    RingTyre
        The same tyre whose measured points, drive points and channels are
        tangential and whose drive-point attachment (``layout.attachment_mass``
        in kg, ``layout.attachment_damping`` in N s/m) loads the tangential
        DOF of each drive point; ``measured_direction`` is ``"tangential"``.
    """
    if isinstance(tyre, _TangentialRingTyre):
        return tyre
    out = _TangentialRingTyre.__new__(_TangentialRingTyre)
    out.__dict__.update(copy.copy(tyre.__dict__))
    n = tyre.n_ring
    m_a, c_a = tyre.layout.attachment_mass, tyre.layout.attachment_damping
    phys = tyre.physical_system
    m = phys.M.copy()
    c_att = np.zeros_like(m)
    for node in tyre.drive_dofs:
        m[node, node] -= m_a
        m[n + node, n + node] += m_a
        c_att[n + node, n + node] += c_a
    sources = dict(tyre.damping_sources)
    sources.pop("attachment", None)
    if np.any(c_att):
        sources["attachment"] = c_att
    c = sum(sources.values(), np.zeros_like(m))
    out.damping_sources = sources
    out.physical_system = MCKSystem(m, 0.5 * (c + c.T), phys.K)
    nu = tyre.nonproportionality
    if nu == 1.0:
        out.system = out.physical_system
    else:
        c_p = proportional_part(out.physical_system)
        c_nu = c_p if nu == 0.0 else c_p + nu * (out.physical_system.C - c_p)
        out.system = out.physical_system.with_damping(0.5 * (c_nu + c_nu.T))
    return out


@dataclass(frozen=True)
class WindupTruth:
    """The exact rotation (wind-up, ``n = 0``) mode of a ring tyre.

    Attributes
    ----------
    frequency_hz, damping_ratio : float
        Of the complex mode of the tested tyre (attachments included).
    bare_frequency_hz, bare_damping_ratio : float
        Of the same tyre without the drive-point attachments (what
        ``FREQ_WINDUP`` and ``DAMP_WINDUP`` describe).
    inertia : float
        Rotational inertia of the belt about the axle, ``R^2`` times the
        tangential masses of the ring (kg m^2, attachments excluded): the
        rigid-ring ``BELT_IYY``.
    modal_inertia : float
        ``R^2 / a^2`` with ``a`` the mean tangential amplitude of the
        mass-normalised mode at the measured points (kg m^2, attachments
        included).
    purity : float
        Share of the mode's harmonic power in ``n = 0`` (1 for a perfect ring).
    """

    frequency_hz: float
    damping_ratio: float
    bare_frequency_hz: float
    bare_damping_ratio: float
    inertia: float
    modal_inertia: float
    purity: float


def _rotation_mode(system: MCKSystem, n: int) -> tuple[int, float]:
    """Index (complex modes, ascending) of the lowest mode labelled ``n = 0`` and its purity."""
    cm = system.complex_modes()
    psi = cm.Psi
    wn, pur = wave_numbers(psi[:n], psi[n : 2 * n])
    idx = np.flatnonzero(wn == 0)
    if idx.size == 0:
        raise PhysicsError("windup_truth: no rotation (n = 0) mode in the tyre's discretisation")
    k = int(idx[np.argmin(cm.frequency_hz[idx])])
    return k, float(pur[k])


def windup_truth(tyre: RingTyre) -> WindupTruth:
    """The exact wind-up mode of ``tyre`` (radial or :func:`tangential_tyre`).

    The mode is the lowest whose shape (radial and tangential, whole ring)
    has most of its harmonic power at ``n = 0``
    (:func:`~tyredamp.virtual.wave_numbers`).

    Raises
    ------
    PhysicsError
        No such mode (a strongly imperfect ring).
    """
    tt = tangential_tyre(tyre)
    n = tt.n_ring
    cm = tt.system.complex_modes()
    k, purity = _rotation_mode(tt.system, n)
    m_a, c_a = tt.layout.attachment_mass, tt.layout.attachment_damping
    drv = tt.drive_dofs
    m_bare = tt.system.M.copy()
    c_bare = tt.system.C.copy()
    m_bare[drv, drv] -= m_a
    c_bare[drv, drv] -= c_a
    bare = MCKSystem(m_bare, c_bare, tt.system.K)
    kb, _ = _rotation_mode(bare, n)
    cb = bare.complex_modes()
    r = tt.params.radius
    inertia = r**2 * float(np.trace(m_bare[n : 2 * n, n : 2 * n]))
    um = tt.system.undamped_modes()
    wn, _ = wave_numbers(um.phi[:n], um.phi[n : 2 * n])
    j = int(np.flatnonzero(wn == 0)[np.argmin(um.frequency_hz[wn == 0])])
    a = abs(float(np.mean(um.phi[tt.point_dofs, j])))
    return WindupTruth(
        frequency_hz=float(cm.frequency_hz[k]),
        damping_ratio=float(cm.damping_ratio[k]),
        bare_frequency_hz=float(cb.frequency_hz[kb]),
        bare_damping_ratio=float(cb.damping_ratio[kb]),
        inertia=inertia,
        modal_inertia=r**2 / a**2,
        purity=purity,
    )


def bare_ring_windup(params: RingTyreParameters) -> tuple[float, float, float]:
    """Closed-form wind-up of the bare ring (module docstring).

    Returns
    -------
    frequency_hz : float
        ``sqrt(k_t / (rho A)) / (2 pi)`` in Hz.
    damping_ratio : float
        ``c_t / (2 rho A omega_0)``.
    inertia : float
        ``rho A 2 pi R^3`` in kg m^2.
    """
    ra = params.mass_per_length
    w0 = math.sqrt(params.tangential_stiffness / ra)
    zeta = params.tangential_damping / (2 * ra * w0)
    return w0 / (2 * math.pi), zeta, ra * 2 * math.pi * params.radius**3
