"""Cells and blocks shared by the demo report's sections (values with errors, warnings)."""

from __future__ import annotations

import html
import math
import re
from collections.abc import Mapping
from typing import Any, NamedTuple

from .html import HtmlReport

__all__ = ["ReportImage", "anchor_id", "fmt_pm"]


def fmt_pm(value: float | None, std: float | None, digits: int = 4, scale: float = 1.0) -> str:
    """``"47.91 ± 0.012"``: a value with its standard error (``-`` when missing)."""
    if value is None or not math.isfinite(value):
        return "-"
    v = value * scale
    if std is None or not math.isfinite(std):
        return f"{v:.{digits}g}"
    return f"{v:.{digits}g} ± {std * scale:.2g}"


def _num(v: Any, spec: str = ".4g") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, spec)


def _pct(v: Any, digits: str = ".3g") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{100 * v:{digits}} %"


class ReportImage(NamedTuple):
    """A rendered plot of the demo report: PNG bytes, caption and place
    (a key of :data:`tyredamp.report.plots.PLACES`; empty: shown nowhere)."""

    png: bytes
    caption: str
    section: str = ""


def _images(rep: HtmlReport, images: Mapping[str, ReportImage], section: str) -> None:
    """Every image of ``section`` with its caption, in the order of ``images``."""
    for img in images.values():
        if img.section == section:
            rep.image(img.png, img.caption)


def anchor_id(about: str) -> str:
    """The page anchor of a result by its ``about`` key (``"radial:7.5"`` -> ``"radial-7-5"``)."""
    return re.sub(r"[^a-z0-9]+", "-", about.lower()).strip("-")


def _warnings(rep: HtmlReport, doc: dict[str, Any], about: str) -> None:
    """The warnings of the stage that produced a result, beside that result.

    Only findings of severity ``"warning"``: a fit verdict and a failed stage are
    stated by their result's own block (once).
    """
    ws = [w for w in doc.get("warnings", []) if w["about"] == about and w["severity"] == "warning"]
    if not ws:
        return
    items = "".join(f"<li>{html.escape(w['message'])}</li>" for w in ws)
    rep.raw(
        f'<div class="warn"><b>Cautions ({html.escape(ws[0]["stage"])})</b><ul>{items}</ul></div>'
    )
