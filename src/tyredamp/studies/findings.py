"""Verdicts and warnings of every stage of a demo run, for results.json, the summary and the report.

Every stage keeps its own warnings in its result (a modal model's
``meta["warnings"]``, the identification's ``warnings``, a check's verdict
and notes, the damping diagnostics, the lateral fits); :func:`demo_findings`
collects them with the fit verdicts of :mod:`tyredamp.studies.verdicts`, each
tagged with the result it concerns (``about``), so that the report can show
it beside that result and the summary can list it.

``about`` keys: ``"radial:<p>"`` (the run at pressure ``p`` bar, ``%g``),
``"radial:checks"``, ``"radial:damping"``, ``"lateral:<label>"`` (a rig
condition, ``"1.7 bar, 5 km/h"``), ``"lateral:time"`` (vehicle and time test).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

from .verdicts import FitVerdict, lateral_fit_verdict, modal_fit_verdict

if TYPE_CHECKING:
    from .results import DemoResult, LateralCondition, PressureRun

__all__ = ["DemoFindings", "Finding", "demo_findings", "pressure_verdicts"]

Severity = Literal["warning", "failed"]


@dataclass(frozen=True)
class Finding:
    """One warning or failure of a stage.

    Attributes
    ----------
    about : str
        The result it concerns (module docstring).
    stage : str
        Human-readable stage (``"radial 9 bar"``).
    message : str
        The warning, in words.
    severity : {"warning", "failed"}
    """

    about: str
    stage: str
    message: str
    severity: Severity = "warning"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (results.json ``warnings`` entries)."""
        return {
            "about": self.about,
            "stage": self.stage,
            "severity": self.severity,
            "message": self.message,
        }


@dataclass(frozen=True)
class DemoFindings:
    """Verdicts and warnings of a demo run.

    Attributes
    ----------
    radial : dict of str to dict of str to FitVerdict
        ``{about: {"complex": verdict, "real": verdict}}`` per pressure run.
    lateral : dict of str to dict of str to FitVerdict
        ``{about: {model: verdict}}`` per rig condition.
    findings : list of Finding
        Every warning and failure, in stage order.
    """

    radial: dict[str, dict[str, FitVerdict]]
    lateral: dict[str, dict[str, FitVerdict]]
    findings: list[Finding]

    def about(self, key: str) -> list[Finding]:
        """The findings concerning one result."""
        return [f for f in self.findings if f.about == key]


def radial_key(run: PressureRun) -> str:
    """``about`` key of a pressure run."""
    return f"radial:{run.pressure_bar:g}"


def lateral_key(cond: LateralCondition) -> str:
    """``about`` key of a rig condition."""
    return f"lateral:{cond.label}"


def pressure_verdicts(run: PressureRun) -> dict[str, FitVerdict]:
    """Complex- and real-mode fit verdicts of one pressure run (truth = expected modes)."""
    truth = run.truth
    lo, hi = run.identification.band_hz
    vis = truth.frequency_hz[truth.select("visible")]
    expected = [float(f) for f in vis if lo <= f <= hi]
    meas = run.fitted_frf
    p = f"{run.pressure_bar:g} bar"
    out: dict[str, FitVerdict] = {}
    if "complex" in run.models:
        out["complex"] = modal_fit_verdict(
            run.models["complex"],
            meas,
            subject=f"complex-mode fit at {p}",
            expected_hz=expected,
        )
    if "real" in run.models:
        out["real"] = modal_fit_verdict(
            run.models["real"],
            meas,
            subject=f"real-mode fit at {p}",
            expected_hz=expected,
            better=out.get("complex"),
        )
    return out


def _plain(warning: str) -> str:
    """A fit warning in the words of the report (the fallback of the real-mode fit named)."""
    head = "real-mode refinement not acceptable ("
    if warning.startswith(head):
        why = warning[len(head) :].split("): ", 1)[0]
        return (
            f"fell back to the complex-mode poles: the real-mode refinement was not acceptable "
            f"({why}), so the poles are those of the complex-mode fit and only real residues "
            "were fitted; its RMSD is not that of a refined real-mode fit"
        )
    return warning


def _verdict_findings(about: str, stage: str, v: FitVerdict) -> list[Finding]:
    out = []
    if v.status == "failed":
        out.append(Finding(about, stage, v.summary(), "failed"))
    out += [Finding(about, stage, f"{v.subject}: {c}") for c in v.cautions]
    return out


def demo_findings(result: DemoResult) -> DemoFindings:
    """Verdicts and warnings of every stage of a demo run (module docstring)."""
    findings: list[Finding] = []
    radial: dict[str, dict[str, FitVerdict]] = {}
    r = result.radial
    for run in r.runs:
        key = radial_key(run)
        stage = f"radial {run.pressure_bar:g} bar"
        verdicts = pressure_verdicts(run)
        radial[key] = verdicts
        for w in run.identification.warnings:
            findings.append(Finding(key, stage, f"identification: {w}"))
        for name, mdl in run.models.items():
            for w in mdl.meta.get("warnings", []):
                findings.append(Finding(key, stage, f"{name}-mode fit: {_plain(w)}"))
        for v in verdicts.values():
            findings += _verdict_findings(key, stage, v)
    for chk in (r.linearity, r.reciprocity, r.quality):
        if not chk.passed:
            findings.append(Finding("radial:checks", "radial checks", chk.summary, "failed"))
            findings += [
                Finding("radial:checks", "radial checks", f"{chk.name} check: {n}")
                for n in chk.notes
            ]
    d = r.damping.diagnostics
    if d.definiteness_modal != "positive definite":
        findings.append(
            Finding(
                "radial:damping",
                "radial damping",
                f"C' in modal coordinates is {d.definiteness_modal}: not a passive damping",
            )
        )
    lateral: dict[str, dict[str, FitVerdict]] = {}
    for c in result.lateral.conditions:
        key = lateral_key(c)
        stage = f"lateral {c.label}"
        vs = {
            f.name: lateral_fit_verdict(f, c.ground.frf, subject=f"{f.name} fit at {c.label}")
            for f in c.ranking.fits
        }
        lateral[key] = vs
        best = c.ranking.best.name
        findings += _verdict_findings(key, stage, vs[best])
        for f in c.ranking.fits:
            if f.nfev <= 0 or "maximum" in f.message.lower():
                findings.append(Finding(key, stage, f"{f.name} fit: optimiser: {f.message}"))
    veh = result.lateral.vehicle
    for name, res in veh.resonances.items():
        if res is None:
            findings.append(
                Finding(
                    "lateral:time",
                    "lateral vehicle",
                    f"vehicle on the {name} tyre: no body resonance between 0.3 and 20 Hz "
                    "(over-damped or outside the search band)",
                )
            )
    if veh.truth_resonance is None:
        findings.append(
            Finding(
                "lateral:time",
                "lateral vehicle",
                "vehicle on the rig's exact tyre: no body resonance between 0.3 and 20 Hz",
            )
        )
    return DemoFindings(radial, lateral, findings)
