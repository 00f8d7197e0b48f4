"""Second-order systems with gyroscopic (non-symmetric) damping: state-space modes.

A rotating structure seen from its rotating frame obeys

``M x'' + (C + G) x' + K x = f``

with ``G = -G^T`` the gyroscopic (Coriolis) matrix and ``K`` symmetric
(the rotating ring of Huang & Soedel, J. Sound Vib. 115(2), 1987, 253-274).
``C + G`` is not symmetric, so the symmetric-pencil modes of
:class:`~tyredamp.mechanics.MCKSystem` do not apply; the modes are those of
the first-order form ``z' = A z + B f`` with ``z = [x; x']``,

``A = [[0, I], [-M^-1 K, -M^-1 (C + G)]]``, ``B = [[0], [M^-1]]``

(the companion linearisation of the quadratic eigenproblem; Tisseur &
Meerbergen, SIAM Review 43(2), 2001, 235-286). With
``A V = V diag(p)`` and ``U = V^-1 B``, each mode obeys ``q' = p q + U f``
and ``z = V q``; for a real system the modes come in conjugate pairs, so
``z = 2 Re sum_{Im p > 0} V q``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import PhysicsError, ShapeError

__all__ = ["GyroscopicSystem", "StateModes"]


@dataclass(frozen=True)
class StateModes:
    """The oscillating state-space modes of a real second-order system (``Im p > 0``).

    Attributes
    ----------
    poles : ndarray, complex, shape (m,)
        ``p = -sigma + i omega_d`` in rad/s, ascending in ``omega_d``.
    displacement : ndarray, complex, shape (n_dof, m)
        Displacement part of the right eigenvectors (``x = 2 Re sum q V_x``).
    velocity : ndarray, complex, shape (n_dof, m)
        Velocity part (``p V_x`` for an exact eigenvector).
    input : ndarray, complex, shape (m, n_dof)
        ``U = (V^-1 B)`` for these modes: the modal force of a physical force
        ``f`` is ``U f``.
    """

    poles: NDArray[np.complex128]
    displacement: NDArray[np.complex128]
    velocity: NDArray[np.complex128]
    input: NDArray[np.complex128]

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Damped frequencies ``Im p / 2 pi`` in Hz, shape (m,)."""
        return np.asarray(self.poles.imag / (2 * np.pi), dtype=np.float64)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``-Re p / |p|``, shape (m,)."""
        return np.asarray(-self.poles.real / np.abs(self.poles), dtype=np.float64)


class GyroscopicSystem:
    """``M x'' + D x' + K x = f`` with a general (non-symmetric) damping matrix ``D``.

    Parameters
    ----------
    M : array_like, shape (n, n)
        Mass matrix in kg, symmetric positive definite.
    D : array_like, shape (n, n)
        Velocity matrix ``C + G`` in N s/m: viscous damping plus the
        skew-symmetric gyroscopic part.
    K : array_like, shape (n, n)
        Stiffness matrix in N/m (may include centrifugal softening).

    Raises
    ------
    ShapeError
        Matrices that are not square or not of one size.
    PhysicsError
        A mass matrix that is not positive definite.
    """

    def __init__(self, M: ArrayLike, D: ArrayLike, K: ArrayLike) -> None:
        m = as_finite(M, "M")
        d = as_finite(D, "D")
        k = as_finite(K, "K")
        n = m.shape[0]
        for name, a in (("M", m), ("D", d), ("K", k)):
            if a.shape != (n, n):
                raise ShapeError(f"{name}: expected shape ({n}, {n}), got {a.shape}")
        try:
            np.linalg.cholesky(0.5 * (m + m.T))
        except np.linalg.LinAlgError:
            raise PhysicsError("M: expected a positive definite mass matrix") from None
        self.M, self.D, self.K = m, d, k

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom."""
        return int(self.M.shape[0])

    def state_matrix(self) -> NDArray[np.float64]:
        """``A = [[0, I], [-M^-1 K, -M^-1 D]]``, shape (2n, 2n)."""
        n = self.n_dof
        minv = np.linalg.inv(self.M)
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -minv @ self.K
        a[n:, n:] = -minv @ self.D
        return a

    def state_modes(self) -> StateModes:
        """The modes with ``Im p > 0`` (one of each conjugate pair), ascending in frequency.

        Raises
        ------
        PhysicsError
            A real (overdamped or unstable static) pole, which has no
            conjugate partner: the rotating system has diverged.
        """
        n = self.n_dof
        a = self.state_matrix()
        p, v = np.linalg.eig(a)
        u_all = np.linalg.solve(v, np.vstack([np.zeros((n, n)), np.linalg.inv(self.M)]))
        scale = np.max(np.abs(p))
        real = np.abs(p.imag) <= 1e-9 * scale
        if np.any(real):
            raise PhysicsError(
                f"the system has {int(real.sum())} non-oscillating pole(s) (e.g. "
                f"{p[real][0].real:.3g} 1/s): overdamped or diverged, not a set of vibration modes"
            )
        keep = np.flatnonzero(p.imag > 0)
        keep = keep[np.argsort(p[keep].imag)]
        return StateModes(
            poles=p[keep].astype(np.complex128),
            displacement=v[:n, keep].astype(np.complex128),
            velocity=v[n:, keep].astype(np.complex128),
            input=u_all[keep].astype(np.complex128),
        )
