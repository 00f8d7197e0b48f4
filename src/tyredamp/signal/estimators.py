"""FRF estimation from sampled time data: H1, H2, Hv; coherence (spec step 1).

The input (force) and output (response) channels are cut into segments, each
segment is windowed and Fourier transformed, and the averaged cross-spectral
matrices

``Gxx = E[x x^H]`` (n_in x n_in), ``Gyx = E[y x^H]`` (n_out x n_in),
``Gyy = E[y y^H]`` (n_out x n_out)

are formed per frequency line (``x``, ``y`` the column vectors of the input
and output spectra of one segment). From them:

* ``H1 = Gyx Gxx^-1``: least squares with noise on the outputs only; biased
  low (in magnitude) by noise on the inputs.
* ``H2 = Gyy Gxy^-1`` with ``Gxy = Gyx^H``: needs as many outputs as inputs
  (square MIMO) or one input (SIMO, then ``H2_j = Gyy_jj / conj(Gyx_j)`` per
  output); biased high by noise on the outputs.
* ``Hv``: total least squares per output ``j``: the eigenvector ``v`` of the
  smallest eigenvalue of ``[[Gxx, Gxy_j], [Gyx_j, Gyy_jj]]`` gives
  ``H_j = -conj(v[:n_in] / v[n_in])``. It assumes equal noise power on the
  input and output channels in their SI units; ``|H1| <= |Hv| <= |H2|`` for
  one input.

Multiple coherence of output ``j`` with all inputs:
``gamma_j^2 = Gyx_j Gxx^-1 Gyx_j^H / Gyy_jj`` (the ordinary coherence
``|Gyx|^2 / (Gxx Gyy)`` for one input).

Segmenting methods:

* ``"cyclic"``: whole periods of a periodic excitation, rectangular window, no
  overlap. With steady-state periodic data and the excitation on DFT lines
  this is exact: no leakage, no window bias.
* ``"welch"``: overlapping windowed segments (Hann by default), constant
  detrend, for random excitation.
* ``"transient"``: consecutive non-overlapping records (burst random, impact
  hits), rectangular by default, with the optional force window on the inputs
  and the exponential window on all channels.
* ``"lrm"``, ``"lpm"``: the local rational / polynomial method on the whole
  record (:mod:`.lrm`), for random excitation: leakage and transients are
  fitted away line by line, with the noise variance of every line.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from .._validate import as_band, as_count, as_finite, check_positive
from ..exceptions import InputError, ShapeError
from ..frf import FRF, Channel, FRFKind
from ..timedata import TimeData
from .cyclic_variance import cyclic_variance_on_lines
from .lrm import local_method_frf
from .segmenting import (
    METHODS,
    Method,
    MethodChoice,
    SegmentPlan,
    checked_starts,
    choose_method,
    plan_starts,
    segment_plan,
    segment_windows,
)

__all__ = [
    "ESTIMATORS",
    "METHODS",
    "RESPONSE_KIND",
    "CrossSpectra",
    "cross_spectra",
    "estimate_frf",
    "frf_from_spectra",
    "frf_variance",
    "multiple_coherence",
    "ordinary_coherence",
    "resolve_channels",
]

Estimator = Literal["H1", "H2", "Hv"]
ESTIMATORS: tuple[str, ...] = ("H1", "H2", "Hv")
#: FRF kind that follows from the measured response quantity.
RESPONSE_KIND: dict[str, FRFKind] = {
    "displacement": "receptance",
    "velocity": "mobility",
    "acceleration": "accelerance",
}
#: Bytes of segment spectra held at once while averaging.
_CHUNK_BYTES = 32e6


@dataclass(frozen=True)
class CrossSpectra:
    """Averaged one-sided cross-spectral density matrices.

    Attributes
    ----------
    frequency : ndarray, shape (n_freq,)
        Frequency lines in Hz (``k * sample_rate / segment_samples``).
    Gxx : ndarray, complex, shape (n_freq, n_in, n_in)
        Input cross-spectral matrix, in (input unit)^2/Hz.
    Gyx : ndarray, complex, shape (n_freq, n_out, n_in)
        Output-input cross spectra ``E[y x^H]``.
    Gyy : ndarray, shape (n_freq, n_out)
        Output auto spectra (real, >= 0).
    Gyy_full : ndarray, complex, shape (n_freq, n_out, n_out) or None
        Full output cross-spectral matrix when requested (H2 for MIMO).
    n_averages : int
        Number of segments averaged.
    segment_samples : int
        Samples per segment.
    sample_rate : float
        Samples per second (Hz).
    """

    frequency: NDArray[np.float64]
    Gxx: NDArray[np.complex128]
    Gyx: NDArray[np.complex128]
    Gyy: NDArray[np.float64]
    Gyy_full: NDArray[np.complex128] | None
    n_averages: int
    segment_samples: int
    sample_rate: float

    def select_lines(self, index: NDArray[np.intp]) -> CrossSpectra:
        """The same spectra on a subset of lines (positions, kept in order)."""
        return CrossSpectra(
            frequency=self.frequency[index],
            Gxx=self.Gxx[index],
            Gyx=self.Gyx[index],
            Gyy=self.Gyy[index],
            Gyy_full=None if self.Gyy_full is None else self.Gyy_full[index],
            n_averages=self.n_averages,
            segment_samples=self.segment_samples,
            sample_rate=self.sample_rate,
        )


def cross_spectra(
    inputs: ArrayLike,
    outputs: ArrayLike,
    sample_rate: float,
    segment_samples: int,
    *,
    step_samples: int | None = None,
    start: int = 0,
    starts: ArrayLike | None = None,
    window: str | tuple[str, float] | ArrayLike = "hann",
    input_window: ArrayLike | None = None,
    detrend: bool = False,
    full_output: bool = False,
) -> CrossSpectra:
    """Average the cross spectra of segmented input and output signals.

    Parameters
    ----------
    inputs : array_like, shape (n_in, n_samples)
        Input (force) signals, N.
    outputs : array_like, shape (n_out, n_samples)
        Output (response) signals in their SI unit.
    sample_rate : float
        Samples per second (Hz).
    segment_samples : int
        Segment length in samples; lines are spaced ``sample_rate / segment_samples``.
    step_samples : int, optional
        Start-to-start distance of segments (default ``segment_samples``: no
        overlap).
    start : int
        First sample used (drops a settling transient).
    starts : array_like of int, optional
        Explicit first sample of every segment (overrides ``step_samples``
        and ``start``), for records made of separate runs.
    window : str, tuple or array_like, shape (segment_samples,)
        Window applied to every channel (name for :func:`segment_window`).
    input_window : array_like, shape (segment_samples,), optional
        Extra window multiplied onto the inputs only (the impact force window).
    detrend : bool
        Remove each segment's mean before windowing.
    full_output : bool
        Also accumulate the full output matrix ``Gyy_full`` (needed by H2 for
        MIMO).

    Returns
    -------
    CrossSpectra
        One-sided densities scaled as :func:`scipy.signal.csd` with
        ``scaling="density"`` (the scale cancels in every FRF estimator).
    """
    x, y = _signals(inputs, outputs)
    fs = check_positive(sample_rate, "sample_rate")
    seg = as_count(segment_samples, "segment_samples", minimum=2)
    step = seg if step_samples is None else as_count(step_samples, "step_samples", minimum=1)
    st0 = as_count(start, "start", minimum=0)
    seg_starts = checked_starts(x.shape[1], seg, step, st0, starts)
    w, w_in = segment_windows(window, input_window, seg)
    gxx, gyx, gyy, gyy_full = _accumulate(x, y, seg_starts, w, w_in, detrend, full_output)
    n_f = seg // 2 + 1
    # one-sided density scaling (as scipy.signal.csd): 2 / (fs sum w^2 n_avg)
    scale = np.full(n_f, 2.0 / (fs * float(np.sum(w * w)) * seg_starts.size))
    scale[0] /= 2
    if seg % 2 == 0:
        scale[-1] /= 2
    gxx *= scale[:, None, None]
    gyx *= scale[:, None, None]
    gyy *= scale[:, None]
    if gyy_full is not None:
        gyy_full *= scale[:, None, None]
    return CrossSpectra(
        frequency=np.arange(n_f, dtype=float) * (fs / seg),
        Gxx=gxx,
        Gyx=gyx,
        Gyy=gyy,
        Gyy_full=gyy_full,
        n_averages=int(seg_starts.size),
        segment_samples=seg,
        sample_rate=fs,
    )


def _signals(inputs: ArrayLike, outputs: ArrayLike) -> tuple[NDArray[Any], NDArray[Any]]:
    """Inputs and outputs as finite 2-D arrays (n_channels, n_samples) of equal length."""
    x = as_finite(inputs, "inputs")
    y = as_finite(outputs, "outputs")
    x = x[None, :] if x.ndim == 1 else x
    y = y[None, :] if y.ndim == 1 else y
    if x.ndim != 2 or y.ndim != 2:
        raise ShapeError("inputs, outputs: expected 2-D arrays (n_channels, n_samples)")
    if x.shape[1] != y.shape[1]:
        raise ShapeError(
            f"inputs, outputs: expected the same number of samples, got {x.shape[1]} and "
            f"{y.shape[1]}"
        )
    return x, y


def _accumulate(
    x: NDArray[Any],
    y: NDArray[Any],
    seg_starts: NDArray[np.intp],
    w: NDArray[np.float64],
    w_in: NDArray[np.float64],
    detrend: bool,
    full_output: bool,
) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any], NDArray[Any] | None]:
    """Unscaled sums of ``X X^H``, ``Y X^H``, ``|Y|^2`` (and ``Y Y^H``) over the segments."""
    seg = w.size
    n_in, n_out = x.shape[0], y.shape[0]
    n_f = seg // 2 + 1
    gxx = np.zeros((n_f, n_in, n_in), dtype=complex)
    gyx = np.zeros((n_f, n_out, n_in), dtype=complex)
    gyy = np.zeros((n_f, n_out))
    gyy_full = np.zeros((n_f, n_out, n_out), dtype=complex) if full_output else None
    chunk = max(1, int(_CHUNK_BYTES // (16 * (n_in + n_out) * seg)))
    ar = np.arange(seg)
    for c in range(0, seg_starts.size, chunk):
        idx = seg_starts[c : c + chunk, None] + ar  # (k, seg)
        xs, ys = x[:, idx], y[:, idx]  # (n_ch, k, seg)
        if detrend:
            xs = xs - xs.mean(axis=-1, keepdims=True)
            ys = ys - ys.mean(axis=-1, keepdims=True)
        xf = scipy.fft.rfft(xs * w_in, axis=-1).transpose(2, 0, 1)  # (n_f, n_in, k)
        yf = scipy.fft.rfft(ys * w, axis=-1).transpose(2, 0, 1)  # (n_f, n_out, k)
        xh = xf.conj().transpose(0, 2, 1)
        gxx += xf @ xh
        gyx += yf @ xh
        gyy += np.sum(yf.real**2 + yf.imag**2, axis=2)
        if gyy_full is not None:
            gyy_full += yf @ yf.conj().transpose(0, 2, 1)
    return gxx, gyx, gyy, gyy_full


def frf_from_spectra(spectra: CrossSpectra, estimator: Estimator = "H1") -> NDArray[np.complex128]:
    """FRF matrix from averaged cross spectra by H1, H2 or Hv.

    Parameters
    ----------
    spectra : CrossSpectra
    estimator : {"H1", "H2", "Hv"}
        See the module docstring. ``"H2"`` needs one input, or as many outputs
        as inputs (then ``spectra.Gyy_full`` is required).

    Returns
    -------
    ndarray, complex, shape (n_out, n_in, n_freq)
        In output unit per input unit (for example m/(s^2 N)).
    """
    if estimator not in ESTIMATORS:
        raise InputError(f"estimator: expected one of {ESTIMATORS}, got {estimator!r}")
    gxx, gyx, gyy = spectra.Gxx, spectra.Gyx, spectra.Gyy
    h: NDArray[Any]
    n_out, n_in = gyx.shape[1], gyx.shape[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        if estimator == "H1":
            if n_in == 1:
                h = gyx / gxx[:, :, :1].real
            else:
                # H Gxx = Gyx  <=>  Gxx^T H^T = Gyx^T
                h = np.linalg.solve(gxx.transpose(0, 2, 1), gyx.transpose(0, 2, 1))
                h = h.transpose(0, 2, 1)
        elif estimator == "H2":
            if n_in == 1:
                h = gyy[:, :, None] / gyx.conj()
            else:
                if n_out != n_in:
                    raise InputError(
                        f"estimator: H2 with {n_in} inputs needs as many outputs, got {n_out}; "
                        "use H1 or Hv"
                    )
                if spectra.Gyy_full is None:
                    raise InputError("spectra: H2 for MIMO needs Gyy_full (full_output=True)")
                gxy = gyx.conj().transpose(0, 2, 1)  # (f, in, out)
                # H Gxy = Gyy  <=>  Gxy^T H^T = Gyy^T
                h = np.linalg.solve(gxy.transpose(0, 2, 1), spectra.Gyy_full.transpose(0, 2, 1))
                h = h.transpose(0, 2, 1)
        else:
            h = np.empty(gyx.shape, dtype=complex)
            n_f = gxx.shape[0]
            gzz = np.zeros((n_f, n_in + 1, n_in + 1), dtype=complex)
            gzz[:, :n_in, :n_in] = gxx
            for j in range(n_out):
                gzz[:, n_in, :n_in] = gyx[:, j, :]
                gzz[:, :n_in, n_in] = gyx[:, j, :].conj()
                gzz[:, n_in, n_in] = gyy[:, j]
                _, vec = np.linalg.eigh(gzz)
                v = vec[:, :, 0]
                h[:, j, :] = -(v[:, :n_in] / v[:, n_in : n_in + 1]).conj()
    out: NDArray[np.complex128] = np.moveaxis(np.asarray(h, dtype=complex), 0, -1)
    return out


def frf_variance(
    spectra: CrossSpectra, coherence: NDArray[np.float64], n_independent: float
) -> NDArray[np.float64] | None:
    """Variance of each FRF estimate from the residual (non-coherent) output power.

    Least squares over ``n`` independent segments ``Y_k = H X_k + E_k`` gives
    ``cov(H_j) = G_ee,j Gxx^-1 / n`` (output ``j``), with the noise density
    estimated from the part of the output not explained by the inputs,
    ``G_ee,j = Gyy_jj (1 - gamma_j^2) n / (n - n_in)``, so::

        var(H_ji) = Gyy_jj (1 - gamma_j^2) [Gxx^-1]_ii / (n - n_in).

    For one input this is ``|H|^2 (1 - gamma^2) / (gamma^2 (n - 1))``, twice
    the squared normalised random error of ``|H|`` of Bendat and Piersol
    (``(1 - gamma^2) / (2 n gamma^2)``) since the complex variance counts the
    magnitude and the phase direction. For cyclic averaging the residual is
    the period-to-period spread of ``Y - H X``. It is the variance of H1 (and
    a first-order one of H2 and Hv with noise on the outputs). Cyclic
    estimates of one input get the errors-in-variables variance of
    :mod:`.cyclic_variance` from :func:`estimate_frf` instead.

    Parameters
    ----------
    spectra : CrossSpectra
        Averaged spectra on the kept lines.
    coherence : ndarray, shape (n_out, n_freq)
        Multiple coherence of each output.
    n_independent : float
        Number of statistically independent segments (the averages, reduced
        for overlapping windows by :func:`_overlap_factor`).

    Returns
    -------
    ndarray, shape (n_out, n_in, n_freq), or None
        Variance in (unit of H)^2; None when ``n_independent <= n_in`` (no
        degree of freedom left for the noise).
    """
    n_in = spectra.Gxx.shape[1]
    dof = float(n_independent) - n_in
    if dof <= 0:
        return None
    try:
        inv_diag = np.real(np.diagonal(np.linalg.inv(spectra.Gxx), axis1=1, axis2=2))  # (f, in)
    except np.linalg.LinAlgError:
        return None
    resid = spectra.Gyy * (1.0 - coherence.T)  # (f, out)
    var = resid[:, :, None] * np.maximum(inv_diag, 0.0)[:, None, :] / dof  # (f, out, in)
    var = np.moveaxis(var, 0, -1)
    if not np.all(np.isfinite(var)):
        return None
    return np.maximum(var, 0.0)


def _overlap_factor(window: ArrayLike, step: int, n_segments: int) -> float:
    """Variance inflation of an average of ``n_segments`` overlapping windowed segments.

    ``1 + 2 sum_j (1 - j/K) rho(j)^2`` with ``rho(j)`` the overlap correlation
    ``sum w[t] w[t + j step] / sum w^2`` (Welch 1967, eq. for the variance
    of the averaged periodogram of white noise); 1 without overlap.
    """
    w = np.asarray(window, dtype=float)
    seg = w.size
    k = int(n_segments)
    total = float(np.sum(w * w))
    out = 1.0
    j = 1
    while j < k and j * step < seg:
        rho = float(np.sum(w[: seg - j * step] * w[j * step :])) / total
        out += 2.0 * (1.0 - j / k) * rho * rho
        j += 1
    return out


def ordinary_coherence(spectra: CrossSpectra) -> NDArray[np.float64]:
    """Ordinary coherence ``|Gyx|^2 / (Gxx Gyy)`` of each output with each input.

    Returns
    -------
    ndarray, shape (n_out, n_in, n_freq)
        Values in [0, 1] (0 where a spectrum is zero).
    """
    gxx_d = np.real(np.diagonal(spectra.Gxx, axis1=1, axis2=2))  # (f, in)
    den = spectra.Gyy[:, :, None] * gxx_d[:, None, :]
    num = np.abs(spectra.Gyx) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return np.moveaxis(np.clip(coh, 0.0, 1.0), 0, -1)


def multiple_coherence(spectra: CrossSpectra) -> NDArray[np.float64]:
    """Multiple coherence of each output with all inputs.

    ``gamma_j^2 = Gyx_j Gxx^-1 Gyx_j^H / Gyy_jj``; equals the ordinary
    coherence for one input.

    Returns
    -------
    ndarray, shape (n_out, n_freq)
        Values in [0, 1] (0 where a spectrum is zero).
    """
    h1 = np.moveaxis(frf_from_spectra(spectra, "H1"), -1, 0)  # (f, out, in)
    num = np.real(np.sum(h1 * spectra.Gyx.conj(), axis=2))  # (f, out)
    den = spectra.Gyy
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    coh = np.where(np.isfinite(coh), coh, 0.0)
    return np.clip(coh, 0.0, 1.0).T


# ------------------------------------------------------------------ channels
def _match(ch: Channel, key: Channel | int | str) -> bool:
    if isinstance(key, Channel):
        return ch == key or (ch.node == key.node and ch.direction == key.direction)
    if isinstance(key, bool):
        return False
    if isinstance(key, int | np.integer):
        return ch.node == int(key)
    s = str(key).strip()
    node_label = Channel(node=ch.node, direction=ch.direction).label
    return s in (ch.label, ch.name, node_label) or (s.isdigit() and int(s) == ch.node)


def resolve_channels(
    channels: Sequence[Channel],
    keys: Sequence[Channel | int | str],
    name: str,
    candidates: Sequence[int] | None = None,
) -> list[int]:
    """Positions of the channels named by ``keys``.

    A key is a :class:`Channel` (matched by node and direction), an int (node
    number) or a str (label such as ``"5+Z"``, channel name, or node number).
    Each key must match exactly one channel among ``candidates`` (positions;
    default all).
    """
    pool = list(range(len(channels))) if candidates is None else list(candidates)
    out: list[int] = []
    for key in keys:
        hits = [i for i in pool if _match(channels[i], key)]
        if not hits:
            avail = ", ".join(channels[i].label for i in pool) or "none"
            raise InputError(f"{name}: no channel matches {key!r}; available: {avail}")
        if len(hits) > 1:
            raise InputError(
                f"{name}: {key!r} matches {len(hits)} channels "
                f"({', '.join(channels[i].label for i in hits)}); give node and direction"
            )
        if hits[0] in out:
            raise InputError(f"{name}: channel {key!r} given twice")
        out.append(hits[0])
    return out


# --------------------------------------------------------------- entry point
def estimate_frf(
    timedata: TimeData,
    estimator: Estimator = "H1",
    reference: Sequence[Channel | int | str] | Channel | int | str | None = None,
    method: Method | None = None,
    *,
    outputs: Sequence[Channel | int | str] | None = None,
    period_samples: int | None = None,
    segment_samples: int | None = None,
    overlap: float | None = None,
    window: str | tuple[str, float] | None = None,
    settle_samples: int | None = None,
    force_window_samples: int | None = None,
    exponential_end: float | None = None,
    band: tuple[float, float] | None = None,
    min_relative_power: float = 1e-10,
    detect: bool = True,
) -> FRF:
    """Estimate the FRF matrix of a test from its time data.

    Parameters
    ----------
    timedata : TimeData
        Force and response channels on one clock, SI units.
    estimator : {"H1", "H2", "Hv"}
        FRF estimator (module docstring).
    reference : channel key or sequence of them, optional
        The input (force) channels; default every force channel. Keys as in
        :func:`resolve_channels` (label ``"1+Z"``, name, node number or
        :class:`Channel`).
    method : {"cyclic", "welch", "transient", "lrm", "lpm"}, optional
        Default: ``"cyclic"`` when ``timedata.acquisition.period_samples``
        (or ``period_samples``) is given, ``"transient"`` when
        ``acquisition.record_samples`` is given, else detected from the data
        (``detect``), else ``"welch"``.
    outputs : sequence of channel keys, optional
        Response channels; default every non-force channel. They must all be
        the same quantity, which sets the FRF kind (acceleration ->
        accelerance, velocity -> mobility, displacement -> receptance).
    period_samples : int, optional
        Period of a periodic excitation in samples (cyclic method); default
        ``timedata.acquisition.period_samples``.
    segment_samples : int, optional
        Segment length: Welch default ``n_samples // 8``; transient default
        ``timedata.acquisition.record_samples``. Not used by the cyclic method.
    overlap : float, optional
        Welch overlap fraction in [0, 1) (default 0.5); 0 for the other methods.
    window : str or tuple, optional
        Window on all channels: ``"hann"`` for Welch, ``"boxcar"`` otherwise
        (the cyclic method accepts only ``"boxcar"``).
    settle_samples : int, optional
        Samples dropped at the start of the record, or of each run when
        ``timedata.acquisition.run_starts`` lists the first samples of
        separately driven runs (segments never straddle runs); default
        ``acquisition.settle_samples``.
    force_window_samples : int, optional
        Transient method: flat length of the force window on the inputs (with
        a taper of a tenth of it).
    exponential_end : float, optional
        Transient method: end value of an exponential window on all channels;
        its time constant goes to ``meta["exponential_tau_s"]`` (it adds
        ``1/tau`` to every modal decay rate).
    band : (float, float), optional
        Keep only lines with ``band[0] <= f <= band[1]`` (Hz); default
        ``timedata.acquisition.band_hz`` when given, else all excited lines.
    min_relative_power : float
        Lines where an input's auto spectrum is below this fraction of its
        maximum are not excited and are left out (for a multisine, every line
        outside its band).
    detect : bool
        When neither ``method`` nor a period or record length is stated
        (argument or ``timedata.acquisition``), decide from the signals with
        :func:`~tyredamp.signal.periodicity.detect_excitation`: periodic data
        get cyclic averaging with the detected period and start transient,
        impact data the transient method on records starting at the hits,
        the rest Welch. ``method="cyclic"`` without a period also detects it.
        A period given as an argument to data that state none gets its start
        transient detected (:func:`~tyredamp.signal.periodicity.transient_periods`)
        unless ``settle_samples`` is given. The verdict and its reason go to
        ``meta["detection"]``.

    Returns
    -------
    FRF
        ``H`` (n_out, n_in, n_lines), the multiple coherence, the variance
        of each line (cyclic with one input and run:
        :mod:`~tyredamp.signal.cyclic_variance`, else :func:`frf_variance`;
        None with too few averages), and ``meta`` with ``estimator``,
        ``method``, ``n_averages``, ``segment_samples``, ``sample_rate``,
        ``window``, ``overlap``, ``variance_dof`` (its real degrees of freedom).

    Raises
    ------
    InputError
        Unknown options, no force channel, a force channel of zeros, mixed
        response quantities, fully correlated inputs (MIMO), too few samples.
    """
    ref_idx, out_idx, kind = _resolve_io(timedata, estimator, reference, outputs)
    choice = choose_method(
        timedata, ref_idx, out_idx, method, period_samples, settle_samples, segment_samples, detect
    )
    if choice.method in ("lrm", "lpm"):
        return local_method_frf(
            timedata,
            ref_idx,
            out_idx,
            kind,
            choice.method,
            estimator,
            choice.settle_samples,
            band,
            min_relative_power,
            window,
            overlap,
            segment_samples,
            choice.detection,
        )
    plan = segment_plan(timedata, choice, window, overlap, force_window_samples, exponential_end)
    io = (ref_idx, out_idx, kind)
    return _segmented_frf(timedata, io, estimator, choice, plan, band, min_relative_power)


def _resolve_io(
    timedata: TimeData,
    estimator: str,
    reference: Sequence[Channel | int | str] | Channel | int | str | None,
    outputs: Sequence[Channel | int | str] | None,
) -> tuple[list[int], list[int], FRFKind]:
    """Positions of the force and response channels and the FRF kind of ``estimate_frf``."""
    if not isinstance(timedata, TimeData):
        raise InputError(f"timedata: expected a TimeData, got {type(timedata).__name__}")
    if estimator not in ESTIMATORS:
        raise InputError(f"estimator: expected one of {ESTIMATORS}, got {estimator!r}")
    chans = timedata.channels
    forces = timedata.force_indices
    if not forces:
        timedata.require_force("an FRF")
    if reference is None:
        ref_idx = list(forces)
    else:
        keys = [reference] if isinstance(reference, Channel | int | str) else list(reference)
        if not keys:
            raise InputError("reference: expected at least one channel, got none")
        ref_idx = resolve_channels(chans, keys, "reference", candidates=forces)
    responses = timedata.response_indices
    if outputs is None:
        out_idx = list(responses)
    else:
        out_idx = resolve_channels(chans, list(outputs), "outputs", candidates=responses)
    if not out_idx:
        timedata.require_response("an FRF")
        raise InputError("no response channel to relate to the force")
    quantities = {timedata.quantities[i] for i in out_idx}
    if len(quantities) > 1:
        raise InputError(
            f"outputs: expected one response quantity, got {sorted(quantities)}; select "
            "outputs of one quantity"
        )
    for i in ref_idx:
        if not np.any(timedata.data[i]):
            raise InputError(
                f"reference: force channel {chans[i].label} is all zeros; no excitation recorded"
            )
    return ref_idx, out_idx, RESPONSE_KIND[quantities.pop()]


def _segmented_frf(
    timedata: TimeData,
    io: tuple[list[int], list[int], FRFKind],
    estimator: Estimator,
    choice: MethodChoice,
    plan: SegmentPlan,
    band: tuple[float, float] | None,
    min_relative_power: float,
) -> FRF:
    """``estimate_frf`` by the cyclic, Welch or transient method (segment averages)."""
    ref_idx, out_idx, kind = io
    chans = timedata.channels
    seg = plan.segment_samples
    starts = plan_starts(timedata, choice, plan)
    spectra = cross_spectra(
        timedata.data[ref_idx],
        timedata.data[out_idx],
        timedata.sample_rate,
        seg,
        starts=starts,
        window=plan.window_values,
        input_window=plan.input_window,
        detrend=plan.detrend,
        full_output=estimator == "H2" and len(ref_idx) > 1,
    )
    if band is None:
        band = timedata.acquisition.band_hz
    spectra = _band_lines(spectra, band, min_relative_power)
    if len(ref_idx) > 1:
        _check_input_rank(spectra, [chans[i].label for i in ref_idx])
    h = frf_from_spectra(spectra, estimator)
    coh = multiple_coherence(spectra)
    n_eff = spectra.n_averages / _overlap_factor(
        plan.window_values, plan.step_samples, spectra.n_averages
    )
    variance, dof = frf_variance(spectra, coh, n_eff), 2.0 * (n_eff - len(ref_idx))
    input_noise = None
    if choice.method == "cyclic" and len(ref_idx) == 1 and len(timedata.acquisition.run_starts) < 2:
        sig = (timedata.data[ref_idx], timedata.data[out_idx])
        wins = segment_windows(plan.window_values, plan.input_window, seg)
        eiv = cyclic_variance_on_lines(sig, starts, wins, plan.detrend, spectra, h)
        if eiv is not None:  # the period-to-period noise of force and responses
            variance, dof, input_noise = eiv
    win = plan.window
    meta_out: dict[str, Any] = {
        "estimator": estimator,
        "method": choice.method,
        "n_averages": spectra.n_averages,
        "segment_samples": seg,
        "sample_rate": timedata.sample_rate,
        "window": win if isinstance(win, str) else list(win),
        "overlap": plan.overlap,
        "settle_samples": choice.settle_samples,
        # real degrees of freedom of ``variance``
        "variance_dof": dof,
        **plan.info,
    }
    if choice.detection is not None:
        meta_out["detection"] = choice.detection.to_dict()
    return FRF(
        spectra.frequency,
        h,
        kind=kind,
        outputs=[chans[i] for i in out_idx],
        inputs=[chans[i] for i in ref_idx],
        coherence=coh,
        meta=meta_out,
        variance=variance,
        input_noise=input_noise,
    )


def _band_lines(
    spectra: CrossSpectra, band: tuple[float, float] | None, min_relative_power: float
) -> CrossSpectra:
    """The spectra on the excited lines inside ``band``."""
    lines = _excited_lines(spectra, min_relative_power)
    if band is not None:
        lo, hi = as_band(band)
        f = spectra.frequency
        lines = lines[(f[lines] >= lo) & (f[lines] <= hi)]
    if lines.size == 0:
        raise InputError(
            "no excited frequency line"
            + (f" in the band {lo:g}-{hi:g} Hz (--band)" if band is not None else "")
            + f": the force's power is nowhere above {min_relative_power:g} of its maximum"
            + (" there" if band is not None else "")
            + "; check the force channel and the band"
        )
    return spectra.select_lines(lines)


def _excited_lines(spectra: CrossSpectra, min_relative_power: float) -> NDArray[np.intp]:
    """Lines where every input's auto spectrum exceeds the relative threshold."""
    thr = float(min_relative_power)
    if not np.isfinite(thr) or thr < 0 or thr >= 1:
        raise InputError(
            f"min_relative_power: expected a value in [0, 1), got {min_relative_power!r}"
        )
    p = np.real(np.diagonal(spectra.Gxx, axis1=1, axis2=2))  # (f, in)
    pmax = p.max(axis=0)
    ok = np.all(p > thr * pmax[None, :], axis=1)
    return np.flatnonzero(ok)


def _check_input_rank(spectra: CrossSpectra, labels: list[str]) -> None:
    """Raise if the inputs are (nearly) fully correlated at some line (MIMO)."""
    d = np.sqrt(np.real(np.diagonal(spectra.Gxx, axis1=1, axis2=2)))  # (f, in)
    norm = spectra.Gxx / (d[:, :, None] * d[:, None, :])
    ev = np.linalg.eigvalsh(norm)
    rc = ev[:, 0] / ev[:, -1]
    bad = np.flatnonzero(rc < 1e-10)
    if bad.size:
        raise InputError(
            f"reference: the inputs {', '.join(labels)} are fully correlated at {bad.size} of "
            f"{rc.size} lines (first at {spectra.frequency[bad[0]]:g} Hz); MIMO needs "
            "independent forces (several realisations or uncorrelated signals)"
        )
