"""The report's section on an output-only identification (``tyredamp oma``).

Called for a modes document with ``"output_only": true``
(:mod:`tyredamp.documents.oma`): the method, references and sampling rate,
how the standard errors were found, the wave number and direction of each
mode, the harmonics kept out of the modes and the notes of the run.
"""

from __future__ import annotations

from typing import Any

from .html import HtmlReport

__all__ = ["oma_section"]


def oma_section(rep: HtmlReport, doc: dict[str, Any]) -> None:
    """Add the output-only facts of ``doc`` (a modes document) to ``rep``; nothing otherwise."""
    if not doc.get("output_only"):
        return
    o = doc.get("oma") or {}
    refs = ", ".join(str(r) for r in o.get("references", [])) or "?"
    wheel = o.get("wheel_speed_hz")
    rep.paragraph(
        f"Output-only data (operational modal analysis, {o.get('method', '?')}) at "
        f"{o.get('sample_rate_hz', float('nan')):g} Hz, reference channels {refs}; "
        f"standard errors: {o.get('uncertainty', '?')}. No force was measured: the mode "
        "shapes are not scaled" + (f"; wheel speed {wheel:.4g} Hz." if wheel else ".")
    )
    waves = o.get("waves")
    model = (doc.get("models") or {}).get("complex") or {}
    freqs = [m.get("frequency_hz") for m in model.get("modes", [])]
    if waves and len(waves) == len(freqs):
        rows = [
            [
                f"{f:.4g}",
                w["wave_number"],
                w["direction"],
                f"{100 * w['forward_share']:.0f} %",
                f"{100 * w['explained']:.0f} %",
                ", ".join(str(a) for a in w.get("aliases", [])) or "-",
            ]
            for f, w in zip(freqs, waves, strict=True)
        ]
        rep.table(
            ["f [Hz]", "wave number", "direction", "forward share", "explained", "aliases"],
            rows,
            caption="Travelling waves of each mode (sensor angles around the tyre).",
        )
    harm = o.get("harmonics") or []
    if harm:
        rep.table(
            ["f [Hz]", "kurtosis", "z", "wheel order"],
            [[h["frequency_hz"], h["kurtosis"], h["z"], h.get("wheel_order") or "-"] for h in harm],
            caption="Harmonics kept out of the modes (kurtosis 1.5 a sinusoid, 3 random).",
        )
    notes = o.get("notes") or []
    if notes:
        rep.bullets([str(n) for n in notes])
