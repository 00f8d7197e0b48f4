"""Checks with numbers: linearity, reciprocity and data quality (spec step 2).

Each check returns a :class:`CheckResult` holding the verdict, the figures it
is based on, the threshold and a one-line summary, so that a report can state
"linear to 0.8 % (threshold 5 %)" instead of showing a plot only.

Definitions (``||.||`` the Frobenius norm over the channel matrix at a line,
sums over the lines of the band):

* linearity, per line: ``d_l(f) = ||H_l(f) - H_0(f)|| / ||H_0(f)||`` for the
  FRFs ``H_l`` measured at the other force levels against the first (the
  reference level); overall: ``sqrt(sum ||H_l - H_0||^2 / sum ||H_0||^2)``,
  the largest over the levels. Passed when the overall figure is at most the
  threshold.
* reciprocity, for each pair of inputs ``a, b`` whose points are also
  measured as outputs: ``H_ba`` (response at ``b`` to a force at ``a``)
  against ``H_ab``; per line ``|H_ba - H_ab| / sqrt((|H_ba|^2 + |H_ab|^2)/2)``;
  overall ``sqrt(sum |H_ba - H_ab|^2 / sum (|H_ba|^2 + |H_ab|^2)/2)``, the
  largest over the pairs. Direction signs are taken into account.
* quality: samples flat-topped at a channel's extreme value (clipping or
  overload, see :func:`clipping`), channels of zeros, the fraction of lines whose multiple
  coherence is below a limit, and passivity of every drive point: a passive
  structure has ``Re Y_kk >= 0`` for the drive-point mobility ``Y_kk``; a line
  violates it when ``Re Y / |Y| < -(floor + k eps)``, with
  ``eps = sqrt((1 - gamma^2) / (2 n_avg gamma^2))`` the normalised random
  error of the estimate (Bendat & Piersol, Random Data, 4th ed., eq. 9.90).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError, ShapeError
from ..frf import FRF, Channel
from ..timedata import TimeData
from .estimators import estimate_frf
from .periodicity import detect_excitation

__all__ = [
    "CheckResult",
    "clipping",
    "dependent_forces",
    "linearity_check",
    "merge_inputs",
    "quality_check",
    "reciprocity_check",
]


@dataclass(frozen=True, eq=False)
class CheckResult:
    """Outcome of a check.

    Attributes
    ----------
    name : str
        ``"linearity"``, ``"reciprocity"`` or ``"quality"``.
    passed : bool
        The verdict.
    figure : float
        The main figure the verdict compares with ``threshold``.
    threshold : float
        The limit of ``figure`` (passed when ``figure <= threshold``, plus any
        further conditions listed in ``notes``).
    figures : dict of str to float
        All figures (fractions, not percent).
    summary : str
        One line with the verdict and the main figures.
    frequency : ndarray, shape (n_freq,) or None
        Lines of ``per_line`` in Hz.
    per_line : ndarray, shape (n_freq,) or None
        Per-line figure (deviation ratio, or for quality the lowest coherence).
    notes : tuple of str
        Further findings, one sentence each.
    """

    name: str
    passed: bool
    figure: float
    threshold: float
    figures: dict[str, float]
    summary: str
    frequency: NDArray[np.float64] | None = None
    per_line: NDArray[np.float64] | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __str__(self) -> str:
        return self.summary

    def report(self) -> str:
        """Multi-line text: the summary, every figure, the notes."""
        rows = [self.summary]
        rows += [f"  {k}: {_fmt(v)}" for k, v in self.figures.items()]
        rows += [f"  note: {n}" for n in self.notes]
        return "\n".join(rows)


def _fmt(v: float) -> str:
    return f"{v:d}" if isinstance(v, int) else f"{v:.6g}"


def _verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def _threshold(value: float, name: str) -> float:
    try:
        t = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number, got {value!r}") from None
    if not np.isfinite(t) or t < 0:
        raise InputError(f"{name}: expected a finite value >= 0, got {value!r}")
    return t


def _same_axis(a: FRF, b: FRF, what: str) -> None:
    if a.n_freq != b.n_freq or not np.allclose(a.frequency, b.frequency, rtol=1e-9, atol=0):
        raise ShapeError(
            f"{what}: expected the same frequency lines as the first FRF "
            f"({a.n_freq} lines {a.frequency[0]:g}-{a.frequency[-1]:g} Hz), got {b.n_freq} "
            f"lines {b.frequency[0]:g}-{b.frequency[-1]:g} Hz"
        )


def _same_point(a: Channel, b: Channel) -> bool:
    return a.node == b.node and abs(a.direction) == abs(b.direction)


def _sign(c: Channel) -> int:
    return -1 if c.direction < 0 else 1


def _ratio(num: NDArray[np.float64], den: NDArray[np.float64]) -> NDArray[np.float64]:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.where(num > 0, np.inf, 0.0))


# -------------------------------------------------------------- linearity
def _relative_rms(
    diff_pow: NDArray[np.float64], ref_pow: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]]:
    """Overall ``sqrt(sum d / sum ref)`` (inf for zero reference) and per line ``sqrt(d / ref)``."""
    total = ref_pow.sum()
    overall = float(np.sqrt(diff_pow.sum() / total)) if total > 0 else np.inf
    return overall, np.sqrt(_ratio(diff_pow, ref_pow))


def linearity_check(
    frfs: Sequence[FRF], threshold: float = 0.05, band: tuple[float, float] | None = None
) -> CheckResult:
    """Compare FRFs measured at two or more force levels.

    Parameters
    ----------
    frfs : sequence of FRF
        The same channels and lines, one FRF per force level; the first is the
        reference. Other kinds are converted to the first one's kind.
    threshold : float
        Largest accepted overall relative deviation (0.05 = 5 %).
    band : (float, float), optional
        Compare only lines in this band (Hz).

    Returns
    -------
    CheckResult
        ``figures``: ``overall_deviation`` (the verdict figure),
        ``max_line_deviation``, ``max_line_frequency_hz``, ``n_levels``;
        ``per_line`` the largest deviation over the levels at each line.
    """
    thr = _threshold(threshold, "threshold")
    if len(frfs) < 2:
        raise InputError(f"frfs: expected FRFs at two or more force levels, got {len(frfs)}")
    for i, f in enumerate(frfs):
        if not isinstance(f, FRF):
            raise InputError(f"frfs[{i}]: expected an FRF, got {type(f).__name__}")
    ref = frfs[0] if band is None else frfs[0].band(*band)
    others = []
    for i, f in enumerate(frfs[1:], start=1):
        g = f.to(ref.kind) if f.kind != ref.kind else f
        g = g if band is None else g.band(*band)
        _same_axis(ref, g, f"frfs[{i}]")
        chans, ref_chans = g.outputs + g.inputs, ref.outputs + ref.inputs
        if g.H.shape != ref.H.shape or not all(
            _same_point(a, b) for a, b in zip(chans, ref_chans, strict=True)
        ):
            raise ShapeError(
                f"frfs[{i}]: expected the same output and input channels as frfs[0] "
                f"({[c.label for c in ref.outputs]} x {[c.label for c in ref.inputs]}), got "
                f"{[c.label for c in g.outputs]} x {[c.label for c in g.inputs]}"
            )
        others.append(g)
    h0 = ref.H
    ref_pow = np.sum(np.abs(h0) ** 2, axis=(0, 1))  # (f,)
    per_level = []
    lines = []
    for g in others:
        d = np.sum(np.abs(g.H - h0) ** 2, axis=(0, 1))
        overall_g, line_g = _relative_rms(d, ref_pow)
        per_level.append(overall_g)
        lines.append(line_g)
    per_line = np.max(np.array(lines), axis=0)
    overall = max(per_level)
    iw = int(np.argmax(per_line))
    passed = overall <= thr
    figures: dict[str, float] = {
        "overall_deviation": overall,
        "max_line_deviation": float(per_line[iw]),
        "max_line_frequency_hz": float(ref.frequency[iw]),
        "n_levels": len(frfs),
    }
    summary = (
        f"linearity: {_verdict(passed)} - FRFs at {len(frfs)} levels differ by "
        f"{100 * overall:.3g} % RMS from the first (threshold {100 * thr:.3g} %); largest "
        f"line deviation {100 * per_line[iw]:.3g} % at {ref.frequency[iw]:.4g} Hz"
    )
    notes = tuple(
        f"level {i}: overall deviation {100 * v:.3g} %" for i, v in enumerate(per_level, start=1)
    )
    return CheckResult(
        "linearity", passed, overall, thr, figures, summary, ref.frequency.copy(), per_line, notes
    )


# ------------------------------------------------------------ reciprocity
def merge_inputs(frfs: Sequence[FRF]) -> FRF:
    """Join FRFs of separate tests (one or more inputs each) into one matrix.

    All must have the same kind (others are converted), lines and outputs;
    the inputs are concatenated. The coherence is kept only for one FRF; the
    variance when every FRF has one (each column keeps its own).
    """
    if len(frfs) == 0:
        raise InputError("frfs: expected at least one FRF")
    base = frfs[0]
    if len(frfs) == 1:
        return base
    hs = [base.H]
    vs = [base.variance]
    ins = list(base.inputs)
    for i, f in enumerate(frfs[1:], start=1):
        g = f.to(base.kind) if f.kind != base.kind else f
        _same_axis(base, g, f"frfs[{i}]")
        if g.n_out != base.n_out or not all(
            _same_point(a, b) for a, b in zip(g.outputs, base.outputs, strict=True)
        ):
            raise ShapeError(f"frfs[{i}]: expected the same outputs as frfs[0]")
        hs.append(g.H)
        vs.append(g.variance)
        ins += list(g.inputs)
    return FRF(
        base.frequency,
        np.concatenate(hs, axis=1),
        kind=base.kind,
        outputs=base.outputs,
        inputs=ins,
        meta={"merged_from": len(frfs)},
        variance=None if any(v is None for v in vs) else np.concatenate(vs, axis=1),  # type: ignore[arg-type]
    )


def reciprocity_check(
    frf: FRF, threshold: float = 0.05, band: tuple[float, float] | None = None
) -> CheckResult:
    """Compare ``H_jk`` with ``H_kj`` for every reciprocal pair in an FRF matrix.

    Parameters
    ----------
    frf : FRF
        At least two inputs whose points (node and direction) also appear as
        outputs (see :func:`merge_inputs` for separate tests).
    threshold : float
        Largest accepted overall relative difference (0.05 = 5 %).
    band : (float, float), optional
        Compare only lines in this band (Hz).

    Returns
    -------
    CheckResult
        ``figures``: ``overall_difference`` (verdict figure, the largest over
        the pairs), ``max_line_difference``, ``max_line_frequency_hz``,
        ``n_pairs``.
    """
    thr = _threshold(threshold, "threshold")
    if not isinstance(frf, FRF):
        raise InputError(f"frf: expected an FRF, got {type(frf).__name__}")
    g = frf if band is None else frf.band(*band)
    pairs: list[tuple[int, int, int, int]] = []  # (i_out, a_in, j_out, b_in)
    for a in range(g.n_in):
        for b in range(a + 1, g.n_in):
            at_b = [k for k, c in enumerate(g.outputs) if _same_point(c, g.inputs[b])]
            at_a = [k for k, c in enumerate(g.outputs) if _same_point(c, g.inputs[a])]
            if at_b and at_a:
                pairs.append((at_b[0], a, at_a[0], b))
    if not pairs:
        raise InputError(
            "frf: reciprocity needs two inputs whose points are also measured as outputs; got "
            f"inputs {[c.label for c in g.inputs]} and outputs {[c.label for c in g.outputs]}"
        )
    per_pair, lines, labels = [], [], []
    for i, a, j, b in pairs:
        h1 = _sign(g.outputs[i]) * _sign(g.inputs[a]) * g.H[i, a]
        h2 = _sign(g.outputs[j]) * _sign(g.inputs[b]) * g.H[j, b]
        d = np.abs(h1 - h2) ** 2
        m = 0.5 * (np.abs(h1) ** 2 + np.abs(h2) ** 2)
        overall_p, line_p = _relative_rms(d, m)
        per_pair.append(overall_p)
        lines.append(line_p)
        labels.append(
            f"{g.outputs[i].label}/{g.inputs[a].label} vs {g.outputs[j].label}/{g.inputs[b].label}"
        )
    per_line = np.max(np.array(lines), axis=0)
    overall = max(per_pair)
    iw = int(np.argmax(per_line))
    passed = overall <= thr
    figures: dict[str, float] = {
        "overall_difference": overall,
        "max_line_difference": float(per_line[iw]),
        "max_line_frequency_hz": float(g.frequency[iw]),
        "n_pairs": len(pairs),
    }
    summary = (
        f"reciprocity: {_verdict(passed)} - {len(pairs)} pair(s) differ by up to "
        f"{100 * overall:.3g} % RMS (threshold {100 * thr:.3g} %); largest line difference "
        f"{100 * per_line[iw]:.3g} % at {g.frequency[iw]:.4g} Hz"
    )
    notes = tuple(f"{lab}: {100 * v:.3g} %" for lab, v in zip(labels, per_pair, strict=True))
    return CheckResult(
        "reciprocity", passed, overall, thr, figures, summary, g.frequency.copy(), per_line, notes
    )


# ---------------------------------------------------------------- quality
def clipping(
    x: NDArray[np.float64], min_run: int = 3, repeats: int = 1, min_fraction: float = 1e-4
) -> int:
    """Number of samples flat-topped at the signal's maximum or minimum (0 if none).

    An overloaded amplifier or ADC holds the signal at its limit: the extreme
    value appears in runs of consecutive samples, or (when the signal changes
    fast between samples) many times over the record. Samples exactly equal to
    ``max(x)`` (likewise ``min(x)``) count as clipped when they form a run of
    ``min_run`` or more, or when there are more than ``repeats`` of them and at
    least ``min_fraction`` of the record (an unclipped periodic signal repeats
    its extreme once per period, so pass ``repeats`` = number of periods). A
    signal of zeros returns 0 (a dead channel, reported separately).

    Parameters
    ----------
    x : ndarray, shape (n_samples,)
    min_run : int
        Shortest run counted (>= 2).
    repeats : int
        Occurrences of the extreme value accepted without a run (>= 1).
    min_fraction : float
        Smallest fraction of the record that scattered extreme samples must
        reach to count.

    Returns
    -------
    int
        Samples at the extremes when clipping is detected, else 0.
    """
    if int(min_run) != min_run or min_run < 2:
        raise InputError(f"min_run: expected an integer >= 2, got {min_run!r}")
    if int(repeats) != repeats or repeats < 1:
        raise InputError(f"repeats: expected an integer >= 1, got {repeats!r}")
    if not np.any(x):
        return 0
    total = 0
    for extreme in (x.max(), x.min()):
        hit = x == extreme
        count = int(hit.sum())
        at = np.concatenate(([0], hit.astype(np.int8), [0]))
        edges = np.diff(at)
        runs = np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)
        scattered = count > repeats and count >= max(3.0, min_fraction * x.size)
        if runs.max() >= min_run or scattered:
            total += count
    return total


def _low_bands(f: NDArray[np.float64], low: NDArray[np.bool_], limit: int = 5) -> list[str]:
    at = np.concatenate(([0], low.astype(np.int8), [0]))
    e = np.diff(at)
    starts, stops = np.flatnonzero(e == 1), np.flatnonzero(e == -1) - 1
    out = [
        f"{f[a]:.4g} Hz" if a == b else f"{f[a]:.4g}-{f[b]:.4g} Hz"
        for a, b in zip(starts, stops, strict=True)
    ]
    if len(out) > limit:
        out = [*out[:limit], f"... ({len(out) - limit} more)"]
    return out


def _passivity(
    frf: FRF, floor: float, ksig: float, figures: dict[str, float], notes: list[str]
) -> float | None:
    """Fraction of drive-point lines with ``Re Y / |Y|`` below ``-(floor + ksig eps)``.

    ``eps`` is the normalised random error of the estimate from the
    coherence and the number of averages. Adds the figures and notes; ``None``
    without a drive point.
    """
    dps = frf.drive_points()
    figures["drive_points"] = len(dps)
    if not dps:
        notes.append("no drive point (no output at an input's point): passivity not checked")
        return None
    mob = frf.to("mobility")
    n_avg = int(frf.meta.get("n_averages", 0) or 0)
    viol, total, worst = 0, 0, np.inf
    for i, j in dps:
        y = _sign(mob.outputs[i]) * _sign(mob.inputs[j]) * mob.H[i, j]
        mag = np.abs(y)
        r = _ratio(y.real, mag)
        r = np.where(mag > 0, r, 0.0)
        eps = np.zeros_like(r)
        if mob.coherence is not None and n_avg > 0:
            g2 = np.clip(mob.coherence[i], 1e-12, 1.0)
            eps = np.sqrt((1 - g2) / (2 * n_avg * g2))
        v = r < -(floor + ksig * eps)
        viol += int(v.sum())
        total += r.size
        worst = min(worst, float(r.min()))
        if v.any():
            notes.append(
                f"drive point {mob.outputs[i].label}: Re(mobility) < 0 beyond noise at "
                f"{int(v.sum())} lines ({', '.join(_low_bands(mob.frequency, v, 3))})"
            )
    pfrac = viol / total if total else 0.0
    figures["passivity_violations"] = viol
    figures["passivity_fraction"] = pfrac
    figures["min_drive_point_real_ratio"] = worst
    return pfrac


def _clipping_and_dead(
    data: TimeData, clip_run: int, figures: dict[str, float], problems: list[str], notes: list[str]
) -> None:
    """Clipped and dead channels of ``quality_check`` into its figures, problems and notes."""
    period = data.acquisition.period_samples
    live = [i for i in data.force_indices if np.any(data.data[i])]
    if period is None and live:
        # a periodic test without metadata repeats its extreme once per period
        det = detect_excitation(data.data[live])
        period = det.period_samples if det.kind == "periodic" else None
    reps = max(1, data.n_samples // int(period)) if period else 1
    clipped = {c.label: clipping(data.data[i], clip_run, reps) for i, c in enumerate(data.channels)}
    bad = {k: v for k, v in clipped.items() if v > 0}
    dead = [c.label for i, c in enumerate(data.channels) if not np.any(data.data[i])]
    figures["clipped_channels"] = len(bad)
    figures["clipped_samples"] = int(sum(bad.values()))
    figures["dead_channels"] = len(dead)
    if bad:
        problems.append(f"{len(bad)} clipped channel(s)")
        notes += [f"channel {k}: {v} flat-topped samples at its extreme" for k, v in bad.items()]
    if dead:
        problems.append(f"{len(dead)} channel(s) of zeros")
        notes.append(f"channels of zeros: {', '.join(dead)}")


def quality_check(
    data: TimeData | FRF,
    *,
    coherence_min: float = 0.9,
    max_low_coherence_fraction: float = 0.1,
    clip_run: int = 3,
    passivity_floor: float = 0.02,
    passivity_sigma: float = 3.0,
    max_passivity_fraction: float = 0.01,
    band: tuple[float, float] | None = None,
    **estimate_kwargs: Any,
) -> CheckResult:
    """Data quality of a test: clipping, dead channels, coherence, passivity.

    Parameters
    ----------
    data : TimeData or FRF
        Time data (all checks; the FRF is estimated with
        :func:`~tyredamp.signal.estimators.estimate_frf` and
        ``estimate_kwargs``) or an FRF (coherence and passivity only).
    coherence_min : float
        Lines with multiple coherence below this count as low.
    max_low_coherence_fraction : float
        Largest accepted fraction of low-coherence (output, line) pairs among
        those where the output's response is strong (above its median
        magnitude over the band; the verdict figure and threshold). Low
        coherence where the response is weak (antiresonances, nodal points)
        is expected with any output noise and is reported as a note.
    clip_run : int
        Shortest run of equal samples at a channel extreme counted as
        clipping (see :func:`clipping`; with ``acquisition.period_samples``, or the
        period detected from the force by
        :func:`~tyredamp.signal.periodicity.detect_excitation`, one repeat
        of the extreme per period is accepted).
    passivity_floor : float
        Allowed negative ``Re Y / |Y|`` at a drive point besides the random
        error (0.02 is about 1 degree of phase error).
    passivity_sigma : float
        Multiple of the normalised random error added to the floor.
    max_passivity_fraction : float
        Largest accepted fraction of drive-point lines violating passivity.
    band : (float, float), optional
        Judge coherence and passivity only on the lines of this band (Hz).

    Returns
    -------
    CheckResult
        Passed when no channel is clipped or dead, the low-coherence fraction
        is within its threshold and the passivity violations are within theirs.
    """
    cmin = _threshold(coherence_min, "coherence_min")
    thr = _threshold(max_low_coherence_fraction, "max_low_coherence_fraction")
    floor = _threshold(passivity_floor, "passivity_floor")
    ksig = _threshold(passivity_sigma, "passivity_sigma")
    pthr = _threshold(max_passivity_fraction, "max_passivity_fraction")
    notes: list[str] = []
    figures: dict[str, float] = {}
    problems: list[str] = []
    frf: FRF | None
    if isinstance(data, TimeData):
        _clipping_and_dead(data, clip_run, figures, problems, notes)
        dead_force = [i for i in data.force_indices if not np.any(data.data[i])]
        if dead_force or not data.force_indices or not data.response_indices:
            frf = None
            notes.append("no FRF estimated (no usable force or response channel)")
        else:
            frf = estimate_frf(data, **estimate_kwargs)
    elif isinstance(data, FRF):
        frf = data
    else:
        raise InputError(f"data: expected TimeData or FRF, got {type(data).__name__}")

    if frf is not None and band is not None:
        frf = frf.band(*band)
    low_frac = all_frac = 0.0
    per_line = freq = None
    if frf is not None and frf.coherence is not None:
        low_frac, all_frac = _coherence(frf, frf.coherence, cmin, thr, figures, notes, problems)
        freq, per_line = frf.frequency.copy(), frf.coherence.min(axis=0)
    elif frf is not None:
        notes.append("no coherence available: coherence check skipped")

    if frf is not None:
        pfrac = _passivity(frf, floor, ksig, figures, notes)
        if pfrac is not None and pfrac > pthr:
            problems.append(f"drive point not passive at {100 * pfrac:.3g} % of lines")
    passed = not problems
    what = "; ".join(problems) if problems else "no clipping, coherence and passivity within limits"
    summary = (
        f"quality: {_verdict(passed)} - {what} (low-coherence lines where the response is "
        f"strong {100 * low_frac:.3g} %, threshold {100 * thr:.3g} %; over all lines "
        f"{100 * all_frac:.3g} %)"
    )
    return CheckResult(
        "quality", passed, low_frac, thr, figures, summary, freq, per_line, tuple(notes)
    )


def _coherence(
    frf: FRF,
    coh: NDArray[np.float64],
    cmin: float,
    thr: float,
    figures: dict[str, float],
    notes: list[str],
    problems: list[str],
) -> tuple[float, float]:
    """The coherence part of :func:`quality_check`: low-coherence fractions where the
    response is strong (the verdict figure) and over all lines; adds figures, notes
    and problems."""
    low = coh < cmin
    strong = _strong_response(frf)
    all_frac = float(np.mean(low))
    low_frac = float(np.mean(low[strong]))
    figures["low_coherence_fraction"] = low_frac
    figures["low_coherence_fraction_all_lines"] = all_frac
    figures["min_coherence"] = float(coh.min())
    figures["mean_coherence"] = float(coh.mean())
    bands = _low_bands(frf.frequency, np.mean(low, axis=0) >= 0.5)
    if bands:
        notes.append(f"coherence below {cmin:g} on most outputs in: {', '.join(bands)}")
    weak_low = float(np.mean(low[~strong])) if np.any(~strong) else 0.0
    if weak_low > thr and low_frac <= thr:
        notes.append(
            f"coherence below {cmin:g} on {100 * weak_low:.3g} % of the lines where the "
            "response is weak (antiresonances, nodal points): the output noise there, "
            "expected at any finite signal-to-noise ratio"
        )
    if low_frac > thr:
        problems.append(
            f"{100 * low_frac:.3g} % of the lines with a strong response have coherence < {cmin:g}"
        )
    if frf.meta.get("n_averages") == 1:
        notes.append("one average only: the coherence is 1 by construction")
    return low_frac, all_frac


def _strong_response(frf: FRF) -> NDArray[np.bool_]:
    """Lines where each output's response is strong: ``max_in |H|`` above its median over the band.

    Coherence is judged there (shape (n_out, n_freq)): with any output noise
    the coherence drops at antiresonances and nodal points, where the
    response falls towards the noise, and that says nothing about the
    measurement; low coherence where the response is strong (near the
    resonances) does: leakage, non-linearity, unmeasured inputs or noise that
    buries the modes themselves.
    """
    mag = np.max(np.abs(frf.H), axis=1)  # (n_out, n_freq)
    return mag >= np.median(mag, axis=1, keepdims=True)


def dependent_forces(
    data: TimeData, channels: Sequence[int] | None = None, min_r2: float = 0.95
) -> list[tuple[int, float, list[int]]]:
    """Force channels that are an instantaneous linear combination of other channels.

    An excitation force is independent of the other channels sample by
    sample; a reaction force measured beside it (the ground force of a
    vehicle body driven by a shaker: ``F_ground = F_body - m a``) is a linear
    combination of the excitation and a response. Each force channel is
    regressed by least squares on every other channel (and a constant); a
    coefficient of determination ``R^2`` above ``min_r2`` (default 0.95:
    what is left is at most 5 % of its variance, the noise of a measured
    channel) marks it as dependent. Dynamic relations (a response to several
    shakers) are not instantaneous and give low ``R^2`` (about 0.5 on the
    virtual tyre driven at two points).

    Parameters
    ----------
    data : TimeData
    channels : sequence of int, optional
        Force channels to test (indices); default every force channel.
    min_r2 : float
        Threshold of ``R^2``, 0 < min_r2 < 1.

    Returns
    -------
    list of (int, float, list of int)
        ``(channel, R^2, channels of the combination)`` for each dependent
        force; the combination lists the channels whose coefficients carry
        at least 1 % of the fitted variance.
    """
    if not 0 < min_r2 < 1:
        raise InputError(f"min_r2: expected 0 < min_r2 < 1, got {min_r2}")
    idx = list(data.force_indices) if channels is None else [int(c) for c in channels]
    out = []
    x_all = data.data
    for k in idx:
        y = x_all[k] - x_all[k].mean()
        vy = float(np.mean(y**2))
        if vy == 0:
            continue
        others = [i for i in range(data.n_channels) if i != k]
        x = np.column_stack([x_all[i] - x_all[i].mean() for i in others])
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        fit = x @ coef
        r2 = 1.0 - float(np.mean((y - fit) ** 2)) / vy
        if r2 > min_r2:
            part = (coef * np.sqrt(np.mean(x**2, axis=0))) ** 2
            uses = [others[j] for j in np.flatnonzero(part >= 0.01 * part.sum())]
            out.append((k, r2, uses))
    return out
