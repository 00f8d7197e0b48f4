"""A mode family's own frequency trend over the conditions: where its next member should be.

Used by the tracking (:mod:`tyredamp.campaign.tracking`, step 3) to limit how
far a family's frequency may move to a new test when no mode of a similar
shape stands beside it (where the gap to a look-alike neighbour gives no
bound): the family's members ``(x_k, f_k)`` (``x`` the numeric conditions,
each over its range in the campaign) are fitted by ordinary least squares
with a plane ``f = b_0 + b^T (x - x_0)`` centred on the new test's conditions
``x_0``, so that ``b_0`` is the prediction there. With ``p`` coefficients and
``n >= p + 2`` members (2 residual degrees of freedom at least) the residual
variance is ``s^2 = RSS / (n - p)`` and the variance of a new observation
about the prediction is

``s^2 (1 + [(X^T X)^-1]_00)``

(the variance of a new observation about a least-squares prediction, the
prediction interval of linear regression; for a straight line it is
``s^2 (1 + 1/n + (x_0 - xbar)^2 / S_xx)``, Draper & Smith, *Applied Regression
Analysis*, 3rd ed., Wiley 1998, ch. 1, the form the tests check); a change ``d`` from the
prediction is then admissible when ``d^2 / var`` is below the squared
Student-t quantile with ``n - p`` degrees of freedom (:func:`change_limit`;
with 1 or 2 residual degrees of freedom the scale ``s`` is barely known and
the limit is wide). Members of the new
test's tyre are used when they are enough; else all the family's members
(another tyre's scatter then widens ``s``). Conditions that do not vary among
the members are left out of the plane. Too few members give no trend (the
tracking then leaves the change unbounded, as the gap does not bound it either).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Any

import numpy as np

__all__ = ["change_limit", "family_trend", "frequency_change_z2", "reference_frequency"]


def family_trend(
    members: Sequence[tuple[Mapping[str, Any], float]],
    target: Mapping[str, Any],
    span: Mapping[str, float],
) -> tuple[float, float, float] | None:
    """The family's predicted frequency at ``target``, the variance of a new observation, dof.

    Parameters
    ----------
    members : sequence of (conditions, frequency)
        The family's members so far: their conditions (``tyre`` and numeric
        conditions) and frequencies (Hz).
    target : mapping
        Conditions of the new test.
    span : mapping of str to float
        Range of each numeric condition in the campaign (> 0), the scale of ``x``.

    Returns
    -------
    (float, float, float) or None
        Prediction (Hz), variance (Hz^2) of a new observation about it
        (module docstring) and the residual degrees of freedom ``n - p``;
        None when neither the members of the target's tyre nor all members
        are enough (``n >= p + 2``).
    """
    same = [m for m in members if m[0].get("tyre") == target.get("tyre")]
    for group in (same, members):
        fit = _plane(group, target, span)
        if fit is not None:
            return fit
    return None


def _plane(
    group: Sequence[tuple[Mapping[str, Any], float]],
    target: Mapping[str, Any],
    span: Mapping[str, float],
) -> tuple[float, float, float] | None:
    names = [c for c in span if _number(target.get(c)) is not None]
    rows = [(m, f) for m, f in group if all(_number(m.get(c)) is not None for c in names) and f > 0]
    if not rows:
        return None
    x = np.array([[float(m[c]) for c in names] for m, _ in rows]).reshape(len(rows), len(names))
    keep = [k for k in range(len(names)) if np.ptp(x[:, k]) > 0]
    x0 = np.array([float(target[names[k]]) for k in keep])
    scale = np.array([span[names[k]] for k in keep])
    a = np.column_stack([np.ones(len(rows)), (x[:, keep] - x0) / scale])
    n, p = a.shape
    if n < p + 2:  # at least 2 residual degrees of freedom for a scale
        return None
    f = np.array([fr for _, fr in rows])
    coef, *_ = np.linalg.lstsq(a, f, rcond=None)
    s2 = float(np.sum((f - a @ coef) ** 2)) / (n - p)
    inv = np.linalg.pinv(a.T @ a)
    return float(coef[0]), s2 * (1.0 + float(inv[0, 0])), float(n - p)


def _number(v: Any) -> float | None:
    if isinstance(v, bool) or not isinstance(v, int | float):
        return None
    return float(v) if math.isfinite(float(v)) else None


def frequency_change_z2(f_new: float, f_ref: float, variance: float) -> float:
    """``z^2 = (f_new - f_ref)^2 / variance`` (inf for a change with no variance to explain it)."""
    d = f_new - f_ref
    if variance > 0:
        return d * d / variance
    return 0.0 if d == 0 else math.inf


def reference_frequency(
    f_rep: float, trend: tuple[float, float, float] | None, member_var: float
) -> tuple[float, float | None, float]:
    """Frequency a family's next member is compared with, its variance (Hz, Hz^2) and dof.

    The family's trend (:func:`family_trend`) where it has one, its variance
    never below ``member_var`` (the representative's squared standard error:
    a noise-free straight line does not bound the change to nothing); else
    the representative ``f_rep`` with no bound (variance None): a family
    without a trend has no course to leave.
    """
    if trend is None:
        return f_rep, None, math.inf
    pred, var, dof = trend
    var = max(var, member_var)
    return pred, (var if var > 0 else None), dof


@lru_cache(maxsize=256)
def change_limit(dof: float, alpha: float) -> float:
    """Upper ``1 - alpha`` quantile of ``z^2`` for ``dof`` residual degrees of freedom.

    The square of Student's t with ``dof`` degrees of freedom, i.e. the F
    distribution with (1, ``dof``) degrees of freedom; chi-square with 1
    degree of freedom for ``dof`` infinite.
    """
    from scipy.stats import chi2, f

    if math.isinf(dof):
        return float(chi2.ppf(1.0 - alpha, 1))
    return float(f.ppf(1.0 - alpha, 1, dof))
