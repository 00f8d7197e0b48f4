"""Trends of a mode family's quantities over one condition of a campaign.

For each family, quantity (frequency, damping ratio, modal damping ``C'_nn``)
and numeric condition, each *series* (observations with the same tyre and
the same other conditions, at least three distinct values of the condition)
gets a weighted least-squares polynomial (weights ``1 / sigma^2`` from the
identification's standard errors) whose degree, 0 to 3, minimises the
corrected Akaike criterion AICc (Hurvich & Tsai 1989) with the scale of the
errors estimated from the residuals. Frequency against pressure is fitted as
``f^2`` (a ring on an elastic foundation under inflation has every stiffness
term linear in pressure, so ``f^2`` is close to linear in ``p``; spec
``virtual-tyre.md``). The uncertainty band is the standard error of the
fitted curve, ``sqrt(a^T Cov a)`` with ``Cov = s^2 (A^T W A)^-1`` and ``s^2``
the reduced chi-square, never below 1 (the band is never narrower than the
stated standard errors allow).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError

__all__ = ["ArrayLike1", "TrendFit", "fit_trend"]

ArrayLike1 = Sequence[float] | NDArray[np.float64]


@dataclass(frozen=True)
class TrendFit:
    """A weighted polynomial trend ``y(x)`` with its uncertainty.

    Attributes
    ----------
    degree : int
        Polynomial degree chosen by AICc.
    coef : ndarray, shape (degree + 1,)
        Coefficients in the scaled variable ``u = (x - x0) / xs``, lowest first.
    cov : ndarray, shape (degree + 1, degree + 1)
        Their covariance (scaled by the reduced chi-square, at least 1).
    x0, xs : float
        Centre and scale of ``x``.
    transform : {"none", "square"}
        ``"square"``: the polynomial is fitted to ``y^2`` (frequency against
        pressure) and :meth:`predict` returns ``sqrt``.
    n : int
        Number of observations.
    aicc : dict of int to float
        AICc of every degree tried.
    """

    degree: int
    coef: NDArray[np.float64]
    cov: NDArray[np.float64]
    x0: float
    xs: float
    transform: str
    n: int
    aicc: dict[int, float]

    def predict(self, x: ArrayLike1) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Trend value and its standard error at ``x`` (same units as the data)."""
        u = (np.asarray(x, dtype=float) - self.x0) / self.xs
        a = np.vander(np.atleast_1d(u), self.degree + 1, increasing=True)
        g = a @ self.coef
        sg = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", a, self.cov, a), 0.0))
        if self.transform == "square":
            y = np.sqrt(np.maximum(g, 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                sy = np.where(y > 0, sg / (2 * y), np.inf)
            return y, sy
        return g, sg

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description."""
        return {
            "degree": self.degree,
            "coef": self.coef.tolist(),
            "cov": self.cov.tolist(),
            "x0": self.x0,
            "xs": self.xs,
            "transform": self.transform,
            "n": self.n,
            "aicc": {str(k): v for k, v in self.aicc.items()},
        }


def fit_trend(
    x: ArrayLike1,
    y: ArrayLike1,
    sigma: ArrayLike1 | None = None,
    *,
    transform: str = "none",
    max_degree: int = 3,
) -> TrendFit:
    """Fit a weighted polynomial trend with the degree chosen by AICc.

    Parameters
    ----------
    x, y : array_like, shape (n,)
        Condition values and observations (finite).
    sigma : array_like, shape (n,), optional
        Standard errors of ``y`` (> 0); missing, zero or non-finite values
        take the median of the others (all missing: equal weights).
    transform : {"none", "square"}
        Fit ``y^2`` instead of ``y`` (standard errors ``2 y sigma``).
    max_degree : int
        Highest degree tried; degree ``d`` needs ``n >= d + 2`` observations
        at ``d + 1`` distinct ``x`` (at least one residual degree of freedom);
        where the AICc correction is undefined (``n = d + 2``) plain AIC is used.

    Raises
    ------
    InputError
        Fewer than 3 finite observations or 2 distinct ``x``, or a bad transform.
    """
    xv = np.asarray(x, dtype=float).reshape(-1)
    yv = np.asarray(y, dtype=float).reshape(-1)
    if xv.size != yv.size:
        raise InputError(f"fit_trend: x and y differ in length ({xv.size} and {yv.size})")
    sv = (
        np.full(yv.size, np.nan)
        if sigma is None
        else np.asarray(
            [np.nan if s is None else s for s in np.asarray(sigma, dtype=object)], dtype=float
        )
    )
    ok = np.isfinite(xv) & np.isfinite(yv)
    xv, yv, sv = xv[ok], yv[ok], sv[ok]
    if transform not in ("none", "square"):
        raise InputError(f"fit_trend: transform must be 'none' or 'square', got {transform!r}")
    n_distinct = np.unique(xv).size
    if yv.size < 3 or n_distinct < 2:
        raise InputError(
            f"fit_trend: expected at least 3 observations at 2 distinct values, got {yv.size} "
            f"at {n_distinct}"
        )
    good = np.isfinite(sv) & (sv > 0)
    sv = np.where(good, sv, np.median(sv[good]) if good.any() else 1.0)
    absolute = bool(good.any())
    if transform == "square":
        sv = 2 * np.abs(yv) * sv
        yv = yv**2
    w = 1.0 / sv**2
    x0 = float(np.mean(xv))
    xs = float(np.ptp(xv)) / 2 or 1.0
    u = (xv - x0) / xs
    n = yv.size
    best: tuple[float, int, Any] | None = None
    aicc: dict[int, float] = {}
    for d in range(0, max_degree + 1):
        k = d + 1
        if n < k + 1 or n_distinct < k:
            break
        a = np.vander(u, k, increasing=True)
        sw = np.sqrt(w)
        coef, *_ = np.linalg.lstsq(a * sw[:, None], yv * sw, rcond=None)
        chi2 = float(np.sum(w * (yv - a @ coef) ** 2))
        # Gaussian likelihood with the error scale estimated from the residuals; the
        # small-sample correction where it is defined (n > k + 1), plain AIC otherwise
        corr = 2 * k * (k + 1) / (n - k - 1) if n > k + 1 else 0.0
        score = n * math.log(max(chi2 / n, 1e-300)) + 2 * k + corr
        aicc[d] = score
        if best is None or score < best[0] - 1e-12:
            best = (score, d, (a, coef, chi2))
    assert best is not None
    _, d, (a, coef, chi2) = best
    k = d + 1
    s2 = chi2 / (n - k) if n > k else 1.0
    if absolute:
        s2 = max(s2, 1.0)
    cov = s2 * np.linalg.inv((a * w[:, None]).T @ a)
    return TrendFit(d, np.asarray(coef), cov, x0, xs, transform, n, aicc)
