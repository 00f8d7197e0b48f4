"""The campaign report: one self-contained HTML page (figures embedded, works offline).

Sections: the campaign in numbers, failed tests with their one-line reasons,
mode families, trend plots per family (frequency, damping ratio and modal
damping against pressure, load, speed and temperature, one series per tyre
and fixed conditions, with the fitted trend and its 95 % band), the lateral
ranking per test, and every test with links to its documents.
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


def _trend_figures(rep: HtmlReport, fits: list[Any]) -> None:
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
        name = fam + (slot and f" ({slot})")
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


def campaign_report(results: Any) -> str:
    """The HTML text of the campaign report of ``results`` (``CampaignResults``)."""
    s = results.summary
    rep = HtmlReport(f"tyredamp campaign: {s['name']}")
    rep.heading("The campaign")
    rep.table(
        ["", "value"],
        [
            ["tests", s["n_tests"]],
            ["succeeded", s["n_ok"]],
            ["failed", s["n_failed"]],
            ["steps computed in this run", s["steps_computed"]],
            ["steps read from the cache", s["steps_reused"]],
            ["mode families", len(s["families"])],
            ["tyredamp", s["tyredamp_version"]],
        ],
    )
    rep.heading("Failed tests")
    failed = [t for t in s["tests"] if t["status"] != "ok"]
    if failed:
        rep.table(
            ["test", "file", "step", "reason"],
            [[t["test_id"], t["file"], t["failed_step"] or "", t["reason"] or ""] for t in failed],
        )
    else:
        rep.paragraph("None: every test was processed.", "ok")
    rep.heading("Mode families")
    rep.paragraph(
        "Modes matched across tests by the MAC of their shapes at the common points and "
        "their frequency (an assignment per test against the nearest observed state of each "
        "family); doubled modes (overlapping half-power bands) are matched as pairs by the "
        "subspace MAC and reported as slots a (lower) and b (upper)."
    )
    rep.table(
        ["family", "median f [Hz]", "modes", "tests", "pair"],
        [
            [
                f["family"],
                f["median_frequency_hz"],
                f["n_modes"],
                f["n_tests"],
                "yes" if f["pair"] else "",
            ]
            for f in s["families"]
        ],
    )
    if results.fits:
        rep.heading("Trends")
        _trend_figures(rep, results.fits)
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
    rows = []
    for t in s["tests"]:
        links = " ".join(
            f'<a href="{html.escape(p)}">{html.escape(Path(p).name)}</a>'
            for p in t["documents"].values()
        )
        c = t["conditions"]
        cond = ", ".join(f"{k} {v}" for k, v in c.items() if v is not None)
        rows.append(
            f'<tr><td class="l">{html.escape(t["test_id"])}</td>'
            f'<td class="l">{html.escape(cond)}</td><td class="l">{html.escape(t["status"])}'
            f'</td><td class="l">{links}</td></tr>'
        )
    rep.raw(
        '<table><thead><tr><th class="l">test</th><th class="l">conditions</th>'
        '<th class="l">status</th><th class="l">documents</th></tr></thead><tbody>'
        + "".join(rows)
        + "</tbody></table>"
    )
    return rep.render()


def write_campaign_report(results: Any, out_dir: str | Path) -> Path:
    """Write ``out_dir/report.html`` atomically; returns its path."""
    path = Path(out_dir) / "report.html"
    text = campaign_report(results)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path
