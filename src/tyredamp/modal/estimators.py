"""The pole-estimator protocol of :func:`~tyredamp.modal.identify.identify_modes`.

A pole estimator turns the FRFs of a band into the poles (and participation
vectors) of a range of model orders, the raw data of a stabilisation
diagram. :func:`~tyredamp.modal.lscf.plscf` (poly-reference LSCF) is the
default; any callable with the signature of :class:`PoleEstimator` plugs in
(LSCE, SSI, a maximum-likelihood estimator, or a test double that returns
known poles)::

    def my_estimator(frequency, H, max_order, *, min_order, band, order_step):
        ...
        return PoleSet(poles=..., order=..., participation=...)

    identify_modes(frf, estimator=my_estimator)

The identification calls it with the normalised data of the band (unit RMS,
:class:`~tyredamp.modal.problem.FitProblem`) and reads, per pole, its order
(stability is judged between consecutive computed orders) and its
participation vector; poles outside the band or with ``Im p <= 0`` are
ignored by the selection.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from .lscf import PoleSet

__all__ = ["PoleEstimator"]


class PoleEstimator(Protocol):
    """Callable that estimates the poles of the model orders ``min_order..max_order``.

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Lines in Hz (uniform, > 0).
    H : ndarray, complex, shape (n_out, n_in, n_freq)
        FRFs of the band (normalised to unit RMS; any kind).
    max_order : int
        Highest model order.
    min_order : int
        Lowest model order to compute.
    band : (float, float)
        Band of the lines in Hz.
    order_step : int
        Compute every ``order_step``-th order counting down from ``max_order``.

    Returns
    -------
    PoleSet
        Poles (rad/s), their orders and participation vectors (n_in each).
    """

    def __call__(
        self,
        frequency: NDArray[np.float64],
        H: NDArray[np.complex128],
        max_order: int,
        *,
        min_order: int,
        band: tuple[float, float],
        order_step: int,
    ) -> PoleSet: ...
