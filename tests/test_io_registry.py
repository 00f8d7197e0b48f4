"""The measurement-format registry: a new format is one module and one registry line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import tyredamp.io as tio
from tyredamp import FRF, Channel
from tyredamp.exceptions import FileFormatError, InputError


def test_a_new_format_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fmt = tio.FileFormat("text", (".txt",), "tests.plain_text_format", "read_text", "write_text")
    monkeypatch.setitem(tio.FILE_FORMATS, "text", fmt)
    f = np.array([1.0, 2.0, 4.0])
    frf = FRF(f, (1 / (1 + 1j * f)).reshape(1, 1, 3), outputs=[Channel(1)], inputs=[Channel(1)])
    path = tio.write_frf(frf, tmp_path / "a.txt")
    back = tio.read_frf(path)
    assert_allclose(back.H, frf.H, rtol=1e-15)  # savetxt's %.18e keeps doubles
    assert tio.format_of("b.txt") == "text"
    assert tio.format_of("b.dat", "text") == "text"


def test_unknown_extension_and_format(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"unknown file extension '\.dat'"):
        tio.read(tmp_path / "x.dat")
    with pytest.raises(InputError, match="format: expected one of"):
        tio.format_of("x.uff", "hdf5")


def test_pyuff_loads_only_for_uff_files() -> None:
    code = (
        "import sys, tyredamp.io, tyredamp.documents\n"
        "assert 'pyuff' not in sys.modules\n"
        "assert tyredamp.io.format_of('a.uff') == 'uff58b'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_read_only_and_one_kind_formats(tmp_path: Path) -> None:
    assert "tdms" in tio.FILE_FORMATS
    assert "tdms" not in tio.FORMATS  # not a write choice
    assert "netcdf" in tio.FORMATS
    f = np.array([1.0, 2.0])
    frf = FRF(f, np.ones((1, 1, 2), complex), outputs=[Channel(1)], inputs=[Channel(1)])
    with pytest.raises(InputError, match="tdms is read only"):
        tio.write(frf, tmp_path / "a.tdms")
    assert not (tmp_path / "a.tdms").exists()
    # asking a time-data-only format for an FRF fails before the file is opened
    with pytest.raises(FileFormatError, match="tdms files hold time data, not an FRF"):
        tio.read_frf(tmp_path / "missing.tdms")
    with pytest.raises(FileFormatError, match="netcdf files hold an FRF, not time data"):
        tio.read_timedata(tmp_path / "missing.nc")
