"""Ranking lateral models fitted to the same data and weights by AIC/BIC.

The information criteria are those of :mod:`.fit` (Gaussian likelihood of the
complex residuals); differences are read on the Kass & Raftery (1995) scale.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..exceptions import ConvergenceError, InputError
from ..frf import FRF
from .fit import DEFAULT_MODELS, Criterion, LateralData, LateralFit, fit_models_on
from .models import LateralModel, get_model_class

__all__ = ["Ranking", "rank_models"]


def _evidence(delta: float) -> str:
    # Kass & Raftery (1995) scale for BIC differences (also used for AIC here).
    if delta < 2:
        return "not distinguishable from the best"
    if delta < 6:
        return "positive evidence against it"
    if delta < 10:
        return "strong evidence against it"
    return "very strong evidence against it"


@dataclass(frozen=True, eq=False)
class Ranking:
    """Models fitted to the same data and weights, best first.

    Attributes
    ----------
    fits : tuple of LateralFit
        Sorted by the criterion (lowest first).
    criterion : {"bic", "aic"}
    delta : tuple of float
        Criterion minus the best one's.
    weight : tuple of float
        ``exp(-delta/2)`` normalised (Akaike or Schwarz weights).
    reasons : tuple of str
        One sentence per model explaining its place.
    """

    fits: tuple[LateralFit, ...]
    criterion: Criterion
    delta: tuple[float, ...]
    weight: tuple[float, ...]
    reasons: tuple[str, ...] = field(default_factory=tuple)

    @property
    def best(self) -> LateralFit:
        """The best fit."""
        return self.fits[0]

    def check(self) -> None:
        """Raise :class:`ConvergenceError` when no model fits the data (a verdict, not a rank).

        A fit fails when :meth:`LateralFit.problems` finds anything (a parameter at
        the bound of the search, a parameter the data do not determine, ``f0``
        a decade or more outside the fitted band). Ranking models that all fail says nothing.

        Raises
        ------
        ConvergenceError
            Every model failed; the message gives the best model's reasons.
        """
        if any(not f.problems() for f in self.fits):
            return
        why = "; ".join(self.best.problems())
        raise ConvergenceError(
            f"no model fits the data ({len(self.fits)} tried; best by "
            f"{self.criterion.upper()}: {why})"
        )

    @property
    def order(self) -> tuple[str, ...]:
        """Model names, best first."""
        return tuple(f.name for f in self.fits)

    def rows(self) -> list[dict[str, Any]]:
        """One dict per model: rank, name, P, RSS, AIC, BIC, delta, weight, errors (%)."""
        return [
            {
                "rank": i + 1,
                "model": f.name,
                "n_params": f.n_params,
                "rss": f.rss,
                "aic": f.aic,
                "bic": f.bic,
                "delta": self.delta[i],
                "weight": self.weight[i],
                "amplitude_error_pct": 100.0 * f.amplitude_error,
                "amplitude_bias_pct": 100.0 * f.amplitude_bias,
            }
            for i, f in enumerate(self.fits)
        ]

    def format_table(self) -> str:
        """Plain aligned text table of :meth:`rows` followed by the reasons."""
        crit = self.criterion.upper()
        head = (
            f"{'rank':>4}  {'model':<13} {'P':>2} {'AIC':>10} {'BIC':>10} "
            f"{'d' + crit:>8} {'weight':>7} {'amp.err %':>9} {'bias %':>7}"
        )
        lines = [head, "-" * len(head)]
        for r in self.rows():
            lines.append(
                f"{r['rank']:>4}  {r['model']:<13} {r['n_params']:>2} {r['aic']:>10.1f} "
                f"{r['bic']:>10.1f} {r['delta']:>8.1f} {r['weight']:>7.3f} "
                f"{r['amplitude_error_pct']:>9.2f} {r['amplitude_bias_pct']:>+7.2f}"
            )
        return "\n".join([*lines, "", *list(self.reasons)])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: criterion, order, rows, reasons and every fit's summary."""
        return {
            "criterion": self.criterion,
            "order": list(self.order),
            "table": self.rows(),
            "reasons": list(self.reasons),
            "fits": [f.to_dict() for f in self.fits],
        }


def _rank(fits: Sequence[LateralFit], criterion: Criterion) -> Ranking:
    if criterion not in ("aic", "bic"):
        raise InputError(f"criterion: expected 'aic' or 'bic', got {criterion!r}")
    ordered = sorted(fits, key=lambda f: f.criterion(criterion))
    vals = np.array([f.criterion(criterion) for f in ordered])
    delta = vals - vals[0]
    wt = np.exp(-0.5 * delta)
    wt = wt / wt.sum()
    crit = criterion.upper()
    reasons = []
    for i, f in enumerate(ordered):
        over = "over" if f.amplitude_bias > 0 else "under"
        tail = (
            f"{f.n_params} parameters; amplitude error {100 * f.amplitude_error:.1f} % "
            f"({over}-estimates by {100 * abs(f.amplitude_bias):.1f} % on average); "
            f"rms weighted residual {f.residual_rms:.3g}"
        )
        if i == 0:
            nxt = (
                f"; next {ordered[1].name} at d{crit} = {delta[1]:.1f}" if len(ordered) > 1 else ""
            )
            reasons.append(f"1. {f.name}: lowest {crit}{nxt}; {tail}.")
        else:
            reasons.append(
                f"{i + 1}. {f.name}: d{crit} = {delta[i]:.1f}, {_evidence(delta[i])}; {tail}."
            )
    return Ranking(
        tuple(ordered),
        criterion,
        tuple(float(x) for x in delta),
        tuple(float(x) for x in wt),
        tuple(reasons),
    )


def rank_models(
    data: LateralData | FRF,
    models: Sequence[str | type[LateralModel]] = DEFAULT_MODELS,
    *,
    criterion: Criterion = "bic",
    **fit_kwargs: Any,
) -> Ranking:
    """Fit several models to the same data and weights and rank them.

    Parameters
    ----------
    data : LateralData or FRF
        The measurement.
    models : sequence of str or LateralModel subclass
        Models to compare; default the paper's four (:data:`DEFAULT_MODELS`).
    criterion : {"bic", "aic"}
        Ranking criterion (lower is better); BIC penalises extra parameters
        more for the usual hundreds of lines.
    **fit_kwargs
        Passed to :func:`fit_model` (``speed``, ``force``, ``wheel_mass``,
        ``band``, ``weights`` ...). ``start`` is not allowed.

    Returns
    -------
    Ranking
    """
    if "start" in fit_kwargs:
        raise InputError("start: not allowed in rank_models (each model finds its own)")
    if not models:
        raise InputError("models: expected at least one model")
    names = [get_model_class(m).name for m in models]
    if len(set(names)) != len(names):
        raise InputError(f"models: duplicated entries in {names}")
    fits = fit_models_on(data, models, **fit_kwargs)  # the lines prepared once
    return _rank(fits, criterion)


# -------------------------------------------------------------------------------- joint fit
