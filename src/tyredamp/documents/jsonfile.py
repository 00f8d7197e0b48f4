"""Strict JSON: the one reader and writer of every result document.

The policy, for every document tyredamp writes:

* **non-finite numbers** (NaN, +-inf) have no JSON spelling; they are written
  as ``null`` so that any JSON reader (not only Python's) accepts the files,
  and the reader refuses the non-standard tokens ``NaN``/``Infinity``;
* **complex numbers** are written as a two-element list ``[re, im]`` (each
  part under the rule above); readers turn them back where they expect one;
* NumPy scalars and arrays become plain JSON numbers and (nested) lists;
  mapping keys become strings.

The document layouts themselves are described with each kind
(:mod:`tyredamp.documents`).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError
from ..io._atomic import atomic_path

__all__ = ["finite", "json_text", "loads_json", "read_json", "write_json"]


def finite(obj: Any) -> Any:
    """Copy of ``obj`` under the module's policy (NaN/inf as ``None``, complex as ``[re, im]``)."""
    if isinstance(obj, dict):
        return {str(k): finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite(obj.tolist())
    if isinstance(obj, np.generic):
        return finite(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, complex):
        return [finite(obj.real), finite(obj.imag)]
    return obj


def json_text(obj: Any, indent: int = 1) -> str:
    """Strict JSON text of ``obj`` (see :func:`finite`), ending in a newline."""
    return json.dumps(finite(obj), indent=indent, allow_nan=False) + "\n"


def write_json(obj: Any, path: str | os.PathLike[str], indent: int = 1) -> Path:
    """Write ``obj`` as strict JSON atomically (no partial file on error); returns the path."""
    target = Path(path)
    text = json_text(obj, indent)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return target


def _refuse_constant(name: str) -> Any:
    raise ValueError(f"non-standard JSON number {name}")


def loads_json(text: str, where: str | os.PathLike[str]) -> Any:
    """Parse strict-JSON text read from ``where``; every failure is a :class:`FileFormatError`.

    Empty text, invalid JSON, the non-standard ``NaN``/``Infinity``, an integer
    beyond Python's digit limit and nesting too deep for the parser (a hostile
    file of 100 000 brackets) are named with ``where``.
    """
    name = os.fspath(where)
    if not text.strip():
        raise FileFormatError(f"{name}: the file is empty")
    try:
        return json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise FileFormatError(f"{name}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except RecursionError:
        raise FileFormatError(f"{name}: JSON nested too deeply") from None
    except ValueError as exc:  # NaN/Infinity, or an integer of more than 4300 digits
        raise FileFormatError(f"{name}: not strict JSON ({exc})") from None


def read_json(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a strict-JSON object (a result document) from ``path``.

    Raises
    ------
    FileFormatError
        Not a text file, empty, not valid JSON (including the non-standard
        ``NaN``/``Infinity``, integers beyond Python's digit limit and nesting
        too deep for the parser), or not a JSON object at the top level.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise FileFormatError(f"{p}: not a text (JSON) file") from None
    doc = loads_json(text, p)
    if not isinstance(doc, dict):
        raise FileFormatError(f"{p}: expected a JSON object, got {type(doc).__name__}")
    return doc
