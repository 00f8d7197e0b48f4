"""The FRF and TimeData objects: shapes, conversions, slicing, validation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp import FRF, Channel, InputError, ShapeError
from tyredamp.frf import UNITS
from tyredamp.timedata import TimeData


def _frf(n_out: int = 3, n_in: int = 2, n_f: int = 11, f0: float = 0.0) -> FRF:
    rng = np.random.default_rng(0)
    f = np.linspace(f0, 100.0, n_f)
    h = rng.normal(size=(n_out, n_in, n_f)) + 1j * rng.normal(size=(n_out, n_in, n_f))
    return FRF(f, h, outputs=[Channel(i + 1, 3, 22.5 * i) for i in range(n_out)])


def test_always_three_dimensional() -> None:
    assert FRF([1.0, 2.0], [1j, 2j]).H.shape == (1, 1, 2)
    assert FRF([1.0, 2.0], np.ones((4, 2))).H.shape == (4, 1, 2)
    f = _frf()
    assert (f.n_out, f.n_in, f.n_freq) == (3, 2, 11)
    assert f.unit == UNITS["receptance"] == "m/N"


def test_immutable() -> None:
    f = _frf()
    with pytest.raises(ValueError, match="read-only"):
        f.H[0, 0, 0] = 1.0
    with pytest.raises(AttributeError):
        f.kind = "mobility"  # type: ignore[misc]


@given(st.sampled_from(["receptance", "mobility", "accelerance"]))
@settings(max_examples=10, deadline=None)
def test_conversion_round_trip(kind: str) -> None:
    f = _frf(f0=1.0)
    back = f.to(kind).to("receptance")  # type: ignore[arg-type]
    assert_allclose(back.H, f.H, rtol=1e-14)  # two multiplications, rounding only


def test_conversion_factors() -> None:
    f = _frf(f0=1.0)
    w = 2 * np.pi * f.frequency
    assert_allclose(f.mobility().H, 1j * w * f.H, rtol=1e-15)
    assert_allclose(f.accelerance().H, -(w**2) * f.H, rtol=1e-15)


def test_zero_hz_conversion() -> None:
    f = _frf(f0=0.0)
    a = f.accelerance()
    assert a.n_freq == f.n_freq  # multiplying by omega keeps 0 Hz (value 0)
    assert np.all(a.H[:, :, 0] == 0)
    r = a.receptance()  # dividing drops the 0 Hz line
    assert r.n_freq == f.n_freq - 1
    assert r.frequency[0] > 0
    with pytest.raises(InputError, match="0 Hz"):
        a.to("receptance", at_zero="raise")


def test_band_and_select() -> None:
    f = _frf()
    b = f.band(20.0, 60.0)
    assert b.frequency.min() >= 20
    assert b.frequency.max() <= 60
    s = f.select(outputs=[2, 0], inputs=[1])
    assert s.H.shape == (2, 1, 11)
    assert s.outputs[0].node == 3
    assert s.outputs[0].angle_deg == 45.0
    assert_allclose(s.H[0, 0], f.H[2, 1])
    with pytest.raises(InputError, match="no line"):
        f.band(200.0, 300.0)


def test_drive_points() -> None:
    f = FRF([1.0, 2.0], np.ones((3, 2, 2)), outputs=[1, 2, 3], inputs=[3, 1])
    assert f.drive_points() == [(2, 0), (0, 1)]
    assert f.output_index(2) == 1


@pytest.mark.parametrize(
    ("freq", "h", "exc", "word"),
    [
        ([1.0, 3.0, 2.0], np.ones(3), InputError, "strictly increasing"),
        ([1.0, np.nan, 3.0], np.ones(3), InputError, "finite"),
        ([1.0, 2.0, 3.0], np.ones(4), ShapeError, "frequency lines"),
        ([1.0, 2.0], [1.0, np.nan], InputError, "finite"),
        ([-1.0, 2.0], np.ones(2), InputError, "non-negative"),
        ([], [], ShapeError, "non-empty"),
    ],
)
def test_bad_frf(freq, h, exc, word) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc, match=word):
        FRF(freq, h)


def test_bad_kind_and_labels() -> None:
    with pytest.raises(InputError, match="kind"):
        FRF([1.0], [1.0], kind="inertance")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="outputs"):
        FRF([1.0], np.ones((2, 1, 1)), outputs=[1])
    with pytest.raises(InputError, match="direction"):
        Channel(1, direction=9)


def test_timedata() -> None:
    td = TimeData(np.zeros((3, 100)), 1000.0, [1, 2, 3], ["force", "acceleration", "velocity"])
    assert td.force_indices == [0]
    assert td.response_indices == [1, 2]
    assert td.units == ("N", "m/s^2", "m/s")
    assert_allclose(td.time[-1], 0.099)
    with pytest.raises(ShapeError, match="channels"):
        TimeData(np.zeros((3, 100)), 1000.0, [1, 2], ["force"] * 3)
    with pytest.raises(InputError, match="channel quantity 'strain': expected one of force"):
        TimeData(np.zeros((1, 100)), 1000.0, [1], ["strain"])
    with pytest.raises(InputError, match="finite"):
        TimeData(np.full((1, 10), np.nan), 1000.0, [1], ["force"])
    with pytest.raises(InputError, match="sample_rate"):
        TimeData(np.zeros((1, 10)), -5.0, [1], ["force"])
