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
from .modeset import outside_side, with_residual
from .residual_peaks import model_of, rank_one_statistic
from .search import (
    FIRST_NFEV,
    MIN_LOW_LINES,
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

    A trial pole is started above the band, and below it when ``f_lo > 0`` and
    at least ``MIN_LOW_LINES`` lines lie in ``[f_lo, 2 f_lo]``, where the
    current fit's residual asks for a pole on that side (:func:`_scan_start`:
    the pole within a factor 2 of the edge whose column explains most of the
    residual; a fixed ladder of starts, ``1.1 f_hi``, ``1.3 f_hi``, ..., began
    a trial far from a strong mode just beyond the edge and lost it behind a
    broad pole or a residual mode piled at the edge). Only the trial mode is refined, with every
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
    k_next = dict.fromkeys(sides, 0)  # residual modes added per side
    failed_at: dict[float, int] = {}  # helpers held when the side's last trial failed
    while any(failed_at.get(s) != cur.hp.size and k_next[s] < max_helpers for s in sides):
        for side in sides:
            while failed_at.get(side) != cur.hp.size and k_next[side] < max_helpers:
                got = _helper(fitter, res, cur, fixed, band, side, zeta0, threshold)
                if got is None or isinstance(got, str):
                    # failed, or the joint refit lost it (into the band): the same
                    # residual would start the same trial
                    failed_at[side] = cur.hp.size
                    continue
                k_next[side] += 1
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
    zeta0: float,
    threshold: float,
) -> tuple[FitResult, ModeSet, list[RejectedMode]] | str | None:
    """A helper trial on ``side`` (+1 above the band, -1 below) of
    :func:`search_helpers`: the refit with it, "lost" when the joint refit lost
    it (into the band, or merged), None when it failed (not significant, at a
    limit, or moved out of its range)."""
    lo, hi = band
    edge = (hi, 2 * hi) if side > 0 else (lo / 2, lo)
    w_lim = (2 * np.pi * edge[0], 2 * np.pi * edge[1])
    ph = _scan_start(fitter, res, edge, side, zeta0)
    if ph is None:
        return None
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


#: damping ratios of the scan for a residual mode's start, relative to the modes'
SCAN_SCALES = (0.5, 1.0, 2.0)
#: grid points of the scan formed at once (per block of lines)
SCAN_CHUNK = 64


def _scan_start(
    fitter: ModalFitter,
    res: FitResult,
    edge: tuple[float, float],
    side: float,
    zeta0: float,
) -> complex | None:
    """Where the fit's residual asks for a pole outside the band: the trial pole
    of the range ``edge`` (Hz, the side's factor 2 beyond the band edge) whose
    column ``kappa / (s - p)`` over the band's lines explains most of the
    residual, in units of each output's noise (the rank-one statistic of the
    coherent scan, :func:`~tyredamp.modal.search.residual_peaks.coherent_scan`, over
    every line: a mode outside the band reaches into it with its tail). Grids of
    damping ``SCAN_SCALES`` times ``zeta0``, step ``zeta f``. None when the
    range holds no grid point."""
    grids = []
    for sc in SCAN_SCALES:
        z = float(np.clip(sc * zeta0, 1e-3, 0.2))
        a0, b0 = (edge[0] * (1 + z), edge[1]) if side > 0 else (edge[0], edge[1] / (1 + z))
        if 0 < a0 < b0:
            fg = a0 * (1 + z) ** np.arange(int(np.log(b0 / a0) / np.log1p(z)) + 1)
            grids.append(pole_from_frequency_damping(fg, z))
    if not grids:
        return None
    pg = np.concatenate(grids)
    poles, residues, terms, s2 = model_of(fitter, res)
    inv = 1.0 / np.sqrt(s2)
    pl = fitter._pseudo_lines()
    if pl is not None:  # a long record: the sums from pseudo-lines (fit._pseudo)
        m, nrm2 = _pseudo_scan(fitter, pl, pg, (poles, residues, terms), inv)
        t = rank_one_statistic(m, nrm2, fitter.n_out, fitter.n_in)
        return complex(pg[int(np.argmax(t))])
    # the inner products <a_g, e_jk> and ||a_g||^2, summed over blocks of lines (the
    # residual of a long axis with many FRFs is never held whole)
    m = np.zeros((fitter.n_out * fitter.n_in, pg.size), complex)
    nrm2 = np.zeros(pg.size)
    # blocks sized for the SCAN_CHUNK complex trial columns formed with each
    for sl, e in residual_blocks(fitter, poles, residues, terms, 2 * SCAN_CHUNK):
        eb = (e * inv[:, None, None]).reshape(-1, e.shape[-1])
        s, kap, _ = factors(fitter, sl)
        for c0 in range(0, pg.size, SCAN_CHUNK):
            g = slice(c0, c0 + SCAN_CHUNK)
            a = s[None, :] - pg[g, None]
            np.divide(kap[None, :], a, out=a)
            m[:, g] += eb @ a.conj().T
            nrm2[g] += np.sum(a.real**2 + a.imag**2, axis=1)
    t = rank_one_statistic(m, nrm2, fitter.n_out, fitter.n_in)
    return complex(pg[int(np.argmax(t))])


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
    """The inner products of :func:`_scan_start` (``<a_g, e_jk>``, ``||a_g||^2``) on a
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
