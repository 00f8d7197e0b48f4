"""The modes JSON file written by ``tyredamp modal`` and read by the damping step.

Schema (all frequencies in Hz, complex numbers as ``[re, im]``)::

    {
      "tyredamp_version": "0.1.0",
      "kind": "modes", "version": 1,        # files before version 1 had no "version"
      "source": "tyre.uff",                 # name of the FRF file (or "")
      "band_hz": [f_lo, f_hi],              # analysis band
      "frf_kind": "accelerance",            # kind of the fitted FRFs
      "models": {
        "complex": {                        # and/or "real"
          ...ModalModel.to_dict()...,       # mode_kind, outputs, inputs, modes, residuals,
                                            # meta, residual_modes
          "shapes_at": "outputs" | "inputs",  # where the mode shapes are ("inputs": roving
                                            # hammer, the shapes are the participations)
          "scaled": bool, "scaling_note": str | None,  # mass-normalised or not, and why not
          "rmsd": float,                    # spec eq. [19], unit of the FRF kind
          "relative_error": float           # RMS(H_model - H) / RMS(H), dimensionless
        }
      }
    }

Each entry of ``modes`` (see :meth:`ModalModel.to_dict`) holds
``frequency_hz``, ``damping_ratio``, ``pole`` (rad/s), ``shape`` (one
``[re, im]`` per output in the eq. [10] scaling ``psi = Psi / sqrt(a)``,
units 1/sqrt(kg/s); real modes are ``phi / sqrt(2 i Omega)``),
``participation`` (the same at the inputs) and ``std`` with the standard
errors ``frequency_hz``, ``damping_ratio`` and ``shape`` (per output, the
magnitude ``sqrt(E|d psi|^2)`` of the complex error). ``outputs`` and
``inputs`` label the rows (node, direction, angle_deg, name). The
human-readable description is ``docs/modes-json.md``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from .. import __version__
from ..exceptions import FileFormatError, InputError
from ..io import FILE_FORMATS
from ..modal.model import ModalModel
from .jsonfile import read_json, write_json

__all__ = [
    "MODES_KIND",
    "MODES_VERSION",
    "models_from_document",
    "modes_document",
    "read_modes",
    "read_modes_json",
    "write_modes_json",
]

MODES_KIND = "modes"
MODES_VERSION = 1

_KINDS = ("complex", "real")


def modes_document(
    models: dict[str, ModalModel],
    *,
    source: str = "",
    band_hz: tuple[float, float] | None = None,
    frf_kind: str | None = None,
) -> dict[str, Any]:
    """Build the JSON-ready modes document (schema in the module docstring).

    Parameters
    ----------
    models : dict of str to ModalModel
        Keys ``"complex"`` and/or ``"real"``. ``rmsd`` and ``relative_error``
        are taken from each model's ``meta`` (NaN when absent).
    source : str
        Name of the FRF file the modes came from.
    band_hz : (float, float), optional
        Analysis band; default from the first model's ``meta["band_hz"]``.
    frf_kind : str, optional
        FRF kind; default from the first model's ``meta["frf_kind"]``.
    """
    if not models:
        raise InputError("models: expected at least one modal model")
    out: dict[str, Any] = {}
    first = next(iter(models.values()))
    for key, mdl in models.items():
        if key not in _KINDS:
            raise InputError(f"models: expected keys in {_KINDS}, got {key!r}")
        if not isinstance(mdl, ModalModel):
            raise InputError(f"models[{key!r}]: expected a ModalModel, got {type(mdl).__name__}")
        d = mdl.to_dict()
        d.update(_shape_facts(mdl))
        d["rmsd"] = float(mdl.meta.get("rmsd", float("nan")))
        d["relative_error"] = float(mdl.meta.get("relative_error", float("nan")))
        out[key] = d
    band = band_hz if band_hz is not None else first.meta.get("band_hz")
    return {
        "tyredamp_version": __version__,
        "kind": MODES_KIND,
        "version": MODES_VERSION,
        "source": str(source),
        "band_hz": None if band is None else [float(band[0]), float(band[1])],
        "frf_kind": frf_kind if frf_kind is not None else first.meta.get("frf_kind"),
        "models": out,
    }


def _shape_facts(mdl: ModalModel) -> dict[str, Any]:
    """Where the shapes are and whether they are scaled (:mod:`tyredamp.damping.modeset`)."""
    from ..damping.modeset import scaling_problem, shape_side

    why = scaling_problem(mdl)
    return {"shapes_at": shape_side(mdl), "scaled": not why, "scaling_note": why or None}


def write_modes_json(
    path: str | os.PathLike[str],
    models: dict[str, ModalModel],
    *,
    source: str = "",
    band_hz: tuple[float, float] | None = None,
    frf_kind: str | None = None,
) -> Path:
    """Write the modes JSON atomically (no partial file on error); returns the path."""
    doc = modes_document(models, source=source, band_hz=band_hz, frf_kind=frf_kind)
    return write_json(doc, path)


def read_modes_json(path: str | os.PathLike[str]) -> dict[str, ModalModel]:
    """Read a modes JSON file into ``{"complex": ModalModel, "real": ModalModel}`` (those present).

    ``rmsd`` and ``relative_error`` of each model are put back into its
    ``meta`` (they are in ``meta`` already when the file was written by
    tyredamp).

    Raises
    ------
    FileFormatError
        Not JSON, not a ``"kind": "modes"`` document, or a malformed model.
    """
    p = Path(path)
    try:
        return models_from_document(read_json(p))
    except FileFormatError as exc:
        msg = str(exc)
        raise FileFormatError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None


def read_modes(path: str | os.PathLike[str]) -> dict[str, ModalModel]:
    """Modes from a modes JSON file or a UFF file of data sets 55 (another program's modes).

    A UFF file (``.uff``, ``.unv``, ``.uf``) is read by
    :func:`tyredamp.io.uff55.read_uff55` (real or complex modes, scaled by
    their modal mass or modal A) into ``{mode_kind: ModalModel}``; anything
    else by :func:`read_modes_json`.

    Raises
    ------
    FileFormatError
        Not a modes JSON, or a UFF file without (or with malformed) data sets 55.
    """
    p = Path(path)
    if p.suffix.lower() in FILE_FORMATS["uff58b"].extensions:
        from ..io.uff55 import read_uff55

        model = read_uff55(p)
        return {model.mode_kind: model}
    if p.suffix.lower() in ("", ".json"):
        return read_modes_json(p)
    try:
        return read_modes_json(p)
    except FileFormatError as exc:  # say what a modes file is (a .tir, a .csv given by mistake)
        raise FileFormatError(
            f"{exc}; modes come from a modes JSON (tyredamp modal --out) or a UFF file of "
            f"data sets 55, not a '{p.suffix}' file"
        ) from None


def models_from_document(doc: dict[str, Any]) -> dict[str, ModalModel]:
    """The models of a parsed modes document (see :func:`read_modes_json`)."""
    if doc.get("kind") != MODES_KIND:
        raise FileFormatError('expected a modes document with "kind": "modes"')
    models = doc.get("models")
    if not isinstance(models, dict) or not models:
        raise FileFormatError('expected a non-empty "models" object')
    out: dict[str, ModalModel] = {}
    for key, d in models.items():
        if key not in _KINDS or not isinstance(d, dict):
            raise FileFormatError(f"models: unexpected entry {key!r}")
        try:
            mdl = ModalModel.from_dict(d)
        except (InputError, TypeError, ValueError, KeyError) as exc:
            raise FileFormatError(f"models[{key!r}]: {exc}") from None
        for extra in ("rmsd", "relative_error"):
            if extra in d and extra not in mdl.meta:
                mdl.meta[extra] = d[extra]
        out[key] = mdl
    return out
