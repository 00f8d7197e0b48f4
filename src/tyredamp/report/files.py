"""A report from the result files of the other commands (``tyredamp report``).

Recognised inputs (by content, not by name):

===========================  ==============================================
file                         written by
===========================  ==============================================
modes JSON (``"kind": "modes"``)        ``tyredamp modal`` (and ``simulate radial --truth``)
damping JSON (``"kind": "damping"``)    ``tyredamp damping``
lateral JSON (``"tyredamp": "lateral-fit"``)  ``tyredamp lateral fit``
demo results (``"kind": "tyredamp-demo-results"``)  ``tyredamp demo``
FRF or time data (extensions of :data:`tyredamp.io.FILE_FORMATS`)  ``tyredamp frf``, a DAQ
UFF modes (data sets 55)   another modal program (with its geometry when the file has nodes)
UFF test geometry (data sets 15, 82)  another modal program (mode shapes drawn on it)
===========================  ==============================================

Mode shapes are drawn as the data call for (:func:`tyredamp.plot.plot_mode_shapes`):
on the geometry (of the modes file itself, else a geometry file), around the
circumference only for points evenly spaced on a circle (a tyre), else
against the point; at the excitation points of a roving-hammer test.
Unscaled shapes (no drive point, no modal A) are said so.

Modes files are drawn against an FRF file of the same channels (the one
named in the modes file's ``source`` when given): measured against fitted
FRFs (paper Figs. 2 and 3) and the discrepancy (Fig. 4). A modes file whose
source starts with ``"truth"`` (the exact modes of a virtual tyre,
``tyredamp simulate radial --truth``) is shown beside the identified modes.
A lateral file is drawn against its FRF file in the same way.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from .. import __version__
from ..documents import read_document
from ..documents.modes import read_modes
from ..exceptions import FileFormatError, InputError, TyredampError
from ..frf import FRF
from ..io import FILE_FORMATS, read
from ..io._common import check_input_file
from ..modal.model import ModalModel
from ..timedata import TimeData
from ._outcomes import _verdict
from .build import fmt_pm
from .html import HtmlReport
from .oma import oma_section

__all__ = ["ResultFile", "build_files_report", "load_result_file"]


def _data_extensions() -> tuple[str, ...]:
    """Extensions of the measurement formats (FRF, time data), from the io registry."""
    return tuple(ext for f in FILE_FORMATS.values() for ext in f.extensions)


@dataclass(frozen=True, eq=False)
class ResultFile:
    """One input of the report.

    Attributes
    ----------
    path : Path
    kind : str
        ``"modes"``, ``"damping"``, ``"lateral"``, ``"demo"``, ``"frf"`` or
        ``"timedata"``.
    obj : Any
        The parsed content: ``dict`` of :class:`ModalModel` (modes),
        :class:`~tyredamp.damping.DampingModel`, the lateral or demo JSON
        document, :class:`FRF` or :class:`TimeData`.
    doc : dict or None
        The JSON document (JSON inputs).
    geometry : Geometry or None
        Node coordinates read from the same file (a UFF file of modes that
        carries its geometry).
    """

    path: Path
    kind: str
    obj: Any
    doc: dict[str, Any] | None = None
    geometry: Any = None

    @property
    def is_truth(self) -> bool:
        """A modes file holding the exact modes of a virtual tyre."""
        return self.kind == "modes" and str((self.doc or {}).get("source", "")).startswith("truth")


def _uff_modes_or_geometry(p: Path) -> ResultFile | None:
    """A UFF file of modes (data sets 55) or test geometry (15, 82), else None."""
    if p.suffix.lower() not in FILE_FORMATS["uff58b"].extensions:
        return None
    from ..io._common import uff_set_types
    from ..io.uff_geometry import read_uff_geometry

    types = uff_set_types(p)  # one read of the file to choose the reader
    if 58 in types:
        return None
    if 55 in types:
        models = read_modes(p)
        doc = {"kind": "modes", "source": str(p), "band_hz": None, "frf_kind": None}
        geo = read_uff_geometry(p) if types & {15, 2411} else None
        return ResultFile(p, "modes", models, doc, geo)
    if types & {15, 2411}:
        return ResultFile(p, "geometry", read_uff_geometry(p))
    return None


def load_result_file(path: str | Path) -> ResultFile:
    """Read and classify one result file.

    Raises
    ------
    FileFormatError
        Unreadable, not JSON where JSON is expected, or not a tyredamp result.
    """
    p = check_input_file(path)
    data_ext = _data_extensions()
    special = _uff_modes_or_geometry(p)
    if special is not None:
        return special
    if p.suffix.lower() in data_ext:
        obj = read(p)
        return ResultFile(p, "frf" if isinstance(obj, FRF) else "timedata", obj)
    if p.suffix.lower() != ".json":
        raise FileFormatError(
            f"{p}: unknown file extension {p.suffix or '(none)'!r}; expected .json (modes, "
            f"damping, lateral fit, demo results) or {', '.join(data_ext)} (FRF, time data)"
        )
    try:
        kind, obj, doc = read_document(p)
    except FileFormatError as exc:
        if "not a tyredamp result document" not in str(exc):
            raise
        raise FileFormatError(
            f"{p}: not a tyredamp result file (expected a modes, damping, lateral-fit or demo "
            f"results JSON, or an FRF/time-data file {', '.join(data_ext)})"
        ) from None
    short = {"lateral-fit": "lateral", "tyredamp-demo-results": "demo"}.get(kind, kind)
    return ResultFile(p, short, obj, doc)


# ----------------------------------------------------------------------------- sections
def _frf_summary(frf: FRF) -> list[list[str]]:
    f = frf.frequency
    rows = [
        ["size", f"{frf.n_out} output(s) x {frf.n_in} input(s)"],
        ["kind", f"{frf.kind} ({frf.unit})"],
        ["lines", f"{frf.n_freq}, {f[0]:.4g}-{f[-1]:.4g} Hz"],
        [
            "drive points",
            ", ".join(
                f"{frf.outputs[i].label}/{frf.inputs[j].label}" for i, j in frf.drive_points()
            )
            or "none",
        ],
    ]
    if frf.coherence is not None:
        rows.append(
            [
                "coherence",
                f"mean {float(frf.coherence.mean()):.4f}, min {float(frf.coherence.min()):.4f}",
            ]
        )
    for key in ("estimator", "method", "n_averages"):
        if key in frf.meta:
            rows.append([key, str(frf.meta[key])])
    return rows


def _frf_section(rep: HtmlReport, item: ResultFile) -> None:
    from ..plot import plot_frf

    frf: FRF = item.obj
    rep.heading(f"FRF: {item.path.name}", 3)
    rep.table(["", "value"], _frf_summary(frf))
    pairs = frf.drive_points()[:2] or [(0, 0)]
    n = 3 if frf.coherence is not None else 2
    fig = Figure(figsize=(7.5, 2.2 * n + 0.4), layout="constrained")
    axs = list(fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0])
    for i, j in pairs:
        plot_frf(frf, i, j, "bode", axes=axs[:2])
    axs[0].legend(fontsize="x-small")
    if frf.coherence is not None:
        for i, _ in pairs:
            axs[2].plot(frf.frequency, frf.coherence[i], lw=0.8)
        axs[2].set_ylabel("coherence")
        axs[2].set_ylim(0, 1.05)
        axs[2].grid(True, alpha=0.3)
        axs[2].set_xlabel("frequency (Hz)")
    rep.figure(
        fig,
        f"{item.path.name}: drive-point FRF(s), amplitude and phase"
        + (", multiple coherence" if frf.coherence is not None else ""),
    )


def _time_section(rep: HtmlReport, item: ResultFile) -> None:
    td: TimeData = item.obj
    rep.heading(f"Time data: {item.path.name}", 3)
    rows = [
        [c.label, q, u, f"{float(np.sqrt(np.mean(td.data[k] ** 2))):.4g}"]
        for k, (c, q, u) in enumerate(zip(td.channels, td.quantities, td.units, strict=True))
    ]
    rep.table(
        ["channel", "quantity", "unit", "RMS"],
        rows,
        caption=f"{td.n_channels} channels, {td.n_samples} samples at {td.sample_rate:g} Hz "
        f"({td.n_samples / td.sample_rate:.4g} s).",
    )
    show = [*td.force_indices[:1], *td.response_indices[:2]]
    n_show = min(td.n_samples, round(2.0 * td.sample_rate))
    fig = Figure(figsize=(7.5, 1.8 * len(show) + 0.4), layout="constrained")
    axs = list(fig.subplots(len(show), 1, sharex=True, squeeze=False)[:, 0])
    t = td.time[:n_show]
    for ax, k in zip(axs, show, strict=True):
        ax.plot(t, td.data[k, :n_show], lw=0.7)
        ax.set_ylabel(f"{td.channels[k].label} ({td.units[k]})")
        ax.grid(True, alpha=0.3)
    axs[-1].set_xlabel("time (s)")
    rep.figure(fig, f"{item.path.name}: the first {t[-1]:.3g} s of a force and two responses")


def _match(freq: np.ndarray, ref: np.ndarray) -> dict[int, int]:
    from ..studies.radial import match_modes

    return {m: t for t, m in match_modes(freq, ref).matched}


def _modes_section(
    rep: HtmlReport,
    item: ResultFile,
    frfs: list[ResultFile],
    truth: ResultFile | None,
    geometry: Any = None,
) -> None:
    models: dict[str, ModalModel] = item.obj
    doc = item.doc or {}
    rep.heading(f"Modes: {item.path.name}", 3)
    src = doc.get("source") or "?"
    band = doc.get("band_hz")
    rep.paragraph(
        f"Source {src}; band {'-'.join(f'{b:g}' for b in band) if band else '?'} Hz; "
        f"FRF kind {doc.get('frf_kind') or '?'}."
    )
    oma_section(rep, doc)
    tmodel = None
    if truth is not None and truth is not item:
        tm = truth.obj
        tmodel = tm.get("complex") or next(iter(tm.values()))
    for name, m in models.items():
        sf = m.std.get("frequency_hz", np.full(m.n_modes, np.nan))
        sz = m.std.get("damping_ratio", np.full(m.n_modes, np.nan))
        mpc = np.asarray(m.meta.get("mpc", np.full(m.n_modes, np.nan)), dtype=float)
        match = {} if tmodel is None else _match(m.frequency_hz, tmodel.frequency_hz)
        header = ["#", "f (Hz)", "zeta (%)", "MPC"]
        if tmodel is not None:
            header += ["f true (Hz)", "zeta true (%)"]
        rows = []
        for n in range(m.n_modes):
            row = [
                str(n + 1),
                fmt_pm(float(m.frequency_hz[n]), float(sf[n]), 6),
                fmt_pm(float(m.damping_ratio[n]), float(sz[n]), 4, 100),
                "-" if not math.isfinite(mpc[n]) else f"{mpc[n]:.4f}",
            ]
            if tmodel is not None:
                t = match.get(n)
                row += (
                    ["-", "-"]
                    if t is None
                    else [f"{tmodel.frequency_hz[t]:.3f}", f"{100 * tmodel.damping_ratio[t]:.3f}"]
                )
            rows.append(row)
        rep.table(
            header,
            rows,
            caption=f"{name}-mode model ({m.n_modes} modes): value ± standard error"
            + ("; truth of the virtual tyre beside" if tmodel is not None else ""),
        )
        v = m.meta.get("verdict")
        if isinstance(v, dict) and "summary" in v and "passed" in v:
            _verdict(rep, v)  # written by tyredamp modal
        for w in m.meta.get("warnings", []):
            rep.paragraph(f"warning ({name}-mode fit): {w}", css_class="bad")
    if len(models) > 1:
        rep.table(
            ["model", "RMSD (eq. [19])", "relative error"],
            [
                [
                    k,
                    f"{_num(v.meta.get('rmsd')):.4g}",
                    f"{100 * _num(v.meta.get('relative_error')):.3g} %",
                ]
                for k, v in models.items()
            ],
            caption="Real against complex modes: fit quality over the same FRFs.",
        )
    any_model = next(iter(models.values()))
    frf = _frf_for(any_model, src, frfs, fallback=not item.is_truth)
    if frf is not None:
        _fit_figures(rep, frf, models)
    shapes = models.get("complex") or any_model
    _shape_notes(rep, shapes)
    if shapes.n_modes:
        _shape_figures(rep, item, shapes, item.geometry if item.geometry is not None else geometry)


def _shape_notes(rep: HtmlReport, model: ModalModel) -> None:
    """Where the shapes are (roving hammer: at the inputs) and whether they are scaled."""
    from ..damping.modeset import at_shape_points, scaling_problem

    pts = at_shape_points(model)
    if pts.meta.get("shapes_from") == "inputs":
        rep.paragraph(
            f"Shapes at the {len(pts.outputs)} excitation points "
            f"({', '.join(c.label for c in pts.outputs)}): one response, the excitation moved "
            "over the points (roving hammer); by reciprocity the residues give the shape at "
            "the inputs."
        )
    why = scaling_problem(pts)
    if why:
        rep.paragraph(
            f"Unscaled mode shapes: {why}. Frequencies, damping ratios and the shapes' form "
            "hold; modal masses and damping, mass and stiffness matrices cannot be computed "
            "from them (a drive-point FRF, or the modal A or modal mass, would scale them).",
            css_class="bad",
        )


def _shape_figures(rep: HtmlReport, item: ResultFile, shapes: ModalModel, geometry: Any) -> None:
    """The mode shapes in the views the data call for (:func:`tyredamp.plot.plot_mode_shapes`)."""
    from ..plot import plot_mode_shapes

    captions = {
        "geometry": "mode shapes on the test geometry (real part; grey undeformed)",
        "ring": "mode shapes around the circumference (real part solid, imaginary part dashed)",
        "points": "mode shapes against the point (real part solid, imaginary part dashed; "
        "normalised to the largest entry)",
    }
    for view, axs in plot_mode_shapes(shapes, geometry):
        rep.figure(axs[0].figure, f"{item.path.name}: {captions[view]}")


def _frf_for(
    model: ModalModel, source: str, frfs: list[ResultFile], fallback: bool = True
) -> FRF | None:
    """The FRF a modal model was fitted to: the one named in its source, else the only
    FRF file with the same channels (when ``fallback``)."""
    same = [
        f
        for f in frfs
        if f.obj.n_out == model.psi_out.shape[0] and f.obj.n_in == model.psi_in.shape[0]
    ]
    named = [f for f in same if f.path.name == Path(source).name]
    pick = named or (same if fallback and len(same) == 1 else [])
    return pick[0].obj if pick else None


def _fit_figures(rep: HtmlReport, frf: FRF, models: dict[str, ModalModel]) -> None:
    from ..plot import plot_discrepancy, plot_frf_comparison

    band = next(iter(models.values())).meta.get("band_hz")
    meas = frf if not band else frf.band(float(band[0]), float(band[1]))
    meas = meas.select_lines(np.flatnonzero(meas.frequency > 0))
    order = sorted(models, key=lambda k: {"real": 0, "complex": 1}.get(k, 2))
    fitted = {f"{k}-mode fit": models[k].frf(meas.frequency, meas.kind) for k in order}
    dp = meas.drive_points()
    i, j = dp[0] if dp else (0, 0)
    for lab, fr in fitted.items():
        axs = plot_frf_comparison(meas, {lab: fr}, i, j)
        rep.figure(
            axs[0].figure,
            f"Measured against the {lab} at {meas.outputs[i].label}/{meas.inputs[j].label}"
            + (" (as the paper's Fig. 2)." if lab.startswith("real") else "")
            + (" (as the paper's Fig. 3)." if lab.startswith("complex") else ""),
        )
    rmsd = {f"{k}-mode fit": _num(m.meta.get("rmsd")) for k, m in models.items()}
    ax = plot_discrepancy(meas, fitted, rmsd)
    rep.figure(ax.figure, "Discrepancy against frequency with the RMSD of eq. [19] (Fig. 4).")


def _damping_section(rep: HtmlReport, item: ResultFile) -> None:
    from ..plot import plot_matrix

    dm = item.obj
    d = dm.diagnostics
    rep.heading(f"Damping: {item.path.name}", 3)
    rep.table(
        ["diagnostic", "value"],
        [
            ["method", f"{dm.method} ({dm.n_modes} modes at {dm.n_points} points)"],
            *_damping_scope(dm),
            ["asymmetry of C'", f"{100 * d.symmetry_modal:.3g} %"],
            ["definiteness of C'", d.definiteness_modal],
            ["non-proportionality", f"{100 * d.non_proportionality:.3g} %"],
            [
                "negative off-diagonal entries of C",
                f"{100 * d.negative_offdiagonal_fraction:.3g} %",
            ],
            [
                "Rayleigh fit alpha, beta",
                f"{dm.proportional.rayleigh_alpha:.4g} 1/s, {dm.proportional.rayleigh_beta:.4g} s",
            ],
        ],
    )
    rep.paragraph("What the numbers say:")
    rep.bullets(list(dm.findings))
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    axs = fig.subplots(1, 2)
    plot_matrix(
        dm.modal,
        [f"{f:.0f} Hz" for f in dm.frequency_hz],
        "C' (modal coordinates)",
        "1/s",
        ax=axs[0],
    )
    plot_matrix(
        dm.physical_symmetric,
        [c.label for c in dm.points],
        "C at the points (physical coordinates)",
        "N s/m",
        ax=axs[1],
    )
    rep.figure(fig, "Damping matrices as heat maps (as the paper's Fig. 5).")


def _damping_scope(dm: Any) -> list[list[str]]:
    """Rows for the modes used (a subset of the file's), the points and the scaling."""
    rows = []
    used = dm.meta.get("modes_used")
    avail = dm.meta.get("n_modes_available")
    if isinstance(used, list) and used:
        of = f" of {avail}" if isinstance(avail, int) else ""
        rows.append(["modes used", ", ".join(str(k) for k in used) + of])
    if dm.meta.get("shape_points") == "inputs":
        rows.append(["points", "the excitation points (roving hammer, shapes by reciprocity)"])
    if dm.meta.get("scaling"):
        rows.append(["shape scaling", str(dm.meta["scaling"])])
    return rows


def _lateral_section(rep: HtmlReport, item: ResultFile, frfs: list[ResultFile]) -> None:
    from ..lateral.models import LateralModel
    from ..plot import plot_lateral_models

    doc: dict[str, Any] = item.obj
    cond = doc["conditions"]
    rep.heading(f"Lateral fit: {item.path.name}", 3)
    inp = doc.get("input", {})
    rep.paragraph(
        f"Input {inp.get('file', '?')}: {inp.get('n_lines', '?')} lines, {cond.get('force')} "
        f"force, wheel mass {cond.get('wheel_mass_kg')} kg, speed "
        f"{'?' if cond.get('speed_kmh') is None else format(cond['speed_kmh'], 'g')} km/h."
    )
    crit = str(doc.get("criterion", "bic")).upper()
    rep.table(
        ["rank", "model", "P", "AIC", "BIC", "d" + crit, "weight", "amp. error (%)", "bias (%)"],
        [
            [
                str(r["rank"]),
                r["model"],
                str(r["n_params"]),
                _f(r["aic"], ".1f"),
                _f(r["bic"], ".1f"),
                _f(r["delta"], ".1f"),
                _f(r["weight"], ".3f"),
                _f(r["amplitude_error_pct"], ".2f"),
                _f(r["amplitude_bias_pct"], "+.2f"),
            ]
            for r in doc["table"]
        ],
        caption="Ranking (lower criterion is better; amplitude error as the paper's Table 1).",
    )
    rep.bullets([str(s) for s in doc.get("reasons", [])])
    rows = []
    for fit in doc["fits"]:
        for n, v in fit["params"].items():
            rows.append([fit["model"], n, fmt_pm(v, fit["stderr"].get(n)), fit["units"].get(n, "")])
        f0 = (fit.get("derived") or {}).get("f0")
        if f0 is not None:
            rows.append([fit["model"], "f0 (eq. 38)", f"{f0:.4g}", "Hz"])
    rep.table(["model", "parameter", "value ± standard error", "unit"], rows)
    band = inp.get("band_hz") or [0.25, 9.0]
    measured = None
    for f in frfs:
        if f.path.name == Path(str(inp.get("file", ""))).name and f.obj.n_out == f.obj.n_in == 1:
            measured = f.obj.band(float(band[0]), float(band[1])).to("accelerance")
    freq = measured.frequency if measured is not None else np.linspace(band[0], band[1], 300)
    preds = {}
    for fit in doc["fits"]:
        try:
            m = LateralModel.from_dict(
                {
                    "model": fit["model"],
                    "params": fit["params"],
                    "conditions": fit.get("conditions", {}),
                }
            )
        except (InputError, TypeError):
            continue
        preds[fit["model"]] = m.response(
            freq, "accelerance", cond.get("force", "ground"), cond.get("wheel_mass_kg") or 0.0
        )
    truth = None if measured is None else _rig_truth(measured.meta)
    truth_h = None
    if truth is not None:
        truth_h = truth.response(
            freq, "accelerance", cond.get("force", "ground"), cond.get("wheel_mass_kg") or 0.0
        )
        rep.paragraph(
            f"The FRF comes from a virtual rig whose exact tyre is a {truth.label}: "
            + ", ".join(f"{k} = {v:.4g}" for k, v in truth.params.items())
            + " (dotted in the figure)."
        )
    if preds:
        meas = measured.H[0, 0] if measured is not None else np.full(freq.shape, np.nan + 0j)
        axs = plot_lateral_models(
            freq,
            meas,
            preds,
            style="bode",
            truth=truth_h,
            title=f"{item.path.name}: {cond.get('force')} force",
        )
        rep.figure(
            axs[0].figure,
            "Fitted models"
            + (" against the measured FRF" if measured is not None else "")
            + " (as the paper's Figs. 11-14).",
        )


def _num(v: Any) -> float:
    """A float from a JSON value (``None`` or junk as NaN)."""
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _rig_truth(meta: dict[str, Any]) -> Any:
    """The exact tyre model a virtual lateral rig stored in an FRF's meta, or None."""
    from ..lateral.models import LateralModel
    from ..virtual.lateral_rig import ViscoelasticStringTyre

    d = meta.get("truth")
    if not isinstance(d, dict) or "params" not in d:
        return None
    try:
        if d.get("model") == ViscoelasticStringTyre.name:
            return ViscoelasticStringTyre(**d["params"], **d.get("conditions", {}))
        return LateralModel.from_dict(d)
    except (TyredampError, TypeError, KeyError):
        return None


def _f(v: Any, spec: str) -> str:
    return "-" if v is None else format(v, spec)


def _demo_section(rep: HtmlReport, item: ResultFile) -> None:
    from .build import _modes_table

    doc: dict[str, Any] = item.obj
    rep.heading(f"Demo results: {item.path.name}", 3)
    rad, lat = doc["radial"], doc["lateral"]
    rep.paragraph(
        f"Radial study at {rad['pressure_bar']:g} bar: RMSD real {rad['rmsd_real']:.4g}, "
        f"complex {rad['rmsd_complex']:.4g}; damping C' within "
        f"{100 * rad['damping']['modal_error']:.3g} % of the truth."
    )
    _modes_table(rep, rad["modes"], "Modes identified beside the truth.")
    for pr in rad.get("pressures", []):
        for v in (pr.get("verdict") or {}).values():
            _verdict(rep, v)
    for c in lat.get("conditions", []):
        if c.get("verdict"):
            _verdict(rep, c["verdict"])
    # the fit verdicts are stated above; the other findings of every stage here
    ws = [w for w in doc.get("warnings", []) if not w.get("fit")]
    if ws:
        rep.paragraph(f"Warnings of every stage of the run ({len(ws)}):")
        rep.bullets([f"{w['stage']}: {w['message']}" for w in ws])
    rep.table(
        ["rank", "model", "mean rank", "best at", "amplitude error (%)"],
        [
            [
                str(r["rank"]),
                r["model"],
                f"{r['mean_rank']:.2f}",
                f"{r['wins']} of {r['n_conditions']}",
                _f(r["mean_amplitude_error_pct"], ".2f"),
            ]
            for r in lat["ranking"]
        ],
        caption="Lateral models over all conditions.",
    )


def build_files_report(paths: Sequence[str | Path], title: str | None = None) -> str:
    """One self-contained HTML page from result files (module docstring).

    Parameters
    ----------
    paths : sequence of path-like
        At least one result file.
    title : str, optional
        Page title.

    Returns
    -------
    str
        The HTML text.

    Raises
    ------
    InputError
        No files.
    FileFormatError
        A file that is not a tyredamp result (names the file).
    """
    if not paths:
        raise InputError("RESULT_FILES: expected at least one result file")
    items = [load_result_file(p) for p in paths]
    rep = HtmlReport(title or "tyredamp report")
    rep.heading("Inputs")
    names = {
        "modes": "modal models (real/complex)",
        "damping": "damping matrices",
        "lateral": "lateral model fits",
        "demo": "demo results",
        "frf": "FRF",
        "timedata": "time data",
        "geometry": "test geometry (nodes, trace lines)",
    }
    rep.table(
        ["file", "content"],
        [
            [str(i.path), names[i.kind] + (" (truth of a virtual tyre)" if i.is_truth else "")]
            for i in items
        ],
    )
    rep.paragraph(f"tyredamp {__version__}.")
    frfs = [i for i in items if i.kind == "frf"]
    truth = next((i for i in items if i.is_truth), None)
    geometry = next((i.obj for i in items if i.kind == "geometry"), None)
    sections = [
        ("Measured data", [i for i in items if i.kind in ("frf", "timedata")]),
        ("Modal analysis", [i for i in items if i.kind == "modes"]),
        ("Damping identification", [i for i in items if i.kind == "damping"]),
        ("Lateral tyre models", [i for i in items if i.kind == "lateral"]),
        ("Demo results", [i for i in items if i.kind == "demo"]),
    ]
    for heading, group in sections:
        if not group:
            continue
        rep.heading(heading)
        for item in group:
            with _content_errors(item.path):
                if item.kind == "frf":
                    _frf_section(rep, item)
                elif item.kind == "timedata":
                    _time_section(rep, item)
                elif item.kind == "modes":
                    _modes_section(rep, item, frfs, truth, geometry)
                elif item.kind == "damping":
                    _damping_section(rep, item)
                elif item.kind == "lateral":
                    _lateral_section(rep, item, frfs)
                else:
                    _demo_section(rep, item)
    return rep.render()


@contextlib.contextmanager
def _content_errors(path: Path) -> Iterator[None]:
    """A result JSON whose fields have the wrong type (strings for numbers, a number for a
    list ...) is the file's fault: one FileFormatError naming it, not a traceback."""
    try:
        yield
    except (TypeError, ValueError, KeyError, AttributeError, IndexError) as exc:
        if isinstance(exc, TyredampError):
            raise FileFormatError(f"{path}: {exc}") from exc
        name = type(exc).__name__
        raise FileFormatError(
            f"{path}: a field has the wrong type or value ({name}: {exc})"
        ) from exc
