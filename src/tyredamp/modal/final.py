"""Final stage of an identification: the maximum-likelihood fit of each model,
its goodness of fit and the :class:`~tyredamp.modal.model.ModalModel` with its
:class:`~tyredamp.modal.statistics.quality.FitQuality`.

The final fits weight every line by the noise model of the
:class:`~tyredamp.modal.problem.problem.FitProblem`. With a per-line variance (given,
or estimated from the coherence and the averages) the fit is weighted by its
separable approximation ``sigma_j^2 g_f``; when the variance is given, or
estimated well enough that weighting every entry by its own estimate beats
that approximation (:func:`full_weights`), this weighted least-squares fit
starts the maximum-likelihood refinement of poles, participation and
residues with the variance of every entry (:mod:`~tyredamp.modal.fit.ml`, the
default final stage), whose standard errors come from its Fisher
information. Otherwise the noise level of each output is estimated from the
residual of the search's model (a generous model) and the fit iterates it
(iteratively reweighted least squares, the maximum-likelihood estimate for a
noise level per output); standard errors from the Gauss-Newton information
``J^T J`` at the optimum, scaled by the residual variance (equal to the
Fisher information of that noise model). The model of a fit, in the data's
units with its quality, is assembled by :mod:`~tyredamp.modal.assemble`.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ConvergenceError
from .assemble import goodness, local_dispersion, to_model, unscale  # noqa: F401 (re-exported)
from .fit._scaling import pole_std
from .fit.fit import FitResult, ModalFitter, pole_bounds
from .fit.ml import fisher_scale, ml_refine
from .fit.profile import fit_intervals
from .problem.problem import FitProblem
from .sandwich import sandwich_shapes
from .search.modeset import outside_side
from .search.refitted import refitted_statistics
from .search.resolution import unresolved_pair, unresolved_pair_text
from .search.search import (
    ModeSet,
    ModeTest,
    fit_checked,
    local_thresholds,
    rejected,
    residual_span,
)
from .statistics.quality import RejectedMode, threshold_text
from .statistics.stats import chi2_isf

__all__ = ["fit_real", "goodness", "to_model", "unscale"]

#: the final fits stop when a full Gauss-Newton step would lower the cost by less
#: than 1e-4 s^2: the remaining step is about 0.01 standard deviations of the
#: parameters, far below their uncertainty (ModalFitter.fit's default is 1e-6)
FINAL_TOL = 1e-4


def _floor_hz(fitter: ModalFitter) -> float:
    """The highest damped frequency (Hz) of a pole held at the lower bound of its
    frequency in a refinement of ``fitter``: ``Omega = 1e-6 w_ref``
    (:func:`~tyredamp.modal.fit.fit.pole_bounds`), which a refinement starts at
    most 1e-9 ``w_ref`` above (``ModalFitter._refine``)."""
    return float((pole_bounds(1, 2)[0][1] + 2e-9) * fitter.w_ref / (2.0 * np.pi))


def _problem(
    res: FitResult, m: int, n_free: int, band: tuple[float, float], floor: float = 0.0
) -> tuple[str, int]:
    """Why a fit is not acceptable ("" when it is: a mode crossed a band edge, or
    two merged) and the index of the mode concerned (-1 when none).

    A pole at or below ``floor`` Hz (:func:`_floor_hz`: held at the lower bound of
    its frequency, 0 Hz) is out of the band even where the band's first line is
    below it (``1e6`` lines from 0 Hz): a pole at its bound is no estimate (the
    cost would fall further beyond it) and no mode of the band."""
    p = res.poles
    fd = p.imag / (2 * np.pi)
    inb = (fd >= band[0]) & (fd <= band[1]) & (fd > floor)
    free = np.zeros(len(p) - m, bool)
    free[:n_free] = True
    wrong = np.flatnonzero(np.concatenate([~inb[:m], inb[m:] & ~free]))
    if wrong.size:
        return f"a pole crossed the band edge ({fd[wrong[0]]:.2f} Hz)", int(wrong[0])
    d = np.abs(p[:, None] - p[None, :]) / np.abs(p)[:, None]
    np.fill_diagonal(d, np.inf)
    if d.size and d.min() < 5e-4:
        i, j = np.unravel_index(np.argmin(d), d.shape)
        return "two poles merged", int(max(i, j))
    return "", -1


class _Stopped(Exception):
    """A real-mode refinement stopped at its best point (:class:`_RealFitter`): mode
    ``index`` at ``freq`` Hz, and why it is not acceptable there."""

    def __init__(self, index: int, freq: float, why: str) -> None:
        super().__init__(index, freq, why)
        self.index, self.freq, self.why = index, freq, why


class _RealFitter(ModalFitter):
    """The real-mode fitter of :func:`fit_real`: while :attr:`watch` is set (``m``,
    the in-band modes coming first; the index of the first residual mode outside
    the band; the band, Hz), a refinement stops (:class:`_Stopped`) as soon as the
    best point it has evaluated in its pass holds

    * an in-band mode's pole at the lower bound of its frequency (``Omega = 1e-6
      w_ref``, :func:`~tyredamp.modal.fit.fit.pole_bounds`, :func:`_floor_hz`),
      where :func:`_problem` would refuse the fit, or
    * a residual mode outside the band out of the range of the residual modes:
      outside the band, within a factor 2 beyond its edge
      (:func:`~tyredamp.modal.search.modeset.outside_side`).

    A pole at 0 Hz: the real-mode model uses it for what real modes cannot hold
    (the out-of-phase part of complex residues, a lower residual term), not for
    a mode of the band. The bounded Levenberg-Marquardt iteration
    (:func:`~tyredamp.modal.fit._linalg._levenberg_marquardt`) holds a parameter
    at its bound while its gradient points out and never accepts a point of
    higher cost, so the pole comes back only if the other parameters turn its
    gradient round with the cost still falling: not excluded in general, so
    checked (``benchmarks/README.md``, "--model both against --model complex":
    on the tyre cases, the package's tests and the real-data gallery no
    refinement's best point held a pole there, while the synthetic complex-mode
    cases that did took most or all of their budget, 100 evaluations per pass,
    to end rejected with the same model).

    A residual mode out of that range: the residual modes stand for the tails
    of the modes outside the band where the residual terms do not hold them
    (they are searched within that range,
    :mod:`~tyredamp.modal.search.out_of_band`), and :func:`_problem` refuses one
    in the band. With real modes one can run far away (to ten times the band
    edge on a structure with non-proportional damping, its damping falling to
    zero), where its column over the band is that of a residual term: the
    basis loses its rank, the cost its curvature, and the refinement crawls
    along the valley to its evaluation limit; or into the band with a damping
    ratio near 1, to end refused there after as many evaluations.

    The best point is the lowest cost evaluated with the pass's weights: the
    iteration's current point (it moves only to lower costs) but after steps
    of too small a gain.
    """

    watch: tuple[int, int, tuple[float, float]] | None = None
    _best: tuple[bytes, float] | None = None

    def _solve(self, th: Any, m: int, ref: Any, w: Any, *args: Any, **kw: Any) -> dict[str, Any]:
        sol = super()._solve(th, m, ref, w, *args, **kw)
        if self.watch is None or not kw.get("gradient", True) or m < self.watch[0]:
            return sol
        n_band, outside, band = self.watch
        key, cost = w.tobytes(), float(sol["cost"])
        if self._best is not None and self._best[0] == key and not cost <= self._best[1]:
            return sol
        self._best = (key, cost)
        f = th[1 : 2 * m : 2] * self.w_ref / (2.0 * np.pi)
        at = np.flatnonzero(f[:n_band] <= _floor_hz(self))
        if at.size:
            i = int(at[0])
            raise _Stopped(i, float(f[i]), f"a pole crossed the band edge ({f[i]:.2f} Hz)")
        far = [i for i in range(outside, m) if outside_side(float(f[i]), band) == 0]
        if far:
            i, (lo, hi) = far[0], band
            raise _Stopped(
                i,
                float(f[i]),
                f"a residual mode left the range of the residual modes ({f[i]:.2f} Hz; "
                f"they lie within a factor 2 beyond the band's edges, {lo / 2:.4g}-{lo:.4g} "
                f"and {hi:.4g}-{2 * hi:.4g} Hz)",
            )
        return sol


def fit_real(
    problem: FitProblem,
    residuals: bool,
    refine: bool,
    search: ModalFitter | None,
    start: tuple[NDArray[np.complex128], NDArray[np.complex128], ModeSet],
    sigma0: NDArray[np.float64] | None = None,
) -> tuple[FitResult, int, list[str], NDArray[np.float64], NDArray[np.float64] | None]:
    """Real-mode fit (pole-pair optimisation) started from the complex-mode poles.

    The real model keeps the modes of the complex model. A residual mode
    outside the band whose refinement is not acceptable is dropped and the
    modes refined again (:func:`_refined`); when the refinement is not
    acceptable for an in-band mode (its pole crosses a band edge or two merge:
    real modes that cannot describe strongly complex data), the poles are kept
    at the complex-mode values, only the real residues are fitted, and a
    warning says so. A refinement whose best point holds an in-band pole at 0
    Hz, or a residual mode beyond the range of the residual modes, stops there
    (:class:`_RealFitter`); one whose band's modes have converged stops
    whatever the residual modes still do (:func:`_watched`). ``search``: the compressed
    search fitter (a pre-fit on the output combinations) or None. ``start``:
    poles and participation of all modes (in-band first) and the mode set they
    belong to. ``sigma0``: the
    noise per output of the final fits; with it, the modes whose linearised
    intervals would be too short get likelihood intervals
    (:func:`~tyredamp.modal.fit.profile.fit_intervals`), as in the complex model.
    Also returns the in-band modes' noise along the response
    (:func:`noise_along_response`) and the factors of their poles' variances
    (:func:`sandwiched`, whose shapes' errors the returned fit then holds), as
    :func:`final_complex` does.
    """
    p0, l0, modes = start
    m, nf = modes.m, modes.n_free
    fitter = _RealFitter(
        problem.frequency,
        problem.H,
        problem.power,
        "real",
        problem.drive,
        upper=residuals,
        lower=residuals,
        line_weights=problem.line_weights,
    )
    sigma = problem.sigma_out
    passes = 1 if sigma is not None else 2
    if not refine:
        res = fitter.fit(p0, l0, refine=False, sigma=sigma)
        return res, m, [], noise_along_response(fitter, res, m), None
    keep = np.arange(p0.size)
    start_p, start_l, why = p0, l0, ""
    if search is not None:
        # real modes start far from the complex optimum: pre-fit on the combinations
        pre_fit = _RealFitter(
            search.f,
            search.H,
            problem.power,
            "real",
            [],
            upper=residuals,
            lower=residuals,
            unit_weights=True,
            line_weights=problem.line_weights,
        )
        pre, why, keep = _refined(pre_fit, p0, l0, m, nf, problem.band, passes=1)
        start_p, start_l = pre.poles, pre.participation
    if not why:
        # the evaluation limit bounds the time spent on data that real modes cannot fit
        res, why, kept = _refined(
            fitter,
            start_p,
            start_l,
            m,
            nf,
            problem.band,
            max_nfev=100,
            tol=FINAL_TOL,
            sigma=sigma,
            passes=passes,
        )
        keep = keep[kept]
    if not why:
        ml = maximum_likelihood(problem, fitter, res)
        if not _problem(ml, m, nf, problem.band, _floor_hz(fitter))[0]:
            res = ml
        # likelihood intervals where the linearised ones would be too short
        res.intervals = fit_intervals(fitter, res, m, sigma0)
        res, ratio = sandwiched(problem, fitter, res, m, sigma)
        return res, m, [], noise_along_response(fitter, res, m), ratio
    res = fitter.fit(p0[keep], l0[keep], refine=False, sigma=sigma)
    return (
        res,
        m,
        [
            f"real-mode refinement not acceptable ({why}): poles kept at the complex-mode "
            "values, real residues fitted"
        ],
        noise_along_response(fitter, res, m),
        None,
    )


def _watched(
    fitter: _RealFitter,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    m: int,
    n_free: int,
    band: tuple[float, float],
    **options: Any,
) -> tuple[FitResult, str, int]:
    """``fitter.fit(poles, part, **options)`` stopped once an in-band pole reaches 0
    Hz or a residual mode leaves the range of the residual modes
    (:class:`_RealFitter`), and why it is not acceptable with the mode concerned
    (:func:`_problem`). A stopped refinement returns the start (its result is
    rejected and not used). The refinement may stop once the band's modes (the
    first ``m + n_free``) have converged, the residual modes outside it being
    nuisance parameters (``n_interest`` of
    :meth:`~tyredamp.modal.fit.fit.ModalFitter.fit`)."""
    fitter.watch, fitter._best = (m, m + n_free, band), None
    try:
        res = fitter.fit(poles, part, n_interest=m + n_free, **options)
    except _Stopped as stop:
        return fitter.fit(poles, part, refine=False, uncertainty=False), stop.why, stop.index
    finally:
        fitter.watch, fitter._best = None, None
    return (res, *_problem(res, m, n_free, band, _floor_hz(fitter)))


def _refined(
    fitter: _RealFitter,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    m: int,
    n_free: int,
    band: tuple[float, float],
    **options: Any,
) -> tuple[FitResult, str, NDArray[np.intp]]:
    """:func:`_watched`, refined again without each residual mode outside the band
    that is not acceptable (it crossed into the band, merged with another mode or
    left the range of the residual modes: real modes cannot hold what it stood
    for, and it only shapes the band's edges). Returns the last fit, why it is
    not acceptable ("" when it is) and the indices into ``poles`` of the modes
    it holds."""
    keep = np.arange(poles.size)
    while True:
        res, why, bad = _watched(fitter, poles[keep], part[keep], m, n_free, band, **options)
        if not why or bad < m + n_free:
            return res, why, keep
        keep = np.delete(keep, bad)


def noise_along_response(
    fitter: ModalFitter, res: FitResult, n_band: int, alpha: float = 0.05
) -> NDArray[np.float64]:
    """Each in-band mode's noise variance along the response, in units of the fit's
    noise, where it is significantly above 1; 1 elsewhere (n_band,).

    With a noisy force, the H1 error ``-H N X^+`` is common to the outputs and lies
    in the span of ``H(f)`` (errors in variables; :mod:`~tyredamp.modal.search.span_noise`),
    which near a mode is the mode's shape: the pole and the shape are estimated
    from that direction, whose noise is ``lambda_in`` times the fit's, while their
    linearised standard errors take every direction at the fit's level (too small
    by up to ``sqrt(n_out)``). ``lambda_in`` over ``n`` lines around the mode holds
    ``2 n_in^2 n`` real units of noise, so under independent outputs ``lambda_in
    nu`` is ``chi2_nu`` with ``nu = 2 n_in^2 n``; it is used where it exceeds that
    law's upper ``alpha`` quantile over ``nu``. Where the FRF carries its input
    noise, the standard errors of the frequencies, damping ratios and shapes are
    the sandwich's instead (:func:`sandwiched`): averaged over the
    window, ``lambda_in`` mixes the lines where the force's noise dominates with
    those where the responses' does, and scatters from seed to seed.
    """
    out = np.ones(n_band)
    if n_band == 0:
        return out
    span = residual_span(fitter, res)
    for i, p in enumerate(res.poles[:n_band]):
        lam, _, n = span.at(complex(p))
        nu = 2.0 * fitter.n_in**2 * n
        if n > 0 and lam > chi2_isf(alpha, nu) / nu:
            out[i] = lam
    return out


def final_complex(
    problem: FitProblem,
    cfit: ModalFitter,
    modes: ModeSet,
    sigma0: NDArray[np.float64] | None,
    refine: bool,
    combined: ModalFitter | None,
    threshold: float | None = None,
    test: ModeTest | None = None,
) -> tuple[
    FitResult,
    ModeSet,
    list[RejectedMode],
    NDArray[np.float64] | None,
    NDArray[np.float64],
    NDArray[np.float64] | None,
]:
    """The final complex-mode fit; ``combined``: a fitter on the re-weighted output
    combinations (many outputs), whose poles then give the residues of every output.

    ``threshold`` (automatic mode count): the final fit holds the mode test too,
    each mode's threshold raised with ``test`` where the noise of the fit's
    residual lies along the response
    (:func:`~tyredamp.modal.search.thresholds.local_thresholds`). A mode whose statistic
    fell to its threshold in the final refinement (its pole moved onto noise,
    e.g. a damping that collapsed) is dropped, the weakest first, and the fit
    repeated. Also returns the threshold applied to each kept in-band mode (fit
    order; None without ``threshold``) and each in-band mode's noise along the
    response (:func:`noise_along_response`, fit order) and the factors of the
    variances of its frequency and damping ratio under the noise's structure
    across outputs (:func:`sandwiched`; None where not known). When
    every mode passes with the other poles held, modes beside a stronger one are
    tested once more with the neighbours' poles refitted
    (:mod:`~tyredamp.modal.search.refitted`: the likelihood ratio of the
    maximised models) and dropped, the weakest first, when that fails.
    """
    dropped: list[RejectedMode] = []
    cur = modes
    thr: NDArray[np.float64] | None = None
    for _ in range(modes.m):
        res, cur, gone = _final_fit(problem, cfit, cur, sigma0, refine, combined)
        dropped += gone
        if threshold is None or cur.m == 0:
            thr = None
            break
        m = cur.m
        t = res.significance[:m]
        pair = unresolved_pair(res.poles[:m], t, _spacing(problem))
        if pair is not None:
            weak, strong = pair
            fs = float(np.abs(res.poles[strong]) / (2.0 * np.pi))
            why = unresolved_pair_text(fs, _spacing(problem))
            dropped.append(rejected(complex(res.poles[weak]), why, float(t[weak]), threshold))
            keep = np.arange(m) != weak
            cur = ModeSet(cur.poles[keep], cur.part[keep], cur.hp, cur.hl, cur.n_free)
            continue
        span = residual_span(cfit, res) if test is not None else None
        thr = local_thresholds(cfit, span, res.poles[:m], threshold, test)
        del span  # its per-line sums are not held through the refits and the ML stage
        refitted = np.zeros(m, bool)
        if refine and m > 1 and not np.any(t <= thr):
            # the held-pole statistic passes: the likelihood ratio with the
            # neighbours' poles refitted where they could take a mode up, on the
            # re-weighted output combinations when the final fit used them
            lr_fit = combined if combined is not None and sigma0 is not None else cfit
            t, refitted = refitted_statistics(lr_fit, res, cur, t, thr, sigma0)
        if m <= 1 or not np.any(t <= thr):
            if refitted.any():  # the statistic the mode passed, reported
                sig = np.array(res.significance, dtype=float)
                sig[:m] = t
                res = dataclasses.replace(res, significance=sig)
            if m == 1 and t[0] <= thr[0]:
                lo, hi = problem.band
                res.warnings.append(
                    f"no mode passes the mode test in [{lo:g}, {hi:g}] Hz (T = {t[0]:.3g} <= "
                    f"{thr[0]:.3g}): the FRFs show no resonance above their noise; the one "
                    "mode reported (a model needs one) is not significant"
                )
            break
        worst = int(np.argmin(np.where(t <= thr, t / thr, np.inf)))
        how = " with its neighbours' poles refitted" if refitted[worst] else ""
        why = (
            f"final fit: not significant{how}: T = {t[worst]:.3g} <= "
            f"{threshold_text(thr[worst], threshold)}"
        )
        dropped.append(rejected(complex(res.poles[worst]), why, float(t[worst]), float(thr[worst])))
        keep = np.arange(m) != worst
        cur = ModeSet(cur.poles[keep], cur.part[keep], cur.hp, cur.hl, cur.n_free)
    if refine:
        # the ML refinement keeps the WLS fit's statistics (:mod:`~tyredamp.modal.fit.ml`),
        # so the thresholds they were tested against stand
        res = maximum_likelihood(problem, cfit, res)
        # likelihood intervals where the linearised ones would be too short
        res.intervals = fit_intervals(cfit, res, cur.m, sigma0)
    ratio = None
    if refine:
        res, ratio = sandwiched(problem, cfit, res, cur.m, sigma0)
    return res, cur, dropped, thr, noise_along_response(cfit, res, cur.m), ratio


def _spacing(problem: FitProblem) -> float:
    """Line spacing of the band (Hz; 0 with fewer than two lines)."""
    f = problem.frequency
    return float(f[1] - f[0]) if f.size > 1 else 0.0


def _final_fit(
    problem: FitProblem,
    cfit: ModalFitter,
    modes: ModeSet,
    sigma0: NDArray[np.float64] | None,
    refine: bool,
    combined: ModalFitter | None,
) -> tuple[FitResult, ModeSet, list[RejectedMode]]:
    """One weighted least-squares final fit of ``modes`` (:func:`final_complex`).

    A refinement that moves every mode out of the band (a few modes standing for
    a band that holds many) leaves no model: the residues are then fitted at the
    search's poles, with a warning, rather than no result."""
    try:
        if combined is not None and sigma0 is not None:
            r0, cur, dropped = fit_checked(
                combined,
                modes,
                True,
                problem.band,
                in_band_only=True,
                passes=1,
                tol=FINAL_TOL,
                uncertainty=False,
            )
            res = cfit.fit(r0.poles, r0.participation, refine=False, sigma=sigma0)
            res.status, res.n_iter = r0.status, r0.n_iter
            return res, cur, dropped
        return fit_checked(
            cfit,
            modes,
            refine,
            problem.band,
            in_band_only=True,
            passes=1 if sigma0 is not None else 2,
            sigma=sigma0,
            tol=FINAL_TOL,
        )
    except ConvergenceError as exc:
        p0, l0 = modes.all()
        res = cfit.fit(p0, l0, refine=False, sigma=sigma0)
        lo, hi = problem.band
        res.warnings.append(
            f"the final refinement failed ({exc}): the poles in [{lo:g}, {hi:g}] Hz are the "
            "search's, only the residues are fitted; the band likely holds more modes than "
            "were found (raise the maximum order or give the mode count)"
        )
        return res, modes, []


def full_weights(problem: FitProblem) -> bool:
    """Whether weighting every entry by its own variance estimate ``V^`` beats the
    separable weights ``sigma_j^2 g_f`` of the WLS fit (both against the true
    weights ``1 / V``).

    A weighted least-squares estimate with weights ``w`` has the covariance of
    the ideal one times ``E[w^2 V] E[1 / V] / E[w]^2`` (lines of equal
    leverage; Kantorovich's inequality makes it >= 1). For the entries' own
    estimates (``V^ / V ~ chi2_nu / nu``) that is ``(nu - 2) / (nu - 4)``
    (infinite for ``nu <= 4``); for the separable model, with ``rho = V /
    (sigma_j^2 g_f)``, it is ``mean(rho) mean(1 / rho)``, estimated from ``rho^ =
    V^ / (sigma_j^2 g_f)`` as ``mean(rho^) mean(1 / rho^) (nu - 2) / nu``
    (``E[1 / rho^] = nu / (nu - 2) E[1 / rho]``). A known variance (``nu``
    None) is always used entry by entry (maximum likelihood).
    """
    nu = problem.noise_dof
    v = problem.variance
    if v is None or problem.sigma_out is None or problem.line_weights is None:
        return False
    if nu is None:
        return True
    if not nu > 4.0:
        return False
    sep = problem.sigma_out[:, None, None] ** 2 / problem.line_weights[None, None, :] ** 2
    pos = v > 0
    rho = v[pos] / np.broadcast_to(sep, v.shape)[pos]
    if rho.size == 0:
        return False
    loss_sep = float(np.mean(rho) * np.mean(1.0 / rho)) * (nu - 2.0) / nu
    return (nu - 2.0) / (nu - 4.0) < loss_sep


def maximum_likelihood(problem: FitProblem, fitter: ModalFitter, res: FitResult) -> FitResult:
    """The maximum-likelihood refinement (:func:`~tyredamp.modal.fit.ml.ml_refine`) of the
    weighted fit ``res`` of ``fitter`` when the per-line variance is known, or
    estimated and :func:`full_weights` says its own weights are the better ones."""
    if problem.variance is None or not full_weights(problem):
        return res
    try:
        return ml_refine(
            _plain(problem, fitter), res, problem.variance, problem.noise_dof, tol=FINAL_TOL
        )
    except (np.linalg.LinAlgError, ValueError):
        res.warnings.append("maximum-likelihood refinement failed: weighted fit kept")
        return res


def _plain(problem: FitProblem, fitter: ModalFitter) -> ModalFitter:
    """The fitter of the maximum-likelihood stage: ``fitter``'s model on the problem's
    unweighted data (no line weights)."""
    return ModalFitter(
        problem.frequency,
        problem.H,
        problem.power,
        fitter.kind,
        problem.drive,
        upper=fitter.use_upper,
        lower=fitter.use_lower,
    )


def sandwiched(
    problem: FitProblem,
    fitter: ModalFitter,
    res: FitResult,
    n_band: int,
    sigma0: NDArray[np.float64] | None,
) -> tuple[FitResult, NDArray[np.float64] | None]:
    """The fit with the shapes' standard errors of White's sandwich, and the factors of
    the variances of each in-band mode's frequency and damping ratio (n_band, 2; fit
    order) under it, over the variances the fit reports
    (:func:`~tyredamp.modal.sandwich.sandwich_shapes`; for f and zeta by the delta
    method of :func:`~tyredamp.modal.fit._scaling.pole_std`).

    Formed where the FRF carries its input noise (:attr:`~tyredamp.frf.FRF.input_noise`,
    the part of the variance common to all outputs) and ``res`` is the
    maximum-likelihood fit with its per-line variance, or the weighted least-squares
    fit of ``fitter`` (each output weighted by ``1 / sigma0``, its residual RMS
    without ``sigma0``); ``std_psi_out`` and ``std_psi_in`` of the returned fit are
    then the sandwich's (the standard errors of a known or estimated variance, the
    latter times the Fisher scale :func:`~tyredamp.modal.fit.ml.fisher_scale`), which
    replace the fit's errors inflated by the noise along the response. Otherwise
    (or where the sandwich is not finite) ``res`` unchanged and None: the modes'
    noise along the response (:func:`noise_along_response`) then stands for that
    structure.
    """
    r = problem.frf.input_noise
    if r is None or problem.variance is None or n_band == 0:
        return res, None
    ml = res.status.startswith("maximum likelihood")
    fit = _plain(problem, fitter) if ml else fitter
    # the ML fit reports its inverse information times its Fisher scale (an estimated variance)
    scale = fisher_scale(problem.noise_dof, 0.0, 1) if ml else 1.0
    w = None if ml else fitter.weights(res.sigma_out if sigma0 is None else sigma0)
    m = int(res.poles.size)
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            cov, s_out, s_in, kappa = sandwich_shapes(
                fit, res, w, problem.variance, r[:, problem.lines], scale
            )
            # the entries' errors as a consumer that takes them independent needs them
            # for the shape's amplitude (eq. (S3) of modal.sandwich)
            kappa = np.where(np.isfinite(kappa), np.maximum(kappa, 1.0), 1.0)
            s_out = s_out * np.sqrt(kappa)[None, :]
            f1, z1, _ = pole_std(fit.w_ref, fit.pack(*_start(res)), m, cov)
            f0 = np.asarray(res.std_frequency_hz, float)
            z0 = np.asarray(res.std_damping_ratio, float)
            out = np.stack([(f1 / f0) ** 2, (z1 / z0) ** 2], axis=1)[:n_band]
    except (np.linalg.LinAlgError, ValueError):  # no covariance: the noise along the response
        return res, None
    if not (np.isfinite(out).all() and np.isfinite(s_out).all() and np.isfinite(s_in).all()):
        return res, None
    return dataclasses.replace(res, std_psi_out=s_out, std_psi_in=s_in), out


def _start(
    res: FitResult,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.intp]]:
    """Poles, participation and reference inputs of ``res`` as the sandwich packs them."""
    part = np.asarray(res.participation, complex)
    return res.poles, part, np.argmax(np.abs(part), axis=1).astype(np.intp)
