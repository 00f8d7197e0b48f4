"""Named channels with units labels (TDMS, MDF4) to a :class:`TimeData`.

Shared by the readers of acquisition formats that store channels by name with
a units label and a sample interval. Which channel is the force: the one
whose units label is a force (``N``, ``kN``, ``lbf`` ...; read by
:mod:`.units`), or the one named in ``quantities`` (channel name ->
``"force"``, ``"acceleration"``, ...), which also fills or overrides the
quantity of channels whose label is blank or not a physical unit.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..exceptions import FileFormatError, InputError
from ..frf import Channel
from ..timedata import QUANTITY_UNITS, TimeData
from .units import quantity_units

__all__ = ["snap_rate", "timedata_from_channels"]


def snap_rate(fs: float) -> float:
    """A sample rate from a stored interval, snapped to the integer it stands for (1e-9)."""
    r = round(fs)
    return float(r) if r > 0 and abs(fs - r) <= 1e-9 * fs else float(fs)


def timedata_from_channels(
    path: Path,
    names: Sequence[str],
    units: Sequence[str],
    arrays: Sequence[NDArray[np.float64]],
    sample_rate: float,
    quantities: Mapping[str, str] | None = None,
) -> TimeData:
    """Build time data from named channels; units converted to SI.

    Raises
    ------
    FileFormatError
        No channels, channels of unequal length, a channel whose quantity
        cannot be told (blank unit and not in ``quantities``), an unreadable
        units label, no force channel.
    """
    if not names:
        raise FileFormatError(f"{path}: no data channels")
    q_given = dict(quantities or {})
    unknown = [k for k in q_given if k not in names]
    if unknown:
        raise InputError(
            f"quantities: no channel named {unknown[0]!r} in {path}; channels: {', '.join(names)}"
        )
    for k, v in q_given.items():
        if v not in QUANTITY_UNITS:
            raise InputError(
                f"quantities[{k!r}]: expected one of {tuple(QUANTITY_UNITS)}, got {v!r}"
            )
    n = len(arrays[0])
    rows, quants, chans = [], [], []
    for i, (name, unit, a) in enumerate(zip(names, units, arrays, strict=True)):
        where = f"{path}: channel {name!r}"
        if len(a) != n:
            raise FileFormatError(
                f"{where}: {len(a)} samples, but channel {names[0]!r} has {n}; channels must "
                "have equal length"
            )
        try:
            qu = quantity_units(unit)
        except InputError as exc:
            if name not in q_given:
                raise FileFormatError(f"{where}: {exc}") from None
            qu = None
        q = q_given.get(name) or (qu[0] if qu else None)
        if q is None:
            raise FileFormatError(
                f"{where}: no units label tells its quantity; name it in quantities= "
                "(channel name -> force, displacement, velocity or acceleration)"
            )
        scale = qu[1] if (qu is not None and qu[0] == q) else 1.0
        try:
            rows.append(np.asarray(a, dtype=float) * scale)
        except (TypeError, ValueError):
            raise FileFormatError(f"{where}: values are not numbers") from None
        quants.append(q)
        chans.append(Channel(node=i + 1, direction=3, name=str(name)))
    if "force" not in quants:
        raise FileFormatError(
            f"{path}: no force channel (none has a force unit such as N, kN, lbf); name it "
            "with quantities={'<channel>': 'force'}"
        )
    try:
        return TimeData(np.array(rows), sample_rate, chans, quants)
    except InputError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
