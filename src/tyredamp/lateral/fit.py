"""Fitting the lateral models to a measured complex lateral FRF.

One function fits any model of :mod:`tyredamp.lateral.models` to the
accelerance ``y''/Fy`` measured at the ground force or at the axle force
(paper: "best fit to the measured complex frequency response function").

Method
------
* Data: a 1x1 :class:`~tyredamp.frf.FRF` (any kind; converted to
  accelerance; the 0 Hz line is dropped), optionally limited to a band.
* Residual on the complex values, stacked as real and imaginary parts:
  ``r_k = w_k (A_model(f_k) - A_meas(f_k))``. Weights ``w_k``:
  ``"relative"`` ``1/|A_meas|`` (each line counts by its relative error);
  ``"coherence"`` ``1/(|A_meas| sqrt((1 - g^2)/g^2))``, the inverse of the
  standard deviation of an FRF estimate with coherence ``g^2`` (up to the
  number of averages); ``"uniform"`` ``1/rms|A_meas|``; ``"auto"`` is
  ``"coherence"`` when the FRF carries coherence, else ``"relative"``; or
  an array per frequency line of the FRF.
* Parameters are fitted as logarithms (so they stay positive) with
  :func:`scipy.optimize.least_squares` (trust-region reflective, bounded to
  ``e^{+-20}`` around the start). Starting values come from each model's
  ``initial_guesses`` (linear regressions on the asymptotes, e.g.
  ``Re Y = 1/K``-like and ``Im Y ~ -1/(omega C_r)``), spread by a coarse grid
  of factors 1/3, 1, 3 per parameter; the three cheapest starts are refined
  and the best result is kept. Axle-force data are first fitted on the
  ground-force accelerance ``A_axle/(1 - M_w A_axle)`` (no wheel resonance,
  so the starts land in the right basin), then refined on the axle data.
* Standard errors: ``cov(log p) = s^2 (J^T J)^-1`` with ``J`` the Jacobian of
  the weighted residuals in log-parameters (analytic, from each model's
  ``_mobility_gradient``; central differences for a model without one, the
  stretched string) and ``s^2 = RSS/(2N - P)``; ``SE(p) = p SE(log p)``
  (delta method).
* Cost: the residual and its Jacobian are never held whole; they are reduced
  block by block to the ``(P+1) x (P+1)`` triangular factor of ``[J r]``, which
  keeps ``J^T J``, ``J^T r`` and ``r^T r`` exactly (:mod:`._lsq`), so time grows
  in proportion to the lines and memory stays near the data's own size. Every
  model fitted to the same data (:func:`~tyredamp.lateral.rank_models`) shares
  one preparation of the lines.
* Paper Table 1 figure, defined here precisely: the **amplitude error**
  ``mean_k | |A_model| - |A_meas| | / |A_meas|`` over the fitted lines, and the
  signed **amplitude bias** ``mean_k (|A_model| - |A_meas|) / |A_meas|``
  (positive: the model over-estimates, as the paper's signs). Both are
  fractions (x 100 for %), unweighted.
* Information criteria on the complex residuals: ``n = 2N`` real residuals,
  Gaussian log-likelihood with the ML variance ``RSS/n``,
  ``AIC = n ln(RSS/n) + 2 (P + 1)``, ``BIC = n ln(RSS/n) + (P + 1) ln n``
  (the ``+1`` counts the noise variance; constants common to all models on
  the same data and weights are dropped). Lower is better; differences
  are meaningful only between fits to the same lines with the same weights.

Ranking several models fitted to the same data is :mod:`.ranking`; fitting
several speeds together with shared physical parameters is :mod:`.joint`.
The data, their band and weights are prepared by :mod:`.data`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import ConvergenceError, InputError
from ..frf import FRF
from ._lsq import BLOCK, Lines, Problem, Segment
from .data import LateralData, Weights, _prepare, _Prepared
from .models import LateralModel, get_model_class
from .response import ForceKind

__all__ = ["DEFAULT_MODELS", "Criterion", "LateralData", "LateralFit", "Weights", "fit_model"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
Criterion = Literal["bic", "aic"]

#: The four spring-damper models compared in the paper.
DEFAULT_MODELS: tuple[str, ...] = ("classic", "maxwell", "viscoplastic", "hysteretic")
_LOG_SPAN = 20.0
_GRID = (1.0 / 3.0, 1.0, 3.0)


# --------------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False)
class LateralFit:
    """Result of fitting one lateral model to one FRF.

    Attributes
    ----------
    model : LateralModel
        The fitted model.
    params, stderr : dict of str to float
        Parameters and their standard errors, SI units (``model.param_units``).
    correlation : ndarray, shape (P, P)
        Correlation of the log-parameters.
    frequency : ndarray, shape (N,)
        Lines used, Hz.
    measured, fitted : ndarray, complex, shape (N,)
        Accelerance at the data's force (ground or axle), m/(s^2 N).
    weights : ndarray, shape (N,)
        Weights used.
    weights_name : str
        How the weights were chosen.
    force : {"ground", "axle"}
    wheel_mass : float
        kg.
    speed : float or None
        m/s.
    rss : float
        Weighted residual sum of squares (real and imaginary parts).
    aic, bic : float
        Information criteria (module docstring).
    amplitude_error, amplitude_bias : float
        Paper Table 1 figure (mean absolute and signed relative amplitude
        error, fractions; module docstring).
    nfev : int
        Residual evaluations in the final refinement.
    message : str
        Optimizer message.
    label : str
        Data label.
    """

    model: LateralModel
    params: dict[str, float]
    stderr: dict[str, float]
    correlation: FloatArray
    frequency: FloatArray
    measured: ComplexArray
    fitted: ComplexArray
    weights: FloatArray
    weights_name: str
    force: ForceKind
    wheel_mass: float
    speed: float | None
    rss: float
    aic: float
    bic: float
    amplitude_error: float
    amplitude_bias: float
    nfev: int
    message: str
    label: str = ""
    at_bound: tuple[str, ...] = ()

    def problems(self) -> list[str]:
        """Why this fit cannot be trusted, one sentence each (empty: none found).

        * a parameter ended on the bound of the search (the data drive it to
          0 or infinity: the model's feature is not in the data);
        * a parameter's standard error exceeds its value (not determined);
        * the corner frequency ``f0`` lies more than a decade outside the fitted
          lines (an extrapolation the data cannot support).
        """
        out: list[str] = []
        if self.at_bound:
            out.append(f"{self.name}: {', '.join(self.at_bound)} at the bound of the search")
        loose = [
            n
            for n, v in self.params.items()
            if not (np.isfinite(self.stderr.get(n, np.nan)) and self.stderr[n] <= abs(v))
        ]
        if loose:
            out.append(
                f"{self.name}: {', '.join(loose)} not determined by the data "
                "(standard error above the value)"
            )
        f0 = self.model.derived().get("f0")
        lo, hi = float(self.frequency[0]), float(self.frequency[-1])
        if f0 is not None and not (lo / 10.0 <= f0 <= 10.0 * hi):
            out.append(
                f"{self.name}: f0 = {f0:.3g} Hz more than a decade outside the fitted band "
                f"{lo:g}-{hi:g} Hz"
            )
        return out

    @property
    def name(self) -> str:
        """Registry name of the model."""
        return self.model.name

    @property
    def n_lines(self) -> int:
        """Number of complex lines fitted."""
        return int(self.frequency.size)

    @property
    def n_params(self) -> int:
        """Number of fitted parameters."""
        return len(self.params)

    @property
    def residual_rms(self) -> float:
        """``sqrt(RSS / 2N)``: rms weighted residual (relative error for relative weights)."""
        return float(np.sqrt(self.rss / (2 * self.n_lines)))

    def criterion(self, name: Criterion) -> float:
        """``aic`` or ``bic``."""
        if name == "aic":
            return self.aic
        if name == "bic":
            return self.bic
        raise InputError(f"criterion: expected 'aic' or 'bic', got {name!r}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (see :mod:`tyredamp.cli.lateral` for the layout)."""
        return {
            "model": self.model.name,
            "label": self.model.label,
            "params": self.params,
            "stderr": self.stderr,
            "units": dict(zip(self.model.param_names, self.model.param_units, strict=True)),
            "conditions": self.model.conditions,
            "derived": self.model.derived(),
            "n_params": self.n_params,
            "n_lines": self.n_lines,
            "rss": self.rss,
            "residual_rms": self.residual_rms,
            "aic": self.aic,
            "bic": self.bic,
            "amplitude_error": self.amplitude_error,
            "amplitude_bias": self.amplitude_bias,
            "weights": self.weights_name,
            "force": self.force,
            "wheel_mass_kg": self.wheel_mass,
            "speed_m_s": self.speed,
            "message": self.message,
            "at_bound": list(self.at_bound),
        }

    def plot(self, **kwargs: Any) -> Any:
        """Measured and fitted FRF; see :func:`tyredamp.plot.lateral.plot_lateral_fit`."""
        from ..plot.lateral import plot_lateral_fit

        return plot_lateral_fit(self, **kwargs)


def _information(rss: float, n_real: int, n_params: int) -> tuple[float, float]:
    tiny = np.finfo(float).tiny
    ll_term = n_real * math.log(max(rss, tiny) / n_real)
    k = n_params + 1
    return ll_term + 2 * k, ll_term + k * math.log(n_real)


def _amplitude_errors(fitted: ComplexArray, measured: ComplexArray) -> tuple[float, float]:
    """Mean absolute and signed relative amplitude error (module docstring), in blocks."""
    s_abs = s_sig = 0.0
    for lo in range(0, fitted.size, BLOCK):
        mag = np.abs(measured[lo : lo + BLOCK])
        rel = (np.abs(fitted[lo : lo + BLOCK]) - mag) / mag
        s_sig += float(np.sum(rel))
        s_abs += float(np.sum(np.abs(rel)))
    return s_abs / fitted.size, s_sig / fitted.size


def _covariance(r_factor: FloatArray, rss: float, n_rows: int) -> tuple[FloatArray, FloatArray]:
    """Standard deviations and correlation of the parameters from ``s^2 (J^T J)^-1``.

    ``r_factor`` is the triangular factor ``R`` of ``J = Q R`` (``n_rows x P``,
    :mod:`._lsq`): ``J`` and ``R`` have the same singular values and right
    singular vectors. Directions the data do not determine (negligible
    singular values) give infinite standard deviations for the parameters
    they involve.
    """
    n, p = n_rows, r_factor.shape[1]
    s2 = rss / max(n - p, 1)
    _, sv, vt = np.linalg.svd(r_factor, full_matrices=False)
    tol = (sv.max() if sv.size else 0.0) * max(n, p) * np.finfo(float).eps
    keep = sv > tol
    cov = (vt[keep].T / sv[keep] ** 2) @ vt[keep] * s2
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    if not np.all(keep):
        bad = np.any(np.abs(vt[~keep]) > 1e-8, axis=0)
        sd = np.where(bad, np.inf, sd)
    finite = np.isfinite(sd) & (sd > 0)
    scale = np.where(finite, sd, 1.0)
    corr = cov / np.outer(scale, scale)
    corr[~finite, :] = np.nan
    corr[:, ~finite] = np.nan
    return sd, corr


def _solve(problem: Problem, starts: Sequence[FloatArray], max_nfev: int) -> Any:
    """Pick the cheapest starts on a factor grid, refine them, return the best result."""
    cands: list[tuple[float, FloatArray]] = []
    for s in starts:
        logs = np.log(np.asarray(s, dtype=float))
        p = logs.size
        grid = np.array(np.meshgrid(*([np.log(_GRID)] * p), indexing="ij")).reshape(p, -1).T
        if grid.shape[0] > 243:  # keep the grid coarse for many parameters
            grid = np.vstack([np.zeros(p), np.eye(p) * np.log(3), -np.eye(p) * np.log(3)])
        for g in grid:
            x = logs + g
            cands.append((problem.rss(x), x))
    cands.sort(key=lambda c: c[0])
    best = None
    for _, x0 in cands[:3]:
        res = problem.solve(x0, _LOG_SPAN, max_nfev, x_scale=1.0)
        if best is None or res.cost < best.cost:
            best = res
    if best is None or not np.all(np.isfinite(best.x)):
        raise ConvergenceError("fit: the least-squares refinement failed from every start")
    return best


def _model_accelerance(m: LateralModel, prep: _Prepared) -> ComplexArray:
    """The model's accelerance at the data's force on the fitted lines (in blocks)."""
    d, f = prep.data, prep.frequency
    out = np.empty(f.size, dtype=complex)
    for lo in range(0, f.size, BLOCK):
        out[lo : lo + BLOCK] = m.response(f[lo : lo + BLOCK], "accelerance", d.force, d.wheel_mass)
    return out


def _lateral_fit(
    m: LateralModel,
    prep: _Prepared,
    cov_log: tuple[FloatArray, FloatArray],
    n_params: int,
    res: Any,
    *,
    rss: float | None = None,
    at_bound: tuple[str, ...] = (),
) -> LateralFit:
    """The :class:`LateralFit` of model ``m`` on ``prep`` (single and joint fits).

    ``cov_log`` holds the standard deviations and correlation of the
    log-parameters; ``n_params`` is the parameter count of the information
    criteria; ``rss`` defaults to that of ``m`` on ``prep``.
    """
    fitted = _model_accelerance(m, prep)
    if rss is None:
        ri = prep.weights * (fitted - prep.measured)
        rss = float(np.sum(ri.real**2 + ri.imag**2))
        del ri
    sd_log, corr = cov_log
    aic, bic = _information(rss, 2 * prep.frequency.size, n_params)
    err, bias = _amplitude_errors(fitted, prep.measured)
    pv = m.vector()
    d = prep.data
    return LateralFit(
        model=m,
        params=m.params,
        stderr={n: float(pv[k] * sd_log[k]) for k, n in enumerate(m.param_names)},
        correlation=corr,
        frequency=prep.frequency,
        measured=prep.measured,
        fitted=fitted,
        weights=prep.weights,
        weights_name=prep.weights_name,
        force=d.force,
        wheel_mass=d.wheel_mass,
        speed=d.speed,
        rss=rss,
        aic=aic,
        bic=bic,
        amplitude_error=err,
        amplitude_bias=bias,
        nfev=int(res.nfev),
        message=str(res.message),
        label=d.label,
        at_bound=at_bound,
    )


def _conditions(cls: type[LateralModel], data: LateralData) -> dict[str, float]:
    cond: dict[str, float] = {}
    for n in cls.condition_names:
        if n == "speed":
            if data.speed is None:
                raise InputError(
                    f"speed: the {cls.name!r} model needs the travel speed: give speed= in "
                    "m/s (Python), --speed KMH (command line), or store it with the FRF "
                    "(meta key speed_m_s, as tyredamp's rig files do)"
                )
            cond["speed"] = float(data.speed)
        else:  # pragma: no cover - no other condition exists yet
            raise InputError(f"{cls.name}: unknown condition {n!r}")
    return cond


def _starts(
    cls: type[LateralModel],
    prep: _Prepared,
    cond: dict[str, float],
    start: ArrayLike | dict[str, float] | None,
) -> list[FloatArray]:
    if start is None:
        starts = cls.initial_guesses(prep.omega, prep.ground_receptance(), **cond)
    else:
        if isinstance(start, dict):
            try:
                sv = np.array([float(start[n]) for n in cls.param_names])
            except KeyError as exc:
                raise InputError(f"start: missing parameter {exc} of {cls.param_names}") from None
        else:
            sv = as_finite(start, "start", ndim=1)
        if sv.size != len(cls.param_names) or np.any(sv <= 0):
            raise InputError(
                f"start: expected {len(cls.param_names)} values > 0 for {cls.param_names}, got {sv}"
            )
        starts = [sv]
    starts = [
        np.asarray(s, dtype=float)
        for s in starts
        if np.all(np.isfinite(s)) and np.all(np.asarray(s) > 0)
    ]
    if not starts:
        raise ConvergenceError(f"fit: no usable starting values for the {cls.name!r} model")
    return starts


def _fit_prepared(
    cls: type[LateralModel],
    prep: _Prepared,
    start: ArrayLike | dict[str, float] | None = None,
    max_nfev: int = 2000,
) -> LateralFit:
    """Fit ``cls`` to prepared lines (:func:`fit_model`, module docstring)."""
    d = prep.data
    cond = _conditions(cls, d)
    n_p = len(cls.param_names)
    problem = Problem([prep.segment(cls, cond)], n_p)
    starts = _starts(cls, prep, cond, start)
    if d.force == "axle" and d.wheel_mass > 0:
        # Stage 1 on the ground-force accelerance A_axle/(1 - M_w A_axle): smoother
        # (no wheel resonance), so the starts land in the right basin.
        a_g = -(prep.omega**2) * prep.ground_receptance()
        stage1 = Segment(cls, cond, Lines(prep.frequency, a_g, 1.0 / np.abs(a_g)))
        res_g = _solve(Problem([stage1], n_p), starts, max_nfev)
        del a_g, stage1
        starts = [np.exp(res_g.x), *starts]
    res = _solve(problem, starts, max_nfev)
    x = np.asarray(res.x, dtype=float)
    r_aug, rss = problem.qr(x)
    cov_log = _covariance(r_aug[:n_p, :n_p], rss, problem.n_residuals)
    at_bound = tuple(
        n for n, a in zip(cls.param_names, np.asarray(res.active_mask), strict=True) if a != 0
    )
    m = cls.from_vector(np.exp(x), **cond)
    return _lateral_fit(m, prep, cov_log, n_p, res, rss=rss, at_bound=at_bound)


def _with_conditions(
    data: LateralData | FRF,
    speed: float | None = None,
    force: ForceKind | None = None,
    wheel_mass: float | None = None,
) -> LateralData:
    d0 = data if isinstance(data, LateralData) else LateralData.from_frf(data)
    return LateralData(
        frf=d0.frf,
        speed=speed if speed is not None else d0.speed,
        force=force if force is not None else d0.force,
        wheel_mass=wheel_mass if wheel_mass is not None else d0.wheel_mass,
        label=d0.label,
    )


def fit_models_on(
    data: LateralData | FRF,
    models: Sequence[str | type[LateralModel]],
    *,
    speed: float | None = None,
    force: ForceKind | None = None,
    wheel_mass: float | None = None,
    band: tuple[float, float] | None = None,
    weights: Weights | ArrayLike = "auto",
    start: ArrayLike | dict[str, float] | None = None,
    channel: tuple[int, int] | None = None,
    max_nfev: int = 2000,
) -> list[LateralFit]:
    """:func:`fit_model` for several models on lines prepared once (same options for all)."""
    classes = [get_model_class(m) for m in models]
    prep = _prepare(_with_conditions(data, speed, force, wheel_mass), band, weights, channel)
    return [_fit_prepared(cls, prep, start, max_nfev) for cls in classes]


def fit_model(
    data: LateralData | FRF,
    model: str | type[LateralModel],
    *,
    speed: float | None = None,
    force: ForceKind | None = None,
    wheel_mass: float | None = None,
    band: tuple[float, float] | None = None,
    weights: Weights | ArrayLike = "auto",
    start: ArrayLike | dict[str, float] | None = None,
    channel: tuple[int, int] | None = None,
    max_nfev: int = 2000,
) -> LateralFit:
    """Fit one lateral model to a measured complex FRF (module docstring for the method).

    Parameters
    ----------
    data : LateralData or FRF
        The measurement. For an FRF, missing conditions come from the keyword
        arguments or ``frf.meta`` (:meth:`LateralData.from_frf`).
    model : str or LateralModel subclass
        ``"classic"``, ``"maxwell"``, ``"viscoplastic"``, ``"hysteretic"``,
        ``"relaxation"``, ``"string"`` or an alias (``"proposed"`` ...).
    speed : float, optional
        Travel speed in m/s (overrides the data's).
    force : {"ground", "axle"}, optional
        Force at which the FRF was measured (overrides the data's).
    wheel_mass : float, optional
        Wheel mass in kg for ``force="axle"`` (overrides the data's).
    band : (float, float), optional
        Frequency band in Hz; default all lines above 0 Hz.
    weights : str or array_like
        ``"auto"``, ``"relative"``, ``"coherence"``, ``"uniform"`` or one
        weight per line of the FRF.
    start : array_like or dict, optional
        Starting parameters (SI); default automatic.
    channel : (int, int)
        Output and input positions in the FRF.
    max_nfev : int
        Evaluation budget of each refinement.

    Returns
    -------
    LateralFit

    Raises
    ------
    InputError
        Bad data or options; a speed-dependent model without a speed.
    ConvergenceError
        The optimizer failed from every start.
    """
    return fit_models_on(
        data,
        [model],
        speed=speed,
        force=force,
        wheel_mass=wheel_mass,
        band=band,
        weights=weights,
        start=start,
        channel=channel,
        max_nfev=max_nfev,
    )[0]


# ---------------------------------------------------------------------------------- ranking
