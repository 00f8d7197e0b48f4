"""Where the residual search tries a mode, and the records of the candidates it
did not keep for a reason of their own (stage 3 of :mod:`tyredamp.modal.search.search`).

Each round starts trial modes at the coherent scan's trial poles, or else at the
residual's peaks where the scan finds room for a mode, then at the diagram's
candidates (clusters that too few orders resolved, modes rejected earlier)
whose half-power band holds enough residual power above the noise. Every
candidate of the diagram gets a record in statistical terms: where its trial
went and why it failed, or why it was not tried (too little residual power in
its half-power band, a fitted mode that stands for it, the round's trials spent:
with the coherent scan's statistic near it).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...mechanics.modal_sum import pole_from_frequency_damping, pole_quantities
from ..fit.fit import FitResult, ModalFitter
from ..statistics.quality import RejectedMode
from .modeset import rejected
from .residual_peaks import SCAN_SHARE, ScanGrid, residual_peaks, room
from .thresholds import ModeTest, local_thresholds, residual_span

#: residual search: most candidates tried per round; rounds go on while one adds a
#: mode (a band missing many modes adds a few per round; search.MAX_ROUNDS bounds them)
MAX_TRIALS = 12
#: a residual peak is tried when the coherent scan near it reaches this share of the
#: threshold (a screen of plain noise peaks; the scan's trial poles need SCAN_SHARE)
SUPPORT_SHARE = 0.5
#: a candidate of the diagram is tried when its half-power band holds residual
#: power above the noise of at least this share of the threshold (the cost drop of
#: a mode there comes from that power; a generous screen)
ROOM_SHARE = 0.25


def round_starts(
    fitter: ModalFitter,
    res: FitResult,
    view: tuple[ScanGrid, NDArray[np.float64]],
    pending: list[tuple[complex, NDArray[np.complex128]]],
    threshold: float,
    zeta0: float,
    test: ModeTest | None,
    scan: bool,
) -> tuple[list[tuple[complex, NDArray[np.complex128]]], list[RejectedMode]]:
    """The starts of one round of the residual search: the coherent scan's trial
    poles (``scan``), or else the residual's peaks where the scan finds room for
    a mode near them (``SUPPORT_SHARE`` of the threshold); then the diagram's
    candidates ``pending`` whose half-power band (+-2 zeta f) holds enough
    residual power above the noise to pass (``ROOM_SHARE`` of the threshold; the
    others are returned as rejected, with that power; one that passes and that
    the round's trials do not reach gets :func:`capped`'s reason). ``view``: the
    scan of the fit's residual and its power per line
    (:func:`~.residual_peaks.residual_view`)."""
    grid, pw = view
    found = residual_peaks(fitter.f, pw, fitter.n_out * fitter.n_in, zeta0, threshold, MAX_TRIALS)
    ones = np.ones(fitter.n_in, complex)
    starts: list[tuple[complex, NDArray[np.complex128]]] = []
    if scan:
        starts = [(p, ones) for p in scanned_poles(fitter, res, grid, threshold, test)]
    if not starts:
        level = SUPPORT_SHARE * threshold
        for fpk in found.freq:
            if grid.support(fpk, zeta0) >= level:
                starts.append((complex(pole_from_frequency_damping(fpk, zeta0)), ones))
    room_min = ROOM_SHARE * threshold
    screened: list[RejectedMode] = []
    for c in pending:
        r = room(fitter.f, found.excess, c[0])
        if r > room_min:
            starts.append(c)
        else:
            why = _too_little(r, room_min, threshold, c[0], res.poles)
            screened.append(rejected(c[0], why))
    return starts, screened


def capped(
    grid: ScanGrid,
    left: list[tuple[complex, NDArray[np.complex128]]],
    own: set[complex],
    zeta0: float,
    threshold: float,
) -> list[RejectedMode]:
    """Records of the diagram's candidates (poles in ``own``, rad/s) among the
    starts ``left`` that a round did not reach, its trials spent: with the
    coherent scan's statistic (``grid``) within ``max(zeta, zeta0) f`` of each (a
    pole held there, the modes' residues refitted: about what a trial there would
    find), against ``threshold``."""
    out = []
    for p, _ in left:
        if complex(p) not in own:
            continue
        f, z = pole_quantities(np.array([p]))
        t = grid.support(float(f[0]), max(float(z[0]), zeta0))
        why = (
            f"not tried: the round had tried its {MAX_TRIALS} candidates already; the "
            f"coherent scan's statistic near it is {t:.3g} against the threshold {threshold:.3g}"
        )
        out.append(rejected(p, why))
    return out


def _too_little(
    r: float, room_min: float, threshold: float, p: complex, poles: NDArray[np.complex128]
) -> str:
    """Why a candidate ``p`` was not tried: the residual left no room for a mode
    there; the fitted mode (of ``poles``) within its half-power band, if any, that
    stands for it."""
    power = (
        f"its half-power band holds {max(r, 0.0):.3g} noise variances of residual power "
        f"above the noise, under {room_min:.3g} ({ROOM_SHARE:g} of the threshold "
        f"{threshold:.3g})"
    )
    f, z = pole_quantities(np.concatenate([[p], poles]))
    near = np.flatnonzero(np.abs(f[1:] - f[0]) <= 2 * z[0] * f[0])
    if near.size:
        k = near[np.argmin(np.abs(f[1:][near] - f[0]))]
        return f"not tried: the mode at {f[1 + k]:.6g} Hz stands for it ({power})"
    return f"not tried: {power}: too little for a mode there to pass"


def scanned_poles(
    fitter: ModalFitter,
    res: FitResult,
    grid: ScanGrid,
    threshold: float,
    test: ModeTest | None,
) -> list[complex]:
    """The coherent scan's trial poles (:func:`~.residual_peaks.coherent_scan`) whose
    statistic reaches ``SCAN_SHARE`` of their own threshold, raised where the
    residual's noise lies along the response (:func:`local_thresholds`): the
    scan weighs the residual with the separable noise model, under which noise
    along the response makes maxima of its own (near strong modes of an H1
    estimate with force noise)."""
    got = grid.candidates(SCAN_SHARE * threshold, MAX_TRIALS)
    if test is None or not got:
        return [p for p, _ in got]
    poles = np.array([p for p, _ in got])
    thr = local_thresholds(fitter, residual_span(fitter, res), poles, threshold, test)
    return [p for (p, t), h in zip(got, thr, strict=True) if t >= SCAN_SHARE * h]


#: reasons of the diagram's candidates that no trial of their own decided
SAME_START = (
    "not tried: its pole lies within 2 x the merge distance of a current mode or of "
    "an earlier trial's start (the same candidate)"
)


def start_records(got: RejectedMode | None, p0: complex, own: bool) -> list[RejectedMode]:
    """The rejected records of one start's trial ``got`` (None: no record of its
    own) and, for a candidate of the diagram (``own``), a record at the start
    itself that says where its trial ended."""
    out = [] if got is None else [got]
    if not own:
        return out
    if got is None:
        return [rejected(p0, "tried: its trial mode did not converge or repeated a refused one")]
    f_t, z_t = got.frequency_hz, got.damping_ratio
    f0, z0 = (float(x[0]) for x in pole_quantities(np.array([p0])))
    # a record at the start itself (the trial did not move) is merged with its others
    if abs(f_t - f0) > 1e-9 * f_t or abs(z_t - z0) > 1e-9 * abs(z_t):
        out.append(
            rejected(
                p0,
                f"tried: its trial mode went to {f_t:.6g} Hz, zeta {z_t:.3g} ({got.reason})",
                got.statistic,
                got.threshold,
            )
        )
    return out


def unique_candidates(
    candidates: list[tuple[complex, NDArray[np.complex128]]],
) -> list[tuple[complex, NDArray[np.complex128]]]:
    """The candidates, each pole once (a cluster of the diagram comes both as a
    cluster and as its rejected record)."""
    out: list[tuple[complex, NDArray[np.complex128]]] = []
    for c in candidates:
        if not any(abs(q - c[0]) <= 1e-9 * abs(c[0]) for q, _ in out):
            out.append(c)
    return out
