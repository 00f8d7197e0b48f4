"""Which modes the data hold: out-of-band residual modes, the mode test, and the
residual-driven search for missed modes.

Three stages of :func:`~tyredamp.modal.identify.identify_modes` (automatic
mode count), all on one :class:`~tyredamp.modal.fit.fit.ModalFitter`:

1. :func:`~tyredamp.modal.search.out_of_band.search_helpers`: out-of-band residual
   modes above and below the band (docstring there);
2. :func:`reject_by_test`: each in-band mode's statistic ``T`` (the rise of
   the weighted cost, in units of the noise variance, when the mode is
   removed; :mod:`tyredamp.modal.statistics.stats`) against the threshold of the
   stated false-alarm rate, raised for each mode where the residual's noise
   lies along the response (an H1 estimate's input noise, common to the
   outputs: :mod:`tyredamp.modal.search.span_noise`, :func:`local_thresholds`); the
   weakest failing mode is dropped and the rest refitted, until every mode
   passes;
3. :func:`residual_search`: candidates for missed modes, from the diagram
   (clusters that too few orders resolved, modes rejected earlier) and from
   the peaks of the residual (the fit's residual power per line, in units of
   the noise, summed over the FRFs, over 5 lines and over windows matched to
   half-power bands: a mode indicator on the residual,
   :mod:`tyredamp.modal.search.residual_peaks`; the starts of a round and the records
   of the candidates not kept for a reason of their own are in
   :mod:`tyredamp.modal.search.search_starts`) where the coherent scan finds room
   for a mode; when those add nothing, the maxima of the coherent scan itself
   (the mode test's statistic of a pole held at each point of a grid, the
   fitted modes' residues refitted, rank-one with their participation held when
   there are several inputs: a weak mode beside a strong one, a broad
   mode spread over many lines). Each is refined alone with the other modes
   held fixed (:meth:`~tyredamp.modal.fit.fit.ModalFitter.fit_added`, its
   frequency within 3 % of the start, followed beyond that window while its
   statistic grows); a candidate whose cost drop passes the mode test is
   refined with all modes, and kept when it still passes (its own threshold
   raised as in 2, from the residual of that fit); repeated until no
   candidate passes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...exceptions import ConvergenceError
from ...mechanics.modal_sum import pole_quantities
from ..fit.fit import FitResult, ModalFitter
from ..statistics.quality import KEPT, RejectedMode, threshold_text
from .joint import SEARCH_TOL, _inadmissible, _joint, _split
from .modeset import (
    MERGE,
    ModeSet,
    as_residual,
    fit_checked,
    rejected,
    too_damped,
)
from .narrow import narrow_refusal, too_narrow
from .residual_peaks import (
    residual_view,
)
from .search_starts import (
    MAX_TRIALS,
    SAME_START,
    capped,
    round_starts,
    start_records,
    unique_candidates,
)
from .span_noise import SpanNoise
from .thresholds import ModeTest, local_thresholds, residual_span
from .trials import FixedParts, _toward, _trial, sigma_bound

__all__ = [
    "FixedParts",
    "ModeSet",
    "ModeTest",
    "local_thresholds",
    "reject_by_test",
    "residual_search",
    "residual_span",
    "sigma_bound",
]

#: residual search: most rounds (they go on while one adds a mode; this only bounds them)
MAX_ROUNDS = 50
#: residual search: a candidate's frequency stays within this factor of its start
TRIAL_SPAN = 0.03
#: times a trial stopped at its window's limit is continued beyond it (_follow)
FOLLOW = 3


def reject_by_test(
    fitter: ModalFitter,
    modes: ModeSet,
    band: tuple[float, float],
    threshold: float,
    refine: bool,
    min_contribution: float = 0.0,
    test: ModeTest | None = None,
    start: FitResult | None = None,
    max_damping: float | None = None,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """Drop the weakest mode that fails the mode test, refit; until every mode passes.

    The first fit refines every mode jointly (and drops modes that leave the
    band); after each removal the residues are refitted at the current poles.
    ``min_contribution`` (default 0: off) also drops modes whose synthesised
    FRFs have an RMS below that fraction of the data's. With ``test``, each
    mode's threshold is raised where the noise of the first fit's residual
    (every mode in it: no mode's signal counts as noise) lies along the
    response (:func:`local_thresholds`). ``start``: the fit the modes come
    from (:func:`search_helpers`); when it is a joint fit at rest, the first
    fit returns it (``ModalFitter.fit(..., start=...)``). A mode that the
    joint fit damps beyond ``max_damping`` (the diagram's admissible damping;
    None: no limit) is not a mode: it stays in the fit as a residual mode
    (:func:`as_residual`), and the residues are refitted.
    """
    out: list[RejectedMode] = []
    cur = modes
    res: FitResult | None = None
    span: SpanNoise | None = None
    for i in range(modes.m + 1):
        if i == 0 and refine:
            # a converged joint fit first (modes that leave the band are dropped); if
            # it loses every mode (the few modes of a band missing most are dragged
            # out), the residues at the current poles, and the search adds the rest
            try:
                res, cur, gone = fit_checked(
                    fitter, cur, True, band, start, passes=1, tol=SEARCH_TOL, uncertainty=False
                )
                out += gone
            except ConvergenceError:
                res = None
        if res is None:
            # after a removal the others barely move: the residues are refitted at
            # the current poles (the final fit refines them all)
            p0, l0 = cur.all()
            res = fitter.fit(p0, l0, refine=False, passes=1, uncertainty=False)
        cur = cur.take(res)
        broad = too_damped(cur.poles, max_damping)
        if np.any(broad) and not np.all(broad):
            cur, res = as_residual(cur, broad), None
            continue
        m = cur.m
        if span is None and test is not None:
            span = residual_span(fitter, res)
        thr = local_thresholds(fitter, span, cur.poles, threshold, test)
        t, con = res.significance[:m], res.contribution[:m]
        bad = (t < thr) | (con < min_contribution)
        if not np.any(bad) or m <= 1:
            break
        worst = int(np.argmin(np.where(bad, t / thr, np.inf)))
        why = (
            f"contribution {con[worst]:.2%} < {min_contribution:.2%}"
            if con[worst] < min_contribution
            else f"not significant: T = {t[worst]:.3g} <= {threshold_text(thr[worst], threshold)}"
        )
        out.append(rejected(complex(cur.poles[worst]), why, float(t[worst]), float(thr[worst])))
        cur = ModeSet(
            np.delete(cur.poles, worst),
            np.delete(cur.part, worst, axis=0),
            cur.hp,
            cur.hl,
            cur.n_free,
        )
        res = None
    if res is None:
        p0, l0 = cur.all()
        res = fitter.fit(p0, l0, refine=False, passes=1, uncertainty=False)
    return res, cur, out


def _repeated_start(fitter: ModalFitter, cur: ModeSet, seen: list[complex], p0: complex) -> bool:
    """Whether the start ``p0`` lies within twice the merge distance of a current mode
    or of an earlier start (with several inputs, of a current residual mode only: a
    start at a mode's pole may be a repeated root's)."""
    held = cur.all()[0] if fitter.n_in == 1 else cur.hp
    p_all = np.concatenate([held, np.asarray(seen, complex)])
    return bool(p_all.size and np.min(np.abs(p_all - p0) / abs(p0)) < 2 * MERGE)


TOWARD_CROSSED = (
    "stopped at its window's limit toward a band edge that another trial crossed in its "
    "joint refit (the same structure outside the band)"
)


def _follow(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    fixed: FixedParts,
    start: tuple[complex, NDArray[np.complex128]],
    w_lim: tuple[float, float],
    band: tuple[float, float],
    max_damping: float | None = None,
) -> tuple[tuple[complex, NDArray[np.complex128], float], tuple[float, float]] | None:
    """A trial (:func:`_trial`) that follows its pole out of its window: one that
    stopped at a limit inside the band runs toward structure beyond it, and is
    continued from there in a window centred on it (at most ``FOLLOW`` times,
    while its statistic grows), unless that window holds a current mode (the
    pole runs toward that mode's misfit or noise, not toward a missed one).
    Returns the trial's last result and window (``max_damping`` as in :func:`_trial`)."""
    got = _trial(fitter, res, cur, fixed, start[0], start[1], w_lim, False, max_damping)
    w_band = (2 * np.pi * band[0], 2 * np.pi * band[1])
    for _ in range(FOLLOW):
        if got is None:
            return None
        p_t, l_t, _ = got
        side = _toward(p_t, w_lim)
        edge = w_lim[1] if side > 0 else w_lim[0]
        if side == 0 or not w_band[0] < edge < w_band[1]:
            break
        w_new = (
            max(abs(p_t.imag) * (1 - TRIAL_SPAN), w_band[0]),
            min(abs(p_t.imag) * (1 + TRIAL_SPAN), w_band[1]),
        )
        if np.any((cur.poles.imag > w_new[0]) & (cur.poles.imag < w_new[1])):
            break  # runs toward a current mode (its misfit or its noise), not beyond
        nxt = _trial(fitter, res, cur, fixed, p_t, l_t, w_new, False, max_damping)
        if nxt is None or nxt[2] <= got[2]:
            break
        got, w_lim = nxt, w_new
    return (got, w_lim) if got is not None else None


def residual_search(
    fitter: ModalFitter,
    res: FitResult,
    modes: ModeSet,
    candidates: list[tuple[complex, NDArray[np.complex128]]],
    band: tuple[float, float],
    threshold: float,
    max_damping: float = 0.2,
    test: ModeTest | None = None,
    fixed: FixedParts | None = None,
    max_helpers: int = 4,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """Add missed in-band modes that pass the mode test (module docstring, stage 3).

    A candidate whose damping ratio exceeds ``max_damping`` (the selection rule
    of the diagram) is not a mode: it is rejected whatever its statistic (a trial
    stops at that bound, :func:`sigma_bound`, rather than running on). A trial
    whose half-power bandwidth ``2 zeta f_n = -Re p / pi`` (Hz) is narrower
    than the line spacing (a lightly damped mode measured with coarse lines: its
    frequency is resolved and its damping only bounded,
    :func:`~tyredamp.modal.search.narrow.unresolved_damping`) can also fit single lines
    (an outlier, a step, the erratic low end of an impact test) or the flank of
    another mode's misfit: it is kept only when its tails hold evidence beyond
    those on both sides, away from the ends of the lines and from the other
    modes (:func:`~tyredamp.modal.search.narrow.narrow_refusal`; poles up to 3 lines
    wide against a spike and a step), in the trial and again in the joint refit.
    A trial mode that passes is refitted with all modes (:func:`_joint`) and
    kept when it stays in the band, merges with no mode, is still admissible and
    every mode still passes the test; a trial mode that alone crosses a band edge
    in the joint refit,
    to an admissible pole within a factor 2 of the edge that passes the test, is
    a mode outside the band whose tail the data hold: it is kept as a residual
    mode while fewer than ``max_helpers`` lie on that side (the limit of
    :func:`~tyredamp.modal.search.out_of_band.search_helpers`). Otherwise it is
    rejected for what the joint refit did (e.g. "joint refit: crossed the band
    edge", a mode outside the band whose tail the trial had taken), and a later
    trial that ends at the same pole (within ``2 MERGE``) against the same modes
    is not refitted again; nor is one that stopped at the limit of its window
    toward a band edge that a trial crossed (it runs toward the same structure
    outside the band).

    ``candidates`` are starting poles and participation vectors from the diagram;
    each round adds the peaks of the current residual. Every candidate
    of the diagram gets a record: not tried (too little residual power in its
    half-power band, the same pole as a mode or an earlier start, the round's
    ``MAX_TRIALS`` reached), where its trial mode went and why it was rejected,
    or ``KEPT`` (its trial mode is now a mode;
    :func:`~tyredamp.modal.statistics.quality.merge_rejected` joins a candidate's records
    and leaves the kept ones out). With
    ``test``, the added mode must also pass its own threshold in the joint
    refit, raised where the noise of that fit's residual (the mode in it: a
    true mode's signal does not count as noise) lies along the response
    (:func:`local_thresholds`). ``fixed``: the trials' fixed parts
    (:class:`FixedParts`; shared with :func:`search_helpers` by the caller, or new).
    """
    df = float(fitter.f[1] - fitter.f[0]) if fitter.f.size > 1 else 0.0
    tried: list[RejectedMode] = []
    cur = modes
    zeta0 = float(np.clip(np.median(pole_quantities(cur.poles)[1]), 0.002, 0.1))
    pending = unique_candidates(candidates)
    seen: list[complex] = []  # starts tried (a start is tried once)
    refused: list[complex] = []  # trial modes whose joint refit failed (current modes)
    crossed: set[int] = set()  # sides of the band trial modes crossed to (current modes)
    fixed = FixedParts(fitter) if fixed is None else fixed
    scan_next = False  # this round tries the coherent scan's poles
    scanned = False  # the coherent scan's poles were tried on the current modes
    split_tried: list[complex] = []  # modes split already (_split)
    view_of: FitResult | None = None  # the fit whose residual ``view`` holds
    for _ in range(MAX_ROUNDS):
        # the residual's peaks first (where the structure is), then the diagram's;
        # when they add nothing, the coherent scan's poles (one round per mode set)
        if view_of is not res:
            fixed.release()  # a long record's, not held beside the residual of every line
            view, view_of = residual_view(fitter, res, zeta0), res
        starts, screened = round_starts(
            fitter, res, view, pending, threshold, zeta0, test, scan_next
        )
        tried += screened
        scanned, scan_next = scanned or scan_next, False
        added, n_tried = False, 0
        from_diagram = {complex(c[0]) for c in pending}
        pending = []
        for k, (p0, l0) in enumerate(starts):
            if _repeated_start(fitter, cur, seen, p0):
                tried += [rejected(p0, SAME_START)] if complex(p0) in from_diagram else []
                continue
            if n_tried >= MAX_TRIALS:
                tried += capped(view[0], starts[k:], from_diagram, zeta0, threshold)
                break
            n_tried += 1
            seen.append(complex(p0))
            got = _try_start(
                fitter,
                (res, cur),
                fixed,
                (p0, np.asarray(l0, complex)),
                band,
                (threshold, df, max_damping),
                (refused, crossed),
                test,
                max_helpers,
            )
            if isinstance(got, RejectedMode) or got is None:
                tried += start_records(got, p0, complex(p0) in from_diagram)
                continue
            res, cur = got
            added, refused, crossed, scanned = True, [], set(), False
            if complex(p0) in from_diagram:
                tried.append(rejected(p0, KEPT))
        if not added and scanned:
            got2 = _split(
                fitter, res, cur, view[1], band, threshold, df, max_damping, test, split_tried
            )
            if got2 is None:
                break
            res, cur = got2
            refused, crossed, scanned = [], set(), False
        elif not added:
            scan_next = True
    return res, cur, tried


def _try_start(
    fitter: ModalFitter,
    current: tuple[FitResult, ModeSet],
    fixed: FixedParts,
    start: tuple[complex, NDArray[np.complex128]],
    band: tuple[float, float],
    limits: tuple[float, float, float],
    state: tuple[list[complex], set[int]],
    test: ModeTest | None,
    max_helpers: int,
) -> tuple[FitResult, ModeSet] | RejectedMode | None:
    """One start of :func:`residual_search`: its trial (followed out of its window,
    :func:`_follow`) and, when the trial mode passes, the joint refit with it
    (:func:`_joint`). Returns the new fit and modes when the mode is kept, else the
    trial's record with the reason, or None (no trial mode, or the same trial mode
    as one whose joint refit was refused). ``limits``: the threshold, the line
    spacing and the largest damping ratio; ``state``: the refused trial modes
    (extended here) and the sides of the band that trial modes crossed to."""
    res, cur = current
    threshold, df, max_damping = limits
    refused, crossed = state
    p0, l0 = start
    w_lim = (
        max(abs(p0.imag) * (1 - TRIAL_SPAN), 2 * np.pi * band[0]),
        min(abs(p0.imag) * (1 + TRIAL_SPAN), 2 * np.pi * band[1]),
    )
    if not w_lim[0] < w_lim[1]:
        return rejected(p0, "not tried: its window lies outside the band")
    got = _follow(fitter, res, cur, fixed, (p0, l0), w_lim, band, max_damping)
    if got is None:
        return None
    (p_t, l_t, t), w_lim = got
    why = _inadmissible(p_t, df, max_damping)
    if (why and too_narrow(p_t, df)) or not why:
        why = narrow_refusal(fitter, res, p_t, threshold)
    if not why and -p_t.real >= (1 - 1e-9) * sigma_bound(max_damping, w_lim[1]):
        why = f"damping above the admissible {max_damping:.0%}"  # stopped at the bound
    if not why and t <= threshold:
        why = f"not significant: T = {t:.3g} <= {threshold:.3g}"
    if why:
        return rejected(p_t, why, t, threshold)
    if refused and np.min(np.abs(np.asarray(refused) - p_t)) < 2 * MERGE * abs(p_t):
        return None  # the same trial mode: its joint refit was rejected already
    if _toward(p_t, w_lim) in crossed:
        return rejected(p_t, TOWARD_CROSSED, t, threshold)
    got1 = _joint(
        fitter, cur, p_t, l_t, band, threshold, df, max_damping, crossed, test, max_helpers
    )
    if isinstance(got1, RejectedMode):
        refused.append(p_t)
    return got1
