"""How :func:`~tyredamp.signal.estimate_frf` cuts a record into segments.

Two steps, both from the arguments, the data's acquisition record
(:class:`~tyredamp.timedata.Acquisition`) and, when neither states it, the
data themselves (:mod:`.periodicity`):

* :func:`choose_method`: the averaging method with its period, record
  length and settle samples (see ``detect`` of ``estimate_frf``);
* :func:`segment_plan`: segment length, step, windows and detrending of the
  cyclic, Welch or transient method, and :func:`plan_starts`, the first
  sample of every segment (within each run, after settling; at the hits of
  detected impacts).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_count, as_finite
from ..exceptions import InputError, ShapeError
from ..timedata import TimeData
from .periodicity import ExcitationDetection, detect_excitation, transient_periods
from .windows import exponential_window, force_window, segment_window

__all__ = [
    "METHODS",
    "MethodChoice",
    "SegmentPlan",
    "checked_starts",
    "choose_method",
    "plan_starts",
    "segment_plan",
    "segment_starts",
    "segment_windows",
]

Method = Literal["cyclic", "welch", "transient", "lrm", "lpm"]
METHODS: tuple[str, ...] = ("cyclic", "welch", "transient", "lrm", "lpm")


@dataclass(frozen=True)
class MethodChoice:
    """The averaging method of an estimate and what it needs.

    Attributes
    ----------
    method : {"cyclic", "welch", "transient", "lrm", "lpm"}
    period_samples : int or None
        Excitation period, samples (argument, record or detected).
    settle_samples : int
        Samples dropped at the start of the record or of each run.
    segment_samples : int or None
        Segment or record length, samples (argument or detected impacts).
    detection : ExcitationDetection or None
        The verdict from the data, when they were examined.
    """

    method: Method
    period_samples: int | None
    settle_samples: int
    segment_samples: int | None
    detection: ExcitationDetection | None


def _detected(
    timedata: TimeData,
    ref_idx: list[int],
    out_idx: list[int],
    method: Method | None,
    period_samples: int | None,
    settle_samples: int | None,
    segment_samples: int | None,
    detect: bool,
) -> tuple[Method | None, int | None, int | None, int | None, ExcitationDetection | None]:
    """Method, period, settle and record length filled from the data where not stated."""
    acq = timedata.acquisition
    data = timedata.data
    detection: ExcitationDetection | None = None
    stated = (
        period_samples is not None
        or acq.period_samples is not None
        or segment_samples is not None
        or acq.record_samples is not None
    )
    needs_period = method == "cyclic" and period_samples is None and acq.period_samples is None
    if detect and ((method is None and not stated) or needs_period):
        detection = detect_excitation(data[ref_idx], data[out_idx])
        if detection.kind == "periodic":
            method = "cyclic"
            period_samples = detection.period_samples
            if settle_samples is None:
                settle_samples = detection.settle_samples
        elif needs_period:
            raise InputError(
                f"method: 'cyclic' needs a period; none stated and none found in the data "
                f"({detection.reason})"
            )
        elif detection.kind == "impact" and detection.record_samples is not None:
            method = "transient"
            segment_samples = detection.record_samples
    elif (
        period_samples is not None
        and acq.period_samples is None
        and settle_samples is None
        and detect
        and method in (None, "cyclic")
    ):
        # a period stated by the caller for data that did not state one: find the
        # start transient in the data
        p_arg = as_count(period_samples, "period_samples", minimum=2)
        if timedata.n_samples >= 2 * p_arg and len(acq.run_starts) == 1:
            settle_samples = transient_periods(data[ref_idx + out_idx], p_arg) * p_arg
    return method, period_samples, settle_samples, segment_samples, detection


def choose_method(
    timedata: TimeData,
    ref_idx: list[int],
    out_idx: list[int],
    method: Method | None,
    period_samples: int | None,
    settle_samples: int | None,
    segment_samples: int | None,
    detect: bool,
) -> MethodChoice:
    """The method of an estimate: as given, else as the record states, else from the data.

    Default order: ``"cyclic"`` with a period (argument or
    ``timedata.acquisition``), ``"transient"`` with a record length, the
    verdict of :func:`~tyredamp.signal.periodicity.detect_excitation` (when
    ``detect``), else ``"welch"``; see ``detect`` of
    :func:`~tyredamp.signal.estimate_frf`. ``ref_idx``, ``out_idx`` are the
    positions of the force and response channels.
    """
    acq = timedata.acquisition
    method, period, settle, segment, detection = _detected(
        timedata, ref_idx, out_idx, method, period_samples, settle_samples, segment_samples, detect
    )
    if method is None:
        if period is not None or acq.period_samples is not None:
            method = "cyclic"
        elif segment is None and acq.record_samples is not None:
            method = "transient"
        else:
            method = "welch"
    if method not in METHODS:
        raise InputError(f"method: expected one of {METHODS}, got {method!r}")
    settle_n = as_count(settle if settle is not None else acq.settle_samples, "settle_samples")
    return MethodChoice(method, period, settle_n, segment, detection)


@dataclass(frozen=True)
class SegmentPlan:
    """Segments of the cyclic, Welch or transient method.

    Attributes
    ----------
    segment_samples, step_samples : int
        Segment length and start-to-start distance, samples.
    window : str or tuple
        Name of the window on all channels (``meta["window"]``).
    window_values : ndarray, shape (segment_samples,)
        The window applied to all channels (with the exponential window, when used).
    input_window : ndarray, shape (segment_samples,), or None
        Extra window on the inputs (the impact force window).
    detrend : bool
        Remove each segment's mean (Welch).
    overlap : float
        Overlap fraction of consecutive segments.
    info : dict
        Extra ``meta`` entries (``force_window_samples``, ``exponential_tau_s``).
    """

    segment_samples: int
    step_samples: int
    window: str | tuple[str, float]
    window_values: NDArray[np.float64]
    input_window: NDArray[np.float64] | None = None
    detrend: bool = False
    overlap: float = 0.0
    info: dict[str, Any] = field(default_factory=dict)


#: Shortest default Welch segment (samples): 8 frequency lines above DC.
_MIN_DEFAULT_SEGMENT = 16


def _cyclic_plan(period: int | None, window: Any, overlap: Any) -> SegmentPlan:
    if period is None:
        raise InputError(
            "method: 'cyclic' needs the period length: period_samples= (Python) or the period "
            "stored with the time data (acquisition metadata)"
        )
    seg = as_count(period, "period_samples", minimum=2)
    if window not in (None, "boxcar", "rect", "rectangular"):
        raise InputError(f"window: the cyclic method uses whole periods unwindowed, got {window!r}")
    if overlap not in (None, 0, 0.0):
        raise InputError(f"overlap: the cyclic method uses whole periods, got {overlap!r}")
    return SegmentPlan(seg, seg, "boxcar", segment_window("boxcar", seg))


def _welch_plan(n: int, segment: int | None, window: Any, overlap: float | None) -> SegmentPlan:
    if segment is None and n // 8 < _MIN_DEFAULT_SEGMENT:
        raise InputError(
            f"timedata: {n} samples per channel are too few for an FRF: the default segments "
            f"(an eighth of the record, for 8 averages) would hold {n // 8} sample(s), and a "
            f"spectrum needs at least {_MIN_DEFAULT_SEGMENT} ({_MIN_DEFAULT_SEGMENT // 2} lines); "
            f"record at least {8 * _MIN_DEFAULT_SEGMENT} samples, or give the segment length "
            "(tyredamp frf --segment)"
        )
    seg = as_count(segment if segment is not None else n // 8, "segment_samples", 2)
    ov = 0.5 if overlap is None else float(overlap)
    if not 0.0 <= ov < 1.0:
        raise InputError(f"overlap: expected a fraction in [0, 1), got {overlap!r}")
    win = window if window is not None else "hann"
    step = max(1, round(seg * (1 - ov)))
    return SegmentPlan(seg, step, win, segment_window(win, seg), detrend=True, overlap=ov)


def _transient_plan(
    record: int | None,
    fs: float,
    window: Any,
    overlap: Any,
    force_window_samples: int | None,
    exponential_end: float | None,
) -> SegmentPlan:
    if record is None:
        raise InputError(
            "method: 'transient' needs the record length: --segment N (command line), "
            "segment_samples= (Python) or the record length stored with the time data"
        )
    seg = as_count(record, "segment_samples", minimum=2)
    if overlap not in (None, 0, 0.0):
        raise InputError(f"overlap: the transient method uses whole records, got {overlap!r}")
    win = window if window is not None else "boxcar"
    values = segment_window(win, seg)
    input_window = None
    info: dict[str, Any] = {}
    if force_window_samples is not None:
        fw = as_count(force_window_samples, "force_window_samples", minimum=1)
        input_window = force_window(seg, min(fw, seg), min(max(fw // 10, 0), seg))
        info["force_window_samples"] = fw
    if exponential_end is not None:
        ew, tau = exponential_window(seg, fs, exponential_end)
        values = values * ew
        info["exponential_tau_s"] = tau
    return SegmentPlan(seg, seg, win, values, input_window, info=info)


def segment_plan(
    timedata: TimeData,
    choice: MethodChoice,
    window: str | tuple[str, float] | None,
    overlap: float | None,
    force_window_samples: int | None,
    exponential_end: float | None,
) -> SegmentPlan:
    """Segments of ``choice.method`` (cyclic, Welch or transient; see ``estimate_frf``)."""
    acq = timedata.acquisition
    if choice.method == "cyclic":
        p = choice.period_samples if choice.period_samples is not None else acq.period_samples
        return _cyclic_plan(p, window, overlap)
    if choice.method == "welch":
        return _welch_plan(timedata.n_samples, choice.segment_samples, window, overlap)
    rec = choice.segment_samples if choice.segment_samples is not None else acq.record_samples
    return _transient_plan(
        rec, timedata.sample_rate, window, overlap, force_window_samples, exponential_end
    )


def segment_starts(
    run_starts: Sequence[int], n: int, seg: int, step: int, settle: int
) -> NDArray[np.intp]:
    """First samples of the segments: within each run (``run_starts``), after settling."""
    r = np.asarray(run_starts, dtype=np.int64)
    stops = np.append(r[1:], n)
    out = [np.arange(a + settle, b - seg + 1, step) for a, b in zip(r, stops, strict=True)]
    return np.concatenate(out).astype(np.intp)


def plan_starts(timedata: TimeData, choice: MethodChoice, plan: SegmentPlan) -> NDArray[np.intp]:
    """First sample of every segment: at the detected hits (impacts), else run by run."""
    n, seg, settle = timedata.n_samples, plan.segment_samples, choice.settle_samples
    det = choice.detection
    if det is not None and det.kind == "impact" and choice.method == "transient":
        starts = np.array([a for a in det.record_starts if a >= settle and a + seg <= n], np.intp)
    else:
        starts = segment_starts(timedata.acquisition.run_starts, n, seg, plan.step_samples, settle)
    if starts.size == 0:
        raise InputError(
            f"timedata: no whole segment of {seg} samples ({choice.method} method) in {n} "
            f"samples after dropping {settle} settle samples"
        )
    return starts


def checked_starts(
    n: int, seg: int, step: int, start: int, starts: ArrayLike | None
) -> NDArray[np.intp]:
    """Segment starts of :func:`~tyredamp.signal.cross_spectra`: given, or every ``step``."""
    if starts is None:
        seg_starts = np.arange(start, n - seg + 1, step)
    else:
        seg_starts = np.asarray(starts)
        if seg_starts.ndim != 1 or not np.issubdtype(seg_starts.dtype, np.integer):
            raise InputError("starts: expected a 1-D array of integer sample indices")
        if seg_starts.size and (seg_starts.min() < 0 or seg_starts.max() > n - seg):
            raise InputError(f"starts: every segment of {seg} samples must lie in 0..{n}")
    if seg_starts.size == 0:
        raise InputError(
            f"segment_samples: a segment of {seg} samples from sample {start} does not fit in "
            f"{n} samples"
        )
    return seg_starts.astype(np.intp)


def segment_windows(
    window: str | tuple[str, float] | ArrayLike, input_window: ArrayLike | None, seg: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The window on all channels and the one on the inputs (times ``input_window``)."""
    if isinstance(window, str | tuple):
        w = segment_window(window, seg)
    else:
        w = as_finite(window, "window", ndim=1)
        if w.size != seg:
            raise ShapeError(f"window: expected {seg} samples, got {w.size}")
    w_in = w
    if input_window is not None:
        wi = as_finite(input_window, "input_window", ndim=1)
        if wi.size != seg:
            raise ShapeError(f"input_window: expected {seg} samples, got {wi.size}")
        w_in = w * wi
    return w, w_in
