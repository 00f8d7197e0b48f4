"""Covariance-driven stochastic subspace identification (SSI-cov).

Peeters & De Roeck, "Reference-based stochastic subspace identification for
output-only modal analysis", Mech. Syst. Signal Process. 13(6) (1999) 855-878:
the block Toeplitz matrix of the output correlations (their eq. 16)

    T_{1|i} = [[R_i,      R_{i-1}, ..., R_1],
               [R_{i+1},  R_i,     ..., R_2],
               ...,
               [R_{2i-1}, ...,          R_i]]      shape (i l, i r)

factorises as ``O_i Gamma_i`` (eq. 17); its SVD gives ``O_i = U_1 S_1^{1/2}``
(eq. 18), ``C`` as the first ``l`` rows of ``O_i`` and ``A`` from the shift
structure ``O_i(1:end-l) A = O_i(l+1:end)`` (eq. 19, least squares). The
eigenvalues ``mu`` of ``A`` give the continuous poles ``lambda = ln(mu) f_s``
and the mode shapes ``C Psi`` (eq. 20-21). One SVD serves every model order
(the first ``n`` singular triplets).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .._validate import as_count
from ..exceptions import InputError

__all__ = ["OrderPoles", "ShiftProjection", "block_toeplitz", "poles_at_order", "ssi_cov"]


@dataclass(frozen=True)
class OrderPoles:
    """Poles of every model order of an SSI run.

    Attributes
    ----------
    order : ndarray of int, shape (n_poles,)
        Model order (state dimension) each pole came from.
    poles : ndarray of complex, shape (n_poles,)
        Continuous poles ``-sigma + i omega`` in rad/s, ``Im > 0``.
    shapes : ndarray of complex, shape (n_poles, n_out)
        Mode shape of each pole, unit norm, largest entry real positive.
    orders : ndarray of int
        The orders computed.
    """

    order: NDArray[np.int64]
    poles: NDArray[np.complex128]
    shapes: NDArray[np.complex128]
    orders: NDArray[np.int64]

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Undamped natural frequency ``|lambda| / 2 pi`` (Hz)."""
        return np.abs(self.poles) / (2 * np.pi)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``-Re lambda / |lambda|`` (dimensionless)."""
        return -self.poles.real / np.abs(self.poles)


def block_toeplitz(R: ArrayLike, block_rows: int) -> NDArray[np.float64]:
    """The block Toeplitz matrix ``T_{1|i}`` of Peeters & De Roeck (1999) eq. 16.

    Parameters
    ----------
    R : array_like, shape (n_lags, n_out, n_ref)
        Correlations ``R_0 .. R_{n_lags-1}``; ``n_lags >= 2 i``.
    block_rows : int
        ``i``.

    Returns
    -------
    ndarray, shape (i n_out, i n_ref)
    """
    r = np.asarray(R, dtype=float)
    i = as_count(block_rows, "block_rows", 1)
    if r.shape[0] < 2 * i:
        raise InputError(f"block_rows: {i} needs {2 * i} correlation lags, got {r.shape[0]}")
    _, l_, m = r.shape
    # block (a, b) is R_{i + a - b}: gather all blocks at once, then lay them out
    idx = i + np.arange(i)[:, None] - np.arange(i)[None, :]
    out: NDArray[np.float64] = r[idx].transpose(0, 2, 1, 3).reshape(i * l_, i * m)
    return out


def _normalised(shapes: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """Unit-norm columns, rotated so that the largest entry is real and positive."""
    k = np.argmax(np.abs(shapes), axis=0)
    ref = shapes[k, np.arange(shapes.shape[1])]
    rot = np.where(np.abs(ref) > 0, np.conj(ref) / np.maximum(np.abs(ref), 1e-300), 1.0)
    s = shapes * rot[None, :]
    n = np.linalg.norm(s, axis=0)
    out: NDArray[np.complex128] = s / np.where(n > 0, n, 1.0)[None, :]
    return out


def poles_at_order(
    U: NDArray[np.float64],
    s: NDArray[np.float64],
    n: int,
    n_out: int,
    sample_rate: float,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Poles (``Im > 0``, rad/s) and unit shapes (n_out, m) of model order ``n``.

    ``O = U_1 S_1^{1/2}`` with the first ``n`` singular triplets, ``C = O[:l]``,
    ``A = O_up^+ O_down`` (Peeters & De Roeck 1999, eq. 18-21). For many orders
    :class:`ShiftProjection` gives the same poles at a fraction of the cost.
    """
    O = U[:, :n] * np.sqrt(s[:n])[None, :]
    A = np.asarray(np.linalg.lstsq(O[:-n_out], O[n_out:], rcond=None)[0], dtype=float)
    return _eig_poles(A, O[:n_out], sample_rate)


def _eig_poles(
    A: NDArray[np.float64], C: NDArray[np.float64], sample_rate: float
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Poles ``ln(mu) f_s`` (``Im > 0``) and unit shapes ``C psi`` of the eigenpairs of ``A``."""
    mu, psi = sla.eig(A)
    keep = mu.imag > 0
    mu, psi = mu[keep], psi[:, keep]
    lam = np.log(mu) * sample_rate
    return lam, _normalised(C @ psi)


class ShiftProjection:
    """The shift-structure least squares of SSI solved once for every model order.

    With ``U_up = U[:-l, :n_hi] = Q R`` (economy QR; ``R`` upper triangular),
    the first ``n`` columns factor as ``Q[:, :n] R[:n, :n]``, so the least
    squares ``U_up,n X = U_down,n`` of order ``n`` is ``X_n = R_n^{-1}
    (Q^T U_down)[:n, :n]`` (Golub & Van Loan, Matrix Computations, 4th ed.
    2013, sec. 5.3.3: least squares by QR). The state matrix of Peeters &
    De Roeck (1999) eq. 19 is ``A_n = S_n^{-1/2} X_n S_n^{1/2}``, similar to
    ``X_n``: the same eigenvalues, and eigenvectors ``psi = S_n^{-1/2} psi_X``,
    so the shapes ``C psi = U[:l, :n] psi_X`` (eq. 21) need no scaling. One QR
    and one product serve all orders instead of one least squares each.

    Parameters
    ----------
    U : ndarray, shape (i l, >= n_hi)
        Left singular vectors of the block Toeplitz matrix.
    n_hi : int
        Largest order needed.
    n_out : int
        ``l``.
    """

    def __init__(self, U: NDArray[np.float64], n_hi: int, n_out: int) -> None:
        Un = np.asarray(U, float)[:, :n_hi]
        self._C = Un[:n_out]
        self._U, self._l = Un, int(n_out)
        Q, self._R = np.linalg.qr(Un[:-n_out])
        self._M = Q.T @ Un[n_out:]
        self.n_hi = int(n_hi)

    def poles(
        self, n: int, sample_rate: float
    ) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Poles (``Im > 0``, rad/s) and unit shapes (n_out, m) of order ``n <= n_hi``."""
        R = self._R[:n, :n]
        d = np.abs(np.diag(R))
        if d.size and d.min() <= 1e-12 * d.max():  # rank-deficient: the minimum-norm solution
            up, down = self._U[: -self._l, :n], self._U[self._l :, :n]
            X = np.asarray(np.linalg.lstsq(up, down, rcond=None)[0], float)
        else:
            X = np.asarray(sla.solve_triangular(R, self._M[:n, :n], check_finite=False), float)
        return _eig_poles(X, self._C[:, :n], sample_rate)


def ssi_cov(
    R: ArrayLike,
    sample_rate: float,
    block_rows: int,
    orders: ArrayLike,
) -> tuple[OrderPoles, tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """SSI-cov poles of every model order in ``orders``.

    Parameters
    ----------
    R : array_like, shape (n_lags, n_out, n_ref)
        Output correlations (:func:`tyredamp.oma.correlation.correlations`).
    sample_rate : float
        Hz of the correlations.
    block_rows : int
        ``i``: the Toeplitz matrix has ``i`` block rows; ``i n_ref`` bounds the order.
    orders : sequence of int
        Model orders (state dimensions), each ``<= min(i n_ref, (i - 1) n_out)``.

    Returns
    -------
    OrderPoles
        Poles and shapes of all orders.
    (U, s)
        Left singular vectors and singular values of ``T_{1|i}`` (reused by the
        uncertainty step and by single-order solves).
    """
    r = np.asarray(R, dtype=float)
    i = as_count(block_rows, "block_rows", 2)
    T = block_toeplitz(r, i)
    n_out = r.shape[1]
    o = np.unique(np.asarray(orders, dtype=int))
    n_hi = min(T.shape[1], T.shape[0] - n_out)
    if o.size == 0 or o[0] < 1 or o[-1] > n_hi:
        raise InputError(
            f"orders: expected model orders 1..{n_hi} for {i} block rows of {r.shape[2]} "
            f"reference(s) and {n_out} output(s), got {o.min() if o.size else 'none'}.."
            f"{o.max() if o.size else ''}"
        )
    U, s, _ = np.linalg.svd(T, full_matrices=False)
    U = U[:, : o[-1]]
    s = s[: o[-1]]
    proj = ShiftProjection(U, int(o[-1]), n_out)
    all_o, all_p, all_s = [], [], []
    for n in o:
        lam, sh = proj.poles(int(n), sample_rate)
        all_o.append(np.full(lam.size, n))
        all_p.append(lam)
        all_s.append(sh.T)
    op = OrderPoles(
        np.concatenate(all_o).astype(np.int64),
        np.concatenate(all_p),
        np.concatenate(all_s, axis=0) if all_s else np.zeros((0, n_out), complex),
        o.astype(np.int64),
    )
    return op, (U, s)
