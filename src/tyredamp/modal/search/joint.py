"""The joint refit of the residual search: a trial mode refitted with all modes.

The moves of :func:`~tyredamp.modal.search.search.residual_search` that change
the mode set (the trial bookkeeping, the trials themselves and the driver stay in
:mod:`.search`): :func:`_joint` refits the current modes with a trial mode that
passed and keeps it when it stays in the band, merges with no mode, is still
admissible and every mode still passes the test (or holds it as a residual mode
outside the band, :func:`_held_outside`, :func:`_as_outside`); :func:`_split`
replaces a mode that stands for a close pair by two poles and refits them
jointly. ``SEARCH_TOL`` and ``JOINT_NFEV`` are the tolerance and evaluation
limit of these joint fits (also of the rejection's and the out-of-band stage's).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...exceptions import ConvergenceError
from ..fit.fit import FitResult, ModalFitter
from ..statistics.quality import RejectedMode, threshold_text
from ..statistics.stats import chi2_isf_each
from .modeset import (
    MERGE,
    ModeSet,
    as_residual,
    fit_checked,
    lost_modes,
    outside_side,
    rejected,
    with_residual,
)
from .narrow import STEP_LINES, narrow_refusal, too_narrow
from .residual_peaks import local_ratio
from .thresholds import ModeTest, local_thresholds, residual_span

__all__ = ["JOINT_NFEV", "SEARCH_TOL"]


#: convergence threshold of the search's joint fits, in units of the residual
#: variance s^2 (ModalFitter.fit ``tol``): the joint fits of the search and of the
#: rejection stop when a further step would lower the cost by less than 10 s^2. They
#: only choose the modes and start the final fit, which converges to a much smaller
#: tolerance.
SEARCH_TOL = 10.0
#: evaluation limit of the joint refit of an accepted trial (the final fit converges)
JOINT_NFEV = 30


def _inadmissible(p: complex, df: float, max_damping: float) -> str:
    """Why the pole ``p`` cannot be an in-band mode of the search ('' if it can):
    narrower than the line spacing ``df`` (Hz), or damped beyond ``max_damping``
    (:func:`residual_search`)."""
    if -p.real / np.pi < df:
        return (
            f"half-power bandwidth {-p.real / np.pi:.3g} Hz below the line "
            f"spacing {df:.3g} Hz (not resolved)"
        )
    if -p.real > max_damping * abs(p):
        return f"damping above the admissible {max_damping:.0%}"
    return ""


def _narrow_joint(
    fitter: ModalFitter,
    r1: FitResult,
    k: int,
    cur: ModeSet,
    threshold: float,
    test: ModeTest | None,
) -> str:
    """Why the trial mode ``k`` of the joint refit ``r1``, a few lines wide or narrower,
    is refused ('' when it is a resonance, :func:`~tyredamp.modal.search.narrow.narrow_refusal`):
    its evidence against the threshold raised where the noise of the fit's residual
    lies along the response (model error, :func:`local_thresholds`), and compared
    with the modes ``cur`` before the refit (one of them may have left its place to
    the trial)."""
    thr = threshold
    if test is not None:
        span = residual_span(fitter, r1)
        thr = float(local_thresholds(fitter, span, r1.poles[k : k + 1], threshold, test)[0])
    return narrow_refusal(fitter, r1, complex(r1.poles[k]), thr, k, cur.poles)


def _held_outside(
    r1: FitResult,
    k: int,
    wrong: NDArray[np.intp],
    band: tuple[float, float],
    limits: tuple[float, float, float],
    max_helpers: int,
) -> bool:
    """Whether the joint refit ``r1`` lost only the trial mode ``k``, across a band
    edge to within a factor 2 of it (the range of the residual modes of
    :func:`~tyredamp.modal.search.out_of_band.search_helpers`), where it is admissible,
    passes the mode test and fewer than ``max_helpers`` residual modes lie on that
    side. ``limits``: the mode test's threshold, the line spacing and the
    admissible damping ratio."""
    threshold, df, max_damping = limits
    if wrong.size != 1 or int(wrong[0]) != k:
        return False
    p1 = complex(r1.poles[k])
    side = outside_side(p1.imag / (2 * np.pi), band)
    f_all = r1.poles.imag[np.arange(r1.poles.size) != k] / (2 * np.pi)
    held = np.count_nonzero(f_all > band[1]) if side > 0 else np.count_nonzero(f_all < band[0])
    return bool(
        side != 0
        and held < max_helpers
        and not _inadmissible(p1, df, max_damping)
        and float(r1.significance[k]) > threshold
    )


def _as_outside(
    fitter: ModalFitter,
    modes: ModeSet,
    k: int,
    band: tuple[float, float],
    kw: dict[str, float],
    p_t: complex,
) -> tuple[FitResult, ModeSet] | RejectedMode | None:
    """``modes`` with the in-band mode ``k`` moved to the residual modes outside the
    band (last, checked against the band), refitted (:func:`fit_checked`); the
    trial ``p_t``'s record when that refit loses a mode (None: the fit failed)."""
    keep = np.arange(modes.m) != k
    rest = ModeSet(modes.poles[keep], modes.part[keep], modes.hp, modes.hl, modes.n_free)
    held = with_residual(rest, complex(modes.poles[k]), modes.part[k])
    try:
        r2, c2, drop = fit_checked(fitter, held, True, band, **kw)  # type: ignore[arg-type]
    except (ConvergenceError, np.linalg.LinAlgError, ValueError):
        return None
    if drop or c2.m != held.m or c2.hp.size != held.hp.size:
        why = drop[0].reason if drop else "lost a mode"
        return rejected(p_t, f"joint refit, held outside the band: {why}")
    return r2, c2


def _joint(
    fitter: ModalFitter,
    cur: ModeSet,
    p_t: complex,
    l_t: NDArray[np.complex128],
    band: tuple[float, float],
    threshold: float,
    df: float,
    max_damping: float,
    crossed: set[int],
    test: ModeTest | None = None,
    max_helpers: int = 0,
) -> tuple[FitResult, ModeSet] | RejectedMode | None:
    """The joint refit of the modes ``cur`` with an accepted trial mode ``p_t``:
    the fit and its modes when the trial mode stays (in the band, no merge, still
    admissible, every mode significant); otherwise the trial's record with the
    reason (None: the fit failed). A joint fit that loses a mode is not refitted
    without it: the trial is rejected for what the fit did to it (crossing the
    band edge, merging, carrying another mode across the edge). ``crossed``
    gets the side (+1 above, -1 below the band) the trial mode crossed to. With
    ``test``, the trial mode kept as a mode must also pass its own threshold,
    raised where the noise of the joint fit's residual (the mode in it: a true
    mode's signal does not count as noise) lies along the response
    (:func:`local_thresholds`). A trial mode that alone crossed an edge may stay
    outside the band (:func:`_held_outside`; ``max_helpers`` a side, 0: never)."""
    new = ModeSet(
        np.append(cur.poles, p_t),
        np.concatenate([cur.part, l_t[None, :]]),
        cur.hp,
        cur.hl,
        cur.n_free,
    )
    p_all, l_all = new.all()
    kw = {"passes": 1, "tol": SEARCH_TOL, "uncertainty": False, "max_nfev": JOINT_NFEV}
    try:
        r1 = fitter.fit(p_all, l_all, **kw)  # type: ignore[arg-type]
    except (np.linalg.LinAlgError, ValueError):
        return None
    k = new.m - 1  # the trial mode
    fd = r1.poles.imag / (2 * np.pi)
    wrong, why = lost_modes(r1, new, band)
    if wrong.size and np.all(wrong >= new.m):
        # only residual modes entered the band: dropped, the rest refitted from
        # their starts (fit_checked), and the trial judged on that fit
        keep = np.setdiff1d(np.arange(new.hp.size), wrong - new.m)
        new = ModeSet(
            new.poles,
            new.part,
            new.hp[keep],
            new.hl[keep],
            int(np.count_nonzero(keep < new.n_free)),
        )
        try:
            r1, c1, drop = fit_checked(
                fitter,
                new,
                True,
                band,
                **kw,  # type: ignore[arg-type]
            )
        except (ConvergenceError, np.linalg.LinAlgError, ValueError):
            return None
        if drop or c1.m != new.m:
            return rejected(p_t, f"joint refit: {drop[0].reason if drop else 'lost a mode'}")
        p_all = new.all()[0]
        fd = r1.poles.imag / (2 * np.pi)
        wrong, why = np.zeros(0, np.intp), ""
    limits = (threshold, df, max_damping)
    if wrong.size and _held_outside(r1, k, wrong, band, limits, max_helpers):
        # a mode outside the band whose tail the data hold: a residual mode that must
        # stay outside (checked in every later fit, as those of search_helpers)
        return _as_outside(fitter, new.take(r1), k, band, kw, p_t)
    if wrong.size:
        if k in wrong:
            how = f"joint refit: {why} ({fd[k]:.2f} Hz)"
            if not band[0] <= fd[k] <= band[1]:
                crossed.add(1 if fd[k] > band[1] else -1)
        else:
            i = int(wrong[0])
            how = (
                f"joint refit: the mode at {abs(p_all[i]) / (2 * np.pi):.2f} Hz "
                f"{why} ({fd[i]:.2f} Hz)"
            )
        return rejected(p_t, how)
    t1 = r1.significance[: new.m]
    if np.min(t1) <= threshold:
        return rejected(
            p_t,
            f"not significant with all modes refitted: T = {np.min(t1):.3g} <= {threshold:.3g}",
            float(np.min(t1)),
            threshold,
        )
    p1 = complex(r1.poles[k])
    why = _inadmissible(p1, df, max_damping)
    if (why and too_narrow(p1, df)) or (not why and too_narrow(p1, STEP_LINES * df)):
        why = _narrow_joint(fitter, r1, k, cur, threshold, test)
    w1 = abs(p1)
    edge = w1 + p1.real <= 2 * np.pi * band[0] or w1 - p1.real >= 2 * np.pi * band[1]
    if why and -p1.real > max_damping * w1 and edge:
        # too damped to be a mode, but significant: broad structure (the tails of
        # modes outside the band: its half-power band reaches past an edge) kept as
        # a residual mode, not reported as a mode; the trial mode is the last
        # in-band one: the order of r1 is kept. A broad pole within the band
        # stands in for missed modes there and would hide them from later trials.
        return r1, as_residual(new.take(r1), np.arange(new.m) == k)
    if why:
        return rejected(p1, f"joint refit: {why}", float(r1.significance[k]), threshold)
    if test is not None:
        span = residual_span(fitter, r1)
        thr_k = float(local_thresholds(fitter, span, r1.poles[k : k + 1], threshold, test)[0])
        t_k = float(t1[k])
        if t_k <= thr_k:
            return rejected(
                p_t,
                f"not significant with all modes refitted: T = {t_k:.3g} <= "
                f"{threshold_text(thr_k, threshold)}",
                t_k,
                thr_k,
            )
    return r1, new.take(r1)


def _split(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    pw: NDArray[np.float64],
    band: tuple[float, float],
    threshold: float,
    df: float,
    max_damping: float,
    test: ModeTest | None,
    tried: list[complex],
) -> tuple[FitResult, ModeSet] | None:
    """A close pair where one mode stands for two: the in-band modes whose local
    dispersion (residual power within two half-widths over the band's mean,
    :func:`~tyredamp.modal.final.local_dispersion`) exceeds its 5 % noise level
    (Bonferroni over the modes), most dispersed first, are each replaced by two
    poles half a half-width either side, refitted with all modes and kept when
    both pass the mode test (:func:`_joint`). A trial adds one mode alone with
    the others held: it cannot move the mode that took the pair's place, so no
    trial finds the second. ``pw``: the fit's residual power per line (n_f,),
    in units of each output's noise; ``tried`` (poles split already) grows."""
    m, k = cur.m, 2 * fitter.n_out * fitter.n_in
    p = res.poles[:m]
    rho, n = local_ratio(fitter.f, pw, p)
    level = chi2_isf_each(0.05 / max(m, 1), k * n) / (k * n)
    if not np.any(rho > level):
        return None
    # where the noise lies along the response (threshold raised), the residual near
    # a mode is that noise: no evidence of a second mode
    span = residual_span(fitter, res) if test is not None else None
    raised = local_thresholds(fitter, span, p, threshold, test) > threshold
    for i in np.argsort(-rho):
        if rho[i] <= level[i] or raised[i]:
            continue
        if any(abs(q - p[i]) < 2 * MERGE * abs(p[i]) for q in tried):
            continue
        tried.append(complex(p[i]))
        shift = 0.5 * -p[i].real  # half a half-power half-width (rad/s)
        keep = np.arange(m) != i
        base = ModeSet(
            np.append(cur.poles[keep], p[i] - 1j * shift),
            np.concatenate([cur.part[keep], cur.part[i : i + 1]]),
            cur.hp,
            cur.hl,
            cur.n_free,
        )
        got = _joint(
            fitter,
            base,
            p[i] + 1j * shift,
            cur.part[i],
            band,
            threshold,
            df,
            max_damping,
            set(),
            test,
        )
        if got is None or isinstance(got, RejectedMode):
            continue
        # the pair's first pole passes its own threshold too (_joint tests the trial's)
        r1, c1 = got
        j = c1.m - 2
        thr_j = local_thresholds(
            fitter, residual_span(fitter, r1), r1.poles[j : j + 1], threshold, test
        )
        if r1.significance[j] > thr_j[0]:
            return got
    return None
