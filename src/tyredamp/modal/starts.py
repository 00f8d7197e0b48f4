"""The modes an identification starts from.

Step 2 of :func:`~tyredamp.modal.identify.identify_modes`: the persistent
clusters of the stabilisation diagram, or as many of the most persistent ones
as a given mode count asks for, or the cluster (failing that, the admissible
pole) nearest to each given frequency; the persistent clusters not chosen are
started as in-band residual modes. The mode count and the frequencies are
checked against the band and what its data can support first.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError
from .poles.lscf import PoleSet
from .poles.order import Diagram, modes_shown
from .poles.selection import Cluster, StabilityFlags
from .problem.problem import FitProblem, max_modes
from .search.search import ModeSet, rejected
from .statistics.quality import RejectedMode


def _start_modes(
    problem: FitProblem,
    dg: Diagram,
    fr: NDArray[np.float64] | None,
    n_modes: int | None,
    min_fraction: float,
    warnings: list[str],
) -> tuple[ModeSet, list[RejectedMode]]:
    """The modes to start from (chosen clusters, then others as residual modes)."""
    rej = [
        rejected(c.pole, f"present in {c.fraction:.0%} of orders < {min_fraction:.0%}")
        for c in dg.weak
    ]
    n_shown = modes_shown(problem) if fr is None and n_modes is None and not dg.kept else None
    cand, extra, rej = _candidates(dg, fr, n_modes, rej, warnings, n_shown)
    if not cand:
        lo, hi = problem.band
        raise InputError(
            f"no stable mode found in [{lo:g}, {hi:g}] Hz up to order {dg.order}; raise "
            "--max-order, widen the band or give --frequencies"
        )
    n_in = problem.shape[1]
    modes = ModeSet(
        np.array([c.pole for c in cand]),
        np.array([c.participation for c in cand]).reshape(len(cand), n_in),
        np.array([c.pole for c in extra], dtype=complex),
        np.array([c.participation for c in extra], dtype=complex).reshape(len(extra), n_in),
        n_free=len(extra),
    )
    return modes, rej


def _check_counts(
    problem: FitProblem, n_modes: int | None, frequencies: ArrayLike | None
) -> NDArray[np.float64] | None:
    """Validate ``n_modes`` (bounded by the data) and ``frequencies`` (inside the band)."""
    n_out, n_in, n_f = problem.shape
    lo, hi = problem.band
    cap = max_modes(n_out, n_in, n_f)
    if n_modes is not None:
        if isinstance(n_modes, bool) or int(n_modes) != n_modes or n_modes < 1:
            raise InputError(f"n_modes: expected a positive integer, got {n_modes!r}")
        if n_modes > cap:
            raise InputError(
                f"n_modes: {n_modes} modes cannot be identified from {n_f} lines x {n_out} "
                f"output(s) x {n_in} input(s) in [{lo:g}, {hi:g}] Hz; at most {cap}"
            )
    if frequencies is None:
        return None
    fr = np.sort(as_finite(frequencies, "frequencies", ndim=1))
    if np.any((fr < lo) | (fr > hi)):
        raise InputError(f"frequencies: expected values inside the band [{lo:g}, {hi:g}] Hz")
    if fr.size > cap:
        raise InputError(
            f"frequencies: {fr.size} modes cannot be identified from the band's data; at most {cap}"
        )
    return fr


def _candidates(
    dg: Diagram,
    fr: NDArray[np.float64] | None,
    n_modes: int | None,
    rej: list[RejectedMode],
    warnings: list[str],
    n_shown: int | None = None,
) -> tuple[list[Cluster], list[Cluster], list[RejectedMode]]:
    """Modes to fit and other persistent modes to fit as in-band residual modes;
    ``n_shown``: the peaks the data show (:func:`~.poles.order.modes_shown`), for the
    start of an automatic count whose diagram kept no cluster."""
    if fr is not None:
        cand = _pick_frequencies(fr, dg.kept + dg.weak, dg.poles, dg.flags)
    else:
        n_pick = n_modes
        if n_pick is None:
            if dg.kept or not dg.weak or n_shown is None:
                return list(dg.kept), [], rej
            # no cluster persists (few orders of many inputs, noisy data): the most
            # persistent ones, as many as the peaks the data show (at least one),
            # start the fit; the mode test decides on them and the residual search,
            # from the other clusters and the residual, on the rest
            n_pick = max(1, n_shown)
        pool = sorted(dg.kept + dg.weak, key=lambda c: -c.fraction)
        if n_modes is not None and len(pool) < n_modes:
            warnings.append(f"n_modes: asked for {n_modes}, only {len(pool)} stable clusters")
        cand = sorted(pool[: int(n_pick)], key=lambda c: c.frequency_hz)
        chosen = {id(c) for c in cand}
        rej = [r for r, c in zip(rej, dg.weak, strict=True) if id(c) not in chosen]
    # modes the user did not ask for still shape the FRFs: keep the persistent
    # clusters that are not chosen (and not within 1 % of a chosen one) as
    # residual modes, so that the refinement does not pull the chosen poles
    extra = [c for c in dg.kept if all(abs(c.pole - d.pole) > 0.01 * abs(d.pole) for d in cand)]
    return cand, extra, rej


def _pick_frequencies(
    fr: NDArray[np.float64], clusters: list[Cluster], ps: PoleSet, flags: StabilityFlags
) -> list[Cluster]:
    """The cluster (or, failing that, the admissible pole) nearest to each frequency."""
    out: list[Cluster] = []
    used: set[int] = set()
    adm = np.flatnonzero(flags.admissible)
    for fi in fr:
        best = None
        if clusters:
            d = np.array([abs(c.frequency_hz - fi) / fi for c in clusters])
            for i in np.argsort(d):
                if d[i] <= 0.05 and int(i) not in used:
                    best = clusters[int(i)]
                    used.add(int(i))
                    break
        if best is None:
            if adm.size == 0:
                raise InputError(f"frequencies: no admissible pole near {fi:g} Hz")
            top = ps.order[adm].max()
            cand = adm[ps.order[adm] >= top - 2]
            j = cand[np.argmin(np.abs(ps.frequency_hz[cand] - fi))]
            if abs(ps.frequency_hz[j] - fi) > 0.1 * fi:
                raise InputError(f"frequencies: no admissible pole within 10 % of {fi:g} Hz")
            best = Cluster(
                pole=complex(ps.poles[j]),
                participation=ps.participation[j],
                members=np.array([j]),
                fraction=0.0,
                spread_frequency=0.0,
            )
        out.append(best)
    return out
