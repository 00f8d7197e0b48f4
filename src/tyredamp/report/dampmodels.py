"""The damping-model section of the demo report: the models ranked, the truth beside them."""

from __future__ import annotations

from typing import Any

from .html import HtmlReport

__all__ = ["DAMPMODELS_HEADING", "dampmodels_report"]

#: Heading of the section.
DAMPMODELS_HEADING = "Which damping model does the tyre have?"


def dampmodels_report(rep: HtmlReport, doc: dict[str, Any]) -> None:
    """Add the section from ``doc["damping_models"]`` (nothing when the demo did not run it)."""
    sec = doc.get("damping_models")
    if not sec:
        return
    truth, fitted = sec["truth"], sec["fitted"]
    lo, hi = sec["band_hz"]
    rep.heading(DAMPMODELS_HEADING)
    rep.paragraph(
        f"The virtual tyre with a tread rubber (fractional Zener law) on its sidewalls and "
        f"band, reduced to its {len(truth['frequency_hz'])} modes between {lo:.0f} and "
        f"{hi:.0f} Hz: exact receptances at the 16 points, driven at one, with noise at "
        f"{sec['snr_db']:g} dB ({sec['n_lines']} lines). Every damping model fitted to "
        "them and ranked by BIC (lower is better); nested models tested by likelihood "
        "ratio. In this band the rubber is the fractional model C' s^alpha with the "
        f"rubber's alpha = {truth['alpha']:g}."
    )
    rep.table(
        ["model", "parameters", "chi2", "BIC", "BIC - best"],
        [
            [m["model"], m["n_params"], f"{m['chi2']:.1f}", f"{m['bic']:.1f}", m["delta_bic"]]
            for m in sec["models"]
        ],
        caption=f"{sec['n_data']} real data; chi2 near the data count means the model "
        "reaches the noise",
    )
    rep.table(
        ["simpler model", "within", "Lambda", "df", "p", "simpler model rejected"],
        [
            [
                t["simple"],
                t["complex"],
                t["statistic"],
                t["df"],
                f"{t['p_value']:.3g}",
                "yes" if t["rejected"] else "no",
            ]
            for t in sec["tests"]
        ],
        caption="likelihood-ratio tests",
    )
    rows = [["model", truth["model"], sec["best"]]]
    if fitted is not None:
        rows.append(
            [
                "alpha",
                f"{truth['alpha']:.3f}",
                f"{fitted['alpha']:.3f} +- {fitted['alpha_std']:.3f}",
            ]
        )
        for k, (ft, ff) in enumerate(
            zip(truth["frequency_hz"], fitted["frequency_hz"], strict=True), start=1
        ):
            rows.append([f"mode {k} frequency, Hz", f"{ft:.2f}", f"{ff:.2f}"])
    rep.table(["", "truth", "identified"], rows, caption="the truth beside the verdict")
    rep.paragraph(f"Verdict: {sec['verdict']}.")
