"""One FRF per record: the hits of an impact test (or the segments of any averaged
estimate) as independent measurements of the same FRFs.

An averaged FRF hides whether a weak resonance is in every record or only in
their average. Each record's own FRF, on the lines of the averaged estimate,
is what a replicate check needs (``tyredamp modal --replicate``,
:mod:`tyredamp.modal.replicates`): a mode of the structure is found again in
each record, noise or an artefact of one fit is not (Ewins, *Modal Testing*,
2nd ed. 2000, sec. 3.11: repeated measurements as the check of a result).

A record's FRF is the estimator of :func:`~tyredamp.signal.estimate_frf` on
that record alone (the same segment, windows, force window, exponential window
and detrend; with one average ``H1 = H2 = Y / X`` at each line), so the
average of the records' cross spectra is the averaged estimate's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..frf import FRF, Channel
from ..timedata import TimeData
from .estimators import Estimator, _resolve_io, cross_spectra, estimate_frf, frf_from_spectra
from .segmenting import Method, SegmentPlan, choose_method, plan_starts, segment_plan

__all__ = ["estimate_record_frfs"]


def estimate_record_frfs(
    timedata: TimeData,
    estimator: Estimator = "H1",
    reference: Sequence[Channel | int | str] | Channel | int | str | None = None,
    method: Method | None = None,
    **options: Any,
) -> tuple[FRF, list[FRF]]:
    """The averaged FRF of :func:`~tyredamp.signal.estimate_frf` and one FRF per record.

    Parameters
    ----------
    timedata, estimator, reference, method
        As :func:`~tyredamp.signal.estimate_frf`.
    **options
        The keyword arguments of :func:`~tyredamp.signal.estimate_frf`
        (``period_samples``, ``segment_samples``, ``settle_samples``, ``band``,
        ``window``, ...).

    Returns
    -------
    frf : FRF
        The averaged estimate, exactly as ``estimate_frf`` returns it.
    records : list of FRF
        One FRF per record (segment) the average is made of, on the same lines,
        with ``meta["record"]`` (1-based), ``meta["record_start_sample"]`` and
        no coherence or variance (one average has none).

    Raises
    ------
    InputError
        Several force inputs (one record cannot separate them), a local method
        (``lrm``/``lpm``, which have no records), or fewer than two records.
    """
    frf = estimate_frf(timedata, estimator, reference, method, **options)
    ref_idx, out_idx, _ = _resolve_io(timedata, estimator, reference, options.get("outputs"))
    if len(ref_idx) > 1:
        raise InputError(
            f"records: {len(ref_idx)} force inputs; one record cannot separate several "
            "inputs (their FRFs need at least as many averages as inputs); give one "
            "force with --reference"
        )
    choice = choose_method(
        timedata,
        ref_idx,
        out_idx,
        method,
        options.get("period_samples"),
        options.get("settle_samples"),
        options.get("segment_samples"),
        options.get("detect", True),
    )
    if choice.method in ("lrm", "lpm"):
        raise InputError(
            f"records: the {choice.method} method fits the whole record at once and has "
            "no records; use the transient, cyclic or Welch method"
        )
    plan = segment_plan(
        timedata,
        choice,
        options.get("window"),
        options.get("overlap"),
        options.get("force_window_samples"),
        options.get("exponential_end"),
    )
    starts = plan_starts(timedata, choice, plan)
    if starts.size < 2:
        raise InputError(
            f"records: the estimate holds {starts.size} record; replicates need at least two"
        )
    return frf, [
        _record(timedata, frf, (ref_idx, out_idx), estimator, plan, int(s), k)
        for k, s in enumerate(starts, start=1)
    ]


def _record(
    timedata: TimeData,
    frf: FRF,
    io: tuple[list[int], list[int]],
    estimator: Estimator,
    plan: SegmentPlan,
    start: int,
    k: int,
) -> FRF:
    """The FRF of the record starting at sample ``start`` on the lines of ``frf``."""
    ref_idx, out_idx = io
    sp = cross_spectra(
        timedata.data[ref_idx],
        timedata.data[out_idx],
        timedata.sample_rate,
        plan.segment_samples,
        starts=np.array([start], dtype=np.intp),
        window=plan.window_values,
        input_window=plan.input_window,
        detrend=plan.detrend,
    )
    # the averaged estimate's lines are a subset of the record's DFT lines (same length)
    idx = np.rint(frf.frequency * plan.segment_samples / timedata.sample_rate).astype(np.intp)
    idx = np.clip(idx, 0, sp.frequency.size - 1)
    if not np.allclose(sp.frequency[idx], frf.frequency, rtol=1e-9, atol=0.0):
        raise InputError("records: the records' lines differ from the averaged estimate's")
    sp = sp.select_lines(idx)
    meta = {
        **{k_: v for k_, v in frf.meta.items() if k_ != "detection"},
        "n_averages": 1,
        "record": k,
        "record_start_sample": start,
    }
    return FRF(
        frf.frequency,
        frf_from_spectra(sp, estimator),
        kind=frf.kind,
        outputs=list(frf.outputs),
        inputs=list(frf.inputs),
        meta=meta,
    )
