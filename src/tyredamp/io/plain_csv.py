"""Plain CSV exports: a header row of column names, a time column, one column per channel.

What DAQ software, spreadsheets and scripts write::

    time_s,F,acc1_m/s2,acc2 [g]
    0.000000,0.05253,0.234571,0.0244

    Zeit (s);Kraft (N);Beschleunigung (m/s²)
    0,000000;0,05253;0,234571

Read rules (detected from the file itself):

* text encoding: UTF-8, else cp1252/Latin-1 (then named in
  ``meta["text_encoding"]``);
* delimiter: comma, semicolon, tab or blanks (an aligned text table),
  whichever splits the rows into equal numbers of numbers; a decimal comma
  is read with the other delimiters than the comma;
* lines before the header row (comments, a title, ``key: value`` lines) are
  kept in ``meta["preamble"]``; lines starting with ``#`` are comments;
* the header row is the last line before the first row of numbers (or the
  two last lines: a row of names and a row of units such as ``s,N,g``); each
  column name may carry its unit as ``name [unit]``, ``name (unit)``,
  ``name / unit`` or ``name_unit`` (``acc1_m/s2``, ``time_s``), read by
  :mod:`.units`;
* the time column is the first column named ``time``, ``t``, ``zeit``,
  ``x_value`` ... or with a time unit (``s``, ``ms``); the sample rate comes
  from its spacing, which must be even (within 1 % of a step and the printed
  resolution);
* a frequency column (named ``freq...`` or in ``Hz``) with complex columns
  (``H.re``/``H.im``, ``Re(H)``/``Im(H)``, ``mag``/``phase``) is an FRF;
  its kind comes from the units (``g/N``, ``m/s^2/N``) or the channel map.

Channels without a unit, or in volts, are named with a channel map
(:mod:`.channelmap`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, Channel
from ..timedata import TimeData
from ._channels import snap_rate, timedata_from_channels
from ._guard import FREQUENCY_UNITS, TIME_UNITS, axis_scale
from .channelmap import ChannelMap
from .units import frf_units, parse_unit

__all__ = ["read_plain_csv", "split_column_name"]

_TIME_NAMES = {"time", "t", "zeit", "temps", "tiempo", "x_value", "sec", "seconds", "timestamp"}
_ANGLE = {"deg", "°", "degree", "degrees", "rad", "radian", "radians"}
_NUM = re.compile(r"^[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?$")


_COMPLEX = re.compile(
    r"^\(?\s*[-+]?[0-9.]+(e[-+]?[0-9]+)?\s*[-+]\s*[0-9.]+(e[-+]?[0-9]+)?j\s*\)?$", re.I
)


def _refuse_complex_column(p: Path, lines: list[str]) -> None:
    """Refuse lines of complex numbers (``(1.2+3.4j)``, one per line): no frequency axis."""
    rows = [ln.strip() for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    if len(rows) >= 3 and all(_COMPLEX.match(r) for r in rows[:50]):
        raise FileFormatError(
            f"{p}: holds complex numbers, one per line, without a frequency column: an FRF "
            "needs its frequency axis; write the file with a header row and a frequency "
            "column, for example 'freq_Hz,H.re [m/s^2/N],H.im [m/s^2/N]'"
        )


def _axis_unit(text: str, table: dict[str, float]) -> bool:
    """Whether ``text`` is one of the axis units of ``table`` (spaces and case ignored)."""
    return "".join(text.split()).lower().strip("[]()") in table


def _is_unit(text: str) -> bool:
    """Whether ``text`` reads as a units label with a dimension (not a bare number)."""
    t = text.strip()
    if not t or _NUM.match(t):
        return False
    if t.lower() in TIME_UNITS or _axis_unit(t, FREQUENCY_UNITS):
        return True
    try:
        u = parse_unit(t)
    except InputError:
        return False
    return u.dimensions != (0, 0, 0) or u.voltage != 0


def split_column_name(text: str) -> tuple[str, str]:
    """``(name, unit)`` of a column name such as ``acc1 [m/s^2]``, ``F (N)``,
    ``Kraft / N``, ``acc1_m/s2`` or ``time_s``; ``unit`` is "" when none."""
    t = text.strip().strip('"').strip()
    for open_, close in (("[", "]"), ("(", ")"), ("{", "}")):
        if t.endswith(close) and open_ in t:
            k = t.rfind(open_)
            name, unit = t[:k].strip(), t[k + 1 : -1].strip()
            # text in [] or {} is a unit as written; in () only when it reads as one
            # ("Excitation (Trigger)" is a name)
            if name and (open_ != "(" or _is_unit(unit) or unit.lower() in _ANGLE or not unit):
                return name, unit
    if " / " in t:
        name, unit = t.rsplit(" / ", 1)
        if _is_unit(unit):
            return name.strip(), unit.strip()
    for k, ch in enumerate(t):
        if ch == "_" and k > 0 and _is_unit(t[k + 1 :]):
            return t[:k], t[k + 1 :]
    return t, ""


def _delimiter(lines: Sequence[str]) -> tuple[str, bool]:
    """``(delimiter, decimal_comma)`` that splits the last lines into equal numeric rows."""
    rows = [ln for ln in lines if ln.strip()]
    sample = rows[-21:-1] if len(rows) > 3 else rows  # the last row may be cut short
    for delim in ("\t", ";", ",", " "):
        for dec_comma in (False, True) if delim != "," else (False,):
            widths = set()
            ok = True
            for ln in sample:
                cells = _cells(ln, delim)
                if len(cells) < 2 or not all(
                    _NUM.match(c) and ("," not in c or dec_comma) for c in cells
                ):
                    ok = False
                    break
                widths.add(len(cells))
            if ok and len(widths) == 1:
                return delim, dec_comma
    raise FileFormatError(
        "no delimiter (comma, semicolon, tab or spaces) splits the rows into numbers"
    )


def _header_cells(line: str, delim: str, n: int) -> list[str]:
    """Column names of a header line; in an aligned table (blanks) names may hold single
    blanks (``F [N]``): columns are then split at runs of two or more blanks."""
    if delim == " ":
        wide = [c for c in re.split(r"\s{2,}|\t", line.strip()) if c]
        if len(wide) == n:
            return wide
    return _cells(line, delim)


def _cells(line: str, delim: str) -> list[str]:
    """The cells of a row (``delim`` ``" "``: runs of blanks, as in aligned text tables)."""
    if delim == " ":
        return line.split()
    cells = [c.strip() for c in line.split(delim)]
    while cells and cells[-1] == "":
        cells.pop()
    return cells


def read_plain_csv(
    p: Path,
    text: str,
    encoding: str,
    what: str | None = None,
    channel_map: ChannelMap | None = None,
) -> FRF | TimeData:
    """Read a plain CSV export (module docstring) from its decoded ``text``.

    Raises
    ------
    FileFormatError
        No header row, no numeric rows, rows of unequal length, no time or
        frequency column, uneven time steps, a channel whose quantity cannot
        be told (name it with a channel map).
    """
    lines = text.splitlines()
    body_start = None
    numeric = 0
    for k, ln in enumerate(lines):
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        cells = [c for c in re.split(r"[,;\t]", ln) if c.strip()]
        if not all(_NUM.match(c.strip()) for c in cells):
            cells = ln.split()  # an aligned table: columns separated by blanks
        if cells and all(_NUM.match(c.strip()) for c in cells):
            body_start = k if body_start is None else body_start
            numeric += 1
            if numeric >= 3:
                break
        else:
            body_start, numeric = None, 0
    if body_start is None:
        _refuse_complex_column(p, lines)
        raise FileFormatError(f"{p}: no rows of numbers found (not a CSV export of data?)")
    head = [ln for ln in lines[:body_start] if ln.strip() and not ln.lstrip().startswith("#")]
    if not head:
        raise FileFormatError(
            f"{p}: no header row of column names above the numbers (expected for example "
            "'time_s,F,acc1_m/s2')"
        )
    body = [ln for ln in lines[body_start:] if ln.strip() and not ln.lstrip().startswith("#")]
    try:
        delim, dec_comma = _delimiter(body)
    except FileFormatError as exc:
        raise FileFormatError(f"{p}: {exc}") from None
    cols = _header_cells(head[-1], delim, len(_cells(body[0], delim)))
    unit_row: list[str] | None = None
    if len(head) > 1:
        above = _header_cells(head[-2], delim, len(cols))
        if len(above) == len(cols) and all(
            not c or _is_unit(c.strip("[]() ")) or c.strip("[]() ").lower() in _ANGLE for c in cols
        ):  # a row of names, then a row of units (as many DAQ programs export)
            unit_row = [c.strip("[]() ") for c in cols]
            cols = above
            head = head[:-1]
    rows = []
    for k, ln in enumerate(body):
        cells = _cells(ln, delim)
        if len(cells) != len(cols):
            if k == len(body) - 1 and len(cells) < len(cols):
                break  # a last row cut short (the export was interrupted): left out
            raise FileFormatError(
                f"{p}: data row {k + 1} has {len(cells)} values, the header row has "
                f"{len(cols)} columns"
            )
        try:
            rows.append([float(c.replace(",", ".") if dec_comma else c) for c in cells])
        except ValueError:
            raise FileFormatError(
                f"{p}: data row {k + 1} holds a value that is not a number"
            ) from None
    table = np.array(rows, dtype=float)
    if table.shape[0] < 2:
        raise FileFormatError(f"{p}: fewer than 2 data rows")
    split = [split_column_name(c) for c in cols]
    if unit_row is not None:
        split = [(n, u or v) for (n, v), u in zip(split, unit_row, strict=True)]
    meta: dict[str, Any] = {} if encoding == "utf-8" else {"text_encoding": encoding}
    if len(head) > 1:
        meta["preamble"] = [ln.strip() for ln in head[:-1]][:50]
    notes = []
    if len(rows) < len(body):
        notes.append("the last row is incomplete and was left out")
    first_name, first_unit = split[0]
    if _axis_unit(first_unit, FREQUENCY_UNITS) or first_name.lower().startswith(("freq", "omega")):
        return _read_frf(p, cols, split, table, meta, channel_map)
    t_scale = None
    if _axis_unit(first_unit, TIME_UNITS) or first_name.strip().lower() in _TIME_NAMES:
        # a time column: its unit converted to s, any unit other than a time refused
        t_scale, note = axis_scale(first_unit, "time", f"{p}: column {cols[0]!r}")
        notes += [note] if note else []
    first = 1
    if t_scale is None:
        stated = _stated_rate(head[:-1])
        if stated is None:
            raise FileFormatError(
                f"{p}: the first column {cols[0]!r} is not a time (named time/t or in s) or a "
                "frequency (named freq... or in Hz) column, and no line above the header "
                "states a sample rate (Sample rate: 1024 Hz); plain CSV needs one of them"
            )
        fs, first = stated, 0
        notes.append(f"sample rate {fs:g} Hz from the lines above the header")
    else:
        t = table[:, 0] * t_scale
        fs = _rate(p, t, [_cells(ln, delim)[0] for ln in body[: len(rows)]], t_scale)
    return timedata_from_channels(
        p,
        [n for n, _ in split[first:]],
        [u for _, u in split[first:]],
        list(table[:, first:].T),
        fs,
        None,
        channel_map,
        aliases=[[c.strip()] for c in cols[first:]],
        meta=meta,
        notes=notes,
    )


_RATE_LINE = re.compile(
    r"(sampl\w*\s*rate|sampling\s*freq\w*|abtastrate|abtastfrequenz|\bfs\b|\bsr\b)"
    r"\s*(\[hz\])?\s*[:=,;\t]?\s*\"?([-+]?\d+(?:[.,]\d*)?(?:[eE][-+]?\d+)?)[\s;,]*(k?hz)?",
    re.IGNORECASE,
)
_STEP_LINE = re.compile(
    r"(delta[_ ]?[tx]|\bdt\b|sample\s*interval|time\s*increment|increment)"
    r"\s*(\[s\])?\s*[:=,;\t]?\s*\"?([-+]?\d+(?:[.,]\d*)?(?:[eE][-+]?\d+)?)\s*(s|ms)?\b",
    re.IGNORECASE,
)


def _stated_rate(lines: Sequence[str]) -> float | None:
    """A sample rate (Hz) stated in lines such as ``Sample rate: 1024 Hz`` or ``dt = 0.001``."""
    for ln in lines:
        m = _RATE_LINE.search(ln)
        if m:
            v = float(m.group(3).replace(",", "."))
            v *= 1e3 if (m.group(4) or "").lower() == "khz" else 1.0
            if v > 0:
                return snap_rate(v)
        m = _STEP_LINE.search(ln)
        if m:
            v = float(m.group(3).replace(",", "."))
            v *= 1e-3 if (m.group(4) or "").lower() == "ms" else 1.0
            if v > 0:
                return snap_rate(1.0 / v)
    return None


def _rate(p: Path, t: np.ndarray, texts: Sequence[str], scale: float) -> float:
    """Sample rate of an evenly spaced time column (its printed resolution allowed for)."""
    n = t.size
    dt = float(t[-1] - t[0]) / (n - 1)
    if not dt > 0:
        raise FileFormatError(f"{p}: the time column does not increase")
    decimals = 0
    for s in texts[:200]:
        s = s.strip().lower()
        if "e" in s:
            decimals = max(decimals, 16)
            continue
        for sep in (".", ","):
            if sep in s:
                decimals = max(decimals, len(s) - s.index(sep) - 1)
    resolution = 0.5 * 10.0 ** (-decimals) * scale
    dev = np.abs(t - (t[0] + dt * np.arange(n)))
    if float(dev.max()) > 0.01 * dt + resolution:
        k = int(np.argmax(dev))
        raise FileFormatError(
            f"{p}: the time column is not evenly spaced (row {k + 1} is {dev[k]:.3g} s off a "
            f"step of {dt:.6g} s); tyredamp reads evenly sampled data"
        )
    return snap_rate(1.0 / dt)


_ROLE_KIND = {"acceleration": "accelerance", "velocity": "mobility", "displacement": "receptance"}
_PAIRS = (
    (
        re.compile(r"^(?P<n>.+?)[._ ]?(re|real)$", re.I),
        re.compile(r"^(?P<n>.+?)[._ ]?(im|imag)$", re.I),
    ),
    (
        re.compile(r"^(re|real)[(_ ]\s*(?P<n>.+?)\)?$", re.I),
        re.compile(r"^(im|imag)[(_ ]\s*(?P<n>.+?)\)?$", re.I),
    ),
    (
        re.compile(r"^(?P<n>.+?)[._ ]?(mag|magnitude|amp|abs)$", re.I),
        re.compile(r"^(?P<n>.+?)[._ ]?(phase|phi|arg)$", re.I),
    ),
    (
        re.compile(r"^(mag|magnitude|amp|abs)[(_ ]\s*(?P<n>.+?)\)?$", re.I),
        re.compile(r"^(phase|phi|arg)[(_ ]\s*(?P<n>.+?)\)?$", re.I),
    ),
)


def _read_frf(
    p: Path,
    cols: Sequence[str],
    split: Sequence[tuple[str, str]],
    table: np.ndarray,
    meta: dict[str, Any],
    channel_map: ChannelMap | None,
) -> FRF:
    """An FRF from a frequency column and pairs of columns (re/im or magnitude/phase)."""
    f_scale, note = axis_scale(split[0][1], "frequency", f"{p}: column {cols[0]!r}")
    f = table[:, 0] * f_scale
    if note:
        meta = {**meta, "read_notes": [*meta.get("read_notes", []), note]}
    items: list[tuple[str, int, int]] = []  # (base name, first column, pair type)
    coh = []
    k = 1
    while k < len(cols):
        name = split[k][0]
        if name.lower().startswith(("coh", "gamma")):
            coh.append(table[:, k])
            k += 1
            continue
        if k + 1 >= len(cols):
            raise FileFormatError(f"{p}: column {cols[k]!r} has no partner (re/im or mag/phase)")
        found = None
        for i, (a, b) in enumerate(_PAIRS):
            ma, mb = a.match(name), b.match(split[k + 1][0])
            if ma and mb and ma.group("n").lower() == mb.group("n").lower():
                found = (ma.group("n").strip(" ._"), k, i)
                break
        if found is None:
            raise FileFormatError(
                f"{p}: columns {cols[k]!r} and {cols[k + 1]!r} are not a complex pair (name.re/"
                "name.im, Re(name)/Im(name) or name.mag/name.phase)"
            )
        items.append(found)
        k += 2
    specs = (channel_map or ChannelMap()).resolve([[b] for b, _, _ in items], p)
    hs, names, kinds = [], [], set()
    for j, (base, k, pair) in enumerate(items):
        unit, unit2 = split[k][1], split[k + 1][1]
        if pair < 2:
            h = table[:, k] + 1j * table[:, k + 1]
        else:
            deg = unit2.strip().lower() not in ("rad", "radian", "radians")
            if unit2.strip() and unit2.strip().lower() not in _ANGLE:
                raise FileFormatError(
                    f"{p}: column {cols[k + 1]!r}: phase unit {unit2!r} is not deg or rad"
                )
            ph = np.deg2rad(table[:, k + 1]) if deg else table[:, k + 1]
            h = table[:, k] * np.exp(1j * ph)
        spec = specs.get(j)
        label = spec.unit if spec and spec.unit else unit
        try:
            r = frf_units(label) if label else None
        except InputError as exc:
            raise FileFormatError(f"{p}: column {cols[k]!r}: {exc}") from None
        kind = r[0] if r else None
        scale = r[1] if r else 1.0
        if spec and spec.role in _ROLE_KIND:
            if kind not in (None, _ROLE_KIND[spec.role]):
                raise InputError(
                    f"{p}: column {cols[k]!r}: unit {label!r} is not a {spec.role} per force"
                )
            kind = _ROLE_KIND[spec.role]
        if kind is None:
            raise FileFormatError(
                f"{p}: column {cols[k]!r}: no unit tells what the FRF relates; give it, for "
                f"example --channel '{base}=acceleration:m/s^2/N'"
            )
        kinds.add(kind)
        hs.append(h * scale)
        names.append(base)
    if not hs:
        raise FileFormatError(f"{p}: no FRF columns after the frequency column")
    if len(kinds) > 1:
        raise FileFormatError(f"{p}: FRFs of different kinds in one file: {sorted(kinds)}")
    outs = [Channel(node=i + 1, direction=3, name=n) for i, n in enumerate(names)]
    if coh and len(coh) != len(hs):
        raise FileFormatError(
            f"{p}: expected {len(hs)} coherence columns (one per FRF) or none, got {len(coh)}"
        )
    cmat = np.array(coh) if coh else None
    try:
        return FRF(
            f,
            np.array(hs)[:, None, :],
            kind=kinds.pop(),  # type: ignore[arg-type]
            outputs=outs,
            inputs=[Channel(node=1, direction=3, name="force")],
            coherence=cmat,
            meta=meta,
        )
    except InputError as exc:
        raise FileFormatError(f"{p}: {exc}") from None
