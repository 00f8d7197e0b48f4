"""File formats: UFF 58/58b (pyuff), CSV and NPZ for FRFs and time data.

Reading dispatches on the file extension:

========================  ============================================
extension                 format
========================  ============================================
``.uff``, ``.unv``, ``.uf``  UFF data set 58, ASCII or binary 58b (read both)
``.csv``                  tyredamp CSV layout (:mod:`.csv_format`)
``.npz``                  tyredamp NPZ layout (:mod:`.npz`)
``.nc``                   FRF as netCDF with named dimensions (:mod:`.netcdf`, xarray)
``.tdms``                 NI TDMS time data, read only (:mod:`.tdms`, npTDMS)
``.mf4``, ``.mdf``        ASAM MDF time data, read only (:mod:`.mdf`, asammdf)
========================  ============================================

Writing takes ``format`` (``"uff58b"`` binary UFF, ``"uff58"`` ASCII UFF,
``"csv"``, ``"npz"``) or, by default, the extension (``.uff``/``.unv``: binary
58b, which is lossless). Every write is atomic (the file appears whole or not
at all) and input files are only ever opened for reading. Corrupt, truncated
or empty files raise :class:`~tyredamp.exceptions.FileFormatError` naming the
file and the problem. See ``docs/file-formats.md``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, FRFKind
from ..timedata import TimeData
from .csv_format import read_csv, write_csv
from .npz import read_npz, write_npz
from .uff import read_uff, write_uff

__all__ = [
    "FORMATS",
    "format_of",
    "read",
    "read_frf",
    "read_timedata",
    "write",
    "write_frf",
    "write_timedata",
]

Format = Literal["uff58b", "uff58", "csv", "npz", "netcdf"]
#: Formats accepted by the writers.
FORMATS: tuple[str, ...] = ("uff58b", "uff58", "csv", "npz", "netcdf")
_EXT: dict[str, Format] = {
    ".uff": "uff58b",
    ".unv": "uff58b",
    ".uf": "uff58b",
    ".csv": "csv",
    ".npz": "npz",
    ".nc": "netcdf",
}


def format_of(path: str | os.PathLike[str], format: str | None = None) -> Format:
    """The file format for ``path``: ``format`` when given, else from the extension."""
    if format is not None:
        if format not in FORMATS:
            raise InputError(f"format: expected one of {FORMATS}, got {format!r}")
        return format  # type: ignore[return-value]
    ext = Path(path).suffix.lower()
    if ext not in _EXT:
        raise InputError(
            f"{path}: unknown file extension {ext or '(none)'!r}; expected one of "
            f"{', '.join(sorted(_EXT))} or an explicit format"
        )
    return _EXT[ext]


#: Read-only time-data formats: extension -> reader module (imported when used).
_READ_ONLY: dict[str, str] = {".tdms": "tdms", ".mf4": "mdf", ".mdf": "mdf"}


def _read_only(path: str | os.PathLike[str]) -> TimeData | None:
    """Time data of a read-only acquisition format (TDMS, MDF), None for the other formats."""
    ext = Path(path).suffix.lower()
    if ext == ".tdms":
        from .tdms import read_tdms

        return read_tdms(path)
    if ext in (".mf4", ".mdf"):
        from .mdf import read_mdf

        return read_mdf(path)
    return None


def _read_format(path: str | os.PathLike[str]) -> Format:
    ext = Path(path).suffix.lower()
    if ext not in _EXT:
        raise FileFormatError(
            f"{path}: unknown file extension {ext or '(none)'!r}; expected one of "
            f"{', '.join(sorted([*_EXT, *_READ_ONLY]))}"
        )
    return _EXT[ext]


def read(path: str | os.PathLike[str]) -> FRF | TimeData:
    """Read whatever the file holds: an FRF or time data."""
    td = _read_only(path)
    if td is not None:
        return td
    fmt = _read_format(path)
    if fmt == "csv":
        return read_csv(path)
    if fmt == "npz":
        return read_npz(path)
    if fmt == "netcdf":
        from .netcdf import read_netcdf

        return read_netcdf(path)
    return read_uff(path)


def read_frf(path: str | os.PathLike[str], kind: FRFKind | None = None) -> FRF:
    """Read an FRF matrix from a UFF, CSV or NPZ file.

    Parameters
    ----------
    path : path-like
    kind : {"receptance", "mobility", "accelerance"}, optional
        UFF only: the FRF kind when the file does not state it.

    Raises
    ------
    FileFormatError
        The file is empty, truncated, corrupt, or holds time data.
    """
    if Path(path).suffix.lower() in _READ_ONLY:
        raise FileFormatError(f"{path}: TDMS and MDF files hold time data, not an FRF")
    fmt = _read_format(path)
    obj = read_uff(path, "frf", kind) if fmt.startswith("uff") else read(path)
    if not isinstance(obj, FRF):
        raise FileFormatError(f"{path}: holds time data, not an FRF")
    return obj


def read_timedata(path: str | os.PathLike[str]) -> TimeData:
    """Read time data from a UFF, CSV, NPZ, TDMS or MDF file.

    Raises
    ------
    FileFormatError
        The file is empty, truncated, corrupt, or holds an FRF.
    """
    td = _read_only(path)
    if td is not None:
        return td
    fmt = _read_format(path)
    obj = read_uff(path, "timedata") if fmt.startswith("uff") else read(path)
    if not isinstance(obj, TimeData):
        raise FileFormatError(f"{path}: holds an FRF, not time data")
    return obj


def write(obj: FRF | TimeData, path: str | os.PathLike[str], format: str | None = None) -> Path:
    """Write an FRF or TimeData; returns the path written.

    Parameters
    ----------
    obj : FRF or TimeData
    path : path-like
    format : {"uff58b", "uff58", "csv", "npz"}, optional
        Default from the extension (``.uff``/``.unv``: ``"uff58b"``).
    """
    fmt = format_of(path, format)
    if not isinstance(obj, FRF | TimeData):
        raise InputError(f"obj: expected FRF or TimeData, got {type(obj).__name__}")
    if fmt == "csv":
        write_csv(obj, path)
    elif fmt == "npz":
        write_npz(obj, path)
    elif fmt == "netcdf":
        if not isinstance(obj, FRF):
            raise InputError("format: netCDF (.nc) holds FRFs; write time data as NPZ, CSV or UFF")
        from .netcdf import write_netcdf

        write_netcdf(obj, path)
    else:
        write_uff(obj, path, binary=fmt == "uff58b")
    return Path(path)


def write_frf(frf: FRF, path: str | os.PathLike[str], format: str | None = None) -> Path:
    """Write an FRF (see :func:`write`)."""
    if not isinstance(frf, FRF):
        raise InputError(f"frf: expected an FRF, got {type(frf).__name__}")
    return write(frf, path, format)


def write_timedata(
    timedata: TimeData, path: str | os.PathLike[str], format: str | None = None
) -> Path:
    """Write time data (see :func:`write`)."""
    if not isinstance(timedata, TimeData):
        raise InputError(f"timedata: expected a TimeData, got {type(timedata).__name__}")
    return write(timedata, path, format)
