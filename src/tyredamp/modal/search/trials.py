"""A trial mode: one added mode refined alone against modes held fixed.

The move that both the out-of-band stage
(:mod:`tyredamp.modal.search.out_of_band`) and the residual search
(:mod:`tyredamp.modal.search.search`) make: :func:`_trial` refines an added
mode with every current mode held (their fixed part formed once per mode set,
:class:`FixedParts`) and returns its statistic ``T``; :func:`sigma_bound` is the
decay rate of the admissible damping at a window's limit, :func:`_toward` the
window limit a trial stopped at.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..fit._added import FixedPart
from ..fit.fit import FitResult, ModalFitter
from .modeset import ModeSet

__all__ = ["TRIAL_NFEV", "TRIAL_TOL", "FixedParts", "sigma_bound"]

#: convergence threshold of a trial mode, in units of the residual variance s^2
#: (ModalFitter.fit_added ``tol``): a trial stops when a further step would lower the
#: cost by less than 1 s^2; like SEARCH_TOL (:mod:`.joint`) it only chooses the modes.
TRIAL_TOL = 1.0
#: evaluation limit of a trial mode (a mode that is there converges in a few steps)
TRIAL_NFEV = 30


class FixedParts:
    """The fixed parts of the trials of one identification: each trial refines
    an added mode against the current modes (:meth:`ModalFitter.fit_added`),
    whose fixed part (:meth:`ModalFitter.fixed_part`, an immutable value) is
    formed at the first trial against a mode set and passed to every trial
    against the same modes (equal poles and participation), across the search
    stages. Owned by the caller of the stages; the fitter keeps nothing.
    """

    def __init__(self, fitter: ModalFitter) -> None:
        self.fitter = fitter
        self.modes: tuple[NDArray[np.complex128], NDArray[np.complex128]] | None = None
        self.value: FixedPart | None = None

    def release(self) -> None:
        """Drop the fixed part held when it holds pseudo-lines of its basis (a long
        record's; formed again at the next trial), not to be held while the residual
        of every line is (:func:`~tyredamp.modal.search.search.residual_search`)."""
        if self.value is not None and self.value.pseudo is not None:
            self.modes = self.value = None

    def of(self, p_all: NDArray[np.complex128], l_all: NDArray[np.complex128]) -> FixedPart | None:
        """The fixed part of these modes (None when it cannot be formed)."""
        held = self.modes
        if held is None or not (np.array_equal(held[0], p_all) and np.array_equal(held[1], l_all)):
            self.modes = (p_all.copy(), l_all.copy())
            try:
                self.value = self.fitter.fixed_part(p_all, l_all)
            except (np.linalg.LinAlgError, ValueError):
                self.value = None
        return self.value


def _trial(
    fitter: ModalFitter,
    res: FitResult,
    modes: ModeSet,
    fixed: FixedParts,
    pole: complex,
    part: NDArray[np.complex128],
    w_lim: tuple[float, float],
    strict: bool = True,
    max_damping: float | None = None,
) -> tuple[complex, NDArray[np.complex128], float] | None:
    """Refine one added mode alone against ``modes`` (their fixed part from
    ``fixed``); its statistic ``T``. ``strict``: None when it stopped at a limit
    of ``w_lim`` (an out-of-band residual mode that runs into the band edge is
    not there); otherwise the limit only localises the trial. ``max_damping``:
    the trial's decay rate is bounded by that damping ratio at the window's upper
    limit (:func:`sigma_bound`), so that a trial that would be refused for its
    damping stops at the bound instead of running on (None: no bound)."""
    p_all, l_all = modes.all()
    fx = fixed.of(p_all, l_all)
    if fx is None:
        return None
    try:
        p_t, l_t, sig_t = fitter.fit_added(
            p_all,
            l_all,
            pole,
            part,
            omega_bounds=w_lim,
            tol=TRIAL_TOL,
            fixed=fx,
            max_nfev=TRIAL_NFEV,
            sigma_max=None if max_damping is None else sigma_bound(max_damping, w_lim[1]),
        )
    except (np.linalg.LinAlgError, ValueError):
        return None
    tol = 1e-4 * (w_lim[1] - w_lim[0])
    if strict and not (w_lim[0] + tol < p_t.imag < w_lim[1] - tol):
        return None  # a trial pole stopped at a limit did not find a mode there
    n_all = p_all.size
    dof0 = max(fitter.n_rows - fitter.n_cols(n_all), 1)
    dof1 = max(fitter.n_rows - fitter.n_cols(n_all + 1), 1)
    s2a = np.maximum(sig_t**2, np.maximum(fitter.noise_floor**2, 1e-300))
    s2b = np.maximum(res.sigma_out**2, s2a)
    t = float(np.sum((s2b * dof0 - s2a * dof1) / s2a))
    return p_t, l_t, t


def sigma_bound(max_damping: float, omega: float) -> float:
    """The decay rate ``sigma = -Re p`` (rad/s) of damping ratio ``max_damping`` at the
    damped natural frequency ``omega`` (rad/s): ``zeta = sigma / |p|`` with ``|p|^2
    = sigma^2 + omega^2`` gives ``sigma = zeta omega / sqrt(1 - zeta^2)``. A pole
    with ``Im p <= omega`` and a larger decay rate has a larger damping ratio."""
    return float(max_damping * omega / np.sqrt(1.0 - max_damping**2))


def _toward(p: complex, w_lim: tuple[float, float]) -> int:
    """The side (+1 up, -1 down, 0 none) of the window ``w_lim`` (rad/s) at whose
    limit a trial pole ``p`` stopped: it found no optimum inside its window and
    runs toward structure beyond it."""
    tol = 1e-4 * (w_lim[1] - w_lim[0])
    if p.imag >= w_lim[1] - tol:
        return 1
    return -1 if p.imag <= w_lim[0] + tol else 0
