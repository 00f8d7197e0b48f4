"""The damping JSON file written by ``tyredamp damping`` (and the demo).

Layout (the envelope ``"kind": "damping"``, ``"version": 1`` around
:meth:`tyredamp.damping.DampingModel.to_dict`; full description in
``docs/damping-json.md``)::

    {"kind": "damping", "version": 1,
     "method": "first" | "improved" | "refined", "normalised": bool,
     "modes": {"frequency_hz": [m], "damping_ratio": [m], "poles": [[re, im]] x m},
     "points": [{"node", "direction", "angle_deg", "name"}] x N,
     "modal": m x m (C', 1/s), "modal_symmetric": m x m,
     "physical": N x N (C, N s/m), "physical_symmetric": N x N,
     "mass": N x N (kg), "stiffness": N x N (N/m), "basis": N x m (1/sqrt(kg)),
     "lancaster_physical": N x N | null,
     "std": {"modal": m x m, "physical": N x N} | {},
     "uncertainty": {"method": "monte_carlo", "n_samples", "n_failed", "seed"} | {},
     "diagnostics": {...}, "proportional": {...}, "findings": [str],
     "meta": {"source": path, "model": "complex" | "real", ...}}
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..damping import DampingModel
from ..exceptions import FileFormatError, InputError
from .jsonfile import read_json, write_json

__all__ = [
    "DAMPING_KIND",
    "DAMPING_VERSION",
    "damping_document",
    "damping_from_document",
    "read_damping_json",
    "write_damping_json",
]

DAMPING_KIND = "damping"
DAMPING_VERSION = 1


def damping_document(dm: DampingModel) -> dict[str, Any]:
    """The JSON-ready damping document of ``dm`` (layout in the module docstring)."""
    if not isinstance(dm, DampingModel):
        raise InputError(f"dm: expected a DampingModel, got {type(dm).__name__}")
    return {"kind": DAMPING_KIND, "version": DAMPING_VERSION, **dm.to_dict()}


def damping_from_document(doc: dict[str, Any]) -> DampingModel:
    """The :class:`DampingModel` of a parsed damping document."""
    try:
        return DampingModel.from_dict(doc)
    except InputError as exc:
        raise FileFormatError(str(exc)) from None


def write_damping_json(path: str | os.PathLike[str], dm: DampingModel) -> Path:
    """Write the damping JSON atomically (no partial file on error); returns the path."""
    return write_json(damping_document(dm), path)


def read_damping_json(path: str | os.PathLike[str]) -> DampingModel:
    """Read a damping JSON file.

    Raises
    ------
    FileFormatError
        Not strict JSON, not a damping document, or a malformed entry.
    """
    p = Path(path)
    try:
        return damping_from_document(read_json(p))
    except FileFormatError as exc:
        msg = str(exc)
        raise FileFormatError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
