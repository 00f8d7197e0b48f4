"""Uncertainty and identifiability of the ring parameters.

``cov = (J^T J)^-1`` of the weighted residuals (scaled by the reduced
chi-square ``RSS/dof`` when it is significantly above 1, p < 0.01, i.e. when
the model error dominates the measurement error, or when there were no
standard errors, :func:`chi2_scaling`); correlations from ``cov``. Verdict
per parameter from its standard error relative to its value, floored at 1 %
of its contribution scale (``T_c`` against the tension itself; ``<= 0.1``
identified, ``<= 0.5`` poorly identified, else not identifiable from these
modes) and from the scaled Jacobian's singular values (collinearity index of
Brun et al. 2001 above 100: the parameters of that near-null direction are
confounded whatever the noise, e.g. ``c_r`` and ``c_d`` when only the driven
member of each pair is measured, whose ``phi_d^2 = A^2`` follows
``n^2/(1+n^2)`` like the ``c_r`` term), with the parameters it is correlated
with (``|rho| > 0.95``). For example ``k_t`` enters eq. (1) with weight 1
against ``n^2`` for ``k_r``: radial modes alone determine it poorly, and its
pressure slope usually not at all.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.stats import chi2

__all__ = [
    "COLLINEARITY",
    "CORRELATED",
    "IDENTIFIED",
    "MODEL_LIMITED",
    "POORLY",
    "admit_model_error",
    "central_jacobian",
    "chi2_scaling",
    "collinearity",
    "correlation",
    "verdict",
    "verdicts",
]

#: Relative standard error (against the contribution scale) up to which a parameter is identified.
IDENTIFIED = 0.1
#: ... up to which it is poorly identified; above it, not identifiable from these modes.
POORLY = 0.5
#: Correlation above which two parameters are reported as correlated.
CORRELATED = 0.95
#: Collinearity index (Brun et al. 2001) above which a parameter combination is confounded: a
#: change of the combination is seen 100 times weaker than a change of one parameter, so with
#: model and data agreeing to about 1 % (modal damping, shape amplitudes, model error) it is
#: undetermined. Brun et al. call 10-15 critical for percent-level environmental data; modal
#: frequencies are more precise, and the standard-error verdict covers the noise itself.
COLLINEARITY = 100.0
#: Reduced chi-square above which the misfit is model error, not noise: the covariance scaled
#: by it describes a random scatter the residuals do not have (systematic misfit moves every
#: parameter together), so no parameter is called identified.
MODEL_LIMITED = 4.0
#: Chi-square upper-tail probability below which the covariance is scaled by ``RSS/dof``.
_SIGNIFICANT = 0.01


def central_jacobian(
    fun: Callable[[NDArray[np.float64]], NDArray[np.float64]], x: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Central-difference Jacobian of ``fun`` at ``x`` (step ``1e-6 max(1, |x_k|)``).

    Parameters
    ----------
    fun : callable
        ``x`` (shape (P,)) to residuals (shape (M,)).
    x : ndarray, shape (P,)

    Returns
    -------
    ndarray, shape (M, P)
    """
    f0 = fun(x)
    jac = np.empty((f0.size, x.size))
    for k in range(x.size):
        h = 1e-6 * max(1.0, abs(float(x[k])))
        xp = x.copy()
        xm = x.copy()
        xp[k] += h
        xm[k] -= h
        jac[:, k] = (fun(xp) - fun(xm)) / (2 * h)
    return jac


def chi2_scaling(rss: float, dof: int, have_std: bool) -> tuple[float | None, bool]:
    """Goodness of fit and whether to scale the covariance by ``RSS/dof`` (module docstring).

    Parameters
    ----------
    rss : float
        Weighted residual sum of squares.
    dof : int
        Degrees of freedom (values minus parameters).
    have_std : bool
        Whether the weights are the measurement standard errors (then ``rss``
        is chi-square distributed under the model).

    Returns
    -------
    p_value : float or None
        Upper tail of ``chi2(dof)`` at ``rss`` (None without standard errors).
    scaled : bool
        True without standard errors or when ``p_value < 0.01``.
    """
    if not have_std:
        return None, True
    pval = float(chi2.sf(rss, dof))
    return pval, pval < _SIGNIFICANT


def correlation(cov: NDArray[np.float64]) -> NDArray[np.float64]:
    """Correlation matrix of the covariance ``cov`` (shape (P, P)); zero-variance rows stay 0."""
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    d = np.where(sd > 0, sd, 1.0)
    return np.asarray(np.clip(cov / np.outer(d, d), -1.0, 1.0), dtype=np.float64)


def collinearity(jac: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Singular values and right vectors of the column-normalised Jacobian (Brun et al. 2001)."""
    norms = np.linalg.norm(jac, axis=0)
    s_tilde = jac / np.where(norms > 0, norms, 1.0)
    _, sv, vt = np.linalg.svd(s_tilde, full_matrices=False)
    return np.asarray(sv, dtype=np.float64), np.asarray(vt, dtype=np.float64)


def verdict(rel: float) -> str:
    """Verdict of a parameter from its relative standard error (module docstring)."""
    if not math.isfinite(rel) or rel > POORLY:
        return "not identifiable from these modes"
    if rel > IDENTIFIED:
        return "poorly identified"
    return "identified"


def verdicts(
    names: Sequence[str],
    rel_se: NDArray[np.float64],
    corr: NDArray[np.float64],
    jac: NDArray[np.float64],
) -> dict[str, dict[str, Any]]:
    """Per-parameter verdicts (module docstring).

    Besides the relative standard error, the collinearity index of Brun,
    Reichert & Kuensch (Water Resour. Res. 37(4), 2001) is used: with the
    column-normalised Jacobian ``S~`` (each parameter's sensitivity scaled to
    unit length), a singular value ``s_k < 1/COLLINEARITY`` means that a
    combination of parameters can change by a factor ``COLLINEARITY`` more
    than the data resolve; the parameters carrying that combination (its
    singular vector's entries above 0.3 of the largest) are not separately
    identifiable, whatever the noise level.
    """
    out: dict[str, dict[str, Any]] = {}
    confounded: dict[int, set[int]] = {}
    sv, vt = collinearity(jac)
    for k in np.flatnonzero(sv < 1.0 / COLLINEARITY):
        v = np.abs(vt[k])
        members = {int(j) for j in np.flatnonzero(v > 0.3 * v.max())}
        for j in members:
            confounded.setdefault(j, set()).update(members - {j})
    for i, nm in enumerate(names):
        rel = float(rel_se[i])
        partners = [
            names[j] for j in range(len(names)) if j != i and abs(float(corr[i, j])) > CORRELATED
        ]
        label = verdict(rel)
        if i in confounded:
            others = ", ".join(names[j] for j in sorted(confounded[i])) or "itself"
            label = f"not separately identifiable (confounded with {others})"
        out[nm] = {"verdict": label, "relative_se": rel, "correlated_with": partners}
    return out


def admit_model_error(
    out: dict[str, dict[str, Any]],
    theta: NDArray[np.float64],
    se: NDArray[np.float64],
    chi2_per_dof: float | None,
    dof: int = 1,
) -> dict[str, dict[str, Any]]:
    """Verdicts that admit a model discrepancy and parameters consistent with zero.

    With weights from the measurement standard errors the reduced chi-square
    ``RSS/dof`` estimates ``1 + s_d^2 / s_noise^2`` (a model discrepancy of
    constant variance ``s_d^2`` beside the noise, Kennedy & O'Hagan, J. R.
    Stat. Soc. B 63(3), 2001, eq. (5)). Above :data:`MODEL_LIMITED` the misfit
    is systematic and the covariance, even scaled by ``RSS/dof``, treats it
    as random. A systematic discrepancy ``d`` (weighted) moves parameter
    ``k`` by ``e_k^T (J^T J)^-1 J^T d``, at most ``sqrt(C_kk) ||P_J d||``
    (Cauchy-Schwarz; ``C = (J^T J)^-1``, ``P_J`` the projection on the
    model's sensitivities). The part of ``d`` the model absorbs cannot be
    seen; taking it no larger than the part it leaves (``||P_J d||^2 <=
    RSS``) gives the bound ``b_k = sqrt(C_kk RSS) = se_k sqrt(dof)`` with
    ``se_k`` the scaled standard error. A parameter whose bound, against its
    verdict scale, exceeds :data:`IDENTIFIED` is not distinguishable from the
    discrepancy: it becomes ``model-limited`` (``model_error_bound`` is
    reported as a fraction of the verdict scale for every parameter). A
    parameter within two standard uncertainties of zero (``sqrt(se^2 + b_k^2)``
    with the bound in the parameter's unit) is flagged ``consistent_with_zero``
    (a 95 % interval that contains 0).

    Parameters
    ----------
    out : dict
        From :func:`verdicts` (changed copies are returned).
    theta, se : ndarray, shape (P,)
        Values and (scaled) standard errors in the order of ``out``.
    chi2_per_dof : float or None
        ``RSS/dof`` with measurement weights, None without standard errors.
    dof : int
        Degrees of freedom of the fit.
    """
    res: dict[str, dict[str, Any]] = {}
    limited = chi2_per_dof is not None and chi2_per_dof > MODEL_LIMITED
    for i, (name, v) in enumerate(out.items()):
        w = dict(v)
        bound = float(w["relative_se"]) * math.sqrt(max(dof, 1)) if limited else 0.0
        # two standard uncertainties, the model-error bound included (se sqrt(1 + dof))
        u = float(se[i]) * math.sqrt(1.0 + (max(dof, 1) if limited else 0.0))
        w["consistent_with_zero"] = bool(abs(float(theta[i])) <= 2 * u)
        w["model_error_bound"] = bound
        w["model_limited"] = bool(
            limited and bound > IDENTIFIED and w["verdict"] in ("identified", "poorly identified")
        )
        if w["model_limited"]:
            w["verdict"] = (
                f"model-limited (chi2/dof {chi2_per_dof:.3g}: the ring's misfit could move it "
                f"by {100 * bound:.2g} %)"
            )
        elif w["consistent_with_zero"] and w["verdict"] == "identified":
            w["verdict"] = "consistent with zero"
        res[name] = w
    return res
