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
from .laws import DampingLaw, Exponential, Hysteretic, Viscous

__all__ = ["DampedSystem", "ExactModes", "newton_mode"]

#: Relative step of Newton's method at which a root counts as converged.
_NEWTON_TOL = 1e-10


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

    def modes(self, max_hz: float | None = None) -> ExactModes:
        """The exact modes (module docstring for the method of each law).

        Parameters
        ----------
        max_hz : float, optional
            Only the elastic modes whose undamped frequency is below this (Hz),
            by Newton's method from each undamped mode (any causal law; the
            relaxation modes are then not computed). Default: all modes, by
            the state space where there is one.
        """
        law = self.law
        if isinstance(law, Hysteretic):
            lam, X = sla.eig(self.K + 1j * law.D, self.M)
            p = 1j * np.sqrt(lam.astype(complex))
            modes = self._finish(p, X, np.zeros(0), np.zeros((self.n_dof, 0)))
            keep = modes.frequency_hz <= (np.inf if max_hz is None else max_hz * 1.5)
            return ExactModes(
                modes.poles[keep],
                modes.shapes[:, keep],
                modes.relaxation_poles,
                modes.relaxation_shapes,
                partner="negative",
            )
        if max_hz is None and isinstance(law, Viscous | Exponential):
            return self._state_space_modes()
        if not law.causal:
            raise ShapeError(f"law: no exact eigensolver for the non-causal {type(law).__name__}")
        w2, phi = sla.eigh(self.K, self.M)
        w = np.sqrt(np.clip(w2, 0.0, None))
        if max_hz is not None:
            w, phi = w[w <= 2 * np.pi * max_hz], phi[:, w <= 2 * np.pi * max_hz]
        roots = [
            newton_mode(self, _scalar_start(self, wj, phi[:, j]), phi[:, j])
            for j, wj in enumerate(w)
        ]
        p = np.array([r[0] for r in roots], dtype=complex)
        X = np.zeros((self.n_dof, len(roots)), dtype=complex)
        for j, r in enumerate(roots):
            X[:, j] = r[1]
        return self._finish(p, X, np.zeros(0), np.zeros((self.n_dof, 0)))

    def state_matrix(self) -> NDArray[np.float64]:
        """First-order matrix ``A`` of the (augmented) state ``[x, v, z_1 .. z_K]``.

        ``x' = v``, ``M v' = -K x - C v - sum_k C_k z_k + f``,
        ``z_k' = mu_k (v - z_k)`` (Wagner & Adhikari 2003, eq. (13)); the force
        enters ``v'`` through ``M^-1``. Viscous and exponential laws only.
        """
        n = self.n_dof
        law = self.law
        if isinstance(law, Viscous):
            C0, Cs, mus = law.C, np.zeros((0, n, n)), np.zeros(0)
        elif isinstance(law, Exponential):
            C0, Cs, mus = np.zeros((n, n)), law.C, law.mu
        else:
            raise ShapeError(
                f"law: the {law.name} law has no finite state space (viscous or exponential only)"
            )
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
        return A

    def time_response(self, force: ArrayLike, dt: float) -> NDArray[np.float64]:
        """Displacements under ``force`` from rest, exact for a force held over each step.

        Parameters
        ----------
        force : array_like, shape (n_t, n)
            Force at each degree of freedom, N, held constant over each step
            (zero-order hold).
        dt : float
            Time step, s.

        Returns
        -------
        ndarray, shape (n_t, n)
            Displacement at the start of each step, m.

        Notes
        -----
        The state space is discretised exactly, ``Phi = e^{A dt}`` and
        ``Gamma = int_0^dt e^{A t} dt B`` from the block matrix exponential
        (Van Loan, IEEE Trans. Autom. Control 23(3) (1978) 395-404, eq. (1.3)).
        The hysteretic law has no time response (not causal; frequency domain only).
        """
        A = self.state_matrix()
        n, N = self.n_dof, A.shape[0]
        f = np.asarray(force, dtype=float)
        if f.ndim != 2 or f.shape[1] != n:
            raise ShapeError(f"force: expected shape (n_t, {n}), got {f.shape}")
        B = np.zeros((N, n))
        B[n : 2 * n] = np.linalg.inv(self.M)
        big = np.zeros((N + n, N + n))
        big[:N, :N] = A * dt
        big[:N, N:] = B * dt
        E = sla.expm(big)
        Phi, Gam = E[:N, :N], E[:N, N:]
        q = np.zeros(N)
        out = np.empty_like(f)
        for i in range(f.shape[0]):
            out[i] = q[:n]
            q = Phi @ q + Gam @ f[i]
        return out

    def _state_space_modes(self) -> ExactModes:
        """Eigenvalues of the augmented state space (Wagner & Adhikari 2003, eq. (13))."""
        n = self.n_dof
        A = self.state_matrix()
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


def _scalar_start(system: DampedSystem, w: float, phi: NDArray[np.float64]) -> complex:
    """Root of the one-mode equation ``s^2 + w^2 + phi^T Z(s) phi = 0`` near ``i w`` (Newton).

    ``phi`` is mass-normalised; this projected root is the start of the full
    Newton iteration (it holds the damping's first-order shift of the pole).
    """
    s = complex(1j * max(w, 1e-6))
    for _ in range(50):
        f = complex(s * s + w * w + phi @ system.law.term(s) @ phi)
        df = complex(2 * s + phi @ system.law.dterm(s) @ phi)
        step = -f / df
        s += step
        if abs(step) <= 1e-12 * abs(s):
            break
    return s


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
