"""Verdicts of the lateral models fitted to one measured FRF.

Each fit is tested against the noise of the FRF it was fitted to, as the
modal fits are (:mod:`.verdicts`: the F test of the residual power against
the noise its coherence implies, or against the noise floor of adjacent
lines without coherence). A miss is then classified by the other models of
the same FRF: another model within the noise makes it a result of the model
comparison (the model's form does not hold the tyre), every converged model
missing makes the tyre one outside the model family; a fit that did not
converge, or a model fitted alone, keeps the outcome "failed".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..frf import FRF
from .noise_tests import _MIN_LINES, ALPHA, floor_test, frf_noise_variance, noise_test
from .verdicts import CAUSE_MODEL_FORM, CAUSE_OUTSIDE_FAMILY, FitVerdict, _p

__all__ = ["lateral_family_verdicts", "lateral_fit_verdict"]


def lateral_fit_verdict(
    fit: Any, frf: FRF, *, subject: str = "", alpha: float = ALPHA
) -> FitVerdict:
    """Verdict on a lateral model fitted to the FRF ``frf`` (:mod:`.verdicts`).

    Parameters
    ----------
    fit : LateralFit
        Its ``frequency``, ``measured`` and ``fitted`` (accelerance at the
        data's force) are tested.
    frf : FRF
        The measured FRF the fit was made on (1x1; without coherence the fit is
        judged against the noise floor of adjacent lines, :func:`floor_test`).
    """
    name = subject or f"{fit.name} fit"
    noise = frf_noise_variance(frf)
    cautions: list[str] = []
    if noise is None:
        if np.size(fit.frequency) < _MIN_LINES:
            return FitVerdict(
                name,
                "not judged",
                cautions=(
                    f"no coherence and only {np.size(fit.frequency)} line(s): too few to "
                    "judge against the noise",
                ),
            )
        # no coherence: the noise floor of adjacent lines (:mod:`.verdicts`)
        test, _, cautions = floor_test(fit.frequency, fit.measured, fit.fitted, alpha)
        cautions.insert(
            0,
            "no coherence: judged against the noise floor of the data themselves "
            "(differences of adjacent lines) and the structure of the residual across lines",
        )
    else:
        keep = np.flatnonzero(np.isin(frf.frequency, fit.frequency))
        if keep.size != fit.frequency.size:
            raise InputError("frf: does not hold every line of the fit")
        acc = frf.to("accelerance").H[0, 0, keep]
        rel_var = noise[0][0, 0, keep] / np.abs(frf.H[0, 0, keep]) ** 2
        var = rel_var * np.abs(acc) ** 2
        test = noise_test(fit.frequency, fit.measured, fit.fitted, var, noise[1], alpha)
    reasons: list[str] = []
    if not test.passed:
        floor = "" if test.noise_from == "coherence" else " floor of adjacent lines"
        reasons.append(
            f"the residual is {math.sqrt(test.ratio):.3g}x the noise{floor} level "
            f"({_p(test.p_value)})"
        )
        where = (
            ""
            if test.misfit_hz is None
            else f" at {test.misfit_hz[0]:.3g}-{test.misfit_hz[1]:.3g} Hz"
        )
        reasons.append(
            f"the model form misses the measured tyre{where} (noise does not explain it)"
        )
    return FitVerdict(
        name, "ok" if not reasons else "failed", tuple(reasons), tuple(cautions), test
    )


def _converged(fit: Any) -> bool:
    """True when the lateral fit's optimiser ran and did not stop on its evaluation limit."""
    return (
        int(getattr(fit, "nfev", 1)) > 0
        and "maximum" not in str(getattr(fit, "message", "")).lower()
    )


def lateral_family_verdicts(
    fits: Sequence[Any], frf: FRF, *, label: str = "", alpha: float = ALPHA
) -> dict[str, FitVerdict]:
    """Verdicts of every lateral model fitted to one FRF, a miss classified by the others.

    Each fit is judged alone (:func:`lateral_fit_verdict`); a fit that misses
    the noise is then an *expected* outcome (:mod:`.verdicts`) when

    * another model of the same FRF is within the noise: this model's form
      does not hold the tyre (``"model form"``), or
    * every one of two or more models misses and every fit converged: the
      measured tyre is none of the models, and the ranking names the closest
      (``"tyre outside the model family"``).

    A fit whose optimiser did not converge, and a single model fitted alone,
    keep the outcome ``"failed"``.

    Parameters
    ----------
    fits : sequence of LateralFit
        The fits of one FRF (one per model).
    frf : FRF
        The measured FRF they were fitted to (1x1, with coherence).
    label : str
        Condition label for the subjects (``"hysteretic fit at 1.7 bar, 5 km/h"``).
    alpha : float
        Significance level of the test against the noise.

    Returns
    -------
    dict of str to FitVerdict
        By model name, in the order of ``fits``.
    """
    at = f" at {label}" if label else ""
    out = {
        f.name: lateral_fit_verdict(f, frf, subject=f"{f.name} fit{at}", alpha=alpha) for f in fits
    }
    conv = {f.name: _converged(f) for f in fits}
    within = [n for n, v in out.items() if v.status == "ok"]
    missed = [n for n, v in out.items() if v.status == "failed"]
    if within:
        names = ", ".join(within)
        for n in missed:
            if conv[n]:
                out[n] = replace(
                    out[n],
                    expected_cause=CAUSE_MODEL_FORM,
                    expected_why=(
                        f"the {names} fit{'s' if len(within) > 1 else ''} of the same FRF "
                        f"{'are' if len(within) > 1 else 'is'} within the noise, so this "
                        "model's form does not hold the measured tyre: a result of the model "
                        "comparison, not a failure of the fit"
                    ),
                )
    elif len(fits) >= 2 and len(missed) == len(fits) and all(conv.values()):
        r = [math.sqrt(v.test.ratio) for v in out.values() if v.test is not None]
        why = (
            f"none of the {len(fits)} models fitted holds the measured tyre within the noise "
            f"(residuals {min(r):.3g}-{max(r):.3g}x the noise) although every fit converged: "
            "the tyre is none of these models, and the ranking names the closest: a result "
            "of the model comparison, not a failure of the fit"
        )
        for n in missed:
            out[n] = replace(out[n], expected_cause=CAUSE_OUTSIDE_FAMILY, expected_why=why)
    return out
