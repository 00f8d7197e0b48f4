"""Automatic model order of the stabilisation diagram (rules in :mod:`tyredamp.modal.identify`).

:func:`settle_order` computes the diagram of the starting order with the pole
estimator and raises the order by the sizing rule and by trials of an
unsettled diagram, as the docstring of :mod:`tyredamp.modal.identify` states,
up to :func:`order_cap`: twice the roots the sizing rule asks for the
resonances the data show (:func:`modes_shown`; with several inputs each may be
a repeated root of as many modes as inputs), so that the order follows the
modes of the band and not its number of lines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..problem.problem import FitProblem
from ..statistics.stats import FALSE_ALARM, difference_noise
from .estimators import PoleEstimator
from .lscf import PoleSet
from .selection import Cluster, StabilityFlags, cluster_poles, stability_flags

__all__ = [
    "Diagram",
    "SelectionRules",
    "default_order",
    "modes_shown",
    "order_cap",
    "order_limit",
    "settle_order",
]

#: lines per block of the mode indicator of :func:`modes_shown`
_BLOCK = 16384
#: most points of the indicator whose peaks :func:`modes_shown` examines
_PEAK_POINTS = 8192

#: automatic order (identify docstring): a stabilisation diagram is settled when at
#: least this share of its stable poles belongs to persistent clusters. Settled
#: diagrams of the test cases (virtual tyre, rings, synthetic 6-20 modes at 20-60 dB)
#: have 0.67-1.0; a band with more modes than the order can hold has 0.1-0.55
_SETTLED_SHARE = 2.0 / 3.0
#: when no mode is stable at the automatic order cap, the order is doubled up to
#: this many times the cap (a 20 dB corpus system of 37 modes had none at its cap, 20)
ESCALATE = 4


@dataclass(frozen=True)
class SelectionRules:
    """Rules of the stabilisation diagram (:mod:`tyredamp.modal.poles.selection`)."""

    order_step: int = 2
    max_damping: float = 0.2
    cluster_distance: float = 0.01
    min_fraction: float = 0.3


@dataclass(frozen=True)
class Diagram:
    """A stabilisation diagram: poles of all orders, flags, kept and weak clusters."""

    order: int
    poles: PoleSet
    flags: StabilityFlags
    kept: list[Cluster]
    weak: list[Cluster]
    max_damping: float = 0.2

    def persistent_share(self) -> float:
        """Share of the stable poles in the persistent clusters (0 when none is stable)."""
        n_stable = int(np.count_nonzero(self.flags.stable))
        if n_stable == 0:
            return 0.0
        return sum(c.members.size for c in self.kept) / n_stable


def order_limit(n_in: int, n_f: int) -> int:
    """Highest order the lines allow: ``2 n_f / (n_in + 1) - 2``."""
    return (2 * n_f) // (n_in + 1) - 2


def default_order(n_in: int, n_f: int, n_modes: int | None) -> int:
    """Starting order: ``ceil(60 / n_in)``, or ``ceil((4 n_modes + 16) / n_in)`` (>= 30 / n_in)."""
    base = 60 if n_modes is None else max(30, 4 * n_modes + 16)
    p = int(np.ceil(base / n_in))
    return max(2, min(p, order_limit(n_in, n_f)))


def modes_shown(problem: FitProblem, false_alarm: float = FALSE_ALARM) -> int:
    """Number of resonance peaks the data show above their noise.

    The indicator is ``r(f) = (sum_jk |H_jk(f)|^2 / s_j^2)^(1/2)``, the FRFs
    in units of each output's noise ``s_j`` (from second differences of
    adjacent lines, :func:`~tyredamp.modal.statistics.stats.difference_noise`). The noise
    moves ``r`` by about one unit at any level (``|h + e| - |h|`` has a
    standard deviation below 1 for ``e`` of unit variance), and the largest of
    ``n_f`` such excursions stays below ``z = (2 ln(n_f / alpha))^(1/2)`` with
    probability about ``1 - alpha`` (the Gaussian tail bound with a Bonferroni
    factor over the lines, ``alpha = false_alarm``). A local maximum counts as a
    peak when it rises more than ``2 z`` above the higher of the two minima that
    separate it from higher ground (its topographic prominence,
    :func:`prominent_peaks`): a maximum and a minimum can each be moved
    by ``z``. Close modes that share one peak count once, so this is a lower
    bound of the modes in the band; it does not grow with the number of lines
    when the lines only sample the same resonances more finely.
    """
    H = problem.H
    n_f = H.shape[-1]
    if n_f < 3:
        return 0
    var = difference_noise(H)
    s2 = np.where(np.isfinite(var) & (var > 0), var, np.inf)
    if not np.all(np.isfinite(s2)):
        # noise-free or too few lines: a noise floor at the data's rounding
        rms2 = np.mean(H.real**2 + H.imag**2, axis=(1, 2))
        s2 = np.where(np.isfinite(s2), s2, np.maximum(1e-20 * rms2, 1e-300))
    r = np.empty(n_f)
    for i in range(0, n_f, _BLOCK):
        h = H[:, :, i : i + _BLOCK]
        r[i : i + _BLOCK] = np.einsum("jkf,j->f", h.real**2 + h.imag**2, 1.0 / s2)
    np.sqrt(r, out=r)
    z = math.sqrt(2.0 * math.log(n_f / false_alarm))
    if n_f > 2 * _PEAK_POINTS:
        # the prominence of every noise maximum of a long axis costs more than the
        # identification: the largest value of each of _PEAK_POINTS windows keeps
        # every resonance wider than two windows (closer ones count once)
        k = n_f // _PEAK_POINTS
        r = r[: k * _PEAK_POINTS].reshape(_PEAK_POINTS, k).max(axis=1)
    return int(prominent_peaks(r, 2.0 * z).size)


def prominent_peaks(r: NDArray[np.float64], prominence: float) -> NDArray[np.intp]:
    """Indices of the local maxima of ``r`` whose topographic prominence exceeds
    ``prominence`` (the peaks of :func:`scipy.signal.find_peaks` with that
    ``prominence``, without importing :mod:`scipy.signal`).

    A maximum is a sample, or the middle of a run of equal samples, higher than
    both neighbours (the two ends are never maxima). From a maximum of value
    ``v`` the interval on each side runs to the first sample higher than ``v``
    (or to the end of ``r``); the prominence is ``v`` less the higher of the two
    intervals' minima (the key col on the way to higher ground). The nearest
    higher samples come from a monotonic stack and the minima from a sparse
    table of range minima: ``O(n log n)``.
    """
    r = np.asarray(r, dtype=float)
    n = r.size
    if n < 3:
        return np.zeros(0, dtype=np.intp)
    # maxima: a rise into a run of equal values followed by a fall
    edges = np.flatnonzero(np.diff(r)) + 1  # starts of runs of equal values
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges - 1, [n - 1]])
    inner = (starts > 0) & (ends < n - 1)
    starts, ends = starts[inner], ends[inner]
    peak = (r[starts - 1] < r[starts]) & (r[ends + 1] < r[starts])
    k = (starts[peak] + ends[peak]) // 2
    if k.size == 0:
        return np.zeros(0, dtype=np.intp)
    left, right = _nearest_higher(r)
    lo = left[k] + 1
    hi = right[k] - 1
    table = [r]  # table[j][i] = min(r[i : i + 2^j])
    while (1 << len(table)) <= n:
        w = 1 << (len(table) - 1)
        table.append(np.minimum(table[-1][:-w], table[-1][w:]))

    def range_min(a: NDArray[np.intp], b: NDArray[np.intp]) -> NDArray[np.float64]:
        # min of r[a..b] (inclusive): two overlapping windows of the largest width
        lvl = np.floor(np.log2(b - a + 1)).astype(np.intp)
        out = np.empty(a.size)
        for j in np.unique(lvl):
            sel = lvl == j
            t = table[j]
            out[sel] = np.minimum(t[a[sel]], t[b[sel] - (1 << j) + 1])
        return out

    col = np.maximum(range_min(lo, k), range_min(k, hi))
    return np.asarray(k[r[k] - col > prominence], dtype=np.intp)


def _nearest_higher(r: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """For each sample, the index of the nearest strictly higher sample to the
    left (-1 when none) and to the right (``n`` when none): monotonic stacks."""
    n = r.size
    v = r.tolist()
    left = np.full(n, -1, dtype=np.intp)
    right = np.full(n, n, dtype=np.intp)
    stack: list[int] = []
    for i in range(n):
        while stack and v[stack[-1]] <= v[i]:
            stack.pop()
        if stack:
            left[i] = stack[-1]
        stack.append(i)
    stack = []
    for i in range(n - 1, -1, -1):
        while stack and v[stack[-1]] <= v[i]:
            stack.pop()
        if stack:
            right[i] = stack[-1]
        stack.append(i)
    return left, right


def order_cap(n_in: int, n_f: int, p_start: int, n_shown: int) -> int:
    """Highest automatic order: ``max(p_start, ceil(8 (n_in n_shown + 2) / n_in))``, at
    most :func:`order_limit`: twice the roots the sizing rule asks for the modes the
    peaks shown can hold (with several inputs a peak can hold a repeated root, up to
    ``n_in`` modes at one pole)."""
    modes = n_in * n_shown
    return max(2, min(order_limit(n_in, n_f), max(p_start, math.ceil(8 * (modes + 2) / n_in))))


def shown_order(n_in: int, n_shown: int) -> int:
    """The order the sizing rule asks for the modes ``n_shown`` peaks can hold:
    ``ceil(4 (n_in n_shown + 2) / n_in)`` (with several inputs a peak can hold up to
    ``n_in`` modes, as in :func:`order_cap`)."""
    return math.ceil(2 * 2 * (n_in * n_shown + 2) / n_in)


def _peaks_trial(
    problem: FitProblem, estimator: PoleEstimator, rules: SelectionRules, cur: Diagram, p: int
) -> Diagram:
    """Several inputs: the settled diagram ``cur`` against a trial at order ``p``
    (:func:`shown_order` of the peaks shown), kept when it holds more persistent
    clusters and is settled itself (``_SETTLED_SHARE``) or has the larger
    persistent share (the rule of the trial raises of :func:`settle_order`: the
    modes resolved there form columns; an order only too high adds noise poles
    and lowers the share, below that of a settled diagram). With several inputs
    a settled diagram of a low order can meet the sizing rule with few of the
    modes resolved (20 modes, 2 inputs, order 30: 8-15 persistent clusters; 30
    modes, 3 inputs, order 43: 17, at a share of 0.90 against 0.83 for the 30 of
    order 119), and the search then adds the others one refit at a time, into
    worse optima (a model error of 0.2-17 % of the response, minutes)."""
    if p <= cur.order:
        return cur
    trial = diagram(problem, estimator, p, rules)
    more = len(trial.kept) > len(cur.kept)
    share = trial.persistent_share()
    return trial if more and (share >= _SETTLED_SHARE or share > cur.persistent_share()) else cur


def diagram(
    problem: FitProblem, estimator: PoleEstimator, p: int, rules: SelectionRules
) -> Diagram:
    """Diagram of orders ``p / 4 .. p`` (lower orders do not count for persistence)."""
    f = problem.frequency
    ps = estimator(
        f,
        problem.H,
        p,
        band=(float(f[0]), float(f[-1])),
        min_order=max(1, p // 4),
        order_step=rules.order_step,
    )
    flags = stability_flags(ps, band=problem.band, max_damping=rules.max_damping)
    kept, weak = cluster_poles(
        ps, flags, cluster_distance=rules.cluster_distance, min_fraction=rules.min_fraction
    )
    return Diagram(p, ps, flags, kept, weak, rules.max_damping)


def settle_order(
    problem: FitProblem,
    estimator: PoleEstimator,
    p_start: int,
    rules: SelectionRules,
    automatic: bool,
    false_alarm: float = FALSE_ALARM,
) -> Diagram:
    """Diagram of the automatic order (sizing rule and trial raises, up to
    :func:`order_cap` of the modes the data show at ``false_alarm``, or up to
    ``ESCALATE`` times that cap and :func:`order_limit` when no mode is stable at
    the cap), or of ``p_start``."""
    n_in = problem.shape[1]
    full = order_limit(n_in, problem.shape[2])
    limit = full
    if automatic:
        shown = modes_shown(problem, false_alarm)
        limit = min(limit, order_cap(n_in, problem.shape[2], p_start, shown))
    cur = diagram(problem, estimator, p_start, rules)
    trial: Diagram | None = None  # the diagram before a trial raise
    while automatic:
        share = cur.persistent_share()
        if trial is not None:
            prev, trial = trial, None
            if len(cur.kept) <= len(prev.kept) or share <= prev.persistent_share():
                cur = prev
                break
        # sizing: the highest order must give at least 2 poles per pole needed
        # (kept modes + 2 for residual effects, conjugates counted)
        need = 2 * 2 * (len(cur.kept) + 2)
        p = cur.order
        if p >= limit:
            break
        if p * n_in < need:
            p = min(limit, max(2 * p, int(np.ceil(need / n_in))))
        elif share < _SETTLED_SHARE:
            # as if every root pair of the top order were a mode: p n_in / 2 modes
            trial = cur
            p = min(limit, 2 * p + int(np.ceil(8 / n_in)))
        else:
            break
        cur = diagram(problem, estimator, p, rules)
    if automatic and n_in > 1:
        cur = _peaks_trial(problem, estimator, rules, cur, min(limit, shown_order(n_in, shown)))
    # the peaks counted in noisy data are a lower bound of the modes: no stable
    # mode up to the cap doubles the order, up to ESCALATE times the cap (and the
    # line limit); beyond that the clusters too few orders show are the
    # candidates and the mode test decides (pure noise of 3 inputs x 900 lines
    # ran to order 448: minutes of companion eigenvalues for no mode)
    top = min(full, ESCALATE * max(limit, cur.order)) if automatic else cur.order
    while automatic and not cur.kept and cur.order < top:
        cur = diagram(problem, estimator, min(top, 2 * cur.order), rules)
    return cur
