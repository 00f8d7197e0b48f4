"""The pole-estimator protocol of :func:`~tyredamp.modal.identify.identify_modes`.

A pole estimator turns the FRFs of a band into the poles (and participation
vectors) of a range of model orders, the raw data of a stabilisation
diagram. :func:`~tyredamp.modal.poles.lscf.plscf` (poly-reference LSCF) is the
default; any callable with the signature of :class:`PoleEstimator` plugs in
(LSCE, SSI, a maximum-likelihood estimator, or a test double that returns
known poles)::

    def my_estimator(frequency, H, max_order, *, min_order, band, order_step):
        ...
        return PoleSet(poles=..., order=..., participation=...)

    identify_modes(frf, estimator=my_estimator)

A named estimator is one line of :data:`ESTIMATORS` (:func:`register_estimator`):
the command line (``tyredamp modal --estimator NAME``), a campaign file
(``[settings.radial.modal] estimator = "NAME"``) and Python
(``identify_modes(frf, estimator="NAME")``) then all select it by that name.

The identification calls it with the normalised data of the band (unit RMS,
:class:`~tyredamp.modal.problem.problem.FitProblem`) and reads, per pole, its order
(stability is judged between consecutive computed orders) and its
participation vector; poles outside the band or with ``Im p <= 0`` are
ignored by the selection.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InputError

if TYPE_CHECKING:
    from .lscf import PoleSet

__all__ = [
    "DEFAULT_ESTIMATOR",
    "ESTIMATORS",
    "PoleEstimator",
    "get_estimator",
    "register_estimator",
]


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


def _plscf(
    frequency: NDArray[np.float64],
    H: NDArray[np.complex128],
    max_order: int,
    *,
    min_order: int,
    band: tuple[float, float],
    order_step: int,
) -> PoleSet:
    """:func:`~tyredamp.modal.lscf.plscf`, imported at the first call: naming the
    estimators (a setting checked, a command refusing its file) loads no linear algebra."""
    from .lscf import plscf

    return plscf(frequency, H, max_order, min_order=min_order, band=band, order_step=order_step)


#: The pole estimators selectable by name (``--estimator``, a campaign's ``estimator``).
ESTIMATORS: dict[str, PoleEstimator] = {"plscf": _plscf}
#: The estimator used when none is named.
DEFAULT_ESTIMATOR = "plscf"


def register_estimator(name: str, estimator: PoleEstimator) -> None:
    """Make ``estimator`` selectable by ``name`` everywhere (replaces one of that name)."""
    if not isinstance(name, str) or not name.strip() or not callable(estimator):
        raise InputError(f"estimator: expected a name and a callable, got {name!r}")
    ESTIMATORS[name] = estimator


def get_estimator(estimator: str | PoleEstimator | None) -> PoleEstimator:
    """The estimator of a name of :data:`ESTIMATORS` (a callable is returned as it is;
    None gives the default)."""
    if estimator is None:
        return ESTIMATORS[DEFAULT_ESTIMATOR]
    if callable(estimator):
        return estimator
    if estimator not in ESTIMATORS:
        raise InputError(
            f"estimator: expected a pole estimator of {sorted(ESTIMATORS)}, got {estimator!r}"
        )
    return ESTIMATORS[estimator]
