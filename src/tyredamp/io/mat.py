"""MATLAB ``.mat`` files (v4 to v7, read by :func:`scipy.io.loadmat`): time data or FRFs.

Analysers and scripts save a test as top-level variables. What is read is
detected from the variables themselves:

Time data
    The time base is a variable whose name says time (``t``, ``time``,
    ``Time_domain`` ...) holding evenly increasing seconds, and/or a scalar
    sample rate (a name with ``fs``, ``rate``, ``Sample_Rate``) or sample
    interval (``dt``, ``Delta_t``). The channels are the real vectors with
    as many samples as the time vector (with only a rate: the largest group
    of equally long real vectors, or those the channel map names); a matrix
    ``n_samples x n_channels`` gives channels ``NAME(:,1)``, ``NAME(:,2)``...
    MAT files have no units: every channel is named with a channel map
    (``--channel "Time_chan_1=force:N"``), whose keys are the variable names.

FRF
    Complex vectors (not named as spectra, cross spectra or correlations)
    with a frequency vector of the same length (a name with ``freq`` or
    ``f``, increasing Hz); a real vector of that length with ``coh`` in its
    name whose name contains the FRF's channel suffix is its coherence. What
    an FRF relates is named with the channel map (``--channel
    "Hf_chan_2=acceleration:g/N"``) or ``kind=``.

Fields of structures are read as ``name.field`` (``test.time``,
``test.acc1``) and match the rules above by their field name. Variables left
out (other lengths, structure arrays, text) are listed in
``meta["read_notes"]``. MATLAB v7.3 files are HDF5 and are not read.
"""

from __future__ import annotations

import os
import re
from typing import Any, Literal

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, Channel, FRFKind
from ..timedata import TimeData
from ._channels import snap_rate, timedata_from_channels
from ._common import check_input_file
from ._guard import axis_scale
from ._mat5 import check_mat5
from .channelmap import ChannelMap
from .units import frf_units

__all__ = ["read_mat"]

_TIME = re.compile(
    r"^(t|time|times|zeit|time_?s|time_?domain|time_?axis|time_?vector)"
    r"([_ ](s|sec|ms|us|min|h|hz|khz|deg|rad))?$",
    re.I,
)
_RATE = re.compile(r"(^fs$|^sr$|samp.*rate|sample_?freq|rate$)", re.I)
_STEP = re.compile(r"^(dt|delta_?t|ts|sample_?interval|time_?step|time_?increment)$", re.I)
_FREQ = re.compile(
    r"^(f|freq.*|frequency.*|f_?hz|.*_?freq_?domain|.*freq.*|omega.*|f_(k?hz|rad_?s|rpm|cpm))$",
    re.I,
)
#: An axis unit at the end of a variable name: ``t_ms``, ``freq_kHz``, ``omega_rad_s``.
_NAME_UNIT = re.compile(
    r"[_ ](?P<unit>k?hz|rad_?s|rad_per_s|cpm|rpm|s|sec|ms|us|min|h|deg|rad)$", re.I
)


def _name_scale(p: Any, name: str, axis: Literal["frequency", "time"]) -> tuple[float, str | None]:
    """``(factor to Hz or s, note)`` of the unit a variable's name ends with (none: Hz or s);
    ``omega`` without a unit is taken as rad/s."""
    leaf = _leaf(name)
    m = _NAME_UNIT.search(leaf)
    unit = "" if m is None else m.group("unit").lower()
    if m is not None and leaf.lower() in ("time_s", "times"):
        unit = "s"
    unit = {"rad_s": "rad/s", "rads": "rad/s", "rad_per_s": "rad/s"}.get(unit, unit)
    if not unit and leaf.lower().startswith("omega"):
        unit = "rad/s"
    return axis_scale(unit, axis, f"{p}: variable {name!r} (unit from its name)")


_NOT_FRF = re.compile(r"(spec|cross|psd|corr|auto|coh|mag|lin_)", re.I)
_ROLE_KIND = {"acceleration": "accelerance", "velocity": "mobility", "displacement": "receptance"}


def _load(p: Any) -> dict[str, np.ndarray]:
    from scipy.io import loadmat

    with open(p, "rb") as fh:
        check_mat5(fh.read(), str(p))  # before SciPy trusts the element sizes
    try:
        raw = loadmat(str(p), squeeze_me=False, struct_as_record=True)
    except NotImplementedError:
        raise FileFormatError(
            f"{p}: MATLAB v7.3 file (HDF5): not read; save it with save(..., '-v7') in MATLAB"
        ) from None
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError ... on garbage
        raise FileFormatError(f"{p}: not a readable MATLAB file ({exc})") from None
    out: dict[str, Any] = {}
    for k, v in raw.items():
        if not k.startswith("__"):
            _flatten(k, v, out, 0)
    return out


def _flatten(name: str, v: Any, out: dict[str, Any], depth: int) -> None:
    """Fields of a 1x1 struct as ``name.field`` (three levels), other values as they are."""
    if isinstance(v, np.ndarray) and v.dtype.names is not None and v.size == 1 and depth < 3:
        rec = v.ravel()[0]
        for field in v.dtype.names:
            _flatten(f"{name}.{field}", rec[field], out, depth + 1)
    else:
        out[name] = v


def _leaf(name: str) -> str:
    """The field name of ``struct.field`` (the name itself otherwise)."""
    return name.rsplit(".", 1)[-1]


def _vector(v: Any) -> np.ndarray | None:
    """A 1-D numeric array of ``v`` (a row or column vector), or None."""
    if not isinstance(v, np.ndarray) or v.dtype.kind not in "iufc" or v.size < 2:
        return None
    if v.ndim == 2 and 1 in v.shape:
        return v.ravel()
    if v.ndim == 1:
        return v
    return None


def _scalar(v: Any) -> float | None:
    if isinstance(v, np.ndarray) and v.dtype.kind in "iuf" and v.size == 1:
        x = float(v.ravel()[0])
        return x if np.isfinite(x) and x > 0 else None
    return None


def _columns(name: str, v: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """Real channels of a variable: a vector, or the columns of an n x k matrix."""
    vec = _vector(v)
    if vec is not None:
        return [(name, vec)] if vec.dtype.kind != "c" else []
    if v.ndim == 2 and v.dtype.kind in "iuf" and min(v.shape) >= 2:
        m = v if v.shape[0] >= v.shape[1] else v.T
        return [(f"{name}(:,{k + 1})", m[:, k]) for k in range(m.shape[1])]
    return []


def read_mat(
    path: str | os.PathLike[str],
    what: str | None = None,
    kind: FRFKind | None = None,
    channel_map: ChannelMap | None = None,
) -> FRF | TimeData:
    """Read time data or an FRF from a MATLAB file (module docstring).

    Parameters
    ----------
    path : path-like
    what : {"timedata", "frf"}, optional
        Default: time data when the file has a time base, else an FRF.
    kind : {"receptance", "mobility", "accelerance"}, optional
        FRF kind when neither the file nor the channel map says it (values
        taken as SI).
    channel_map : ChannelMap, optional
        Roles, units and sensitivities of the variables (:mod:`.channelmap`).

    Raises
    ------
    FileFormatError
        Not a MATLAB file, v7.3, no time base or FRF found, a channel whose
        quantity is not named.
    """
    p = check_input_file(path)
    vars_ = _load(p)
    if what is None:
        what = "timedata" if _time_base(vars_, p)[0] is not None else "frf"
    if what == "frf":
        return _read_frf(p, vars_, kind, channel_map)
    if what == "timedata":
        return _read_time(p, vars_, channel_map)
    raise InputError(f"what: expected 'frf' or 'timedata', got {what!r}")


def _time_base(
    vars_: dict[str, Any], p: Any = "MATLAB file"
) -> tuple[float | None, str | None, int | None]:
    """``(sample rate, time vector name, its length)`` from the variables (a unit in the
    time vector's name, ``t_ms``, converted)."""
    fs = tname = None
    n = None
    for name, v in vars_.items():
        vec = _vector(v)
        if _TIME.match(_leaf(name)) and vec is not None and vec.dtype.kind in "iuf":
            t = vec.astype(float) * _name_scale(p, name, "time")[0]
            dt = np.diff(t)
            if np.all(dt > 0):
                tname, n = name, t.size
                step = (t[-1] - t[0]) / (t.size - 1)
                if np.max(np.abs(dt - step)) <= 1e-3 * step:
                    fs = 1.0 / step
                break
    for name, v in vars_.items():
        x = _scalar(v)
        if x is None:
            continue
        if _RATE.search(_leaf(name)):
            fs = x
            break
        if _STEP.match(_leaf(name)):
            fs = 1.0 / x
            break
    return fs, tname, n


def _read_time(p: Any, vars_: dict[str, Any], channel_map: ChannelMap | None) -> TimeData:
    fs, tname, n = _time_base(vars_, p)
    if fs is None:
        raise FileFormatError(
            f"{p}: no time base: expected an evenly spaced time vector (t, time ...) or a "
            f"sample rate (fs, Sample_Rate ...) among the variables {', '.join(vars_)}"
        )
    cols: list[tuple[str, np.ndarray]] = []
    for name, v in vars_.items():
        if name != tname:
            cols += _columns(name, np.asarray(v) if isinstance(v, np.ndarray) else v)
    if not cols:
        raise FileFormatError(f"{p}: no real vectors to read as channels")
    keys = set(channel_map.keys) if channel_map else set()
    if n is None:
        named = {c[1].size for c in cols if c[0] in keys or c[0].split("(")[0] in keys}
        if len(named) == 1:
            n = named.pop()
        else:
            sizes: dict[int, int] = {}
            for _, a in cols:
                sizes[a.size] = sizes.get(a.size, 0) + 1
            n = max(sizes, key=lambda s: (sizes[s], s))
    keep = [(c, a) for c, a in cols if a.size == n]
    left = sorted({c.split("(")[0] for c, a in cols if a.size != n})
    left += sorted(
        k for k, v in vars_.items() if not _columns(k, v) and k != tname and _scalar(v) is None
    )
    if not keep:
        raise FileFormatError(f"{p}: no channel with the {n} samples of the time base {tname}")
    notes = [f"left out (not on the time base): {', '.join(left)}"] if left else []
    t_note = None if tname is None else _name_scale(p, tname, "time")[1]
    notes += [t_note] if t_note else []
    return timedata_from_channels(
        p,
        [c for c, _ in keep],
        [""] * len(keep),
        [a.astype(float) for _, a in keep],
        snap_rate(fs),
        None,
        channel_map,
        aliases=[
            [a for a in dict.fromkeys([c.split("(")[0], _leaf(c.split("(")[0])]) if a != c]
            for c, _ in keep
        ],
        notes=notes,
    )


def _read_frf(
    p: Any, vars_: dict[str, Any], kind: FRFKind | None, channel_map: ChannelMap | None
) -> FRF:
    frfs = {
        k: v
        for k, v in ((k, _vector(v)) for k, v in vars_.items())
        if v is not None and v.dtype.kind == "c" and not _NOT_FRF.search(k)
    }
    if not frfs:
        raise FileFormatError(
            f"{p}: no FRF: expected a complex vector (H, Hf_chan_2 ...) among the variables "
            f"{', '.join(vars_)}"
        )
    n = next(iter(frfs.values())).size
    frfs = {k: v for k, v in frfs.items() if v.size == n}
    freq: np.ndarray | None = None
    f_note = freq_note = None
    for name, v in vars_.items():
        vec = _vector(v)
        if (
            vec is not None
            and vec.size == n
            and vec.dtype.kind in "iuf"
            and _FREQ.match(_leaf(name))
        ):
            scale, f_note = _name_scale(p, name, "frequency")
            f = vec.astype(float) * scale
            if np.all(np.diff(f) > 0):
                freq, freq_note = f, f_note
                break
    if freq is None:
        df = None
        for name, v in vars_.items():
            x = _scalar(v)
            if x is not None and re.search(r"(delta_?f|^df$)", _leaf(name), re.I):
                df = x
        if df is None:
            raise FileFormatError(
                f"{p}: no frequency vector of {n} lines (freq, Freq_domain ...) or line "
                "spacing (df, DeltaF) for the FRFs"
            )
        freq = df * np.arange(n)
    names = list(frfs)
    specs = (channel_map or ChannelMap()).resolve([[k] for k in names], p)
    hs, kinds = [], set()
    notes = [f"FRF variables: {', '.join(names)}"]
    for j, name in enumerate(names):
        spec = specs.get(j)
        k_j: str | None = kind
        scale = 1.0
        if spec is not None and spec.unit:
            try:
                r = frf_units(spec.unit)
            except InputError as exc:
                raise InputError(f"{p}: FRF {name!r}: {exc}") from None
            k_j, scale = (None, 1.0) if r is None else r
        if spec is not None and spec.role in _ROLE_KIND:
            if k_j not in (None, _ROLE_KIND[spec.role]):
                raise InputError(
                    f"{p}: FRF {name!r}: unit {spec.unit!r} is not a {spec.role} per force"
                )
            if not spec.unit:
                notes.append(f"{name}: no unit given, taken as SI ({spec.role} per N)")
            k_j = _ROLE_KIND[spec.role]
        if k_j is None:
            raise FileFormatError(
                f"{p}: FRF {name!r}: the file does not say what it relates; name it, for "
                f"example --channel '{name}=acceleration:m/s^2/N' (Python: kind= or a ChannelMap)"
            )
        kinds.add(k_j)
        hs.append(frfs[name] * scale)
    if len(kinds) > 1:
        raise FileFormatError(f"{p}: FRFs of different kinds named: {sorted(kinds)}")
    coh = []
    used = set()
    for name in names:
        suffix = re.sub(r"^(hf?|frf)_?", "", name, flags=re.I)
        match = [
            _vector(v)
            for k, v in vars_.items()
            if "coh" in k.lower() and suffix and k.lower().endswith(suffix.lower())
        ]
        hit = [
            k
            for k, v in vars_.items()
            if "coh" in k.lower() and suffix and k.lower().endswith(suffix.lower())
        ]
        vec = next((m for m in match if m is not None and m.size == n), None)
        if vec is not None:
            used.update(hit)
            c = vec.real.astype(float)
            over = int(np.sum((c > 1.0) | (c < 0.0)))
            if over:
                notes.append(
                    f"{name}: coherence outside 0..1 at {over} line(s) (as stored), clipped"
                )
            vec = np.clip(c, 0.0, 1.0)
        coh.append(vec)
    cmat = np.array(coh) if all(c is not None for c in coh) else None
    left = sorted(k for k in vars_ if k not in frfs and k not in used)
    if used:
        notes.append(f"coherence: {', '.join(sorted(used))}")
    if left:
        notes.append(f"other variables not read: {', '.join(left)}")
    if freq_note:
        notes.append(freq_note)
    meta: dict[str, Any] = {"read_notes": notes}
    try:
        return FRF(
            freq,
            np.array(hs)[:, None, :],
            kind=kinds.pop(),  # type: ignore[arg-type]
            outputs=[Channel(node=j + 2, direction=3, name=nm) for j, nm in enumerate(names)],
            inputs=[Channel(node=1, direction=3, name="force")],
            coherence=cmat,
            meta=meta,
        )
    except InputError as exc:
        raise FileFormatError(f"{p}: {exc}") from None
