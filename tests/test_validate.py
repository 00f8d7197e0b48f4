"""The shared checks and helpers: as_band, pole_quantities, the FRF-kind table, plot axes."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import FRF, Channel
from tyredamp._validate import as_band
from tyredamp.exceptions import InputError
from tyredamp.frf import KIND_POWER
from tyredamp.mechanics import kind_factor, pole_from_frequency_damping, pole_quantities


@pytest.mark.parametrize(
    ("band", "expected"),
    [((0, 200), (0.0, 200.0)), ([30.5, 31.0], (30.5, 31.0)), (np.array([1.0, 2.0]), (1.0, 2.0))],
)
def test_as_band_accepts(band: Any, expected: tuple[float, float]) -> None:
    out = as_band(band)
    assert out == expected
    assert all(type(x) is float for x in out)


@pytest.mark.parametrize(
    "band",
    [(5.0, 2.0), (2.0, 2.0), (-1.0, 2.0), (0.0, np.inf), (np.nan, 1.0), (1.0,), "wide", None, 3.0],
)
def test_as_band_rejects(band: Any) -> None:
    with pytest.raises(InputError, match=r"^width: expected \(f_lo, f_hi\) in Hz with 0 <= f_lo"):
        as_band(band, "width")


def test_as_band_positive() -> None:
    assert as_band((0.1, 1.0), positive=True) == (0.1, 1.0)
    with pytest.raises(InputError, match="0 < f_lo < f_hi"):
        as_band((0.0, 1.0), positive=True)


def test_one_band_rule_everywhere() -> None:
    # the FRF's band selection and the modal identification share the rule
    frf = FRF(np.arange(5.0), np.ones((1, 1, 5)), outputs=[Channel(1)], inputs=[Channel(1)])
    assert frf.band(1.0, 3.0).n_freq == 3
    with pytest.raises(InputError, match="0 <= f_lo < f_hi"):
        frf.band(-1.0, 3.0)


def test_pole_quantities_inverts_the_pole_formula() -> None:
    f = np.array([12.5, 47.9, 180.0])
    z = np.array([0.0, 0.02, 0.3])
    p = pole_from_frequency_damping(f, z)
    fn, zeta = pole_quantities(p)
    # round trip through sqrt(1 - zeta^2): a few ulps
    assert_allclose(fn, f, rtol=1e-14)
    assert_allclose(zeta, z, rtol=1e-14, atol=1e-16)
    # closed form: p = -3 + 4i -> |p| = 5 rad/s, zeta = 3/5
    fn1, z1 = pole_quantities(-3 + 4j)
    assert fn1 == pytest.approx(5 / (2 * np.pi), rel=1e-15)
    assert z1 == pytest.approx(0.6, rel=1e-15)


def test_kind_table_matches_kind_factor() -> None:
    w = np.array([2.0, 3.0])
    for kind, k in KIND_POWER.items():
        assert_allclose(kind_factor(w, kind), (1j * w) ** k, rtol=0)  # type: ignore[arg-type]


def test_plot_axes_helper_counts() -> None:
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    from tyredamp.plot._axes import axes_grid, single_axes

    ax = Figure().subplots()
    assert single_axes(ax, (1.0, 1.0)) is ax
    assert len(axes_grid(None, 3, (4.0, 6.0))) == 3
    assert len(axes_grid(None, 2, (6.0, 3.0), columns=True)) == 2
    with pytest.raises(InputError, match="axes: expected 2 axes, got 1"):
        axes_grid([ax], 2, (1.0, 1.0))
