"""A small builder for one self-contained, offline-readable HTML file.

The builder holds sections of already-escaped HTML; figures are rendered to
PNG and embedded as base64 data URIs, so the file needs nothing beside it.
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Sequence
from typing import Any

__all__ = ["HtmlReport"]

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1100px;color:#222;line-height:1.45;padding:0 1em}
h1{border-bottom:2px solid #345;padding-bottom:.2em}h2{margin-top:2em;color:#234}
table{border-collapse:collapse;margin:.6em 0 1.2em 0;font-size:.92em}
th,td{border:1px solid #bbb;padding:.25em .6em;text-align:right}
th{background:#eef2f6}td.l,th.l{text-align:left}
figure{margin:1em 0}figcaption{font-size:.9em;color:#555}
img{max-width:100%}.note{background:#f6f6ee;border-left:4px solid #cc9;padding:.5em 1em}
.ok{color:#185}.bad{color:#a22}code{background:#f3f3f3;padding:0 .2em}
nav.toc{background:#f4f6f9;padding:.3em 1em;border:1px solid #dde}nav.toc ul{margin:.3em 0}
.verdict{padding:.4em 1em;margin:.6em 0;border-left:4px solid #185;background:#eef7f1}
.verdict.expected{border-left-color:#678;background:#f2f4f7;color:#222}
.verdict.nj{border-left-color:#999;background:#f5f5f5}
.verdict.bad{border-left-color:#c22;background:#fdeeee;color:#a11;font-weight:600}
.warn{border-left:4px solid #d80;background:#fff6e8;padding:.3em 1em;margin:.6em 0}
.warn.bad{border-left-color:#c22;background:#fdeeee;color:#a11}
.warn ul{margin:.2em 0}
ul.findings{padding-left:1.2em}ul.findings li{margin:.25em 0;padding-left:.4em;
border-left:4px solid #bbb;list-style:none}
ul.findings li.ok{border-left-color:#185;color:#222}
ul.findings li.expected{border-left-color:#678}
ul.findings li.warning{border-left-color:#d80}
ul.findings li.failed{border-left-color:#c22;color:#a11;font-weight:600}
@page{size:A4;margin:12mm 12mm 14mm 12mm}
@media print{body{max-width:none;margin:0;padding:0;font-size:9.5pt;line-height:1.3}
nav.toc{display:none}h1{font-size:16pt;margin:0 0 .3em 0}
h2{break-before:page;margin-top:0}h2#s1{break-before:auto}h2,h3,h4{break-after:avoid}
figure,table,.verdict,.warn,ul.findings li{break-inside:avoid}
figure{margin:.5em 0}img{max-height:23cm;max-width:100%;width:auto}
a{color:inherit;text-decoration:none}
.first table{font-size:8.5pt;margin:.3em 0 .6em 0}.first td,.first th{padding:.1em .4em;
text-align:left}
.first p{margin:.3em 0}ul.findings{margin:.2em 0}ul.findings li{margin:.15em 0}
.verdict,.warn,ul.findings li{-webkit-print-color-adjust:exact;print-color-adjust:exact}}
"""


class HtmlReport:
    """Accumulate headings, text, tables and figures; render one HTML page.

    Parameters
    ----------
    title : str
        Page title and top heading.
    toc : bool
        Put a table of contents of the level-2 headings under the title
        (links within the page; default True).
    """

    def __init__(self, title: str, toc: bool = True) -> None:
        self.title = title
        self.toc = toc
        self._parts: list[str] = []
        self._sections: list[tuple[str, str]] = []

    def heading(self, text: str, level: int = 2, anchor: str | None = None) -> None:
        """Add a heading (level 2-4); level-2 headings get an anchor and a TOC entry.

        ``anchor`` gives a level-3 or level-4 heading an ``id`` to link to.
        """
        lvl = min(max(int(level), 2), 4)
        if lvl == 2:
            anchor = f"s{len(self._sections) + 1}"
            self._sections.append((anchor, text))
            self._parts.append(f'<h2 id="{anchor}">{html.escape(text)}</h2>')
        else:
            ident = f' id="{html.escape(anchor)}"' if anchor else ""
            self._parts.append(f"<h{lvl}{ident}>{html.escape(text)}</h{lvl}>")

    def paragraph(self, text: str, css_class: str | None = None) -> None:
        """Add a paragraph of plain text (escaped)."""
        cls = f' class="{html.escape(css_class)}"' if css_class else ""
        self._parts.append(f"<p{cls}>{html.escape(text)}</p>")

    def bullets(self, items: Sequence[str]) -> None:
        """Add a bulleted list of plain-text items."""
        lis = "".join(f"<li>{html.escape(s)}</li>" for s in items)
        self._parts.append(f"<ul>{lis}</ul>")

    def table(
        self,
        header: Sequence[str],
        rows: Sequence[Sequence[Any]],
        caption: str | None = None,
        fmt: str = "{:.4g}",
    ) -> None:
        """Add a table; floats are formatted with ``fmt``, first column left-aligned."""

        def cell(v: Any, first: bool, tag: str) -> str:
            s = fmt.format(v) if isinstance(v, float) else str(v)
            cls = ' class="l"' if first else ""
            return f"<{tag}{cls}>{html.escape(s)}</{tag}>"

        head = "".join(cell(h, i == 0, "th") for i, h in enumerate(header))
        body = "".join(
            "<tr>" + "".join(cell(v, i == 0, "td") for i, v in enumerate(r)) + "</tr>" for r in rows
        )
        cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
        self._parts.append(
            f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
        )

    def figure(self, fig: Any, caption: str = "", dpi: int = 110) -> bytes:
        """Embed a matplotlib figure as PNG; returns the PNG bytes (to save beside)."""
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi)
        png = buf.getvalue()
        self.image(png, caption)
        return png

    def image(self, png: bytes, caption: str = "") -> None:
        """Embed PNG bytes."""
        b64 = base64.b64encode(png).decode("ascii")
        cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
        self._parts.append(
            f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{b64}">'
            f"{cap}</figure>"
        )

    def raw(self, fragment: str) -> None:
        """Add a trusted HTML fragment as is."""
        self._parts.append(fragment)

    def render(self) -> str:
        """The whole page as one string (with a table of contents of the level-2 headings
        when there are three or more and ``toc`` is set)."""
        parts = list(self._parts)
        if self.toc and len(self._sections) >= 3:
            items = "".join(
                f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t in self._sections
            )
            parts.insert(0, f'<nav class="toc"><ul>{items}</ul></nav>')
        body = "\n".join(parts)
        t = html.escape(self.title)
        return (
            '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{t}</title><style>{_CSS}</style></head><body><h1>{t}</h1>\n"
            f"{body}\n</body></html>\n"
        )
