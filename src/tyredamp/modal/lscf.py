"""Pole estimation by the (poly-reference) least-squares complex-frequency method.

The FRF rows are modelled by a right matrix-fraction description in a
z-domain basis (Guillaume et al. 2003, Peeters et al. 2004, "PolyMAX")::

    H_o(w) ~ B_o(z) A(z)^{-1},   A(z) = sum_r alpha_r z^r,  B_o(z) = sum_r beta_or z^r

with real matrix coefficients ``alpha_r`` (n_in x n_in) and ``beta_or``
(1 x n_in). The analysis band ``[f_lo, f_hi]`` is normalised onto the upper
unit half-circle, ``z = exp(i pi (f - f_lo) / (f_hi - f_lo))``, which keeps
the basis orthogonal for any band (for ``f_lo = 0`` this is the classical
``z = exp(i w dt)``, ``dt = 1 / (2 f_hi)``).

The numerator coefficients are eliminated per output (reduced normal
equations). With one weight per output the normal-equation blocks are
Toeplitz in the polynomial degree, so they are built from the real parts of
the sums ``sum_f z_f^d H_ok(f)``: two real matrix products over all outputs
and lines, ``O(n_out n_freq order)``. The blocks of every lower order are leading
sub-blocks of the highest order, so a whole stabilisation diagram costs about
as much as one high-order solve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, as_frequency
from ..exceptions import InputError, ShapeError

__all__ = ["PoleSet", "plscf"]

#: from this order on (one input) the roots come from Aberth-Ehrlich sweeps started
#: at the previous order's roots instead of the companion eigenvalues (same roots
#: to ~1e-13; faster for the large orders of many-mode bands)
_ABERTH_MIN_ORDER = 64


@dataclass(frozen=True)
class PoleSet:
    """Poles of a range of model orders (the raw stabilisation data).

    Attributes
    ----------
    order : ndarray of int, shape (n,)
        Model order (polynomial degree) that produced each pole.
    poles : ndarray, complex, shape (n,)
        Poles ``p = -sigma + i Omega`` in rad/s (one of each conjugate pair,
        ``Omega > 0``); unstable poles (``sigma <= 0``) are kept.
    participation : ndarray, complex, shape (n, n_in)
        Modal participation vectors (unit norm, largest entry real positive).
    orders : ndarray of int
        All orders computed, ascending.
    band_hz : tuple of float
        The band ``(f_lo, f_hi)`` the poles were estimated on.
    """

    order: NDArray[np.int64]
    poles: NDArray[np.complex128]
    participation: NDArray[np.complex128]
    orders: NDArray[np.int64]
    band_hz: tuple[float, float]

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Undamped natural frequency ``|p| / 2 pi`` in Hz, shape (n,)."""
        return np.abs(self.poles) / (2 * np.pi)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta = -Re p / |p|``, shape (n,)."""
        return -self.poles.real / np.abs(self.poles)

    def at_order(self, order: int) -> NDArray[np.intp]:
        """Indices of the poles of one model order."""
        return np.flatnonzero(self.order == order)


def plscf(
    frequency: ArrayLike,
    H: ArrayLike,
    max_order: int,
    *,
    min_order: int = 1,
    band: tuple[float, float] | None = None,
    output_weights: ArrayLike | None = None,
    order_step: int = 1,
) -> PoleSet:
    """Estimate poles of all model orders ``min_order..max_order`` by pLSCF.

    Parameters
    ----------
    frequency : array_like, shape (n_freq,)
        Frequency lines in Hz (strictly increasing).
    H : array_like, complex, shape (n_out, n_in, n_freq)
        FRFs of any kind; the rational model absorbs the kind.
    max_order : int
        Highest polynomial degree ``p``; each order yields ``p * n_in`` poles
        (conjugate pairs counted twice).
    min_order : int, optional
        Lowest order computed (default 1).
    band : (float, float), optional
        Band in Hz; default the whole axis. The band is normalised onto the
        upper unit half-circle.
    output_weights : array_like, shape (n_out,), optional
        Weight of each output row; default ``1 / RMS`` of the row, so every
        output counts equally whatever its level.
    order_step : int, optional
        Compute every ``order_step``-th order, counting down from
        ``max_order`` (default 1: every order from ``min_order``).

    Returns
    -------
    PoleSet
        Poles with ``Im p > 0`` (inside the band) of every order.

    Notes
    -----
    With ``alpha_p = I`` imposed, the denominator follows from the reduced
    normal equations ``M = 2 sum_o (T_o - S_o^T R_o^{-1} S_o)``, and the poles
    ``z_n`` and participation vectors ``l_n`` from the companion matrix of
    ``A(z)^T`` (``l_n^T A(z_n) = 0``); ``p_n = i w_lo + ln(z_n) / dt`` with
    ``dt = pi / (w_hi - w_lo)``. The poles are the eigenvalues alone; each
    ``l_n`` is then the null vector of ``A(z_n)^T`` (for one input,
    ``l_n = 1``).

    With more outputs than entries of the lag sums of one output
    (``n_in (2 max_order + 1)``), the sum over outputs is taken over the
    equivalent rows of the sums' Gram matrix instead (same normal
    equations, fewer rows).
    """
    f = as_frequency(frequency)
    h = as_finite(H, "H", dtype=complex)
    if h.ndim != 3 or h.shape[2] != f.size:
        raise ShapeError(f"H: expected shape (n_out, n_in, {f.size}), got {h.shape}")
    p_max = int(max_order)
    p_min = int(min_order)
    if p_max < 1 or p_min < 1 or p_min > p_max:
        raise InputError(f"max_order/min_order: expected 1 <= min <= max, got {p_min}, {p_max}")
    if isinstance(order_step, bool) or not isinstance(order_step, (int, np.integer)):
        raise InputError(f"order_step: expected a positive integer, got {order_step!r}")
    step = int(order_step)
    if step < 1:
        raise InputError(f"order_step: expected a positive integer, got {order_step!r}")
    lo, hi = (float(f[0]), float(f[-1])) if band is None else (float(band[0]), float(band[1]))
    if not hi > lo:
        raise InputError(f"band: expected f_lo < f_hi, got [{lo}, {hi}] Hz")
    sel = (f >= lo) & (f <= hi)
    f, h = f[sel], h[:, :, sel]
    n_out, n_in, n_f = h.shape
    if n_f * 2 <= (p_max + 1) * (n_in + 1):
        raise InputError(
            f"max_order: {p_max} is too high for {n_f} lines in the band "
            f"(need 2 * n_freq > (max_order + 1) * (n_in + 1))"
        )
    if output_weights is None:
        rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2)))
        w = 1.0 / np.where(rms > 0, rms, 1.0)
    else:
        w = as_finite(output_weights, "output_weights", ndim=1)
        if w.size != n_out:
            raise ShapeError(f"output_weights: expected {n_out} values, got {w.size}")
    h = h * w[:, None, None]
    dt = np.pi / (2 * np.pi * (hi - lo))
    theta = 2 * np.pi * (f - lo) * dt  # in [0, pi]
    P = p_max
    ph = np.outer(theta, np.arange(P + 1))
    zc, zs = np.cos(ph), np.sin(ph)  # Re and Im of z^d, d = 0..P, shape (n_f, P+1)
    lag = np.arange(P + 1)[None, :] - np.arange(P + 1)[:, None]  # r' - r
    # R[r, r'] = Re sum_f z^(r'-r)    (common to all outputs)
    R = zc.sum(axis=0)[np.abs(lag)]
    # c_ok(d) = Re sum_f z^d H_ok(f), d = -P..P (index d + P): two real products
    c = _real_lag_sums(h.reshape(n_out * n_in, n_f), zc, zs).reshape(n_out, n_in * (2 * P + 1))
    # sum_o T_o[(r,k),(r',k')] = Re sum_f z^(r'-r) sum_o conj(H_ok) H_ok'
    q = np.einsum("okf,olf->klf", h.conj(), h).reshape(n_in * n_in, n_f)
    t = _real_lag_sums(q, zc, zs).reshape(n_in, n_in, 2 * P + 1)
    T = t[:, :, lag + P].transpose(2, 0, 3, 1).reshape((P + 1) * n_in, (P + 1) * n_in)
    # sum_o S_o^T R^-1 S_o is a quadratic form in the rows c_o: with more outputs
    # than entries of c_o, any rows with the same Gram matrix sum_o c_o c_o^T give
    # the same sum; its scaled eigenvectors are the fewest such rows (exact)
    if n_out > c.shape[1]:
        lam, vec = np.linalg.eigh(c.T @ c)
        keep = lam > lam[-1] * 1e-15
        c = (vec[:, keep] * np.sqrt(lam[keep])).T
    n_v = c.shape[0]
    # S_o[r, (r', k)] = -c_ok(r' - r);  U_o = L^-1 S_o with R = L L^T
    S = -c.reshape(n_v, n_in, 2 * P + 1)[:, :, lag + P]  # (o, k, r, r')
    S = S.transpose(2, 0, 3, 1).reshape(P + 1, n_v * (P + 1) * n_in)
    L = np.linalg.cholesky(R)
    U = sla.solve_triangular(L, S, lower=True, check_finite=False)
    U = U.reshape(P + 1, n_v, (P + 1) * n_in)

    orders = np.arange(P, p_min - 1, -step)[::-1]
    out_order: list[NDArray[np.int64]] = []
    out_poles: list[NDArray[np.complex128]] = []
    out_part: list[NDArray[np.complex128]] = []
    w_lo = 2 * np.pi * lo
    # the reduced matrix of order p uses the leading p + 1 rows of every U_o:
    # sum_o U_o^T U_o accumulates row block by row block up the orders
    acc = np.zeros(((P + 1) * n_in, (P + 1) * n_in))
    r0 = 0
    prev_roots: NDArray[np.complex128] | None = None  # all roots of the previous order
    for p in orders:
        blk = U[r0 : p + 1].reshape(-1, U.shape[2])
        acc += blk.T @ blk
        r0 = p + 1
        nc = (p + 1) * n_in
        M = T[:nc, :nc] - acc[:nc, :nc]
        M = 0.5 * (M + M.T)
        m11 = M[: p * n_in, : p * n_in]
        m12 = M[: p * n_in, p * n_in :]
        try:
            sol = np.linalg.solve(m11, m12)
        except np.linalg.LinAlgError:
            sol = np.linalg.lstsq(m11, m12, rcond=None)[0]
        alpha = np.asarray(-sol, dtype=float)  # (p n_in, n_in): alpha_0..alpha_{p-1}
        zall = None
        if n_in == 1 and p >= _ABERTH_MIN_ORDER and prev_roots is not None:
            zall = _aberth(np.append(alpha[:, 0], 1.0), prev_roots)
        if zall is None:
            zall = np.asarray(np.linalg.eigvals(_companion(alpha, n_in)), dtype=complex)
        prev_roots = zall
        # upper half plane (a real root from the sweeps has |Im| at round-off level)
        zval = zall[zall.imag > 1e-12 * np.abs(zall)]
        if zval.size == 0:
            continue
        pole = np.asarray(1j * w_lo + np.log(zval) / dt, dtype=complex)
        lvec = _participation(alpha, zval, n_in)
        pos = pole.imag > 0
        out_order.append(np.full(int(pos.sum()), p, dtype=np.int64))
        out_poles.append(pole[pos])
        out_part.append(lvec[pos])
    if not out_poles:
        raise InputError("plscf: no pole found in the band at any order")
    return PoleSet(
        order=np.concatenate(out_order),
        poles=np.concatenate(out_poles),
        participation=np.concatenate(out_part),
        orders=orders.astype(np.int64),
        band_hz=(lo, hi),
    )


def _real_lag_sums(
    x: NDArray[np.complex128], zc: NDArray[np.float64], zs: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``Re sum_f z_f^d x(f)`` for ``d = -P..P`` (column ``d + P``), rows of ``x``.

    ``Re(x z^d) = Re x cos - Im x sin`` and ``Re(x z^-d) = Re x cos + Im x sin``:
    two real matrix products instead of two complex ones.
    """
    a = x.real @ zc
    b = x.imag @ zs
    return np.concatenate([(a + b)[:, :0:-1], a - b], axis=1)


def _aberth(
    c: NDArray[np.float64], guess: NDArray[np.complex128], max_iter: int = 50
) -> NDArray[np.complex128] | None:
    """All roots of ``sum_k c_k z^k`` (``c_n = 1``) by Aberth-Ehrlich iteration.

    ``guess`` holds the roots of the previous order of the stabilisation
    diagram, which are close to most roots of this one; the missing starting
    values (one per added degree) are spread asymmetrically so that a pair of
    real roots can form. Each root is updated by ``w_k = N_k / (1 - N_k sum_j
    1 / (z_k - z_j))`` with the Newton correction ``N_k = P(z_k) / P'(z_k)``
    (evaluated through the reversed polynomial for ``|z_k| > 1``) until
    ``|w_k| <= 1e-14 |z_k|``, or ``|w_k| <= 1e-9 |z_k|`` and no longer shrinking
    (the attainable accuracy); converged roots leave the active set. Cubic
    convergence from close starting values: a few ``O(n^2)`` sweeps replace
    the ``O(n^3)`` eigenvalues of the companion matrix. Returns ``None`` when
    the iteration does not converge (the caller then uses the eigenvalues).
    """
    n = c.size - 1
    k_new = n - guess.size
    if k_new < 0 or n < 1:
        return None
    extra = (1.4 - 0.3 * np.arange(k_new)) * np.exp(1j * (0.3 + 2.4 * np.arange(k_new)))
    z = np.concatenate([np.asarray(guess, complex), extra])
    dc = c[1:] * np.arange(1, n + 1)  # P'
    cr = c[::-1]  # reversed: u^n P(1/u)
    dcr = cr[1:] * np.arange(1, n + 1)
    act = np.arange(n)
    w_last = np.full(n, np.inf)  # |w| of the previous sweep, per root
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            za = z[act]
            big = np.abs(za) > 1
            u = np.where(big, 1 / za, za)
            ones = np.ones((u.size, 1), complex)
            V = np.cumprod(np.hstack([ones, np.broadcast_to(u[:, None], (u.size, n))]), axis=1)
            fwd = (V @ c) / (V[:, :n] @ dc)
            qv = V @ cr
            rev = za * qv / (n * qv - u * (V[:, :n] @ dcr))
            N = np.where(big, rev, fwd)
            diff = za[:, None] - z[None, :]
            diff[np.arange(act.size), act] = np.inf
            w = N / (1 - N * np.sum(1 / diff, axis=1))
            if not np.all(np.isfinite(w)):
                return None
            z[act] = za - w
            # done: at round-off, or at the attainable accuracy (|w| small and no
            # longer shrinking: the polynomial's own rounding error)
            aw, az = np.abs(w), np.abs(z[act])
            done = (aw <= 1e-14 * az) | ((aw <= 1e-9 * az) & (aw >= 0.5 * w_last[act]))
            w_last[act] = aw
            act = act[~done]
            if act.size == 0:
                return z
    return None


def _companion(alpha: NDArray[np.float64], n_in: int) -> NDArray[np.float64]:
    """Block companion matrix of ``A(z)^T`` (``alpha_p = I``), eigenvalues ``z_n``."""
    n = alpha.shape[0]
    comp = np.zeros((n, n))
    if n > n_in:
        comp[: n - n_in, n_in:] = np.eye(n - n_in)
    comp[n - n_in :, :] = -alpha.reshape(-1, n_in, n_in).transpose(2, 0, 1).reshape(n_in, n)
    return comp


def _participation(
    alpha: NDArray[np.float64], z: NDArray[np.complex128], n_in: int
) -> NDArray[np.complex128]:
    """Participation vectors ``l_n``: ``l_n^T A(z_n) = 0``, unit norm, largest entry real > 0.

    The left null vector of ``A(z_n)`` is the right singular vector of
    ``A(z_n)^T`` of the smallest singular value; ``A`` is evaluated as
    ``z^-p A(z)`` for ``|z| > 1`` so that no power exceeds 1 in modulus.
    """
    if n_in == 1:
        return np.ones((z.size, 1), complex)
    p = alpha.shape[0] // n_in
    coef = np.concatenate([alpha.reshape(p, n_in * n_in), np.eye(n_in).reshape(1, -1)])
    big = np.abs(z) > 1
    u = np.where(big, 1 / z, z)
    pw = u[:, None] ** np.arange(p + 1)[None, :]  # u^r, r = 0..p
    pw = np.where(big[:, None], pw[:, ::-1], pw)  # z^(r - p) = u^(p - r) for |z| > 1
    A = (pw @ coef).reshape(-1, n_in, n_in)
    vh = np.linalg.svd(A.transpose(0, 2, 1))[2]
    lvec = vh[:, -1, :].conj()
    big_i = np.argmax(np.abs(lvec), axis=1)
    ph = lvec[np.arange(lvec.shape[0]), big_i]
    return np.asarray(lvec * (np.abs(ph) / np.where(ph != 0, ph, 1.0))[:, None])
