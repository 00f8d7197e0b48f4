"""Joint fits of one lateral model to several speeds with shared physical parameters.

The tyre-road damper of each model (``c`` Maxwell, ``c2`` visco-plastic,
``C_r`` proposed) becomes ``C_alpha / V`` with one cornering stiffness
``C_alpha`` (spec eq. 19, 33), and every other parameter (carcass ``K``,
``h`` ...) is shared; the least-squares problem, standard errors and
information criteria are those of :mod:`.fit`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ._lsq import Problem
from .data import LateralData, Weights, _prepare
from .fit import (
    _LOG_SPAN,
    FloatArray,
    LateralFit,
    _conditions,
    _covariance,
    _fit_prepared,
    _information,
    _lateral_fit,
)
from .models import LateralModel, get_model_class

__all__ = ["JointFit", "fit_by_pressure", "fit_joint"]


@dataclass(frozen=True, eq=False)
class JointFit:
    """One model fitted to several conditions with shared parameters.

    Attributes
    ----------
    model_name : str
        Registry name.
    share : {"physical", "none"}
        How parameters are shared (:func:`fit_joint`).
    names, units : tuple of str
        Global parameter names and units.
    params, stderr : dict of str to float
        Global parameters and standard errors (SI).
    fits : tuple of LateralFit
        Per-condition results with the shared parameters (their ``stderr``
        follow from the joint covariance; their ``aic``/``bic`` are those of
        the condition alone with the global parameter count).
    rss : float
        Total weighted residual sum of squares.
    aic, bic : float
        Of the joint fit (``n`` = all real residuals, ``P`` = global count).
    """

    model_name: str
    share: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    params: dict[str, float]
    stderr: dict[str, float]
    fits: tuple[LateralFit, ...]
    rss: float
    aic: float
    bic: float

    @property
    def n_params(self) -> int:
        """Number of global parameters."""
        return len(self.names)

    @property
    def amplitude_error(self) -> float:
        """Mean of the per-condition amplitude errors (fraction)."""
        return float(np.mean([f.amplitude_error for f in self.fits]))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "model": self.model_name,
            "share": self.share,
            "params": self.params,
            "stderr": self.stderr,
            "units": dict(zip(self.names, self.units, strict=True)),
            "rss": self.rss,
            "aic": self.aic,
            "bic": self.bic,
            "amplitude_error": self.amplitude_error,
            "conditions": [f.to_dict() for f in self.fits],
        }


def _joint_parameters(
    cls: type[LateralModel],
    ds: list[LateralData],
    singles: list[LateralFit],
    share: str,
) -> tuple[list[str], list[str], list[tuple[FloatArray, FloatArray]], FloatArray]:
    """Names, units, maps and start of the global log-parameters of a joint fit.

    Each map turns the global log-parameters ``x`` into one condition's:
    ``logp_i = T_i @ x + b_i``; the start is the mean of the separate fits.
    """
    p = len(cls.param_names)
    maps: list[tuple[FloatArray, FloatArray]] = []
    if share == "physical":
        names = list(cls.param_names)
        units = list(cls.param_units)
        k_road = cls.param_names.index(cls.road_damper) if cls.road_damper else -1
        if k_road >= 0:
            names[k_road] = "C_alpha"
            units[k_road] = "N/rad"
        for d in ds:
            b = np.zeros(p)
            if k_road >= 0:
                b[k_road] = -math.log(float(d.speed))  # type: ignore[arg-type]
            maps.append((np.eye(p), b))
        x0 = np.mean(
            [np.log(f.model.vector()) - b for f, (_, b) in zip(singles, maps, strict=True)], axis=0
        )
        return names, units, maps, x0
    names, units = [], []
    for i, d in enumerate(ds):
        tag = d.label or f"#{i}"
        names += [f"{n}@{tag}" for n in cls.param_names]
        units += list(cls.param_units)
        t = np.zeros((p, p * len(ds)))
        t[:, i * p : (i + 1) * p] = np.eye(p)
        maps.append((t, np.zeros(p)))
    return names, units, maps, np.concatenate([np.log(f.model.vector()) for f in singles])


def fit_joint(
    data: Sequence[LateralData],
    model: str | type[LateralModel],
    *,
    share: Literal["physical", "none"] = "physical",
    band: tuple[float, float] | None = None,
    weights: Weights | ArrayLike = "auto",
    max_nfev: int = 4000,
) -> JointFit:
    """Fit one model to several speeds (at one pressure) with shared physical parameters.

    With ``share="physical"`` the model's tyre-road damper (``road_damper``:
    ``c`` Maxwell, ``c2`` visco-plastic, ``C_r`` proposed) is replaced by
    ``C_alpha / V_i`` with one global cornering stiffness ``C_alpha`` (N/rad;
    spec: ``C_r = C_alpha / V``, eq. 19, 33) and all other parameters (carcass
    ``K``, ``h`` ...) are shared. Models with the speed as an operating
    condition (relaxation, string) share all their parameters. The classic
    model has no speed term, so all its parameters are shared. With
    ``share="none"`` every condition keeps its own parameters (the sum of
    separate fits, for comparison by AIC/BIC).

    Parameters
    ----------
    data : sequence of LateralData
        Two or more measurements, each with its ``speed``.
    model : str or LateralModel subclass
    share : {"physical", "none"}
    band, weights :
        As in :func:`fit_model` (the same for every condition).
    max_nfev : int
        Evaluation budget of the joint refinement.

    Returns
    -------
    JointFit
    """
    cls = get_model_class(model)
    ds = list(data)
    if len(ds) < 2:
        raise InputError(f"data: expected at least 2 conditions, got {len(ds)}")
    if share not in ("physical", "none"):
        raise InputError(f"share: expected 'physical' or 'none', got {share!r}")
    for i, d in enumerate(ds):
        if not isinstance(d, LateralData):
            raise InputError(f"data[{i}]: expected LateralData, got {type(d).__name__}")
        if d.speed is None and (cls.road_damper is not None or cls.condition_names):
            raise InputError(f"data[{i}]: the joint fit needs each condition's speed (m/s)")
    preps = [_prepare(d, band, weights) for d in ds]
    singles = [_fit_prepared(cls, pr) for pr in preps]
    conds = [_conditions(cls, d) for d in ds]
    names, units, maps, x0 = _joint_parameters(cls, ds, singles, share)
    segments = [
        pr.segment(cls, cd, t, b) for pr, cd, (t, b) in zip(preps, conds, maps, strict=True)
    ]
    problem = Problem(segments, int(x0.size))
    res = problem.solve(x0, _LOG_SPAN, max_nfev)
    x = np.asarray(res.x, dtype=float)
    r_aug, rss = problem.qr(x)
    r_factor = r_aug[: x.size, : x.size]
    n_real = problem.n_residuals
    dof = max(n_real - x.size, 1)
    sd_g, _ = _covariance(r_factor, rss, n_real)
    # Full covariance for per-condition standard errors (J^T J = R^T R).
    cov = np.linalg.pinv(r_factor.T @ r_factor) * (rss / dof)
    aic, bic = _information(rss, n_real, x.size)
    gp = np.exp(x)
    fits = []
    for pr, cd, (t, b) in zip(preps, conds, maps, strict=True):
        cov_i = t @ cov @ t.T
        sd_i = np.sqrt(np.clip(np.diag(cov_i), 0.0, None))
        scale = np.where(sd_i > 0, sd_i, 1.0)
        m = cls.from_vector(np.exp(t @ x + b), **cd)
        fits.append(_lateral_fit(m, pr, (sd_i, cov_i / np.outer(scale, scale)), x.size, res))
    return JointFit(
        model_name=cls.name,
        share=share,
        names=tuple(names),
        units=tuple(units),
        params={n: float(gp[i]) for i, n in enumerate(names)},
        stderr={n: float(gp[i] * sd_g[i]) for i, n in enumerate(names)},
        fits=tuple(fits),
        rss=rss,
        aic=aic,
        bic=bic,
    )


def fit_by_pressure(
    data: Sequence[LateralData],
    model: str | type[LateralModel],
    **joint_kwargs: Any,
) -> dict[float, JointFit]:
    """Joint fits (:func:`fit_joint`) of the conditions grouped by inflation pressure.

    Parameters
    ----------
    data : sequence of LateralData
        Measurements whose ``frf.meta["pressure_bar"]`` gives the pressure (as
        written by :mod:`tyredamp.virtual.lateral_rig`); at least two speeds per
        pressure.
    model : str or LateralModel subclass
    **joint_kwargs
        Passed to :func:`fit_joint` (``share``, ``band``, ``weights`` ...).

    Returns
    -------
    dict of float to JointFit
        By pressure in bar, increasing.
    """
    groups: dict[float, list[LateralData]] = {}
    for i, d in enumerate(data):
        p = d.frf.meta.get("pressure_bar") if isinstance(d, LateralData) else None
        if p is None:
            raise InputError(f"data[{i}]: expected frf.meta['pressure_bar'] (bar)")
        groups.setdefault(float(p), []).append(d)
    return {p: fit_joint(g, model, **joint_kwargs) for p, g in sorted(groups.items())}
