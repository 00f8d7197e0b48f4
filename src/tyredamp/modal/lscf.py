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
Toeplitz in the polynomial degree, so they are built from the sums
``sum_f z_f^d H_ok(f)``: one real matrix product over all outputs and lines,
``O(n_out n_freq order)``. The blocks of every lower order are leading
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
    ``dt = pi / (w_hi - w_lo)``.
    """
    f = as_frequency(frequency)
    h = as_finite(H, "H", dtype=complex)
    if h.ndim != 3 or h.shape[2] != f.size:
        raise ShapeError(f"H: expected shape (n_out, n_in, {f.size}), got {h.shape}")
    p_max = int(max_order)
    p_min = int(min_order)
    if p_max < 1 or p_min < 1 or p_min > p_max:
        raise InputError(f"max_order/min_order: expected 1 <= min <= max, got {p_min}, {p_max}")
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
    zd = np.exp(1j * np.outer(theta, np.arange(P + 1)))  # (n_f, P+1): z^d, d >= 0

    # R[r, r'] = Re sum_f z^(r'-r)    (common to all outputs)
    rvec = np.real(zd.sum(axis=0))
    dd = np.arange(P + 1)
    lag = dd[None, :] - dd[:, None]  # r' - r
    R = rvec[np.abs(lag)]
    # s_ok(d) = sum_f z^d H_ok(f) for d = -P..P
    hf = h.reshape(n_out * n_in, n_f)
    s_pos = hf @ zd  # d >= 0
    s_neg = hf @ zd.conj()  # d <= 0: z^-d = conj(z^d)
    # S_o[r, (r', k)] = -Re s_ok(r' - r)
    alag = np.abs(lag)
    S = -np.where(lag[None, :, :] >= 0, s_pos.real[:, alag], s_neg.real[:, alag])
    S = S.reshape(n_out, n_in, P + 1, P + 1)  # (o, k, r, r')
    S = S.transpose(0, 2, 3, 1).reshape(n_out, P + 1, (P + 1) * n_in)  # cols r' * n_in + k
    # sum_o T_o[(r,k),(r',k')] = Re sum_f z^(r'-r) sum_o conj(H_ok) H_ok'
    q = np.einsum("okf,olf->klf", h.conj(), h)  # (k, k', f)
    qf = q.reshape(n_in * n_in, n_f)
    t_pos = qf @ zd
    t_neg = qf @ zd.conj()
    T = (
        np.where(lag[None, :, :] >= 0, t_pos.real[:, alag], t_neg.real[:, alag])
        .reshape(n_in, n_in, P + 1, P + 1)
        .transpose(2, 0, 3, 1)
    )
    T = T.reshape((P + 1) * n_in, (P + 1) * n_in)

    # U_o = L^-1 S_o with R = L L^T; leading rows/cols give every lower order
    L = np.linalg.cholesky(R)
    U = sla.solve_triangular(L, S.transpose(1, 0, 2).reshape(P + 1, -1), lower=True)
    U = U.reshape(P + 1, n_out, (P + 1) * n_in)
    # cumulative sum over rows r of sum_o u_or^T u_or
    prow = np.einsum("roa,rob->rab", U, U, optimize=True)
    pcum = np.cumsum(prow, axis=0)

    orders = np.arange(p_min, P + 1)
    out_order: list[NDArray[np.int64]] = []
    out_poles: list[NDArray[np.complex128]] = []
    out_part: list[NDArray[np.complex128]] = []
    w_lo = 2 * np.pi * lo
    for p in orders:
        nc = (p + 1) * n_in
        M = T[:nc, :nc] - pcum[p, :nc, :nc]
        M = 0.5 * (M + M.T)
        m11 = M[: p * n_in, : p * n_in]
        m12 = M[: p * n_in, p * n_in :]
        try:
            alpha = -np.linalg.solve(m11, m12)  # (p n_in, n_in): alpha_0..alpha_{p-1}
        except np.linalg.LinAlgError:
            alpha = -np.linalg.lstsq(m11, m12, rcond=None)[0]
        # companion of A(z)^T: z l_ = ..., last block row -alpha_r^T
        n = p * n_in
        comp = np.zeros((n, n))
        if p > 1:
            comp[: n - n_in, n_in:] = np.eye(n - n_in)
        blocks = alpha.reshape(p, n_in, n_in)
        comp[n - n_in :, :] = -np.concatenate([b.T for b in blocks], axis=1)
        zval, zvec = np.linalg.eig(comp)
        keep = (zval.imag > 0) & (np.abs(zval) > 0)
        zval, zvec = zval[keep], zvec[:, keep]
        if zval.size == 0:
            continue
        pole = 1j * w_lo + np.log(zval) / dt
        lvec = zvec[:n_in, :].T  # first block: participation
        nrm = np.linalg.norm(lvec, axis=1, keepdims=True)
        lvec = lvec / np.where(nrm > 0, nrm, 1.0)
        big = np.argmax(np.abs(lvec), axis=1)
        ph = lvec[np.arange(lvec.shape[0]), big]
        lvec = lvec * (np.abs(ph) / np.where(ph != 0, ph, 1.0))[:, None]
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
