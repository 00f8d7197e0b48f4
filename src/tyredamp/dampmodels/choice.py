"""Model choice: the damping models ranked by their likelihood under the measured noise.

For independent complex Gaussian noise of known standard deviation, ``-2 ln L``
of a fit is its ``chi2`` (sum of squared weighted residuals) up to a constant
common to all models. The models are ranked by

* BIC ``= chi2 + k ln n`` (Schwarz, Ann. Stat. 6(2) (1978) 461-464), the
  verdict's criterion: consistent, so the true model wins with probability
  tending to 1 as the data grow; differences read on the scale of Kass &
  Raftery, J. Am. Stat. Assoc. 90 (1995) 773-795, sec. 3.2: below 2 not worth
  more than a bare mention, 2-6 positive, 6-10 strong, above 10 very strong;
* AIC ``= chi2 + 2 k`` (Akaike, IEEE Trans. Autom. Control 19(6) (1974) 716-723),
  reported beside it;

and the nested pairs are tested by likelihood ratio, ``Lambda = chi2_simple -
chi2_complex`` against ``chi^2`` with ``df`` degrees of freedom (Wilks, Ann.
Math. Stat. 9 (1938) 60-62): proportional within viscous (``df = m(m-1)/2``),
viscous within fractional (``alpha = 1``, ``df = 1``) and viscous within
exponential (``mu -> infinity``, a boundary of the parameter space: the
statistic follows the mixture ``(chi^2_0 + chi^2_1)/2``, Self & Liang,
J. Am. Stat. Assoc. 82 (1987) 605-610, case 5, so ``p`` is half the ``chi^2_1``
tail). The hysteretic model is nested in none: only the criteria rank it.
The best model's ``chi2`` is also compared with its expectation ``n - k``:
when no model reaches the noise, the verdict says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.stats import chi2 as chi2_dist

from ..exceptions import InputError
from .frffit import MODELS, ModalStart, ModelFit, fit_model

__all__ = ["LikelihoodRatio", "ModelComparison", "compare_models", "likelihood_ratio"]

#: BIC difference below which two models are not told apart (Kass & Raftery 1995).
BIC_TIE = 2.0
#: Level of the likelihood-ratio tests and of the goodness-of-fit check.
LEVEL = 0.01
#: Nested pairs (simple, complex, boundary?).
NESTED: tuple[tuple[str, str, bool], ...] = (
    ("proportional", "viscous", False),
    ("viscous", "exponential", True),
    ("viscous", "fractional", False),
)


@dataclass(frozen=True)
class LikelihoodRatio:
    """A likelihood-ratio test of a simple model within a richer one (module docstring)."""

    simple: str
    complex: str
    statistic: float
    df: int
    p_value: float
    boundary: bool

    @property
    def rejected(self) -> bool:
        """The simple model is rejected at :data:`LEVEL`."""
        return self.p_value < LEVEL

    def format(self) -> str:
        """One line for people."""
        word = "rejected" if self.rejected else "not rejected"
        return (
            f"{self.simple} within {self.complex}: Lambda = {self.statistic:.4g} "
            f"(df {self.df}{', boundary' if self.boundary else ''}), p = {self.p_value:.3g}: "
            f"{self.simple} {word}"
        )


def likelihood_ratio(simple: ModelFit, rich: ModelFit, boundary: bool = False) -> LikelihoodRatio:
    """``Lambda = chi2_simple - chi2_rich`` against ``chi^2_df`` (Wilks 1938; Self & Liang 1987)."""
    df = rich.n_params - simple.n_params
    lam = max(simple.chi2 - rich.chi2, 0.0)
    p = float(chi2_dist.sf(lam, df))
    if boundary:
        p = 0.5 * p if lam > 0 else 1.0
    return LikelihoodRatio(simple.model, rich.model, lam, df, p, boundary)


@dataclass(frozen=True)
class ModelComparison:
    """The fitted models, their ranking, the tests and the verdict.

    Attributes
    ----------
    fits : dict of str to ModelFit
    ranking : tuple of str
        Models by increasing BIC.
    delta_bic : dict of str to float
        BIC minus the best BIC.
    tests : tuple of LikelihoodRatio
    best : str
        The model the data support (lowest BIC; among ties the simplest).
    tied : tuple of str
        Models within :data:`BIC_TIE` of the best (the data cannot tell them apart).
    fit_p_value : float
        Probability of a ``chi2`` at least as large as the best model's under
        its noise (``chi^2_{n-k}``): small means no model reaches the noise.
    verdict : str
    extra : dict
        Other findings (e.g. the A-W part 2 consistency test), for documents.
    """

    fits: dict[str, ModelFit]
    ranking: tuple[str, ...]
    delta_bic: dict[str, float]
    tests: tuple[LikelihoodRatio, ...]
    best: str
    tied: tuple[str, ...]
    fit_p_value: float
    verdict: str
    extra: dict[str, object] = field(default_factory=dict)

    def summary(self) -> list[str]:
        """Lines for people: the table, the tests, the verdict."""
        rows = ["model         k      chi2       AIC       BIC   dBIC"]
        for name in self.ranking:
            f = self.fits[name]
            rows.append(
                f"{name:<12}{f.n_params:>3}{f.chi2:>10.1f}{f.aic:>10.1f}{f.bic:>10.1f}"
                f"{self.delta_bic[name]:>7.1f}"
            )
        rows += [t.format() for t in self.tests]
        rows.append(self.verdict)
        return rows

    def to_dict(self) -> dict[str, object]:
        """Plain dictionary (strict JSON: finite floats, lists)."""
        return {
            "ranking": list(self.ranking),
            "best": self.best,
            "tied": list(self.tied),
            "verdict": self.verdict,
            "fit_p_value": self.fit_p_value,
            "models": {
                name: {
                    "n_params": f.n_params,
                    "chi2": f.chi2,
                    "aic": f.aic,
                    "bic": f.bic,
                    "delta_bic": self.delta_bic[name],
                    "frequency_hz": (f.omega / (2 * np.pi)).tolist(),
                    "c_modal": f.c_modal.tolist(),
                    **{k: float(v) for k, v in f.extra.items()},
                    **{f"{k}_std": float(f.std[-1]) for k in f.extra},
                }
                for name, f in self.fits.items()
            },
            "tests": [
                {
                    "simple": t.simple,
                    "complex": t.complex,
                    "statistic": t.statistic,
                    "df": t.df,
                    "p_value": t.p_value,
                    "boundary": t.boundary,
                    "rejected": t.rejected,
                }
                for t in self.tests
            ],
            **self.extra,
        }


def _strength(d: float) -> str:
    """Kass & Raftery (1995, sec. 3.2) words for a BIC difference."""
    if d < BIC_TIE:
        return "not worth more than a bare mention"
    if d < 6:
        return "positive"
    if d < 10:
        return "strong"
    return "very strong"


def _verdict(
    fits: dict[str, ModelFit],
    ranking: tuple[str, ...],
    delta: dict[str, float],
    tied: tuple[str, ...],
    best: str,
    fit_p: float,
) -> str:
    if len(ranking) == 1:
        return f"only the {best} model was fitted: no comparison"
    others = [r for r in ranking if r not in tied]
    if len(tied) > 1:
        text = (
            f"the data cannot tell {', '.join(tied)} apart (BIC within {BIC_TIE:g}); "
            f"the simplest of them, {best}, is kept"
        )
    else:
        text = f"the data support the {best} model"
    if others:
        d = delta[others[0]] - delta[best]
        text += (
            f"; the next model, {others[0]}, is {d:.1f} BIC units worse "
            f"(evidence {_strength(d)}, likelihood ratio {np.exp(min(d, 1400) / 2):.3g})"
        )
    if fit_p < LEVEL:
        n = fits[best].n_data - fits[best].n_params
        text += (
            f"; but even the {best} model leaves residuals above the noise (chi2 "
            f"{fits[best].chi2:.0f} for {n} degrees of freedom): none of the models "
            "describes the data to within the noise (other modes in the band, a wrong "
            "noise level, or a damping law not in the list)"
        )
    return text


def compare_models(
    frequency: ArrayLike,
    H: ArrayLike,
    noise_std: ArrayLike,
    inputs: ArrayLike,
    start: ModalStart,
    models: Sequence[str] = MODELS,
) -> ModelComparison:
    """Fit each model and rank them (module docstring).

    Parameters
    ----------
    frequency, H, noise_std, inputs, start
        As :func:`tyredamp.dampmodels.frffit.fit_model`.
    models : sequence of str
        Models to compare (names in :data:`~tyredamp.dampmodels.frffit.MODELS`).

    Returns
    -------
    ModelComparison
    """
    names = list(dict.fromkeys(models))
    bad = [m for m in names if m not in MODELS]
    if bad or not names:
        raise InputError(
            f"models: expected names among {', '.join(MODELS)}, got {', '.join(bad) or 'none'}"
        )
    fits: dict[str, ModelFit] = {}
    for m in sorted(names, key=lambda m: m != "viscous"):  # viscous first: the warm start
        fits[m] = fit_model(m, frequency, H, noise_std, inputs, start, warm=fits.get("viscous"))
    fits = {m: fits[m] for m in names}
    bic = {m: f.bic for m, f in fits.items()}
    ranking = tuple(sorted(bic, key=lambda m: (bic[m], fits[m].n_params)))
    delta = {m: bic[m] - bic[ranking[0]] for m in ranking}
    tied_all = [m for m in ranking if delta[m] < BIC_TIE]
    best = min(tied_all, key=lambda m: (fits[m].n_params, delta[m]))
    tied = tuple(tied_all)
    tests = tuple(
        likelihood_ratio(fits[a], fits[b], boundary)
        for a, b, boundary in NESTED
        if a in fits and b in fits
    )
    fb = fits[best]
    fit_p = float(chi2_dist.sf(fb.chi2, max(fb.n_data - fb.n_params, 1)))
    verdict = _verdict(fits, ranking, delta, tied, best, fit_p)
    return ModelComparison(fits, ranking, delta, tests, best, tied, fit_p, verdict)
