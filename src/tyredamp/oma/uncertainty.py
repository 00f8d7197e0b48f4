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
from .ssi import block_toeplitz, poles_at_order

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
    orders: NDArray[np.int64],
    poles: NDArray[np.complex128],
    shapes: NDArray[np.complex128],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Jackknife standard errors of the natural frequency (Hz) and damping ratio.

    Parameters
    ----------
    corr : Correlations
        With its group sums.
    block_rows : int
        As in the identification.
    orders : ndarray of int, shape (m,)
        Model order each mode was taken at.
    poles : ndarray of complex, shape (m,)
        Full-record poles (rad/s).
    shapes : ndarray of complex, shape (m, n_out)
        Full-record unit shapes.

    Returns
    -------
    std_f, std_zeta : ndarray, shape (m,)
        NaN where fewer than two replicates kept the mode.
    """
    G = corr.n_groups
    m = poles.size
    fr = np.full((G, m), np.nan)
    zr = np.full((G, m), np.nan)
    n_out = corr.R.shape[1]
    n_hi = int(orders.max()) if m else 0
    for g in range(G):
        T = block_toeplitz(corr.leave_out(g), block_rows)
        U, s, _ = np.linalg.svd(T, full_matrices=False)
        for n in np.unique(orders):
            lam, sh = poles_at_order(U[:, :n_hi], s[:n_hi], int(n), n_out, corr.sample_rate)
            for j in np.flatnonzero(orders == n):
                k = _match(lam, sh, complex(poles[j]), shapes[j])
                if k < 0:
                    continue
                ok = abs(abs(lam[k]) - abs(poles[j])) < 0.05 * abs(poles[j])
                if ok and lam[k].real < 0:
                    fr[g, j] = abs(lam[k]) / (2 * np.pi)
                    zr[g, j] = -lam[k].real / abs(lam[k])
    return np.sqrt(jackknife_variance(fr)), np.sqrt(jackknife_variance(zr))
