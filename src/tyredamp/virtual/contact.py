"""The loaded contact patch of the ring tyre: tread springs to the road and the hub stiffness.

A load ``F`` presses the tyre on a flat road at ``angle_deg`` (default 180 deg,
opposite measurement point 1). The road holds the tread over the patch
``|theta - theta_c| <= a / R`` through the tread rubber, modelled as radial and
tangential Winkler springs per unit circumferential length (the linearised
brush/foundation contact of Pacejka, *Tire and Vehicle Dynamics*, 3rd ed.,
2012, sec. 3.2 and ch. 9; the finite-difference ring with a patch of Dynamics
2(2), 2022), with a Kelvin-Voigt loss of the tread rubber.

The patch half-length follows from the load and the vertical stiffness of the
tyre itself: the deflection is ``rho = F / K_hub`` and the half-length is the
contact-length law of MF-Tyre 6.1 (Pacejka & Besselink, *Tire and Vehicle
Dynamics*, 3rd ed., 2012, eq. (A3.7)),

``a = R_0 (q_ra2 rho / R_0 + q_ra1 sqrt(rho / R_0))``,

with ``R_0`` the unloaded outer radius (band radius plus tread depth). The
geometric chord of the deflected circle, ``sqrt(2 R_0 rho)`` (``q_ra1 =
sqrt 2``), is about twice as long: a tyre's sidewalls bulge and its belt
bends smoothly into the patch instead of following the road over the whole
chord, which measured contact lengths show (public MF 6.1 property files
carry ``Q_RA1`` 0.67 and ``Q_RA2`` 0.73-0.76, the TNO example tyre of
Pacejka 2012). The chord law made the patch 0.30 m long at 6.5 bar and 25 kN,
and the hub stiffness, which grows with the patch, 26 % above the
.tir value.
``K_hub`` is the static vertical stiffness between a rigid hub and the road
(:func:`hub_stiffness`): the ring's stiffness condensed onto the road
displacement,

``K_hub = e^T K_c e - e^T K_c (K + K_c)^{-1} K_c e``

((static condensation, Guyan, AIAA J. 3 (1965) 380), with ``K`` the ring with
the hub fixed, ``K_c`` the tread springs and ``e`` the ring-coordinate image of
a unit vertical road displacement. Since ``K_hub`` grows with ``a``, the pair
``(a, K_hub)`` is found by bisection on ``a`` (:func:`solve_patch`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError, PhysicsError
from .parameters import _check_field

__all__ = [
    "ContactPatch",
    "PatchState",
    "contact_blocks",
    "contact_half_length",
    "hub_stiffness",
    "patch_intrusion",
    "patch_springs",
    "solve_patch",
]


@dataclass(frozen=True)
class ContactPatch:
    """A static load on a flat road and the tread between road and band.

    Parameters
    ----------
    load : float
        Vertical load ``F`` in N, > 0. A 295/80R22.5 carries 20-37 kN (single
        fitment at 8-9 bar); the demo of a loaded tyre uses 25 kN.
    radial_stiffness : float
        Radial tread stiffness per unit circumferential length in N/m^2.
        Default 1.75e7: the compression stiffness ``E b_c / h`` of a tread of
        ``h`` = 20 mm with an effective (unconfined) modulus of about 2 MPa
        on the ``b_c`` = 0.175 m of the 0.24 m tread that touches the road
        (truck rib and drive patterns have a land-to-sea ratio of about
        0.7). With the default ring the hub stiffness is 1-14 % above
        the Goodyear 335/65R22.5 (Project Chrono ``feda`` .tir,
        Calspan-measured) at the files' pressures and nominal loads (2.76 and
        6.55 bar) and 0.9 MN/m at 7.5 bar and 25 kN, beside the 1.0 MN/m of the
        315/80R22.5 bus tyre at 8 bar (Pacejka 2012, appendix 3).
    tangential_stiffness : float
        Tangential (shear) tread stiffness per unit length in N/m^2. Default
        1.2e7: ``G b / h`` with ``G`` = 1 MPa, ``h`` = 20 mm (tread shear;
        Pacejka 2012, sec. 3.2, brush stiffness per length of the same order).
    loss_factor : float
        Loss factor of the tread rubber in contact, >= 0. Default 0.15
        (tread compounds 0.1-0.2 near room temperature; Gehman, Rubber Chem.
        Technol. 1957; spec ``tyre-physics-references.md``).
    loss_frequency : float
        Frequency in Hz where the Kelvin-Voigt loss ``eta / omega_ref K_c`` has
        loss factor ``eta``. Default 100 (the middle of the 0-200 Hz band).
    angle_deg : float
        Centre of the patch in deg (0 deg is measurement point 1). Default 180.
    tread_depth : float
        Tread rubber between the band and the road in m, > 0 (``R_0 = R +
        tread_depth`` in the length law). Default 0.02.
    length_sqrt, length_linear : float
        ``q_ra1`` and ``q_ra2`` of the contact-length law (module docstring),
        >= 0. Defaults 0.671 and 0.733 (MF 6.1 ``Q_RA1``, ``Q_RA2`` of the
        public TNO example property file, Pacejka 2012). ``length_sqrt =
        sqrt(2)``, ``length_linear = 0`` is the geometric chord.
    """

    load: float
    radial_stiffness: float = 1.75e7
    tangential_stiffness: float = 1.2e7
    loss_factor: float = 0.15
    loss_frequency: float = 100.0
    angle_deg: float = 180.0
    tread_depth: float = 0.02
    length_sqrt: float = 0.671
    length_linear: float = 0.733

    def __post_init__(self) -> None:
        for name in ("load", "radial_stiffness", "tangential_stiffness", "loss_frequency"):
            _check_field(self, name, allow_zero=False)
        _check_field(self, "tread_depth", allow_zero=False)
        for name in ("loss_factor", "length_sqrt", "length_linear"):
            _check_field(self, name, allow_zero=True)
        for name in ("tread_depth", "length_sqrt", "length_linear"):
            object.__setattr__(self, name, float(getattr(self, name)))
        try:
            ang = float(self.angle_deg)
        except (TypeError, ValueError):
            raise InputError(
                f"ContactPatch.angle_deg: expected a number, got {self.angle_deg!r}"
            ) from None
        if not math.isfinite(ang):
            raise InputError(f"ContactPatch.angle_deg: expected a finite angle, got {ang}")
        for name in ("load", "radial_stiffness", "tangential_stiffness", "loss_factor"):
            object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "loss_frequency", float(self.loss_frequency))
        object.__setattr__(self, "angle_deg", ang)


@dataclass(frozen=True)
class PatchState:
    """The solved patch of a loaded ring.

    Attributes
    ----------
    half_length : float
        Patch half-length ``a`` in m.
    deflection : float
        Static vertical deflection ``rho = F / K_hub`` in m.
    hub_stiffness : float
        Vertical hub-to-road stiffness ``K_hub`` in N/m.
    radial_springs, tangential_springs : ndarray, shape (n_ring,)
        Spring of each ring node (radial) and mid-point (tangential) in N/m.
    """

    half_length: float
    deflection: float
    hub_stiffness: float
    radial_springs: NDArray[np.float64]
    tangential_springs: NDArray[np.float64]


def _cell_overlap(
    centres: NDArray[np.floating], h: float, lo: float, hi: float
) -> NDArray[np.float64]:
    """Angle (rad) of each cell ``[c - h/2, c + h/2]`` inside ``[lo, hi]``, periodic."""
    out = np.zeros(centres.size)
    for shift in (-2 * np.pi, 0.0, 2 * np.pi):
        a = np.maximum(centres + shift - h / 2, lo)
        b = np.minimum(centres + shift + h / 2, hi)
        out += np.clip(b - a, 0.0, None)
    return out


def patch_springs(
    patch: ContactPatch, radius: float, n_ring: int, half_length: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Tread springs of a patch of half-length ``half_length`` (m) on ``n_ring`` cells.

    Each node (radial) and mid-point (tangential) gets its stiffness per
    length times the arc ``R dtheta`` of its cell inside the patch, N/m.

    Returns
    -------
    radial, tangential : ndarray, shape (n_ring,)
    """
    h = 2 * np.pi / n_ring
    c = math.radians(patch.angle_deg) % (2 * np.pi)
    half = half_length / radius
    nodes = np.arange(n_ring) * h
    radial = patch.radial_stiffness * radius * _cell_overlap(nodes, h, c - half, c + half)
    tang = patch.tangential_stiffness * radius * _cell_overlap(nodes + h / 2, h, c - half, c + half)
    return radial, tang


def _road_direction(patch: ContactPatch, n_ring: int) -> NDArray[np.float64]:
    """Ring-coordinate image of a unit road displacement towards the hub, shape (2 n_ring,)."""
    h = 2 * np.pi / n_ring
    c = math.radians(patch.angle_deg)
    nodes = np.arange(n_ring) * h
    # the road moves along -e_r(c); its radial part at theta is -cos(theta - c),
    # its tangential part (e_theta) is sin(theta - c)
    return np.concatenate([-np.cos(nodes - c), np.sin(nodes + h / 2 - c)])


def hub_stiffness(
    k_ring: NDArray[np.float64],
    radial: NDArray[np.float64],
    tangential: NDArray[np.float64],
    patch: ContactPatch,
) -> float:
    """Static vertical hub-to-road stiffness ``K_hub`` in N/m (Guyan condensation).

    Parameters
    ----------
    k_ring : ndarray, shape (2 n_ring, 2 n_ring)
        Ring stiffness with the hub fixed (sidewalls to ground), N/m.
    radial, tangential : ndarray, shape (n_ring,)
        Tread springs (:func:`patch_springs`), N/m.
    patch : ContactPatch

    Returns
    -------
    float
        ``e^T K_c e - e^T K_c (K + K_c)^{-1} K_c e`` (module docstring).
    """
    n = radial.size
    kc = np.concatenate([radial, tangential])
    e = _road_direction(patch, n)
    f = kc * e
    x = np.linalg.solve(k_ring + np.diag(kc), f)
    return float(e @ f - f @ x)


def contact_half_length(patch: ContactPatch, radius: float, deflection: float) -> float:
    """Half-length ``a`` (m) of the MF 6.1 contact-length law at ``deflection`` (m).

    ``a = R_0 (q_ra2 rho / R_0 + q_ra1 sqrt(rho / R_0))``, ``R_0 = radius +
    tread_depth`` (Pacejka & Besselink 2012, eq. (A3.7); module docstring).
    """
    r0 = radius + patch.tread_depth
    x = max(deflection, 0.0) / r0
    return r0 * (patch.length_linear * x + patch.length_sqrt * math.sqrt(x))


def solve_patch(k_ring: NDArray[np.float64], patch: ContactPatch, radius: float) -> PatchState:
    """Patch half-length and hub stiffness consistent with the load (module docstring).

    Bisection on ``a`` of ``g(a) = a_law(rho(a)) - a`` with ``rho(a) = F /
    K_hub(a)`` and ``a_law`` of :func:`contact_half_length`; ``g`` falls with
    ``a`` since ``K_hub`` rises.

    Raises
    ------
    PhysicsError
        A load that flattens the tyre by more than its radius.
    """
    n = k_ring.shape[0] // 2

    def state(a: float) -> tuple[float, float, float]:
        r, t = patch_springs(patch, radius, n, a)
        kh = hub_stiffness(k_ring, r, t, patch)
        d = patch.load / kh
        return kh, d, contact_half_length(patch, radius, d)

    lo, hi = 1e-6 * radius, 0.99 * radius
    _, d_hi, a_hi = state(hi)
    if d_hi >= radius or a_hi > hi:
        raise PhysicsError(
            f"ContactPatch.load: {patch.load:g} N flattens the tyre by more than its radius; "
            "expected a load the sidewalls can carry"
        )
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if state(mid)[2] > mid:
            lo = mid
        else:
            hi = mid
    a = 0.5 * (lo + hi)
    kh, d, _ = state(a)
    r, t = patch_springs(patch, radius, n, a)
    return PatchState(a, d, kh, r, t)


def contact_blocks(
    state: PatchState, patch: ContactPatch
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Stiffness and damping of the tread springs on the ring DOFs.

    Returns
    -------
    k_c, c_c : ndarray, shape (2 n_ring, 2 n_ring)
        Diagonal ``K_c`` (N/m) and ``eta / omega_ref K_c`` (N s/m).
    """
    kc = np.diag(np.concatenate([state.radial_springs, state.tangential_springs]))
    return kc, patch.loss_factor / (2 * np.pi * patch.loss_frequency) * kc


def patch_intrusion(
    state: PatchState, patch: ContactPatch, radius: float, n_ring: int
) -> NDArray[np.float64]:
    """Inward radial displacement (m) of the band flattened on the road, at each node.

    The deflected band follows the road line at distance ``R - d`` from the
    hub: at angle ``phi`` from the patch centre it is ``R - (R - d)/cos phi``
    inside the patch and zero outside (Pacejka 2012, sec. 3.2).

    Returns
    -------
    ndarray, shape (n_ring,)
        Intrusion >= 0 in m.
    """
    th = np.arange(n_ring) * (2 * np.pi / n_ring)
    phi = np.angle(np.exp(1j * (th - math.radians(patch.angle_deg))))
    inside = np.abs(phi) < state.half_length / radius
    depth = radius - (radius - state.deflection) / np.cos(np.where(inside, phi, 0.0))
    return np.where(inside, np.clip(depth, 0.0, None), 0.0)
