"""Self-contained HTML reports (figures embedded as PNG data URIs)."""

from __future__ import annotations

from .html import HtmlReport

__all__ = ["HtmlReport"]
