"""A linear system ``M x'' + (damping law) + K x = f``: exact FRFs and exact modes.

The receptance is ``H(s) = (s^2 M + K + Z(s))^-1`` (A-W part 2, eq. (3)), computed
directly at each frequency. The modes are the roots of ``det D(s) = 0``,
the nonlinear eigenproblem of A-W part 2, eq. (6):

* viscous and exponential laws: the (augmented) first-order state space,
  exact. For ``Z(s) = s sum_k C_k mu_k/(s + mu_k)`` the internal variables
  ``z_k = mu_k/(s + mu_k) v`` (``z_k' = mu_k (v - z_k)``) give the linear
  system of size ``(2 + n_k) n`` of Wagner & Adhikari, AIAA J. 41(5) (2003)
  951-956, eq. (13): its eigenvalues are the elastic modes (conjugate pairs)
  and the non-viscous modes (real, negative);
* hysteretic: the complex linear eigenproblem ``(K + i D) x = lambda M x``,
  ``p = i sqrt(lambda)`` (the partner ``-p`` lies in the right half plane:
  the law is not causal);
* fractional: Newton's method on ``[D(s) x; c^T x - 1] = 0`` (Ruhe, SIAM J.
  Numer. Anal. 10(4) (1973) 674-689, sec. 3) on the principal branch,
  started from each undamped mode; the branch cut on the negative real
  axis carries no poles, so only the elastic modes exist.

Every mode is scaled by its residue, ``x^T D'(p) x = 1`` with
``D'(s) = 2 s M + dZ/ds`` (A-W part 2, eq. (9)): then
``H(s) = sum_j x_j x_j^T/(s - p_j)`` over all roots (and their conjugates),
which is exact for the viscous and exponential laws.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .._validate import as_frequency
from ..exceptions import ConvergenceError, ShapeError
from .laws import DampingLaw, Exponential, Fractional, Hysteretic, Viscous

__all__ = ["DampedSystem", "ExactModes", "newton_mode"]

#: Relative step of Newton's method at which a root counts as converged.
_NEWTON_TOL = 1e-13


@dataclass(frozen=True)
class ExactModes:
    """The exact modes of a damped system (module docstring).

    Attributes
    ----------
    poles : ndarray, complex, shape (m,)
        Elastic poles ``p_j`` (``Im p_j > 0``), rad/s, sorted by ``Im p``.
    shapes : ndarray, complex, shape (n, m)
        Residue-normalised shapes, ``x^T D'(p) x = 1``, so that the residue
        of ``H`` at ``p_j`` is ``x_j x_j^T`` (1/sqrt(kg s^-1)).
    relaxation_poles : ndarray, shape (r,)
        Real negative poles of the non-viscous modes (exponential law), 1/s.
    relaxation_shapes : ndarray, shape (n, r)
        Their residue-normalised shapes (real).
    """

    poles: NDArray[np.complex128]
    shapes: NDArray[np.complex128]
    relaxation_poles: NDArray[np.float64]
    relaxation_shapes: NDArray[np.float64]
    #: The second pole of each pair: ``"conjugate"`` (causal laws) or ``"negative"``
    #: (``-p``, hysteretic: the right half plane).
    partner: str = "conjugate"

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """``|p| / 2 pi``, Hz."""
        return np.abs(self.poles) / (2 * np.pi)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``-Re p / |p|``."""
        return -self.poles.real / np.abs(self.poles)

    def receptance(self, frequency: ArrayLike) -> NDArray[np.complex128]:
        """Modal sum at ``frequency`` (Hz, > 0), shape (n, n, n_f), m/N.

        ``sum_j x x^T/(s - p) + conj(x) conj(x)^T/(s - conj p)`` plus the relaxation
        terms (A-W part 2, eq. (11)); for the hysteretic law the partner pole is
        ``-p`` with residue ``-x x^T``.
        """
        s = 2j * np.pi * as_frequency(frequency, "frequency")
        X = self.shapes
        out = np.einsum("ij,kj,fj->ikf", X, X, 1 / (s[:, None] - self.poles))
        if self.partner == "negative":
            out -= np.einsum("ij,kj,fj->ikf", X, X, 1 / (s[:, None] + self.poles))
        else:
            out += np.einsum(
                "ij,kj,fj->ikf", X.conj(), X.conj(), 1 / (s[:, None] - self.poles.conj())
            )
        R = self.relaxation_shapes
        out += np.einsum("ij,kj,fj->ikf", R, R, 1 / (s[:, None] - self.relaxation_poles))
        return np.asarray(out, dtype=complex)


class DampedSystem:
    """``M x'' + K x + (damping law) = f``; receptance ``(s^2 M + K + Z(s))^-1``.

    Parameters
    ----------
    M, K : array_like, shape (n, n)
        Mass (kg) and stiffness (N/m) matrices, symmetric.
    law : DampingLaw
        The damping (:mod:`tyredamp.dampmodels.laws`) of the same size.
    """

    def __init__(self, M: ArrayLike, K: ArrayLike, law: DampingLaw) -> None:
        m = np.array(M, dtype=float)
        k = np.array(K, dtype=float)
        if m.ndim != 2 or m.shape != k.shape or m.shape[0] != m.shape[1]:
            raise ShapeError(
                f"M, K: expected square matrices of one size, got {m.shape}, {k.shape}"
            )
        if law.n_dof != m.shape[0]:
            raise ShapeError(f"law: expected matrices of size {m.shape[0]}, got {law.n_dof}")
        m.setflags(write=False)
        k.setflags(write=False)
        self.M, self.K, self.law = m, k, law

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom."""
        return int(self.M.shape[0])

    def dynamic_stiffness(self, s: complex) -> NDArray[np.complex128]:
        """``D(s) = s^2 M + K + Z(s)``, N/m."""
        return np.asarray(s * s * self.M + self.K + self.law.term(s), dtype=complex)

    def dstiffness(self, s: complex) -> NDArray[np.complex128]:
        """``D'(s) = 2 s M + dZ/ds``, N s/m."""
        return np.asarray(2 * s * self.M + self.law.dterm(s), dtype=complex)

    def receptance(self, frequency: ArrayLike) -> NDArray[np.complex128]:
        """Exact ``H(i omega) = D(i omega)^-1`` at ``frequency`` (Hz), shape (n, n, n_f), m/N."""
        f = as_frequency(frequency, "frequency")
        out = np.empty((self.n_dof, self.n_dof, f.size), dtype=complex)
        for i, fi in enumerate(f):
            out[:, :, i] = np.linalg.inv(self.dynamic_stiffness(2j * np.pi * fi))
        return out

    def modes(self) -> ExactModes:
        """The exact modes (module docstring for the method of each law)."""
        law = self.law
        if isinstance(law, Viscous | Exponential):
            return self._state_space_modes()
        if isinstance(law, Hysteretic):
            lam, X = sla.eig(self.K + 1j * law.D, self.M)
            p = 1j * np.sqrt(lam.astype(complex))
            modes = self._finish(p, X, np.zeros(0), np.zeros((self.n_dof, 0)))
            return ExactModes(
                modes.poles,
                modes.shapes,
                modes.relaxation_poles,
                modes.relaxation_shapes,
                partner="negative",
            )
        if isinstance(law, Fractional):
            w2, phi = sla.eigh(self.K, self.M)
            roots = [
                newton_mode(self, 1j * np.sqrt(max(w, 0.0)), phi[:, j]) for j, w in enumerate(w2)
            ]
            p = np.array([r[0] for r in roots])
            X = np.column_stack([r[1] for r in roots])
            return self._finish(p, X, np.zeros(0), np.zeros((self.n_dof, 0)))
        raise ShapeError(f"law: no exact eigensolver for {type(law).__name__}")

    def _state_space_modes(self) -> ExactModes:
        """Eigenvalues of the augmented state space (Wagner & Adhikari 2003, eq. (13))."""
        n = self.n_dof
        law = self.law
        if isinstance(law, Viscous):
            C0, Cs, mus = law.C, np.zeros((0, n, n)), np.zeros(0)
        else:
            assert isinstance(law, Exponential)
            C0, Cs, mus = np.zeros((n, n)), law.C, law.mu
        nk = mus.size
        Minv = np.linalg.inv(self.M)
        A = np.zeros(((2 + nk) * n, (2 + nk) * n))
        A[:n, n : 2 * n] = np.eye(n)
        A[n : 2 * n, :n] = -Minv @ self.K
        A[n : 2 * n, n : 2 * n] = -Minv @ C0
        for k in range(nk):
            rows = slice((2 + k) * n, (3 + k) * n)
            A[n : 2 * n, rows] = -Minv @ Cs[k]
            A[rows, n : 2 * n] = mus[k] * np.eye(n)
            A[rows, rows] = -mus[k] * np.eye(n)
        lam, V = np.linalg.eig(A)
        X = V[:n]
        keep = np.linalg.norm(X, axis=0) > 1e-9 * np.linalg.norm(V, axis=0)
        lam, X = lam[keep], X[:, keep]
        scale = np.max(np.abs(lam)) if lam.size else 1.0
        real = np.abs(lam.imag) <= 1e-10 * scale
        osc = lam.imag > 1e-10 * scale
        rp = lam[real].real
        R = self._normalise(lam[real], X[:, real]).real
        order = np.argsort(rp)[::-1]
        return self._finish(lam[osc], X[:, osc], rp[order], R[:, order])

    def _normalise(
        self, p: NDArray[np.complex128], X: NDArray[np.complex128]
    ) -> NDArray[np.complex128]:
        out = np.empty_like(X, dtype=complex)
        for j in range(p.size):
            x = X[:, j]
            out[:, j] = x / np.sqrt(x @ self.dstiffness(p[j]) @ x)
        return out

    def _finish(
        self,
        p: NDArray[np.complex128],
        X: NDArray[np.complex128],
        rp: NDArray[np.float64],
        R: NDArray[np.float64],
    ) -> ExactModes:
        order = np.argsort(p.imag)
        p, X = p[order], self._normalise(p[order], X[:, order])
        # sign: largest real entry positive (the square root leaves it open)
        idx = np.argmax(np.abs(X.real), axis=0)
        X = X * np.sign(X.real[idx, np.arange(X.shape[1])] + 1e-300)
        return ExactModes(
            p.astype(complex), X, np.asarray(rp, dtype=float), np.asarray(R, dtype=float)
        )


def newton_mode(
    system: DampedSystem, s0: complex, x0: ArrayLike, max_iter: int = 100
) -> tuple[complex, NDArray[np.complex128]]:
    """A root of ``D(s) x = 0`` by Newton's method (Ruhe 1973, sec. 3).

    Solves ``[D(s) x; c^T x - 1] = 0`` for ``(x, s)`` with ``c = x0``, from
    ``(x0, s0)``; the Jacobian is ``[[D(s), D'(s) x], [c^T, 0]]``.

    Parameters
    ----------
    system : DampedSystem
    s0 : complex
        Starting pole, rad/s (e.g. ``i omega_n`` of the undamped mode).
    x0 : array_like, shape (n,)
        Starting shape (e.g. the undamped mode).
    max_iter : int
        Iteration limit.

    Returns
    -------
    s : complex
        The root, rad/s.
    x : ndarray, complex, shape (n,)
        Its null vector with ``x0^T x = 1``.

    Raises
    ------
    ConvergenceError
        When the iteration does not converge.
    """
    c = np.asarray(x0, dtype=complex)
    x = c / (c @ c)
    s = complex(s0)
    n = c.size
    J = np.zeros((n + 1, n + 1), dtype=complex)
    for _ in range(max_iter):
        D = system.dynamic_stiffness(s)
        F = np.concatenate([D @ x, [c @ x - 1]])
        J[:n, :n] = D
        J[:n, n] = system.dstiffness(s) @ x
        J[n, :n] = c
        J[n, n] = 0
        step = np.linalg.solve(J, -F)
        x = x + step[:n]
        s = s + step[n]
        if abs(step[n]) <= _NEWTON_TOL * max(abs(s), 1.0):
            return s, x
    raise ConvergenceError(
        f"the mode near {abs(s0) / (2 * np.pi):.4g} Hz did not converge in {max_iter} Newton steps"
    )
