"""Variance of a cyclic (periodic-excitation) FRF from the period-to-period noise.

With a periodic excitation in steady state the force and the responses repeat
from period to period except for their noise, so the spread of the spectra
``Z_k = [X_k; Y_k]`` of the ``n`` periods measures the noise of the input
*and* of the outputs (errors in variables) directly. The sample noise
covariance of each line (Pintelon and Schoukens, *System Identification: A
Frequency Domain Approach*, 2nd ed. 2012, sec. 2.5, the sample means and
(co)variances of periodic data)::

    C = (sum_k Z_k Z_k^H - n Zbar Zbar^H) / (n - 1)

has ``n - 1`` complex degrees of freedom per line. The FRF ``H = Ybar / Xbar``
then has, to first order, the variance (ibid. sec. 2.5, the variance of the
FRF estimated from the sample means)::

    var(H_j) = (C_yy,j + |H_j|^2 C_xx - 2 Re(conj(H_j) C_yx,j)) / (n |Xbar|^2)

(``C_xx`` the force noise, ``C_yy,j`` that of output ``j``, ``C_yx,j`` their
cross term): the error ``(dY_j - H_j dX) / Xbar`` of the first-order
expansion, whatever channel the noise is on. With two to a few periods ``n -
1`` degrees of freedom make a variance too uncertain to weight a fit by (the
inverse of a ``chi^2_2`` has no finite mean; Schoukens, Pintelon, Vandersteen
and Guillaume, "Frequency-domain system identification using non-parametric
noise models estimated from a small number of data sets", *Automatica* 33(6),
1997, need ``n >= 4`` for it). Measurement noise has spectra that change
little from one line to the next, so the noise covariance ``C`` (not the
variance of ``H``, which follows ``|H|^2`` across a resonance) is averaged over
``L`` neighbouring lines, ``L`` the smallest odd count that gives
:data:`TARGET_DOF` real degrees of freedom, ``2 (n - 1) L`` (the periods'
white-noise lines are independent under the rectangular window of cyclic
averaging). From 11 periods on ``L = 1``: the variance of every line is its own.

Limitation: force fluctuations that *excite* the structure (shaker noise
measured by the force transducer) are no error of ``H`` (``dY = H dX``), and
line by line the formula gives them no variance; averaged over ``L`` lines
across a sharp resonance, where ``H`` changes within the window, they leave
``|H(f') - H(f)|^2`` of them: the variance is then too large (conservative)
near the resonance. Measurement noise on either channel, the usual case and
the virtual rigs', is what the averaging assumes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.fft
from numpy.typing import NDArray

__all__ = [
    "TARGET_DOF",
    "cyclic_frf_variance",
    "cyclic_input_noise",
    "cyclic_variance_on_lines",
    "mean_spectra",
    "smoothing_lines",
]

#: real degrees of freedom the line-averaged noise covariance aims at (the
#: ratio of a squared error to such a variance has mean ``d / (d - 2)`` = 1.11)
TARGET_DOF = 20.0


def smoothing_lines(n_periods: int, n_lines: int) -> int:
    """Lines ``L`` over which the noise covariance is averaged (module docstring).

    The smallest odd ``L`` with ``2 (n_periods - 1) L >= TARGET_DOF``, at most
    ``n_lines`` (then the largest odd count not above it).
    """
    need = math.ceil(TARGET_DOF / (2.0 * (n_periods - 1)))
    odd = need + (1 - need % 2)
    if odd > n_lines:
        odd = n_lines if n_lines % 2 else n_lines - 1
    return max(int(odd), 1)


def mean_spectra(
    x: NDArray[Any],
    y: NDArray[Any],
    starts: NDArray[np.intp],
    w: NDArray[np.float64],
    w_in: NDArray[np.float64],
    detrend: bool,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Spectra of the mean period of the inputs and the outputs.

    Parameters
    ----------
    x, y : ndarray, shape (n_in, n_samples), (n_out, n_samples)
        Input and output signals (their SI units).
    starts : ndarray of int, shape (n,)
        First sample of every period.
    w, w_in : ndarray, shape (seg,)
        Window on the outputs and the (full) window on the inputs, as
        :func:`~tyredamp.signal.segmenting.segment_windows` returns them.
    detrend : bool
        Remove each period's mean first.

    Returns
    -------
    xbar, ybar : ndarray, complex, shape (seg // 2 + 1, n_in), (seg // 2 + 1, n_out)
        ``rfft`` of the mean windowed period (unscaled): the mean of the
        periods' spectra, since the transform is linear.
    """
    seg = w.size
    xs = np.zeros((x.shape[0], seg))
    ys = np.zeros((y.shape[0], seg))
    for s in starts:
        xs += x[:, s : s + seg]
        ys += y[:, s : s + seg]
    xs /= starts.size
    ys /= starts.size
    if detrend:
        xs -= xs.mean(axis=-1, keepdims=True)
        ys -= ys.mean(axis=-1, keepdims=True)
    xbar = scipy.fft.rfft(xs * w_in, axis=-1).T
    ybar = scipy.fft.rfft(ys * w, axis=-1).T
    return np.asarray(xbar, dtype=complex), np.asarray(ybar, dtype=complex)


def cyclic_frf_variance(
    gxx: NDArray[np.float64],
    gyx: NDArray[np.complex128],
    gyy: NDArray[np.float64],
    zbar: tuple[NDArray[np.complex128], NDArray[np.complex128]],
    line_scale: NDArray[np.float64],
    h: NDArray[np.complex128],
    n_periods: int,
) -> tuple[NDArray[np.float64], float] | None:
    """Errors-in-variables variance of a one-input cyclic FRF (module docstring).

    Parameters
    ----------
    gxx : ndarray, shape (n_freq,)
        Input auto spectrum ``c mean_k |X_k|^2`` on the kept lines.
    gyx : ndarray, complex, shape (n_freq, n_out)
        Cross spectra ``c mean_k Y_k conj(X_k)``.
    gyy : ndarray, shape (n_freq, n_out)
        Output auto spectra ``c mean_k |Y_k|^2``.
    zbar : (ndarray, ndarray), complex, shapes (n_freq,), (n_freq, n_out)
        Mean spectra ``Xbar``, ``Ybar`` of the periods on the same lines
        (unscaled, as :func:`mean_spectra`).
    line_scale : ndarray, shape (n_freq,)
        Density scale ``c`` of each line (``G = c mean_k Z_k Z_k^H``).
    h : ndarray, complex, shape (n_out, 1, n_freq)
        The FRF estimate, output unit per input unit.
    n_periods : int
        Number of periods ``n`` averaged.

    Returns
    -------
    (ndarray, float) or None
        Variance of each line, shape (n_out, 1, n_freq) in (unit of H)^2, and
        its real degrees of freedom ``2 (n - 1) L``; None with fewer than two
        periods or no finite result.
    """
    n = int(n_periods)
    n_f = gxx.shape[0]
    if n < 2 or n_f == 0:
        return None
    xbar, ybar = zbar
    c = line_scale
    k = n / (n - 1.0)
    # noise (co)variances per period, in the density units of the spectra
    cxx = k * (gxx - c * np.abs(xbar) ** 2)  # (f,)
    cyx = k * (gyx - c[:, None] * ybar * xbar.conj()[:, None])  # (f, out)
    cyy = k * (gyy - c[:, None] * np.abs(ybar) ** 2)  # (f, out)
    n_lines = smoothing_lines(n, n_f)
    cxx, cyx, cyy = (_line_average(a, n_lines) for a in (cxx, cyx, cyy))
    hf = h[:, 0, :].T  # (f, out)
    num = cyy + np.abs(hf) ** 2 * cxx[:, None] - 2.0 * np.real(hf.conj() * cyx)
    with np.errstate(divide="ignore", invalid="ignore"):
        var = np.maximum(num, 0.0) / (n * c[:, None] * np.abs(xbar[:, None]) ** 2)
    if not np.all(np.isfinite(var)):
        return None
    return np.asarray(var.T[:, None, :], dtype=float), 2.0 * (n - 1) * n_lines


def _line_average(a: NDArray[Any], n_lines: int) -> NDArray[Any]:
    """Mean of ``a`` over ``n_lines`` neighbouring lines (axis 0), kept inside the axis.

    Every line gets a full window: centred where it fits, shifted inwards at
    the ends, so every line's average has the same degrees of freedom.
    """
    n_f = a.shape[0]
    if n_lines <= 1:
        return a
    cs = np.concatenate([np.zeros((1, *a.shape[1:]), dtype=a.dtype), np.cumsum(a, axis=0)])
    lo = np.clip(np.arange(n_f) - n_lines // 2, 0, n_f - n_lines)
    out: NDArray[Any] = (cs[lo + n_lines] - cs[lo]) / n_lines
    return out


def cyclic_input_noise(
    gxx: NDArray[np.float64],
    xbar: NDArray[np.complex128],
    line_scale: NDArray[np.float64],
    n_periods: int,
) -> NDArray[np.float64] | None:
    """Relative variance ``r`` of the error the force noise makes in a one-input cyclic FRF.

    The first-order error of ``H_j = Ybar_j / Xbar`` is ``(dY_j - H_j dX) /
    Xbar`` (module docstring): its part ``-H_j dX / Xbar`` is one complex noise
    ``n = dX / Xbar`` times ``H_j``, the same ``n`` for every output, of variance
    ``r = C_xx / (n |Xbar|^2)`` (the term ``|H_j|^2 C_xx`` of the variance over
    ``|H_j|^2``; Pintelon & Schoukens 2012, sec. 2.5). ``C_xx`` is averaged over the
    lines of :func:`smoothing_lines` as in :func:`cyclic_frf_variance`.

    Parameters
    ----------
    gxx : ndarray, shape (n_freq,)
        Input auto spectrum ``c mean_k |X_k|^2``.
    xbar : ndarray, complex, shape (n_freq,)
        Mean spectrum of the periods' force (unscaled, :func:`mean_spectra`).
    line_scale : ndarray, shape (n_freq,)
        Density scale ``c`` of each line.
    n_periods : int
        Number of periods ``n`` averaged.

    Returns
    -------
    ndarray, shape (1, n_freq) or None
        ``r`` (dimensionless, >= 0) per line; None with fewer than two periods
        or no finite result.
    """
    n = int(n_periods)
    n_f = gxx.shape[0]
    if n < 2 or n_f == 0:
        return None
    c = line_scale
    cxx = (n / (n - 1.0)) * (gxx - c * np.abs(xbar) ** 2)
    cxx = _line_average(cxx, smoothing_lines(n, n_f))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.maximum(cxx, 0.0) / (n * c * np.abs(xbar) ** 2)
    if not np.all(np.isfinite(r)):
        return None
    return np.asarray(r[None, :], dtype=float)


def cyclic_variance_on_lines(
    signals: tuple[NDArray[Any], NDArray[Any]],
    starts: NDArray[np.intp],
    windows: tuple[NDArray[np.float64], NDArray[np.float64]],
    detrend: bool,
    spectra: Any,
    h: NDArray[np.complex128],
) -> tuple[NDArray[np.float64], float, NDArray[np.float64] | None] | None:
    """:func:`cyclic_frf_variance` and :func:`cyclic_input_noise` of a one-input cyclic
    estimate on its kept lines: the variance, its real degrees of freedom and the
    relative input-noise variance (1, n_freq) (None where not finite).

    Parameters
    ----------
    signals : (ndarray, ndarray)
        Inputs (1, n_samples) and outputs (n_out, n_samples).
    starts : ndarray of int
        First sample of every period averaged.
    windows : (ndarray, ndarray), shape (seg,) each
        Output and input windows (:func:`~tyredamp.signal.segmenting.segment_windows`).
    detrend : bool
        Whether each period's mean was removed.
    spectra : CrossSpectra
        The averaged spectra on the kept lines (``n_in == 1``;
        :class:`~tyredamp.signal.estimators.CrossSpectra`, not imported here:
        the estimators import this module).
    h : ndarray, complex, shape (n_out, 1, n_freq)
        The FRF estimate on those lines.
    """
    w, w_in = windows
    seg = w.size
    xbar, ybar = mean_spectra(signals[0], signals[1], starts, w, w_in, detrend)
    k = np.rint(spectra.frequency * seg / spectra.sample_rate).astype(np.intp)
    # density scale of one segment's line (cross_spectra's, times the averages)
    c = np.full(k.size, 2.0 / (spectra.sample_rate * float(np.sum(w * w))))
    c[(k == 0) | ((seg % 2 == 0) & (k == seg // 2))] /= 2
    gxx = np.real(spectra.Gxx[:, 0, 0])
    got = cyclic_frf_variance(
        gxx, spectra.Gyx[:, :, 0], spectra.Gyy, (xbar[k, 0], ybar[k]), c, h, spectra.n_averages
    )
    if got is None:
        return None
    return got[0], got[1], cyclic_input_noise(gxx, xbar[k, 0], c, spectra.n_averages)
