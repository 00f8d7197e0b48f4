"""The demo's HTML report: results and figures into one self-contained page.

:func:`build_demo_report` lays out the page from a
:class:`~tyredamp.studies.demo.DemoResult`, its results document
(:func:`tyredamp.studies.document.build_results`) and the rendered figures
(:func:`tyredamp.report.figures.demo_figures`). Sections: summary, inputs and
settings, the radial study (checks, stabilisation, modes with standard errors
beside the truth, real against complex fit, mode shapes, damping matrices with
diagnostics in words, pressures) and the lateral study (Figure 7, ranking,
parameters beside the truth, Figures 11-14, vehicle model and Figure 15).
The report for result files of the other commands is
:func:`tyredamp.report.files.build_files_report`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from .. import __version__
from .html import HtmlReport

if TYPE_CHECKING:
    from ..studies.results import DemoResult

__all__ = ["SECTIONS", "build_demo_report", "fmt_pm"]

#: Level-2 headings of the demo report, in order (the tests look for them).
SECTIONS = (
    "Summary",
    "Inputs and settings",
    "Radial study: modal test of the virtual truck tyre",
    "Lateral study: rolling-tyre rig",
    "Files",
)


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


def _image(rep: HtmlReport, images: Mapping[str, tuple[bytes, str]], name: str) -> None:
    if name in images:
        png, caption = images[name]
        rep.image(png, caption)


def _modes_table(rep: HtmlReport, modes: list[dict[str, Any]], caption: str) -> None:
    rows = []
    for k, m in enumerate(modes):
        t, c, r = m["true"], m["complex"], m["real"]
        rows.append(
            [
                str(k + 1),
                "-" if m["wave_number"] is None else str(m["wave_number"]),
                "-" if t is None else f"{t['frequency_hz']:.3f}",
                "-" if c is None else fmt_pm(c["frequency_hz"], c["frequency_std_hz"], 6),
                "-" if r is None else fmt_pm(r["frequency_hz"], r["frequency_std_hz"], 6),
                "-" if t is None else f"{100 * t['damping_ratio']:.3f}",
                "-" if c is None else fmt_pm(c["damping_ratio"], c["damping_ratio_std"], 4, 100),
                "-" if r is None else fmt_pm(r["damping_ratio"], r["damping_ratio_std"], 4, 100),
                "-" if t is None else f"{t['mpc']:.4f}",
                "-" if c is None or c["mpc"] is None else f"{c['mpc']:.4f}",
            ]
        )
    rep.table(
        [
            "#",
            "n",
            "f true (Hz)",
            "f complex (Hz)",
            "f real (Hz)",
            "zeta true (%)",
            "zeta complex (%)",
            "zeta real (%)",
            "MPC true",
            "MPC complex",
        ],
        rows,
        caption=caption,
    )


def _summary(rep: HtmlReport, result: DemoResult, doc: dict[str, Any]) -> None:
    rad, lat = doc["radial"], doc["lateral"]
    dmp = rad["damping"]
    best = lat["ranking"][0]
    rep.heading(SECTIONS[0])
    rep.paragraph(
        "Both studies of the papers run end to end on virtual tyres with a known truth; every "
        "identified value below stands beside the exact value of the virtual tyre or rig."
        + (" Reduced setting (--quick)." if result.settings.quick else "")
    )
    rep.table(
        ["quantity", "value"],
        [
            [
                f"RMSD of the real-mode fit at {rad['pressure_bar']:g} bar (eq. [19])",
                _num(rad["rmsd_real"]),
            ],
            ["RMSD of the complex-mode fit", _num(rad["rmsd_complex"])],
            [
                "real / complex RMSD (paper: 0.0011 / 0.00053, about 2)",
                _num(rad["rmsd_ratio"], ".3g"),
            ],
            [
                "relative fit error real / complex",
                f"{_pct(rad['relative_error_real'])} / {_pct(rad['relative_error_complex'])}",
            ],
            [
                "modes identified / visible true modes",
                f"{sum(1 for m in rad['modes'] if m['complex'])} / "
                f"{sum(1 for m in rad['modes'] if m['true'])}",
            ],
            [
                "damping C' against the truth (Frobenius, raw / symmetric part)",
                f"{_pct(dmp['modal_error'])} / {_pct(dmp['modal_error_symmetric'])}",
            ],
            ["C' in modal coordinates", dmp["definiteness_modal"]],
            [
                "best lateral model over all conditions (mean rank)",
                f"{best['model']} ({best['mean_rank']:.2g}, best at {best['wins']} of "
                f"{best['n_conditions']} conditions)",
            ],
            ["computation time", f"{result.elapsed_s:.1f} s"],
        ],
    )


def _excitation(meta: dict[str, Any], force_rms: float) -> str:
    exc = meta.get("excitation", "")
    kind = exc.get("kind", "") if isinstance(exc, dict) else str(exc)
    band = meta.get("band_hz") or [float("nan"), float("nan")]
    kind = kind.replace("_", " ")
    if not kind.startswith("periodic"):
        kind = f"periodic {kind}"
    return f"{kind}, {band[0]:g}-{band[1]:g} Hz, {force_rms:g} N RMS"


def _settings(rep: HtmlReport, result: DemoResult, doc: dict[str, Any]) -> None:
    s = result.settings
    main = result.radial.main
    tp = main.test.tyre.params
    lay = main.test.tyre.layout
    meta = main.test.meta
    rig = result.lateral.rig
    rep.heading(SECTIONS[1])
    rep.table(
        ["virtual truck tyre (paper 000)", "value"],
        [
            ["model", "in-plane ring on an elastic foundation, staggered finite differences"],
            ["degrees of freedom", str(main.test.tyre.n_dof)],
            ["belt radius, width", f"{tp.radius:g} m, {tp.width:g} m"],
            [
                "band mass per length, bending stiffness",
                f"{tp.mass_per_length:g} kg/m, {tp.bending_stiffness:g} N m^2",
            ],
            ["pressures", ", ".join(f"{p:g} bar" for p in s.radial_pressures_bar)],
            [
                "points, drive point",
                f"{lay.n_points} radial points 22.5 deg apart, shaker at "
                f"point {lay.drive_points[0]}",
            ],
            ["non-proportional damping knob", f"{main.test.tyre.nonproportionality:g}"],
            ["excitation", _excitation(meta, s.force_levels_n[0])],
            [
                "sampling",
                f"{main.test.data.sample_rate:g} Hz, period "
                f"{main.test.period_samples / main.test.data.sample_rate:g} s",
            ],
            [
                "averages",
                f"{s.radial_periods} at {s.radial_pressures_bar[0]:g} bar, "
                f"{s.radial_side_periods} at the other pressures, {s.check_periods} for the checks",
            ],
            ["noise", f"{s.snr_db:g} dB SNR on every channel"],
            ["FRF estimator", "H1, cyclic (whole periods, no window)"],
            [
                "modal fits",
                "pLSCF poles, automatic selection, LSFD and refinement of real "
                "(eq. [2]/[3]) and complex (eq. [10]) modes with residual terms",
            ],
            [
                "damping",
                f"{s.damping_method} (eq. [16]/[18]), {s.damping_samples} Monte Carlo "
                "samples for standard errors",
            ],
        ],
    )
    rep.table(
        ["rolling-tyre rig (paper 001)", "value"],
        [
            [
                "truth",
                "viscoelastic stretched string with contact length (not one of the fitted models)",
            ],
            ["speeds", ", ".join(f"{v:g} km/h" for v in s.lateral_speeds_kmh)],
            ["pressures", ", ".join(f"{p:g} bar" for p in s.lateral_pressures_bar)],
            ["FRF lines", f"{rig.f_min:g}-{rig.f_max:g} Hz every {rig.df:g} Hz"],
            ["noise", f"{100 * rig.relative_noise:g} % relative per line"],
            ["wheel mass, body mass", f"{rig.wheel_mass:g} kg, {rig.body_mass:g} kg"],
            ["models fitted", ", ".join(s.lateral_models)],
            ["ranking criterion", doc["lateral"]["criterion"].upper()],
            [
                "time test",
                f"{s.time_test_frequency_hz:g} Hz sine at "
                f"{s.reference_condition[0]:g} bar, {s.reference_condition[1]:g} km/h",
            ],
        ],
    )
    rep.paragraph(f"tyredamp {__version__}, seed {s.seed}.")


def _radial(rep: HtmlReport, result: DemoResult, doc: dict[str, Any], images: Any) -> None:
    rad = doc["radial"]
    r = result.radial
    p = f"{rad['pressure_bar']:g} bar"
    rep.heading(SECTIONS[2])
    rep.heading("Linearity, reciprocity and data quality", 3)
    rep.bullets([c.summary for c in (r.linearity, r.reciprocity, r.quality)])
    rep.paragraph(
        "A linear model with a symmetric damping matrix needs both checks to pass. The quality "
        "check counts lines with coherence below 0.9; on this tyre they lie at the "
        "anti-resonances and below the first mode, where the response is small."
    )
    _image(rep, images, "checks")

    rep.heading("Stabilisation diagram", 3)
    _image(rep, images, "stabilisation")
    ident = r.main.identification
    if ident.rejected:
        rep.paragraph(
            "Candidates rejected: "
            + "; ".join(f"{x['frequency_hz']:.1f} Hz ({x['reason']})" for x in ident.rejected[:8])
            + ("; ..." if len(ident.rejected) > 8 else "")
        )

    rep.heading("Modes: identified with standard errors, beside the truth", 3)
    _modes_table(
        rep,
        rad["modes"],
        f"Modes at {p}: exact values of the virtual tyre, complex-mode and real-mode fits "
        "(± one standard error); n = circumferential wave number; MPC = modal phase "
        "collinearity (1 for a real mode).",
    )

    rep.heading("Real versus complex modes", 3)
    rep.table(
        ["fit", "RMSD (eq. [19])", "relative error", "modes"],
        [
            [
                "real modes (eq. [2]/[3])",
                _num(rad["rmsd_real"]),
                _pct(rad["relative_error_real"]),
                str(r.main.models["real"].n_modes),
            ],
            [
                "complex modes (eq. [10])",
                _num(rad["rmsd_complex"]),
                _pct(rad["relative_error_complex"]),
                str(r.main.models["complex"].n_modes),
            ],
        ],
        caption=f"Fit quality at {p} over {rad['n_lines']} lines and 16 FRFs ({rad['frf_kind']}, "
        f"{r.main.fitted_frf.unit}).",
    )
    ratio = rad["rmsd_ratio"]
    rep.paragraph(
        f"The complex-mode fit is {_num(ratio, '.3g')} times better in RMSD (the paper found "
        "about 2 on the real tyre). The modes are nearly real (MPC close to 1: near-"
        "proportional damping), yet the complex description fits better because the damping "
        "couples the modes (off-diagonal C')."
    )
    for name in ("fig02_real_fit", "fig03_complex_fit", "fig04_discrepancy"):
        _image(rep, images, name)
    rep.heading("Mode shapes", 3)
    _image(rep, images, "mode_shapes")

    _radial_damping(rep, rad["damping"], images)
    _radial_pressures(rep, rad["pressures"], images)


def _radial_damping(rep: HtmlReport, dmp: dict[str, Any], images: Any) -> None:
    rep.heading("Damping matrices", 3)
    rep.table(
        ["diagnostic", "value"],
        [
            ["method", f"{dmp['method']} ({dmp['n_modes']} modes at {dmp['n_points']} points)"],
            ["C' against the true C' (matched modes)", _pct(dmp["modal_error"])],
            ["its symmetric part against the truth", _pct(dmp["modal_error_symmetric"])],
            ["diagonal of C' against the truth", _pct(dmp["diagonal_error"])],
            ["symmetric C at the points against the true reduced C", _pct(dmp["physical_error"])],
            ["asymmetry of C'", _pct(dmp["symmetry_modal"])],
            ["definiteness of C'", dmp["definiteness_modal"]],
            [
                "non-proportionality ||C' - diag C'|| / ||diag C'||",
                _pct(dmp["non_proportionality"]),
            ],
            ["negative off-diagonal entries of C", _pct(dmp["negative_offdiagonal_fraction"])],
        ],
    )
    rep.paragraph("What the numbers say:")
    rep.bullets(dmp["findings"])
    _image(rep, images, "fig05_damping")


def _radial_pressures(rep: HtmlReport, pressures: list[dict[str, Any]], images: Any) -> None:
    rep.heading("Inflation pressure", 3)
    rows = []
    for pr in pressures:
        ident_n = sum(1 for m in pr["modes"] if m["complex"])
        true_n = sum(1 for m in pr["modes"] if m["true"])
        fr = ", ".join(
            f"{m['complex']['frequency_hz']:.1f}" if m["complex"] else "-" for m in pr["modes"]
        )
        ft = ", ".join(
            f"{m['true']['frequency_hz']:.1f}" if m["true"] else "-" for m in pr["modes"]
        )
        rows.append(
            [
                f"{pr['pressure_bar']:g}",
                str(pr["n_averages"]),
                f"{ident_n} / {true_n}",
                fr,
                ft,
                _num(pr["rmsd_ratio"], ".3g"),
            ]
        )
    rep.table(
        [
            "pressure (bar)",
            "averages",
            "modes id. / true",
            "f identified (Hz)",
            "f true (Hz)",
            "RMSD real / complex",
        ],
        rows,
    )
    _image(rep, images, "pressures")


def _lateral(rep: HtmlReport, result: DemoResult, doc: dict[str, Any], images: Any) -> None:
    lat = doc["lateral"]
    rep.heading(SECTIONS[3])
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
    _image(rep, images, "fig07_corner_frequency")

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
            ]
            for r in lat["ranking"]
        ],
        caption="Overall ranking over every condition (lower information criterion is better; "
        "amplitude errors as the paper's Table 1: mean relative error of the amplitude ratio).",
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
    rep.table(
        ["condition", "best", "f0 (Hz), eq. 38", "C_r fitted (kN s/m)", "C_alpha/V true (kN s/m)"],
        [
            [
                c["label"],
                c["best"],
                fmt_pm(c["corner_frequency_hz"], c["corner_frequency_std_hz"]),
                fmt_pm(c["road_damping"]["fitted"], c["road_damping"]["stderr"], 4, 1e-3),
                _num(c["road_damping"]["true"] / 1e3, ".4g"),
            ]
            for c in conds
        ],
        caption="Corner frequency of the fitted proposed model and its tyre-road damper C_r "
        "beside C_alpha/V of the rig's tyre (eq. 33: the low-frequency limit of its "
        "mobility). The band starts at 0.25 Hz, near f0, so C_r is set mostly by the "
        "transition region, where the rig's stiffening foundation and contact length depart "
        "from the model: a model-form difference, not noise (compare the standard error).",
    )
    ref = result.lateral.reference
    rep.paragraph(f"Ranking at {ref.label}:")
    rep.bullets(list(ref.ranking.reasons))
    rep.heading(f"Fitted parameters at {ref.label}", 3)
    rows = []
    for f in ref.ranking.fits:
        for n, u in zip(f.model.param_names, f.model.param_units, strict=True):
            rows.append([f.name, n, fmt_pm(f.params[n], f.stderr[n]), u])
    rep.table(["model", "parameter", "value ± standard error", "unit"], rows)
    truth = ref.truth
    rep.paragraph(
        "Truth at this condition (viscoelastic string): "
        + ", ".join(f"{k} = {v:.4g}" for k, v in truth.params.items())
        + f"; C_alpha/V = {ref.true_road_damping:.4g} N s/m."
    )
    speeds = result.settings.lateral_speeds_kmh
    rep.heading("Measured against predicted FRFs (paper Figs. 11-14)", 3)
    for force in ("ground", "axle"):
        for v in speeds:
            _image(rep, images, _fig_name(images, force, v))

    _lateral_vehicle(rep, lat, images)


def _lateral_vehicle(rep: HtmlReport, lat: dict[str, Any], images: Any) -> None:
    models = lat["models"]
    rep.heading("Vehicle model and time response", 3)
    veh = lat["vehicle"]
    tr = lat["time_response"]
    rows = [
        [name, _num(veh["resonance_hz"].get(name), ".3f"), _pct(tr["relative_error"].get(name))]
        for name in models
    ]
    rows.append(["rig truth", _num(veh["true_resonance_hz"], ".3f"), "-"])
    rep.table(
        [
            "tyre model",
            "body resonance (Hz)",
            f"time response error {tr['window_s'][0]:g}-{tr['window_s'][1]:g} s",
        ],
        rows,
        caption=f"{veh['body_mass_kg']:g} kg body (eq. 41-42) on each tyre fitted at "
        f"{veh['pressure_bar']:g} bar, {veh['speed_kmh']:g} km/h; time error = RMS of "
        "prediction minus measurement over RMS of the measurement (3 % measurement noise).",
    )
    _image(rep, images, "vehicle")
    _image(rep, images, "fig15_time_response")
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


def _fig_name(images: Mapping[str, Any], force: str, v: float) -> str:
    for name in images:
        if name.endswith(f"_{force}_{v:g}kmh"):
            return name
    return ""


def build_demo_report(
    result: DemoResult,
    doc: dict[str, Any],
    images: Mapping[str, tuple[bytes, str]],
    files: list[str] | None = None,
) -> str:
    """The demo report as one self-contained HTML page.

    Parameters
    ----------
    result : DemoResult
    doc : dict
        Its results document (:func:`tyredamp.studies.document.build_results`).
    images : mapping of str to (bytes, str)
        PNG bytes and caption of each figure by name
        (:func:`tyredamp.report.figures.demo_figures`).
    files : list of str, optional
        Files of the output directory to list; default ``doc["files"]``.

    Returns
    -------
    str
        The HTML text (figures embedded as data URIs; no external resource).
    """
    rep = HtmlReport("tyredamp demo: damping of pneumatic tyres on virtual tyres")
    _summary(rep, result, doc)
    _settings(rep, result, doc)
    _radial(rep, result, doc, images)
    _lateral(rep, result, doc, images)
    rep.heading(SECTIONS[4])
    listed = doc.get("files", []) if files is None else files
    rep.paragraph(
        "Written beside this report: results.json (all numbers; schema in the README), the "
        "figures as PNG, the generated data as UFF 58 (binary 58b: time data function type 1, "
        "FRFs type 4) and the modes and damping JSON files, which the other commands read "
        "(tyredamp damping, tyredamp report)."
    )
    rep.bullets(list(listed))
    return rep.render()
