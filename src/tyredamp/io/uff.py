"""Universal File Format data set 58 (ASCII) and 58b (binary) through pyuff.

One data set holds one function: a time history (function type 1) of one
channel, an FRF (function type 4) of one output/input pair, or a coherence
(function type 6). An FRF matrix is a group of type-4 sets; a test's time
data is a group of type-1 sets of equal length and sampling.

What is written
---------------
* Record 6: response node and direction = the output channel (or the time
  channel), reference node and direction = the input channel (0/0 for time
  data and for a multiple coherence).
* Records 8-10: abscissa data type 18 (frequency, "Hz") or 17 (time, "s");
  ordinate (numerator) data type 8/11/12/13 for displacement, velocity,
  acceleration, force with SI units labels ``m``, ``m/s``, ``m/s^2``, ``N``;
  for an FRF the denominator is type 13 (excitation force, ``N``). So
  receptance, mobility and accelerance are told apart by the ordinate data
  type; the units exponents are set to the SI dimensions as well.
* ID line 1: a description (``meta["description"]`` or ``"tyredamp FRF ..."``);
  ID line 2: ``tyredamp1 ...`` with the exact frequency axis or sample rate
  as Python floats (the fixed E13.5 fields of record 7 keep only 6 digits);
  ID line 3: as much of ``meta`` as fits in 80 characters as JSON, for time
  data the acquisition fields first (``period_samples``, ``settle_samples``,
  ``record_samples``, ``run_starts`` (evenly spaced runs as ``run_every``:
  [step, count]), ``band_hz`` ..., read back into ``TimeData.acquisition``;
  an acquisition that does not fit is an error, never silently dropped),
  then the operating conditions of a lateral rig FRF (``speed_m_s``,
  ``force``, ``wheel_mass_kg``, ``pressure_bar``); the whole ``meta`` is in
  the metadata record below when it does not fit;
  ID lines 4 and 5: channel name and angle of the response and reference as
  JSON (``NONE`` when there are none); time data have no reference, and ID
  line 5 continues the metadata.
* ``FRF.variance`` (when present): one extra data set per output/input pair
  of function type 0 ("general") with ID line 1 ``tyredamp FRF variance``,
  the pair's response and reference nodes, and the variance of ``H`` in
  (unit of H)^2 as ordinate; other programs see a general function, tyredamp
  reads it back into ``FRF.variance``.

Precision
---------
Binary 58b (format ``"uff58b"``, the default for ``.uff`` and ``.unv``)
stores every value as a float64 and the frequencies as uneven abscissa
values: FRF and time data round-trip bit for bit. ASCII 58 (format
``"uff58"``) stores values in E20.12 fields, 12 significant digits, relative
error up to 5e-12; the frequency axis must then be evenly spaced (it is
rebuilt exactly from ID line 2).

Metadata record
---------------
When ``meta`` does not fit the ID lines whole, the file also holds the whole
``meta`` as JSON in a chain of data sets 151 (header) placed before the data
sets 58, so nothing is truncated (layout in :mod:`tyredamp.io._uff_meta`).

Reading other programs' files
-----------------------------
The response quantity comes from the ordinate data type (8, 11, 12; 9 or 13
for forces) or else from the ordinate units label, read by
:mod:`tyredamp.io.units` (``m/s²``, ``m/s2``, ``ms^-2``, ``g``, ``mm/s``,
``in``, ``µm``, ``lbf``, ``kN`` ..., converted to SI); a blank label or
``NONE`` is taken as SI; a label that cannot be read is an error naming it.
An FRF label may hold the whole ratio (``g/N``, ``(m/s^2)/N``,
``(1/N)*(m/s²)``) or only the response with the force in the denominator
label; a label and a data type that disagree are an error.

Modules
-------
This module reads; :mod:`tyredamp.io._uff_write` writes (:func:`write_uff` is
imported from there); :mod:`tyredamp.io._uff_records` holds the record
conventions both follow (data types, units labels, ID lines);
:mod:`tyredamp.io._uff_load` loads and checks the data sets through pyuff and
:mod:`tyredamp.io._uff_meta` holds the metadata record.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, KINDS, Channel, FRFKind
from ..timedata import TimeData
from ._channels import timedata_from_channels
from ._common import check_input_file, wrap_errors
from ._uff_load import (
    load_sets,
    not_frf_or_time,
    read_coherence,
    read_input_noise,
    read_variance,
)
from ._uff_records import (
    _KIND_QUANTITY,
    _QUANTITY_KIND,
    _SDT_QUANTITY,
    _extras,
    _rebuild_axis,
    _tokens,
)
from ._uff_write import write_uff
from .channelmap import ChannelMap
from .units import frf_units, quantity_units

__all__ = ["read_uff", "uff_contents", "write_uff"]


def _channel(node: Any, direction: Any, extras: dict[str, Any], where: str) -> Channel:
    try:
        angle = extras.get("angle_deg")
        return Channel(
            node=int(node),
            direction=int(direction),
            angle_deg=None if angle is None else float(angle),
            name=str(extras.get("name", "")),
        )
    except (TypeError, ValueError) as exc:
        raise FileFormatError(f"{where}: invalid node/direction ({exc})") from None


def _quantity(s: dict[str, Any], where: str) -> tuple[str | None, float]:
    """(quantity, factor to SI) of a data set from its ordinate data type and units labels."""
    sdt = int(s.get("ordinate_spec_data_type", 0) or 0)
    label = s.get("ordinate_axis_units_lab", "")
    q_sdt = _SDT_QUANTITY.get(sdt)
    q: str | None
    try:
        if int(s.get("func_type", 0)) == 4:
            r = frf_units(label, s.get("orddenom_axis_units_lab", ""))
            kind, scale = (None, 1.0) if r is None else r
            q = None if kind is None else _KIND_QUANTITY[kind]
        else:
            u = quantity_units(label)
            q, scale = (None, 1.0) if u is None else u
    except InputError as exc:
        raise FileFormatError(f"{where}: {exc}") from None
    if q is None:
        q = q_sdt
    elif q_sdt is not None and q != q_sdt:
        raise FileFormatError(
            f"{where}: ordinate data type {sdt} ({q_sdt}) disagrees with units label {label!r}"
        )
    return q, scale


def uff_contents(path: str | os.PathLike[str]) -> str:
    """``"frf"`` or ``"timedata"``: what the UFF file at ``path`` holds."""
    p = check_input_file(path)
    types = {int(s.get("func_type", -1)) for s in load_sets(p)}
    if 4 in types:
        return "frf"
    if 1 in types:
        return "timedata"
    raise not_frf_or_time(p, types)


def read_uff(
    path: str | os.PathLike[str],
    what: str | None = None,
    kind: FRFKind | None = None,
    channel_map: ChannelMap | None = None,
) -> FRF | TimeData:
    """Read FRFs (function type 4) or time data (type 1) from a UFF file.

    Parameters
    ----------
    path : path-like
    what : {"frf", "timedata"}, optional
        Which to read; default FRF when the file holds FRFs, else time data.
    kind : {"receptance", "mobility", "accelerance"}, optional
        FRF kind when the file does not tell it (ordinate data type and units
        label missing); when given it overrides the file.
    channel_map : ChannelMap, optional
        Time data: roles, units and sensitivities of channels (keys: the
        response entity name, ID line 1 or the point label such as ``1+Z``,
        or the position 1, 2 ...).

    Raises
    ------
    FileFormatError
        Empty, truncated or corrupt file; missing FRFs of the matrix; channels
        of different length or sampling; unknown units.
    """
    p = check_input_file(path)
    sets = load_sets(p)
    types = {int(s.get("func_type", -1)) for s in sets}
    if what is None:
        what = "frf" if 4 in types else "timedata" if 1 in types else ""
        if not what:
            raise not_frf_or_time(p, types)
    if what == "frf" and 4 not in types:
        if 1 in types:
            raise FileFormatError(f"{p}: holds time data (function type 1), not an FRF")
        raise not_frf_or_time(p, types)
    if what == "timedata" and 1 not in types:
        if 4 in types:
            raise FileFormatError(f"{p}: holds FRFs (function type 4), not time data")
        raise not_frf_or_time(p, types)
    if what == "frf" and channel_map:
        raise InputError(
            f"{p}: holds FRFs, whose units and channels the file states; a channel map "
            "(--channel, --sensitivity) applies to time data"
        )
    with wrap_errors(p):
        if what == "frf":
            return _read_frf(p, sets, kind)
        if what == "timedata":
            return _read_time(p, sets, channel_map)
    raise InputError(f"what: expected 'frf' or 'timedata', got {what!r}")


def _meta(s: dict[str, Any], tok: dict[str, str] | None) -> dict[str, Any]:
    meta = _extras(s.get("id3")) if tok is not None else {}
    if tok is not None and tok.get("_what") == "time":
        meta.update(_extras(s.get("id5")))
        every = meta.pop("run_every", None)
        if isinstance(every, list) and len(every) == 2:
            try:
                meta["run_starts"] = [int(every[0]) * k for k in range(int(every[1]))]
            except (TypeError, ValueError):
                raise FileFormatError(f"ID line: run_every {every!r} is not two integers") from None
    desc = str(s.get("id1", "")).strip()
    if desc and desc != "NONE" and not desc.startswith("tyredamp "):
        meta.setdefault("description", desc)
    if "_meta" in s:  # the whole meta from the metadata record (the acquisition stays above)
        meta.update(s["_meta"])
    return meta


def _read_frf(p: Path, sets: list[dict[str, Any]], kind: FRFKind | None) -> FRF:
    frf_sets = [s for s in sets if int(s["func_type"]) == 4]
    if not frf_sets:
        raise FileFormatError(f"{p}: no FRF (function type 4) data set")
    if kind is not None and kind not in KINDS:
        raise InputError(f"kind: expected one of {KINDS}, got {kind!r}")
    first = frf_sets[0]
    tok = _tokens(first)
    n = len(first["data"])
    x = np.asarray(first["x"], dtype=float)[:n]
    if tok is not None and "df" in tok:
        rebuilt = _rebuild_axis(tok, n)
        if rebuilt is not None and np.allclose(rebuilt, x, rtol=1e-5, atol=1e-5 * abs(rebuilt[-1])):
            x = rebuilt
    outs: dict[tuple[int, int], Channel] = {}
    ins: dict[tuple[int, int], Channel] = {}
    cells: dict[tuple[tuple[int, int], tuple[int, int]], np.ndarray] = {}
    kinds: set[str] = set()
    for s in frf_sets:
        where = f"{p}: data set #{s['_index']}"
        if int(s.get("abscissa_spec_data_type", 18) or 0) not in (0, 1, 18):
            raise FileFormatError(
                f"{where}: abscissa data type {s['abscissa_spec_data_type']} is not frequency (18)"
            )
        if len(s["data"]) != n or not np.allclose(
            np.asarray(s["x"], dtype=float)[:n],
            np.asarray(first["x"], dtype=float)[:n],
            rtol=1e-9,
            atol=0,
        ):
            raise FileFormatError(
                f"{where}: frequency axis differs from data set #{first['_index']}"
            )
        q, scale = _quantity(s, where)
        if kind is None:
            if q is None:
                raise FileFormatError(
                    f"{where}: cannot tell the response quantity (ordinate data type "
                    f"{s.get('ordinate_spec_data_type')}, no units label); give the ordinate "
                    "data type or units label in the file, or kind= to read_frf (Python)"
                )
            if q == "force":
                raise FileFormatError(f"{where}: the ordinate is a force, not a response")
            kinds.add(_QUANTITY_KIND[q])
        ko = (int(s["rsp_node"]), int(s["rsp_dir"]))
        ki = (int(s["ref_node"]), int(s["ref_dir"]))
        if ko not in outs:
            outs[ko] = _channel(*ko, _extras(s.get("id4")) if tok else {}, where)
        if ki not in ins:
            ins[ki] = _channel(*ki, _extras(s.get("id5")) if tok else {}, where)
        if (ko, ki) in cells:
            raise FileFormatError(f"{where}: a second FRF for response {ko} and reference {ki}")
        cells[(ko, ki)] = np.asarray(s["data"], dtype=complex) * scale
    if kind is None:
        if len(kinds) > 1:
            raise FileFormatError(f"{p}: FRFs of different kinds in one file: {sorted(kinds)}")
        kind = kinds.pop()  # type: ignore[assignment]
    h = np.empty((len(outs), len(ins), n), dtype=complex)
    for a, ko in enumerate(outs):
        for b, ki in enumerate(ins):
            if (ko, ki) not in cells:
                raise FileFormatError(
                    f"{p}: incomplete FRF matrix: no data set for response node {ko[0]} dir "
                    f"{ko[1]} and reference node {ki[0]} dir {ki[1]}"
                )
            h[a, b] = cells[(ko, ki)]
    coh = read_coherence(sets, list(outs), list(ins), n)
    var = read_variance(sets, list(outs), list(ins), n, h.shape)
    rin = read_input_noise(sets, list(ins), n)
    meta = _meta(first, tok)
    encodings = sorted({s["_encoding"] for s in frf_sets if "_encoding" in s})
    if encodings:
        meta["text_encoding"] = ", ".join(encodings)
    return FRF(
        x,
        h,
        kind=kind or "receptance",
        outputs=list(outs.values()),
        inputs=list(ins.values()),
        coherence=coh,
        meta=meta,
        variance=var,
        input_noise=rin,
    )


def _uff_name(s: dict[str, Any], tok: dict[str, str] | None) -> str:
    """The name a data set's channel goes by: tyredamp's, the response entity, ID line 1."""
    name = str(_extras(s.get("id4")).get("name", "")) if tok else ""
    for key in ("rsp_ent_name", "id1"):
        if not name:
            v = str(s.get(key, "") or "").strip()
            name = "" if v.upper() in ("", "NONE") else v
    return name


def _read_time(
    p: Path, sets: list[dict[str, Any]], channel_map: ChannelMap | None = None
) -> TimeData:
    ts = [s for s in sets if int(s["func_type"]) == 1]
    if not ts:
        raise FileFormatError(f"{p}: no time response (function type 1) data set")
    first = ts[0]
    n = len(first["data"])
    tok = _tokens(first)
    rows, chans, quants = [], [], []
    for s in ts:
        where = f"{p}: data set #{s['_index']}"
        if int(s.get("abscissa_spec_data_type", 17) or 0) not in (0, 1, 17):
            raise FileFormatError(
                f"{where}: abscissa data type {s['abscissa_spec_data_type']} is not time (17)"
            )
        if len(s["data"]) != n:
            raise FileFormatError(
                f"{where}: {len(s['data'])} samples, but data set #{first['_index']} has {n}; "
                "channels must have equal length"
            )
    meta = _meta(first, tok)
    encodings = sorted({s["_encoding"] for s in ts if "_encoding" in s})
    if encodings:
        meta["text_encoding"] = ", ".join(encodings)
    fs = _sample_rate(p, ts, tok)
    if channel_map:
        points, names, aliases, labels, hints = [], [], [], [], []
        for k, s in enumerate(ts):
            ch = _channel(s["rsp_node"], s["rsp_dir"], {}, f"{p}: data set #{s['_index']}")
            name = _uff_name(s, tok) or f"{ch.label}"
            names.append(name)
            aliases.append([ch.label, str(s.get("id1", "")).strip(), f"#{k + 1}"])
            points.append((ch.node, ch.direction))
            labels.append(str(s.get("ordinate_axis_units_lab", "") or ""))
            hints.append(_SDT_QUANTITY.get(int(s.get("ordinate_spec_data_type", 0) or 0)))
        return timedata_from_channels(
            p,
            names,
            labels,
            [np.asarray(s["data"], dtype=float) for s in ts],
            fs,
            None,
            channel_map,
            aliases=aliases,
            hints=hints,
            points=points,
            meta=meta,
        )
    for s in ts:
        where = f"{p}: data set #{s['_index']}"
        q, scale = _quantity(s, where)
        if q is None:
            name = _uff_name(s, tok) or str(s["rsp_node"])
            raise FileFormatError(
                f"{where}: cannot tell the measured quantity (ordinate data type "
                f"{s.get('ordinate_spec_data_type')}, no units label); name it, for example "
                f"--channel '{name}=acceleration:m/s^2'"
            )
        rows.append(np.asarray(s["data"], dtype=float) * scale)
        chans.append(
            _channel(s["rsp_node"], s["rsp_dir"], _extras(s.get("id4")) if tok else {}, where)
        )
        quants.append(q)
    return TimeData(np.array(rows), fs, chans, quants, meta=meta)


def _sample_rate(p: Path, ts: list[dict[str, Any]], tok: dict[str, str] | None) -> float:
    if tok is not None and "fs" in tok:
        try:
            return float(tok["fs"])
        except ValueError:
            pass
    steps = []
    for s in ts:
        x = np.asarray(s["x"], dtype=float)
        if int(s.get("abscissa_spacing", 1)) == 1:
            steps.append(float(s["abscissa_inc"]))
        else:
            dx = np.diff(x)
            if dx.size == 0 or np.any(dx <= 0) or np.ptp(dx) > 1e-4 * np.mean(dx):
                raise FileFormatError(f"{p}: data set #{s['_index']}: uneven time sampling")
            steps.append(float(np.mean(dx)))
    dt = steps[0]
    if dt <= 0 or any(abs(d - dt) > 1e-5 * dt for d in steps):
        raise FileFormatError(
            f"{p}: channels have different sampling intervals {sorted(set(steps))}"
        )
    fs = 1.0 / dt
    # E13.5 keeps 6 digits: snap to the integer rate it stands for
    if abs(fs - round(fs)) <= 1e-5 * fs:
        fs = float(round(fs))
    return fs
