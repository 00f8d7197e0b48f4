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

``V`` a robust noise level per output (:func:`noise_floor`: the larger of the
median of the first fit's residual and the noise floor from second differences
of adjacent lines; a median leaves out the few lines near sharp peaks where the
model errs), ``H`` the data (its magnitude, not the model's, so that a mode
the model lacks is not taken for lines without error), ``H^`` the fitted model
and ``eps`` the relative model error, estimated from the data by the moment
equation of the weighted cost (its expectation for a correct noise model)::

    sum 2 |H^ - H|^2 / (V + eps^2 |H|^2) = n_obs - n_par                (2)

whose left side falls monotonically in ``eps``: (2) has one root when the
cost at ``eps = 0`` exceeds ``n_obs - n_par`` (the fit leaves structure) and
none otherwise (``eps = 0``: the noise explains the residual, and nothing
changes). The identification is repeated with (1) as the per-line variance
(the mode count decided again against it, standard errors widened by it) and
``eps`` re-estimated from the new fit. A fit that split a peak into two poles
leaves a small residual, and gives back a small ``eps``: eq. (2) can hold for
a split fit and for the merged one alike. The repetitions therefore only raise
``eps``: a pass whose fit gives back a larger ``eps`` than it was decided with
(by more than :data:`EPS_TOLERANCE`) is followed by one against that larger
value (at most :data:`PASSES` passes), and the last pass is the result.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...frf import FRF, FRFKind
from ...mechanics.modal_sum import kind_factor
from ..model import ModalModel
from ..statistics.stats import difference_noise
from .problem import FitProblem, build_problem

__all__ = [
    "EPS_TOLERANCE",
    "PASSES",
    "Identification",
    "NoiseFloor",
    "noise_floor",
    "relative_model_error",
    "with_model_error",
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
        ``V`` of eq. (1), units of ``H`` squared (read-only; one level per FRF
        is a view along the lines).
    what : str
        Where it comes from, for people.
    """

    variance: NDArray[np.float64]
    what: str


def noise_floor(
    frf: FRF, problem: FitProblem, residual: NDArray[np.complex128] | None = None
) -> NoiseFloor:
    """``V`` of eq. (1) on the whole axis of ``frf``, for a fit whose noise was
    estimated from its residual: per FRF the larger of two robust estimates, the
    noise floor from second differences of the band's lines
    (:func:`~tyredamp.modal.statistics.stats.difference_noise`) and the median of the fit's own
    ``residual`` (shape (n_out, n_in, n_band), units of ``H``; ``|r|^2`` of complex
    Gaussian noise is exponential with median ``s^2 ln 2``). A median leaves out the
    few lines near sharp peaks where the model errs; the residual's median also holds
    noise that adjacent lines share (a window's leakage), which second differences
    cancel."""
    s2 = difference_noise(problem.H, per_input=True) * problem.scale**2  # (n_out, n_in)
    if residual is not None and residual.size:
        r2 = residual.real**2 + residual.imag**2
        s2 = np.fmax(s2, np.median(r2, axis=2) / math.log(2.0))
    # one level per FRF: a read-only view along the lines, not an array of them
    full = np.broadcast_to(s2[:, :, None], frf.H.shape)
    return NoiseFloor(full, "the noise of the fit's residual (a median over lines)")


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
    if ok.all():  # every entry counts: the same entries in the same order, no copies
        r2, P, V = r2.ravel(), P.ravel(), V.ravel()
    else:
        r2, P, V = r2[ok], P[ok], V[ok]
    del ok

    def excess(log_eps: float) -> float:
        return float(np.sum(2.0 * r2 / (V + math.exp(2.0 * log_eps) * P))) - dof

    lo, hi = math.log(1e-9), math.log(1e3)
    pos = V > 0
    # the cost at eps = 0; a residual on a line without noise makes it infinite
    at_zero = math.inf if np.any(r2[~pos] > 0) else float(np.sum(2.0 * r2[pos] / V[pos]))
    if not at_zero > dof:
        return 0.0
    if excess(hi) > 0:
        return math.exp(hi)
    if excess(lo) <= 0:
        return math.exp(lo)
    # the cost falls monotonically with eps: bisection of log eps to 1e-3
    # (0.1 % of eps) brackets the root in 15 halvings of [log 1e-9, log 1e3]
    while hi - lo > 1e-3:
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0:
            lo = mid
        else:
            hi = mid
    return math.exp(0.5 * (lo + hi))


class Identification(Protocol):
    """What :func:`with_model_error` reads of an identification
    (:class:`~tyredamp.modal.identify.ModalIdentification`)."""

    @property
    def models(self) -> dict[str, ModalModel]: ...
    @property
    def band_hz(self) -> tuple[float, float]: ...
    @property
    def noise_source(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...


R = TypeVar("R", bound=Identification)


def with_model_error(
    frf: FRF,
    variance: ArrayLike | None,
    first: list[R],
    run: Callable[[ArrayLike | None, str], R],
) -> tuple[R, float]:
    """``first`` decided again against eq. (1), when its fit leaves structure beyond
    a noise estimated from its residual (module docstring).

    Parameters
    ----------
    frf : FRF
        The data ``first`` was identified from; ``variance`` the variance it was given.
    first : list of one identification
        The identification against the noise alone, in a list that is emptied
        once the passes begin (its arrays are not held through them).
    run : callable
        ``run(variance, note)`` identifies ``frf`` again with a per-line
        ``variance`` (shape of ``frf.H``, units of ``H`` squared, made for the
        call: it may normalise it in place) that ``note`` describes.

    Returns
    -------
    identification, float
        The last pass (a warning added) and its ``eps``; ``(first, 0.0)`` where
        the noise was measured, the fit passed, or eq. (2) has no root.
    """
    res = first[0]
    kind = "complex" if "complex" in res.models else "real"
    q = res.models[kind].quality
    if res.noise_source != "residual":
        return res, 0.0  # a measured noise: a fit that misses it has failed, and says so
    if q is None or q.passed or not math.isfinite(q.chi2) or q.dof <= 0:
        return res, 0.0
    problem = build_problem(frf, res.band_hz, variance=variance)
    lines, f_band = problem.lines, problem.frequency
    H = np.asarray(frf.H)[:, :, lines]
    floor = noise_floor(frf, problem, _model_band(res.models[kind], f_band, frf.kind) - H)
    del problem  # its normalised copy of the data is not held through the passes
    V = floor.variance[:, :, lines]

    def eps_of(r: R) -> float:
        m = r.models[kind]
        dof = m.quality.dof if m.quality is not None else 0
        return relative_model_error(H, _model_band(m, f_band, frf.kind), V, dof)

    eps = eps_of(res)
    if eps <= 0.0:
        return res, 0.0
    first.clear()
    # each pass decides the modes against the eps of the fits before it; a pass
    # whose fit gives back a larger eps (it merged a split, so the model error
    # shows) is followed by one against that eps: the sequence only rises, to the
    # largest eps the fits of the data give back (the fixed point of eq. (2) that
    # holds the fewest modes; a split fit reproduces its own smaller eps too)
    for _ in range(PASSES):
        del res  # the pass before is not held through this one
        res = run(
            _floor_plus_error(floor, H, lines, eps),
            f"{floor.what} plus a model error of {eps:.2%} of the response",
        )
        again = eps_of(res)
        if again <= eps * (1.0 + EPS_TOLERANCE):
            break
        eps = again
    res.warnings.append(
        f"the fit left structure beyond {floor.what} that no modal sum explains (leakage, "
        "a window, a non-linearity, ...): modes were decided and their uncertainty stated "
        f"against a noise that includes a model error of {eps:.2%} of the response"
    )
    return res, eps


def _floor_plus_error(
    floor: NoiseFloor, H: NDArray[np.complex128], lines: slice, eps: float
) -> NDArray[np.float64]:
    """Eq. (1) on the whole axis: the floor plus ``eps^2 |H|^2`` on the band's lines
    (``H`` the band's data), formed in blocks of lines without full-length
    temporaries."""
    v = np.empty(floor.variance.shape)
    v[...] = floor.variance
    vb = v[:, :, lines]
    for a in range(0, H.shape[2], _SYNTH_BLOCK):
        h = H[:, :, a : a + _SYNTH_BLOCK]
        vb[:, :, a : a + h.shape[2]] += eps**2 * (h.real**2 + h.imag**2)
    return v


#: lines per block of the synthesised model (:func:`_model_band`): the modal sum's
#: per-mode temporaries do not grow with the lines
_SYNTH_BLOCK = 1 << 15


def _model_band(m: ModalModel, f: NDArray[np.float64], kind: FRFKind) -> NDArray[np.complex128]:
    """The model ``m`` synthesised on the band's lines ``f`` (Hz), in the FRF ``kind``,
    in blocks of :data:`_SYNTH_BLOCK` lines."""
    h = np.empty((m.psi_out.shape[0], m.psi_in.shape[0], f.size), np.complex128)
    for a in range(0, f.size, _SYNTH_BLOCK):
        fb = f[a : a + _SYNTH_BLOCK]
        h[:, :, a : a + fb.size] = m.receptance(fb) * kind_factor(2 * np.pi * fb, kind)
    return h
