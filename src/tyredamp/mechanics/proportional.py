"""Proportional damping helpers (spec eq. [2], [14]).

Rayleigh damping ``C = alpha M + beta K`` gives modal damping ratios
``zeta_n = alpha / (2 omega_n) + beta omega_n / 2``; any ``C`` whose modal
matrix ``C' = Phi^T C Phi`` is diagonal is proportional and has real modes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, as_square_symmetric, check_positive
from ..exceptions import InputError, ShapeError
from .system import MCKSystem

__all__ = [
    "modal_damping_matrix",
    "proportional_part",
    "rayleigh_coefficients",
    "rayleigh_damping",
    "rayleigh_damping_ratios",
]


def rayleigh_damping(M: ArrayLike, K: ArrayLike, alpha: float, beta: float) -> NDArray[np.float64]:
    """``C = alpha M + beta K`` (alpha in 1/s, beta in s), shape (n, n)."""
    m = as_square_symmetric(M, "M")
    k = as_square_symmetric(K, "K", n=m.shape[0])
    a = check_positive(alpha, "alpha", allow_zero=True)
    b = check_positive(beta, "beta", allow_zero=True)
    return a * m + b * k


def rayleigh_damping_ratios(alpha: float, beta: float, omega: ArrayLike) -> NDArray[np.float64]:
    """Modal damping ratios ``zeta = alpha/(2 omega) + beta omega / 2`` of Rayleigh damping.

    ``omega`` in rad/s (> 0), any shape.
    """
    w = as_finite(omega, "omega")
    if np.any(w <= 0):
        raise InputError("omega: expected angular frequencies > 0 rad/s")
    return alpha / (2 * w) + beta * w / 2


def rayleigh_coefficients(f1: float, zeta1: float, f2: float, zeta2: float) -> tuple[float, float]:
    """Rayleigh ``(alpha, beta)`` that give ``zeta1`` at ``f1`` and ``zeta2`` at ``f2`` (Hz)."""
    f1 = check_positive(f1, "f1")
    f2 = check_positive(f2, "f2")
    check_positive(zeta1, "zeta1", allow_zero=True)
    check_positive(zeta2, "zeta2", allow_zero=True)
    if f1 == f2:
        raise InputError("f1, f2: expected two different frequencies")
    w1, w2 = 2 * np.pi * f1, 2 * np.pi * f2
    a = np.array([[1 / (2 * w1), w1 / 2], [1 / (2 * w2), w2 / 2]])
    alpha, beta = np.linalg.solve(a, [zeta1, zeta2])
    return float(alpha), float(beta)


def modal_damping_matrix(M: ArrayLike, K: ArrayLike, zeta: ArrayLike) -> NDArray[np.float64]:
    """Proportional ``C`` with given modal damping ratios.

    ``C = M Phi diag(2 zeta_n omega_n) Phi^T M`` with mass-normalised ``Phi``,
    so that ``C' = diag(2 zeta_n omega_n)`` exactly. ``zeta`` has shape (n,)
    (one per mode, ascending frequency) or is a scalar.
    """
    m = as_square_symmetric(M, "M")
    sysm = MCKSystem(m, np.zeros_like(m), K)
    um = sysm.undamped_modes()
    z = (
        np.broadcast_to(as_finite(zeta, "zeta"), um.omega.shape)
        if np.ndim(zeta) == 0
        else (as_finite(zeta, "zeta", ndim=1))
    )
    if z.shape != um.omega.shape:
        raise ShapeError(f"zeta: expected shape {um.omega.shape} (one per mode), got {z.shape}")
    if np.any(z < 0):
        raise InputError("zeta: expected damping ratios >= 0")
    mp = m @ um.phi
    return (mp * (2 * z * um.omega)) @ mp.T


def proportional_part(system: MCKSystem) -> NDArray[np.float64]:
    """The proportional part of ``system.C``: keep only the diagonal of ``C'``.

    ``C_p = M Phi diag(C'_nn) Phi^T M``; ``C - C_p`` is the non-proportional
    part, whose modal matrix has a zero diagonal.
    """
    um = system.undamped_modes()
    cp = system.modal_damping()
    mp = system.M @ um.phi
    return (mp * np.diag(cp)) @ mp.T
