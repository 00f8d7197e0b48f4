"""The rolling-tyre section of the demo report: each exact wave beside the identified one."""

from __future__ import annotations

from typing import Any

from .html import HtmlReport

__all__ = ["ROLLING_HEADING", "rolling_report"]

#: Heading of the section.
ROLLING_HEADING = "The rolling tyre, identified output-only"


def _rows(waves: list[dict[str, Any]]) -> list[list[Any]]:
    out = []
    for w in waves:
        z = w["damping_ratio"]
        out.append(
            [
                f"n={w['wave_number']} {w['direction']}",
                w["truth_hz"],
                "not found" if not w["found"] else w["frequency_hz"],
                "" if w["f_error_pct"] is None else f"{w['f_error_pct']:+.2f} %",
                100 * w["truth_damping_ratio"],
                "" if z is None else 100 * z,
            ]
        )
    return out


def rolling_report(rep: HtmlReport, doc: dict[str, Any]) -> None:
    """Add the section from ``doc["rolling"]`` (nothing when the demo did not run it)."""
    sec = doc.get("rolling")
    if not sec:
        return
    rep.heading(ROLLING_HEADING)
    rep.paragraph(
        "The rotating virtual tyre under a random road force, recorded by 16 sensors fixed "
        f"round it and one inside it ({sec['duration_s']:g} s at 512 Hz), identified without "
        "the force: SSI on the fixed sensors, each mode split into its forward and backward "
        "waves; the in-tyre peaks resolved through f_fixed = f_in_tyre +- n f_wheel. "
        "Direction is on the tyre (forward: with the rotation). Frequencies in Hz, "
        "damping ratios in %."
    )
    head = ["wave", "exact Hz", "identified Hz", "error", "exact zeta %", "identified zeta %"]
    for s in sec["speeds"]:
        rep.heading(f"{s['speed_kmh']:g} km/h (wheel {s['wheel_speed_hz']:.3f} Hz)", level=3)
        rep.paragraph(
            f"{sum(w['found'] for w in s['fixed'])} of {len(s['fixed'])} exact waves found by "
            f"the fixed sensors; {s['false_modes']} identified wave(s) match no exact one; "
            f"{s['unresolved_in_tyre']} in-tyre peak(s) not resolved."
        )
        rep.table(head, _rows(s["fixed"]), caption="fixed sensors (fixed frame)")
        rep.table(head, _rows(s["in_tyre"]), caption="in-tyre sensor (rotating frame)")
