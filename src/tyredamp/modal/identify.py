"""Automatic modal identification: FRFs in, real and complex modal models out.

Pipeline of :func:`identify_modes` (spec ``radial-damping.md`` steps 3-6):

1. poles of the model orders ``max_order / 4 .. max_order`` (every
   ``order_step``-th, default every second) by pLSCF
   (:func:`~tyredamp.modal.poles.lscf.plscf`);
2. stabilisation and automatic selection (:mod:`~tyredamp.modal.poles.selection`),
   no frequencies needed; a mode count or approximate frequencies may be given;
3. residues by LSFD with the complex-mode model; modes whose contribution to
   the FRFs is negligible are rejected (rule below) and the fit repeated;
4. for each requested model (``"complex"``: eq. [10]; ``"real"``: eq. [2]/[3])
   non-linear refinement of poles, participation and residues over all FRFs
   together (:class:`~tyredamp.modal.fit.fit.ModalFitter`), mass-normalised
   scaling from the drive points, standard errors, fit indicators.

Automatic order of step 1 (``max_order`` not given; ``n = n_in`` inputs, ``m``
persistent clusters in the diagram of highest order ``p``, which has ``p n``
roots; ``limit = 2 n_freq / (n_in + 1) - 2``):

* start at ``ceil(60 / n)``, or ``ceil((4 n_modes + 16) / n)`` (at least
  ``30 / n``) with a mode count or frequencies;
* *sizing*: while ``p n < 4 (m + 2)`` (fewer than twice the roots of the ``m``
  modes and of two residual terms), raise ``p`` to ``max(2 p, 4 (m + 2) / n)``;
* *settling*: a sized diagram whose persistent clusters hold fewer than two
  thirds of its stable poles is unsettled. Such a share is the signature of an
  order too low for the band: with about as many modes as root pairs, the
  roots are shared among the modes and move from order to order, and few
  columns persist, so ``m`` is small and the sizing rule is met although most
  modes are missing (30 modes in 10-190 Hz at order 60: 3-5 persistent
  clusters holding 24-55 % of the stable poles; the settled diagrams of the
  virtual tyre, the rings and synthetic bands of 6-20 modes hold 67-100 %).
  An order too high also lowers the share: its surplus roots fit the noise
  and are now and then stable. A trial at ``2 p + 8 / n`` (what the sizing
  rule asks when every root pair of order ``p`` is a mode) tells the two
  apart. It is kept, and sizing and settling go on from it, only when its
  diagram has more persistent clusters *and* a larger persistent share:
  modes that were not resolved form columns at the higher order, whereas a
  higher order only adds noise poles to a resolved band, so the share falls.
  Otherwise order ``p`` and its diagram are kept as they were and the
  search stops.
* *several inputs*: a settled diagram can meet the sizing rule with few of
  the modes resolved (20 modes, 2 inputs, order 30: 8-15 persistent
  clusters); one more trial at the order the sizing rule asks for the modes
  the peaks shown can hold, ``ceil(4 (n M + 2) / n)`` (``M`` below), is kept
  when it has more persistent clusters and either a larger share or a share
  of its own that is settled (30 modes, 3 inputs: 17 clusters at order 43 and
  a share of 0.90, all 30 at order 119 and 0.83, a settled diagram that an
  order only too high would not give).

No order exceeds ``limit``, nor the cap set by the modes the data show:
``max(p_start, ceil(8 (M + 2) / n))`` with ``M`` the resonance peaks of the
FRFs that stand out of their noise (:func:`~tyredamp.modal.poles.order.modes_shown`:
prominence of the FRFs in noise units above twice the largest excursion
``n_freq`` lines of noise make at the false-alarm rate), i.e. twice the roots
the sizing rule asks for those modes. The cap follows the resonances, not the
lines: a band sampled more finely shows the same peaks and keeps its order,
where the surplus roots of a higher order would fit the noise of the many
lines and form persistent columns of their own. Settled diagrams (the virtual tyre, the rings,
bands of up to about 20 modes) take no trial and cost what the sizing rule
alone costs; each raise or trial recomputes pLSCF at the higher order, and a
rejected trial costs one pLSCF at about twice the final order.

Mode count of step 3 (automatic selection only), decided by statistics
(:mod:`~tyredamp.modal.statistics.stats`, :mod:`~tyredamp.modal.search.search`): each mode's
statistic ``T`` (the rise of the weighted cost, in units of the noise
variance, when the mode is removed) must exceed ``chi2_k^-1(1 - alpha /
n_freq)`` (``k`` the mode's parameters, ``alpha`` the false-alarm rate,
default 1 %), raised where the residual's noise lies along the response
(:mod:`~tyredamp.modal.search.span_noise`, :func:`~tyredamp.modal.statistics.stats.span_threshold`:
an H1 estimate's input noise is common to the outputs and lies in the span
of ``H(f)``, where a mode's shape lies); the weakest failing mode is dropped
and the rest refitted.
Then a residual-driven search tries candidates for missed modes (diagram
clusters that too few orders resolved, modes rejected earlier, peaks of the
residual) and keeps those that pass the same test, until none does. After
the refinement a mode that left the band, or that merged with another
(poles closer than 0.05 % of ``|p|``; with several inputs, participation
vectors parallel too: two modes at one pole with different participation
are a repeated root), is dropped and the fit repeated.

The data are cut to the band and normalised first
(:func:`~tyredamp.modal.problem.problem.build_problem`): the result does not depend
on the magnitude of the data, and the noise model (given per-line variance,
coherence and averages, or the residual) weights the final
maximum-likelihood fits (:mod:`~tyredamp.modal.final`), whose goodness of
fit is tested against the noise (``ModalModel.quality``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._blas import blas_threads as blas_limit
from ..exceptions import InputError
from ..frf import FRF
from .assemble import ModelContext, to_model
from .final import final_complex, fit_real
from .fit.fit import ModalFitter
from .mode_count import (
    _COMPRESS_FINAL,
    _Fitters,
    _mode_test,
    _noise_per_output,
    _select,
    _threshold,
)
from .model import ModalModel
from .poles.estimators import PoleEstimator, get_estimator
from .poles.lscf import PoleSet, plscf
from .poles.order import SelectionRules, default_order, settle_order
from .poles.selection import Cluster, StabilityFlags
from .problem.compress import combine_outputs
from .problem.model_error import with_model_error
from .problem.problem import SET_ASIDE, FitProblem, build_problem
from .search.search import ModeSet
from .starts import _check_counts, _start_modes
from .statistics.quality import RejectedMode, merge_rejected
from .statistics.stats import FALSE_ALARM

__all__ = ["ModalIdentification", "ModelChoice", "identify_modes"]

ModelChoice = Literal["real", "complex", "both"]
_METHOD = (
    "pole estimator {est}, automatic selection, mode count by a likelihood-ratio test, "
    "residual search, maximum-likelihood refinement (variable projection)"
)


@dataclass(frozen=True)
class ModalIdentification:
    """Result of :func:`identify_modes`.

    Attributes
    ----------
    models : dict of str to ModalModel
        ``"complex"`` and/or ``"real"``; each has its
        :class:`~tyredamp.modal.statistics.quality.FitQuality` in ``quality`` (goodness
        of fit, each mode's test statistic), standard
        errors in ``std``, and the same indicators in ``meta`` (``"rmsd"``,
        eq. [19], FRF unit; ``"relative_error"``, ``"warnings"``, ``"mpc"``,
        ``"mpd_deg"``, ...).
    band_hz : (float, float)
        Analysis band.
    frf_kind : str
        Kind of the fitted FRFs.
    poles : PoleSet
        Stabilisation data (poles of all orders).
    flags : StabilityFlags
        Per-pole stability flags.
    clusters : list of Cluster
        Persistent clusters (candidate modes before the residue fit).
    rejected : list of dict
        Candidates dropped, each ``{"frequency_hz", "damping_ratio", "reason",
        "statistic", "threshold"}`` (:class:`~tyredamp.modal.statistics.quality.RejectedMode`).
    frequency : ndarray, shape (n_freq,)
        Lines used (Hz; a read-only view of the FRF's axis, no copy).
    discrepancy : dict of str to ndarray
        ``|H_model - H_data|`` RMS over FRFs per line, for each model.
    warnings : list of str
        Pipeline-level remarks.
    noise_source : str
        Noise model of the fit: ``"variance"``, ``"coherence"`` or ``"residual"``.
    model_error : float
        Relative model error ``eps`` included in the noise (0: none;
        :mod:`tyredamp.modal.problem.model_error`): the fit of the measured noise alone
        left structure, and the modes were decided against eq. (1) there.
    """

    models: dict[str, ModalModel]
    band_hz: tuple[float, float]
    frf_kind: str
    poles: PoleSet
    flags: StabilityFlags
    clusters: list[Cluster]
    rejected: list[dict[str, Any]]
    frequency: NDArray[np.float64]
    discrepancy: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    noise_source: str = "residual"
    model_error: float = 0.0


@dataclass(frozen=True)
class IdentifyOptions:
    """The settings of :func:`identify_modes`, one object (its parameters, in its
    order, but the data ``frf``, ``band``, ``variance`` and ``blas_threads``;
    ``estimator`` resolved to a function). Documented there."""

    model: ModelChoice = "both"
    n_modes: int | None = None
    frequencies: ArrayLike | None = None
    max_order: int | None = None
    order_step: int = 2
    residuals: bool = True
    refine: bool = True
    max_damping: float = 0.2
    cluster_distance: float = 0.01
    min_fraction: float = 0.3
    false_alarm: float = FALSE_ALARM
    min_contribution: float = 0.0
    max_helpers: int = 4
    estimator: PoleEstimator | None = None
    search: bool = True


def identify_modes(
    frf: FRF,
    band: tuple[float, float] | None = None,
    model: ModelChoice = "both",
    *,
    n_modes: int | None = None,
    frequencies: ArrayLike | None = None,
    max_order: int | None = None,
    order_step: int = 2,
    residuals: bool = True,
    refine: bool = True,
    max_damping: float = 0.2,
    cluster_distance: float = 0.01,
    min_fraction: float = 0.3,
    false_alarm: float = FALSE_ALARM,
    min_contribution: float = 0.0,
    max_helpers: int = 4,
    variance: ArrayLike | None = None,
    estimator: PoleEstimator | str | None = None,
    search: bool = True,
    blas_threads: int | None = 1,
) -> ModalIdentification:
    """Identify modes from measured FRFs without hand-holding (module docstring).

    Parameters
    ----------
    frf : FRF
        FRFs, shape (n_out, n_in, n_freq), any kind, uniform axis. Drive points
        (output at the node and direction of an input) fix the mass
        normalisation; without one the shapes are unscaled (a warning says so).
    band : (float, float), optional
        Band in Hz (default the whole axis, 0 Hz skipped); cut before anything else.
    model : {"both", "complex", "real"}
        Modal models to fit (default both).
    n_modes : int, optional
        Modes to keep (the most persistent clusters); default automatic (the
        mode test). At most :func:`~tyredamp.modal.problem.problem.max_modes`.
    frequencies : array_like of float, optional
        Approximate natural frequencies (Hz) of the wanted modes; overrides ``n_modes``.
    max_order : int, optional
        Highest estimator order, used as given; default automatic (module docstring).
    order_step : int
        Every ``order_step``-th order from ``max_order`` down to ``max_order / 4``.
    residuals : bool
        Upper and lower residual terms (default True).
    refine : bool
        Non-linear refinement (default True); without it the poles stay at the
        estimator's values (standard errors still from the Gauss-Newton covariance).
    max_damping, cluster_distance, min_fraction : float
        Selection rules, see :mod:`tyredamp.modal.poles.selection`.
    false_alarm : float
        False-alarm rate of the mode test and level of the goodness-of-fit
        test (default 0.01; :mod:`tyredamp.modal.statistics.stats`).
    min_contribution : float
        Optional extra rule: drop modes whose synthesised FRFs have an RMS below
        this fraction of the data's (default 0: off).
    max_helpers : int
        Most out-of-band residual modes per side (default 4; 0 for none), kept
        in ``ModalModel.residual_modes``.
    variance : array_like, shape (n_out, n_in, n_freq), optional
        Variance of each line of ``frf.H``; default ``frf.variance`` when
        present, else from the coherence and ``meta["n_averages"]``, else
        estimated from the residual (:mod:`tyredamp.modal.problem.problem`).
    estimator : PoleEstimator or str, optional
        Pole estimator, or its name in :data:`~tyredamp.modal.poles.estimators.ESTIMATORS`
        (default ``"plscf"``, :func:`~tyredamp.modal.poles.lscf.plscf`; protocol in
        :mod:`tyredamp.modal.poles.estimators`).
    search : bool
        Residual-driven search for missed modes (default True; automatic count).
    blas_threads : int or None
        BLAS threads while the identification runs (default 1: its matrices
        are small, and more threads make it several times slower,
        :mod:`tyredamp._blas`); None leaves the process's setting as it is.

    Returns
    -------
    ModalIdentification
        Raises :class:`InputError` on bad arguments, a band without lines, a
        non-uniform axis, more modes than the data support, or no mode found.

    Examples
    --------
    The virtual modal test of the truck tyre (40 dB noise, 8 averages): the
    complex modes found, against the tyre's exact ones.

    >>> import numpy as np
    >>> from tyredamp.modal import identify_modes
    >>> from tyredamp.signal import estimate_frf
    >>> from tyredamp.virtual import run_modal_test
    >>> test = run_modal_test(seed=1)
    >>> result = identify_modes(estimate_frf(test.data), band=(30, 200))
    >>> modes = result.models["complex"]
    >>> modes.n_modes
    6
    >>> exact = [row["frequency_hz"] for row in test.truth.table("visible")]
    >>> bool(np.allclose(modes.frequency_hz, exact, atol=0.1))  # Hz
    True
    >>> modes.quality.passed  # the residual is within the noise
    True
    """
    o = IdentifyOptions(
        model, n_modes, frequencies, max_order, order_step, residuals, refine, max_damping,
        cluster_distance, min_fraction, false_alarm, min_contribution, max_helpers,
        get_estimator(estimator), search,
    )  # fmt: skip
    with blas_limit(blas_threads):
        # the first identification is handed over in a list, which the model-error
        # passes empty: its arrays are not held through them
        first = [_identify(frf, band, o, variance)]
        aside = [w for w in first[0].warnings[:1] if w.startswith(SET_ASIDE)]
        res, eps = with_model_error(
            frf, variance, first, lambda v, note: _identify(frf, band, o, v, note, owned=True)
        )
    if eps == 0.0:
        return res
    res.warnings[:0] = aside  # the last pass was given a variance: first's notes on its own
    return dataclasses.replace(res, model_error=eps)


def _identify(
    frf: FRF,
    band: tuple[float, float] | None,
    o: IdentifyOptions,
    variance: ArrayLike | None,
    noise_note: str = "",
    owned: bool = False,
) -> ModalIdentification:
    """The body of :func:`identify_modes` (``noise_note`` says what a given
    ``variance`` is, :attr:`~tyredamp.modal.problem.problem.FitProblem.noise_note`;
    ``owned``: the variance is this call's to normalise in place, one made for it)."""
    if o.model not in ("both", "complex", "real"):
        raise InputError(f"model: expected 'both', 'complex' or 'real', got {o.model!r}")
    problem = build_problem(frf, band, variance=variance, noise_note=noise_note, owned=owned)
    _, n_in, n_f = problem.shape
    lo, hi = problem.band
    fr = _check_counts(problem, o.n_modes, o.frequencies)
    nm_hint = int(o.n_modes) if o.n_modes is not None else (None if fr is None else fr.size)
    rules = SelectionRules(o.order_step, o.max_damping, o.cluster_distance, o.min_fraction)
    est: PoleEstimator = plscf if o.estimator is None else o.estimator
    p_start = default_order(n_in, n_f, nm_hint) if o.max_order is None else int(o.max_order)
    dg = settle_order(problem, est, p_start, rules, o.max_order is None, o.false_alarm)
    auto = fr is None and o.n_modes is None
    warnings = [w for w in (problem.variance_set_aside, problem.lines_left_out) if w]
    modes, rej = _start_modes(problem, dg, fr, o.n_modes, o.min_fraction, warnings)
    fitters = _Fitters.build(problem, o.residuals, modes, o.max_helpers)
    thr, test = _threshold(problem, "complex", o.false_alarm), _mode_test(problem, o.false_alarm)
    opts = (auto, o.refine, o.max_helpers, o.min_contribution, o.search, (lo, hi))
    last, modes, more = _select(fitters, modes, dg, rej, (thr, test), *opts)
    rej = merge_rejected(rej + more)
    sigma0 = _noise_per_output(problem, fitters, modes, last, o.refine)
    ctx = {
        "problem": problem,
        "max_order": dg.order,
        "order_step": o.order_step,
        "threshold": thr,
        "test": test,
        "false_alarm": o.false_alarm,
        "kept": None if auto else tuple(_asked(fr) for _ in range(modes.m)),
        "method": _METHOD.format(est=getattr(est, "__name__", type(est).__name__)),
    }
    models, disc = _final_models(
        problem, fitters, modes, sigma0, o.refine, o.residuals, o.model, ctx, rej
    )
    return ModalIdentification(
        models=models,
        band_hz=(lo, hi),
        frf_kind=problem.kind,
        poles=dg.poles,
        flags=dg.flags,
        clusters=dg.kept,
        rejected=[r.to_dict() for r in rej],
        frequency=problem.frequency,
        discrepancy=disc,
        warnings=warnings,
        noise_source=problem.noise_source,
    )


def _asked(fr: NDArray[np.float64] | None) -> str:
    return "asked for (near a given frequency)" if fr is not None else "asked for (mode count)"


def _final_models(
    problem: FitProblem,
    fitters: _Fitters,
    modes: ModeSet,
    sigma0: NDArray[np.float64] | None,
    refine: bool,
    residuals: bool,
    model: ModelChoice,
    ctx: dict[str, Any],
    rej: list[RejectedMode],
) -> tuple[dict[str, ModalModel], dict[str, NDArray[np.float64]]]:
    """Step 4: the final fit of each model kind, as ModalModels."""
    kinds: list[Literal["complex", "real"]] = ["complex", "real"] if model == "both" else [model]
    models: dict[str, ModalModel] = {}
    disc: dict[str, NDArray[np.float64]] = {}
    base: tuple[NDArray[np.complex128], NDArray[np.complex128], ModeSet] = (*modes.all(), modes)
    for kind in kinds:
        extra_warn: list[str] = []
        thresholds = along = ratio = None
        if kind == "complex":
            res, cur, dropped, thresholds, along, ratio = final_complex(
                problem,
                fitters.cfit,
                modes,
                sigma0,
                refine,
                _combined(problem, fitters, sigma0, residuals),
                ctx["threshold"] if ctx["kept"] is None else None,
                ctx["test"],
            )
            rej = rej + dropped
            base = (res.poles, res.participation, cur)
            n_band = cur.m
        else:
            compressed = fitters.sfit if fitters.sfit is not fitters.cfit else None
            res, n_band, extra_warn, along, ratio = fit_real(
                problem, residuals, refine, compressed, base, sigma0
            )
        res.warnings.extend(extra_warn)
        kept = ctx["kept"]
        if kept is not None and len(kept) != n_band:
            kept = tuple(kept[:1]) * n_band
        c = ModelContext(
            problem=problem,
            kind=kind,
            max_order=ctx["max_order"],
            order_step=ctx["order_step"],
            threshold=ctx["threshold"]
            if kind == "complex"
            else _threshold(problem, "real", ctx["false_alarm"]),
            false_alarm=ctx["false_alarm"],
            kept=kept,
            rejected=tuple(rej),
            method=ctx["method"],
            thresholds=thresholds,
            along=along,
            pole_ratio=ratio,
        )
        models[kind], disc[kind] = to_model(res, n_band, c)
    return models, disc


def _combined(
    problem: FitProblem,
    fitters: _Fitters,
    sigma0: NDArray[np.float64] | None,
    residuals: bool,
) -> ModalFitter | None:
    """Fitter on the search's output patterns re-weighted by ``1 / sigma`` (many outputs)."""
    n_out = problem.shape[0]
    if sigma0 is None or fitters.patterns is None or n_out <= _COMPRESS_FINAL * fitters.rank:
        return None
    H = problem.H
    rms = np.sqrt(np.mean(H.real**2 + H.imag**2, axis=(1, 2)))
    wts = 1.0 / np.maximum(sigma0, np.maximum(1e-9 * rms, 1e-300))
    return ModalFitter(
        problem.frequency,
        combine_outputs(H, fitters.patterns, wts),
        problem.power,
        "complex",
        [],
        upper=residuals,
        lower=residuals,
        unit_weights=True,
        line_weights=problem.line_weights,
    )
