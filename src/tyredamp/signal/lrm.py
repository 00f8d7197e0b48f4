"""Local polynomial and local rational FRF estimation (LPM, LRM) from one record.

Random excitation measured over one record of ``N`` samples, transformed
without a window (``U = DFT(u)``, ``Y = DFT(y)`` on lines ``k``), obeys
exactly (Pintelon, Schoukens et al. 2010, "Estimation of nonparametric noise
and FRF models for multivariable systems", part I, eq. 6)::

    Y(k) = H(k) U(k) + T(k) + V(k)

with ``T`` the leakage (transient) term, a smooth function of frequency, and
``V`` the noise. Around every line ``k`` the lines ``k + r``, ``r`` in a
window of ``2 n + 1`` lines, are fitted by least squares:

* LPM (local polynomial method): ``H(k + r) = H_k + sum_s h_s r^s`` and
  ``T(k + r) = T_k + sum_s t_s r^s`` (``s = 1 .. R``);
* LRM (local rational method, McKelvey and Guérin 2012): numerator and
  transient polynomials over a common denominator
  ``1 + sum_s d_s r^s``, linearised as
  ``Y(k + r) (1 + sum d_s r^s) = (N_k + sum n_s r^s) U + T_k + sum t_s r^s``,
  which follows a resonance inside the window far better than a polynomial.

The estimate is the value at ``r = 0``: ``H(k) = H_k`` (LPM) or ``N_k``
(LRM). The residual of the local fit gives the noise variance
``sigma_V^2 = |e|^2 / (2 n + 1 - n_par)`` and the variance of the estimate
``var(H_k,i) = sigma_V^2 [(K^H K)^-1]_ii`` (``K`` the local regression
matrix). Leakage and the start transient are in ``T`` and so removed; what
remains is the bias of the local model over the window.
"""

from __future__ import annotations

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import InputError, ShapeError

__all__ = ["local_frf"]


def _windows(n_lines: int, half: int) -> NDArray[np.intp]:
    """Line indices (n_lines, 2 half + 1) of each local window, shifted inside at the edges."""
    w = 2 * half + 1
    start = np.clip(np.arange(n_lines) - half, 0, n_lines - w)
    return start[:, None] + np.arange(w)[None, :]


def local_frf(
    inputs: ArrayLike,
    outputs: ArrayLike,
    sample_rate: float,
    *,
    order: int = 2,
    half_width: int | None = None,
    rational: bool = True,
) -> tuple[NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64]]:
    """FRF by the local rational (or polynomial) method from one record.

    Parameters
    ----------
    inputs : array_like, shape (n_in, n_samples)
        Force signals.
    outputs : array_like, shape (n_out, n_samples)
        Response signals (same length).
    sample_rate : float
        Hz.
    order : int
        Degree ``R`` of the local polynomials (>= 0; 2 is usual).
    half_width : int, optional
        ``n``: the window holds ``2 n + 1`` lines. Default: the smallest
        window with at least ``n_par + 4`` lines (4 degrees of freedom for
        the noise), ``n_par`` the number of local parameters.
    rational : bool
        LRM (True) or LPM (False).

    Returns
    -------
    frequency : ndarray, shape (n_freq,)
        DFT lines ``k sample_rate / n_samples``, 0 Hz to Nyquist, in Hz.
    H : ndarray, complex, shape (n_out, n_in, n_freq)
        FRF estimate.
    variance : ndarray, shape (n_out, n_in, n_freq)
        Variance of each estimate (unit of ``H`` squared).
    """
    x = as_finite(inputs, "inputs")
    y = as_finite(outputs, "outputs")
    x = x[None, :] if x.ndim == 1 else x
    y = y[None, :] if y.ndim == 1 else y
    if x.ndim != 2 or y.ndim != 2 or x.shape[1] != y.shape[1]:
        raise ShapeError(
            f"inputs, outputs: expected (n_in, n) and (n_out, n) arrays, got {x.shape} and "
            f"{y.shape}"
        )
    fs = check_positive(sample_rate, "sample_rate")
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or order < 0:
        raise InputError(f"order: expected an integer >= 0, got {order!r}")
    r_ord = int(order)
    n_in, n_out = x.shape[0], y.shape[0]
    n_par = (r_ord + 1) * (n_in + 1) + (r_ord if rational else 0)
    if half_width is None:
        half = int(np.ceil((n_par + 4 - 1) / 2))
    else:
        if isinstance(half_width, bool) or not isinstance(half_width, int | np.integer):
            raise InputError(f"half_width: expected an integer, got {half_width!r}")
        half = int(half_width)
        if 2 * half + 1 <= n_par:
            raise InputError(
                f"half_width: {2 * half + 1} lines cannot fit {n_par} local parameters and "
                f"leave a degree of freedom for the noise; use at least {n_par // 2 + 1}"
            )
    n = x.shape[1]
    n_f = n // 2 + 1
    w = 2 * half + 1
    if n_f < w:
        raise InputError(f"inputs: {n} samples give {n_f} lines, fewer than a window of {w}")
    u_f = scipy.fft.rfft(x, axis=1).T  # (f, in)
    y_f = scipy.fft.rfft(y, axis=1).T  # (f, out)
    idx = _windows(n_f, half)  # (f, w)
    r = (idx - np.arange(n_f)[:, None]).astype(float)  # (f, w)
    powers = r[:, :, None] ** np.arange(r_ord + 1)[None, None, :]  # (f, w, R+1)
    u_w = u_f[idx]  # (f, w, in)
    # columns: H terms (in x R+1, the r^0 ones first), T terms (R+1)
    h_cols = (u_w[:, :, None, :] * powers[:, :, :, None]).reshape(n_f, w, -1)
    base = np.concatenate([h_cols, powers.astype(complex)], axis=2)
    h_out = np.empty((n_out, n_in, n_f), dtype=complex)
    var = np.empty((n_out, n_in, n_f))
    dof = w - n_par
    for j in range(n_out):
        yw = y_f[idx, j]  # (f, w)
        k_mat = base
        if rational:
            k_mat = np.concatenate([base, -yw[:, :, None] * powers[:, :, 1:]], axis=2)
        scale = np.linalg.norm(k_mat, axis=1, keepdims=True)  # column scaling
        scale = np.where(scale > 0, scale, 1.0)
        ks = k_mat / scale
        pinv = np.linalg.pinv(ks)  # (f, p, w)
        theta = np.einsum("fpw,fw->fp", pinv, yw) / scale[:, 0, :]
        resid = yw - np.einsum("fwp,fp->fw", k_mat, theta)
        s2 = np.sum(np.abs(resid) ** 2, axis=1) / dof  # (f,)
        # (K^H K)^-1 diagonal of the unscaled columns = diag(P P^H) / scale^2
        cov_diag = np.sum(np.abs(pinv) ** 2, axis=2) / scale[:, 0, :] ** 2  # (f, p)
        # the r^0 H columns are the first n_in of each (R+1)-block ordered (s, i)
        h_out[j] = theta[:, :n_in].T
        var[j] = (s2[:, None] * cov_diag[:, :n_in]).T
    return np.arange(n_f) * (fs / n), h_out, var
