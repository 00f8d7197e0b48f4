"""Strict JSON output shared by every command that writes a JSON file.

NaN and infinities have no JSON spelling; they are written as ``null`` so
that any JSON reader (not only Python's) accepts the files. NumPy scalars and
arrays become plain JSON numbers and lists.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import FileFormatError
from ._atomic import atomic_path

__all__ = ["finite", "json_text", "loads_json", "read_json", "write_json"]


def finite(obj: Any) -> Any:
    """Copy of ``obj`` with NumPy types as Python types and NaN/inf as ``None``."""
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


def loads_json(text: str, where: str | os.PathLike[str]) -> Any:
    """Parse JSON text read from ``where``; every failure is a :class:`FileFormatError`.

    Empty text, invalid JSON and nesting too deep for the parser (a hostile
    file of 100 000 brackets) are named with ``where``.
    """
    if not text.strip():
        raise FileFormatError(f"{os.fspath(where)}: the file is empty")
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise FileFormatError(
            f"{os.fspath(where)}: not valid JSON ({exc.msg} at line {exc.lineno})"
        ) from None
    except RecursionError:
        raise FileFormatError(f"{os.fspath(where)}: JSON nested too deeply") from None
    except ValueError as exc:  # for example an integer of more than 4300 digits
        raise FileFormatError(f"{os.fspath(where)}: not valid JSON ({exc})") from None


def read_json(path: str | os.PathLike[str]) -> Any:
    """Read a JSON file (UTF-8); every failure to parse is a :class:`FileFormatError`."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise FileFormatError(f"{p}: not a text (JSON) file") from None
    return loads_json(text, p)
