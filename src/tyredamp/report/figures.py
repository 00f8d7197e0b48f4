"""The builders of the demo report's plots, from a :class:`~tyredamp.studies.demo.DemoResult`.

Each builder takes the result and returns ``(Figure, caption)`` (or ``None``
when it has nothing to show; :func:`lateral_frf_figures` returns several
named figures); :data:`tyredamp.report.plots.PLOTS` lists them with their
name (the PNG file stem: ``fig02_real_fit`` ... ``fig15_time_response``; the
numbers follow the papers' figures where there is one) and their place in
the report, and :func:`tyredamp.report.plots.demo_figures` builds them. Only
:class:`matplotlib.figure.Figure` objects are used (no pyplot).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..plot import (
    plot_discrepancy,
    plot_figure7,
    plot_frf_comparison,
    plot_lateral_models,
    plot_matrix,
    plot_mode_shapes_ring,
    plot_stabilisation,
    plot_time_comparison,
)
from ..plot.comparison import model_color
from ..plot.tyremodel import plot_ring_frequencies
from ..studies.document import time_test_truth

if TYPE_CHECKING:
    from ..frf import FRF
    from ..lateral.response import ForceKind
    from ..studies.results import DemoResult, LateralCondition

__all__ = [
    "PAPER_MODELS",
    "checks_figure",
    "complex_fit_figure",
    "corner_frequency_figure",
    "damping_figure",
    "discrepancy_figure",
    "lateral_frf_figures",
    "mac_figure",
    "mode_shapes_figure",
    "pressures_figure",
    "real_fit_figure",
    "residual_zoom_figure",
    "ring_frequencies_figure",
    "stabilisation_figure",
    "time_response_figure",
    "vehicle_figure",
]

#: What a builder returns: a figure and its caption, or None (nothing to show).
Built = tuple[Figure, str] | None
#: The four spring-damper models of the paper (Figures 11-15 show these).
PAPER_MODELS = ("classic", "maxwell", "viscoplastic", "hysteretic")


def _figure(ax: Axes) -> Figure:
    """The :class:`Figure` that holds ``ax``."""
    fig = ax.figure
    while not isinstance(fig, Figure):  # a SubFigure: go up to the root Figure
        fig = fig.figure
    return fig


def _paper_models(names: Any) -> list[str]:
    return [n for n in PAPER_MODELS if n in names]


@dataclass(frozen=True)
class _Fits:
    """What the figures of the fits at the main pressure share."""

    main: Any
    meas: FRF
    out_i: int
    in_i: int
    lab: str
    p: str

    @property
    def rmsd(self) -> tuple[float, float]:
        """RMSD of the real- and complex-mode fits (eq. [19])."""
        return self.main.models["real"].meta["rmsd"], self.main.models["complex"].meta["rmsd"]


def _fits(result: DemoResult) -> _Fits:
    main = result.radial.main
    meas = main.fitted_frf
    dp = meas.drive_points()
    out_i, in_i = dp[0] if dp else (0, 0)
    lab = f"{meas.outputs[out_i].label}/{meas.inputs[in_i].label}"
    return _Fits(main, meas, out_i, in_i, lab, f"{main.pressure_bar:g} bar")


def real_fit_figure(result: DemoResult) -> Built:
    """Paper Fig. 2: the driving-point FRF and the real-mode fit."""
    c = _fits(result)
    real = c.main.synthesised("real")
    ax = plot_frf_comparison(c.meas, {"real-mode fit": real}, c.out_i, c.in_i)
    return (
        _figure(ax[0]),
        f"Paper Fig. 2: driving-point accelerance {c.lab} at {c.p}, measured (dots) and the "
        f"real-mode fit (eq. [2]/[3]): real part, imaginary part, amplitude, phase. "
        f"RMSD {c.rmsd[0]:.3g} {c.meas.unit}.",
    )


def complex_fit_figure(result: DemoResult) -> Built:
    """Paper Fig. 3: the driving-point FRF and the complex-mode fit."""
    c = _fits(result)
    cplx = c.main.synthesised("complex")
    ax = plot_frf_comparison(c.meas, {"complex-mode fit": cplx}, c.out_i, c.in_i)
    return (
        _figure(ax[0]),
        f"Paper Fig. 3: the same FRF and the complex-mode fit (eq. [10]). "
        f"RMSD {c.rmsd[1]:.3g} {c.meas.unit}.",
    )


def discrepancy_figure(result: DemoResult) -> Built:
    """Paper Fig. 4: discrepancy of both fits and of the exact FRF against frequency."""
    c = _fits(result)
    meas = c.meas
    real = c.main.synthesised("real")
    cplx = c.main.synthesised("complex")
    exact = c.main.exact()
    mr, mc = c.rmsd
    ax1 = plot_discrepancy(
        meas,
        {"real-mode fit": real, "complex-mode fit": cplx, "exact FRF (noise level)": exact},
        {"real-mode fit": mr, "complex-mode fit": mc},
    )
    plotted = {
        name: float(np.sqrt(np.mean(np.sum(np.abs(fr.H - meas.H) ** 2, axis=(0, 1)))))
        for name, fr in (("real", real), ("complex", cplx))
    }
    return (
        _figure(ax1),
        "Paper Fig. 4: discrepancy sqrt(sum_jk |H_fit - H_meas|^2) over the 16 FRFs against "
        "frequency, with the RMSD of eq. [19] in the legend; the exact FRF of the virtual tyre "
        "shows the noise level no fit can beat. The curves' RMS over the "
        f"{meas.n_freq} lines is {plotted['real']:.3g} (real) and {plotted['complex']:.3g} "
        f"(complex) {meas.unit}; eq. [19] divides the root of the same sum by the number of "
        f"values ({meas.H.size}) instead of its root, hence RMSD "
        f"{mr:.3g} and {mc:.3g}: the same ratio, another scale.",
    )


def residual_zoom_figure(result: DemoResult) -> Built:
    """Where the real-mode fit misses: residual against the noise, and a zoom."""
    c = _fits(result)
    real = c.main.synthesised("real")
    cplx = c.main.synthesised("complex")
    return _residual_zoom(c.main, c.meas, real, cplx, c.out_i, c.in_i, c.lab)


def stabilisation_figure(result: DemoResult) -> Built:
    """The stabilisation diagram of the fit at the main pressure."""
    c = _fits(result)
    ident = c.main.identification
    mc = c.main.models["complex"]
    ax2 = plot_stabilisation(ident.poles, ident.flags, c.meas, mc.frequency_hz)
    return (
        _figure(ax2),
        f"Stabilisation diagram (pLSCF poles of every model order) at {c.p}; dashed lines: "
        "the modes selected automatically; grey curve: summed FRF amplitude.",
    )


def mode_shapes_figure(result: DemoResult) -> Built:
    """The complex mode shapes around the circumference, with the true wave numbers."""
    main = result.radial.main
    axs3 = plot_mode_shapes_ring(main.models["complex"])
    vis = main.truth.select("visible")
    wave = {m: int(main.truth.wave_number[vis[t]]) for t, m in main.matches["complex"].matched}
    for j, a in enumerate(axs3):
        if j in wave:
            a.set_title(f"n = {wave[j]}: " + a.get_title(), fontsize="small")
    return (
        _figure(axs3[0]),
        "Complex mode shapes around the circumference (16 points): real part of the "
        "second-order shape (solid) and imaginary part (dashed), normalised; n = "
        "circumferential wave number of the matched true mode.",
    )


def damping_figure(result: DemoResult) -> Built:
    """Paper Fig. 5: identified and true damping matrices as heat maps."""
    r = result.radial
    p = f"{r.main.pressure_bar:g} bar"
    dm = r.damping
    dc = r.damping_truth
    fig = Figure(figsize=(10.0, 8.4), layout="constrained")
    axs = fig.subplots(2, 2)
    mlab = [f"{f:.0f} Hz" for f in dm.frequency_hz]
    tlab = [f"{dm.frequency_hz[i]:.0f} Hz" for i in dc.model_index]
    # symmetric log colours, linear below the largest true off-diagonal term / 10, so that
    # the coupling terms show beside the diagonal (100x larger)
    off = dc.modal_true - np.diag(np.diag(dc.modal_true))
    lt = float(np.max(np.abs(off))) / 10 if off.size and np.any(off) else None
    plot_matrix(
        dm.modal, mlab, "identified C' (modal coordinates)", "1/s", ax=axs[0, 0], linthresh=lt
    )
    plot_matrix(
        dc.modal_true,
        tlab,
        "true C' of the virtual tyre (eq. [14])",
        "1/s",
        axs[0, 1],
        linthresh=lt,
    )
    plab = [c.label for c in dm.points]
    plot_matrix(
        dm.physical_symmetric,
        plab,
        "identified C at the 16 points (physical coordinates)",
        "N s/m",
        ax=axs[1, 0],
    )
    if dc.physical_true is not None:
        plot_matrix(
            dc.physical_true,
            plab,
            "true C reduced to the points by the same modes",
            "N s/m",
            ax=axs[1, 1],
        )
    else:
        axs[1, 1].set_visible(False)
    return (
        fig,
        f"Paper Fig. 5: damping matrices at {p} ({dm.method} method, eq. [18]) as heat maps, "
        "identified beside the truth. The modal matrices use a symmetric logarithmic colour "
        + ("scale (linear within +-" + f"{lt:.2g} 1/s) " if lt else "scale ")
        + "so that the off-diagonal coupling terms show beside the diagonal. Negative (blue) "
        "entries of the physical matrix come from projecting on few modes ('power leakage'), "
        "as in the paper.",
    )


def checks_figure(result: DemoResult) -> Built:
    """Linearity and reciprocity: relative difference per line and overall."""
    r = result.radial
    fig = Figure(figsize=(9.0, 3.2), layout="constrained")
    axs = fig.subplots(1, 2)
    for ax_, res, name in ((axs[0], r.linearity, "linearity"), (axs[1], r.reciprocity, "")):
        if res.frequency is not None and res.per_line is not None:
            ax_.semilogy(res.frequency, 100 * res.per_line, color="C0", lw=0.8)
        ax_.axhline(100 * res.threshold, color="C3", ls="--", lw=0.8, label="threshold (RMS)")
        ax_.axhline(100 * res.figure, color="k", lw=1, label=f"overall {100 * res.figure:.2g} %")
        ax_.set_xlabel("frequency (Hz)")
        ax_.set_ylabel("per-line deviation (%)")
        ax_.set_title(
            f"{name or 'reciprocity'}: {'PASS' if res.passed else 'FAIL'}", fontsize="small"
        )
        ax_.grid(True, which="both", alpha=0.3)
        ax_.legend(fontsize="x-small")
    return (
        fig,
        f"Linearity (FRFs at {result.settings.force_levels_n[0]:g} N and "
        f"{result.settings.force_levels_n[1]:g} N RMS) and reciprocity (H between drive points "
        f"{result.settings.reciprocity_points[0]} and {result.settings.reciprocity_points[1]}): "
        "relative difference per line and overall.",
    )


def pressures_figure(result: DemoResult) -> Built:
    """Frequencies and damping ratios against wave number at every pressure."""
    r = result.radial
    fig = Figure(figsize=(9.0, 3.4), layout="constrained")
    axs = fig.subplots(1, 2)
    for i, run in enumerate(r.runs):
        tr = run.truth
        vis = tr.select("visible")
        c = f"C{i}"
        axs[0].plot(
            tr.wave_number[vis],
            tr.frequency_hz[vis],
            color=c,
            lw=0.8,
            label=f"true, {run.pressure_bar:g} bar",
        )
        axs[1].plot(tr.frequency_hz[vis], 100 * tr.damping_ratio[vis], color=c, lw=0.8)
        m = run.models["complex"]
        pairs = run.matches["complex"].matched
        n = [int(tr.wave_number[vis[t]]) for t, _ in pairs]
        fi = [float(m.frequency_hz[j]) for _, j in pairs]
        zi = [100 * float(m.damping_ratio[j]) for _, j in pairs]
        axs[0].plot(n, fi, ls="none", marker="o", mfc="none", color=c, label="identified")
        axs[1].plot(fi, zi, ls="none", marker="o", mfc="none", color=c)
    axs[0].set_xlabel("circumferential wave number n")
    axs[0].set_ylabel("natural frequency (Hz)")
    axs[1].set_xlabel("natural frequency (Hz)")
    axs[1].set_ylabel("damping ratio (%)")
    axs[0].legend(fontsize="x-small")
    for a in axs:
        a.grid(True, alpha=0.3)
    return (
        fig,
        "Inflation pressure: natural frequencies against wave number and damping ratios, "
        "identified (circles, complex-mode fit) against the exact modes (lines).",
    )


def ring_frequencies_figure(result: DemoResult) -> Built:
    """Identified against updated-ring frequencies per n and pressure (None: no fit)."""
    res = result.radial.tyre_model.result
    if res is None:
        return None
    fig = Figure(figsize=(6.5, 4.0), layout="constrained")
    plot_ring_frequencies(res.ring, ax=fig.subplots())
    pressures = ", ".join(f"{p / 1e5:g}" for p in res.ring.pressures)
    return (
        fig,
        f"Tyre model: natural frequencies identified at {pressures} bar (markers, 1-sigma "
        "bars; hollow: the member of a pair away from the drive point) and of the flexible "
        "ring updated jointly across the pressures (lines, with the shaker's attachment "
        "mass), against the circumferential wave number n.",
    )


def _ground_axle(
    cond: LateralCondition, names: list[str], wheel_mass: float, force: ForceKind
) -> tuple[Any, Any, dict[str, Any], Any]:
    data = cond.ground if force == "ground" else cond.axle
    f = data.frf.frequency
    meas = data.frf.H[0, 0]
    preds = {n: cond.fit(n).model.response(f, "accelerance", force, wheel_mass) for n in names}
    truth = cond.truth.response(f, "accelerance", force, wheel_mass)
    return f, meas, preds, truth


def corner_frequency_figure(result: DemoResult) -> Built:
    """Paper Fig. 7: the proposed model's amplitude ratio, asymptotes and corner frequency."""
    lat = result.lateral
    ref = lat.reference
    fig = Figure(figsize=(11.0, 4.0), layout="constrained")
    axs = fig.subplots(1, 2)
    plot_figure7(lat.figure7, ax=axs[0])
    axs[0].set_title("paper's parameters: K 260 kN/m, h 20 kN/m, C_r 300 kN s/m", fontsize="small")
    from ..lateral import figure7_curves

    hy = ref.fit("hysteretic").model
    plot_figure7(figure7_curves(hy.K, hy.h, hy.C_r, np.logspace(-3, 2, 401)), ax=axs[1])
    axs[1].set_title(
        f"fitted at {ref.label}: K {hy.K / 1e3:.3g} kN/m, h {hy.h / 1e3:.3g} kN/m, "
        f"C_r {hy.C_r / 1e3:.3g} kN s/m",
        fontsize="small",
    )
    return (
        fig,
        "Paper Fig. 7: amplitude ratio of the proposed model with its low-frequency "
        "(1/(i w C_r)) and high-frequency (1/(K + i h)) asymptotes, the Maxwell model and "
        f"the corner frequency f0 = K/(2 pi C_r) (eq. 38; f0 = {lat.figure7.f0:.4g} Hz and "
        f"{hy.corner_frequency():.3g} Hz).",
    )


def lateral_frf_figures(result: DemoResult) -> dict[str, tuple[Figure, str]]:
    """Paper Figs. 11-14: ground-force fits and axle-force predictions at each speed."""
    lat = result.lateral
    figs: dict[str, tuple[Figure, str]] = {}
    names = _paper_models(result.settings.lateral_models)
    p_ref = lat.reference.pressure_bar
    n = 11
    forces: tuple[tuple[ForceKind, str], ...] = (("ground", "reim"), ("axle", "bode"))
    for force, style in forces:
        for v in result.settings.lateral_speeds_kmh:
            cond = next(c for c in lat.conditions if c.pressure_bar == p_ref and c.speed_kmh == v)
            f, meas, preds, truth = _ground_axle(cond, names, lat.rig.wheel_mass, force)
            axs2 = plot_lateral_models(
                f,
                meas,
                preds,
                style=style,  # type: ignore[arg-type]
                truth=truth,
                title=f"{cond.label}, {force} force",
            )
            what = (
                "fits to the lateral acceleration per ground force (real and imaginary parts)"
                if force == "ground"
                else "predictions, from the ground-force fits and the 100 kg wheel, of the "
                "acceleration per axle force (amplitude ratio and phase)"
            )
            figs[f"fig{n}_{force}_{v:g}kmh"] = (
                _figure(axs2[0]),
                f"Paper Fig. {n}: measured (dots) against the models' {what} at {cond.label}; "
                "dotted black: the rig's exact FRF.",
            )
            n += 1
    return figs


def vehicle_figure(result: DemoResult) -> Built:
    """The single-DOF vehicle on each fitted tyre and on the rig's exact tyre."""
    lat = result.lateral
    ref = lat.reference
    veh = lat.vehicle
    f = np.linspace(0.25, 9.0, 500)
    fig = Figure(figsize=(7.5, 5.4), layout="constrained")
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 2])
    a_true = np.abs(veh.truth.accelerance(f))
    ax.semilogy(f, a_true, color="k", lw=1.5, label="rig truth")
    for i, (name, vh) in enumerate(veh.vehicles.items()):
        res = veh.resonances[name]
        lab = name + ("" if res is None else f" ({res.frequency:.2f} Hz)")
        a = np.abs(vh.accelerance(f))
        ax.semilogy(f, a, color=model_color(name, i), lw=1, label=lab)
        ax2.plot(f, 100 * (a / a_true - 1), color=model_color(name, i), lw=1)
    for a_ in (ax, ax2):
        a_.axvline(lat.time_test.frequency_hz, color="0.5", ls="--", lw=0.8)
    ax2.axhline(0.0, color="k", lw=1.0)
    ax2.set_xlabel("frequency (Hz)")
    ax.set_ylabel("|body acceleration / force| (m/(s^2 N))")
    ax2.set_ylabel("model / truth - 1 (%)")
    ax.grid(True, which="both", alpha=0.3)
    ax2.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small")
    return (
        fig,
        f"Single-degree-of-freedom vehicle (eq. 41-42): a {veh.body_mass:g} kg body on each "
        f"fitted tyre at {ref.label} and on the rig's exact tyre; body resonance in brackets; "
        f"dashed: the {lat.time_test.frequency_hz:g} Hz time test. Below, on a linear scale: "
        "each model's amplitude against the rig's exact one (the gap the log scale hides).",
    )


def time_response_figure(result: DemoResult) -> Built:
    """Paper Fig. 15: the sine test against each fitted model and the exact tyre."""
    lat = result.lateral
    ref = lat.reference
    names = _paper_models(result.settings.lateral_models)
    tt = lat.time_test
    fig = Figure(figsize=(8.0, 5.2), layout="constrained")
    axs = fig.subplots(2, 1, sharex=True)
    t = tt.data.time
    win = (t >= tt.window_s[0]) & (t <= tt.window_s[1])
    axs[0].plot(t[win], tt.data.data[0][win], color="0.25", lw=1)
    axs[0].set_ylabel("lateral force (N)")
    axs[0].grid(True, alpha=0.3)
    truth_acc, gaps = time_test_truth(result)
    plot_time_comparison(
        t,
        tt.data.data[1],
        {k: tt.predictions[k] for k in names},
        ax=axs[1],
        window=tt.window_s,
    )
    axs[1].plot(t, truth_acc, color="k", ls="--", lw=1.5, label="rig truth (exact)")
    axs[1].legend(loc="upper right", fontsize="small")
    axs[1].grid(True, alpha=0.3)
    best = min((k for k in names if k in gaps), key=lambda k: gaps[k], default=None)
    return (
        fig,
        f"Paper Fig. 15: lateral force and body acceleration at {tt.frequency_hz:g} Hz "
        f"({ref.label}), measured against the steady state of each fitted model and of the "
        f"rig's exact tyre (dashed; {tt.window_s[0]:g}-{tt.window_s[1]:g} s). The exact "
        f"response misses the measurement by {100 * gaps['truth_vs_measured']:.3g} % (noise)"
        + (
            ""
            if best is None
            else f"; the closest model ({best}) misses the exact response by "
            f"{100 * gaps[best]:.3g} %"
        )
        + ".",
    )


def mac_figure(result: DemoResult) -> Built:
    """Auto-MAC of the identified shapes at the main pressure and MAC across pressures."""
    from ..modal.statistics.indicators import auto_mac, mac

    runs = result.radial.runs
    main = runs[0]
    psi0 = main.models["complex"].psi_out
    f0 = main.models["complex"].frequency_hz
    n = len(runs)
    fig = Figure(figsize=(3.8 * n, 3.6), layout="constrained")
    axs = np.atleast_1d(fig.subplots(1, n))
    panels = [(auto_mac(psi0), f0, f"auto-MAC at {main.pressure_bar:g} bar")]
    for run in runs[1:]:
        m = run.models["complex"]
        panels.append(
            (
                mac(psi0, m.psi_out),
                m.frequency_hz,
                f"{main.pressure_bar:g} against {run.pressure_bar:g} bar",
            )
        )
    im = None
    for ax, (mm, fc, title) in zip(axs, panels, strict=True):
        im = ax.imshow(mm, cmap="viridis", vmin=0.0, vmax=1.0)
        ax.set_yticks(range(f0.size), [f"{f:.0f}" for f in f0], fontsize="x-small")
        ax.set_xticks(range(fc.size), [f"{f:.0f}" for f in fc], fontsize="x-small", rotation=90)
        for (i, j), v in np.ndenumerate(mm):
            ax.text(
                j,
                i,
                f"{v:.2f}",
                ha="center",
                va="center",
                fontsize=6,
                color="k" if v > 0.5 else "w",
            )
        ax.set_title(title, fontsize="small")
        ax.set_xlabel("mode (Hz)", fontsize="small")
    axs[0].set_ylabel(f"mode at {main.pressure_bar:g} bar (Hz)", fontsize="small")
    if im is not None:
        fig.colorbar(im, ax=list(axs), label="MAC")
    return (
        fig,
        "Modal assurance criterion of the identified complex shapes: with themselves at the "
        "main pressure (small off-diagonal values: distinct shapes, 16 points resolve them) and "
        "against the shapes identified at the other pressures (a value near 1 pairs the same "
        "mode; a missing partner marks a mode not found at that pressure).",
    )


def _residual_zoom(
    main: Any, meas: Any, real: Any, cplx: Any, out_i: int, in_i: int, lab: str
) -> tuple[Figure, str]:
    """Where the real-mode fit misses: per-line residual against the noise, and a zoom."""
    from ..studies.verdicts import frf_noise_variance

    f = meas.frequency
    fig = Figure(figsize=(8.0, 5.6), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1)
    for name, fr, c in (("real-mode fit", real, "C0"), ("complex-mode fit", cplx, "C1")):
        r = np.sqrt(np.mean(np.abs(fr.H - meas.H) ** 2, axis=(0, 1)))
        ax1.semilogy(f, r, color=c, lw=0.9, label=name)
    noise = frf_noise_variance(meas)
    if noise is not None:
        ax1.semilogy(
            f,
            np.sqrt(np.mean(noise[0], axis=(0, 1))),
            color="k",
            lw=0.9,
            ls="--",
            label="noise (from the coherence)",
        )
    ax1.set_ylabel(f"RMS residual ({meas.unit})")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize="x-small")
    lo = max(float(f[0]), 0.7 * float(f[-1]))
    keep = f >= lo
    ax2.semilogy(f[keep], np.abs(meas.H[out_i, in_i, keep]), "k.", ms=3, label="measured")
    ax2.semilogy(
        f[keep], np.abs(real.H[out_i, in_i, keep]), color="C0", lw=1, label="real-mode fit"
    )
    ax2.semilogy(
        f[keep],
        np.abs(cplx.H[out_i, in_i, keep]),
        color="C1",
        lw=1,
        ls="--",
        label="complex-mode fit",
    )
    ax2.set_xlabel("frequency (Hz)")
    ax2.set_ylabel(f"|H| {lab} ({meas.unit})")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize="x-small")
    return (
        fig,
        f"Where the real-mode fit misses at {main.pressure_bar:g} bar: RMS residual over the 16 "
        "FRFs per line against the noise the coherence implies (above) and the driving-point "
        f"amplitude zoomed on {lo:.0f}-{f[-1]:.0f} Hz (below), the upper part of the band where "
        "the paper saw the real-mode fit depart.",
    )
