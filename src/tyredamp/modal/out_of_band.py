"""Out-of-band residual modes: the first stage of the automatic mode count.

:func:`search_helpers` refines the diagram's modes, then adds residual modes
above and below the band while they pass the mode test
(:mod:`tyredamp.modal.search` holds the trials and the other stages).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..exceptions import ConvergenceError
from ..mechanics.modal_sum import pole_quantities
from .fit import FitResult, ModalFitter
from .modeset import outside_side, with_residual
from .quality import RejectedMode
from .search import (
    FIRST_NFEV,
    MIN_LOW_LINES,
    SEARCH_TOL,
    FixedParts,
    ModeSet,
    _trial,
    fit_checked,
)

__all__ = ["search_helpers"]


def search_helpers(
    fitter: ModalFitter,
    modes: ModeSet,
    band: tuple[float, float],
    data_band: tuple[float, float],
    max_helpers: int,
    threshold: float,
    fixed: FixedParts | None = None,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """Refine, then add out-of-band residual modes while they pass the mode test.

    A trial pole is started at ``1.1 f_hi`` (then ``1.3 f_hi``, ...) above the
    band, and at ``0.9 f_lo`` (...) below it when ``f_lo > 0`` and at least
    ``MIN_LOW_LINES`` lines lie in ``[f_lo, 2 f_lo]``, with the median
    damping of the in-band modes. Only the trial mode is refined, with every
    other mode held fixed, its damped frequency kept outside the band but
    within a factor 2 of its edge. It is kept when it did not stop at one of
    these limits and its statistic ``T`` (cost drop in units of the noise
    variance per output) exceeds ``threshold``; all modes are then refined
    together, and the search on that side stops instead if that moves the
    trial mode out of its range or an in-band mode out of the band. A side
    whose search stopped is searched again, from the start where it stopped,
    once a residual mode on the other side is added: the residual it failed
    on has changed (the tail of a strong mode just below the band is fitted
    better by a broad pole far above it than by the mode just above the edge,
    until a residual mode below holds it). ``fixed``: the trials' fixed parts
    (:class:`FixedParts`, new when None).
    """
    lo = band[0]
    res, cur, dropped = fit_checked(
        fitter,
        modes,
        True,
        band,
        passes=1,
        tol=SEARCH_TOL,
        uncertainty=False,
        max_nfev=FIRST_NFEV,
    )
    zeta0 = float(np.clip(np.median(pole_quantities(cur.poles)[1]), 0.005, 0.1))
    n_low = int(np.count_nonzero((fitter.f >= lo) & (fitter.f <= 2 * lo)))
    sides = [1.0] + ([-1.0] if data_band[0] > 0 and n_low >= MIN_LOW_LINES else [])
    fixed = FixedParts(fitter) if fixed is None else fixed
    # a side whose trial failed is tried again once a helper on the other side
    # changed the residual (a strong mode below the band leaves a tail that an
    # upper helper far away fits better than the mode just above the edge)
    k_next = dict.fromkeys(sides, 0)
    failed_at: dict[float, int] = {}  # helpers held when the side's last trial failed
    while any(failed_at.get(s) != cur.hp.size and k_next[s] < max_helpers for s in sides):
        for side in sides:
            while failed_at.get(side) != cur.hp.size and k_next[side] < max_helpers:
                got = _helper(fitter, res, cur, fixed, band, side, k_next[side], zeta0, threshold)
                if got is None:
                    failed_at[side] = cur.hp.size
                    continue
                k_next[side] += 1  # the next start is further out
                if not isinstance(got, str):  # else the joint refit lost it (into the band)
                    res, cur, lost = got
                    dropped += [_took_tail(r) for r in lost]
    return res, cur, dropped


def _helper(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    fixed: FixedParts,
    band: tuple[float, float],
    side: float,
    k: int,
    zeta0: float,
    threshold: float,
) -> tuple[FitResult, ModeSet, list[RejectedMode]] | str | None:
    """The ``k``-th helper trial on ``side`` (+1 above the band, -1 below) of
    :func:`search_helpers`: the refit with it, "lost" when the joint refit lost
    it (into the band, or merged), None when it failed (not significant, at a
    limit, or moved out of its range)."""
    lo, hi = band
    fh = hi * (1.1 + 0.2 * k) if side > 0 else lo * (0.9 - 0.2 * k)
    if fh <= 0:
        return None
    wh = 2 * np.pi * fh
    ph = complex(-zeta0 * wh, wh * np.sqrt(1 - zeta0**2))
    edge = (hi, 2 * hi) if side > 0 else (lo / 2, lo)
    w_lim = (2 * np.pi * edge[0], 2 * np.pi * edge[1])
    got = _trial(fitter, res, cur, fixed, ph, np.ones(fitter.n_in, complex), w_lim)
    if got is None or got[2] < threshold:
        return None
    p_t, l_t, _ = got
    try:
        trial, new, lost = fit_checked(
            fitter,
            with_residual(cur, p_t, l_t),
            True,
            band,
            passes=1,
            tol=SEARCH_TOL,
            uncertainty=False,
        )
    except (ConvergenceError, np.linalg.LinAlgError, ValueError):
        return None
    if new.hp.size <= cur.hp.size:
        return "lost"
    # the helper must stay on its side of the band, within a factor 2 of the edge
    on_side = outside_side(new.hp[-1].imag / (2 * np.pi), band) == side
    return (trial, new, lost) if on_side else None


def _took_tail(r: RejectedMode) -> RejectedMode:
    """An in-band mode that a residual mode's refit moved out of the band: it stood
    for the tail of the modes outside the band, which the residual mode now holds."""
    return replace(r, reason=f"{r.reason}, once a residual mode outside the band held the tails")
