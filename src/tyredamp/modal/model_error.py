"""A noise level that includes model error: the fit's lack of fit, proportional to the response.

Measured FRFs hold structure that no modal sum of the identified order
explains: leakage and windows of an impact test with few lines per half-power
band, a slightly non-linear structure, a transducer's mass, a step where an
analyser changed its range. Near a resonance this error is proportional to
the response (a window's or a leakage error is a fraction of the peak), and it
dwarfs the measured noise there: on a measured free beam with 1 Hz lines and
0.02 % damping the residual of the correct six-mode model is 10-70 times the
noise floor at the peaks and at the floor elsewhere. Tested against the noise
floor alone, a second pole beside each peak is "significant" although it only
fits the peak's distortion: the data do not prove two modes there.

This applies where the data carry no measured noise (no variance, no
coherence: an impact test's FRFs as exported, a file of FRFs alone), where
the noise is estimated from the fit's residual and the second differences of
adjacent lines. Where the noise was measured (a variance, or the coherence of
averages), a fit that leaves structure beyond it has failed, and its verdict
says so: the lack of fit is not renamed noise.

The noise model used instead (the additive-plus-proportional error model of
measurement practice; Pintelon & Schoukens, *System Identification*, 2nd ed.
2012, sec. 3.5 and 4.3, treat non-linear distortions the same way, as a noise
whose level follows the signal)::

    Var H_jkf = V_jkf + eps^2 |H_jkf|^2                                 (1)

``V`` the noise the first fit used (estimated from its residual and the
second differences of adjacent lines), ``H`` the data (its magnitude, not the
model's, so that a mode the model lacks is not taken for noise-free lines),
``H^`` the fitted model and ``eps`` the relative model error, estimated from the data by the moment
equation of the weighted cost (its expectation for a correct noise model)::

    sum 2 |H^ - H|^2 / (V + eps^2 |H|^2) = n_obs - n_par                (2)

whose left side falls monotonically in ``eps``: (2) has one root when the
cost at ``eps = 0`` exceeds ``n_obs - n_par`` (the fit leaves structure) and
none otherwise (``eps = 0``: the measured noise explains the residual, and
nothing changes). The identification is repeated with (1) as the per-line
variance (the mode count decided again against it, standard errors widened by
it) and ``eps`` re-estimated from the new fit, until it changes by less than
:data:`EPS_TOLERANCE` (at most :data:`PASSES` repetitions). Eq. (1) is
never below the noise the first identification used, so a repetition can
only take modes away; one that finds a mode the first did not (a noise
model inconsistent with the data: a floor from second differences below the
noise of some lines) is not used, and the first result stands. So does the first result when the
repetition keeps as many modes: eq. (1) is there to decide which peaks the
data prove to be modes, and a fit whose modes it confirms keeps its values
and the errors of its own noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from ..frf import FRF
from .problem import FitProblem, line_variance
from .stats import difference_noise

__all__ = [
    "EPS_TOLERANCE",
    "PASSES",
    "NoiseFloor",
    "noise_floor",
    "relative_model_error",
]

#: most repetitions of the identification with a re-estimated model error
PASSES = 3
#: relative change of ``eps`` below which the repetitions stop
EPS_TOLERANCE = 0.2


@dataclass(frozen=True)
class NoiseFloor:
    """The measured noise of an FRF, per line, on its whole axis.

    Attributes
    ----------
    variance : ndarray, shape (n_out, n_in, n_freq)
        ``V`` of eq. (1), units of ``H`` squared.
    what : str
        Where it comes from, for people.
    """

    variance: NDArray[np.float64]
    what: str


def noise_floor(
    frf: FRF,
    problem: FitProblem,
    variance: NDArray[np.float64] | None,
    sigma_out: NDArray[np.float64] | None = None,
) -> NoiseFloor:
    """``V`` of eq. (1) on the whole axis of ``frf``: the variance the fit of
    ``problem`` used (given, carried by the FRF or from the coherence), or, for
    a fit whose noise was estimated from its residual, per output the larger of
    that estimate ``sigma_out`` (RMS, units of ``H``) and the noise floor from
    second differences of the band's lines
    (:func:`~tyredamp.modal.stats.difference_noise`). ``V`` is never below the
    noise the first fit decided its modes with, so eq. (1) can only raise it:
    the repeated identification does not find modes in noise the first one
    did not call noise."""
    n = frf.frequency.size
    source, v = line_variance(frf, np.arange(n), np.asarray(frf.H), variance)
    if v is not None and source == "variance":
        return NoiseFloor(np.asarray(v, dtype=float), "the per-line variance")
    if v is not None:
        return NoiseFloor(np.asarray(v, dtype=float), "the noise from the coherence")
    full = np.empty(frf.H.shape)
    s2 = difference_noise(problem.H) * problem.scale**2
    if sigma_out is not None and np.all(np.isfinite(sigma_out)):
        s2 = np.fmax(s2, np.asarray(sigma_out, dtype=float) ** 2)
    full[:] = s2[:, None, None]
    return NoiseFloor(full, "the noise estimated from the residual")


def relative_model_error(
    H: NDArray[np.complex128],
    H_model: NDArray[np.complex128],
    V: NDArray[np.float64],
    dof: int,
) -> float:
    """Relative model error ``eps`` of eq. (2) (0 when the noise explains the residual).

    Parameters
    ----------
    H, H_model : ndarray, complex, shape (n_out, n_in, n_freq)
        Data and fitted model on the band's lines.
    V : ndarray, shape (n_out, n_in, n_freq)
        Measured variance ``V`` of each line (units of ``H`` squared).
    dof : int
        ``n_obs - n_par`` of the fit (real observations less real parameters).

    Returns
    -------
    float
        ``eps >= 0``; 0 when the cost at ``eps = 0`` does not exceed ``dof``,
        or when it cannot be formed (no positive variance, no degrees of freedom).
    """
    r2 = np.abs(H_model - H) ** 2
    P = np.abs(H) ** 2
    V = np.asarray(V, dtype=float)
    ok = (V > 0) | (P > 0)
    if dof <= 0 or not np.any(ok):
        return 0.0
    r2, P, V = r2[ok], P[ok], V[ok]

    def excess(log_eps: float) -> float:
        return float(np.sum(2.0 * r2 / (V + math.exp(2.0 * log_eps) * P))) - dof

    lo, hi = math.log(1e-9), math.log(1e3)
    pos = V > 0
    if not np.all(pos):  # lines without noise: the cost is infinite at eps = 0
        start = np.inf if np.any(r2[~pos] > 0) else excess(-math.inf)
    else:
        start = float(np.sum(2.0 * r2 / V)) - dof
    if not start > 0 or excess(hi) > 0:
        return 0.0 if not start > 0 else math.exp(hi)
    if excess(lo) <= 0:
        return math.exp(lo)
    return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-3))
