"""ASAM MDF4 (and MDF3) time data through asammdf.

An MDF file holds channel groups, each on its own time base (a logger
records fast vibration channels beside slow temperatures, CAN signals, text
and value-table channels). One time base is read: the group of the channels
the user names (``channels`` or the channel map), else the time base with
the most numeric channels. On that time base the numeric channels are read;
text, value-table (strings) and structure channels, channels of other rates
and channels whose unit is not a vibration quantity (``degC``, ``rpm``,
``km/h``) when the map does not name them are left out, and the left-out
names and why are listed in ``meta["read_notes"]``.

The sample rate is ``(n - 1) / (t[-1] - t[0])`` of the evenly spaced
timestamps (snapped to the integer it stands for). Units come from each
channel's unit (read by :mod:`.units`, converted to SI) or from the channel
map (see :mod:`._channels`). Channels are numbered as nodes 1..n in the
order read (direction +Z), named as in the file.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..timedata import TimeData
from ._channels import snap_rate, timedata_from_channels
from ._common import check_input_file
from ._guard import axis_scale, quiet_libraries
from .channelmap import ChannelMap
from .units import quantity_units

__all__ = ["read_mdf"]


def _is_vibration_unit(unit: str) -> bool:
    try:
        quantity_units(unit)
    except InputError:
        return False
    return True


def _choose_group(
    p: Any,
    sigs: Sequence[Any],
    names: list[str],
    groups: list[int],
    numeric: list[int],
    wanted: list[str],
    skipped: list[str],
) -> int:
    """The channel group to read: that of the named channels, else the one with the most
    numeric channels of vibration units (or without a unit)."""
    named = [k for k in numeric if names[k] in wanted]
    if named:
        group_of = {groups[k] for k in named}
        if len(group_of) > 1:
            raise InputError(
                f"{p}: the channels named ({', '.join(names[k] for k in named)}) are on "
                "different time bases; name channels of one rate"
            )
        return group_of.pop()
    counts: dict[int, int] = {}
    for k in numeric:
        if _is_vibration_unit(str(sigs[k].unit or "")) or not str(sigs[k].unit or "").strip():
            counts[groups[k]] = counts.get(groups[k], 0) + 1
    if not counts:
        for k in numeric:
            counts[groups[k]] = counts.get(groups[k], 0) + 1
    if not counts:
        raise FileFormatError(f"{p}: no numeric channels in the MDF file; {'; '.join(skipped)}")
    return max(counts, key=lambda g: (counts[g], -g))


def read_mdf(
    path: str | os.PathLike[str],
    quantities: Mapping[str, str] | None = None,
    channels: Sequence[str] | None = None,
    channel_map: ChannelMap | None = None,
) -> TimeData:
    """Read time data from an MDF file (``.mf4``, ``.mdf``).

    Parameters
    ----------
    path : path-like
    quantities : mapping of channel name to quantity, optional
        For channels whose unit is blank (or to override it); older form of
        ``channel_map``.
    channels : sequence of str, optional
        Channel names to read (default: the numeric channels of one time
        base, see the module docstring).
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of channels (:mod:`.channelmap`).

    Raises
    ------
    FileFormatError
        Not an MDF file, no numeric channels, channels named on different
        time bases, uneven sampling, a channel whose quantity cannot be told.
    """
    p = check_input_file(path)
    cmap = ChannelMap.from_quantities(quantities).merged(channel_map)
    mdf = _open(p)
    skipped: list[str] = []
    sigs, groups = [], []
    master_units: dict[int, str] = {}
    with mdf:
        masters = getattr(mdf, "masters_db", {})
        groups_: list[Any] = list(mdf.groups)
        for gi, grp in enumerate(groups_):
            for ci, ch in enumerate(grp.channels):
                if masters.get(gi) == ci:
                    master_units[gi] = str(getattr(ch, "unit", "") or "")
                    continue
                try:  # one channel asammdf cannot read (a bus frame ...) is left out
                    sigs.append(mdf.get(group=gi, index=ci))
                    groups.append(gi)
                except Exception as exc:
                    skipped.append(f"{ch.name} (not readable: {type(exc).__name__})")
    if not sigs:
        raise FileFormatError(f"{p}: no data channels in the MDF file")
    names = [str(s.name) for s in sigs]
    numeric = []
    for k, s in enumerate(sigs):
        a = np.asarray(s.samples)
        if a.dtype.kind not in "iufb" or a.ndim != 1:
            skipped.append(f"{names[k]} (not numeric: text, value table or structure)")
        else:
            numeric.append(k)
    wanted = list(channels) if channels is not None else [s.key for s in cmap.channels]
    if channels is not None:
        missing = [c for c in channels if c not in names]
        if missing:
            raise FileFormatError(
                f"{p}: no channel named {missing[0]!r}; channels: {', '.join(names)}"
            )
    group = _choose_group(p, sigs, names, groups, numeric, wanted, skipped)
    keep = []
    for k in numeric:
        if groups[k] != group:
            skipped.append(f"{names[k]} (another time base)")
        elif channels is not None and names[k] not in channels:
            skipped.append(f"{names[k]} (not among the channels asked for)")
        elif (
            channels is None
            and names[k] not in wanted
            and str(sigs[k].unit or "").strip()
            and not _is_vibration_unit(str(sigs[k].unit))
        ):
            skipped.append(f"{names[k]} (unit {sigs[k].unit!r} is not a vibration quantity)")
        else:
            keep.append(k)
    if not keep:
        raise FileFormatError(f"{p}: no channel to read; {'; '.join(skipped)}")
    t_scale, t_note = axis_scale(
        master_units.get(group), "time", f"{p}: master (time) channel unit"
    )
    t = np.asarray(sigs[keep[0]].timestamps, dtype=float)
    for k in keep:
        ts = np.asarray(sigs[k].timestamps, dtype=float)
        if ts.shape != t.shape or not np.array_equal(ts, t):
            raise FileFormatError(
                f"{p}: channel {names[k]!r} is on another time base than {names[keep[0]]!r}; "
                "name channels of one rate"
            )
    if t.size < 2:
        raise FileFormatError(f"{p}: fewer than 2 samples")
    dt = np.diff(t)
    span = float(t[-1] - t[0])
    if span <= 0 or np.any(dt <= 0) or np.ptp(dt) > 1e-6 * span / (t.size - 1):
        raise FileFormatError(f"{p}: timestamps are not evenly increasing")
    fs = snap_rate((t.size - 1) / (span * t_scale))
    notes = ([f"left out: {'; '.join(skipped)}"] if skipped else []) + ([t_note] if t_note else [])
    meta: dict[str, Any] = {}
    return timedata_from_channels(
        p,
        [names[k] for k in keep],
        [str(sigs[k].unit or "") for k in keep],
        [np.asarray(sigs[k].samples, dtype=float) for k in keep],
        fs,
        None,
        _only(cmap, [names[k] for k in keep], p, names),
        meta=meta,
        notes=notes,
    )


def _open(p: Any) -> Any:
    """The asammdf ``MDF`` object of ``p`` (its loggers quiet: they exist once imported)."""
    try:
        from asammdf import MDF
    except ImportError:  # pragma: no cover - optional dependency
        raise FileFormatError(
            f"{p}: reading MDF needs asammdf (pip install 'tyredamp[mdf]')"
        ) from None
    try:
        with quiet_libraries():
            return MDF(str(p))
    except Exception as exc:  # asammdf raises MdfException, ValueError ... on garbage
        raise FileFormatError(f"{p}: not a readable MDF file ({exc})") from None


def _only(cmap: ChannelMap, kept: list[str], p: Any, all_names: list[str]) -> ChannelMap:
    """The map, checked against every channel of the file (a key for a left-out channel
    is refused by name, one for no channel lists them all)."""
    for s in cmap.channels:
        if s.key in kept or (s.key.isdigit() and 1 <= int(s.key) <= len(kept)):
            continue
        if s.key in all_names:
            raise InputError(
                f"{p}: channel {s.key!r} of the channel map is not read (not numeric, or on "
                f"another time base than {', '.join(kept)})"
            )
    return cmap
