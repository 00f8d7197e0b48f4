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

from typing import Any

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import InputError, ShapeError
from ..frf import FRF, FRFKind
from ..timedata import TimeData
from .periodicity import ExcitationDetection

__all__ = ["local_frf", "local_method_frf", "local_variance_dof"]


def _windows(n_lines: int, half: int) -> NDArray[np.intp]:
    """Line indices (n_lines, 2 half + 1) of each local window, shifted inside at the edges."""
    w = 2 * half + 1
    start = np.clip(np.arange(n_lines) - half, 0, n_lines - w)
    return start[:, None] + np.arange(w)[None, :]


def _local_size(n_in: int, order: int, half_width: int | None, rational: bool) -> tuple[int, int]:
    """Half width ``n`` of the window and number ``n_par`` of local parameters (checked)."""
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or order < 0:
        raise InputError(f"order: expected an integer >= 0, got {order!r}")
    r_ord = int(order)
    n_par = (r_ord + 1) * (n_in + 1) + (r_ord if rational else 0)
    if half_width is None:
        return int(np.ceil((n_par + 4 - 1) / 2)), n_par
    if isinstance(half_width, bool) or not isinstance(half_width, int | np.integer):
        raise InputError(f"half_width: expected an integer, got {half_width!r}")
    half = int(half_width)
    if 2 * half + 1 <= n_par:
        raise InputError(
            f"half_width: {2 * half + 1} lines cannot fit {n_par} local parameters and "
            f"leave a degree of freedom for the noise; use at least {n_par // 2 + 1}"
        )
    return half, n_par


def local_variance_dof(
    n_in: int, *, order: int = 2, half_width: int | None = None, rational: bool = True
) -> float:
    """Real degrees of freedom of the variance of :func:`local_frf`: ``2 (2 n + 1 - n_par)``.

    The noise variance of a line is the residual of a complex least-squares
    fit of ``2 n + 1`` lines with ``n_par`` complex parameters (module
    docstring): ``2 n + 1 - n_par`` complex, twice as many real degrees of
    freedom (Pintelon et al. 2010, part I, sec. 4; Seber & Lee 2003, thm. 3.5).
    Stated as ``FRF.meta["variance_dof"]`` by the local methods of
    :func:`~tyredamp.signal.estimate_frf` (:mod:`tyredamp.modal.problem.problem`).
    Arguments as in :func:`local_frf`.
    """
    half, n_par = _local_size(int(n_in), order, half_width, rational)
    return 2.0 * (2 * half + 1 - n_par)


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
    n_in, n_out = x.shape[0], y.shape[0]
    half, n_par = _local_size(n_in, order, half_width, rational)
    r_ord = int(order)
    n = x.shape[1]
    n_f = n // 2 + 1
    w = 2 * half + 1
    if n_f < w:
        raise InputError(
            f"the record's {n} samples give {n_f} lines, fewer than the local method's window of "
            f"{w} lines: use a longer record or another method (--method)"
        )
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


def _local_lines(
    x: NDArray[np.float64],
    f: NDArray[np.float64],
    band: tuple[float, float] | None,
    min_relative_power: float,
) -> NDArray[np.intp]:
    """Lines of a local estimate: every input excited (relative power), not 0 Hz, in ``band``."""
    thr = float(min_relative_power)
    if not np.isfinite(thr) or thr < 0 or thr >= 1:
        raise InputError(
            f"min_relative_power: expected a value in [0, 1), got {min_relative_power!r}"
        )
    pu = np.abs(scipy.fft.rfft(x, axis=1)) ** 2  # (in, f)
    keep = np.all(pu > thr * pu.max(axis=1, keepdims=True), axis=0)
    keep[0] = False  # 0 Hz: the mean is not a response to the force
    if band is not None:
        lo, hi = float(band[0]), float(band[1])
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
            raise InputError(f"band (--band): expected F_LO < F_HI in Hz, got {band!r}")
        keep &= (f >= lo) & (f <= hi)
    lines = np.flatnonzero(keep)
    if lines.size == 0:
        raise InputError(
            "no frequency line is excited by the force (in the band, --band) for the local "
            "method: check the force channel and the band"
        )
    return lines


def local_method_frf(
    timedata: TimeData,
    ref_idx: list[int],
    out_idx: list[int],
    kind: FRFKind,
    method: str,
    estimator: str,
    settle: int,
    band: tuple[float, float] | None,
    min_relative_power: float,
    window: Any,
    overlap: Any,
    segment_samples: Any,
    detection: ExcitationDetection | None,
) -> FRF:
    """:func:`~tyredamp.signal.estimate_frf` by the LRM/LPM methods (one record, local models).

    ``ref_idx``, ``out_idx``: positions of the force and response channels;
    ``settle`` samples are dropped; ``band`` defaults to
    ``timedata.acquisition.band_hz``. Segment options (``window``,
    ``overlap``, ``segment_samples``) and estimators other than H1 are
    errors: the local methods fit the whole record by least squares.
    """
    if estimator != "H1":
        raise InputError(
            f"estimator: the {method} method is a least-squares (H1) fit, got {estimator!r}"
        )
    for name, v in (("window", window), ("overlap", overlap), ("segment_samples", segment_samples)):
        if v not in (None, 0, 0.0, "boxcar"):
            raise InputError(f"{name}: the {method} method uses the whole record, got {v!r}")
    acq = timedata.acquisition
    if len(acq.run_starts) > 1:
        raise InputError(
            f"method: {method} takes one record; this one holds {len(acq.run_starts)} runs"
        )
    chans = timedata.channels
    data = timedata.data[:, settle:]
    x, y = data[ref_idx], data[out_idx]
    rational = method == "lrm"
    f, h, var = local_frf(x, y, timedata.sample_rate, rational=rational)
    lines = _local_lines(x, f, band if band is not None else acq.band_hz, min_relative_power)
    meta_out: dict[str, Any] = {
        "estimator": "H1",
        "method": method,
        "n_averages": 1,
        "segment_samples": int(data.shape[1]),
        "sample_rate": timedata.sample_rate,
        "window": "boxcar",
        "overlap": 0.0,
        "settle_samples": settle,
        "local_order": 2,
        # the local fit's residual degrees of freedom (modal.problem.problem: goodness of fit)
        "variance_dof": local_variance_dof(len(ref_idx), rational=rational),
    }
    if detection is not None:
        meta_out["detection"] = detection.to_dict()
    return FRF(
        f[lines],
        h[:, :, lines],
        kind=kind,
        outputs=[chans[i] for i in out_idx],
        inputs=[chans[i] for i in ref_idx],
        meta=meta_out,
        variance=var[:, :, lines],
    )
