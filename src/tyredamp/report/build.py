"""The demo's HTML report: results and figures into one self-contained page.

:func:`build_demo_report` lays out the page from a
:class:`~tyredamp.studies.demo.DemoResult`, its results document
(:func:`tyredamp.studies.document.build_results`) and the rendered figures
(:func:`tyredamp.report.plots.demo_figures`; each at the place its entry of
:data:`tyredamp.report.plots.PLOTS` names). Sections: summary, inputs and
settings, the radial study (checks, stabilisation, modes with standard errors
beside the truth, real against complex fit, mode shapes, damping matrices with
diagnostics in words, pressures), the tyre model (flexible ring across the
pressures and rigid ring beside the virtual tyre's values, the ``.tir``
subset) and the lateral study (Figure 7, ranking,
parameters beside the truth, Figures 11-14, vehicle model and Figure 15;
written by :func:`tyredamp.report.lateral.lateral_report`).
The report for result files of the other commands is
:func:`tyredamp.report.files.build_files_report`.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from .. import __version__
from ..modal.statistics.quality import RejectedMode, rejected_summary
from ._cells import ReportImage, _images, _num, _pct, _warnings, anchor_id, fmt_pm
from ._outcomes import _findings, _Page, _status, _verdict_block
from .dampmodels import dampmodels_report
from .html import HtmlReport
from .lateral import lateral_report
from .rolling import rolling_report
from .tyremodel import tyre_model_brief, tyre_model_report

if TYPE_CHECKING:
    from ..studies.results import DemoResult

__all__ = ["SECTIONS", "build_demo_report", "fmt_pm"]

#: Level-2 headings of the demo report, in order (the tests look for them).
SECTIONS = (
    "Summary",
    "Inputs and settings",
    "Radial study: modal test of the virtual truck tyre",
    "Tyre model: flexible ring and rigid ring from the modes",
    "Lateral study: rolling-tyre rig",
    "Files",
)


def _physics_note(rad: dict[str, Any]) -> str:
    """Why the ratio is what it is: the noise, and the sources of non-proportional damping."""
    tyre = rad.get("tyre", {})
    text = (
        "The ratio measures the real modes' model error against the noise: the complex fit "
        "reaches the noise, the real fit adds its model error B, so the ratio is about "
        "sqrt(1 + (B/noise)^2) and grows with the SNR."
    )
    src = tyre.get("nonproportional_sources")
    if src:
        parts = sorted(src.items(), key=lambda kv: -abs(kv[1]))
        text += (
            f" {100 * tyre['offdiagonal_share']:.0f} % of the tyre's in-band modal damping is "
            "off-diagonal; it comes from "
            + ", ".join(f"{k} ({100 * v:.0f} %)" for k, v in parts if abs(v) >= 0.01)
            + ". The shaker tip adds only the tread loss under it: with the force gauge at the "
            "tyre surface (ISO 7626-2) the shaker's own damping is outside the measured FRF."
        )
    cpl = tyre.get("largest_coupling")
    ratio = rad.get("rmsd_ratio")
    if cpl and isinstance(ratio, float) and math.isfinite(ratio):
        fk, fn = cpl["frequencies_hz"]
        text += (
            f" The strongest coupling of two modes (eq. [16], omega_n |C'_kn| / |omega_n^2 - "
            f"omega_k^2|) is {cpl['value']:.2g}, between the modes at {fk:.0f} and {fn:.0f} Hz"
        )
        text += (
            ": the modes are nearly real, so at this SNR the real-mode fit reaches the noise "
            "as well (a loaded tyre's contact patch couples neighbouring modes far more)."
            if ratio < 1.2
            else ": enough for real modes to miss the data by more than the noise."
        )
    return text


def _fallback_mark(doc: dict[str, Any], pressure_bar: float) -> str:
    """A note on an RMSD ratio whose real-mode fit kept the complex-mode poles."""
    about = f"radial:{pressure_bar:g}"
    fell = any(
        w["about"] == about and "fell back to the complex-mode poles" in w["message"]
        for w in doc.get("warnings", [])
    )
    return " (real-mode fit fell back to the complex poles: not a refined real fit)" if fell else ""


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
                _gap(c, t, "frequency_hz"),
                _gap(c, t, "damping_ratio"),
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
            "f complex - true",
            "zeta complex - true",
        ],
        rows,
        caption=caption + " Gaps: relative difference, and in standard errors (sigma); a "
        "gap of more than about 3 sigma is more than the noise explains.",
    )


def _gap(c: dict[str, Any] | None, t: dict[str, Any] | None, key: str) -> str:
    """``"+0.02 % (0.4 sigma)"``: identified minus true, relative and in standard errors."""
    if c is None or t is None or not t[key]:
        return "-"
    d = c[key] - t[key]
    std = c.get("frequency_std_hz" if key == "frequency_hz" else "damping_ratio_std")
    sig = f" ({d / std:+.1f} sigma)" if std and math.isfinite(std) and std > 0 else ""
    return f"{100 * d / t[key]:+.3g} %{sig}"


def _summary(rep: HtmlReport, result: DemoResult, doc: dict[str, Any]) -> None:
    rad, lat = doc["radial"], doc["lateral"]
    dmp = rad["damping"]
    best = lat["ranking"][0]
    rep.raw('<div class="first">')
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
            [
                "tyre model (flexible ring, all pressures)",
                tyre_model_brief(rad["tyre_model"])
                if rad["tyre_model"]["status"] == "ok"
                else "not fitted (the tyre model section says why)",
            ],
            ["computation time", f"{result.elapsed_s:.1f} s"],
        ],
    )
    _findings(rep, doc)
    rep.raw("</div>")


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
        ["virtual truck tyre (Popov & Geng 2005)", "value"],
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
        ["rolling-tyre rig (Peng et al.)", "value"],
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


def _radial(
    rep: HtmlReport, result: DemoResult, doc: dict[str, Any], images: Any, page: _Page
) -> None:
    rad = doc["radial"]
    r = result.radial
    p = f"{rad['pressure_bar']:g} bar"
    rep.heading(SECTIONS[2])
    rep.heading("Linearity, reciprocity and data quality", 3, anchor=anchor_id("radial:checks"))
    checks = (r.linearity, r.reciprocity, r.quality)
    rep.bullets([c.summary for c in checks if c.passed])
    for c in checks:
        if not c.passed:  # a check that fails on these data is a genuine failure
            rep.raw(f'<div class="verdict bad">{html.escape(c.summary)}</div>')
    _warnings(rep, doc, "radial:checks")
    rep.paragraph(
        "A linear model with a symmetric damping matrix needs both checks to pass. The quality "
        "check counts lines with coherence below 0.9 over the same band as the other checks "
        f"({result.settings.check_band_hz[0]:g}-{result.settings.check_band_hz[1]:g} Hz); on "
        "this tyre they lie at the anti-resonances, where the response is small, and below "
        "the first mode, outside that band."
    )
    _images(rep, images, "radial:checks")

    rep.heading("Stabilisation diagram", 3)
    _images(rep, images, "radial:stabilisation")
    ident = r.main.identification
    if ident.rejected:
        line = rejected_summary([RejectedMode.from_dict(x) for x in ident.rejected])
        rep.paragraph(
            f"{line[0].upper()}{line[1:]}. Every candidate's reason (the statistic of its "
            f"trial, or why it was not tried) is in modes_{rad['pressure_bar']:g}bar.json "
            "under quality.rejected."
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
    key = f"radial:{rad['pressure_bar']:g}"
    _verdict_block(rep, page, [(key, rad["verdict"]["complex"]), (key, rad["verdict"]["real"])])
    _warnings(rep, doc, key)
    ratio = rad["rmsd_ratio"]
    rep.paragraph(
        f"The complex-mode fit is {_num(ratio, '.3g')} times better in RMSD (the paper found "
        "about 2 on the real tyre). The modes are nearly real (MPC close to 1: near-"
        "proportional damping), yet the complex description fits better because the damping "
        "couples the modes (off-diagonal C')."
    )
    rep.paragraph(_physics_note(rad))
    _images(rep, images, "radial:fits")
    rep.heading("Mode shapes", 3)
    _images(rep, images, "radial:shapes")

    _radial_damping(rep, doc, images)
    _radial_pressures(rep, doc, images, page)


def _radial_damping(rep: HtmlReport, doc: dict[str, Any], images: Any) -> None:
    dmp = doc["radial"]["damping"]
    rep.heading("Damping matrices", 3, anchor=anchor_id("radial:damping"))
    rep.table(
        ["diagnostic", "value"],
        [
            ["method", f"{dmp['method']} ({dmp['n_modes']} modes at {dmp['n_points']} points)"],
            ["C' against the true C' (matched modes)", _pct(dmp["modal_error"])],
            ["its symmetric part against the truth", _pct(dmp["modal_error_symmetric"])],
            *(
                [
                    [
                        "C' against the truth without the terms of modes "
                        + ", ".join(f"{i} and {j}" for i, j in dmp["undetermined_pairs"])
                        + " (shapes the points cannot tell apart)",
                        _pct(dmp["modal_error_determined"]),
                    ]
                ]
                if dmp.get("undetermined_pairs")
                else []
            ),
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
    _warnings(rep, doc, "radial:damping")
    _images(rep, images, "radial:damping")


def _radial_pressures(rep: HtmlReport, doc: dict[str, Any], images: Any, page: _Page) -> None:
    rad = doc["radial"]
    rep.heading("Inflation pressure", 3)
    rows = []
    for pr in rad["pressures"]:
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
                _num(pr["rmsd_ratio"], ".3g") + _fallback_mark(doc, pr["pressure_bar"]),
                _status(pr["verdict"]["complex"]),
                _status(pr["verdict"]["real"]),
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
            "complex fit",
            "real fit",
        ],
        rows,
        caption="A ratio of RMSDs compares two fits only when both are sound: see the verdicts "
        "and warnings of each pressure below.",
    )
    for pr in rad["pressures"]:
        if pr["pressure_bar"] == rad["pressure_bar"]:
            continue  # the main pressure's verdicts stand beside its fit above
        key = f"radial:{pr['pressure_bar']:g}"
        rep.heading(f"At {pr['pressure_bar']:g} bar", 4)
        _verdict_block(rep, page, [(key, pr["verdict"]["complex"]), (key, pr["verdict"]["real"])])
        _warnings(rep, doc, key)
        _modes_table(
            rep,
            pr["modes"],
            f"Modes at {pr['pressure_bar']:g} bar ({pr['n_averages']} averages), as above.",
        )
    _images(rep, images, "radial:pressures")


def build_demo_report(
    result: DemoResult,
    doc: dict[str, Any],
    images: Mapping[str, ReportImage],
    files: list[str] | None = None,
) -> str:
    """The demo report as one self-contained HTML page.

    Parameters
    ----------
    result : DemoResult
    doc : dict
        Its results document (:func:`tyredamp.studies.document.build_results`).
    images : mapping of str to ReportImage
        PNG bytes, caption and place of each figure by name, in report order
        (the plots of :data:`tyredamp.report.plots.PLOTS`); each stands at its
        place (:data:`~tyredamp.report.plots.PLACES`), one with no place nowhere.
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
    page = _Page()
    _radial(rep, result, doc, images, page)
    rep.raw(f'<span id="{anchor_id("radial:tyre_model")}"></span>')
    tyre_model_report(rep, result, doc, images, SECTIONS[3])
    lateral_report(rep, result, doc, images, page, SECTIONS[4])
    rolling_report(rep, doc)
    dampmodels_report(rep, doc)
    rep.heading(SECTIONS[5])
    listed = doc.get("files", []) if files is None else files
    rep.paragraph(
        "Written beside this report: results.json (all numbers; described in the "
        "documentation's results.json reference), the "
        "figures as PNG, the generated data as UFF 58 (binary 58b: time data function type 1, "
        "FRFs type 4), the modes and damping JSON files, which the other commands read "
        "(tyredamp damping, tyredamp report), and the tyre model of all pressures "
        "(tyre_model/: ring.json, rigid_ring.json and the in-plane .tir subsets)."
    )
    rep.bullets(list(listed))
    return rep.render()
