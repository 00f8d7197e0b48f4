"""Lateral figures draw without error and return what they drew."""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes

from tyredamp.lateral import HystereticModel, fit_model, rank_models
from tyredamp.plot.lateral import (
    plot_figure7,
    plot_lateral_fit,
    plot_ranking,
    plot_time_comparison,
)
from tyredamp.virtual import VirtualLateralRig


def test_figure7() -> None:
    out = plot_figure7()
    assert isinstance(out["ax"], Axes)
    # The model line is the proposed model's amplitude ratio in dB re 1 m/N.
    y = out["model"].get_ydata()
    m = HystereticModel(260e3, 20e3, 300e3)
    f = out["model"].get_xdata()
    assert np.allclose(y, 20 * np.log10(np.abs(m.receptance(f))))


def test_fit_and_ranking_plots() -> None:
    d = VirtualLateralRig().measure(5.0, 1.7)
    fit = fit_model(d, "proposed")
    axes = plot_lateral_fit(fit)
    assert len(axes) == 2
    assert len(axes[0].lines) == 2
    axes = fit.plot(style="bode")
    assert axes[1].get_ylabel() == "phase (deg)"
    r = rank_models(d, ["maxwell", "hysteretic"])
    axes = plot_ranking(r)
    assert len(axes[0].lines) == 3


def test_time_plot() -> None:
    t = np.linspace(0, 6, 601)
    ax = plot_time_comparison(t, np.sin(t), {"model": np.cos(t)})
    assert len(ax.lines) == 2
    assert ax.get_xlim() == (4.0, 6.0)
