"""The lateral-study section of the demo report: the rolling-tyre rig's FRFs fitted.

:func:`lateral_report` writes the section of :func:`~tyredamp.report.build.build_demo_report`
on the lateral study: the corner frequency and asymptotes of the proposed model
(Figure 7, eq. 38-40), the ranking of the models over every condition and the
Table 1 analogue, each condition's corner frequency and tyre-road damper beside
the rig's ``C_alpha/V`` with its verdict against the noise, the fitted
parameters at the reference condition beside the rig's own values, the
measured against predicted FRFs (Figures 11-14), and the vehicle model with its
time response and the causality of the hysteretic tyre (eq. 41-42, Figure 15).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ._cells import _images, _num, _pct, _warnings, anchor_id, fmt_pm
from ._outcomes import _Page, _status, _verdict_block
from .html import HtmlReport

if TYPE_CHECKING:
    from ..studies.results import DemoResult

__all__ = ["lateral_report"]


def lateral_report(
    rep: HtmlReport,
    result: DemoResult,
    doc: dict[str, Any],
    images: Any,
    page: _Page,
    heading: str,
) -> None:
    """The lateral study's section, under ``heading`` (level 2), into ``rep``
    (``page``: what the page has stated so far, :class:`~tyredamp.report._outcomes._Page`)."""
    lat = doc["lateral"]
    rep.heading(heading)
    f7 = lat["figure7"]
    rep.heading("Corner frequency and asymptotes (eq. 38-40)", 3)
    r = f7["h"] / f7["K"]
    rep.paragraph(
        f"With the parameters of the paper's Figure 7 (h/K = {r:.3f}) the corner frequency is "
        f"f0 = K/(2 pi C_r) = {f7['f0_hz']:.4g} Hz (eq. 38); at f0 the model lies "
        f"{f7['delta_ar_asymptote_db']:.3f} dB above its high-frequency asymptote (eq. 39: "
        f"10 log10(2 + 2r + r^2)) and {f7['delta_ar_maxwell_db']:.4f} dB above the Maxwell "
        "model (eq. 40). The values the paper quotes, 3.87 dB and 0.694 dB, are those of "
        "h/K = 0.2."
    )
    _images(rep, images, "lateral:corner")

    _lateral_ranking(rep, lat)
    conds = lat["conditions"]
    rep.table(
        [
            "condition",
            "best",
            "f0 (Hz), eq. 38",
            "C_r fitted (kN s/m)",
            "C_alpha/V true (kN s/m)",
            "C_r / (C_alpha/V)",
            "best fit against the noise",
        ],
        [
            [
                c["label"],
                c["best"],
                fmt_pm(c["corner_frequency_hz"], c["corner_frequency_std_hz"]),
                fmt_pm(c["road_damping"]["fitted"], c["road_damping"]["stderr"], 4, 1e-3),
                _num(c["road_damping"]["true"] / 1e3, ".4g"),
                _num(c["road_damping"]["ratio"], ".3g"),
                _status(c["verdict"]),
            ]
            for c in conds
        ],
        caption="Corner frequency of the fitted proposed model and its tyre-road damper C_r "
        "beside C_alpha/V of the rig's tyre (eq. 33: the low-frequency limit of its "
        "mobility). The band starts at 0.25 Hz, near f0, so C_r is set mostly by the "
        "transition region, where the rig's stiffening foundation and contact length depart "
        "from the model: a model-form difference, not noise (compare the standard error).",
    )
    _verdict_block(rep, page, [(f"lateral:{c['label']}", c["verdict"]) for c in conds])
    for c in conds:
        _warnings(rep, doc, f"lateral:{c['label']}")
    _lateral_parameters(rep, result)
    rep.heading("Measured against predicted FRFs (paper Figs. 11-14)", 3)
    _images(rep, images, "lateral:frfs")

    _lateral_vehicle(rep, doc, images)


def _lateral_ranking(rep: HtmlReport, lat: dict[str, Any]) -> None:
    """The overall ranking and the Table 1 analogue (amplitude errors per condition)."""
    rep.heading("Model ranking", 3)
    rep.table(
        [
            "rank",
            "model",
            "mean rank",
            "best at",
            "mean d" + lat["criterion"].upper(),
            "amplitude error (%)",
            "amplitude bias (%)",
            "axle prediction error (%)",
            "within noise at",
        ],
        [
            [
                str(r["rank"]),
                r["model"],
                f"{r['mean_rank']:.2f}",
                f"{r['wins']} of {r['n_conditions']}",
                _num(r["mean_delta"], ".1f"),
                _num(r["mean_amplitude_error_pct"], ".2f"),
                _num(r["mean_amplitude_bias_pct"], "+.2f"),
                _num(r["mean_axle_amplitude_error_pct"], ".2f"),
                _within_noise(lat["conditions"], r["equivalent"][0]),
            ]
            for r in lat["ranking"]
        ],
        caption="Overall ranking over every condition (lower information criterion is better; "
        "amplitude errors as the paper's Table 1: mean relative error of the amplitude ratio)."
        + "".join(
            f" {' = '.join(g)}: one model in other parameters (fitted FRFs equal at every "
            "condition), ranked as one entry."
            for g in lat["equivalent_models"]
        ),
    )
    conds = lat["conditions"]
    models = lat["models"]
    header = ["model", *[c["label"] for c in conds]]
    rows = []
    for mdl in models:
        row = [mdl]
        for c in conds:
            t = next(x for x in c["table"] if x["model"] == mdl)
            mark = " *" if c["best"] == mdl else ""
            row.append(
                f"{t['amplitude_bias_pct']:+.1f} / {t['axle_amplitude_bias_pct']:+.1f}" + mark
            )
        rows.append(row)
    rep.table(
        header,
        rows,
        caption="Table 1 analogue: signed relative error (%) of the amplitude ratio, ground-force "
        "fit / axle-force prediction (positive: over-estimation); * best by "
        + lat["criterion"].upper()
        + " at that condition.",
    )


def _lateral_parameters(rep: HtmlReport, result: DemoResult) -> None:
    """Every fitted parameter at the reference condition beside the rig's own value."""
    ref = result.lateral.reference
    rep.paragraph(f"Ranking at {ref.label}:")
    rep.bullets(list(ref.ranking.reasons))
    rep.heading(f"Fitted parameters at {ref.label}", 3)
    rows = []
    truth = ref.truth
    for f in ref.ranking.fits:
        for n, u in zip(f.model.param_names, f.model.param_units, strict=True):
            if n == getattr(f.model, "road_damper", None):
                tv: float | None = ref.true_road_damping
                tname = "C_alpha/V"
            elif n in truth.params:
                tv, tname = float(truth.params[n]), n
            else:
                tv, tname = None, ""
            gap = "-" if tv is None or tv == 0 else f"{100 * (f.params[n] / tv - 1):+.3g} %"
            rows.append(
                [
                    f.name,
                    n,
                    fmt_pm(f.params[n], f.stderr[n]),
                    u,
                    "-" if tv is None else f"{tv:.4g} ({tname})",
                    gap,
                ]
            )
    rep.table(
        ["model", "parameter", "value ± standard error", "unit", "truth", "gap"],
        rows,
        caption="Each parameter beside the rig's own value where the rig's tyre has one: its "
        "cornering stiffness and relaxation length, and C_alpha/V for the tyre-road damper of "
        "each model (the low-frequency limit of the rig's mobility, eq. 33). The other "
        "parameters have no counterpart in the rig's tyre (a string with contact length).",
    )
    units = truth.to_dict().get("units", {})
    rep.paragraph(
        "Truth at this condition (viscoelastic string): "
        + ", ".join(
            f"{k} = {v:.4g}" + ("" if units.get(k, "-") == "-" else f" {units[k]}")
            for k, v in truth.params.items()
        )
        + f"; C_alpha/V = {ref.true_road_damping:.4g} N s/m."
    )


def _lateral_vehicle(rep: HtmlReport, doc: dict[str, Any], images: Any) -> None:
    lat = doc["lateral"]
    models = lat["models"]
    rep.heading("Vehicle model and time response", 3, anchor=anchor_id("lateral:time"))
    veh = lat["vehicle"]
    tr = lat["time_response"]
    rows = [
        [
            name,
            _num(veh["resonance_hz"].get(name), ".3f"),
            _pct(tr["relative_error"].get(name)),
            _pct(tr["error_to_truth"].get(name)),
        ]
        for name in models
    ]
    rows.append(
        ["rig truth", _num(veh["true_resonance_hz"], ".3f"), _pct(tr["truth_error"]), "0 %"]
    )
    worst = min(tr["error_to_truth"].values())
    rep.table(
        [
            "tyre model",
            "body resonance (Hz)",
            f"error against the measurement {tr['window_s'][0]:g}-{tr['window_s'][1]:g} s",
            "error against the rig's exact response",
        ],
        rows,
        caption=f"{veh['body_mass_kg']:g} kg body (eq. 41-42) on each tyre fitted at "
        f"{veh['pressure_bar']:g} bar, {veh['speed_kmh']:g} km/h; error = RMS of the "
        "difference over RMS of the reference. The rig's own exact response misses the "
        f"measurement by {_pct(tr['truth_error'])} (its noise alone); every fitted model misses "
        f"the exact response by {_pct(worst)} or more: a model-form gap at "
        f"{tr['frequency_hz']:g} Hz, not noise.",
    )
    _warnings(rep, doc, "lateral:time")
    _images(rep, images, "lateral:vehicle")
    ca = tr["causal"]
    rep.paragraph(
        f"Causality: the hysteretic tyre 1/(K + i h) is not causal; its impulse response has a "
        f"precursor of {_pct(ca['precursor_ratio'])} of the peak. The steady states above are "
        f"exact in the frequency domain. A causal generalised-Maxwell approximation "
        f"({ca['n_arms']} arms over {ca['band_hz'][0]:g}-{ca['band_hz'][1]:g} Hz) differs from "
        f"K + i h by up to {_pct(ca['stiffness_error'])}, changes the body FRF by up to "
        f"{_pct(ca['frf_error'])} and the {tr['frequency_hz']:g} Hz switched-on sine by "
        f"{_pct(ca['sine_error'])}."
    )


def _within_noise(conds: list[dict[str, Any]], model: str) -> str:
    """``"0 of 6 (residual 1.4-2.8x the noise)"``: conditions a model fits within the noise."""
    vs = [c["verdicts"][model] for c in conds if model in c.get("verdicts", {})]
    if not vs:
        return "-"
    ok = sum(1 for v in vs if v["passed"])
    r = [math.sqrt(v["residual_to_noise"]) for v in vs if v["residual_to_noise"] is not None]
    span = f" (residual {min(r):.2g}-{max(r):.2g}x the noise)" if r else ""
    return f"{ok} of {len(vs)}{span}"
