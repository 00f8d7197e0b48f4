"""Verdicts and warnings of every stage of a demo run, for results.json, the summary and the report.

Every stage keeps its own warnings in its result (a modal model's
``meta["warnings"]``, the identification's ``warnings``, a check's verdict
and notes, the damping diagnostics, the lateral fits); :func:`demo_findings`
collects them with the fit verdicts of :mod:`tyredamp.studies.verdicts`, each
tagged with the result it concerns (``about``), so that the report can show
it beside that result and the summary can list it.

``about`` keys: ``"radial:<p>"`` (the run at pressure ``p`` bar, ``%g``),
``"radial:checks"``, ``"radial:damping"``, ``"radial:tyre_model"``, ``"lateral:<label>"`` (a rig
condition, ``"1.7 bar, 5 km/h"``), ``"lateral:time"`` (vehicle and time test).

A fit verdict that misses the noise is a finding of severity ``"failed"`` (a
genuine failure) or ``"expected"`` (a miss the data explain, such as a
real-mode fit of non-proportionally damped data: its ``outcome`` in
:mod:`tyredamp.studies.verdicts`). :func:`outcome_groups` gathers the verdicts
of a results document into one line per outcome and cause (all real-mode
fits missing for the same cause are one finding), for the report's summary and
the console table.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

from .lateral_verdicts import lateral_family_verdicts
from .verdicts import CAUSE_MEANING, FitVerdict, modal_fit_verdict

if TYPE_CHECKING:
    from .results import DemoResult, LateralCondition, PressureRun

__all__ = [
    "DemoFindings",
    "Finding",
    "OutcomeGroup",
    "demo_findings",
    "outcome_groups",
    "pressure_verdicts",
]

Severity = Literal["warning", "failed", "expected"]


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
    severity : {"warning", "failed", "expected"}
        ``"expected"``: a fit's miss that the data explain (not a failure).
    fit : str
        The fit it judges (``"real"``, a lateral model's name) when it is a fit
        verdict; empty for other findings.
    """

    about: str
    stage: str
    message: str
    severity: Severity = "warning"
    fit: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (results.json ``warnings`` entries)."""
        return {
            "about": self.about,
            "stage": self.stage,
            "severity": self.severity,
            "message": self.message,
            "fit": self.fit,
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


def _verdict_findings(about: str, stage: str, v: FitVerdict, fit: str) -> list[Finding]:
    out = []
    if v.outcome in ("failed", "expected"):
        sev: Severity = "failed" if v.outcome == "failed" else "expected"
        out.append(Finding(about, stage, v.summary(), sev, fit))
    out += [Finding(about, stage, f"{v.subject}: {c}") for c in v.cautions]
    return out


_EDGE = re.compile(r"^mode at ([0-9.eE+-]+) Hz: its half-power band")


def _edge_mode(caution: str) -> float | None:
    m = _EDGE.match(caution)
    return float(m.group(1)) if m else None


def _modal_findings(about: str, stage: str, verdicts: dict[str, FitVerdict]) -> list[Finding]:
    """Findings of the fits of one band; a band-edge mode both fits caution about is one."""
    cx, re_ = verdicts.get("complex"), verdicts.get("real")
    shared: dict[str, str] = {}  # complex caution -> merged subject
    skip: set[str] = set()
    if cx is not None and re_ is not None:
        p = cx.subject.split(" at ", 1)[1] if " at " in cx.subject else ""
        for c in cx.cautions:
            fc = _edge_mode(c)
            for r in re_.cautions:
                fr = _edge_mode(r)
                if fc is not None and fr is not None and abs(fr - fc) <= 0.01 * fc:
                    shared[c] = "complex- and real-mode fits" + (f" at {p}" if p else "")
                    skip.add(r)
    out: list[Finding] = []
    for name, v in verdicts.items():
        for f in _verdict_findings(about, stage, v, name):
            c = f.message[len(v.subject) + 2 :] if not f.fit else ""
            if not f.fit and c in skip and name == "real":
                continue
            if not f.fit and c in shared and name == "complex":
                f = Finding(about, stage, f"{shared[c]}: {c}")
            out.append(f)
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
        findings += _modal_findings(key, stage, verdicts)
    for chk in (r.linearity, r.reciprocity, r.quality):
        if not chk.passed:
            findings.append(Finding("radial:checks", "radial checks", chk.summary, "failed"))
            findings += [
                Finding("radial:checks", "radial checks", f"{chk.name} check: {n}")
                for n in chk.notes
            ]
    d = r.damping.diagnostics
    if d.definiteness_modal != "positive definite":
        why = (
            "from the terms of the modes whose shapes coincide at the measured points "
            f"({len(d.collinear_pairs)} pair(s)): those terms are not determined by these "
            "points; a sensor that sees the pair differently (e.g. a cavity microphone) "
            "determines them"
            if d.collinear_pairs
            else "not a passive damping"
        )
        findings.append(
            Finding(
                "radial:damping",
                "radial damping",
                f"C' in modal coordinates is {d.definiteness_modal}: {why}",
            )
        )
    tm = r.tyre_model
    if tm.error is not None:
        findings.append(
            Finding(
                "radial:tyre_model",
                "tyre model",
                f"tyre model not fitted: {tm.error}",
                "failed",
            )
        )
    lateral: dict[str, dict[str, FitVerdict]] = {}
    for c in result.lateral.conditions:
        key = lateral_key(c)
        stage = f"lateral {c.label}"
        vs = lateral_family_verdicts(c.ranking.fits, c.ground.frf, label=c.label)
        lateral[key] = vs
        best = c.ranking.best.name
        findings += _verdict_findings(key, stage, vs[best], best)
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


# ----------------------------------------------------------------------- summary lines
@dataclass(frozen=True)
class OutcomeGroup:
    """One line of a summary: the fits of one kind that share an outcome and its cause.

    Attributes
    ----------
    outcome : {"failed", "expected", "not judged", "ok"}
    title : str
        What it concerns (``"real-mode fits at 7.5, 6 and 9 bar"``).
    detail : str
        The outcome in words, starting with ``"FAILED"``, ``"expected"``,
        ``"not judged"`` or ``"within noise"``.
    about : tuple of str
        The results concerned (module docstring), one per fit, in order.
    labels : tuple of str
        A short name of each (``"7.5 bar"``) for links to them.
    residual : str
        The residuals against the noise (``"residual 10.7-11.7x"``; empty without).
    cause : str
        The short cause of an expected miss; empty otherwise.
    stage : bool
        True for a failed stage that is not a fit (a check, the tyre model).
    """

    outcome: str
    title: str
    detail: str
    about: tuple[str, ...]
    labels: tuple[str, ...]
    residual: str = ""
    cause: str = ""
    stage: bool = False


def verdict_outcome(v: dict[str, Any]) -> str:
    """The outcome of a verdict of a results document (older documents: its status)."""
    out = v.get("outcome")
    return str(out) if out else str(v["status"])


def _span(vs: list[dict[str, Any]]) -> str:
    r = [math.sqrt(v["residual_to_noise"]) for v in vs if v.get("residual_to_noise") is not None]
    if not r:
        return ""
    lo, hi = min(r), max(r)
    return f"residual {lo:.3g}x" if f"{lo:.3g}" == f"{hi:.3g}" else f"residual {lo:.3g}-{hi:.3g}x"


def _at(labels: list[str], total: int, unit: str) -> str:
    if len(labels) == total and total > 2:
        return f"at all {total} {unit}"
    if all(x.endswith(" bar") for x in labels):  # "7.5, 6 and 9 bar"
        nums = [x[: -len(" bar")] for x in labels]
        head = ", ".join(nums[:-1])
        return f"at {head} and {nums[-1]} bar" if head else f"at {nums[-1]} bar"
    return "at " + "; ".join(labels)


def outcome_groups(doc: dict[str, Any]) -> list[OutcomeGroup]:
    """Every fit verdict and failed stage of a demo results document, one line per finding.

    Each genuine failure is a line of its own; the fits of one kind (complex-mode,
    real-mode, best lateral model) that share an outcome and its cause are one
    line (module docstring). Failures first, then expected misses, fits not
    judged and fits within the noise.
    """
    entries: list[tuple[str, str, str, str, dict[str, Any]]] = []  # kind, unit, label, about, v
    for pr in doc["radial"]["pressures"]:
        for name in ("complex", "real"):
            v = pr["verdict"].get(name)
            if v is not None:
                key = f"radial:{pr['pressure_bar']:g}"
                entries.append(
                    (f"{name}-mode fit", "pressures", f"{pr['pressure_bar']:g} bar", key, v)
                )
    for c in doc["lateral"]["conditions"]:
        entries.append(
            ("best lateral fit", "conditions", c["label"], f"lateral:{c['label']}", c["verdict"])
        )
    totals: dict[str, int] = {}
    for kind, *_ in entries:
        totals[kind] = totals.get(kind, 0) + 1
    failed: list[OutcomeGroup] = []
    groups: dict[tuple[str, str, str], list[tuple[str, str, str, str, dict[str, Any]]]] = {}
    for e in entries:
        v = e[4]
        out = verdict_outcome(v)
        if out == "failed":
            failed.append(
                OutcomeGroup("failed", v["subject"], v["brief"], (e[3],), (e[2],), _span([v]))
            )
        else:
            groups.setdefault((out, e[0], v.get("expected_cause", "")), []).append(e)
    for w in doc.get("warnings", []):
        if w["severity"] == "failed" and not w.get("fit"):
            failed.append(
                OutcomeGroup(
                    "failed",
                    w["stage"],
                    f"FAILED: {w['message']}",
                    (w["about"],),
                    (w["stage"],),
                    stage=True,
                )
            )
    rest: list[OutcomeGroup] = []
    order = {"expected": 0, "not judged": 1, "ok": 2}
    for (out, kind, cause), es in sorted(groups.items(), key=lambda kv: order.get(kv[0][0], 3)):
        vs = [e[4] for e in es]
        labels = [e[2] for e in es]
        title = f"{kind}s {_at(labels, totals[kind], es[0][1])}"
        span = _span(vs)
        if out == "expected":
            meaning = CAUSE_MEANING.get(cause, vs[0].get("outcome_reason", ""))
            detail = f"expected ({span} the noise): {cause}: {meaning}"
        elif out == "ok":
            detail = "within noise" + (f" ({span} the noise level)" if span else "")
        else:
            detail = "not judged (no noise to judge against, or too few lines)"
        rest.append(
            OutcomeGroup(out, title, detail, tuple(e[3] for e in es), tuple(labels), span, cause)
        )
    return failed + rest
