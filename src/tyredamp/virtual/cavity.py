"""The air cavity of the tyre as a 1-D toroidal acoustic ring coupled to the band.

Model
-----
The air in the torus (mean radius ``R_c``, cross-section ``A(theta)``,
density ``rho``, sound speed ``c``) moves circumferentially; its DOFs are the
volume displacements ``q = A u`` (m^3) at the mid-points of the ring's
staggered grid, where the band's tangential DOFs sit. The band's radial
motion ``w`` changes the cross-section by ``b w`` (``b`` the band width), so
the condensation at node ``i`` is

``s_i = (D q)_i / (R_c A_i) + b w_i / A_i``

(Webster's horn equation for a duct of slowly varying section with a moving
wall: Pierce, *Acoustics*, 3rd ed., 2019, sec. 7.6; the tyre cavity as a
curved duct: Sakata, Morimura & Ide, Tire Sci. Technol. 18 (1990), and
Thompson, J. Sound Vib. 186 (1995)). The energies are

``T = 1/2 sum_j rho q_j'^2 / A_j R_c h`` (kinetic, ``q'`` the time derivative),
``U = 1/2 sum_i rho c^2 A_i s_i^2 R_c h`` (potential),

so ``M``, ``K`` are symmetric and the coupled ring-cavity system stays MCK
(eq. [1]). The acoustic loss is a complex bulk modulus,
``C_a = (eta_a / omega_1) K_a`` with ``omega_1 = c / R_c`` (loss factor
``eta_a`` at the first cavity mode).

Closed forms (uniform ``A``): with ``w = a cos n theta``, ``v = c sin n theta``,
``u = q sin n theta`` the energies per wave number give the 3x3 problem of
:func:`cavity_dispersion`; without the band (``b = 0``) the cavity modes are
``f_n = n c / (2 pi R_c)`` (the torus as a closed tube of length
``2 pi R_c``). A short local area loss ``dA(theta) < 0`` (the flattened
contact patch) splits each double by, to first order (Rayleigh quotient of
the horn equation; derived in :func:`loaded_split_estimate`),

``delta f / f = |int dA dtheta| / (pi A) = 2 dV / V``.

The uniform flux ``q = const`` is a zero-frequency (rigid circulation) mode
of the closed torus; it is removed by restricting ``q`` to the mass-orthogonal
complement of the constant (every other mode is mass-orthogonal to it), so
the cavity adds ``n_ring - 1`` DOFs in mass-normalised coordinates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from .parameters import _check_field

__all__ = [
    "Cavity",
    "CavityBlocks",
    "cavity_blocks",
    "cavity_dispersion",
    "loaded_split_estimate",
]

#: Atmospheric pressure in Pa (inflation pressures are gauge pressures).
P_ATM = 101_325.0


@dataclass(frozen=True)
class Cavity:
    """The air cavity of the tyre (defaults: 295/80R22.5 on a 22.5 in rim).

    Parameters
    ----------
    mean_radius : float
        Mean radius ``R_c`` of the torus in m. Default 0.39: rim radius about
        0.286 m and band inner radius about 0.49 m (spec
        ``tyre-physics-references.md``).
    area : float
        Cross-section ``A`` in m^2. Default 0.045: about 0.20 m high and
        0.27 m wide with rounded corners; the volume ``2 pi R_c A`` is 110 l.
    sound_speed : float
        ``c`` in m/s. Default 343 (air at 20 deg C; ideal gas, so it does not
        change with the inflation pressure).
    density_atm : float
        Air density at atmospheric pressure in kg/m^3. Default 1.204
        (20 deg C); the cavity density is ``rho_atm (1 + p / p_atm)`` for the
        gauge inflation pressure ``p`` (isothermal filling).
    loss_factor : float
        Acoustic loss factor ``eta_a = 1/Q`` at the first mode, >= 0.
        Default 0.015 (Q about 67: tyre-cavity resonances are sharp, with
        damping ratios of 0.5-1 %, i.e. Q 50-100; Thompson 1995; spec
        ``tyre-physics-references.md``).
    """

    mean_radius: float = 0.39
    area: float = 0.045
    sound_speed: float = 343.0
    density_atm: float = 1.204
    loss_factor: float = 0.015

    def __post_init__(self) -> None:
        for name in ("mean_radius", "area", "sound_speed", "density_atm"):
            _check_field(self, name, allow_zero=False)
            object.__setattr__(self, name, float(getattr(self, name)))
        _check_field(self, "loss_factor", allow_zero=True)
        object.__setattr__(self, "loss_factor", float(self.loss_factor))

    def density(self, pressure: float) -> float:
        """Air density in kg/m^3 at the gauge pressure ``pressure`` (Pa)."""
        return self.density_atm * (1.0 + pressure / P_ATM)

    @property
    def first_mode_hz(self) -> float:
        """``c / (2 pi R_c)`` in Hz: the n = 1 mode of the rigid-walled torus."""
        return self.sound_speed / (2 * np.pi * self.mean_radius)


@dataclass(frozen=True)
class CavityBlocks:
    """Matrices of the cavity on ``[w, v, r]`` (ring DOFs then reduced air DOFs).

    Attributes
    ----------
    k_ring, c_ring : ndarray, shape (2 n_ring, 2 n_ring)
        Air stiffness and loss acting on the band (the ``b w`` terms).
    k_cross, c_cross : ndarray, shape (2 n_ring, n_ring - 1)
        Band-air coupling.
    k_air, c_air : ndarray, shape (n_ring - 1, n_ring - 1)
        Air stiffness and loss in the reduced coordinates.
    m_air : ndarray, shape (n_ring - 1, n_ring - 1)
        The identity (mass-normalised reduced coordinates).
    basis : ndarray, shape (n_ring, n_ring - 1)
        ``q = basis @ r``: volume displacements (m^3) at the mid-points.
    """

    k_ring: NDArray[np.float64]
    c_ring: NDArray[np.float64]
    k_cross: NDArray[np.float64]
    c_cross: NDArray[np.float64]
    k_air: NDArray[np.float64]
    c_air: NDArray[np.float64]
    m_air: NDArray[np.float64]
    basis: NDArray[np.float64]


def _reduced_basis(mq: NDArray[np.float64]) -> NDArray[np.float64]:
    """``T`` with ``T^T diag(mq) T = I`` spanning the ``diag(mq)``-complement of the constant."""
    n = mq.size
    s = np.sqrt(mq)
    one = s / np.linalg.norm(s)  # M^(1/2) 1, normalised
    # orthonormal complement of `one` by a Householder reflection
    e = np.zeros(n)
    e[0] = 1.0
    v = one - e if one[0] < 1 else one + e
    hh = np.eye(n) - 2.0 * np.outer(v, v) / float(v @ v)
    t0 = hh[:, 1:]
    return t0 / s[:, None]


def cavity_blocks(
    cavity: Cavity,
    d_op: NDArray[np.float64],
    *,
    pressure: float,
    band_width: float,
    area_change: ArrayLike | None = None,
) -> CavityBlocks:
    """Assemble the cavity matrices of the module docstring.

    Parameters
    ----------
    cavity : Cavity
    d_op : ndarray, shape (n_ring, n_ring)
        Staggered difference ``D`` (mid-points to nodes, per rad) of the ring.
    pressure : float
        Gauge inflation pressure in Pa (sets the air density).
    band_width : float
        Width ``b`` in m over which the band's radial motion changes the
        section.
    area_change : array_like, shape (n_ring,), optional
        Static change of the section at each node in m^2 (<= 0 under the
        contact patch). Default: none.

    Returns
    -------
    CavityBlocks
    """
    n = d_op.shape[0]
    rc, h = cavity.mean_radius, 2 * np.pi / n
    rho = cavity.density(pressure)
    da = np.zeros(n) if area_change is None else as_finite(area_change, "area_change")
    a_node = cavity.area + da
    a_mid = 0.5 * (a_node + np.roll(a_node, -1))  # mid-point j between nodes j, j+1
    mq = rho * rc * h / a_mid
    t = _reduced_basis(mq)
    # s_i A_i = (D q)_i / R_c + b w_i; U = 1/2 rho c^2 R_c h sum (s_i A_i)^2 / A_i
    weight = rho * cavity.sound_speed**2 * rc * h / a_node
    sq = (d_op @ t) / rc  # (n, n-1)
    k_ww = np.diag(weight * band_width**2)
    k_wr = (weight * band_width)[:, None] * sq
    k_rr = sq.T @ (weight[:, None] * sq)
    zero = np.zeros((n, n))
    k_ring = np.block([[k_ww, zero], [zero, zero]])
    k_cross = np.vstack([k_wr, np.zeros((n, n - 1))])
    k_rr = 0.5 * (k_rr + k_rr.T)
    eta = cavity.loss_factor / (cavity.sound_speed / rc)
    return CavityBlocks(
        k_ring=k_ring,
        c_ring=eta * k_ring,
        k_cross=k_cross,
        c_cross=eta * k_cross,
        k_air=k_rr,
        c_air=eta * k_rr,
        m_air=np.eye(n - 1),
        basis=t,
    )


def cavity_dispersion(
    ring_q: NDArray[np.float64],
    s: float,
    *,
    mass_per_length: float,
    radius: float,
    cavity: Cavity,
    pressure: float,
    band_width: float,
) -> NDArray[np.float64]:
    """Frequencies (Hz) of wave number ``n`` of the band coupled to the uniform cavity.

    With ``w = a cos n theta``, ``v = c sin n theta``, ``q = A u = g sin n theta``
    the energies of the ring (``1/2 pi R [a c] Q [a c]^T``, ``Q`` the 2x2
    matrix of :func:`~tyredamp.virtual.ring.ring_dispersion`) and of the
    cavity (module docstring) give, divided by ``pi``,

    ``K = [[R q_aa + rho c^2 b^2 R_c / A, R q_ac, rho c^2 b s / A],
           [R q_ac, R q_cc, 0],
           [rho c^2 b s / A, 0, rho c^2 s^2 / (R_c A)]]``,
    ``M = diag(R rho_A, R rho_A, rho R_c / A)``,

    with ``s = n`` (continuous) or the difference symbol ``s(n)`` (exact for
    the staggered discretisation).

    Parameters
    ----------
    ring_q : ndarray, shape (2, 2)
        ``[[q_aa, q_ac], [q_ac, q_cc]]`` of the ring per unit length, N/m^2.
    s : float
        Wave number or its difference symbol.
    mass_per_length, radius : float
        ``rho A`` (kg/m) and ``R`` (m) of the band.
    cavity : Cavity
    pressure, band_width : float
        Gauge pressure (Pa) and band width ``b`` (m).

    Returns
    -------
    ndarray, shape (3,)
        Ascending frequencies in Hz.
    """
    rc, a = cavity.mean_radius, cavity.area
    rho = cavity.density(pressure)
    rc2 = rho * cavity.sound_speed**2
    k = np.array(
        [
            [radius * ring_q[0, 0] + rc2 * band_width**2 * rc / a, radius * ring_q[0, 1],
             rc2 * band_width * s / a],
            [radius * ring_q[0, 1], radius * ring_q[1, 1], 0.0],
            [rc2 * band_width * s / a, 0.0, rc2 * s**2 / (rc * a)],
        ]
    )  # fmt: skip
    m = np.array([radius * mass_per_length, radius * mass_per_length, rho * rc / a])
    mh = 1.0 / np.sqrt(m)
    w2 = np.linalg.eigvalsh(mh[:, None] * k * mh[None, :])
    return np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)


def loaded_split_estimate(
    cavity: Cavity, area_change: ArrayLike, n: int = 1
) -> tuple[float, float]:
    """First-order split of the cavity double ``n`` by a local section change.

    The Rayleigh quotient of the horn equation in the flux ``q``,
    ``omega^2 = c^2 int (q')^2 / A dtheta / (R_c^2 int q^2 / A dtheta)``, for
    ``q = cos n(theta - theta_0)`` and ``sin n(theta - theta_0)`` with a short
    change ``dA`` at ``theta_0``: the cosine (flux maximum at the patch) gains
    ``-int dA dtheta / A`` in its denominator, the sine loses as much in its
    numerator, so ``omega^2`` moves by ``-+ int dA dtheta / (pi A)``
    relative and the split is ``delta f / f = |int dA dtheta| / (pi A)``
    (``= 2 dV / V``).

    Parameters
    ----------
    cavity : Cavity
    area_change : array_like, shape (n_ring,)
        Section change at equally spaced nodes, m^2 (<= 0).
    n : int
        Wave number.

    Returns
    -------
    f, split : float
        Unperturbed frequency ``n c / (2 pi R_c)`` and the split in Hz.
    """
    da = as_finite(area_change, "area_change")
    h = 2 * np.pi / da.size
    f = n * cavity.first_mode_hz
    return f, f * abs(float(np.sum(da)) * h) / (math.pi * cavity.area)
