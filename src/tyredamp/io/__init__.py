"""Measurement file formats: FRFs and time data in UFF, CSV, NPZ, TDMS, MDF4, LVM, MAT, WAV.

One module per format, one line per format in :data:`FILE_FORMATS`: its name,
the extensions it owns and its reader and writer (the module is imported when
a file of that format is read or written, so pyuff loads only for UFF files).
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
``.csv``, ``.txt``        also plain CSV exports with a header row (:mod:`.csv_format`)
``.lvm``                  LabVIEW Measurement time data, read only (:mod:`.lvm`)
``.mat``                  MATLAB v5 time data or FRFs, read only (:mod:`.mat`, scipy)
``.wav``                  WAV recordings, read only (:mod:`.wav`, scipy)
========================  ============================================

Channels whose role, unit or sensitivity the file does not state are named
with a :class:`ChannelMap` (``channel_map=``; on the command line
``--channel``, ``--sensitivity``, ``--channel-map``).

Writing takes ``format`` (``"uff58b"`` binary UFF, ``"uff58"`` ASCII UFF,
``"csv"``, ``"npz"``) or, by default, the extension (``.uff``/``.unv``: binary
58b, which is lossless). Every write is atomic (the file appears whole or not
at all) and input files are only ever opened for reading. Corrupt, truncated
or empty files raise :class:`~tyredamp.exceptions.FileFormatError` naming the
file and the problem. See ``docs/file-formats.md``. Result documents (modes,
damping, ... JSON) are :mod:`tyredamp.documents`.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, FRFKind
from ..timedata import TimeData
from ._guard import guarded_read
from .channelmap import ChannelMap, ChannelSpec

__all__ = [
    "FILE_FORMATS",
    "FORMATS",
    "ChannelMap",
    "ChannelSpec",
    "FileFormat",
    "format_of",
    "read",
    "read_frf",
    "read_timedata",
    "write",
    "write_frf",
    "write_timedata",
]

Format = Literal["uff58b", "uff58", "csv", "npz", "netcdf", "tdms", "mdf", "lvm", "mat", "wav"]


@dataclass(frozen=True)
class FileFormat:
    """One measurement file format.

    Attributes
    ----------
    name : str
        Format name (``format=`` of the writers).
    extensions : tuple of str
        Lower-case extensions read as (and written by default in) this format.
    module : str
        Module holding the reader and writer: ``".uff"`` (relative to this
        package) or an absolute module name.
    reader : str
        Its name: ``reader(path)`` returns an FRF or TimeData (with
        ``selects=True``: ``reader(path, what, kind)``, ``what`` in
        ``{"frf", "timedata", None}``).
    writer : str or None
        Its name, ``writer(obj, path, **write_options)``; None for a read-only
        format (acquisition files such as TDMS and MDF).
    selects : bool
        The reader can pick FRF or time data out of a file holding both.
    write_options : mapping
        Fixed keyword arguments of the writer.
    holds : {"any", "frf", "timedata"}
        What the format can hold: FRFs and time data, or only one of them
        (reading the other kind from it, or writing it, is an error before
        any I/O).
    maps : bool
        The reader takes ``channel_map=`` (a :class:`ChannelMap`): formats
        whose channels may lack roles, units or sensitivities.
    """

    name: str
    extensions: tuple[str, ...]
    module: str
    reader: str
    writer: str | None
    selects: bool = False
    write_options: Mapping[str, Any] = field(default_factory=dict)
    holds: Literal["any", "frf", "timedata"] = "any"
    maps: bool = False

    def _function(self, name: str) -> Callable[..., Any]:
        fn: Callable[..., Any] = getattr(importlib.import_module(self.module, __name__), name)
        return fn

    def read(
        self,
        path: str | os.PathLike[str],
        what: str | None = None,
        kind: FRFKind | None = None,
        channel_map: ChannelMap | None = None,
    ) -> FRF | TimeData:
        """Read ``path`` in this format (``what``/``kind`` only where the reader selects)."""
        if what is not None and self.holds not in ("any", what):
            held = "an FRF" if self.holds == "frf" else "time data"
            asked = "an FRF" if what == "frf" else "time data"
            raise FileFormatError(f"{path}: {self.name} files hold {held}, not {asked}")
        kw: dict[str, Any] = {}
        if channel_map:
            if not self.maps:
                raise InputError(
                    f"{path}: {self.name} files state what each channel is; a channel map "
                    "(--channel, --sensitivity, --channel-map) is not used for them"
                )
            kw["channel_map"] = channel_map
        with guarded_read(path):
            if self.selects:
                obj: FRF | TimeData = self._function(self.reader)(path, what, kind, **kw)
            else:
                obj = self._function(self.reader)(path, **kw)
        return obj

    def write(self, obj: FRF | TimeData, path: str | os.PathLike[str]) -> None:
        """Write ``obj`` to ``path`` in this format."""
        if self.writer is None:
            raise InputError(f"format: {self.name} is read only; write as one of {FORMATS}")
        if self.holds != "any" and isinstance(obj, FRF) != (self.holds == "frf"):
            held = "FRFs" if self.holds == "frf" else "time data"
            raise InputError(
                f"format: {self.name} ({', '.join(self.extensions)}) holds {held}, "
                f"not {type(obj).__name__}"
            )
        self._function(self.writer)(obj, path, **self.write_options)


#: Every measurement format; a new format is one module and one line here.
FILE_FORMATS: dict[str, FileFormat] = {
    f.name: f
    for f in (
        FileFormat(
            "uff58b",
            (".uff", ".unv", ".uf"),
            ".uff",
            "read_uff",
            "write_uff",
            True,
            {"binary": True},
            maps=True,
        ),
        FileFormat(
            "uff58", (), ".uff", "read_uff", "write_uff", True, {"binary": False}, maps=True
        ),
        FileFormat("csv", (".csv", ".txt"), ".csv_format", "read_csv", "write_csv", maps=True),
        FileFormat("npz", (".npz",), ".npz", "read_npz", "write_npz"),
        FileFormat("netcdf", (".nc",), ".netcdf", "read_netcdf", "write_netcdf", holds="frf"),
        FileFormat("tdms", (".tdms",), ".tdms", "read_tdms", None, holds="timedata", maps=True),
        FileFormat("mdf", (".mf4", ".mdf"), ".mdf", "read_mdf", None, holds="timedata", maps=True),
        FileFormat("lvm", (".lvm",), ".lvm", "read_lvm", None, holds="timedata", maps=True),
        FileFormat("mat", (".mat",), ".mat", "read_mat", None, True, maps=True),
        FileFormat("wav", (".wav",), ".wav", "read_wav", None, holds="timedata", maps=True),
    )
}
#: The built-in formats that can be written (choices of the command line).
FORMATS: tuple[str, ...] = tuple(n for n, f in FILE_FORMATS.items() if f.writer is not None)


def _extensions() -> dict[str, str]:
    """Extension -> format name, from :data:`FILE_FORMATS`."""
    return {ext: f.name for f in FILE_FORMATS.values() for ext in f.extensions}


def format_of(path: str | os.PathLike[str], format: str | None = None) -> Format:
    """The file format for ``path``: ``format`` when given, else from the extension."""
    if format is not None:
        if format not in FILE_FORMATS:
            raise InputError(f"format: expected one of {tuple(FILE_FORMATS)}, got {format!r}")
        return format  # type: ignore[return-value]
    ext = Path(path).suffix.lower()
    exts = _extensions()
    if ext not in exts:
        raise InputError(
            f"{path}: unknown file extension {ext or '(none)'!r}; expected one of "
            f"{', '.join(sorted(exts))} or an explicit format"
        )
    return exts[ext]  # type: ignore[return-value]


def _read_format(path: str | os.PathLike[str]) -> FileFormat:
    ext = Path(path).suffix.lower()
    exts = _extensions()
    if ext not in exts:
        raise FileFormatError(
            f"{path}: unknown file extension {ext or '(none)'!r}; expected one of "
            f"{', '.join(sorted(exts))}"
        )
    return FILE_FORMATS[exts[ext]]


def read(path: str | os.PathLike[str], channel_map: ChannelMap | None = None) -> FRF | TimeData:
    """Read whatever the file holds: an FRF or time data.

    Parameters
    ----------
    path : path-like
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of channels the file does not state
        (:mod:`tyredamp.io.channelmap`); for the acquisition formats (UFF time
        data, plain CSV, TDMS, MDF, LVM, MAT, WAV).
    """
    return _read_format(path).read(path, channel_map=channel_map)


def read_frf(
    path: str | os.PathLike[str],
    kind: FRFKind | None = None,
    channel_map: ChannelMap | None = None,
) -> FRF:
    """Read an FRF matrix from a UFF, CSV, NPZ, netCDF or MATLAB file.

    Parameters
    ----------
    path : path-like
    kind : {"receptance", "mobility", "accelerance"}, optional
        UFF and MATLAB: the FRF kind when the file does not state it.
    channel_map : ChannelMap, optional
        MATLAB and plain CSV: what an FRF relates (``"Hf_chan_2=acceleration:g/N"``).

    Raises
    ------
    FileFormatError
        The file is empty, truncated, corrupt, or holds time data.

    Examples
    --------
    Write an FRF of the virtual tyre as UFF 58b and read it back:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from tyredamp.io import read_frf, write_frf
    >>> from tyredamp.virtual import RingTyre
    >>> frf = RingTyre().truth().frf(np.arange(0.0, 200.25, 0.25))  # exact accelerances
    >>> path = write_frf(frf, Path(tempfile.mkdtemp()) / "tyre_frf.uff")
    >>> back = read_frf(path)
    >>> back.H.shape, back.kind
    ((16, 1, 801), 'accelerance')
    >>> bool(np.allclose(back.H, frf.H, rtol=1e-6))  # 58b keeps double precision
    True
    """
    obj = _read_format(path).read(path, "frf", kind, channel_map)
    if not isinstance(obj, FRF):
        raise FileFormatError(f"{path}: holds time data, not an FRF")
    return obj


def read_timedata(path: str | os.PathLike[str], channel_map: ChannelMap | None = None) -> TimeData:
    """Read time data from a UFF, CSV, NPZ, TDMS, MDF, LVM, MATLAB or WAV file.

    Parameters
    ----------
    path : path-like
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of channels the file does not state
        (:mod:`tyredamp.io.channelmap`).

    Raises
    ------
    FileFormatError
        The file is empty, truncated, corrupt, or holds an FRF.
    """
    obj = _read_format(path).read(path, "timedata", channel_map=channel_map)
    if not isinstance(obj, TimeData):
        raise FileFormatError(f"{path}: holds an FRF, not time data")
    return obj


def write(obj: FRF | TimeData, path: str | os.PathLike[str], format: str | None = None) -> Path:
    """Write an FRF or TimeData; returns the path written.

    Parameters
    ----------
    obj : FRF or TimeData
    path : path-like
    format : {"uff58b", "uff58", "csv", "npz", "netcdf"}, optional
        Default from the extension (``.uff``/``.unv``: ``"uff58b"``).
    """
    fmt = format_of(path, format)
    if not isinstance(obj, FRF | TimeData):
        raise InputError(f"obj: expected FRF or TimeData, got {type(obj).__name__}")
    FILE_FORMATS[fmt].write(obj, path)
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
