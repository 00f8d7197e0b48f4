"""Out-of-band residual modes: the first stage of the automatic mode count.

:func:`search_helpers` refines the diagram's modes, then adds residual modes
above and below the band while they pass the mode test
(:mod:`tyredamp.modal.search.search` holds the trials and the other stages).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...exceptions import ConvergenceError
from ...mechanics.modal_sum import pole_from_frequency_damping, pole_quantities
from ..fit import _pseudo
from ..fit._basis import factors, residual_blocks, residual_lines
from ..fit.fit import FitResult, ModalFitter
from ..statistics.quality import RejectedMode
from .joint import SEARCH_TOL
from .modeset import ModeSet, fit_checked, outside_side, with_residual
from .residual_peaks import model_of, rank_one_statistic
from .trials import FixedParts, _toward, _trial

__all__ = ["FIRST_NFEV", "MIN_LOW_LINES", "more_helpers", "search_helpers"]

#: evaluation limit of the search's first joint fit: before the residual modes are
#: found, the modes near a band edge absorb the out-of-band ones and converge slowly
#: (linearly) to that biased optimum; one Gauss-Newton step takes most of the gain
#: from the estimator's poles, the later joint fits and the final fit do the rest
FIRST_NFEV = 2
#: a residual mode below the band (damped frequency in [f_lo / 2, f_lo]) shapes the
#: FRFs mainly near f_lo; with fewer lines than this in [f_lo, 2 f_lo] (a band that
#: starts at the first lines) it cannot be told from the lower residual term
MIN_LOW_LINES = 10


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

    A trial pole is started above the band, and below it when ``f_lo > 0`` and
    at least ``MIN_LOW_LINES`` lines lie in ``[f_lo, 2 f_lo]``, where the
    current fit's residual asks for a pole on that side (:func:`_scan_starts`:
    the poles within a factor 2 of the edge whose columns explain most of the
    residual, the best first and then the scan's further distinct maxima above
    the threshold; a fixed ladder of starts, ``1.1 f_hi``, ``1.3 f_hi``, ...,
    began a trial far from a strong mode just beyond the edge and lost it behind
    a broad pole or a residual mode piled at the edge). Only the trial mode is
    refined, with every other mode held fixed, its damped frequency kept outside
    the band but within a factor 2 of its edge. It is kept when it did not stop
    at one of these limits and its statistic ``T`` (cost drop in units of the
    noise variance per output) exceeds ``threshold``; a trial that fails starts
    the next of the scan's maxima. The first that passes is refined with all
    modes, and the search on that side stops instead if that moves the trial
    mode out of its range or an in-band mode out of the band. A side whose
    search stopped is searched again, from the start where it stopped, once a
    residual mode on the other side is added: the residual it failed on has
    changed (the tail of a strong mode just below the band is fitted better by
    a broad pole far above it than by the mode just above the edge, until a
    residual mode below holds it). ``fixed``: the trials' fixed parts
    (:class:`FixedParts`, new when None).
    """
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
    n_low = int(np.count_nonzero((fitter.f >= band[0]) & (fitter.f <= 2 * band[0])))
    sides = [1.0] + ([-1.0] if data_band[0] > 0 and n_low >= MIN_LOW_LINES else [])
    fixed = FixedParts(fitter) if fixed is None else fixed
    res, cur, more = more_helpers(fitter, (res, cur), fixed, band, sides, threshold, max_helpers)
    return res, cur, dropped + more


def more_helpers(
    fitter: ModalFitter,
    current: tuple[FitResult, ModeSet],
    fixed: FixedParts,
    band: tuple[float, float],
    sides: list[float],
    threshold: float,
    max_helpers: int,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """Add residual modes on ``sides`` (+1 above the band, -1 below) to the fit and
    modes ``current`` while their trials pass (:func:`search_helpers`), up to
    ``max_helpers`` outside the band on each side. Returns the fit, the modes and
    the in-band modes the helpers' refits moved out of the band."""
    res, cur = current
    zeta0 = float(np.clip(np.median(pole_quantities(cur.poles)[1]), 0.005, 0.1))
    dropped: list[RejectedMode] = []

    def held(side: float) -> int:
        f = cur.hp[cur.n_free :].imag / (2 * np.pi)  # the residual modes outside
        return int(np.count_nonzero(f > band[1] if side > 0 else f < band[0]))

    # a side whose trial failed is tried again once a helper on the other side
    # changed the residual (a strong mode below the band leaves a tail that an
    # upper helper far away fits better than the mode just above the edge)
    failed_at: dict[float, int] = {}  # helpers held when the side's last trial failed
    while any(failed_at.get(s) != cur.hp.size and held(s) < max_helpers for s in sides):
        for side in sides:
            while failed_at.get(side) != cur.hp.size and held(side) < max_helpers:
                got = _helper(fitter, res, cur, fixed, band, side, zeta0, threshold)
                if got is None or isinstance(got, str):
                    # failed, or the joint refit lost it (into the band): the same
                    # residual would start the same trial
                    failed_at[side] = cur.hp.size
                    continue
                res, cur, lost = got
                dropped += [_took_tail(r) for r in lost]
    return res, cur, dropped


#: most starts of a side's helper trial (the scan's distinct maxima, best first)
HELPER_STARTS = 3


def _helper(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    fixed: FixedParts,
    band: tuple[float, float],
    side: float,
    zeta0: float,
    threshold: float,
) -> tuple[FitResult, ModeSet, list[RejectedMode]] | str | None:
    """A helper trial on ``side`` (+1 above the band, -1 below) of
    :func:`search_helpers` (:func:`helper_trial`): the refit with it, "lost" when
    the joint refit lost it (into the band, or merged), None when it failed (no
    trial passed, or the helper moved out of its range)."""
    found = helper_trial(fitter, res, cur, fixed, band, side, zeta0, threshold)
    if found is None:
        return None
    p_t, l_t, _ = found
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


def helper_trial(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    fixed: FixedParts,
    band: tuple[float, float],
    side: float,
    zeta0: float,
    threshold: float,
) -> tuple[complex, NDArray[np.complex128], float] | None:
    """The trial of a residual mode on ``side`` (+1 above the band, -1 below) against
    the fit ``res`` of the modes ``cur``, refined alone within a factor 2 of the
    band edge: its pole, participation and statistic ``T``. The trials start at the
    scan's maxima (:func:`_scan_starts`), the next when one stops at a limit of its
    range (at the band edge: in-band structure there, not a mode outside) or does
    not pass ``threshold``; None when none passes."""
    lo, hi = band
    edge = (hi, 2 * hi) if side > 0 else (lo / 2, lo)
    w_lim = (2 * np.pi * edge[0], 2 * np.pi * edge[1])
    starts = _scan_starts(fitter, res, edge, side, zeta0, threshold)
    ones = np.ones(fitter.n_in, complex)
    for ph in starts:
        got = _trial(fitter, res, cur, fixed, ph, ones, w_lim, strict=False)
        if got is not None and _toward(got[0], w_lim) == 0 and got[2] >= threshold:
            return got
    return None


#: damping ratios of the scan for a residual mode's start, relative to the modes'
SCAN_SCALES = (0.5, 1.0, 2.0)
#: grid points of the scan formed at once (per block of lines)
SCAN_CHUNK = 64


def _scan_starts(
    fitter: ModalFitter,
    res: FitResult,
    edge: tuple[float, float],
    side: float,
    zeta0: float,
    threshold: float,
) -> list[complex]:
    """Where the fit's residual asks for a pole outside the band: the trial poles
    of the range ``edge`` (Hz, the side's factor 2 beyond the band edge) whose
    column ``kappa / (s - p)`` over the band's lines explains most of the
    residual, in units of each output's noise (the rank-one statistic of the
    coherent scan, :func:`~tyredamp.modal.search.residual_peaks.coherent_scan`, over
    every line: a mode outside the band reaches into it with its tail). Grids of
    damping ``SCAN_SCALES`` times ``zeta0``, step ``zeta f``; the grid's best pole
    first, then the further distinct maxima whose statistic exceeds ``threshold``
    (:func:`distinct_maxima`; a start below it cannot give a significant trial).
    Empty when the range holds no grid point."""
    grids, zetas = [], []
    for sc in SCAN_SCALES:
        z = float(np.clip(sc * zeta0, 1e-3, 0.2))
        a0, b0 = (edge[0] * (1 + z), edge[1]) if side > 0 else (edge[0], edge[1] / (1 + z))
        if 0 < a0 < b0:
            fg = a0 * (1 + z) ** np.arange(int(np.log(b0 / a0) / np.log1p(z)) + 1)
            grids.append(pole_from_frequency_damping(fg, z))
            zetas.append(z)
    if not grids:
        return []
    pg = np.concatenate(grids)
    poles, residues, terms, s2 = model_of(fitter, res)
    inv = 1.0 / np.sqrt(s2)
    pl = fitter._pseudo_lines()
    if pl is not None:  # a long record: the sums from pseudo-lines (fit._pseudo)
        m, nrm2 = _pseudo_scan(fitter, pl, pg, (poles, residues, terms), inv)
    else:
        m, nrm2 = _scan_sums(fitter, pg, (poles, residues, terms), inv)
    t = rank_one_statistic(m, nrm2, fitter.n_out, fitter.n_in)
    sizes = [g.size for g in grids]
    best = distinct_maxima(t, sizes, pg, zetas, threshold)
    return [complex(pg[i]) for i in best]


def _scan_sums(
    fitter: ModalFitter,
    pg: NDArray[np.complex128],
    model: tuple[Any, Any, Any],
    inv: NDArray[np.float64],
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """The inner products of :func:`_scan_starts`, ``<a_g, e_jk>`` (n_out n_in, G)
    and ``||a_g||^2`` (G,), summed over blocks of lines (the residual of a long
    axis with many FRFs is never held whole)."""
    m = np.zeros((fitter.n_out * fitter.n_in, pg.size), complex)
    nrm2 = np.zeros(pg.size)
    # blocks sized for the SCAN_CHUNK complex trial columns formed with each
    for sl, e in residual_blocks(fitter, *model, 2 * SCAN_CHUNK):
        eb = (e * inv[:, None, None]).reshape(-1, e.shape[-1])
        s, kap, _ = factors(fitter, sl)
        for c0 in range(0, pg.size, SCAN_CHUNK):
            g = slice(c0, c0 + SCAN_CHUNK)
            a = s[None, :] - pg[g, None]
            np.divide(kap[None, :], a, out=a)
            m[:, g] += eb @ a.conj().T
            nrm2[g] += np.sum(a.real**2 + a.imag**2, axis=1)
    return m, nrm2


def distinct_maxima(
    t: NDArray[np.float64],
    sizes: list[int],
    pg: NDArray[np.complex128],
    zetas: list[float],
    threshold: float,
    most: int = HELPER_STARTS,
) -> list[int]:
    """Indices into the grids' poles ``pg`` of the scan's distinct maxima, best first:
    the grid's largest statistic ``t``, then the further local maxima over
    frequency of each damping grid (``sizes`` points each, damping ratio ``zetas``;
    a grid's end counts when it exceeds its one neighbour) whose statistic exceeds
    ``threshold``, each farther than the sum of the two half-power bandwidths
    (``2 zeta f``) from every one taken (the same maximum seen on several damping
    grids), at most ``most``."""
    cand, z_of = [], np.repeat(zetas, sizes)
    c0 = 0
    for n in sizes:
        tg = t[c0 : c0 + n]
        up = np.append(True, tg[1:] >= tg[:-1])  # not below the left neighbour
        down = np.append(tg[:-1] >= tg[1:], True)  # not below the right one
        cand += list(c0 + np.flatnonzero(up & down))
        c0 += n
    f, bw = np.abs(pg.imag), 2 * z_of * np.abs(pg)
    order = sorted(cand, key=lambda i: -t[i])
    out = [int(np.argmax(t))]
    for i in order:
        if len(out) >= most or t[i] <= threshold:
            break
        if all(abs(f[i] - f[j]) > bw[i] + bw[j] for j in out):
            out.append(int(i))
    return out


def _took_tail(r: RejectedMode) -> RejectedMode:
    """An in-band mode that a residual mode's refit moved out of the band: it stood
    for the tail of the modes outside the band, which the residual mode now holds."""
    return replace(r, reason=f"{r.reason}, once a residual mode outside the band held the tails")


def _pseudo_scan(
    fitter: ModalFitter,
    pl: _pseudo.PseudoLines,
    pg: NDArray[np.complex128],
    model: tuple[Any, Any, Any],
    inv: NDArray[np.float64],
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """The inner products of :func:`_scan_starts` (``<a_g, e_jk>``, ``||a_g||^2``) on a
    long record, from the pseudo-lines of the bins far from every grid pole
    (:func:`~tyredamp.modal.fit._pseudo.scan_sums`, ``SCAN_CHUNK`` grid poles at a
    time)."""
    poles, residues, terms = model

    def vals(sl: slice) -> Any:
        e = residual_lines(fitter, poles, residues, terms, sl) * inv[:, None, None]
        return e.reshape(-1, e.shape[-1])

    return _pseudo.scan_sums(
        fitter,
        pl,
        vals,
        lambda s, kap, p: kap[None, :] / (s[None, :] - p[:, None]),
        pg,
        SCAN_CHUNK,
    )
