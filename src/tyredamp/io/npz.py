"""NPZ files: lossless storage of FRF and TimeData objects.

Layout (a NumPy ``.npz`` archive, no pickled objects):

``header``
    0-d unicode array with a JSON object: ``format`` ("tyredamp"),
    ``version`` (1), ``type`` ("frf" or "timedata") and, for an FRF,
    ``kind``, ``outputs``, ``inputs`` (lists of channel records ``{"node",
    "direction", "angle_deg", "name"}``) and ``meta``; for time data
    ``sample_rate`` (Hz), ``channels`` (channel records with ``quantity``),
    ``acquisition`` (the stated fields of
    :class:`~tyredamp.timedata.Acquisition`; older files kept them in
    ``meta`` and read the same) and ``meta``.
``frequency`` (n_freq,), ``H`` (n_out, n_in, n_freq) complex, optional
``coherence`` (n_out, n_freq), optional ``variance`` (n_out, n_in, n_freq),
optional ``input_noise`` (n_in, n_freq)
    FRF arrays, Hz and SI units of the kind (``input_noise`` is dimensionless).
``data`` (n_channels, n_samples)
    Time data in SI units.

Everything round-trips bit for bit (``meta`` must be JSON-compatible).
"""

from __future__ import annotations

import os
import zipfile
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError
from ..frf import FRF
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
from ._guard import check_archive

__all__ = ["read_npz", "write_npz"]

_VERSION = 1


def write_npz(obj: FRF | TimeData, path: str | os.PathLike[str]) -> None:
    """Write an FRF or TimeData to ``path`` (atomically).

    Parameters
    ----------
    obj : FRF or TimeData
    path : path-like
        Output file; NumPy appends nothing (the name is used as given).
    """
    arrays: dict[str, Any] = {}
    if isinstance(obj, FRF):
        head: dict[str, Any] = {
            "type": "frf",
            "kind": obj.kind,
            "outputs": [channel_to_dict(c) for c in obj.outputs],
            "inputs": [channel_to_dict(c) for c in obj.inputs],
        }
        arrays.update(frequency=obj.frequency, H=obj.H)
        if obj.coherence is not None:
            arrays["coherence"] = obj.coherence
        if obj.variance is not None:
            arrays["variance"] = obj.variance
        if obj.input_noise is not None:
            arrays["input_noise"] = obj.input_noise
    elif isinstance(obj, TimeData):
        head = {
            "type": "timedata",
            "sample_rate": obj.sample_rate,
            "channels": [
                channel_to_dict(c, quantity=q)
                for c, q in zip(obj.channels, obj.quantities, strict=True)
            ],
        }
        arrays["data"] = obj.data
        head["acquisition"] = obj.acquisition.to_dict()
    else:
        raise InputError(f"obj: expected FRF or TimeData, got {type(obj).__name__}")
    text = meta_to_json({"format": "tyredamp", "version": _VERSION, **head, "meta": obj.meta})
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, header=np.array(text), **arrays)


def _check_members(p: os.PathLike[str], max_bytes: int | None = None) -> None:
    """Refuse an archive whose members could not be loaded safely, before inflating any.

    Every member, whatever its name, is checked from the archive's directory
    first (:func:`._guard.check_archive`: the declared sizes fit in
    ``max_bytes``, default the memory available, and no member inflates
    more than :data:`._guard.MAX_ARCHIVE_RATIO`-fold: a "zip bomb"); then each
    member must be a ``.npy`` array (NumPy would inflate any other member
    whole) whose header claims no more data than the member holds (a ``shape``
    of 1e12 elements would otherwise be allocated before the data are found
    missing) and no Python objects.
    """
    limit = _available_memory() if max_bytes is None else max_bytes
    with zipfile.ZipFile(p) as zf:
        what = None if max_bytes is not None or limit is None else "the memory available"
        total = check_archive(zf, str(p), (1 << 62) if limit is None else limit, limit_text=what)
        for info in zf.infolist():
            if not info.filename.endswith(".npy"):
                raise FileFormatError(
                    f"{p}: member {info.filename[:60]!r} is not a NumPy array (.npy); a tyredamp "
                    "NPZ file holds arrays only"
                )
            try:
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
                    else:
                        shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
            except Exception as exc:  # ValueError, tokenize's TokenError, zlib.error ... on garbage
                raise FileFormatError(
                    f"{p}: {info.filename}: the array's header is not readable ({exc})"
                ) from None
            if dtype.hasobject:
                raise FileFormatError(f"{p}: {info.filename}: object arrays are not accepted")
            need = int(np.prod(shape, dtype=object)) * dtype.itemsize
            if need > info.file_size:
                raise FileFormatError(
                    f"{p}: {info.filename}: header claims shape {shape} ({need} bytes) but the "
                    f"archive holds {info.file_size} bytes; the file is corrupt"
                )
    if limit is not None and total > limit:  # pragma: no cover - check_archive refuses first
        raise InputError(f"{p}: its arrays take {total / 1e9:.3g} GB unpacked")


def _available_memory() -> int | None:
    """Bytes of memory available to a new allocation (Linux ``MemAvailable``), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _check_header(p: os.PathLike[str], head: dict[str, Any]) -> None:
    """Type checks of the header fields (each mistake named)."""
    expected: dict[str, tuple[type, ...]] = {
        "meta": (dict,),
        "outputs": (list,),
        "inputs": (list,),
        "channels": (list,),
        "kind": (str,),
        "type": (str,),
        "sample_rate": (int, float),
    }
    for key, types in expected.items():
        if key in head and (not isinstance(head[key], types) or isinstance(head[key], bool)):
            names = " or ".join(t.__name__ for t in types)
            raise FileFormatError(
                f"{p}: header {key!r}: expected {names}, got {type(head[key]).__name__}"
            )


def read_npz(path: str | os.PathLike[str], max_bytes: int | None = None) -> FRF | TimeData:
    """Read a file written by :func:`write_npz`.

    Parameters
    ----------
    path : path-like
    max_bytes : int, optional
        Most bytes the arrays may take once inflated (default: the memory
        available); checked from the archive's directory before any is read.

    Raises
    ------
    FileFormatError
        Not an NPZ archive, truncated, or without the expected entries.
    """
    p = check_input_file(path)
    try:
        _check_members(p, max_bytes)
        with open(p, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            if "header" not in z.files:
                raise FileFormatError(f"{p}: not a tyredamp NPZ file (no 'header' entry)")
            h = z["header"]
            if h.ndim != 0 or h.dtype.kind != "U":
                raise FileFormatError(
                    f"{p}: header: expected a text (unicode) scalar, got dtype {h.dtype} "
                    f"shape {h.shape}"
                )
            head = meta_from_json(str(h[()]), f"{p}: header")
            arrays = {k: z[k] for k in z.files if k != "header"}
    except (FileFormatError, InputError):
        raise
    except Exception as exc:  # zipfile, zlib and NumPy raise a dozen kinds on a damaged archive
        raise FileFormatError(f"{p}: not a readable NPZ file ({exc})") from None
    _check_header(p, head)
    if head.get("format") != "tyredamp":
        raise FileFormatError(f"{p}: header 'format' is {head.get('format')!r}, not 'tyredamp'")
    if head.get("version") != _VERSION:
        raise FileFormatError(f"{p}: unsupported version {head.get('version')!r}")
    meta = head.get("meta", {})
    kind = head.get("type")
    with wrap_errors(p):
        if kind == "frf":
            for k in ("frequency", "H"):
                if k not in arrays:
                    raise FileFormatError(f"{p}: missing array {k!r}")
            return FRF(
                arrays["frequency"],
                arrays["H"],
                kind=head.get("kind", ""),
                outputs=[channel_from_dict(c, f"{p}: outputs") for c in head.get("outputs", [])],
                inputs=[channel_from_dict(c, f"{p}: inputs") for c in head.get("inputs", [])],
                coherence=arrays.get("coherence"),
                meta=meta,
                variance=arrays.get("variance"),
                input_noise=arrays.get("input_noise"),
            )
        if kind == "timedata":
            if "data" not in arrays:
                raise FileFormatError(f"{p}: missing array 'data'")
            chans = head.get("channels", [])
            acq = head.get("acquisition")
            if acq is not None and not isinstance(acq, dict):
                raise FileFormatError(f"{p}: header 'acquisition' is not a JSON object")
            return TimeData(
                arrays["data"],
                head.get("sample_rate", 0.0),
                [channel_from_dict(c, f"{p}: channels") for c in chans],
                [str(c.get("quantity", "")) if isinstance(c, dict) else "" for c in chans],
                meta=meta,
                acquisition=None if acq is None else Acquisition.from_dict(acq),
            )
    raise FileFormatError(f"{p}: header 'type' is {kind!r}, expected 'frf' or 'timedata'")
