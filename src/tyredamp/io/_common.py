"""Helpers shared by the file formats: input checks, channel and metadata encoding."""

from __future__ import annotations

import contextlib
import json
import math
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError, InputError, TyredampError
from ..frf import Channel

__all__ = [
    "channel_from_dict",
    "channel_to_dict",
    "check_input_file",
    "meta_from_json",
    "meta_to_json",
    "uff_set_types",
    "wrap_errors",
]


def uff_set_types(path: str | os.PathLike[str]) -> frozenset[int]:
    """The data-set types of a UFF file (empty when the file is not readable as UFF).

    A probe for choosing a reader: a file that is not UFF gives an empty set and
    the chosen reader reports it. pyuff is imported here only when called.
    """
    import gc
    import warnings

    import pyuff

    p = check_input_file(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ResourceWarning)
            types = frozenset(int(t) for t in pyuff.UFF(str(p)).get_set_types())
            gc.collect()
    except Exception:  # not a UFF file: the caller's reader reports it
        return frozenset()
    return types


def check_input_file(path: str | os.PathLike[str]) -> Path:
    """Return ``path`` as a Path after checking it is a readable, non-empty file.

    Raises FileNotFoundError when missing (an OSError, reported by the CLI) and
    :class:`FileFormatError` for a directory or an empty file.
    """
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(2, "No such file", str(p))
    if not p.is_file():
        raise FileFormatError(f"{p}: not a regular file")
    if p.stat().st_size == 0:
        raise FileFormatError(f"{p}: empty file")
    return p


def channel_to_dict(c: Channel, **extra: Any) -> dict[str, Any]:
    """Channel as a JSON-ready dict (node, direction, angle_deg, name, extras)."""
    return {
        "node": int(c.node),
        "direction": int(c.direction),
        "angle_deg": None if c.angle_deg is None else float(c.angle_deg),
        "name": c.name,
        **extra,
    }


def channel_from_dict(d: Any, where: str) -> Channel:
    """Channel from a dict made by :func:`channel_to_dict`."""
    if not isinstance(d, dict) or "node" not in d:
        raise FileFormatError(f"{where}: expected a channel record with a node, got {d!r}")
    try:
        angle = d.get("angle_deg")
        return Channel(
            node=int(d["node"]),
            direction=int(d.get("direction", 3)),
            angle_deg=None if angle is None else float(angle),
            name=str(d.get("name", "") or ""),
        )
    except (TypeError, ValueError) as exc:
        raise FileFormatError(f"{where}: invalid channel record {d!r} ({exc})") from None


def _jsonable(obj: Any, key: str) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v, f"{key}.{k}") for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v, key) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist(), key)
    if isinstance(obj, np.generic):
        return _jsonable(obj.item(), key)
    if obj is None or isinstance(obj, bool | int | str):
        return obj
    if isinstance(obj, float):
        if not math.isfinite(obj):
            return repr(obj)
        return obj
    raise InputError(
        f"meta[{key!r}]: expected JSON-compatible values (numbers, strings, lists, dicts) to "
        f"store in a file, got {type(obj).__name__}"
    )


def meta_to_json(meta: dict[str, Any], compact: bool = True) -> str:
    """JSON of a metadata dict (one line); raises InputError for unsupported values."""
    return json.dumps(
        {str(k): _jsonable(v, str(k)) for k, v in meta.items()},
        separators=(",", ":") if compact else (", ", ": "),
    )


def meta_from_json(text: str, where: str) -> dict[str, Any]:
    """Inverse of :func:`meta_to_json`."""
    try:
        out = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FileFormatError(f"{where}: invalid JSON ({exc})") from None
    except RecursionError:
        raise FileFormatError(f"{where}: JSON nested too deeply") from None
    except ValueError as exc:  # for example an integer of more than 4300 digits
        raise FileFormatError(f"{where}: invalid JSON ({exc})") from None
    if not isinstance(out, dict):
        raise FileFormatError(f"{where}: expected a JSON object, got {type(out).__name__}")
    return out


@contextlib.contextmanager
def wrap_errors(path: Path) -> Iterator[None]:
    """Turn data errors raised while building an object from a file into FileFormatError.

    :class:`TyredampError` other than FileFormatError (for example a NaN
    sample, a decreasing frequency axis) get the file name prepended; type
    errors from content of the wrong type become FileFormatError too.
    """
    try:
        yield
    except FileFormatError:
        raise
    except TyredampError as exc:
        if str(exc).startswith(f"{path}:"):
            raise  # names the file already (a channel map that disagrees with it)
        raise FileFormatError(f"{path}: {exc}") from exc
    except (TypeError, ValueError, KeyError, IndexError, AttributeError, OverflowError) as exc:
        # content of the wrong type somewhere in the file: still the file's fault
        raise FileFormatError(f"{path}: invalid content ({type(exc).__name__}: {exc})") from exc
