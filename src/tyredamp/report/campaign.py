"""The campaign report: one self-contained HTML page (figures embedded, works offline).

Sections: the campaign in numbers; problems (tests that failed with an
error, quality checks that failed, steps skipped because a test's data
cannot give them, each with its reason); mode families with a figure per
family (natural frequency and damping ratio across the tests, against the
condition that varies most); trend plots per family (frequency, damping
ratio and modal damping against pressure, load, speed and temperature, one
series per tyre and fixed conditions, with the fitted trend and its 95 %
band); the lateral ranking per test; and every test with the outcome of
each step (ran, skipped with the reason, failed with the error), its
quality verdicts and links to its documents.
"""

from __future__ import annotations

import html
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from ..io._safety import atomic_path
from .html import HtmlReport

__all__ = ["campaign_report", "write_campaign_report"]

_QLABELS: dict[str, tuple[str, float]] = {
    "frequency_hz": ("natural frequency [Hz]", 1.0),
    "damping_ratio": ("damping ratio [%]", 100.0),
    "modal_damping": ("modal damping C'_nn [1/s]", 1.0),
}
_LABELS: dict[str, str] = {
    "pressure_bar": "pressure [bar]",
    "load_n": "load [N]",
    "speed_kmh": "speed [km/h]",
    "temperature_c": "temperature [degC]",
}


def _family_order(name: str) -> tuple[int, str]:
    return (int(name[1:]), "") if name[:1] == "F" and name[1:].isdigit() else (10**9, name)


def _trend_figures(rep: HtmlReport, fits: list[Any], labels: dict[str, str]) -> None:
    from matplotlib.figure import Figure

    from ..plot.campaign import plot_trend

    groups: dict[tuple[str, str, str], list[Any]] = defaultdict(list)
    for about, fit, pts in fits:
        groups[(about["family"], about["slot"], about["condition"])].append((about, fit, pts))
    order = sorted(groups, key=lambda k: (_family_order(k[0]), k[1], k[2]))
    for fam, slot, cond in order:
        items = groups[(fam, slot, cond)]
        quantities: list[str] = []
        for about, _, _ in items:
            if about["quantity"] not in quantities:
                quantities.append(about["quantity"])
        ncol = min(len(quantities), 3)
        nrow = -(-len(quantities) // ncol)
        fig = Figure(figsize=(11, 3.2 * nrow), layout="constrained")
        axes = fig.subplots(nrow, ncol, squeeze=False).ravel()
        for ax, q in zip(axes, quantities, strict=False):
            ylabel, scale = _QLABELS.get(q, (q, 1.0))
            series = [it for it in items if it[0]["quantity"] == q]
            for k, (about, fit, pts) in enumerate(series):
                plot_trend(
                    pts,
                    fit,
                    cond,
                    q,
                    ax=ax,
                    label=about["series"],
                    color=f"C{k % 10}",
                    scale=scale,
                )
            ax.set_xlabel(_LABELS.get(cond, cond))
            ax.set_ylabel(ylabel)
        for ax in axes[len(quantities) :]:
            ax.set_axis_off()
        n_series = sum(it[0]["quantity"] == quantities[0] for it in items)
        if n_series <= 12:
            axes[0].legend(fontsize=6)
        name = fam + (f", {labels[fam]}" if labels.get(fam, fam) != fam else "")
        name += slot and f" ({slot})"
        rep.figure(
            fig,
            f"{name}: against {_LABELS.get(cond, cond)}; line: fitted trend "
            "(degree by AICc), band: 95 %",
            dpi=80,
        )


def _label(family: str | None, slot: str) -> str:
    return f"{family}{slot}" if family else "?"


def _damping_figures(rep: HtmlReport, rows: list[dict[str, Any]]) -> int:
    """C' at the two ends of the longest sweep of the first tyre, per condition; their change."""
    from matplotlib.figure import Figure

    from ..plot.damping import plot_matrix

    by_test: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        by_test[r["test_id"]].append(r)
    if not by_test:
        return 0
    tyres = sorted({str(v[0]["tyre"] or "") for v in by_test.values()})
    first = {t: v for t, v in by_test.items() if str(v[0]["tyre"] or "") == tyres[0]}
    n = 0
    for cond in ("pressure_bar", "load_n", "speed_kmh", "temperature_c"):
        series: dict[tuple[Any, ...], dict[float, str]] = defaultdict(dict)
        for tid, v in first.items():
            c = v[0]
            if c[cond] is None:
                continue
            others = tuple((k, c[k]) for k in _LABELS if k != cond)
            series[others].setdefault(float(c[cond]), tid)
        best = max(series.values(), key=len, default={})
        if len(best) < 2:
            continue
        lo, hi = min(best), max(best)
        mats = []
        for x in (lo, hi):
            entries = {
                (_label(r["family_k"], r["slot_k"]), _label(r["family_n"], r["slot_n"])): r["value"]
                for r in by_test[best[x]]
            }
            mats.append(entries)
        labels = sorted(
            {k for k, _ in mats[0]} & {k for k, _ in mats[1]},
            key=lambda s: (_family_order(s.rstrip("ab"))[0], s),
        )
        if not labels:
            continue
        a, b = (np.array([[m[(i, j)] for j in labels] for i in labels]) for m in mats)
        fig = Figure(figsize=(13, 3.9), layout="constrained")
        axes = fig.subplots(1, 3)
        unit = "1/s"
        name = _LABELS[cond]
        plot_matrix(a, labels, f"C' at {name} = {lo:g}", unit, ax=axes[0])
        plot_matrix(b, labels, f"C' at {name} = {hi:g}", unit, ax=axes[1])
        plot_matrix(b - a, labels, "change", unit, ax=axes[2])
        rep.figure(
            fig,
            f"modal damping matrix C' of tyre {tyres[0] or '-'} by mode family at the two ends "
            f"of its longest {name} sweep, and the change (damping.csv has every test)",
            dpi=80,
        )
        n += 1
    return n


def _family_condition(rows: list[dict[str, Any]]) -> str | None:
    """The numeric condition with the most distinct values (at least 2) among ``rows``."""
    best, n_best = None, 1
    for cond in _LABELS:
        n = len({r[cond] for r in rows if r.get(cond) is not None})
        if n > n_best:
            best, n_best = cond, n
    return best


def _family_figures(rep: HtmlReport, modes: list[dict[str, Any]]) -> None:
    """Frequency and damping ratio of every family across the tests (one figure each)."""
    from matplotlib.figure import Figure

    from ..plot.campaign import plot_family

    by_family: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in modes:
        if r.get("family"):
            by_family[r["family"]].append(r)
    for fam in sorted(by_family, key=_family_order):
        rows = by_family[fam]
        cond = _family_condition(rows)
        if cond is not None:
            rows = sorted(rows, key=lambda r: (r.get(cond) is None, r.get(cond) or 0.0))
        fig = Figure(figsize=(11, 3.0), layout="constrained")
        axes = fig.subplots(1, 2)
        plot_family(rows, cond, axes=axes)
        if cond is not None:
            for ax in axes:
                ax.set_xlabel(_LABELS[cond])
        med = float(np.median([r["frequency_hz"] for r in rows]))
        label = rows[0].get("family_label")
        name = f"{fam}, {label}" if label and label != fam else fam
        n_tests = len({r["test_id"] for r in rows})
        against = f"against {_LABELS[cond]}" if cond else "test by test"
        rep.figure(
            fig,
            f"{name} (median {med:.4g} Hz, {n_tests} test{'s' if n_tests != 1 else ''}): "
            f"natural frequency and damping ratio {against}, +- 1 standard error",
            dpi=80,
        )


def _excitation_note(rep: HtmlReport, s: dict[str, Any]) -> None:
    """Say which doubled pairs the shaker layout cannot show both members of."""
    layouts: dict[tuple[tuple[float, ...], tuple[int, ...]], list[str]] = defaultdict(list)
    for t in s["tests"]:
        ex = t.get("excitation")
        if ex and ex["single_member"]:
            key = (tuple(ex["angles_deg"]), tuple(ex["single_member"]))
            layouts[key].append(t["test_id"])
    for (angles, waves), ids in layouts.items():
        where = ", ".join(f"{a:g}" for a in angles)
        ns = ", ".join(str(n) for n in waves)
        tests = f"{len(ids)} test{'s' if len(ids) != 1 else ''}"
        if len(angles) == 1:
            rep.paragraph(
                f"One shaker at {where} deg ({tests}) drives only the member of each doubled "
                f"mode whose antinode is at the shaker (cos) for wave numbers n = {ns}: the "
                "other member (sin) has a node there and cannot appear in these FRFs, so each "
                "family holds one member, not the pair, and the pair's splitting is not "
                "measured. Two shakers see both members of wave number n when n times their "
                "angular spacing is not a multiple of 180 deg (0 and 45 deg: n = 1, 2, 3).",
                "note",
            )
            continue
        rep.paragraph(
            f"Shakers at {where} deg ({tests}) drive "
            f"only one member of the doubled modes of wave number n = {ns}: for these n every "
            "shaker lies on a nodal line of the same member (n times the angle between the "
            "shakers is a multiple of 180 deg), so the second member cannot appear in these "
            "FRFs and such families hold a single mode, not a pair. Two shakers see both "
            "members of wave number n when n times their angular spacing is not a multiple "
            "of 180 deg (0 and 45 deg: n = 1, 2, 3).",
            "note",
        )


def _outcome_text(step: dict[str, Any]) -> str:
    o = step["outcome"]
    if o == "ran":
        return "ran (cache)" if step.get("cached") == "yes" else "ran"
    if o in ("skipped", "failed"):
        reason = str(step.get("reason") or "")
        prefix = f"{step['step']} step skipped: "
        return f"{o}: {reason[len(prefix) :] if reason.startswith(prefix) else reason}"
    return o


def _verdict_cell(v: str | None) -> str:
    if v is None:
        return ""
    cls = "bad" if v == "failed" else ("ok" if v in ("ok", "passed") else "")
    word = {"ok": "OK", "failed": "FAILED", "passed": "PASS", "caution": "caution"}.get(v, v)
    return f'<span class="{cls}">{html.escape(word)}</span>' if cls else html.escape(word)


def _problems(rep: HtmlReport, s: dict[str, Any]) -> None:
    tests = s["tests"]
    failed = [t for t in tests if t["status"] == "failed"]
    checks = [(t, t["checks"]) for t in tests if t.get("checks", {}).get("failed")]
    skipped: dict[str, list[str]] = defaultdict(list)
    for t in tests:
        for reason in (t.get("skipped") or {}).values():
            skipped[reason].append(t["test_id"])
    if not failed and not checks and not skipped:
        rep.paragraph("None: every step of every test ran and every quality check passed.", "ok")
        return
    rep.heading("Failed tests", 3)
    if failed:
        rep.paragraph("A step failed with an error; the test's later steps did not run.", "bad")
        rep.table(
            ["test", "file", "step", "error"],
            [[t["test_id"], t["file"], t["failed_step"] or "", t["reason"] or ""] for t in failed],
        )
    else:
        rep.paragraph("No step failed with an error.", "ok")
    rep.heading("Failed quality checks", 3)
    if checks:
        rep.paragraph(
            f"{len(checks)} of {len(tests)} tests ran but carry a failed check: their results "
            "are in the tables; read them with the reasons below.",
            "bad",
        )
        rows = []
        for t, c in checks:
            for name in c["failed"]:
                if name == "data quality":
                    rows.append([t["test_id"], name, c["data_quality"]["summary"]])
                else:
                    model = name.split(" ", 1)[1]
                    rows.append([t["test_id"], f"{model}-mode fit", c["fit"][model]["brief"]])
        rep.table(["test", "check", "verdict"], rows)
    else:
        rep.paragraph("Every quality check passed (or was not judged).", "ok")
    rep.heading("Skipped steps", 3)
    if skipped:
        rep.paragraph(
            "These steps could not run on the tests' data (not an error); every other result "
            "of these tests is kept."
        )
        rep.table(
            ["reason", "tests"],
            [[reason, f"{len(ids)}: " + ", ".join(ids)] for reason, ids in skipped.items()],
        )
    else:
        rep.paragraph("No step was skipped.", "ok")


def _tests_table(rep: HtmlReport, s: dict[str, Any]) -> None:
    step_names: list[str] = []
    for t in s["tests"]:
        for st in t.get("steps", []):
            if st["step"] not in step_names:
                step_names.append(st["step"])
    head = "".join(f'<th class="l">{html.escape(n)}</th>' for n in step_names)
    rows = []
    for t in s["tests"]:
        links = " ".join(
            f'<a href="{html.escape(p)}">{html.escape(Path(p).name)}</a>'
            for p in t["documents"].values()
        )
        c = t["conditions"]
        cond = ", ".join(f"{k} {v}" for k, v in c.items() if v is not None)
        by_step = {st["step"]: st for st in t.get("steps", [])}
        cells = "".join(
            f'<td class="l">{html.escape(_outcome_text(by_step[n])) if n in by_step else ""}</td>'
            for n in step_names
        )
        checks = t.get("checks", {})
        dq = checks.get("data_quality", {})
        tracked = checks.get("tracked")
        fit = checks.get("fit", {}).get(tracked) if tracked else None
        if fit is not None:
            fit_cell = f"{_verdict_cell(fit['status'])} ({html.escape(tracked or '')})"
            if fit["status"] == "failed":
                fit_cell += f": {html.escape(fit['brief'])}"
        elif "lateral" in checks:
            lat = checks["lateral"]
            fit_cell = f"{_verdict_cell(lat['status'])} {html.escape(lat['summary'])}"
        else:
            fit_cell = ""
        rows.append(
            f'<tr><td class="l">{html.escape(t["test_id"])}</td>'
            f'<td class="l">{html.escape(cond)}</td>'
            f'<td class="l">{html.escape(t["status"])}</td>{cells}'
            f'<td class="l">{_verdict_cell(dq.get("status"))}</td>'
            f'<td class="l">{fit_cell}</td><td class="l">{links}</td></tr>'
        )
    rep.paragraph(
        "Status: ok (every step ran), partial (a step could not run on the test's data and "
        "was skipped), failed (a step failed with an error). Data quality: the FRF check of "
        "tyredamp check quality; fit: the verdict of the tracked model's fit against the "
        "noise (the lateral tests: the best model and its problems)."
    )
    rep.raw(
        '<table><thead><tr><th class="l">test</th><th class="l">conditions</th>'
        f'<th class="l">status</th>{head}<th class="l">data quality</th>'
        '<th class="l">fit</th><th class="l">documents</th></tr></thead><tbody>'
        + "".join(rows)
        + "</tbody></table>"
    )


def campaign_report(results: Any) -> str:
    """The HTML text of the campaign report of ``results`` (``CampaignResults``)."""
    s = results.summary
    rep = HtmlReport(f"tyredamp campaign: {s['name']}")
    rep.heading("The campaign")
    rep.table(
        ["", "value"],
        [
            ["tests", s["n_tests"]],
            ["every step ran", s["n_ok"] - s.get("n_partial", 0)],
            ["steps skipped (the data cannot give them)", s.get("n_partial", 0)],
            ["failed with an error", s["n_failed"]],
            ["with a failed quality check", s.get("n_checks_failed", 0)],
            ["steps computed in this run", s["steps_computed"]],
            ["steps read from the cache", s["steps_reused"]],
            ["mode families", len(s["families"])],
            ["tyredamp", s["tyredamp_version"]],
        ],
    )
    rep.heading("Problems")
    _problems(rep, s)
    rep.heading("Mode families")
    tr = s.get("tracking") or {}
    rep.paragraph(
        "Modes matched across tests by the MAC of their shapes at the common points and "
        "their frequency (an assignment per test against the nearest observed state of each "
        "family); doubled modes (overlapping half-power bands) are matched as pairs by the "
        "subspace MAC and reported as slots a (lower) and b (upper). Where two tests share "
        "fewer than 2 points the MAC cannot be formed, and modes are matched by frequency "
        "and damping ratio, in units of their standard errors and of the scatter of one mode "
        "between neighbouring tests."
    )
    if tr:
        n_f = tr.get("matched_by_frequency", 0)
        text = (
            f"Matched by shape: {tr.get('matched_by_shape', 0)} modes; by frequency and "
            f"damping: {n_f} modes"
        )
        if n_f:
            text += (
                f" (scatter of one mode between neighbouring tests, from "
                f"{tr.get('scatter_pairs', 0)} pairs: "
                f"{100 * float(tr.get('scatter_ln_frequency') or 0):.3g} % in frequency, "
                f"{100 * float(tr.get('scatter_ln_damping_ratio') or 0):.3g} % in damping ratio)"
            )
        rep.paragraph(text + ".")
    rep.paragraph(
        "Each family is named by the circumferential wave number n of its shapes (the "
        "single harmonic a cos n theta + b sin n theta that explains most of a shape at the "
        "points' angles, counted when it explains at least 80 % of it; the family takes the "
        "wave number most of its modes carry) and, for a single member of a doubled mode, by "
        "the member: cos (antinode at the first shaker) or sin (node there)."
    )
    rep.table(
        ["family", "name", "median f [Hz]", "modes", "tests", "pair"],
        [
            [
                f["family"],
                f.get("label") or "",
                f["median_frequency_hz"],
                f["n_modes"],
                f["n_tests"],
                "yes" if f["pair"] else "",
            ]
            for f in s["families"]
        ],
    )
    _excitation_note(rep, s)
    if results.modes:
        _family_figures(rep, results.modes)
    if results.fits:
        rep.heading("Trends")
        labels = {f["family"]: f.get("label") or f["family"] for f in s["families"]}
        _trend_figures(rep, results.fits, labels)
    if results.damping:
        rep.heading("Damping matrix across conditions")
        if not _damping_figures(rep, results.damping):
            rep.paragraph("No sweep with two or more values of a condition.")
    if results.lateral:
        rep.heading("Lateral tests")
        best: dict[str, dict[str, Any]] = {}
        for r in results.lateral:
            if r["rank"] == 1:
                best.setdefault(r["test_id"], r)
        rep.table(
            ["test", "speed [km/h]", "pressure [bar]", "best model", "BIC"],
            [[t, r["speed_kmh"], r["pressure_bar"], r["model"], r["bic"]] for t, r in best.items()],
        )
    rep.heading("Tests")
    _tests_table(rep, s)
    return rep.render()


def write_campaign_report(results: Any, out_dir: str | Path) -> Path:
    """Write ``out_dir/report.html`` atomically; returns its path."""
    path = Path(out_dir) / "report.html"
    text = campaign_report(results)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path
