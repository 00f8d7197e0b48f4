"""Loading UFF data sets 58 through pyuff, as other programs write them.

The checks that come before any interpretation: delimiters counted (a
truncated file), headers that declare more values than the file stores,
header text in cp1252/Latin-1 (pyuff decodes it as UTF-8 with replacement
characters: the original bytes are decoded again here), and one line saying
what a file holds when it holds no time data or FRF (geometry, mode shapes,
a PSD ...). Also the coherence and variance data sets that accompany FRFs.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pyuff

from ..exceptions import FileFormatError
from ._guard import axis_scale
from ._text import decode_text
from ._uff_meta import read_meta_record

#: ID line 1 of the extra data sets (function type 0) holding FRF.variance.
VARIANCE_ID = "tyredamp FRF variance"
#: ID line 1 of tyredamp's extra type-0 data sets that hold FRF.input_noise (one per input)
INPUT_NOISE_ID = "tyredamp FRF input noise"


def _markers(raw: bytes) -> int:
    """Count data-set delimiters as pyuff does (``    -1`` ending a record)."""
    count, i, n = 0, -1, len(raw)
    while True:
        i = raw.find(b"    -1", i + 1)
        if i == -1:
            return count
        if (
            i + 6 == n
            or (i + 6 < n and raw[i + 6] in (10, 13))
            or (i + 80 < n and raw[i + 6 : i + 80] == b" " * 74)
        ):
            count += 1


def check_delimiters(p: Path, raw: bytes) -> None:
    """Refuse a UFF file without data sets or whose last data set is cut off.

    Every UFF data set (58, 55, 15, 2411, ...) opens and closes with a ``    -1``
    line; an odd count means the file ends inside a data set (a truncated copy).
    """
    n_marks = _markers(raw)
    if n_marks == 0:
        raise FileFormatError(f"{p}: no UFF data set found (no '    -1' delimiters)")
    if n_marks % 2:
        raise FileFormatError(
            f"{p}: truncated UFF file: the last data set has no closing '    -1' delimiter"
        )


def load_sets(p: Path) -> list[dict[str, Any]]:
    raw = p.read_bytes()
    check_delimiters(p, raw)
    try:
        uff = pyuff.UFF(str(p))
        types = list(uff.get_set_types())
        idx = [k for k, t in enumerate(types) if t == 58]
        if not idx:
            raise FileFormatError(f"{p}: {_what_instead(types)}")
        sets = uff.read_sets(idx)
        record = read_meta_record(p, uff, types)
    except FileFormatError:
        raise
    except Exception as exc:  # pyuff raises bare Exception, and others on garbage
        raise FileFormatError(f"{p}: corrupt UFF data set 58 ({exc})") from None
    if isinstance(sets, dict):
        sets = [sets]
    for k, s in zip(idx, sets, strict=True):
        data = s.get("data")
        if data is None or "num_pts" not in s or len(data) != int(s["num_pts"]):
            got = "no" if data is None else len(data)
            declared = s.get("num_pts")
            if isinstance(got, int) and isinstance(declared, int) and 0 < got < declared:
                raise FileFormatError(
                    f"{p}: data set #{k + 1} is corrupt or truncated: its header declares "
                    f"{declared} values, the file stores {got} (a cut-off excerpt of a longer "
                    "recording, not a complete measurement)"
                )
            raise FileFormatError(
                f"{p}: data set #{k + 1} is corrupt or truncated: header says "
                f"{declared} values, found {got}"
            )
        s["_index"] = k + 1
    _redecode_strings(raw, sets)
    notes = _abscissa_units(p, sets)
    if record is not None or notes:
        extra = {"read_notes": [*(record or {}).get("read_notes", []), *notes]} if notes else {}
        for s in sets:
            s["_meta"] = {**(record or {}), **extra}
    return sets


def _abscissa_units(p: Path, sets: list[dict[str, Any]]) -> list[str]:
    """Convert each data set's abscissa to Hz or s from its units label (record 8).

    A frequency axis (abscissa data type 18, or a non-time function) may be in
    Hz, kHz, rad/s, cpm or rpm, a time axis (type 17, or function type 1) in
    s, ms, us or min; the values are converted and a note says so. Any other
    label is refused (:func:`._guard.axis_scale`).
    """
    notes: list[str] = []
    for s in sets:
        sdt = int(s.get("abscissa_spec_data_type", 0) or 0)
        timelike = sdt == 17 or (sdt not in (17, 18) and int(s.get("func_type", 0) or 0) == 1)
        factor, note = axis_scale(
            s.get("abscissa_axis_units_lab"),
            "time" if timelike else "frequency",
            f"{p}: data set #{s['_index']} abscissa units",
        )
        if note is None:
            continue
        if note not in notes:
            notes.append(note)
        s["x"] = np.asarray(s["x"], dtype=float) * factor
        for key in ("abscissa_inc", "abscissa_min"):
            if key in s:
                s[key] = float(s[key]) * factor
    return notes


#: UFF data-set types that hold geometry (nodes, coordinate systems, lines, elements, units).
_GEOMETRY_SETS = {15, 18, 82, 164, 2411, 2412, 2420, 151}
#: Function types of data set 58 (record 6), by the UFF specification.
_FUNCTION_TYPES = {
    0: "a general function",
    1: "a time response",
    2: "an auto spectrum",
    3: "a cross spectrum",
    4: "an FRF",
    5: "a transmissibility",
    6: "a coherence",
    7: "an auto-correlation",
    8: "a cross-correlation",
    9: "a PSD",
    10: "an ESD",
    11: "a probability density",
    12: "a spectrum",
    13: "a cumulative frequency distribution",
    18: "a mode indicator function",
    24: "a shock response spectrum",
    26: "a multiple coherence",
    27: "an order function",
}


def _what_instead(types: list[int]) -> str:
    """One line saying what a UFF file without data sets 58 holds instead."""
    found = sorted({int(t) for t in types})
    listed = ", ".join(str(t) for t in found)
    if found and set(found) <= _GEOMETRY_SETS:
        return (
            f"holds geometry only (data sets {listed}: nodes, coordinate systems, lines, "
            "elements), not time data or an FRF; use it as a geometry file (tyredamp modal "
            "--geometry)"
        )
    if 55 in found:
        return (
            f"holds mode shapes (data sets {listed}), not time data or an FRF; use it where "
            "modes are read (tyredamp damping, tyredamp tyre-model)"
        )
    return f"no data set 58 (time data or FRF); found data sets {listed}"


def _function_name(t: int) -> str:
    return _FUNCTION_TYPES.get(int(t), "an unknown function")


def not_frf_or_time(p: Path, types: set[int]) -> FileFormatError:
    kinds = ", ".join(f"{_function_name(t)} (function type {t})" for t in sorted(types))
    return FileFormatError(
        f"{p}: holds {kinds}, not time data or an FRF; export the time data it was computed "
        "from (function type 1), or FRFs (function type 4)"
    )


def _redecode_strings(raw: bytes, sets: list[dict[str, Any]]) -> None:
    """Header strings pyuff decoded with replacement characters, read again as cp1252.

    pyuff decodes header lines as UTF-8 with ``errors="replace"``; a label
    such as ``g²/Hz`` written by Windows software as cp1252/Latin-1 (``²`` =
    byte 0xB2) comes back as ``g\ufffd/Hz``. The original bytes are found in
    the file around the intact parts and decoded as cp1252 (Latin-1 for the
    bytes cp1252 leaves undefined); the set's ``_encoding`` records it.
    """
    cache: dict[str, tuple[str, str] | None] = {}
    for s in sets:
        for key, value in list(s.items()):
            if not isinstance(value, str) or "\ufffd" not in value:
                continue
            if value not in cache:
                if len(value.replace("\ufffd", "")) < 2:  # too little to find it by
                    cache[value] = None
                    continue
                parts = [re.escape(x.encode("utf-8")) for x in value.split("\ufffd")]
                m = re.search(b"(?:.{1,3}?)".join(parts), raw, flags=re.DOTALL)
                found = None if m is None else decode_text(m.group(0))
                cache[value] = None if found is None or "\ufffd" in found[0] else found
            hit = cache[value]
            if hit is not None:
                s[key], s["_encoding"] = hit


def read_coherence(
    sets: list[dict[str, Any]], outs: list[tuple[int, int]], ins: list[tuple[int, int]], n: int
) -> np.ndarray | None:
    want = ins[0] if len(ins) == 1 else (0, 0)
    found: dict[tuple[int, int], np.ndarray] = {}
    for s in sets:
        if int(s["func_type"]) not in (6, 26) or len(s["data"]) != n:
            continue
        if (int(s["ref_node"]), int(s["ref_dir"])) != want:
            continue
        found[(int(s["rsp_node"]), int(s["rsp_dir"]))] = np.real(np.asarray(s["data"]))
    if not all(o in found for o in outs):
        return None
    return np.array([found[o] for o in outs])


def read_variance(
    sets: list[dict[str, Any]],
    outs: list[tuple[int, int]],
    ins: list[tuple[int, int]],
    n: int,
    shape: tuple[int, ...],
) -> np.ndarray | None:
    """FRF.variance from tyredamp's extra type-0 data sets, when every pair has one."""
    found: dict[tuple[tuple[int, int], tuple[int, int]], np.ndarray] = {}
    for s in sets:
        if int(s["func_type"]) != 0 or str(s.get("id1", "")).strip() != VARIANCE_ID:
            continue
        if len(s["data"]) != n:
            continue
        ko = (int(s["rsp_node"]), int(s["rsp_dir"]))
        ki = (int(s["ref_node"]), int(s["ref_dir"]))
        found[(ko, ki)] = np.real(np.asarray(s["data"], dtype=float))
    if not all((o, i) in found for o in outs for i in ins):
        return None
    return np.array([[found[(o, i)] for i in ins] for o in outs]).reshape(shape)


def read_input_noise(
    sets: list[dict[str, Any]], ins: list[tuple[int, int]], n: int
) -> np.ndarray | None:
    """FRF.input_noise from tyredamp's extra type-0 data sets, when every input has one."""
    found: dict[tuple[int, int], np.ndarray] = {}
    for s in sets:
        if int(s["func_type"]) != 0 or str(s.get("id1", "")).strip() != INPUT_NOISE_ID:
            continue
        if len(s["data"]) != n:
            continue
        found[(int(s["ref_node"]), int(s["ref_dir"]))] = np.real(np.asarray(s["data"], dtype=float))
    if not all(i in found for i in ins):
        return None
    return np.array([found[i] for i in ins])
