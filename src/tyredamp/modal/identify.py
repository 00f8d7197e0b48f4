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
from .._validate import as_finite
from ..exceptions import InputError
from ..frf import FRF
from ..mechanics.modal_sum import pole_from_frequency_damping
from .final import ModelContext, final_complex, fit_real, to_model
from .fit.fit import FitResult, ModalFitter
from .model import ModalModel
from .poles.estimators import PoleEstimator, get_estimator
from .poles.lscf import PoleSet, plscf
from .poles.order import Diagram, SelectionRules, default_order, modes_shown, settle_order
from .poles.selection import Cluster, StabilityFlags
from .problem.compress import _compress, combine_outputs
from .problem.model_error import with_model_error
from .problem.problem import SET_ASIDE, FitProblem, build_problem, max_modes
from .search.out_of_band import search_helpers
from .search.search import (
    FixedParts,
    ModeSet,
    ModeTest,
    reject_by_test,
    rejected,
    residual_search,
)
from .statistics.quality import RejectedMode, merge_rejected
from .statistics.stats import FALSE_ALARM, mode_parameters, mode_threshold

__all__ = ["ModalIdentification", "ModelChoice", "identify_modes"]

ModelChoice = Literal["real", "complex", "both"]
#: output compression (fit.compress_outputs) of the search when n_out > 1.5 rank,
#: and of the final refinement when n_out > 4 rank (module docstring of identify)
_COMPRESS_SEARCH = 1.5
_COMPRESS_FINAL = 4.0
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
        first = _identify(frf, band, o, variance)
        res, eps = with_model_error(
            frf, variance, first, lambda v, note: _identify(frf, band, o, v, note)
        )
    if res is not first:  # the last pass was given a variance: first's notes on its own
        res.warnings[:0] = [w for w in first.warnings[:1] if w.startswith(SET_ASIDE)]
    return res if eps == 0.0 else dataclasses.replace(res, model_error=eps)


def _identify(
    frf: FRF,
    band: tuple[float, float] | None,
    o: IdentifyOptions,
    variance: ArrayLike | None,
    noise_note: str = "",
) -> ModalIdentification:
    """The body of :func:`identify_modes` (``noise_note`` says what a given
    ``variance`` is, :attr:`~tyredamp.modal.problem.problem.FitProblem.noise_note`)."""
    if o.model not in ("both", "complex", "real"):
        raise InputError(f"model: expected 'both', 'complex' or 'real', got {o.model!r}")
    problem = build_problem(frf, band, variance=variance, noise_note=noise_note)
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


def _asked(fr: NDArray[np.float64] | None) -> str:
    return "asked for (near a given frequency)" if fr is not None else "asked for (mode count)"


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
        thresholds = along = None
        if kind == "complex":
            res, cur, dropped, thresholds, along = final_complex(
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
            res, n_band, extra_warn, along = fit_real(
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
