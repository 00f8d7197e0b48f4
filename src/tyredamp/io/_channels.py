"""Named channels with units labels to a :class:`TimeData`, through a channel map.

Shared by every reader of time data from acquisition formats (TDMS, MDF4,
plain CSV, LVM, MATLAB, WAV, UFF 58 type 1). What a channel measures comes
from, in order: the user's :class:`~tyredamp.io.channelmap.ChannelMap`
(role, unit, sensitivity), the file's units label (read by :mod:`.units`:
``N``, ``g``, ``m/s²``, ``Pa``, ``V`` ...), a hint of the format (a UFF data
type). Values are converted to SI; a channel in volts stays a voltage until a
sensitivity makes it a physical quantity. A recording without a force channel
reads (output-only data); the steps that need a force say so.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import FileFormatError, InputError
from ..frf import Channel
from ..timedata import QUANTITY_UNITS, Acquisition, TimeData
from .channelmap import ChannelMap, ChannelSpec
from .units import quantity_units

__all__ = ["channel_values", "snap_rate", "timedata_from_channels"]

_EXAMPLE_UNIT = {
    "force": "N",
    "acceleration": "m/s^2",
    "velocity": "m/s",
    "displacement": "m",
    "pressure": "Pa",
    "voltage": "V",
}
_EXAMPLE_SENS = {
    "force": "2.25 mV/N",
    "acceleration": "100 mV/g",
    "velocity": "100 mV/(m/s)",
    "displacement": "8 mV/um",
    "pressure": "50 mV/Pa",
}


class _Unnamed(FileFormatError):
    """A channel without a unit that the channel map does not name."""


def snap_rate(fs: float) -> float:
    """A sample rate from a stored interval, snapped to the integer it stands for (1e-9)."""
    r = round(fs)
    return float(r) if r > 0 and abs(fs - r) <= 1e-9 * fs else float(fs)


def _opt(name: str, value: str) -> str:
    return f"--channel '{name}={value}'"


def channel_values(
    where: str,
    name: str,
    file_label: str,
    values: NDArray[np.float64],
    spec: ChannelSpec | None,
    hint: str | None = None,
    notes: list[str] | None = None,
) -> tuple[str, NDArray[np.float64]]:
    """``(quantity, values in SI)`` of one channel.

    Parameters
    ----------
    where : str
        ``"<file>: channel 'name'"`` for messages.
    name : str
        The channel's name (for the options suggested in messages).
    file_label : str
        The units label the file gives ("" when none).
    values : ndarray
        Stored values.
    spec : ChannelSpec or None
        What the channel map says about it.
    hint : str, optional
        The quantity a format states besides the label (a UFF data type).
    notes : list of str, optional
        Assumptions made are appended here.

    Raises
    ------
    InputError
        The map and the file disagree, or a voltage channel lacks its sensitivity.
    FileFormatError
        The file's label cannot be read and the map does not say.
    """
    notes = notes if notes is not None else []
    role = spec.role if spec else None
    label = spec.unit if spec and spec.unit else file_label
    try:
        qu = quantity_units(label)
    except InputError as exc:
        if spec and spec.unit:
            raise InputError(f"{where}: {exc}") from None
        if role is None and not (spec and spec.sensitivity):
            raise FileFormatError(
                f"{where}: {exc}; give what it measures, for example "
                f"{_opt(name, 'acceleration:m/s^2')}"
            ) from None
        if role is not None and spec and spec.sensitivity is None:
            raise InputError(
                f"{where}: the file's units label {label!r} cannot be read; give the unit with "
                f"the role: {_opt(name, role + ':' + _EXAMPLE_UNIT.get(role, 'N'))}"
            ) from None
        qu = None
    q_file, factor = (None, 1.0) if qu is None else qu
    if q_file is None and hint is not None and not (spec and spec.unit):
        q_file = hint
    v = np.asarray(values, dtype=float)
    if spec is not None and spec.sensitivity is not None:
        sens = spec.sensitivity
        if q_file not in (None, "voltage"):
            raise InputError(
                f"{where}: stored in {label!r} ({q_file}), not volts; a sensitivity applies to "
                "a channel in V or mV (remove --sensitivity, or give its unit as V)"
            )
        if role not in (None, sens.quantity):
            raise InputError(
                f"{where}: sensitivity {sens.text!r} is for a {sens.quantity} sensor, but the "
                f"channel map names it {role}"
            )
        if q_file is None:
            notes.append(f"channel {name!r}: no unit in the file, taken as volts")
        return sens.quantity, v * factor / sens.volts_per_si
    if role is None:
        if q_file is None:
            raise _Unnamed(
                f"{where}: no units label tells what it measures; name it, for example "
                f"{_opt(name, 'force:N')} or {_opt(name, 'acceleration:m/s^2')}"
            )
        if q_file == "voltage":
            notes.append(f"channel {name!r} is in volts (no sensitivity given): kept as a voltage")
        return q_file, v * factor
    if role == "voltage" or q_file is None or q_file == role:
        if q_file is None:
            notes.append(
                f"channel {name!r}: no unit in the file, taken as {QUANTITY_UNITS[role]} ({role})"
            )
        elif role == "voltage" and q_file != "voltage":
            raise InputError(
                f"{where}: stored in {label!r} ({q_file}), not volts; the channel map names it "
                "voltage"
            )
        return role, v * factor
    if q_file == "voltage":
        raise InputError(
            f"{where}: stored in volts ({label!r}); give its sensitivity to make it a {role}, "
            f"for example --sensitivity '{name}={_EXAMPLE_SENS.get(role, '1 V/N')}'"
        )
    raise InputError(
        f"{where}: units label {label!r} means {q_file}, but the channel map names it "
        f"{role}; give the unit with the role: "
        f"{_opt(name, role + ':' + _EXAMPLE_UNIT.get(role, 'N'))}"
    )


def _refuse_unnamed(path: Any, unnamed: Sequence[tuple[str, Exception]], has_force: bool) -> None:
    """One error for the channels no units label names, with an example channel map."""
    if len(unnamed) == 1:
        raise unnamed[0][1]
    if unnamed:
        listed = ", ".join(repr(n) for n, _ in unnamed)
        # the example names a force only when no channel read so far is one
        role = "acceleration:m/s^2" if has_force else "force:N"
        raise FileFormatError(
            f"{path}: no units label tells what channels {listed} measure; name them, for "
            f"example {_opt(unnamed[0][0], role)} {_opt(unnamed[1][0], 'acceleration:m/s^2')} "
            "(or a --channel-map file)"
        )


def timedata_from_channels(
    path: Path,
    names: Sequence[str],
    units: Sequence[str],
    arrays: Sequence[NDArray[Any]],
    sample_rate: float,
    quantities: Mapping[str, str] | None = None,
    channel_map: ChannelMap | None = None,
    *,
    aliases: Sequence[Sequence[str]] | None = None,
    hints: Sequence[str | None] | None = None,
    points: Sequence[tuple[int, int]] | None = None,
    meta: Mapping[str, Any] | None = None,
    notes: Sequence[str] = (),
    acquisition: Acquisition | None = None,
) -> TimeData:
    """Build time data from named channels; units converted to SI.

    Parameters
    ----------
    path : Path
        The file (for messages).
    names, units : sequence of str
        Channel names and units labels as the file gives them.
    arrays : sequence of ndarray
        Samples of each channel (equal lengths).
    sample_rate : float
        Hz.
    quantities : mapping, optional
        Channel name -> role (older form of ``channel_map``).
    channel_map : ChannelMap, optional
        Roles, units, sensitivities and points given by the user.
    aliases : sequence of sequence of str, optional
        Further names each channel answers to in the map.
    hints : sequence of str or None, optional
        Quantity a format states besides the label.
    points : sequence of (node, direction), optional
        Default point of each channel (else node = position, +Z).
    meta, notes, acquisition
        Stored in the result; ``notes`` and the assumptions made here go to
        ``meta["read_notes"]``.

    Raises
    ------
    FileFormatError
        No channels, channels of unequal length, a channel whose quantity
        cannot be told (blank unit and not in the map), an unreadable label.
    InputError
        The channel map names a channel the file does not have, or disagrees
        with the file.
    """
    if not names:
        raise FileFormatError(f"{path}: no data channels")
    cmap = ChannelMap.from_quantities(quantities).merged(channel_map)
    alias = [[str(n), *(aliases[i] if aliases else ())] for i, n in enumerate(names)]
    specs = cmap.resolve(alias, path)
    n = len(arrays[0])
    rows, quants, chans = [], [], []
    read_notes = list(notes)
    skipped = []
    unnamed: list[tuple[str, FileFormatError]] = []
    for i, (name, unit, a) in enumerate(zip(names, units, arrays, strict=True)):
        where = f"{path}: channel {name!r}"
        spec = specs.get(i)
        if spec is not None and spec.role == "ignore":
            skipped.append(str(name))
            continue
        if len(a) != n:
            raise FileFormatError(
                f"{where}: {len(a)} samples, but channel {names[0]!r} has {n}; channels must "
                "have equal length"
            )
        try:
            values = np.asarray(a, dtype=float)
        except (TypeError, ValueError):
            raise FileFormatError(f"{where}: values are not numbers") from None
        try:
            q, si = channel_values(
                where,
                str(name),
                str(unit or ""),
                values,
                spec,
                hints[i] if hints else None,
                read_notes,
            )
        except _Unnamed as exc:
            unnamed.append((str(name), exc))
            continue
        rows.append(si)
        quants.append(q)
        node, direction = points[i] if points else (i + 1, 3)
        if spec is not None and spec.node is not None:
            node = spec.node
        if spec is not None and spec.direction is not None:
            direction = spec.direction
        chans.append(Channel(node=node, direction=direction, name=str(name)))
    _refuse_unnamed(path, unnamed, "force" in quants)
    if skipped:
        read_notes.append(f"left out as the channel map asks: {', '.join(skipped)}")
    if not rows:
        raise InputError(f"{path}: the channel map leaves no channel to read")
    out_meta = dict(meta or {})
    if cmap:
        out_meta["channel_map"] = cmap.source or "given"
    if read_notes:
        out_meta["read_notes"] = read_notes
    try:
        return TimeData(np.array(rows), sample_rate, chans, quants, out_meta, acquisition)
    except InputError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
