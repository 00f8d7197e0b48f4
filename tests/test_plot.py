"""Figures draw what they are given (data checked on the returned artists)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import FRF, Channel
from tyredamp.modal import ModalModel
from tyredamp.plot import (
    plot_discrepancy,
    plot_frf,
    plot_frf_comparison,
    plot_matrix,
    plot_mode_shapes_ring,
)

from .helpers import chain_system


def test_plot_frf_draws_data() -> None:
    f = np.linspace(1, 10, 20)
    h = 1 / (50 - f**2 + 1j * f)
    axes = plot_frf(FRF(f, h), style="all")
    assert len(axes) == 4
    assert_allclose(axes[0].lines[0].get_ydata(), h.real)
    assert_allclose(axes[2].lines[0].get_ydata(), 20 * np.log10(np.abs(h)))
    with pytest.raises(ValueError, match="style"):
        plot_frf(FRF(f, h), style="nyquist")  # type: ignore[arg-type]


def test_comparison_and_discrepancy() -> None:
    s = chain_system()
    cm = s.complex_modes()
    f = np.linspace(1, 40, 100)
    meas = s.frf(f, inputs=[0])
    mm = ModalModel(cm.poles[:3], cm.psi[:, :3], cm.psi[[0], :3])
    fit = mm.frf(f)
    axes = plot_frf_comparison(meas, {"fit": fit})
    assert len(axes[0].lines) == 2
    ax = plot_discrepancy(meas, {"fit": fit}, {"fit": 1e-3})
    d = np.sqrt(np.sum(np.abs(fit.H - meas.H) ** 2, axis=(0, 1)))
    assert_allclose(ax.lines[0].get_ydata(), d)
    assert "RMSD 0.001" in ax.get_legend().get_texts()[0].get_text()


def test_matrix_and_ring() -> None:
    a = np.array([[1.0, -0.5], [-0.5, 2.0]])
    ax = plot_matrix(a, ["a", "b"])
    assert_allclose(ax.images[0].get_array(), a)
    assert ax.images[0].get_clim() == (-2.0, 2.0)
    s = chain_system()
    cm = s.complex_modes()
    mm = ModalModel(
        cm.poles, cm.psi, cm.psi[[0]], outputs=[Channel(i + 1, 3, 60.0 * i) for i in range(6)]
    )
    axes = plot_mode_shapes_ring(mm, modes=[0, 2])
    assert len(axes) == 2
    assert "Hz" in axes[0].get_title()
