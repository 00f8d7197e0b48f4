"""The mode count (step 3 of :func:`~tyredamp.modal.identify.identify_modes`).

The fitters of one identification (:class:`_Fitters`: every output, and the
search's principal output combinations when there are many outputs), the mode
test's threshold and what each mode's own threshold needs, and the stages that
decide which modes the data hold (:func:`_select`): the out-of-band residual
modes, the mode test and the residual search of :mod:`tyredamp.modal.search`;
then the noise per output that weights the final fits. The rules are stated
in the module docstring of :mod:`tyredamp.modal.identify` (mode count of step 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..mechanics.modal_sum import pole_from_frequency_damping
from .fit.fit import FitResult, ModalFitter
from .poles.order import Diagram
from .problem.compress import _compress
from .problem.problem import FitProblem
from .search.out_of_band import search_helpers
from .search.search import (
    FixedParts,
    ModeSet,
    ModeTest,
    reject_by_test,
    residual_search,
)
from .statistics.quality import RejectedMode
from .statistics.stats import mode_parameters, mode_threshold

#: output compression (fit.compress_outputs) of the search when n_out > 1.5 rank,
#: and of the final refinement when n_out > 4 rank (module docstring of identify)
_COMPRESS_SEARCH = 1.5
_COMPRESS_FINAL = 4.0


def _threshold(problem: FitProblem, kind: str, false_alarm: float) -> float:
    """Threshold of the mode test for ``kind`` modes on ``problem`` (:func:`mode_threshold`)."""
    n_out, n_in, n_f = problem.shape
    k = mode_parameters(n_out, n_in, kind)
    # the rank-one law of a residue (complex or real, :func:`rank_one_sf`)
    return mode_threshold(k, n_f, false_alarm, problem.weight_dof, (n_out, n_in), kind)


def _mode_test(problem: FitProblem, false_alarm: float) -> ModeTest:
    """What each complex mode's own threshold needs
    (:class:`~tyredamp.modal.search.thresholds.ModeTest`)."""
    n_out, n_in, n_f = problem.shape
    return ModeTest(mode_parameters(n_out, n_in, "complex"), n_f, false_alarm)


@dataclass(frozen=True)
class _Fitters:
    """The fitters of one identification (stateless; built once per problem).

    ``cfit`` fits every output; ``sfit`` is the search's (``cfit`` or one on
    principal output combinations when there are many outputs, with their
    ``patterns``); ``rank`` the compression rank.
    """

    cfit: ModalFitter
    sfit: ModalFitter
    patterns: NDArray[np.float64] | None
    rank: int

    @classmethod
    def build(
        cls, problem: FitProblem, residuals: bool, modes: ModeSet, max_helpers: int
    ) -> _Fitters:
        n_out, n_in, _ = problem.shape
        f, H, pw, lw = problem.frequency, problem.H, problem.power, problem.line_weights
        cfit = ModalFitter(
            f, H, pw, "complex", problem.drive, upper=residuals, lower=residuals, line_weights=lw
        )
        # the searches refit many times: with more outputs than 1.5 times ``rank``
        # they run on principal output combinations; so does the final refinement
        # with more than 4 times ``rank``, whose residues, standard errors and
        # model then use every output
        rank = 2 * (modes.m + modes.hp.size + max_helpers + 2 * n_in) + 16
        if n_out <= _COMPRESS_SEARCH * rank:
            return cls(cfit, cfit, None, rank)
        h_comb, patterns = _compress(H, rank)
        sfit = ModalFitter(
            f,
            h_comb,
            pw,
            "complex",
            [],
            upper=residuals,
            lower=residuals,
            unit_weights=True,
            line_weights=lw,
        )
        return cls(cfit, sfit, patterns, rank)


def _select(
    fitters: _Fitters,
    modes: ModeSet,
    dg: Diagram,
    rej: list[RejectedMode],
    thresholds: tuple[float, ModeTest],
    auto: bool,
    refine: bool,
    max_helpers: int,
    min_contribution: float,
    search: bool,
    problem_band: tuple[float, float],
) -> tuple[FitResult | None, ModeSet, list[RejectedMode]]:
    """Step 3: refine, add out-of-band residual modes, decide the mode count.

    ``thresholds``: the mode test's threshold and what each in-band mode's own
    threshold needs (raised where the noise lies along the response,
    :func:`~tyredamp.modal.search.thresholds.local_thresholds`)."""
    thr, test = thresholds
    sfit = fitters.sfit
    band = (float(sfit.f[0]), float(sfit.f[-1]))
    out: list[RejectedMode] = []
    last: FitResult | None = None
    fixed = FixedParts(sfit)  # the trials' fixed parts, shared by the stages
    if refine and max_helpers > 0:
        last, modes, dropped = search_helpers(
            sfit, modes, problem_band, band, max_helpers, thr, fixed
        )
        out += dropped
    if not auto:
        return last, modes, out
    last, modes, dropped = reject_by_test(
        sfit,
        modes,
        problem_band,
        thr,
        refine,
        min_contribution,
        test=test,
        start=last,
        max_damping=dg.max_damping,
    )
    out += dropped
    if search and refine:
        cands = [(c.pole, c.participation) for c in dg.weak] + [
            (_pole_of(r), np.ones(sfit.n_in, complex)) for r in rej + out
        ]
        last, modes, tried = residual_search(
            sfit,
            last,
            modes,
            cands,
            problem_band,
            thr,
            dg.max_damping,
            test=test,
            fixed=fixed,
            max_helpers=max_helpers,
        )
        out += tried
    return last, modes, out


def _pole_of(r: RejectedMode) -> complex:
    """The start pole of a rejected candidate (damping ratio clipped to [1e-4, 0.5])."""
    z = min(max(r.damping_ratio, 1e-4), 0.5)
    return complex(pole_from_frequency_damping(r.frequency_hz, z))


def _noise_per_output(
    problem: FitProblem,
    fitters: _Fitters,
    modes: ModeSet,
    last: FitResult | None,
    refine: bool,
) -> NDArray[np.float64] | None:
    """Noise RMS per output for the final fit's weights: known, or from the residual
    of the latest search fit when it ran on every output, else from a linear fit."""
    if problem.sigma_out is not None:
        return np.asarray(problem.sigma_out)
    if not refine:
        return None
    if last is not None and fitters.sfit is fitters.cfit:
        return last.sigma_out
    p0, l0 = modes.all()
    return fitters.cfit.fit(p0, l0, refine=False, uncertainty=False).sigma_out
