"""Small-damping (Rayleigh) approximation of complex modes (spec eq. [12]-[18]).

With time dependence ``e^{i lambda t}`` the damped eigenproblem is
``(-lambda^2 M + i lambda C + K) Psi = 0`` (eq. [12]) and ``p_n = i lambda_n``.
Writing the complex mode in undamped modal coordinates,
``Psi_n = sum_k alpha_k^(n) phi_k`` with ``alpha_n^(n) = 1`` (eq. [13]), the
first-order perturbation gives

* ``lambda_n ~ omega_n + i C'_nn / 2`` (eq. [15]);
* ``alpha_k^(n) ~ i omega_n C'_kn / (omega_n^2 - omega_k^2)`` (eq. [16]);
* improved: ``alpha_k^(n) ~ i lambda_n C'_kn / ((lambda_n - lambda_k)(lambda_n + conj(lambda_k)))``
  (eq. [18]),

with ``C' = Phi^T C Phi`` (eq. [14]). The error of the approximation is
second order in the damping.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError, PhysicsError
from .system import MCKSystem

__all__ = [
    "SmallDampingError",
    "SmallDampingModes",
    "alpha_coefficients",
    "small_damping_error",
    "small_damping_modes",
]

Method = Literal["first", "improved"]


@dataclass(frozen=True)
class SmallDampingModes:
    """Approximate complex modes from the small-damping perturbation.

    Attributes
    ----------
    poles : ndarray, complex, shape (n,)
        ``p_n = i lambda_n = -C'_nn/2 + i omega_n`` (eq. [15]), rad/s.
    alpha : ndarray, complex, shape (n, n)
        ``alpha[k, n] = alpha_k^(n)`` (eq. [16] or [18]); ``alpha[n, n] = 1``.
    Psi : ndarray, complex, shape (n_dof, n)
        Second-order complex modes ``Phi alpha``; ``Re Psi_n = phi_n`` to first
        order (mass-normalised).
    method : {"first", "improved"}
        Which of eq. [16] / [18] was used.
    """

    poles: NDArray[np.complex128]
    alpha: NDArray[np.complex128]
    Psi: NDArray[np.complex128]
    method: Method


def alpha_coefficients(
    omega: NDArray[np.float64],
    c_modal: NDArray[np.float64],
    method: Method = "improved",
) -> NDArray[np.complex128]:
    """Mode-mixing coefficients ``alpha[k, n]`` of eq. [16] (first) or [18] (improved).

    Parameters
    ----------
    omega : ndarray, shape (n,)
        Undamped natural frequencies in rad/s (distinct).
    c_modal : ndarray, shape (n, n)
        Damping in modal coordinates ``C'`` (eq. [14]), in 1/s for
        mass-normalised modes.
    method : {"first", "improved"}
    """
    w = np.asarray(omega, dtype=float)
    cp = np.asarray(c_modal)
    n = w.size
    if cp.shape != (n, n):
        raise InputError(f"c_modal: expected shape ({n}, {n}), got {cp.shape}")
    wn = w[None, :]  # column n
    wk = w[:, None]  # row k
    if method == "first":
        den = wn**2 - wk**2
        num = 1j * wn * cp
    elif method == "improved":
        lam = w + 0.5j * np.diag(cp)  # eq. [15]
        ln = lam[None, :]
        lk = lam[:, None]
        den = (ln - lk) * (ln + np.conj(lk))
        num = 1j * ln * cp
    else:
        raise InputError(f"method: expected 'first' or 'improved', got {method!r}")
    off = ~np.eye(n, dtype=bool)
    if np.any(np.abs(den[off]) == 0):
        raise PhysicsError(
            "alpha_coefficients: repeated natural frequencies make eq. [16]/[18] singular"
        )
    alpha = np.eye(n, dtype=complex)
    alpha[off] = num[off] / den[off]
    return alpha


def small_damping_modes(system: MCKSystem, method: Method = "improved") -> SmallDampingModes:
    """Approximate complex modes of ``system`` by eq. [15] and [16] or [18]."""
    um = system.undamped_modes()
    cp = system.modal_damping()
    poles = -0.5 * np.diag(cp) + 1j * um.omega
    alpha = alpha_coefficients(um.omega, cp, method)
    return SmallDampingModes(poles=poles, alpha=alpha, Psi=um.phi @ alpha, method=method)


@dataclass(frozen=True)
class SmallDampingError:
    """Error of the small-damping approximation against the exact complex modes.

    Attributes
    ----------
    pole_error : ndarray, shape (n,)
        ``|p_approx - p_exact| / |p_exact|`` per mode.
    alpha_error : ndarray, shape (n,)
        ``||alpha_approx^(n) - alpha_exact^(n)||_2`` per mode, with both
        normalised so that ``alpha_n^(n) = 1``.
    alpha_exact : ndarray, complex, shape (n, n)
        The exact mode-mixing coefficients.
    """

    pole_error: NDArray[np.float64]
    alpha_error: NDArray[np.float64]
    alpha_exact: NDArray[np.complex128]


def small_damping_error(system: MCKSystem, method: Method = "improved") -> SmallDampingError:
    """Compare :func:`small_damping_modes` with the exact state-space modes.

    The exact modes are projected on the undamped modes
    (``gamma = Phi^T M Psi``) and scaled so that ``gamma_n^(n) = 1``; they are
    matched to the approximate ones in ascending frequency order.
    """
    approx = small_damping_modes(system, method)
    exact = system.complex_modes()
    phi = system.undamped_modes().phi
    gamma = phi.T @ system.M @ exact.Psi
    diag = np.diag(gamma)
    if np.any(np.abs(diag) < 1e-12 * np.max(np.abs(gamma), axis=0)):
        raise PhysicsError(
            "small_damping_error: an exact mode has no component on its undamped mode; "
            "the damping is too large for the perturbation"
        )
    alpha_exact = gamma / diag[None, :]
    pole_error = np.abs(approx.poles - exact.poles) / np.abs(exact.poles)
    alpha_error = np.linalg.norm(approx.alpha - alpha_exact, axis=0)
    return SmallDampingError(
        pole_error=pole_error, alpha_error=alpha_error, alpha_exact=alpha_exact
    )
