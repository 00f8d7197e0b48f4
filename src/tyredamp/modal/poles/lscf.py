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
and lines, ``O(n_out n_freq order)``, accumulated over blocks of lines of a fixed
memory. The blocks of every lower order are leading
sub-blocks of the highest order, so a whole stabilisation diagram costs about
as much as one high-order solve.

Computation: the table ``z_f^d``, ``d = 0..order``, comes from repeated
products of ``z_f`` (about ``log2 order`` block products; rounding error
growing like ``d 1e-16``, as that of ``cos(d theta)``) instead of a cosine
and sine per entry. The per-output
elimination is one triangular solve (BLAS ``dtrsm``, in place) and a rank
update per order (``dsyrk``); the reduced equations of each order are solved
by Cholesky (``dposv``), with LU and least squares as fallbacks. The roots
of each order are the eigenvalues of the companion matrix (``dgeev``), or,
from ``p n_in = 64`` roots on, Aberth-Ehrlich sweeps started at the previous
order's roots (the same roots to round-off, fewer operations) on the
denominator's polynomial (one input) or on the determinant of the matrix
polynomial (several inputs, its coefficients by FFT interpolation on the unit
circle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from ..._validate import as_band, as_finite, as_frequency
from ...exceptions import InputError, ShapeError
from ...mechanics.modal_sum import pole_quantities
from ..problem.problem import check_uniform

__all__ = ["PoleSet", "plscf"]

#: from this number of roots ``p n_in`` on the roots come from Aberth-Ehrlich sweeps
#: started at the previous order's roots instead of the companion eigenvalues (same
#: roots to ~1e-13; faster for the large orders of many-mode bands); with several
#: inputs on the determinant of the matrix polynomial (:func:`_det_coefficients`)
_ABERTH_MIN_ORDER = 64
#: convergence tolerances of :func:`_aberth` on ``|w| / |z|``, chosen by the
#: shrink ratio ``|w| / |w_last|`` of the correction (edges ``_SHRINK``)
_SHRINK = np.array([1e-3, 0.5, 1e300])
_TOL = np.array([1e-8, 1e-14, 1e-9, 1e-14])


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
        return pole_quantities(self.poles)[0]

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta = -Re p / |p|``, shape (n,)."""
        return pole_quantities(self.poles)[1]

    def at_order(self, order: int) -> NDArray[np.intp]:
        """Indices of the poles of one model order."""
        return np.flatnonzero(self.order == order)


def _order_too_high(p_max: int, n_f: int, n_in: int) -> InputError:
    """The error for an order above what ``n_f`` lines and ``n_in`` inputs allow
    (``2 n_f > (p + 1)(n_in + 1)``), with the highest order they allow."""
    top = math.ceil(2 * n_f / (n_in + 1)) - 2
    return InputError(
        f"max_order (--max-order): {p_max} is too high for the {n_f} lines in the band "
        f"with {n_in} input(s)"
        + (
            f": at most {top}; lower --max-order or widen the band (--band)"
            if top >= 2
            else ": too few lines for a stabilisation diagram; widen the band (--band)"
        )
    )


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
        Frequency lines in Hz (strictly increasing and uniformly spaced in the
        band: the z-domain basis assumes it; a non-uniform axis is refused).
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
    lo, hi = (float(f[0]), float(f[-1])) if band is None else as_band(band)
    sel = (f >= lo) & (f <= hi)
    if not sel.all():  # (no copy when the band holds every line)
        f, h = f[sel], h[:, :, sel]
    check_uniform(f)
    n_out, n_in, n_f = h.shape
    if n_f * 2 <= (p_max + 1) * (n_in + 1):
        raise _order_too_high(p_max, n_f, n_in)
    if output_weights is None:
        ms = np.einsum("okf,okf->o", h.real, h.real) + np.einsum("okf,okf->o", h.imag, h.imag)
        rms = np.sqrt(ms / (n_in * n_f))
        w = 1.0 / np.where(rms > 0, rms, 1.0)
    else:
        w = as_finite(output_weights, "output_weights", ndim=1)
        if w.size != n_out:
            raise ShapeError(f"output_weights: expected {n_out} values, got {w.size}")
    dt = np.pi / (2 * np.pi * (hi - lo))
    P = p_max
    lag = np.arange(P + 1)[None, :] - np.arange(P + 1)[:, None]  # r' - r
    z0, c, t = _lag_sums(f, h, w, lo, dt, P)
    # R[r, r'] = Re sum_f z^(r'-r)    (common to all outputs)
    R = z0[np.abs(lag)]
    c = c.reshape(n_out, n_in * (2 * P + 1))
    t = t.reshape(n_in, n_in, 2 * P + 1)
    T = t[:, :, lag + P].transpose(2, 0, 3, 1).reshape((P + 1) * n_in, (P + 1) * n_in)
    U = _whitened(c, R, P, n_in)

    orders = np.arange(P, p_min - 1, -step)[::-1]
    w_lo = 2 * np.pi * lo
    z_up, l_up = _roots_of_orders(U, T, orders, n_in)
    # the poles of all orders at once
    zv = np.concatenate(z_up)
    if zv.size == 0:
        raise InputError("plscf: no pole found in the band at any order")
    pole = np.asarray(1j * w_lo + np.log(zv) / dt, dtype=complex)
    order = np.repeat(orders.astype(np.int64), [z.size for z in z_up])
    lvec = np.ones((zv.size, 1), complex) if n_in == 1 else np.concatenate(l_up)
    pos = pole.imag > 0
    return PoleSet(
        order=order[pos],
        poles=pole[pos],
        participation=lvec[pos],
        orders=orders.astype(np.int64),
        band_hz=(lo, hi),
    )


def _whitened(
    c: NDArray[np.float64], R: NDArray[np.float64], P: int, n_in: int
) -> NDArray[np.float64]:
    """``U_o = L^-1 S_o`` of every output (``R = L L^T``), shape (P+1, n_v, (P+1) n_in)."""
    # sum_o S_o^T R^-1 S_o is a quadratic form in the rows c_o: with more outputs
    # than entries of c_o, any rows with the same Gram matrix sum_o c_o c_o^T give
    # the same sum; its scaled eigenvectors are the fewest such rows (exact)
    if c.shape[0] > c.shape[1]:
        lam, vec = np.linalg.eigh(c.T @ c)
        keep = lam > lam[-1] * 1e-15
        c = (vec[:, keep] * np.sqrt(lam[keep])).T
    n_v = c.shape[0]
    # S_o[r, (r', k)] = -c_ok(r' - r);  U_o = L^-1 S_o with R = L L^T. Only the
    # products U_o^T U_o are used, so the sign is dropped. All S_o side by side:
    # S[r, (o, r', k)] = c_ok(r' - r), C-ordered (P+1, n_v (P+1) n_in); row r of
    # S_o is the window of c_ok starting at lag -r
    win = np.lib.stride_tricks.sliding_window_view(c.reshape(n_v, n_in, 2 * P + 1), P + 1, axis=2)
    S = np.ascontiguousarray(win[:, :, ::-1, :].transpose(2, 0, 3, 1)).reshape(P + 1, -1)
    L = np.linalg.cholesky(R)
    # U^T = S^T L^-T by BLAS dtrsm (right side) on S^T, an F-ordered view of S:
    # solved in place, no copy of S, and U comes out C-ordered
    U = sla.blas.dtrsm(1.0, L, S.T, side=1, lower=1, trans_a=1, overwrite_b=1).T
    U = U.reshape(P + 1, n_v, (P + 1) * n_in)
    return U


def _roots_of_orders(
    U: NDArray[np.float64], T: NDArray[np.float64], orders: NDArray[np.int64], n_in: int
) -> tuple[list[NDArray[np.complex128]], list[NDArray[np.complex128]]]:
    """Upper-half-plane roots ``z`` of the denominator of every order, and their
    participation vectors (``n_in > 1``), from the reduced normal equations
    (``U`` the whitened numerator blocks, ``T`` the denominator block)."""
    P = int(orders[-1])
    z_up: list[NDArray[np.complex128]] = []  # upper-half-plane roots of each order
    l_up: list[NDArray[np.complex128]] = []  # their participation vectors (n_in > 1)
    # the reduced matrix of order p uses the leading p + 1 rows of every U_o:
    # sum_o U_o^T U_o accumulates row block by row block up the orders (lower
    # triangle only, F-ordered, updated in place by BLAS dsyrk)
    nm = (P + 1) * n_in
    acc = np.zeros((nm, nm), order="F")
    Tf = np.asfortranarray(T)
    r0 = 0
    prev_roots: NDArray[np.complex128] | None = None  # all roots of the previous order
    for p in orders:
        blk = U[r0 : p + 1].reshape(-1, nm)
        acc = sla.blas.dsyrk(1.0, blk.T, beta=1.0, c=acc, trans=0, lower=1, overwrite_c=1)
        r0 = p + 1
        nc = (p + 1) * n_in
        k = p * n_in
        # M = T - acc (symmetric): m11 = M[:k, :k] (lower triangle), m12 = M[:k, k:]
        m11 = Tf[:k, :k] - acc[:k, :k]
        m12 = np.asfortranarray((Tf[k:nc, :k] - acc[k:nc, :k]).T)
        # M is a Schur complement of a Gram matrix (positive semi-definite):
        # Cholesky (LAPACK dposv), or the general solvers (LU, least squares)
        # when round-off left it indefinite or it is singular
        _, sol, info = sla.lapack.dposv(m11, m12, lower=1, overwrite_a=1, overwrite_b=0)
        if info != 0:
            m11 = Tf[:k, :k] - acc[:k, :k]
            m11 = np.tril(m11) + np.tril(m11, -1).T
            try:
                sol = np.linalg.solve(m11, m12)
            except np.linalg.LinAlgError:
                sol = np.linalg.lstsq(m11, m12, rcond=None)[0]
        alpha = np.asarray(-sol, dtype=float)  # (p n_in, n_in): alpha_0..alpha_{p-1}
        zall = None
        if p * n_in >= _ABERTH_MIN_ORDER and prev_roots is not None:
            c = np.append(alpha[:, 0], 1.0) if n_in == 1 else _det_coefficients(alpha, n_in)
            zall = _aberth(c, prev_roots)
        if zall is None:
            zall = _companion_eigvals(alpha, n_in)
        prev_roots = zall
        # upper half plane (a real root from the sweeps has |Im| at round-off level)
        zval = zall[zall.imag > 1e-12 * np.abs(zall)]
        z_up.append(zval)
        if n_in > 1:
            l_up.append(_participation(alpha, zval, n_in))
    return z_up, l_up


#: bytes of one block of the lag sums (:func:`_lag_sums`): per line the power
#: tables hold ``3 (P + 1)`` floats and the weighted data ``2 n_out n_in + 2 n_in^2``,
#: so a block has ``_BLOCK_BYTES / (8 (3 (P + 1) + 2 n_out n_in + 2 n_in^2))`` lines
#: (at least ``_MIN_BLOCK``; 668 at P = 60 with one output and input), whatever
#: the length of the axis
_BLOCK_BYTES = 1_000_000
_MIN_BLOCK = 256


def _lag_sums(
    f: NDArray[np.float64],
    h: NDArray[np.complex128],
    w: NDArray[np.float64],
    lo: float,
    dt: float,
    P: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The sums over lines of the normal equations, accumulated block by block.

    Returns ``Re sum_f z^d`` (d = 0..P), ``c_ok(d) = Re sum_f z^d w_o H_ok(f)``
    (rows ``(o, k)``, columns ``d = -P..P``) and ``Re sum_f z^d q_kk'(f)`` with
    ``q_kk' = sum_o w_o^2 conj(H_ok) H_ok'`` (rows ``(k, k')``). Blocks of
    ``_BLOCK_BYTES`` keep the memory of the power tables independent of the
    number of lines (the sums are the same to rounding).
    """
    n_out, n_in, n_f = h.shape
    z0 = np.zeros(P + 1)
    c = np.zeros((n_out * n_in, 2 * P + 1))
    t = np.zeros((n_in * n_in, 2 * P + 1))
    nb = max(_MIN_BLOCK, _BLOCK_BYTES // (8 * (3 * (P + 1) + 2 * n_out * n_in + 2 * n_in * n_in)))
    for a in range(0, n_f, nb):
        b = min(a + nb, n_f)
        # weighted real and imaginary parts, each contiguous for the matrix products
        h_re = h[:, :, a:b].real * w[:, None, None]
        h_im = h[:, :, a:b].imag * w[:, None, None]
        theta = 2 * np.pi * (f[a:b] - lo) * dt  # in [0, pi]
        zc, zs = _unit_powers(theta, P)  # Re and Im of z^d, d = 0..P, shape (P+1, n)
        z0 += zc.sum(axis=1)
        n = b - a
        # c_ok(d) = Re sum_f z^d H_ok(f), d = -P..P (index d + P): two real products
        c += _real_lag_sums(h_re.reshape(n_out * n_in, n), h_im.reshape(n_out * n_in, n), zc, zs)
        # sum_o T_o[(r,k),(r',k')] = Re sum_f z^(r'-r) q_kk'(f)
        q_re = np.einsum("okf,olf->klf", h_re, h_re) + np.einsum("okf,olf->klf", h_im, h_im)
        q_im = np.einsum("okf,olf->klf", h_re, h_im) - np.einsum("okf,olf->klf", h_im, h_re)
        t += _real_lag_sums(q_re.reshape(n_in * n_in, n), q_im.reshape(n_in * n_in, n), zc, zs)
    return z0, c, t


def _unit_powers(
    theta: NDArray[np.float64], p: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``cos(d theta)`` and ``sin(d theta)`` for ``d = 0..p``, each of shape (p+1, n_f).

    With rows ``0..k`` known, ``z^(k+j) = z^k z^j`` gives rows ``k+1..k+j``
    (``j <= k``) by one complex product per entry (in real arithmetic), so the
    table costs about ``log2 p`` block products instead of ``n_f (p+1)``
    cosines and sines. The rounding error grows about linearly in ``d``
    (``d 1e-16``), as that of ``np.cos(d * theta)`` does through the rounding
    of ``d * theta`` (the two tables differ by up to ``4e-14`` at ``d = 120``).
    """
    zc = np.empty((p + 1, theta.size))
    zs = np.empty((p + 1, theta.size))
    tmp = np.empty((max(p // 2, 1), theta.size))
    zc[0], zs[0] = 1.0, 0.0
    if p >= 1:
        zc[1], zs[1] = np.cos(theta), np.sin(theta)
    k = 1
    while k < p:  # rows 0..k known: rows k+1..k+j = row k times rows 1..j
        j = min(k, p - k)
        a, b = zc[k], zs[k]
        ca, sa, t = zc[1 : j + 1], zs[1 : j + 1], tmp[:j]
        np.multiply(ca, a, out=zc[k + 1 : k + j + 1])
        zc[k + 1 : k + j + 1] -= np.multiply(sa, b, out=t)
        np.multiply(sa, a, out=zs[k + 1 : k + j + 1])
        zs[k + 1 : k + j + 1] += np.multiply(ca, b, out=t)
        k += j
    return zc, zs


def _real_lag_sums(
    xr: NDArray[np.float64],
    xi: NDArray[np.float64],
    zc: NDArray[np.float64],
    zs: NDArray[np.float64],
) -> NDArray[np.float64]:
    """``Re sum_f z_f^d x(f)`` for ``d = -P..P`` (column ``d + P``), rows of ``x = xr + i xi``.

    ``Re(x z^d) = Re x cos - Im x sin`` and ``Re(x z^-d) = Re x cos + Im x sin``:
    two real matrix products instead of two complex ones (``zc``, ``zs``: the
    tables of :func:`_unit_powers`, shape (P+1, n_f)).
    """
    a = xr @ zc.T
    b = xi @ zs.T
    return np.concatenate([(a + b)[:, :0:-1], a - b], axis=1)


def _aberth(
    c: NDArray[np.float64], guess: NDArray[np.complex128], max_iter: int = 50
) -> NDArray[np.complex128] | None:
    """All roots of ``sum_k c_k z^k`` (``c_n = 1``) by Aberth-Ehrlich iteration.

    ``guess`` holds the roots of the previous order of the stabilisation
    diagram, which are close to most roots of this one; the missing starting
    values (one per added degree) are spread asymmetrically so that a pair of
    real roots can form. Each root is updated by ``w_k = N_k / (1 - N_k sum_j
    1 / (z_k - z_j))`` with the Newton correction ``N_k = P(z_k) / P'(z_k)``,
    evaluated in powers of ``u = z_k`` or, for ``|z_k| > 1``, of ``u = 1 / z_k``
    through the reversed polynomial ``q(u) = u^n P(1/u)``
    (``N_k = q(u) / (u (n q(u) - u q'(u)))``), so that no power exceeds 1 in
    modulus. The four polynomials ``P, P', q`` and ``u (n q - u q')`` are
    evaluated together by splitting the degree into blocks of ``b ~ sqrt(n)``:
    ``sum_J u^(bJ) sum_i c_(bJ+i) u^i``, one matrix product with the powers
    ``u^0..u^(b-1)`` and a short sum over the powers of ``u^b``.

    A root leaves the active set when ``|w_k| <= 1e-14 |z_k|`` (round-off), when
    ``|w_k| <= 1e-9 |z_k|`` and ``|w_k|`` no longer shrinks (at least half the
    previous correction: the attainable accuracy), or when ``|w_k| <= 1e-8 |z_k|``
    after a step that shrank the correction at least 1000-fold (the cubic
    convergence then leaves an error far below ``1e-14 |z_k|``; not on the
    first sweep, which has no previous correction). A few ``O(n^2)`` sweeps
    replace the ``O(n^3)`` eigenvalues of the companion matrix. Returns ``None``
    when the iteration does not converge (the caller then uses the eigenvalues).
    """
    n = c.size - 1
    k_new = n - guess.size
    if k_new < 0 or n < 1:
        return None
    extra = (1.4 - 0.3 * np.arange(k_new)) * np.exp(1j * (0.3 + 2.4 * np.arange(k_new)))
    z = np.concatenate([np.asarray(guess, complex), extra])
    b = math.isqrt(n) + 1  # block length, b * b >= n + 1
    nb = -(-(n + 1) // b)  # number of blocks
    k = np.arange(n + 1)
    cr = c[::-1]
    coef = np.zeros((nb * b, 4))  # columns: P, P', q, u (n q - u q'), ascending powers of u
    coef[: n + 1, 0] = c
    coef[:n, 1] = c[1:] * k[1:]
    coef[: n + 1, 2] = cr
    coef[1 : n + 1, 3] = (n - k[:-1]) * cr[:-1]
    # cb[i, (col, J)] = coef[b J + i, col]
    cb = np.ascontiguousarray(
        coef.reshape(nb, b, 4).transpose(1, 2, 0).reshape(b, 4 * nb), dtype=complex
    )
    kb, kn = np.arange(b), np.arange(nb)
    act = np.arange(n)  # active roots
    diag = act * (n + 1)  # flat indices of the pairs (k, k) in the (active, all) differences
    w_last = np.zeros(n)  # |w| of the previous sweep (0: none yet), per active root
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            za = z[act]
            m = za.size
            az = np.abs(za)
            big = az > 1
            u = np.where(big, 1 / za, za)[:, None]
            low = u**kb  # u^i, i < b
            ev = (low @ cb).reshape(m, 4, nb) @ ((low[:, -1:] * u) ** kn)[:, :, None]
            newton = np.where(big, ev[:, 2, 0] / ev[:, 3, 0], ev[:, 0, 0] / ev[:, 1, 0])
            d = np.subtract.outer(za, z)
            d.flat[diag] = np.inf  # no self term
            w = newton / (1 - newton * np.reciprocal(d, out=d).sum(axis=1))
            z[act] = za - w
            aw = np.abs(w)
            if not math.isfinite(aw.sum()):
                return None
            # tolerance on |w| / |z| by the shrink ratio |w| / |w_last|: <= 1e-3
            # (cubic phase) 1e-8, up to 0.5 1e-14, > 0.5 (stalled) 1e-9, and
            # inf or nan (first sweep) 1e-14
            done = aw <= az * _TOL[np.searchsorted(_SHRINK, aw / w_last)]
            if done.all():
                return z
            keep = ~done
            act = act[keep]
            w_last = aw[keep]
            diag = act + n * np.arange(act.size)
    return None


def _companion_eigvals(alpha: NDArray[np.float64], n_in: int) -> NDArray[np.complex128]:
    """Eigenvalues of the block companion matrix of ``A(z)^T`` (all roots ``z_n``).

    LAPACK ``dgeev`` (eigenvalues only) on the transposed matrix: the
    F-ordered view of the C-ordered companion is passed without a copy, and
    for one input it is upper Hessenberg already (a little faster than the
    companion itself). The same eigenvalues as ``np.linalg.eigvals`` of the
    companion to round-off (possibly in another order); that is the fallback
    when the QR iteration does not converge or ``alpha`` is not finite (it
    then raises ``LinAlgError``).
    """
    comp = _companion(alpha, n_in)
    if np.isfinite(alpha).all():
        wr, wi, _, _, info = sla.lapack.dgeev(comp.T, compute_vl=0, compute_vr=0, overwrite_a=1)
        if info == 0:
            return np.asarray(wr + 1j * wi)
    return np.asarray(np.linalg.eigvals(_companion(alpha, n_in)), dtype=complex)


def _det_coefficients(alpha: NDArray[np.float64], n_in: int) -> NDArray[np.float64]:
    """Coefficients ``c_0..c_N`` (ascending, ``c_N = 1``, ``N = p n_in``) of ``det A(z)``,
    ``A(z) = sum_r alpha_r z^r`` with ``alpha_p = I`` (its roots are the eigenvalues of
    the block companion matrix, :func:`_companion_eigvals`).

    Evaluation and interpolation at the ``M >= N + 1`` roots of unity (the product
    of polynomials by the discrete Fourier transform, Aho, Hopcroft & Ullman 1974,
    sec. 7.2): the ``n_in x n_in`` blocks ``A(w^-j) = sum_r alpha_r w^-jr``, ``w =
    exp(2 pi i / M)``, are one FFT over ``r``; their determinants are the values of
    a polynomial of degree ``N < M``, whose coefficients are their inverse FFT
    (exactly, up to round-off of the order of ``1e-16`` times the largest value on
    the unit circle, where the roots that are modes lie).
    """
    p = alpha.shape[0] // n_in
    n = p * n_in
    m = 1 << n.bit_length()  # M > N, a power of 2
    blocks = np.zeros((m, n_in, n_in))
    blocks[:p] = alpha.reshape(p, n_in, n_in)
    blocks[p] = np.eye(n_in)
    det = np.linalg.det(np.fft.fft(blocks, axis=0))
    c = np.fft.ifft(det).real[: n + 1]
    c[n] = 1.0  # monic: alpha_p = I (its round-off dropped)
    return np.asarray(c)


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
