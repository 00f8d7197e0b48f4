"""FRF <-> xarray Dataset and netCDF files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from tyredamp import Channel, FileFormatError, InputError
from tyredamp.frf import FRF
from tyredamp.io import read, read_frf, write, write_frf
from tyredamp.timedata import TimeData

xr = pytest.importorskip("xarray")


def sample() -> FRF:
    rng = np.random.default_rng(0)
    f = np.arange(1, 21) * 0.5
    h = rng.normal(size=(3, 2, 20)) + 1j * rng.normal(size=(3, 2, 20))
    outs = [Channel(i + 1, 3, 22.5 * i, f"acc{i}") for i in range(3)]
    ins = [Channel(1, 3), Channel(9, -2, None, "shaker B")]
    return FRF(
        f,
        h,
        "accelerance",
        outs,
        ins,
        coherence=rng.random((3, 20)),
        meta={"estimator": "H1", "n_averages": 8},
        variance=rng.random((3, 2, 20)),
    )


def same(a: FRF, b: FRF) -> None:
    assert_array_equal(b.frequency, a.frequency)
    assert_array_equal(b.H, a.H)
    assert_array_equal(b.coherence, a.coherence)
    assert_array_equal(b.variance, a.variance)
    assert b.kind == a.kind
    assert b.outputs == a.outputs
    assert b.inputs == a.inputs
    assert b.meta == a.meta


def test_to_xarray_has_named_dimensions_and_round_trips() -> None:
    frf = sample()
    ds = frf.to_xarray()
    assert ds["H"].dims == ("output", "input", "frequency")
    assert list(ds["output"].values) == ["acc0", "acc1", "acc2"]
    assert list(ds["input"].values) == ["1+Z", "shaker B"]
    assert ds["frequency"].attrs["units"] == "Hz"
    assert ds.attrs["kind"] == "accelerance"
    # select by label as any xarray user would
    assert_array_equal(ds["H"].sel(output="acc1", input="shaker B").values, frf.H[1, 1])
    same(frf, FRF.from_xarray(ds))


def test_netcdf_file_round_trip(tmp_path: Path) -> None:
    frf = sample()
    path = write_frf(frf, tmp_path / "frf.nc")
    same(frf, read_frf(path))
    with xr.open_dataset(path, engine="scipy") as ds:  # a plain netCDF reader sees named arrays
        assert ds["H_real"].dims == ("output", "input", "frequency")
    no_extras = FRF(frf.frequency, frf.H)
    same(no_extras, read(write(no_extras, tmp_path / "plain.nc")))  # type: ignore[arg-type]


def test_netcdf_bad_input(tmp_path: Path) -> None:
    td = TimeData(np.ones((2, 10)), 1.0, [1, 2], ["force", "acceleration"])
    with pytest.raises(InputError, match=r"netcdf \(\.nc\) holds FRFs, not TimeData"):
        write(td, tmp_path / "td.nc")
    assert not (tmp_path / "td.nc").exists()
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"CDF\x01garbage" * 5)
    with pytest.raises(FileFormatError, match="not a readable netCDF"):
        read_frf(bad)
    other = tmp_path / "other.nc"
    xr.Dataset({"x": ("t", np.arange(3.0))}).to_netcdf(other, engine="scipy")
    with pytest.raises(FileFormatError, match="not a tyredamp FRF"):
        read_frf(other)
    with pytest.raises(InputError, match="'H'"):
        FRF.from_xarray(xr.Dataset({"x": ("t", np.arange(3.0))}))
