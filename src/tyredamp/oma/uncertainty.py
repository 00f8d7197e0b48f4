"""Standard errors of OMA frequencies and damping ratios: the delete-one-segment jackknife.

The record is cut into ``G`` groups of consecutive blocks
(:class:`~tyredamp.oma.correlation.Correlations`); the identification is
repeated ``G`` times, each time on the correlations without one group, at the
model order of each selected mode, and the pole nearest the full-record one
(frequency and MAC) is taken. The jackknife variance (Efron & Tibshirani, *An
Introduction to the Bootstrap*, Chapman & Hall 1993, eq. 11.5; for blocks of a
stationary series Kuensch, Ann. Statist. 17 (1989) 1217-1241) is

    var(theta) = (G - 1) / G * sum_g (theta_(g) - theta_(.))^2.

This is the simpler alternative to the first-order perturbation of Reynders,
Pintelon & De Roeck (2008); its coverage is checked by Monte Carlo in
``benchmarks/oma_coverage.py``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .correlation import Correlations
from .ssi import ShiftProjection, block_toeplitz

__all__ = ["jackknife_std", "jackknife_variance"]


def jackknife_variance(replicates: NDArray[np.float64]) -> NDArray[np.float64]:
    """Jackknife variance of each column of ``replicates`` (shape (G, m)), eq. 11.5.

    Rows with NaN (a replicate that lost the mode) are left out.
    """
    r = np.asarray(replicates, float)
    out = np.full(r.shape[1], np.nan)
    for j in range(r.shape[1]):
        x = r[:, j][np.isfinite(r[:, j])]
        g = x.size
        if g >= 2:
            out[j] = (g - 1) / g * np.sum((x - x.mean()) ** 2)
    return out


def _match(
    lam: NDArray[np.complex128],
    shapes: NDArray[np.complex128],
    pole: complex,
    shape: NDArray[np.complex128],
) -> int:
    f = np.abs(lam)
    d = np.abs(f - abs(pole)) / abs(pole) + 1 - np.abs(np.conj(shapes.T) @ shape) ** 2
    return int(np.argmin(d)) if d.size else -1


def jackknife_std(
    corr: Correlations,
    block_rows: int,
    orders: list[NDArray[np.int64]],
    poles: list[NDArray[np.complex128]],
    shapes: NDArray[np.complex128],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Jackknife standard errors of the natural frequency (Hz) and damping ratio.

    The estimator replicated is the one of :func:`tyredamp.oma.identify.oma`: the
    mean over a few model orders of the mode's pole at each.

    Parameters
    ----------
    corr : Correlations
        With its group sums.
    block_rows : int
        As in the identification.
    orders : list of ndarray of int
        Per mode, the model orders its estimate averages over.
    poles : list of ndarray of complex
        Per mode, the full-record poles (rad/s) at those orders.
    shapes : ndarray of complex, shape (m, n_out)
        Full-record unit shapes.

    Returns
    -------
    std_f, std_zeta : ndarray, shape (m,)
        NaN where fewer than two replicates kept the mode.
    """
    G = corr.n_groups
    m = len(orders)
    fr = np.full((G, m), np.nan)
    zr = np.full((G, m), np.nan)
    n_out = corr.R.shape[1]
    need = np.unique(np.concatenate(orders)) if m else np.zeros(0, int)
    n_hi = int(need.max()) if m else 0
    for g in range(G):
        T = block_toeplitz(corr.leave_out(g), block_rows)
        U = np.linalg.svd(T, full_matrices=False)[0]
        proj = ShiftProjection(U, n_hi, n_out)
        fs_: list[list[float]] = [[] for _ in range(m)]
        zs_: list[list[float]] = [[] for _ in range(m)]
        for n in need:
            lam, sh = proj.poles(int(n), corr.sample_rate)
            for j in range(m):
                hit = np.flatnonzero(orders[j] == n)
                if hit.size == 0:
                    continue
                p0 = complex(poles[j][hit[0]])
                k = _match(lam, sh, p0, shapes[j])
                if k >= 0 and abs(abs(lam[k]) - abs(p0)) < 0.05 * abs(p0) and lam[k].real < 0:
                    fs_[j].append(abs(lam[k]) / (2 * np.pi))
                    zs_[j].append(-lam[k].real / abs(lam[k]))
        for j in range(m):
            if len(fs_[j]) == orders[j].size:  # the replicate kept the mode at every order
                fr[g, j] = np.mean(fs_[j])
                zr[g, j] = np.mean(zs_[j])
    return np.sqrt(jackknife_variance(fr)), np.sqrt(jackknife_variance(zr))
