"""LabVIEW Measurement files (``.lvm``) through lvm_read.

An LVM file is text: a file header, then one or more segments, each with
its own header (``Channels``, ``Samples``, ``Y_Unit_Label``, ``X0``,
``Delta_X`` per channel) and a table of samples. The text is decoded here
(UTF-8, else cp1252/Latin-1, named in ``meta["text_encoding"]``) and parsed
by :func:`lvm_read.read_str`, which reads tab or comma separators and the
decimal comma of European LabVIEW installations.

The channels of every segment are read; segments with the same channels and
sample interval are joined, and each segment after the first starts a new
run (``TimeData.acquisition.run_starts``), so no FRF average straddles two
segments. The sample rate is ``1 / Delta_X``. Units come from
``Y_Unit_Label`` (read by :mod:`.units`; ``Newtons``, ``g``, ``m/s^2``,
``V`` ...) or from a channel map (:mod:`.channelmap`), which also names
channels whose label is wrong (a hammer labelled ``g``).
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..exceptions import FileFormatError
from ..timedata import Acquisition, TimeData
from ._channels import snap_rate, timedata_from_channels
from ._common import check_input_file
from ._text import decode_text
from .channelmap import ChannelMap

__all__ = ["read_lvm"]


def read_lvm(path: str | os.PathLike[str], channel_map: ChannelMap | None = None) -> TimeData:
    """Read time data from a LabVIEW Measurement file.

    Parameters
    ----------
    path : path-like
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of channels (:mod:`.channelmap`).

    Raises
    ------
    FileFormatError
        Not an LVM file, no data segment, segments of different channels or
        sample intervals, unequal intervals in a segment, values that are
        not numbers.
    """
    try:
        import lvm_read
    except ImportError:  # pragma: no cover - optional dependency
        raise FileFormatError(
            f"{path}: reading LVM needs lvm_read (pip install 'tyredamp[lvm]')"
        ) from None
    p = check_input_file(path)
    text, encoding = decode_text(p.read_bytes())
    if not text.lstrip().startswith("LabVIEW Measurement"):
        raise FileFormatError(
            f"{p}: not a LabVIEW Measurement file (the first line must be 'LabVIEW Measurement')"
        )
    try:
        lvm = lvm_read.read_str(text)
    except Exception as exc:  # lvm_read raises ValueError, SyntaxError, IndexError ... on garbage
        raise FileFormatError(f"{p}: not a readable LVM file ({exc})") from None
    try:
        n_seg = int(lvm.get("Segments", 0))
    except (TypeError, ValueError):
        raise FileFormatError(f"{p}: the header's segment count is not a number") from None
    names: list[str] = []
    units: list[str] = []
    blocks: list[np.ndarray] = []
    dt = None
    for k in range(n_seg):
        where = f"{p}: segment {k + 1}"
        try:
            seg = lvm[k]
            seg_names, data, steps = _segment(seg, where)
            seg_units = [str(u) for u in seg.get("Y_Unit_Label", [""] * len(seg_names))]
        except (TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
            # lvm_read hands on whatever a damaged header parses to (tuples, lists, text)
            raise FileFormatError(f"{where}: header or data not readable ({exc})") from None
        if k == 0:
            names, dt = seg_names, steps[0]
            units = seg_units[: len(names)]
            units += [""] * (len(names) - len(units))
        elif seg_names != names or abs(steps[0] - float(dt or 0)) > 1e-9 * steps[0]:
            raise FileFormatError(
                f"{where}: channels {seg_names} at Delta_X {steps[0]} differ from segment 1 "
                f"({names} at {dt}); read the segments as separate files"
            )
        if np.isnan(data).any():
            row = int(np.argwhere(np.isnan(data))[0][0])
            raise FileFormatError(f"{where}: row {row + 1} holds a value that is not a number")
        blocks.append(data)
    if not blocks or dt is None:
        raise FileFormatError(f"{p}: no data segment")
    table = np.vstack(blocks)
    starts = tuple(int(s) for s in np.cumsum([0] + [b.shape[0] for b in blocks[:-1]]))
    meta: dict[str, Any] = {}
    if encoding != "utf-8":
        meta["text_encoding"] = encoding
    for key in ("Operator", "Date", "Time", "Description", "Project"):
        if str(lvm.get(key, "")).strip():
            meta[key.lower()] = str(lvm[key]).strip()
    return timedata_from_channels(
        p,
        names,
        units,
        list(table.T),
        snap_rate(1.0 / dt),
        None,
        channel_map,
        meta=meta,
        acquisition=Acquisition(run_starts=starts) if len(starts) > 1 else None,
    )


def _segment(seg: Any, where: str) -> tuple[list[str], np.ndarray, list[float]]:
    """Channel names, data (n_samples, n_channels) and sample intervals of one segment."""
    data = np.asarray(seg.get("data", []), dtype=float)
    if data.ndim != 2 or data.shape[0] == 0:
        raise FileFormatError(f"{where}: no samples")
    seg_names = [str(c) for c in seg.get("Channel names", [])]
    if seg_names[-1:] == ["Comment"]:
        seg_names = seg_names[:-1]
    if seg_names[:1] == ["X_Value"] and len(seg_names) == data.shape[1]:
        seg_names, data = seg_names[1:], data[:, 1:]
    if len(seg_names) != data.shape[1]:
        raise FileFormatError(
            f"{where}: {len(seg_names)} channel names but {data.shape[1]} columns of data"
        )
    steps = [float(d) for d in seg.get("Delta_X", []) if d == d][: len(seg_names)]
    if not steps or any(abs(s - steps[0]) > 1e-9 * abs(steps[0]) for s in steps):
        raise FileFormatError(f"{where}: channels have different or no Delta_X {steps}")
    if not steps[0] > 0:
        raise FileFormatError(f"{where}: Delta_X {steps[0]} is not a positive interval")
    return seg_names, data, steps
