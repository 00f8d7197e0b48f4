"""Fit verdicts: does an identified model fit its FRF to within the noise, and if not, why.

The verdict judges a fit from the data alone:

* **against the noise.** The variance of an FRF estimate follows from its
  coherence: for an H1 estimate from ``n_d`` averages of a periodic force
  with noise on the response, ``var(H) = |H|^2 (1 - g^2) / (n_d g^2)``
  (the random error of frequency-response estimates, Bendat & Piersol,
  *Random Data*, ch. 9, for the complex value). The estimated coherence is
  biased upwards, ``E[1 - g_est^2] ~ (1 - g^2)(n_d - 1)/n_d``, so the
  variance is taken as ``|H|^2 (1 - g_est^2) / ((n_d - 1) g_est^2)``
  (``n_d`` from ``frf.meta["n_averages"]``). With a new random force in
  every average the variance of H1 is larger, ``|H|^2 (1 - g^2) /
  ((n_d - 1) g^2)`` (the mean inverse force spectrum), and the same formula
  holds again: for a periodic and a random force alike the mean of the
  statistic ``q`` below is 1 (``tests/test_studies_verdicts.py``,
  ``benchmarks/verdict_calibration.py``).

  With ``m > 1`` inputs (``g^2`` the multiple coherence of an output) the
  inputs are taken as uncorrelated and of equal power, so ``|H|^2`` becomes
  ``sum_j |H_oj|^2``, and the factor ``1/(n_d - 1)`` becomes
  ``n_d / (n_d - m)^2`` (mean inverse spectrum ``1/(n_d - m)`` of random
  forces, coherence bias ``(n_d - m)/n_d``). The line-to-line scatter of the
  forces' spectra makes this approximate, on the side of more noise (mean
  ``q`` 0.9-1.0 for two inputs and 8-32 averages): a MIMO verdict is
  conservative. An FRF without a number of averages (the virtual
  rolling-tyre rig) carries the coherence of the estimate itself:
  ``var(H) = |H|^2 (1 - g^2) / g^2``.

  The statistic is ``q = sum |H_model - H|^2 / sum var(H)`` over the fitted
  lines and FRFs: about 1 when the model leaves only noise. Under that
  hypothesis ``sum |e|^2`` is a weighted sum of chi-square variables with
  ``nu = 2 (sum var)^2 / sum var^2`` effective degrees of freedom
  (Satterthwaite), and the variance estimated from ``n_d`` averages has
  ``(n_d - m) nu``; ``q`` is then F-distributed, and the fit is *within the
  noise* when ``q`` is below the ``1 - alpha`` quantile (``alpha = 1e-3``).
  Without averages the chi-square quantile ``chi2(nu) / nu`` is used.
  Fitted parameters only lower ``q``, so the test is conservative.
* **where it misses.** The lines holding the central 80 % of the excess
  residual ``(|e|^2 - var)+`` give the misfit region; when it reaches a band
  edge the likely cause is a mode at or beyond that edge.
* **the modes** (modal fits): a mode whose half-power band ``f (1 +- 2 zeta)``
  crosses a band edge; a strongly complex shape (modal phase collinearity
  below 0.5, the conventional mark of a spurious or distorted mode unless
  the damping is strongly non-proportional); expected modes (when the
  caller knows them, for example the truth of a virtual tyre) that are not
  identified.

* **without coherence** (an impact-test FRF exported alone): the noise is
  estimated from the data themselves, from differences of adjacent lines
  (as :func:`tyredamp.modal.statistics.stats.difference_noise`, but fourth differences
  ``d_f = H_{f-2} - 4 H_{f-1} + 6 H_f - 4 H_{f+1} + H_{f+2}``, which cancel a
  cubic trend, with ``E|d|^2 = 70 s^2`` for white noise of variance ``s^2``),
  as a running median over 21 lines of each FRF (``median |d|^2 = 70 s^2
  ln 2``), so noise that varies along the band is followed and the few lines
  where a sharp peak curves the FRF are ignored. The residual is
  tested against that floor as above (F quantile, with the floor's own
  degrees of freedom taken as ``ln(2)^2 / 4`` of the residual's: a median
  of correlated differences), and its structure is measured by the correlation
  of adjacent lines of the residual (``r``, about 0 with ``sd 1/sqrt(2 N)``
  for white noise over ``N`` pairs), or by lines that stand out of the floor
  (a mode sharper than the line spacing). The floor is an upper bound where the
  FRF curves at most lines and a lower one when the noise is itself
  correlated across lines (a window): a residual above the floor *and*
  structured is a failed fit, with where it misses and the rejected
  candidates there; above the floor but white, it is judged within the
  noise with a caution. When the modal fit widened its noise by a model
  error (``ModalIdentification.model_error``: it left structure beyond the
  floor), the verdict tests against the floor alone and says so.

A verdict's ``status`` is ``"ok"`` (within the noise), ``"failed"`` (with
the reasons and likely causes) or ``"not judged"`` (too few lines, or no
noise that the data or their coherence give). Its ``outcome`` says what a miss
means, from the verdict's own cause:

* ``"expected"``: the miss is an identification result, not a failure of the
  fit, because another model of the same data shows where it comes from.
  A real-mode fit that misses while the complex-mode fit of the same band is
  within the noise: the data are non-proportional (the damping couples the
  modes), which real modes cannot hold; the complex-mode model is the general
  form of a linear viscously damped structure, so nothing else explains the
  gap. A lateral model that misses while another model of the family holds
  the tyre (its form does not), or while every model of the family misses
  although each fit converged (the measured tyre is none of the models: the
  ranking names the closest, :func:`lateral_family_verdicts`).
* ``"failed"``: a fit that should hold and does not (the complex-mode fit
  outside its noise, an expected mode not found, a lateral fit whose optimiser
  did not converge, or the only model fitted), with its reasons;
* ``"ok"`` and ``"not judged"`` as the status.

Core-free of plotting and I/O: the report, the CLI summary and results.json
render :class:`FitVerdict`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ..frf import FRF, FRFKind
from ..modal.identify import ModalIdentification
from .noise_tests import (
    _MIN_LINES,
    ALPHA,
    BLOCK_LINES,
    NoiseTest,
    _fitted_span,
    _num,
    adjacent_line_variance,
    floor_test,
    floor_test_blocks,
    frf_noise_variance,
    noise_test,
    noise_test_blocks,
    residual_correlation,
)

__all__ = [
    "ALPHA",
    "CAUSE_MEANING",
    "CAUSE_MODEL_FORM",
    "CAUSE_NON_PROPORTIONAL",
    "CAUSE_OUTSIDE_FAMILY",
    "FitVerdict",
    "NoiseTest",
    "adjacent_line_variance",
    "floor_test",
    "frf_noise_variance",
    "modal_fit_verdict",
    "modal_verdicts",
    "noise_test",
    "residual_correlation",
]

#: Modal phase collinearity below which a shape is called strongly complex.
_MPC_LOW = 0.5

Status = Literal["ok", "failed", "not judged"]
Outcome = Literal["ok", "expected", "failed", "not judged"]

#: Short causes of an expected miss (``FitVerdict.expected_cause``).
CAUSE_NON_PROPORTIONAL = "non-proportional damping"
CAUSE_MODEL_FORM = "model form"
CAUSE_OUTSIDE_FAMILY = "tyre outside the model family"
#: What an expected miss of each cause means, said once for every fit it concerns.
CAUSE_MEANING = {
    CAUSE_NON_PROPORTIONAL: "the complex-mode fit of the same band is within the noise, so the "
    "damping couples the modes, which real modes cannot hold: an identification result (the "
    "data are non-proportionally damped), not a failure of the fit",
    CAUSE_MODEL_FORM: "another model of the same data is within the noise, so this model's form "
    "cannot hold the data: a result of the model comparison, not a failure of the fit",
    CAUSE_OUTSIDE_FAMILY: "every model fitted misses the measured tyre although every fit "
    "converged: the tyre is none of these models, and the ranking names the closest: a result "
    "of the model comparison, not a failure of the fit",
}


@dataclass(frozen=True)
class FitVerdict:
    """Verdict on one fit.

    Attributes
    ----------
    subject : str
        What was fitted (``"radial 9 bar, complex-mode fit"``).
    status : {"ok", "failed", "not judged"}
    reasons : tuple of str
        Why it failed, each with its likely cause and remedy.
    cautions : tuple of str
        Findings that do not fail the fit but qualify it.
    test : NoiseTest or None
        The test against the noise (None without coherence).
    expected_cause : str
        For a miss that is an identification result rather than a failure
        (module docstring), its short cause (``"non-proportional damping"``);
        empty otherwise.
    expected_why : str
        Why that miss is expected, in words; empty otherwise.
    """

    subject: str
    status: Status
    reasons: tuple[str, ...] = ()
    cautions: tuple[str, ...] = ()
    test: NoiseTest | None = None
    expected_cause: str = ""
    expected_why: str = ""

    @property
    def passed(self) -> bool:
        """True for ``"ok"``: the fit is within the noise."""
        return self.status == "ok"

    @property
    def outcome(self) -> Outcome:
        """``"ok"``, ``"expected"`` (a miss explained by the data), ``"failed"`` or
        ``"not judged"`` (module docstring)."""
        if self.status == "failed" and self.expected_cause:
            return "expected"
        return self.status

    @property
    def outcome_reason(self) -> str:
        """Why the outcome: the expected miss's cause, the failure's reasons, or the
        residual of a fit within the noise."""
        t = self.test
        if self.outcome == "expected":
            return f"{self.expected_cause}: {self.expected_why}"
        if self.outcome == "failed":
            return "; ".join(self.reasons)
        if self.outcome == "ok" and t is not None:
            return f"residual {math.sqrt(t.ratio):.3g}x the noise level"
        return self.cautions[0] if self.cautions else ""

    def summary(self) -> str:
        """One line: outcome, the residual against the noise, the reasons."""
        t = self.test
        if self.outcome == "expected":
            # the reasons without the model-form one, which the explanation replaces
            rs = [r for r in self.reasons if "model form misses" not in r]
            text = "; ".join(rs)
            return (
                f"{self.subject}: not within the noise, as the data explain "
                f"({self.expected_cause}): {self.expected_why}"
                + (f". {text[0].upper()}{text[1:]}" if text else "")
            )
        head = {"ok": "OK", "failed": "FAILED", "not judged": "NOT JUDGED"}[self.status]
        if self.reasons:
            return f"{self.subject}: {head}: " + "; ".join(self.reasons)
        if t is not None:
            what = (
                "the noise"
                if t.noise_from == "coherence"
                else "the noise floor of adjacent lines (no coherence)"
            )
            return (
                f"{self.subject}: {head}: within {what} (residual {math.sqrt(t.ratio):.3g}x "
                f"the noise level; relative error {100 * t.relative_error:.3g} % against "
                f"{100 * t.noise_relative_error:.3g} % from noise alone)"
            )
        return f"{self.subject}: {head}" + (f": {self.cautions[0]}" if self.cautions else "")

    def brief(self) -> str:
        """A short form for a summary table: ``"FAILED (residual 11x the noise): <cause>"``,
        ``"expected (residual 11x the noise): non-proportional damping"``."""
        t = self.test
        if self.status == "ok":
            return "within noise"
        if self.status == "not judged":
            return "not judged" + (f" ({self.cautions[0]})" if self.cautions else "")
        size = "" if t is None else f" (residual {math.sqrt(t.ratio):.3g}x the noise)"
        if self.outcome == "expected":
            return f"expected{size}: {self.expected_cause}"
        causes = [r for r in self.reasons if not r.startswith("the residual is")]
        return f"FAILED{size}: " + ("; ".join(causes) or "see the report")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (results.json ``verdict`` objects)."""
        t = self.test
        return {
            "subject": self.subject,
            "status": self.status,
            "passed": self.passed,
            "outcome": self.outcome,
            "outcome_reason": self.outcome_reason,
            "expected_cause": self.expected_cause,
            "summary": self.summary(),
            "brief": self.brief(),
            "reasons": list(self.reasons),
            "cautions": list(self.cautions),
            "residual_to_noise": None if t is None else t.ratio,
            "threshold": None if t is None else t.threshold,
            "p_value": None if t is None else t.p_value,
            "relative_error": None if t is None else t.relative_error,
            "noise_relative_error": None if t is None else t.noise_relative_error,
            "misfit_hz": None if t is None or t.misfit_hz is None else list(t.misfit_hz),
            "noise_from": None if t is None else t.noise_from,
            "residual_correlation": None if t is None else _num(t.correlation),
        }


# ------------------------------------------------------------------------------- the test


def _p(p: float) -> str:
    return "p < 1e-300" if p <= 0 else f"p = {p:.2g}"


def _edge_reason(t: NoiseTest, band: tuple[float, float]) -> str | None:
    """The likely cause when the misfit region reaches a band edge."""
    if t.misfit_hz is None:
        return None
    lo, hi = band
    near = 0.05 * (hi - lo)
    a, b = t.misfit_hz
    where = f"{a:.4g}-{b:.4g} Hz"
    if b >= hi - near:
        return (
            f"the misfit lies at the upper band edge ({where}): a mode at or just above "
            f"{hi:g} Hz is missing or cut by the edge; widen or narrow the band"
        )
    if a <= lo + near:
        return (
            f"the misfit lies at the lower band edge ({where}): a mode at or just below "
            f"{lo:g} Hz is missing or cut by the edge; widen or narrow the band"
        )
    return None


# ----------------------------------------------------------------------------- the verdicts
def modal_fit_verdict(
    model: Any,
    measured: FRF,
    *,
    subject: str = "modal fit",
    expected_hz: Sequence[float] | None = None,
    better: FitVerdict | None = None,
    alpha: float = ALPHA,
    model_error: float = 0.0,
    lines: slice | None = None,
    kind: FRFKind | None = None,
    block: int = BLOCK_LINES,
) -> FitVerdict:
    """Verdict on a modal model fitted to ``measured`` (module docstring).

    Parameters
    ----------
    model : ModalModel
        The fit (its ``meta["band_hz"]``, ``meta["mpc"]`` are used when present).
    measured : FRF
        The measured FRF on the fitted lines (with coherence to judge against
        the noise).
    subject : str
        Name of the fit in the messages.
    expected_hz : sequence of float, optional
        Natural frequencies that should be found (the truth of a virtual
        test); those in the band without an identified mode within 5 % are
        reported.
    better : FitVerdict, optional
        Verdict of another model of the same data (the complex-mode fit for a
        real-mode one): when it is within the noise and this one is not, the
        likely cause is the model form (non-proportional damping), and a
        misfit at a band edge is not put down to a mode missing there.
    alpha : float
        Significance level of the test against the noise.
    model_error : float
        Relative model error the identification included in its noise
        (``ModalIdentification.model_error``; 0: none): said in the verdict,
        which tests against the noise without it.
    lines : slice, optional
        The lines of ``measured`` the model was fitted on (default: every line).
    kind : {"receptance", "mobility", "accelerance"}, optional
        The kind of FRF the model was fitted to (default ``measured.kind``):
        ``measured`` is converted block by block (a 0 Hz line, which a
        conversion that divides by the frequency drops, must not be in ``lines``).
    block : int
        Lines per block of the statistics (:func:`floor_test_blocks`,
        :func:`noise_test_blocks`): the memory they take beyond the data does
        not grow with the lines but for 8-16 bytes per line.
    """
    span = slice(0, measured.n_freq) if lines is None else lines
    lo, hi, _ = span.indices(measured.n_freq)
    f = measured.frequency[lo:hi]
    band_meta = model.meta.get("band_hz")
    band = (
        (float(band_meta[0]), float(band_meta[1]))
        if band_meta is not None
        else (float(f[0]), float(f[-1]))
    )
    to = kind or measured.kind

    def part(a: int, b: int) -> FRF:  # the measured lines [a, b) of the fit, as fitted
        p = measured.select_lines(slice(lo + a, lo + b))
        return p if p.kind == to else p.to(to)

    reasons: list[str] = []
    cautions: list[str] = []
    noise = frf_noise_variance(part(0, 1))
    test = None
    form = False
    excess: NDArray[np.float64] | None = None
    if noise is not None:

        def with_noise(a: int, b: int) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any]]:
            p = part(a, b)
            return p.H, model.frf(p.frequency, to).H, frf_noise_variance(p)[0]  # type: ignore[index]

        test, excess = noise_test_blocks(f, with_noise, noise[1], alpha, block)
    elif f.size >= _MIN_LINES:
        test, excess, notes = floor_test_blocks(
            f, lambda a, b: part(a, b).H, lambda a, b: model.frf(f[a:b], to).H, alpha, block
        )
        cautions += notes
    if test is not None and not test.passed:
        # another model of the same band within the noise refutes a missing mode
        # at an edge: the misfit is this model's form
        form = better is not None and better.passed
        reasons += _misfit_reasons(
            test, model, f, band, excess, model_error, better if form else None
        )
    fn = np.asarray(model.frequency_hz, dtype=float)
    cautions += _shape_cautions(model, band)
    lost = _missing_expected(fn, band, expected_hz)
    reasons += lost
    status: Status = (
        ("failed" if reasons else "not judged")
        if test is None
        else ("ok" if not reasons else "failed")
    )
    cautions = _noise_cautions(test, status, f.size, model_error) + cautions
    cause = why = ""
    # a miss that only the model form explains (no expected mode lost) is a result
    if status == "failed" and form and better is not None and not lost:
        cause, why = _form_cause(model, better)
    return FitVerdict(subject, status, tuple(reasons), tuple(cautions), test, cause, why)


def _misfit_reasons(
    test: NoiseTest,
    model: Any,
    f: NDArray[np.float64],
    band: tuple[float, float],
    excess: NDArray[np.float64] | None,
    model_error: float,
    better: FitVerdict | None,
) -> list[str]:
    """Why a fit that failed its test against the noise failed (``better``: another
    model of the same data within the noise, so the misfit is this model's form)."""
    source = (
        "from the coherence"
        if test.noise_from == "coherence"
        else "from the noise floor of adjacent lines (no coherence)"
    )
    shape = ""
    if test.structured and math.isinf(test.correlation_z):
        shape = ", concentrated on a few lines"
    elif test.structured:
        shape = (
            f", structured across lines (correlation of adjacent lines "
            f"{test.correlation:.2f}, {test.correlation_z:.3g} standard deviations "
            "of white noise)"
        )
    reasons = [
        f"the residual is {math.sqrt(test.ratio):.3g}x the noise level (relative error "
        f"{100 * test.relative_error:.3g} % against {100 * test.noise_relative_error:.3g}"
        f" % {source}; {_p(test.p_value)}){shape}"
    ]
    if model_error > 0:
        reasons.append(
            f"the identification widened its noise by a model error of "
            f"{100 * model_error:.3g} % of the response because the fit left this "
            "structure (leakage, a window, a non-linearity, or a mode it did not "
            "keep); its modes and their errors are stated against that wider noise"
        )
    edge = None if better is not None else _edge_reason(test, band)
    if edge:
        reasons.append(edge)
    elif test.misfit_hz is not None:
        reasons.append(f"the misfit lies at {test.misfit_hz[0]:.4g}-{test.misfit_hz[1]:.4g} Hz")
    there = "" if excess is None else _rejected_in(model, f, excess)
    if there and better is None:
        reasons.append(there)
    if any(
        str(w).startswith("real-mode refinement not acceptable")
        for w in model.meta.get("warnings", [])
    ):
        reasons.append(
            "its refinement fell back to the complex-mode poles (only the residues are fitted)"
        )
    if better is not None:
        reasons.append(
            f"the {better.subject} is within the noise: the model form misses (real "
            "modes cannot hold damping that couples the modes)"
        )
    return reasons


def _shape_cautions(model: Any, band: tuple[float, float]) -> list[str]:
    """Cautions on the modes themselves: a half-power band across an edge, resonances
    held by residual terms inside the band, strongly complex shapes."""
    out: list[str] = []
    fn = np.asarray(model.frequency_hz, dtype=float)
    zeta = np.asarray(model.damping_ratio, dtype=float)
    for k in range(fn.size):
        half = 2.0 * zeta[k] * fn[k]
        if (band[0] > 0 and fn[k] - half < band[0]) or fn[k] + half > band[1]:
            out.append(
                f"mode at {fn[k]:.4g} Hz: its half-power band ({fn[k] - half:.4g}-"
                f"{fn[k] + half:.4g} Hz) crosses the band edge; its damping is poorly "
                "determined: widen the band"
            )
    held = getattr(model, "residual_modes", None)
    if held is not None and int(getattr(held, "n_modes", 0)) > 0:
        inside = [x for x in np.asarray(held.frequency_hz, float) if band[0] <= x <= band[1]]
        if inside:
            at = ", ".join(f"{x:.4g}" for x in inside)
            out.append(
                f"the fit holds {len(inside)} resonance(s) inside the band at {at} Hz with "
                "residual terms, not listed as modes: their frequency and damping are not "
                "identified"
            )
    mpc = model.meta.get("mpc")
    if mpc is not None and model.mode_kind == "complex":
        for k, v in enumerate(np.asarray(mpc, dtype=float)):
            if v < _MPC_LOW:
                out.append(
                    f"mode at {fn[k]:.4g} Hz: MPC {v:.2f}, a strongly complex shape: a "
                    "spurious or distorted mode unless the damping is strongly non-proportional"
                )
    return out


def _missing_expected(
    fn: NDArray[np.float64], band: tuple[float, float], expected_hz: Sequence[float] | None
) -> list[str]:
    """The expected modes in the band without an identified mode within 5 %."""
    out: list[str] = []
    for fe in expected_hz or ():
        if not band[0] <= fe <= band[1]:
            continue
        if fn.size == 0 or np.min(np.abs(fn - fe)) > 0.05 * fe:
            gap = min(fe - band[0], band[1] - fe)
            at_edge = gap < 0.05 * (band[1] - band[0])
            out.append(
                f"expected mode at {fe:.4g} Hz not identified"
                + (f" ({gap:.3g} Hz from the band edge)" if at_edge else "")
            )
    return out


def _noise_cautions(
    test: NoiseTest | None, status: str, n_lines: int, model_error: float
) -> list[str]:
    """What the verdict's noise was (first among the cautions)."""
    if test is None:
        if status == "failed":
            return []
        return [
            f"no coherence (or a single average) and only {n_lines} line(s): too few to "
            "judge against the noise"
        ]
    out: list[str] = []
    if test.noise_from != "coherence":
        out.append(
            "no coherence (or a single average): judged against the noise floor of the "
            "data themselves (differences of adjacent lines, a running median) and the "
            "structure of the residual across lines"
        )
        if status == "failed":
            out.append(
                "that floor takes the noise as uncorrelated across lines; a window (an "
                "exponential or force window) correlates it and lowers the floor, so a "
                "residual a few times the floor may be that: a measured coherence decides"
            )
    if model_error > 0 and status == "ok":
        out.append(
            f"the identification stated its modes against a noise that includes a model "
            f"error of {100 * model_error:.3g} % of the response; this verdict judged "
            "the fit against the noise without it"
        )
    return out


def _rejected_in(model: Any, f: NDArray[np.float64], excess: NDArray[np.float64]) -> str:
    """The candidates the identification rejected where the excess residual per line
    ``excess`` (``(|e|^2 - var)+`` summed over the FRFs, shape (n_freq,)) concentrates:
    at least a fifth of it within two half-power bandwidths (at least 1.5 line
    spacings, at most a twentieth of the band) of the candidate. The likely cause of
    the miss, with why each was rejected."""
    q = getattr(model, "quality", None)
    if q is None or not q.rejected or f.size < 2:
        return ""
    from ..modal.statistics.quality import short_reason, strongest_rejected

    ex = excess
    total = float(ex.sum())
    if not total > 0:
        return ""
    df = float(np.median(np.diff(f)))
    seen: dict[str, tuple[float, str]] = {}
    for r in strongest_rejected(q.rejected):
        w = max(4.0 * r.damping_ratio * r.frequency_hz, 1.5 * df)
        if 2.0 * w > 0.1 * (f[-1] - f[0]):
            continue  # too broad to place a misfit
        share = float(ex[np.abs(f - r.frequency_hz) <= w].sum()) / total
        key = f"{r.frequency_hz:.2f} Hz"
        if share >= 0.2 and key not in seen:
            seen[key] = (share, short_reason(r))
    if not seen:
        return ""
    items = sorted(seen.items(), key=lambda kv: -kv[1][0])[:3]
    return "the identification rejected a candidate where the misfit lies: " + "; ".join(
        f"{k} ({w}; {100 * sh:.0f} % of the excess residual)" for k, (sh, w) in items
    )


def _form_cause(model: Any, better: FitVerdict) -> tuple[str, str]:
    """Cause and explanation of a modal model's miss beside a better model within the noise."""
    if getattr(model, "mode_kind", None) == "real":
        return CAUSE_NON_PROPORTIONAL, (
            f"the {better.subject} of the same band is within the noise, so the damping "
            "couples the modes, which real modes cannot hold: an identification result, "
            "not a failure of the fit"
        )
    return CAUSE_MODEL_FORM, (
        f"the {better.subject} of the same band is within the noise, so this model's "
        "form cannot hold the data: an identification result, not a failure of the fit"
    )


def modal_verdicts(
    frf: FRF, res: ModalIdentification, *, block: int = BLOCK_LINES
) -> dict[str, FitVerdict]:
    """Verdict of each fitted model of ``res`` against the noise of the fitted lines of ``frf``.

    The complex-mode fit is judged first; the real-mode fit is judged with it
    as the better model (:func:`modal_fit_verdict`). ``tyredamp modal`` and
    the campaign store these as ``meta["verdict"]`` of each model. The fitted
    lines are read from ``frf`` in blocks of ``block`` lines (a band of its
    lines is not copied).
    """
    kind = res.frf_kind
    span = _fitted_span(frf, res.frequency, kind)
    if span is None:  # lines that are no band of the FRF's: their copy
        keep = np.flatnonzero(np.isin(frf.frequency, res.frequency))
        meas, span = frf.select_lines(keep).to(kind), None  # type: ignore[arg-type]
    else:
        meas = frf
    out: dict[str, FitVerdict] = {}
    eps = float(getattr(res, "model_error", 0.0))
    common: dict[str, Any] = {"model_error": eps, "lines": span, "kind": kind, "block": block}
    if "complex" in res.models:
        out["complex"] = modal_fit_verdict(
            res.models["complex"], meas, subject="complex-mode fit", **common
        )
    if "real" in res.models:
        out["real"] = modal_fit_verdict(
            res.models["real"], meas, subject="real-mode fit", better=out.get("complex"), **common
        )
    return out
