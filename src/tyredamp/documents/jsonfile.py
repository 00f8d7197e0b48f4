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

from ..io._atomic import atomic_path

__all__ = ["finite", "json_text", "write_json"]


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
