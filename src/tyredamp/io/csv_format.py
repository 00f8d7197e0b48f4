"""CSV files: a documented text layout for FRFs and time data.

Other CSV exports (a header row of column names and a time or frequency
column) are read by :mod:`.plain_csv`.

The file is UTF-8 text. It starts with comment lines (``#``) holding the
metadata, then one line of column names, then one line per frequency line or
sample, values separated by commas. Numbers are written with 17 significant
digits, so every float64 value reads back bit for bit.

FRF layout::

    # tyredamp csv 1
    # type: frf
    # kind: accelerance
    # unit: m/(s^2 N)
    # output: {"node": 1, "direction": 3, "angle_deg": 0.0, "name": "acc01"}
    # output: ...                    (one line per output, in order)
    # input: {"node": 1, "direction": 3, "angle_deg": 0.0, "name": "force"}
    # meta: {"estimator": "H1", ...} (JSON object, optional)
    frequency_Hz,H[acc01/force].re,H[acc01/force].im,...,coherence[acc01],...
    1.25,0.0012345678901234567,-0.00098765432109876543,...

* ``frequency_Hz``: lines in Hz, strictly increasing.
* ``H[out/in].re``, ``H[out/in].im``: real and imaginary part of ``H`` for
  every output (outer loop) and input (inner loop), in the SI unit of the
  kind (``unit`` line: m/N, m/(s N) or m/(s^2 N)).
* ``coherence[out]``: optional multiple coherence of each output (0..1).
* ``variance[out/in]``: optional variance of each ``H`` estimate (unit of
  ``H`` squared), for every output (outer) and input (inner).
* ``input_noise[in]``: optional relative variance of the input (force) noise
  of each input (dimensionless, :attr:`tyredamp.frf.FRF.input_noise`), last.

Time-data layout::

    # tyredamp csv 1
    # type: timedata
    # sample_rate: 2048.0
    # channel: {"node": 1, "direction": 3, "angle_deg": null, "name": "", "quantity": "force"}
    # channel: ...                   (one line per column after time_s)
    # acquisition: {"period_samples": 4096, "settle_samples": 8192} (optional)
    # meta: {"operator": "..."}      (free notes, optional)
    time_s,1+Z [N],2+Z [m/s^2],...
    0,0.5,0.001,...

* ``time_s``: sample time in s (informative; ``sample_rate`` in Hz is what is
  used; without a ``sample_rate`` line it is taken from the time column).
* one column per channel in SI units (N, m, m/s, m/s^2 by ``quantity``).
* ``acquisition``: the fields of :class:`~tyredamp.timedata.Acquisition`
  (``period_samples``, ``run_starts``, ``settle_samples``,
  ``record_samples``, ``band_hz``, ``n_averages``, ``excitation``); files
  written before it existed kept them in ``meta`` and still read the same.

Channel records: ``node`` (int), ``direction`` (UFF code, 3 = +Z/radial),
``angle_deg`` (float or null), ``name`` (str); time-data channels add
``quantity`` (force, displacement, velocity, acceleration).
"""

from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, UNITS
from ..timedata import Acquisition, TimeData
from ._atomic import atomic_path
from ._common import (
    channel_from_dict,
    channel_to_dict,
    check_input_file,
    meta_from_json,
    meta_to_json,
    wrap_errors,
)
from ._text import decode_text
from .channelmap import ChannelMap

__all__ = ["read_csv", "write_csv"]

_MAGIC = "# tyredamp csv 1"
_FMT = "%.17g"


def _json(d: dict[str, Any]) -> str:
    return meta_to_json(d, compact=False)


def write_csv(obj: FRF | TimeData, path: str | os.PathLike[str]) -> None:
    """Write an FRF or TimeData to ``path`` in the layout of the module docstring.

    The file appears whole or not at all.
    """
    head = [_MAGIC]
    if isinstance(obj, FRF):
        head += ["# type: frf", f"# kind: {obj.kind}", f"# unit: {obj.unit}"]
        head += [f"# output: {_json(channel_to_dict(c))}" for c in obj.outputs]
        head += [f"# input: {_json(channel_to_dict(c))}" for c in obj.inputs]
        cols = ["frequency_Hz"]
        blocks = [obj.frequency[:, None]]
        for o, co in enumerate(obj.outputs):
            for i, ci in enumerate(obj.inputs):
                cols += [f"H[{co.label}/{ci.label}].re", f"H[{co.label}/{ci.label}].im"]
                blocks.append(np.stack([obj.H[o, i].real, obj.H[o, i].imag], axis=1))
        if obj.coherence is not None:
            cols += [f"coherence[{c.label}]" for c in obj.outputs]
            blocks.append(obj.coherence.T)
        if obj.variance is not None:
            cols += [f"variance[{co.label}/{ci.label}]" for co in obj.outputs for ci in obj.inputs]
            blocks.append(obj.variance.reshape(-1, obj.n_freq).T)
        if obj.input_noise is not None:
            cols += [f"input_noise[{c.label}]" for c in obj.inputs]
            blocks.append(obj.input_noise.T)
        table = np.hstack(blocks)
    elif isinstance(obj, TimeData):
        head += ["# type: timedata", f"# sample_rate: {obj.sample_rate!r}"]
        head += [
            f"# channel: {_json(channel_to_dict(c, quantity=q))}"
            for c, q in zip(obj.channels, obj.quantities, strict=True)
        ]
        cols = ["time_s"] + [
            f"{c.label} [{u}]" for c, u in zip(obj.channels, obj.units, strict=True)
        ]
        table = np.hstack([obj.time[:, None], obj.data.T])
        acq = obj.acquisition.to_dict()
        if acq:
            head.append(f"# acquisition: {meta_to_json(acq)}")
    else:
        raise InputError(f"obj: expected FRF or TimeData, got {type(obj).__name__}")
    if obj.meta:
        head.append(f"# meta: {meta_to_json(obj.meta)}")
    for c in cols:
        if "," in c:
            raise InputError(f"channel label {c!r}: a comma cannot appear in a CSV column name")
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write("\n".join(head) + "\n")
        fh.write(",".join(cols) + "\n")
        np.savetxt(fh, table, fmt=_FMT, delimiter=",")


def _parse(p: Path, text: str) -> tuple[dict[str, list[str]], list[str], np.ndarray]:
    lines = text.splitlines()
    if not lines or lines[0].strip() != _MAGIC:
        raise FileFormatError(
            f"{p}: not a tyredamp CSV file (first line must be {_MAGIC!r}; see "
            "docs/file-formats.md)"
        )
    fields: dict[str, list[str]] = {}
    k = 1
    while k < len(lines) and lines[k].startswith("#"):
        body = lines[k][1:].strip()
        if ":" in body:
            key, val = body.split(":", 1)
            fields.setdefault(key.strip(), []).append(val.strip())
        k += 1
    if k >= len(lines):
        raise FileFormatError(f"{p}: no column-name line after the header (truncated file?)")
    if not text.endswith(("\n", "\r")):
        raise FileFormatError(
            f"{p}: truncated file: the last row has no line end (tyredamp ends every row "
            "with one; a copy cut short loses it)"
        )
    cols = [c.strip() for c in lines[k].split(",")]
    body_text = "\n".join(lines[k + 1 :])
    if not body_text.strip():
        raise FileFormatError(f"{p}: no data rows (truncated file?)")
    try:
        table = np.loadtxt(io.StringIO(body_text), delimiter=",", ndmin=2, dtype=float)
    except ValueError as exc:
        raise FileFormatError(f"{p}: bad data row ({exc})") from None
    if table.shape[1] != len(cols):
        raise FileFormatError(
            f"{p}: expected {len(cols)} values per row to match the column names, got "
            f"{table.shape[1]}"
        )
    return fields, cols, table


def _one(fields: dict[str, list[str]], key: str, p: Path) -> str:
    vals = fields.get(key)
    if not vals:
        raise FileFormatError(f"{p}: missing header line '# {key}: ...'")
    return vals[0]


def read_csv(path: str | os.PathLike[str], channel_map: ChannelMap | None = None) -> FRF | TimeData:
    """Read a CSV file: the layout of the module docstring, or a plain export.

    A file that does not start with ``# tyredamp csv 1`` is read as a plain
    CSV export with a header row (:mod:`.plain_csv`), where ``channel_map``
    names the channels' roles, units and sensitivities.

    Raises
    ------
    FileFormatError
        Missing header lines, rows of unequal length, values that are not
        numbers, NaN, a frequency axis that is not increasing, ...
    """
    p = check_input_file(path)
    text, encoding = decode_text(p.read_bytes())
    if text.lstrip("\ufeff").split("\n", 1)[0].strip() != _MAGIC:
        from .plain_csv import read_plain_csv

        return read_plain_csv(p, text, encoding, None, channel_map)
    if channel_map:
        raise InputError(
            f"{p}: a tyredamp CSV file states what each channel is; a channel map is not used"
        )
    fields, cols, table = _parse(p, text)
    typ = _one(fields, "type", p)
    meta = meta_from_json(fields["meta"][0], f"{p}: meta") if "meta" in fields else {}
    with wrap_errors(p):
        if typ == "frf":
            kind: Any = _one(fields, "kind", p)
            if kind not in UNITS:
                raise FileFormatError(f"{p}: kind {kind!r} is not one of {tuple(UNITS)}")
            outs = [
                channel_from_dict(meta_from_json(v, f"{p}: output"), f"{p}: output")
                for v in fields.get("output", [])
            ]
            ins = [
                channel_from_dict(meta_from_json(v, f"{p}: input"), f"{p}: input")
                for v in fields.get("input", [])
            ]
            if not outs or not ins:
                raise FileFormatError(f"{p}: expected '# output:' and '# input:' header lines")
            n_h = 2 * len(outs) * len(ins)
            n_rin = sum(c.startswith("input_noise[") for c in cols)
            if n_rin not in (0, len(ins)) or any(
                c.startswith("input_noise[") for c in cols[: len(cols) - n_rin]
            ):
                raise FileFormatError(
                    f"{p}: expected {len(ins)} input_noise columns at the end, got {n_rin}"
                )
            rin = table[:, len(cols) - n_rin :].T if n_rin else None
            cols = cols[: len(cols) - n_rin]
            table = table[:, : len(cols)]
            n_var = sum(c.startswith("variance[") for c in cols)
            if n_var not in (0, len(outs) * len(ins)) or any(
                c.startswith("variance[") for c in cols[: len(cols) - n_var]
            ):
                raise FileFormatError(
                    f"{p}: expected {len(outs) * len(ins)} variance columns at the end, got {n_var}"
                )
            n_rest = len(cols) - n_var
            var = table[:, n_rest:].T.reshape(len(outs), len(ins), -1) if n_var else None
            if n_rest == 1 + n_h:
                coh = None
            elif n_rest == 1 + n_h + len(outs):
                coh = table[:, 1 + n_h : n_rest].T
            else:
                raise FileFormatError(
                    f"{p}: expected {1 + n_h} columns ({len(outs)} outputs x {len(ins)} inputs, "
                    f"re and im) or {1 + n_h + len(outs)} with coherence (and the variance "
                    f"columns), got {len(cols)}"
                )
            h = table[:, 1 : 1 + n_h : 2] + 1j * table[:, 2 : 2 + n_h : 2]
            h = h.T.reshape(len(outs), len(ins), -1)
            return FRF(
                table[:, 0],
                h,
                kind=kind,
                outputs=outs,
                inputs=ins,
                coherence=coh,
                meta=meta,
                variance=var,
                input_noise=rin,
            )
        if typ == "timedata":
            recs = [meta_from_json(v, f"{p}: channel") for v in fields.get("channel", [])]
            if len(recs) != len(cols) - 1:
                raise FileFormatError(
                    f"{p}: expected one '# channel:' line per data column ({len(cols) - 1}), "
                    f"got {len(recs)}"
                )
            if "sample_rate" in fields:
                try:
                    fs = float(fields["sample_rate"][0])
                except ValueError:
                    raise FileFormatError(
                        f"{p}: sample_rate {fields['sample_rate'][0]!r} is not a number"
                    ) from None
            else:
                if table.shape[0] < 2:
                    raise FileFormatError(f"{p}: no sample_rate line and fewer than 2 samples")
                dt = np.diff(table[:, 0])
                if np.any(dt <= 0) or np.ptp(dt) > 1e-6 * np.mean(dt):
                    raise FileFormatError(f"{p}: time column is not evenly increasing")
                fs = 1.0 / float(np.mean(dt))
            acq = None
            if "acquisition" in fields:
                acq = Acquisition.from_dict(
                    meta_from_json(fields["acquisition"][0], f"{p}: acquisition")
                )
            return TimeData(
                table[:, 1:].T,
                fs,
                [channel_from_dict(r, f"{p}: channel") for r in recs],
                [str(r.get("quantity", "")) for r in recs],
                meta=meta,
                acquisition=acq,
            )
    raise FileFormatError(f"{p}: type {typ!r} is not 'frf' or 'timedata'")
