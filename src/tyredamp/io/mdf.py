"""ASAM MDF4 (and MDF3) time data through asammdf.

Every non-master channel of the file is read (``channels`` selects by name).
They must share one time base: equal, evenly spaced timestamps; the sample
rate is ``(n - 1) / (t[-1] - t[0])`` (snapped to the integer it stands for).
Units come from each channel's unit (read by :mod:`.units`, converted to
SI); the force is the channel with a force unit or the one named
``"force"`` in ``quantities`` (see :mod:`._channels`). Channels are numbered
as nodes 1..n in file order (direction +Z), named as in the file.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from ..exceptions import FileFormatError
from ..timedata import TimeData
from ._channels import snap_rate, timedata_from_channels
from ._common import check_input_file

__all__ = ["read_mdf"]


def read_mdf(
    path: str | os.PathLike[str],
    quantities: Mapping[str, str] | None = None,
    channels: Sequence[str] | None = None,
) -> TimeData:
    """Read time data from an MDF file (``.mf4``, ``.mdf``).

    Parameters
    ----------
    path : path-like
    quantities : mapping of channel name to quantity, optional
        For channels whose unit is blank (or to override it).
    channels : sequence of str, optional
        Channel names to read (default all).

    Raises
    ------
    FileFormatError
        Not an MDF file, no channels, channels on different time bases,
        uneven sampling, unknown quantities, no force channel.
    """
    try:
        from asammdf import MDF
    except ImportError:  # pragma: no cover - optional dependency
        raise FileFormatError(
            f"{path}: reading MDF needs asammdf (pip install 'tyredamp[mdf]')"
        ) from None
    p = check_input_file(path)
    try:
        with MDF(str(p)) as mdf:
            sigs = [s for s in mdf.iter_channels() if channels is None or s.name in channels]
            names = [str(s.name) for s in sigs]
            units = [str(s.unit or "") for s in sigs]
            arrays = [np.asarray(s.samples, dtype=float) for s in sigs]
            stamps = [np.asarray(s.timestamps, dtype=float) for s in sigs]
    except FileFormatError:
        raise
    except Exception as exc:  # asammdf raises MdfException, ValueError ... on garbage
        raise FileFormatError(f"{p}: not a readable MDF file ({exc})") from None
    if channels is not None:
        missing = [c for c in channels if c not in names]
        if missing:
            raise FileFormatError(f"{p}: no channel named {missing[0]!r}")
    if not sigs:
        raise FileFormatError(f"{p}: no data channels in the MDF file")
    t = stamps[0]
    if t.size < 2:
        raise FileFormatError(f"{p}: fewer than 2 samples")
    for name, ts in zip(names, stamps, strict=True):
        if ts.shape != t.shape or not np.array_equal(ts, t):
            raise FileFormatError(
                f"{p}: channel {name!r} is on another time base than {names[0]!r}; read "
                "channels of one rate (channels=...)"
            )
    dt = np.diff(t)
    span = float(t[-1] - t[0])
    if span <= 0 or np.any(dt <= 0) or np.ptp(dt) > 1e-6 * span / (t.size - 1):
        raise FileFormatError(f"{p}: timestamps are not evenly increasing")
    fs = snap_rate((t.size - 1) / span)
    return timedata_from_channels(p, names, units, arrays, fs, quantities)
