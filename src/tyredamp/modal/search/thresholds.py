"""Each mode's own threshold: the mode test's, raised where the residual's noise
lies along the response (:mod:`tyredamp.modal.search.span_noise`,
:func:`~tyredamp.modal.statistics.stats.span_threshold`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..fit.fit import FitResult, ModalFitter
from ..statistics.stats import FALSE_ALARM, span_threshold
from .residual_peaks import model_of
from .span_noise import SpanNoise, span_noise

__all__ = ["ModeTest", "local_thresholds", "residual_span"]


@dataclass(frozen=True)
class ModeTest:
    """What a mode's own threshold needs besides the base one: the parameters
    ``k`` of a mode, the lines of the band and the false-alarm rate
    (:func:`~tyredamp.modal.statistics.stats.span_threshold`)."""

    k: int
    n_lines: int
    false_alarm: float = FALSE_ALARM


def residual_span(fitter: ModalFitter, res: FitResult) -> SpanNoise:
    """Residual noise in and off the span of the data (:mod:`~tyredamp.modal.search.span_noise`)."""
    poles, residues, terms, s2 = model_of(fitter, res)
    return span_noise(fitter, poles, residues, terms, s2)


def local_thresholds(
    fitter: ModalFitter,
    span: SpanNoise | None,
    poles: NDArray[np.complex128],
    threshold: float,
    test: ModeTest | None,
) -> NDArray[np.float64]:
    """Each pole's threshold: ``threshold`` raised where the residual's noise lies
    along the response (:func:`~tyredamp.modal.statistics.stats.span_threshold`); ``threshold``
    for every pole without ``test`` or ``span``."""
    if test is None or span is None:
        return np.full(poles.size, float(threshold))
    return np.array(
        [
            span_threshold(
                threshold, test.k, fitter.n_in, test.n_lines, span.at(complex(p)), test.false_alarm
            )
            for p in poles
        ]
    )
