"""The "Tyre model" section of the demo report.

The updated flexible ring and the rigid ring beside the virtual tyre's own
values, the parameters the modes cannot identify, the figure of identified
against model frequencies and the in-plane ``.tir`` fragment; or, when the fit
failed, the reason. Laid out from the ``radial.tyre_model`` section of
results.json (:func:`tyredamp.studies.tyremodel.tyre_model_section`).
"""

from __future__ import annotations

import html
from typing import TYPE_CHECKING, Any

from ._cells import _images, _num, _warnings, fmt_pm
from .html import HtmlReport

if TYPE_CHECKING:
    from ..studies.results import DemoResult

__all__ = ["tyre_model_brief", "tyre_model_report"]


def tyre_model_brief(tm: dict[str, Any]) -> str:
    """Summary cell: EI and k_r at the main pressure beside the truth, or the failure."""
    if tm["status"] != "ok":
        return f"FAILED: {tm['error']}"
    par = {p["name"]: p for p in tm["parameters"]}
    parts = []
    if "EI" in par:
        parts.append("EI " + _vs_true(par["EI"]))
    if tm["per_pressure"]:
        pp = tm["per_pressure"][0]
        parts.append(f"k_r at {pp['pressure_bar']:g} bar " + _vs_true(pp["k_r"]))
    return "; ".join(parts) + f" ({len(tm['pressures_bar'])} pressures)"


def _vs_true(c: dict[str, Any], digits: int = 4) -> str:
    """``"48.2 ± 0.18 (true 50, -3.6 %)"``."""
    out = fmt_pm(c["value"], c["stderr"], digits)
    if c["true"] is None:
        return out
    gap = "" if c["relative_gap"] is None else f", {100 * c['relative_gap']:+.2g} %"
    return f"{out} (true {c['true']:.4g}{gap})"


def _gap_cells(c: dict[str, Any]) -> list[str]:
    """True value, relative gap and gap in standard errors of a compared value."""
    true = "-" if c["true"] is None else f"{c['true']:.5g}"
    rel = "-" if c["relative_gap"] is None else f"{100 * c['relative_gap']:+.3g} %"
    sig = "-" if c["gap_sigma"] is None else f"{c['gap_sigma']:+.2g}"
    return [true, rel, sig]


def _tyre_model_rigid(rep: HtmlReport, tm: dict[str, Any], doc: dict[str, Any]) -> None:
    """The rigid ring per pressure beside the values from the exact modes."""
    failed = [
        f"{pr['pressure_bar']:g} bar"
        for pr in doc["radial"]["pressures"]
        if pr["pressure_bar"] in tm["pressures_bar"]
        and not pr["verdict"].get("complex", {"passed": True})["passed"]
    ]
    rows = []
    for rr in tm["rigid_ring"]:
        for key in ("BELT_MASS", "FREQ_LONG", "DAMP_LONG", "k_long", "c_long"):
            c = rr[key]
            rows.append(
                [
                    f"{_num(rr['pressure_bar'], 'g')} bar",
                    key,
                    fmt_pm(c["value"], c["stderr"], 5),
                    c["unit"],
                    *_gap_cells(c),
                ]
            )
    rep.table(
        [
            "pressure",
            "quantity",
            "value ± standard error",
            "unit",
            "from exact modes",
            "gap",
            "gap (sigma)",
        ],
        rows,
        caption="In-plane rigid ring (MF-Swift) per pressure from the identified n = 1 modes, "
        "beside the same quantities computed from the exact modes of the virtual tyre "
        "(attachment mass and damper removed). FREQ_WINDUP, DAMP_WINDUP and BELT_IYY are not "
        "given by these tests: the wind-up mode (n = 0) has no radial motion, so radial "
        "accelerometers cannot see it; a tangential test gives them (tyredamp tyre-model "
        "--tangential)."
        + (
            f" The complex-mode fit at {', '.join(failed)} did not pass its verdict (see the "
            "radial study): its modes, and what is derived from them here, carry more error "
            "than the noise explains."
            if failed
            else ""
        ),
    )


def tyre_model_report(
    rep: HtmlReport, result: DemoResult, doc: dict[str, Any], images: Any, heading: str
) -> None:
    """Updated flexible ring and rigid ring beside the virtual tyre, the .tir fragment."""
    tm = doc["radial"]["tyre_model"]
    rep.heading(heading)
    ps = ", ".join(f"{p:g}" for p in tm["pressures_bar"])
    rep.paragraph(
        f"The modes identified at {ps} bar go to tyredamp tyre-model: every mode "
        "is labelled with its wave number, the flexible ring (EI, tension law T0 = p b R + T_c, "
        "foundation k_r, k_t linear in pressure, mass per length, dampers c_r, c_t and band "
        "loss) is fitted to all pressures at once with the modal standard errors as weights, "
        "and the in-plane rigid ring (BELT_MASS, FREQ_LONG, DAMP_LONG) comes from the n = 1 "
        f"modes. Given to the fit, as a user would measure them: the belt radius "
        f"{_num(tm['radius_m'], 'g')} m and the shaker attachment "
        f"({_num(tm['attachment_mass_kg'], 'g')} kg, {_num(tm['attachment_damping_ns_m'], 'g')} "
        "N s/m) of the virtual tyre."
    )
    if tm["status"] != "ok":
        rep.raw(
            f'<div class="verdict bad">Tyre model not fitted: {html.escape(str(tm["error"]))}</div>'
        )
        _warnings(rep, doc, "radial:tyre_model")
        return
    _images(rep, images, "tyre_model")
    fit = tm["fit"]
    rep.table(
        [
            "parameter",
            "value ± standard error",
            "unit",
            "virtual tyre",
            "gap",
            "gap (sigma)",
            "fit to exact modes",
            "verdict",
        ],
        [
            [
                p["name"],
                fmt_pm(p["value"], p["stderr"], 5),
                p["unit"],
                *_gap_cells(p),
                _num(p["from_exact_modes"], ".5g"),
                p["verdict"],
            ]
            for p in tm["parameters"]
        ],
        caption=f"Updated flexible ring ({fit['n_modes']} modes, weights: {fit['weights']}, "
        f"chi2/dof {fit['chi2'] / max(fit['dof'], 1):.3g}"
        + (", covariance scaled by it" if fit["scaled_covariance"] else "")
        + f", fit {1e3 * fit['fit_time_s']:.0f} ms) beside the virtual tyre's own values, and "
        "the same fit to the tyre's exact modes (no noise). The virtual tyre is a "
        "finite-difference ring: its discretisation lowers the higher modes a little, which "
        "the continuous ring model reads as less EI even from the exact modes; the rest of a "
        "gap is the identification's. A model-limited verdict means the ring model, not the "
        "noise, limits the value (a misfit beyond the noise, or a belt the data see stretch, "
        "which the inextensible ring cannot hold); ring.json gives each parameter's "
        "model-error term, which its interval should include.",
    )
    rows = []
    for pp in tm["per_pressure"]:
        for key, unit in (("T0", "N"), ("k_r", "N/m^2"), ("k_t", "N/m^2")):
            c = pp[key]
            rows.append(
                [
                    f"{pp['pressure_bar']:g} bar",
                    key,
                    fmt_pm(c["value"], c["stderr"], 5),
                    unit,
                    *_gap_cells(c),
                    _num(c["from_exact_modes"], ".5g"),
                ]
            )
    rep.table(
        [
            "pressure",
            "quantity",
            "value ± standard error",
            "unit",
            "virtual tyre",
            "gap",
            "gap (sigma)",
            "fit to exact modes",
        ],
        rows,
        caption="Tension and foundation stiffnesses of the updated ring at each test pressure.",
    )
    _not_identified(rep, tm)
    _tyre_model_rigid(rep, tm, doc)
    res = result.radial.tyre_model.result
    if res is not None:
        name, text = next(iter(res.tir_files().items()))
        rep.paragraph(
            f"The in-plane .tir fragment at {tm['pressures_bar'][0]:g} bar ({name}; one "
            "file per pressure in tyre_model/), with each value's uncertainty budget and "
            "assumptions; a simulation needs it merged into a complete property file of the "
            "tyre (tyredamp tyre-model --merge-into BASE.tir):"
        )
        rep.raw(f"<pre>{html.escape(text)}</pre>")
    _warnings(rep, doc, "radial:tyre_model")


def _not_identified(rep: Any, tm: dict[str, Any]) -> None:
    """The ring parameters flagged model-limited, and those not identified."""
    from ..studies.tyremodel import ring_verdict_groups

    par = {p["name"]: p for p in tm["parameters"]}
    groups = ring_verdict_groups(tm)
    limited, unknown = groups["model-limited"], groups["not identified"]
    if limited:
        rep.paragraph(
            "Model-limited (the ring model does not hold these modes within their noise; the "
            "value is given with a model-error term in its uncertainty, and says what the "
            "updated ring needs, not what the tyre has):"
        )
        rep.bullets([f"{n}: {par[n]['verdict']}" for n in limited])
    if unknown:
        rep.paragraph("Not identified from these modes (reported, not given an arbitrary value):")
        rep.bullets([f"{n}: {par[n]['verdict']}" for n in unknown])
    if tm["not_identifiable"]:
        rep.paragraph(
            "Confounded parameters are determined only in combination: the tension and the "
            "foundation stiffness at each tested pressure (table above) are well determined "
            "even when their pressure laws are not (few pressures cannot tell a law's slope "
            "from its constant, nor the tension's share from the foundation's)."
        )
    else:
        rep.paragraph(
            "Every ring parameter is identified from these modes (standard error within 10 % "
            "of its scale, no confounded combination). What a radial test cannot give at all "
            "(wind-up, lateral, footprint) is listed with the rigid ring below."
        )
