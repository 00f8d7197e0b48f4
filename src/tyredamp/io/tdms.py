"""NI TDMS time data (LabVIEW) through npTDMS.

All channels of one group (the first group holding data, the group of the
channels a channel map names, or ``group``) are read. The sample rate comes
from the channels' ``wf_increment`` property (seconds per sample, the
LabVIEW waveform attribute; all equal), the units
from ``unit_string`` (read by :mod:`.units` and converted to SI), the channel
names from the TDMS channel names. Channels without a ``unit_string`` (or
with one that is wrong) are named with a channel map; see :mod:`._channels`.
Channels are numbered as nodes 1..n in file order (direction +Z), named as
in the file.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..exceptions import FileFormatError
from ..timedata import TimeData
from ._channels import snap_rate, timedata_from_channels
from ._common import check_input_file
from ._guard import axis_scale, library_messages, quiet_libraries
from .channelmap import ChannelMap

__all__ = ["read_tdms"]


def read_tdms(
    path: str | os.PathLike[str],
    quantities: Mapping[str, str] | None = None,
    group: str | None = None,
    channel_map: ChannelMap | None = None,
) -> TimeData:
    """Read time data from a TDMS file.

    Parameters
    ----------
    path : path-like
    quantities : mapping of channel name to quantity, optional
        ``"force"``, ``"displacement"``, ``"velocity"`` or ``"acceleration"``
        for channels whose ``unit_string`` is blank (or to override it).
    group : str, optional
        Group to read; default the group of the channels the channel map
        names, else the first group with channels.
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of channels (:mod:`.channelmap`);
        channels answer to their name and to ``group/name``.

    Channels without ``wf_increment`` (files written by scripts) take the
    interval of an evenly spaced time channel of the group (``Time``, ``t``
    ...), which is then not read as data.

    Raises
    ------
    FileFormatError
        Not a TDMS file, no channels, no or unequal ``wf_increment``,
        unequal lengths, unknown quantities, no force channel.
    """
    try:
        from nptdms import TdmsFile
    except ImportError:  # pragma: no cover - optional dependency
        raise FileFormatError(
            f"{path}: reading TDMS needs npTDMS (pip install 'tyredamp[tdms]')"
        ) from None
    p = check_input_file(path)
    try:
        with quiet_libraries():  # again: npTDMS's loggers exist once it is imported
            f = TdmsFile.read(str(p))
            groups = [g for g in f.groups() if g.channels()]
            said = library_messages()
        if any("less data than expected" in m for m in said):
            raise FileFormatError(
                f"{p}: truncated TDMS file: its last segment holds less data than its header "
                "declares"
            )
    except FileFormatError:
        raise
    except Exception as exc:  # npTDMS raises ValueError, KeyError, struct.error ... on garbage
        raise FileFormatError(f"{p}: not a readable TDMS file ({exc})") from None
    if group is not None:
        groups = [g for g in groups if g.name == group]
        if not groups:
            raise FileFormatError(f"{p}: no group {group!r} with channels")
    if not groups:
        raise FileFormatError(f"{p}: no channels in the TDMS file")
    if group is None and channel_map:
        keys = set(channel_map.keys)
        named = [
            g
            for g in groups
            if any(c.name in keys or f"{g.name}/{c.name}" in keys for c in g.channels())
        ]
        if named:
            groups = named
    chans = list(groups[0].channels())
    time_dt, time_name = _time_channel(p, chans)
    notes = []
    if time_name is not None:
        notes.append(f"sample interval from the time channel {time_name!r}")
        chans = [c for c in chans if c.name != time_name]
    names, units, arrays, steps = [], [], [], []
    for c in chans:
        props = c.properties
        if "wf_increment" not in props and time_dt is None:
            raise FileFormatError(
                f"{p}: channel {c.name!r} has no wf_increment (sample interval) property and "
                "the group has no evenly spaced time channel (Time, t, ...)"
            )
        try:
            raw = np.asarray(c[:])
            if raw.dtype.kind == "c":
                raise FileFormatError(
                    f"{p}: channel {c.name!r} holds complex values; time data are real "
                    "(a spectrum or FRF stored in TDMS is not read as time data)"
                )
            scale, note = (1.0, None)
            if "wf_increment" in props:  # in the waveform's x unit (s by default)
                scale, note = axis_scale(
                    props.get("wf_xunit_string"), "time", f"{p}: channel {c.name!r} wf_xunit_string"
                )
            if note and note not in notes:
                notes.append(note)
            steps.append(float(props.get("wf_increment", time_dt)) * scale)
            arrays.append(np.asarray(raw, dtype=float))
        except (TypeError, ValueError) as exc:
            if isinstance(exc, FileFormatError):
                raise
            raise FileFormatError(f"{p}: channel {c.name!r}: {exc}") from None
        names.append(str(c.name))
        units.append(str(props.get("unit_string", "") or ""))
    if not names:
        raise FileFormatError(f"{p}: no data channels besides the time channel")
    dt = steps[0]
    if not np.isfinite(dt) or dt <= 0 or any(abs(s - dt) > 1e-12 * dt for s in steps):
        raise FileFormatError(f"{p}: channels have different or invalid sample intervals {steps}")
    gname = str(groups[0].name)
    return timedata_from_channels(
        p,
        names,
        units,
        arrays,
        snap_rate(1.0 / dt),
        quantities,
        channel_map,
        aliases=[[f"{gname}/{n}"] for n in names],
        notes=notes,
    )


_TIME_NAMES = {"time", "t", "zeit", "time_s", "timestamp", "x_value", "relative time"}


def _time_channel(p: Any, chans: list[Any]) -> tuple[float | None, str | None]:
    """``(interval in s, name)`` of an evenly spaced time channel when a channel lacks
    ``wf_increment`` (files written by scripts rather than LabVIEW waveforms)."""
    if all("wf_increment" in c.properties for c in chans):
        return None, None
    for c in chans:
        if str(c.name).strip().lower() not in _TIME_NAMES:
            continue
        try:
            t = np.asarray(c[:], dtype=float)
        except (TypeError, ValueError):
            continue
        if t.size < 2:
            continue
        scale, _ = axis_scale(
            c.properties.get("unit_string"), "time", f"{p}: time channel {c.name!r} unit"
        )
        dt = float(t[-1] - t[0]) / (t.size - 1) * scale
        if dt > 0 and np.max(np.abs(np.diff(t) * scale - dt)) <= 1e-6 * dt:
            return dt, str(c.name)
    return None, None
