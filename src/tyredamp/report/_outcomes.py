"""Fit verdicts and findings in the demo report: each stated once, by its outcome.

A fit within the noise is a green line; a miss the other fits of the same data
explain (:attr:`tyredamp.studies.verdicts.FitVerdict.outcome` ``"expected"``)
is a neutral block whose cause is explained once in the page; a genuine
failure is stated once, in red, beside its result. The summary lists every
finding once (:func:`tyredamp.studies.findings.outcome_groups`) with links to
the results.
"""

from __future__ import annotations

import html
import math
from typing import Any

from ..studies.findings import outcome_groups, verdict_outcome
from ..studies.verdicts import CAUSE_MEANING
from ._cells import anchor_id
from .html import HtmlReport

__all__: list[str] = []


def _verdict(rep: HtmlReport, v: dict[str, Any] | None) -> None:
    """A fit verdict by its outcome: green within the noise, neutral for a miss the data
    explain (an identification result), red with its reasons for a genuine failure."""
    if v is None:
        return
    cls = {"ok": "verdict", "expected": "verdict expected", "failed": "verdict bad"}.get(
        verdict_outcome(v), "verdict nj"
    )
    rep.raw(f'<div class="{cls}">{html.escape(v["summary"])}</div>')


class _Page:
    """What the page has stated so far: each expected cause is explained once, each
    result gets one anchor (the first block that concerns it)."""

    def __init__(self) -> None:
        self.explained: dict[str, str] = {}  # cause -> anchor where it is explained
        self.anchored: set[str] = set()

    def anchor(self, about: str) -> str:
        """`` id="..."`` for the first element about a result, else ``""``."""
        a = anchor_id(about)
        if a in self.anchored:
            return ""
        self.anchored.add(a)
        return f' id="{a}"'


def _residual(v: dict[str, Any]) -> str:
    q = v.get("residual_to_noise")
    if q is None:
        return ""
    text = f"residual {math.sqrt(q):.3g}x the noise"
    rel, noise = v.get("relative_error"), v.get("noise_relative_error")
    if rel is not None and noise is not None:
        text += f" (relative error {100 * rel:.3g} % against {100 * noise:.3g} % from noise alone)"
    return text


def _verdict_block(rep: HtmlReport, page: _Page, items: list[tuple[str, dict[str, Any]]]) -> None:
    """The verdicts of the fits of a result, beside it: those within the noise on one
    line, the expected misses of one cause in one neutral block (its meaning said once
    in the page), each genuine failure in red with its reasons."""
    ok = [(a, v) for a, v in items if verdict_outcome(v) == "ok"]
    if ok:
        text = "; ".join(
            f"<span{page.anchor(a)}>{html.escape(v['subject'])}</span>: "
            + html.escape(_residual(v) or "within the noise")
            for a, v in ok
        )
        rep.raw(f'<div class="verdict">Within the noise: {text}</div>')
    causes: dict[str, list[tuple[str, dict[str, Any]]]] = {}
    for a, v in items:
        if verdict_outcome(v) == "expected":
            causes.setdefault(v.get("expected_cause", ""), []).append((a, v))
    for cause, group in causes.items():
        lines = []
        for a, v in group:
            extra = [r for r in v["reasons"] if r.startswith("its refinement fell back")]
            where = v.get("misfit_hz")
            text = _residual(v) + (
                f", the misfit at {where[0]:.4g}-{where[1]:.4g} Hz" if where else ""
            )
            lines.append(
                f"<li{page.anchor(a)}>{html.escape(v['subject'])}: "
                f"{html.escape('; '.join([text, *extra]))}</li>"
            )
        key = f"expected-{anchor_id(cause)}"
        if cause in page.explained:
            why = f'as explained <a href="#{page.explained[cause]}">above</a>: ' + html.escape(
                cause
            )
            ident = ""
        else:
            meaning = CAUSE_MEANING.get(cause) or group[0][1].get("outcome_reason", "")
            why = html.escape(meaning[0].upper() + meaning[1:] if meaning else "")
            page.explained[cause] = key
            ident = f' id="{key}"'
        rep.raw(
            f'<div class="verdict expected"{ident}><b>Not within the noise, as the data explain '
            f"({html.escape(cause)})</b><ul>{''.join(lines)}</ul>{why}.</div>"
        )
    for a, v in items:
        out = verdict_outcome(v)
        if out == "failed":
            rep.raw(f'<div class="verdict bad"{page.anchor(a)}>{html.escape(v["summary"])}</div>')
        elif out not in ("ok", "expected"):
            rep.raw(f'<div class="verdict nj"{page.anchor(a)}>{html.escape(v["summary"])}</div>')


def _status(v: dict[str, Any] | None) -> str:
    """A verdict in a table cell: the outcome only (it is stated in full beside its fit)."""
    if v is None:
        return "-"
    out = verdict_outcome(v)
    if out == "expected":
        return f"expected ({v.get('expected_cause', '')})"
    return {"ok": "within noise", "failed": "failed (see below)"}.get(out, out)


def _links(about: tuple[str, ...], labels: tuple[str, ...]) -> str:
    return "; ".join(
        f'<a href="#{anchor_id(a)}">{html.escape(lab)}</a>'
        for a, lab in zip(about, labels, strict=True)
    )


def _findings(rep: HtmlReport, doc: dict[str, Any]) -> None:
    """The findings, each once, with links to where each result is stated in full."""
    rep.heading("Findings", 3)
    items = []
    groups = outcome_groups(doc)
    if not any(g.outcome == "failed" for g in groups):
        items.append(
            '<li class="ok">No genuine failure: every fit that should hold holds and every '
            "check passes.</li>"
        )
    for g in groups:
        links = _links(g.about, g.labels)
        title = html.escape(g.title)
        span = g.residual + " the noise" if g.residual else ""
        if g.outcome == "failed":
            if g.stage:  # a check or the tyre model: its name is the link
                items.append(f'<li class="failed">{links}: failed.</li>')
                continue
            what = "does not fit within the noise" if span.startswith("residual") else "failed"
            text = f"{title}: {what}" + (f" ({html.escape(span)})" if span else "")
            items.append(f'<li class="failed">{text}: see {links}.</li>')
        elif g.outcome == "expected":
            items.append(
                f'<li class="expected">{title}: not within the noise ({html.escape(span)}), as '
                f"the data explain: {html.escape(g.cause)} ({links}).</li>"
            )
        elif g.outcome == "ok":
            items.append(
                f'<li class="ok">{title}: within the noise'
                + (f" ({html.escape(span)})" if span else "")
                + f" ({links}).</li>"
            )
        else:
            items.append(f'<li class="expected">{title}: {html.escape(g.detail)} ({links}).</li>')
    counts: dict[tuple[str, str], int] = {}
    for w in doc.get("warnings", []):
        if w["severity"] == "warning":
            k = (w["about"], w["stage"])
            counts[k] = counts.get(k, 0) + 1
    if counts:
        links = ", ".join(
            f'<a href="#{anchor_id(a)}">{html.escape(st)}</a> ({n})'
            for (a, st), n in counts.items()
        )
        items.append(f'<li class="warning">Cautions beside their results: {links}.</li>')
    rep.raw(f'<ul class="findings">{"".join(items)}</ul>')
