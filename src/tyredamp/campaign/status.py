"""What happened to each test of a campaign: step outcomes, skips, quality checks.

Three things are kept apart (``docs/campaign.md``): a step *skipped*
because the test's data cannot give it (:mod:`.skips`), a step that
*failed* with an error, and a step that ran but whose result carries a
*failed quality check* (the FRF quality check of the modal step, the fit
verdict of the tracked model). :func:`step_rows` gives the step table,
:func:`summary_entry` a test's entry in ``campaign.json``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from . import steps
from .excitation import single_member_wave_numbers
from .runner import TestRun
from .spec import CONDITIONS

__all__ = [
    "STEP_COLUMNS",
    "excitation_layout",
    "quality_checks",
    "run_status",
    "step_rows",
    "summary_entry",
]

_COND_TYPES = {c: ("string" if CONDITIONS[c][1] == "text" else "float") for c in CONDITIONS}
#: Columns of the step table (one row per step of every test).
STEP_COLUMNS: dict[str, str] = {
    "test_id": "string",
    "file": "string",
    **_COND_TYPES,
    "study": "string",
    "step": "string",
    "outcome": "string",
    "cached": "string",
    "reason": "string",
    "verdict": "string",
    "verdict_summary": "string",
}


def _fit_checks(modal: dict[str, Any]) -> dict[str, dict[str, Any]]:
    out = {}
    for name, m in (modal.get("models") or {}).items():
        v = (m.get("meta") or {}).get("verdict")
        if isinstance(v, dict):
            out[name] = {
                "status": str(v.get("status")),
                "brief": str(v.get("brief") or ""),
                "summary": str(v.get("summary") or ""),
            }
    return out


def quality_checks(run: TestRun, model: str = "complex") -> dict[str, Any]:
    """The quality checks of a test's results, as the campaign reports them.

    Returns a dict with, when the step ran:

    ``data_quality``
        The FRF quality check of the modal step (``tyredamp check quality``):
        ``status`` ``"passed"``/``"failed"``/``"off"`` and its ``summary``.
    ``fit``
        The fit verdict of every identified model (:mod:`tyredamp.studies.verdicts`)
        by model name: ``status`` (``"ok"``, ``"failed"``, ``"not judged"``),
        ``brief`` and ``summary``; ``tracked`` names the model that is tracked.
    ``damping``
        ``status`` ``"ok"`` when ``C'`` is positive definite (every mode
        dissipates), else ``"caution"``, and a ``summary``.
    ``lateral``
        The best lateral model and the problems its fit shows (``status``
        ``"ok"`` without problems, else ``"caution"``).
    ``failed``
        The names of the checks that failed, empty when none did: ``"data
        quality"`` and ``"fit <model>"`` for the tracked model (the verdicts
        of the other models stay in ``fit``: a real-mode fit that misses where
        the complex-mode fit is within the noise tells of non-proportional
        damping, not of a bad test).
    """
    out: dict[str, Any] = {}
    failed: list[str] = []
    modal = run.documents.get("modal")
    if modal is not None:
        q = (modal.get("campaign") or {}).get("quality")
        if q is None:
            out["data_quality"] = {"status": "off", "summary": "not checked (switched off)"}
        else:
            ok = bool(q.get("passed"))
            out["data_quality"] = {"status": "passed" if ok else "failed", "summary": q["summary"]}
            if not ok:
                failed.append("data quality")
        fits = _fit_checks(modal)
        out["fit"] = fits
        names = sorted(fits)
        tracked = model if model in fits else (names[0] if names else None)
        out["tracked"] = tracked
        if tracked is not None and fits[tracked]["status"] == "failed":
            failed.append(f"fit {tracked}")
    damp = run.documents.get("damping")
    if damp is not None:
        d = damp.get("diagnostics") or {}
        definite = str(d.get("definiteness_modal") or "")
        out["damping"] = {
            "status": "ok" if definite == "positive definite" else "caution",
            "summary": f"C' is {definite}" if definite else "no diagnostics",
        }
    fit = run.documents.get("fit")
    if fit is not None:
        best = next((r["model"] for r in fit.get("table", []) if r.get("rank") == 1), None)
        problems = list((fit.get("problems") or {}).get(best, [])) if best else []
        out["lateral"] = {
            "status": "ok" if best and not problems else "caution",
            "best": best,
            "summary": (
                f"best model {best}" + (": " + "; ".join(problems) if problems else "")
                if best
                else "no model ranked"
            ),
        }
    out["failed"] = failed
    return out


def excitation_layout(run: TestRun, model: str = "complex") -> dict[str, Any] | None:
    """Shaker angles of a ring test, and the doubled pairs of which they drive one member.

    From the channels of the test's modes document: when every input and at
    least three outputs carry an angular position, returns
    ``angles_deg`` (the inputs) and ``single_member`` (the wave numbers up to
    the outputs' spatial Nyquist limit of which only one member of the
    doubled pair is driven, :func:`~.excitation.single_member_wave_numbers`);
    None otherwise.
    """
    modal = run.documents.get("modal")
    if modal is None:
        return None
    models = modal.get("models") or {}
    m = models.get(model) or next(iter(models.values()), None)
    if m is None:
        return None
    ins = [c.get("angle_deg") for c in m.get("inputs") or []]
    outs = [c.get("angle_deg") for c in m.get("outputs") or []]
    if m.get("shapes_at") == "inputs":
        return None  # a roving hammer: the excitation moves over the points
    if not ins or any(a is None for a in ins) or sum(a is not None for a in outs) < 3:
        return None
    n_max = len({round(float(a) % 360.0, 6) for a in outs if a is not None}) // 2
    angles = [float(a) for a in ins]
    return {"angles_deg": angles, "single_member": single_member_wave_numbers(angles, n_max)}


def _step_verdict(step: str, checks: dict[str, Any]) -> tuple[str | None, str | None]:
    """The verdict of one step's result and its summary (None when nothing was judged)."""
    if step == "modal" and "fit" in checks:
        parts, bad = [], False
        dq = checks.get("data_quality", {})
        if dq.get("status") in ("passed", "failed"):
            parts.append(dq["summary"])
            bad |= dq["status"] == "failed"
        tracked = checks.get("tracked")
        for name, v in sorted(checks["fit"].items(), key=lambda kv: kv[0] != tracked):
            parts.append(f"{name}-mode fit{' (tracked)' if name == tracked else ''}: {v['brief']}")
        bad |= any(n.startswith("fit ") for n in checks["failed"])
        return ("failed" if bad else "ok"), "; ".join(parts)
    if step == "damping" and "damping" in checks:
        return checks["damping"]["status"], checks["damping"]["summary"]
    if step == "fit" and "lateral" in checks:
        return checks["lateral"]["status"], checks["lateral"]["summary"]
    return None, None


def run_status(run: TestRun) -> str:
    """``"ok"`` (every step ran), ``"partial"`` (steps skipped) or ``"failed"``."""
    if not run.ok:
        return "failed"
    return "partial" if run.skipped else "ok"


def step_rows(runs: Sequence[TestRun], model: str = "complex") -> list[dict[str, Any]]:
    """One row per step of every test: outcome, reason, cache use and verdict (STEP_COLUMNS)."""
    rows = []
    for r in runs:
        checks = quality_checks(r, model)
        for step in steps.STUDIES[r.spec.study].steps:
            outcome = r.outcome(step)
            reason = None
            if outcome == "skipped":
                reason = r.skipped[step]["reason"]
            elif outcome == "failed":
                reason = r.reason
            elif outcome == "not run":
                reason = f"the {r.failed_step} step failed"
            verdict, summary = _step_verdict(step, checks) if outcome == "ran" else (None, None)
            row: dict[str, Any] = {"test_id": r.spec.test_id, "file": r.spec.rel}
            row.update({c: r.spec.conditions.get(c) for c in CONDITIONS})
            row.update(
                {
                    "study": r.spec.study,
                    "step": step,
                    "outcome": outcome,
                    "cached": (
                        "yes" if step in r.reused else ("no" if step in r.computed else None)
                    ),
                    "reason": reason,
                    "verdict": verdict,
                    "verdict_summary": summary,
                }
            )
            rows.append(row)
    return rows


def summary_entry(
    run: TestRun, rows: Sequence[dict[str, Any]], documents: dict[str, str], model: str
) -> dict[str, Any]:
    """A test's entry in ``campaign.json``: status, step outcomes, skips, checks, documents.

    ``rows`` are the test's rows of :func:`step_rows`; ``documents`` its
    written documents (step -> relative path).
    """
    return {
        "test_id": run.spec.test_id,
        "file": run.spec.rel,
        "study": run.spec.study,
        "conditions": run.spec.conditions,
        "sha256": run.digest,
        "status": run_status(run),
        "failed_step": run.failed_step,
        "reason": run.reason,
        "steps": [
            {k: x[k] for k in ("step", "outcome", "cached", "reason", "verdict")} for x in rows
        ],
        "skipped": {k: v["reason"] for k, v in run.skipped.items()},
        "checks": quality_checks(run, model),
        "excitation": excitation_layout(run, model),
        "computed": run.computed,
        "reused": run.reused,
        "documents": documents,
    }
