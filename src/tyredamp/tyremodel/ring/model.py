"""The inextensible flexible ring: natural frequencies, mode amplitudes, modal damping.

The inextensible inflated ring on an elastic foundation (spec
``virtual-tyre.md``; Kung, Soedel & Yang 1986; Pacejka, *Tire and Vehicle
Dynamics*, ch. 9; Gong 1993) has, for wave number ``n >= 1``,

``omega_n^2 = [EI n^2 (n^2-1)^2/R^4 + T0 n^2 (n^2-1)/R^2 + k_r n^2 + k_t]
/ [rho A (1 + n^2)]``                                                    (1)

(the same formula as :func:`tyredamp.virtual.analytic_ring_frequencies`), and
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
parameters are ``EI, T0, k_r, k_t, rho A`` (:class:`ParameterLayout`).

Damping: modal viscous damping of the ring with radial and tangential
foundation dampers ``c_r``, ``c_t`` (N s/m^2), a band loss on the bending
stiffness only (``eta_b K_bend``, ``eta_b = eta / omega_ref`` in s) and a
local radial damper ``c_d`` (N s/m) at the drive point(s), as in the virtual
tyre (:class:`tyredamp.virtual.RingTyreParameters`):

``2 zeta_n omega_n = [c_r n^2 + c_t + eta_b EI n^2 (n^2-1)^2/R^4] (1 - m_a phi_d^2)
/ [rho A (1 + n^2)] + c_d phi_d^2``                                      (3)

The inextensible ring is the limit ``EA -> inf`` of the extensible ring
(:func:`extensible_ring`): a finite membrane stiffness moves a little of
each mode's motion from the radial to the tangential direction, which
eqs. (1)-(3) do not hold; :mod:`~tyredamp.tyremodel.ring.extension` tests
the data for it.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...exceptions import InputError

__all__ = [
    "BAR",
    "FoundationLaw",
    "ParameterLayout",
    "damping_columns",
    "extensible_ring",
    "ring_amplitude",
    "ring_frequency",
]

FoundationLaw = Literal["linear", "constant"]
#: Pa per bar (pressures are in Pa; messages and documents also give bar).
BAR = 1e5


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


def damping_columns(
    n: NDArray[np.float64],
    phi2: NDArray[np.float64],
    ei: float,
    rho_a: float,
    radius: float,
    m_a: float,
    with_cd: bool,
) -> NDArray[np.float64]:
    """Design matrix of eq. (3) for ``2 zeta omega`` in ``c_r, c_t, eta_b (, c_d)``.

    Parameters
    ----------
    n : ndarray, shape (M,)
        Wave numbers of the modes.
    phi2 : ndarray, shape (M,)
        Drive-point ``phi_d^2`` (1/kg) of each mass-normalised mode.
    ei, rho_a : float
        ``EI`` (N m^2) and ``rho A`` (kg/m).
    radius : float
        ``R`` in m.
    m_a : float
        Attachment mass at each drive point in kg.
    with_cd : bool
        Append the column of the local drive-point damper ``c_d``.

    Returns
    -------
    ndarray, shape (M, 3) or (M, 4)
        Columns multiplying ``c_r`` (N s/m^2), ``c_t`` (N s/m^2), ``eta_b`` (s)
        and, with ``with_cd``, ``c_d`` (N s/m); their sum is ``2 zeta omega`` in 1/s.
    """
    n2 = n**2
    s_r = n2 / (1 + n2)
    return share_columns(
        s_r, ei * n2 * (n2 - 1) ** 2 / (radius**4 * (1 + n2)), phi2, rho_a, m_a, with_cd
    )


def share_columns(
    s_r: NDArray[np.float64],
    bend: NDArray[np.float64],
    phi2: NDArray[np.float64],
    rho_a: float,
    m_a: float,
    with_cd: bool,
) -> NDArray[np.float64]:
    """Design matrix of eq. (3) from each mode's radial share and bending stiffness.

    ``2 zeta omega = [c_r s_r + c_t (1 - s_r) + eta_b bend] (1 - m_a phi_d^2) / rho A
    + c_d phi_d^2``: the Rayleigh quotient of the sidewall dashpots and the
    band loss over the ring's kinetic energy ``rho A (a^2 + c^2)`` of the mode
    ``w = a cos n theta``, ``v = c sin n theta`` (radial share
    ``s_r = a^2 / (a^2 + c^2)``). The inextensible ring has ``s_r = n^2/(1 + n^2)``
    and ``bend = EI n^2 (n^2-1)^2 / (R^4 (1 + n^2))``, which is eq. (3).

    Parameters
    ----------
    s_r : ndarray, shape (M,)
        Radial share of each mode's ring kinetic energy (1).
    bend : ndarray, shape (M,)
        Bending stiffness quotient ``EI (n^2 a + n c)^2 / (R^4 (a^2 + c^2))`` in N/m^2.
    phi2 : ndarray, shape (M,)
        Drive-point ``phi_d^2`` (1/kg).
    rho_a, m_a : float
        ``rho A`` (kg/m) and the attachment mass (kg).
    with_cd : bool
        Append the column of ``c_d``.

    Returns
    -------
    ndarray, shape (M, 3) or (M, 4)
        Columns multiplying ``c_r``, ``c_t``, ``eta_b`` (, ``c_d``).
    """
    fac = (1.0 - m_a * phi2) / rho_a
    cols = [s_r * fac, (1.0 - s_r) * fac, bend * fac]
    if with_cd:
        cols.append(phi2)
    return np.column_stack(cols)


def extensible_ring(
    n: ArrayLike,
    *,
    radius: float,
    bending_stiffness: ArrayLike,
    tension: ArrayLike,
    radial_stiffness: ArrayLike,
    tangential_stiffness: ArrayLike,
    compliance: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Flexural branch of the extensible ring: stiffness quotient, radial share, bending quotient.

    The 2x2 energy of ``w = a cos n theta``, ``v = c sin n theta`` (Soedel,
    *Vibrations of Shells and Plates*, 3rd ed., sec. 5.4; spec
    ``virtual-tyre.md``, the ``q_aa, q_ac, q_cc`` of
    :func:`tyredamp.virtual.ring_dispersion`) is ``Q = Q_b + kappa u u^T`` with the
    membrane term ``kappa = (EA + T0)/R^2``, ``u = (1, n)`` and
    ``Q_b = [[EI n^4/R^4 + T0 (n^2-1)/R^2 + k_r, EI n^3/R^4], [., EI n^2/R^4 + k_t]]``.
    In the orthonormal basis ``p = (n, -1)/|u|`` (inextensible motion) and
    ``u/|u|`` the lower eigenvalue ``lambda`` solves
    ``(Q_pp - lambda)(1 + chi (Q_uu - lambda)) = chi Q_pu^2`` with
    ``chi = 1/(kappa |u|^2) = C R^2 / ((1 + C T0)(1 + n^2))``, ``C = 1/EA``
    the membrane compliance; its root that tends to ``Q_pp`` (eq. (1) times
    ``rho A``) as ``C -> 0`` is taken in the cancellation-free form
    ``2 c0 / (b + sqrt(b^2 - 4 chi c0))``. The eigenvector has
    ``t = beta/alpha = -chi Q_pu / (1 + chi (Q_uu - lambda))``.

    Parameters
    ----------
    n : array_like, shape (M,)
        Wave numbers >= 1.
    radius : float
        ``R`` in m.
    bending_stiffness, tension, radial_stiffness, tangential_stiffness : array_like
        ``EI`` (N m^2), ``T0`` (N), ``k_r``, ``k_t`` (N/m^2), broadcast against ``n``.
    compliance : float
        ``C = 1/EA`` in 1/N (0: the inextensible ring).

    Returns
    -------
    lam : ndarray, shape (M,)
        ``rho A omega^2`` in N/m^2.
    s_r : ndarray, shape (M,)
        Radial share ``a^2/(a^2 + c^2) = (n + t)^2 / ((1 + t^2)(1 + n^2))``.
    bend : ndarray, shape (M,)
        ``EI n^2 (n^2 - 1 + 2 n t)^2 / (R^4 (1 + t^2)(1 + n^2))`` in N/m^2 (for eq. (3)).
    """
    s = np.asarray(n, dtype=float)
    r = float(radius)
    ei, t0 = np.asarray(bending_stiffness, float), np.asarray(tension, float)
    qaa = ei * s**4 / r**4 + t0 * (s**2 - 1) / r**2 + np.asarray(radial_stiffness, float)
    qac = ei * s**3 / r**4
    qcc = ei * s**2 / r**4 + np.asarray(tangential_stiffness, float)
    u2 = 1 + s**2
    qpp = (qaa * s**2 - 2 * qac * s + qcc) / u2
    qpu = (s * (qaa - qcc) + qac * (s**2 - 1)) / u2
    quu = (qaa + 2 * qac * s + qcc * s**2) / u2
    chi = float(compliance) * r**2 / ((1 + float(compliance) * t0) * u2)
    b = 1 + chi * (quu + qpp)
    c0 = qpp * (1 + chi * quu) - chi * qpu**2
    lam = 2 * c0 / (b + np.sqrt(np.clip(b**2 - 4 * chi * c0, 0.0, None)))
    t = -chi * qpu / (1 + chi * (quu - lam))
    s_r = (s + t) ** 2 / ((1 + t**2) * u2)
    bend = ei * s**2 * (s**2 - 1 + 2 * s * t) ** 2 / (r**4 * (1 + t**2) * u2)
    return (
        np.asarray(lam, dtype=np.float64),
        np.asarray(s_r, dtype=np.float64),
        np.asarray(bend, dtype=np.float64),
    )


class ParameterLayout:
    """The stiffness/mass parameters of one fit and the pressure laws that combine them.

    One pressure: ``EI, T0, k_r, k_t``; several: ``EI, b, T_c`` and
    ``k_r0, k_rp, k_t0, k_tp`` (``foundation_law="linear"``) or ``k_r, k_t``
    (``"constant"``); ``rhoA`` last when it is fitted (module docstring).

    Parameters
    ----------
    pressures : ndarray
        Test pressure of each observation in Pa (two or more distinct values
        switch on the pressure laws).
    law : {"linear", "constant"}
        Pressure law of ``k_r`` and ``k_t``.
    fit_mass : bool
        Whether ``rho A`` is a parameter.
    """

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
        """``EI, T0(p), k_r(p), k_t(p), rhoA`` at pressures ``p`` (``rhoA`` None: not fitted)."""
        d = dict(zip(self.names, theta, strict=True))
        t0 = d["b"] * p * r + d["T_c"] if self.multi else np.full(p.shape, d["T0"])
        kr = d["k_r0"] + d["k_rp"] * p if "k_r0" in d else np.full(p.shape, d["k_r"])
        kt = d["k_t0"] + d["k_tp"] * p if "k_t0" in d else np.full(p.shape, d["k_t"])
        return d["EI"], t0, kr, kt, d.get("rhoA")
