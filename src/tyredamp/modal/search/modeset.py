"""The mode set of the automatic mode count and its checked fit.

:class:`ModeSet` holds the current modes of the search stages
(:mod:`tyredamp.modal.search.search`, :mod:`tyredamp.modal.search.out_of_band`,
:mod:`tyredamp.modal.final`); :func:`fit_checked` fits them and drops the
modes a fit lost (:func:`lost_modes`: left their side of the band, or merged).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...exceptions import ConvergenceError
from ..fit.fit import FitResult, ModalFitter
from ..poles.selection import same_place_distinct
from ..statistics.quality import RejectedMode

__all__ = [
    "MERGE",
    "ModeSet",
    "as_residual",
    "fit_checked",
    "lost_modes",
    "outside_side",
    "rejected",
    "too_damped",
    "with_residual",
]

#: poles closer than this (relative to |p|) are one mode (but see :func:`lost_modes`)
MERGE = 5e-4


@dataclass
class ModeSet:
    """Current modes of a search: ``m`` in-band, then ``len(hp)`` residual modes.

    The first ``n_free`` residual modes are in-band modes the user did not ask
    for (not checked against the band), the others lie outside the band.
    """

    poles: NDArray[np.complex128]
    part: NDArray[np.complex128]
    hp: NDArray[np.complex128]
    hl: NDArray[np.complex128]
    n_free: int = 0

    @property
    def m(self) -> int:
        return int(self.poles.size)

    def all(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        return np.concatenate([self.poles, self.hp]), np.concatenate([self.part, self.hl])

    def take(self, res: FitResult) -> ModeSet:
        m = self.m
        return ModeSet(
            res.poles[:m], res.participation[:m], res.poles[m:], res.participation[m:], self.n_free
        )


def rejected(
    p: complex, why: str, t: float = float("nan"), thr: float = float("nan")
) -> RejectedMode:
    """Record of a candidate that was not kept."""
    return RejectedMode(
        float(abs(p) / (2 * np.pi)), float(-p.real / abs(p)), why, float(t), float(thr)
    )


def lost_modes(
    res: FitResult, modes: ModeSet, band: tuple[float, float]
) -> tuple[NDArray[np.intp], str]:
    """The modes a fit of ``modes`` lost, and why: those that left their side of
    the band (in-band modes outside it, out-of-band residual modes inside it), or
    else the weaker of two that merged (none: an empty index); residual modes (tails
    shaped together) and modes of distinct participation (repeated roots) do not."""
    m = modes.m
    p = res.poles
    fd = p.imag / (2 * np.pi)
    inb = (fd >= band[0]) & (fd <= band[1])
    free = np.zeros(modes.hp.size, bool)
    free[: modes.n_free] = True
    wrong = np.flatnonzero(np.concatenate([~inb[:m], inb[m:] & ~free]))
    if wrong.size:
        return wrong, "crossed the band edge during refinement"
    d = np.abs(p[:, None] - p[None, :]) / np.abs(p)[:, None]
    np.fill_diagonal(d, np.inf)
    d[m:, m:] = np.inf
    if res.participation.shape[1] > 1:
        d[same_place_distinct(res.participation)] = np.inf
    if d.size and d.min() < MERGE:
        i, j = np.unravel_index(np.argmin(d), d.shape)
        k = i if res.contribution[i] < res.contribution[j] else j
        return np.array([k], np.intp), "merged with another mode during refinement"
    return wrong, ""


def as_residual(modes: ModeSet, broad: NDArray[np.bool_]) -> ModeSet:
    """``modes`` with the in-band modes ``broad`` (m,) moved to the front of the
    residual modes, as free ones (not checked against the band, not reported):
    poles damped beyond the admissible limit that the data still need (broad
    structure, e.g. the tails of modes outside the band). The order of
    :meth:`ModeSet.all` is kept when only the last in-band modes move."""
    keep = ~broad
    return ModeSet(
        modes.poles[keep],
        modes.part[keep],
        np.concatenate([modes.poles[broad], modes.hp]),
        np.concatenate([modes.part[broad], modes.hl]),
        modes.n_free + int(np.count_nonzero(broad)),
    )


def with_residual(modes: ModeSet, p: complex, lv: NDArray[np.complex128]) -> ModeSet:
    """``modes`` with the residual mode ``p`` (participation ``lv``, (n_in,)) added
    last: outside the band, checked against it in every later fit."""
    return ModeSet(
        modes.poles,
        modes.part,
        np.append(modes.hp, p),
        np.concatenate([modes.hl, np.asarray(lv)[None, :]]),
        modes.n_free,
    )


def outside_side(f_hz: float, band: tuple[float, float]) -> int:
    """The side of ``band`` (Hz) on which a residual mode of damped frequency ``f_hz``
    (Hz) lies within the range of the residual modes outside the band (a factor 2
    beyond its edge): +1 above, -1 below, 0 neither."""
    lo, hi = band
    if hi < f_hz <= 2 * hi:
        return 1
    return -1 if lo / 2 <= f_hz < lo else 0


def too_damped(poles: NDArray[np.complex128], max_damping: float | None) -> NDArray[np.bool_]:
    """Which poles are damped beyond ``max_damping`` (none when it is None)."""
    if max_damping is None:
        return np.zeros(poles.size, bool)
    return np.asarray(-poles.real > max_damping * np.abs(poles))


def fit_checked(
    fitter: ModalFitter,
    modes: ModeSet,
    refine: bool,
    band: tuple[float, float],
    start: FitResult | None = None,
    in_band_only: bool = False,
    **fit_kw: object,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """Fit the modes; drop any that left its side of the band or merged, and refit.

    ``fit_kw`` go to :meth:`~tyredamp.modal.fit.fit.ModalFitter.fit`, ``start`` (the
    fit the modes come from, if any) to its first fit. ``in_band_only``: a
    refinement may stop once the in-band modes have converged, the residual modes
    outside the band being nuisance parameters (``n_interest`` of ``fit``).
    Returns the fit, the modes at the fit's values and the dropped ones.
    """
    dropped: list[RejectedMode] = []
    cur = modes
    for _ in range(modes.m + modes.hp.size + 1):
        m = cur.m
        p0, l0 = cur.all()
        first = start if cur is modes else None
        n_int = m if in_band_only else None
        res = fitter.fit(p0, l0, refine=refine, start=first, n_interest=n_int, **fit_kw)  # type: ignore[arg-type]
        fd = res.poles.imag / (2 * np.pi)
        wrong, why = lost_modes(res, cur, band)
        if not wrong.size:
            return res, cur.take(res), dropped
        # every mode that crossed a band edge is dropped at once (one refit)
        inband = wrong[wrong < m]
        if inband.size >= m:
            raise ConvergenceError(f"every mode {why}")
        dropped += [
            rejected(complex(cur.poles[i]), f"complex fit: {why} ({fd[i]:.2f} Hz)") for i in inband
        ]
        out = wrong[wrong >= m] - m
        keep_m = np.setdiff1d(np.arange(m), inband)
        keep_h = np.setdiff1d(np.arange(cur.hp.size), out)
        cur = ModeSet(
            cur.poles[keep_m],
            cur.part[keep_m],
            cur.hp[keep_h],
            cur.hl[keep_h],
            int(np.count_nonzero(keep_h < cur.n_free)),
        )
    raise ConvergenceError("refinement kept losing modes")
