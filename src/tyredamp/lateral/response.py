"""Response algebra shared by the lateral models, the vehicle and the virtual rig.

Frequency checks, the force location (ground or axle), attaching a mass to a
mobility, the axle/ground accelerance conversions and the stretched-string
impedance (spec ``lateral-models.md``).

Axle force. The lateral force measured at the wheel axle also accelerates the
wheel (mass ``M_w``): ``Fy_axle = Fy_ground + M_w y''``. With the ground
accelerance ``A_g = y''/Fy_ground`` this gives
``Fy_axle = Fy_ground (1 + M_w A_g)``, hence

    A_axle = y''/Fy_axle = A_g / (1 + M_w A_g)

and, dividing by ``i omega``, the same form for the mobility
``V_axle = V_g / (1 + i omega M_w V_g)`` (:func:`attach_mass`). The same
formula gives the single-degree-of-freedom vehicle of spec eq. 41-42 with the
body mass ``M`` in place of ``M_w`` (:mod:`tyredamp.lateral.vehicle`).
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import InputError

__all__ = [
    "FORCES",
    "ForceKind",
    "as_freq",
    "attach_mass",
    "axle_from_ground_accelerance",
    "ground_from_axle_accelerance",
    "string_impedance",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
ForceKind = Literal["ground", "axle"]
FORCES: tuple[ForceKind, ...] = ("ground", "axle")


def as_freq(freq_hz: ArrayLike, name: str = "freq_hz") -> FloatArray:
    """Return finite, non-negative frequencies in Hz (any shape, scalar kept 0-D)."""
    f = as_finite(freq_hz, name, dtype=float)
    if np.any(f < 0):
        raise InputError(
            f"{name}: expected non-negative frequencies in Hz, got minimum {f.min():g}"
        )
    return f


def _check_force(force: str) -> ForceKind:
    if force not in FORCES:
        raise InputError(f"force: expected 'ground' or 'axle', got {force!r}")
    return force


def attach_mass(mobility: ArrayLike, omega: ArrayLike, mass: float) -> ComplexArray:
    """Mobility seen by a force that also accelerates a rigid mass on the tyre.

    ``V_axle = V_g / (1 + i omega M V_g)``, the mobility form of
    ``A_axle = A_g / (1 + M A_g)`` (module docstring; spec "Validation
    experiment"; also the vehicle of spec eq. 42).

    Parameters
    ----------
    mobility : array_like, complex
        Ground-force mobility ``V_g`` of the tyre in m/(s N).
    omega : array_like, same shape
        Angular frequency in rad/s.
    mass : float
        Mass in kg (>= 0; 0 returns ``mobility`` unchanged).

    Returns
    -------
    ndarray, complex, same shape
        Mobility at the force acting on the mass, m/(s N).
    """
    m = check_positive(mass, "mass", allow_zero=True)
    v = np.asarray(mobility, dtype=complex)
    w = np.asarray(omega, dtype=float)
    return np.asarray(v / (1.0 + 1j * w * m * v), dtype=complex)


def axle_from_ground_accelerance(accelerance: ArrayLike, wheel_mass: float) -> ComplexArray:
    """Axle-force accelerance ``A_g / (1 + M_w A_g)`` from the ground-force accelerance.

    Parameters
    ----------
    accelerance : array_like, complex
        ``y''/Fy_ground`` in m/(s^2 N).
    wheel_mass : float
        Wheel mass ``M_w`` between force transducer and tyre, kg (>= 0).

    Returns
    -------
    ndarray, complex
        ``y''/Fy_axle`` in m/(s^2 N).
    """
    m = check_positive(wheel_mass, "wheel_mass", allow_zero=True)
    a = np.asarray(accelerance, dtype=complex)
    return np.asarray(a / (1.0 + m * a), dtype=complex)


def ground_from_axle_accelerance(accelerance: ArrayLike, wheel_mass: float) -> ComplexArray:
    """Inverse of :func:`axle_from_ground_accelerance`: ``A_g = A_axle / (1 - M_w A_axle)``.

    This is ``Fy_ground = Fy_axle - M_w y''`` (spec, validation experiment)
    applied to the FRF.

    Parameters
    ----------
    accelerance : array_like, complex
        ``y''/Fy_axle`` in m/(s^2 N).
    wheel_mass : float
        Wheel mass in kg (>= 0).

    Returns
    -------
    ndarray, complex
        ``y''/Fy_ground`` in m/(s^2 N).
    """
    m = check_positive(wheel_mass, "wheel_mass", allow_zero=True)
    a = np.asarray(accelerance, dtype=complex)
    den = 1.0 - m * a
    if np.any(den == 0):
        raise InputError("accelerance: 1 - wheel_mass * A_axle is 0 at some line (A_g infinite)")
    return np.asarray(a / den, dtype=complex)


def _receptance_from_mobility(mob: Any, static: float, f: FloatArray) -> ComplexArray:
    w = 2.0 * np.pi * f
    zero = w == 0
    if np.any(zero) and math.isinf(static):
        raise InputError(
            "freq_hz: the receptance of a model with a damper in series is infinite at 0 Hz; "
            "drop the 0 Hz line or use the mobility or accelerance"
        )
    out = np.empty(np.shape(f), dtype=complex)
    wn = w[~zero]
    out[~zero] = mob(wn) / (1j * wn)
    out[zero] = static
    return out


def _phi12(x: ComplexArray) -> tuple[ComplexArray, ComplexArray]:
    """``phi1 = (1 - e^-x)/x`` and ``phi2 = (x - 1 + e^-x)/x^2``, stable near ``x = 0``."""
    x = np.asarray(x, dtype=complex)
    phi1 = np.empty_like(x)
    phi2 = np.empty_like(x)
    small = np.abs(x) < 0.1
    xs = x[small]
    # Series: phi1 = sum (-x)^n/(n+1)!, phi2 = sum (-x)^n/(n+2)!; 12 terms, |x| < 0.1.
    p1 = np.zeros_like(xs)
    p2 = np.zeros_like(xs)
    term = np.ones_like(xs)
    for n in range(12):
        p1 += term / math.factorial(n + 1)
        p2 += term / math.factorial(n + 2)
        term = term * (-xs)
    phi1[small] = p1
    phi2[small] = p2
    xl = x[~small]
    em = np.expm1(-xl)
    phi1[~small] = -em / xl
    phi2[~small] = (xl + em) / xl**2
    return phi1, phi2


def string_impedance(
    omega: FloatArray, c_c: ArrayLike, sigma: ArrayLike, a: float, speed: float
) -> ComplexArray:
    """Mechanical impedance ``Fy/y'`` of Pacejka's stretched string with contact length.

    For pure lateral motion ``y(t)`` of a wheel rolling at speed ``V``, a
    string on a foundation of stiffness ``c_c`` per unit length, relaxation
    length ``sigma`` and contact half-length ``a`` (adhesion everywhere, free
    string outside the contact decaying as ``e^{-|x|/sigma}``):

    * the leading-edge deflection obeys ``u1' + (V/sigma) u1 = y'``;
    * a contact point keeps its ground position, so at ``x`` in the contact
      ``u(x, t) = y(t) - y(t_e) + u1(t_e)``, ``t_e = t - (a - x)/V`` (the delay
      ``e^{-2 s a/V}`` of paper eq. 10);
    * ``Fy = c_c [sigma u1 + int_{-a}^{a} u dx + sigma u2]``.

    With ``s = i omega``, ``g = 1/(1 + s sigma/V)`` and ``x = 2 a s/V`` this
    gives the closed form (finite at ``omega = 0``)::

        Fy/(s y) = (c_c g / V) [2 sigma^2 + 2 a sigma (1 + phi1(x)) + 4 a^2 phi2(x)]

    with ``phi1 = (1 - e^-x)/x`` and ``phi2 = (x - 1 + e^-x)/x^2``. At
    ``omega = 0`` it equals ``C_alpha/V`` with ``C_alpha = 2 c_c (sigma + a)^2``;
    at high frequency ``Fy/y -> 2 c_c (sigma + a)``, the standing lateral
    stiffness (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed., 2012, ch. 5).
    ``a = 0`` gives the first-order relaxation model exactly.

    ``c_c`` and ``sigma`` may be complex arrays of ``omega``'s shape (the
    viscoelastic string of :mod:`tyredamp.virtual.lateral_rig`).

    Parameters
    ----------
    omega : ndarray
        Angular frequency in rad/s (>= 0).
    c_c : float or ndarray
        Foundation stiffness per unit length, N/m^2.
    sigma : float or ndarray
        Relaxation length, m.
    a : float
        Contact half-length, m (>= 0).
    speed : float
        Travel speed, m/s (> 0).

    Returns
    -------
    ndarray, complex
        ``Fy / y'`` in N s/m.
    """
    s = 1j * np.asarray(omega, dtype=float)
    sg = np.asarray(sigma, dtype=complex)
    g = 1.0 / (1.0 + s * sg / speed)
    phi1, phi2 = _phi12(2.0 * a * s / speed)
    bracket = 2.0 * sg**2 + 2.0 * a * sg * (1.0 + phi1) + 4.0 * a**2 * phi2
    return np.asarray(np.asarray(c_c) * g / speed * bracket, dtype=complex)
