"""Principal combinations of many outputs (for the searches of an identification)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["combine_outputs", "compress_outputs"]


def compress_outputs(
    H: NDArray[np.complex128],
    rank: int,
    seed: int = 0,
    weights: NDArray[np.float64] | None = None,
) -> NDArray[np.complex128]:
    """Principal output combinations of weighted FRFs (for fast pole searches).

    See :func:`_compress` (same arguments) for the method; returns the
    combinations, complex, shape (rank, n_in, n_freq).
    """
    return _compress(H, rank, seed, weights)[0]


def combine_outputs(
    H: NDArray[np.complex128], patterns: NDArray[np.float64], weights: NDArray[np.float64]
) -> NDArray[np.complex128]:
    """Orthonormal combinations of the weighted outputs spanning ``weights * patterns``.

    With the patterns of :func:`_compress` (found with other weights) this
    re-weights a compression without a new range search: the rows
    ``diag(weights) H`` are combined by ``Q``, the orthonormal basis of
    ``diag(weights) patterns`` (one product with the data).

    Parameters
    ----------
    H : ndarray, complex, shape (n_out, n_in, n_freq)
    patterns : ndarray, shape (n_out, rank)
    weights : ndarray, shape (n_out,)

    Returns
    -------
    ndarray, complex, shape (rank, n_in, n_freq)
    """
    n_out, n_in, n_f = H.shape
    q, _ = np.linalg.qr(weights[:, None] * patterns)
    x = H.reshape(n_out, -1)
    c = (q * weights[:, None]).T
    return np.asarray(((c @ x.real) + 1j * (c @ x.imag)).reshape(q.shape[1], n_in, n_f))


def _compress(
    H: NDArray[np.complex128],
    rank: int,
    seed: int = 0,
    weights: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """Principal output combinations of normalised FRFs (for fast pole searches).

    Each output row is multiplied by its weight (default ``1 / RMS`` of the
    row), then the rows are combined by the ``rank`` leading left singular
    vectors of the real matrix ``[Re H, Im H]`` (``n_out x 2 n_in n_freq``),
    found by a randomised range finder with one power iteration (Halko et al.
    2011). A real orthogonal combination of outputs keeps the modal model
    (eq. [10]: the combined rows have combined coefficients), and the leading
    components hold the modes while the dropped ones hold mostly noise, so
    poles fitted to the combinations are close to those fitted to all
    outputs at a fraction of the cost.

    Parameters
    ----------
    H : ndarray, complex, shape (n_out, n_in, n_freq)
    rank : int
        Number of combinations kept (``< n_out``).
    seed : int
        Seed of the random test matrix.
    weights : ndarray, shape (n_out,), optional
        Row weights (e.g. ``1 / sigma`` of a noise estimate); default
        ``1 / RMS``.

    Returns
    -------
    combinations : ndarray, complex, shape (rank, n_in, n_freq)
    patterns : ndarray, shape (n_out, rank)
        The combinations in unweighted outputs (``weights^-1 v``): they span the
        same signal subspace for any other row weighting
        (:func:`combine_outputs`).
    """
    n_out, n_in, n_f = H.shape
    if weights is None:
        rms = np.sqrt(np.mean(np.abs(H) ** 2, axis=(1, 2)))
        wt = 1.0 / np.where(rms > 0, rms, 1.0)
    else:
        wt = np.asarray(weights, float)
    x = H.reshape(n_out, -1)
    xr = np.empty((n_out, 2 * x.shape[1]))
    xr[:, : x.shape[1]] = x.real
    xr[:, x.shape[1] :] = x.imag
    xr *= wt[:, None]
    rng = np.random.default_rng(seed)
    k = min(n_out, rank + 10)
    q0, _ = np.linalg.qr(xr @ rng.normal(size=(xr.shape[1], k)))
    q1, _ = np.linalg.qr(xr @ (xr.T @ q0))
    b = q1.T @ xr  # (k, 2 n_in n_freq): the rows in the found basis
    # left singular vectors of b from its (k x k) Gram matrix, largest first
    _, u = np.linalg.eigh(b @ b.T)
    u = u[:, ::-1][:, :rank]
    c = u.T @ b  # = v^T xr with v = q1 u
    half = x.shape[1]
    comb = np.asarray((c[:, :half] + 1j * c[:, half:]).reshape(rank, n_in, n_f))
    return comb, (q1 @ u) / wt[:, None]
