"""The lateral-fit JSON file written by ``tyredamp lateral fit``.

Layout (``"kind": "lateral-fit"``, ``"version": 1``; SI units; non-finite
numbers as ``null``; files written before the ``"kind"`` key carry only
``"tyredamp": "lateral-fit"``, which is still written and read)::

    {
      "tyredamp": "lateral-fit", "kind": "lateral-fit", "version": 1,
      "input": {"file": str, "kind": str, "n_lines": int, "band_hz": [lo, hi]},
      "conditions": {"speed_m_s": float|null, "speed_kmh": float|null,
                     "force": "ground"|"axle", "wheel_mass_kg": float,
                     "pressure_bar": float|null (from the FRF's meta)},
      "criterion": "bic"|"aic",
      "order": [model names, best first],
      "table": [{"rank", "model", "n_params", "rss", "aic", "bic", "delta",
                 "weight", "amplitude_error_pct", "amplitude_bias_pct"}, ...],
      "reasons": [one sentence per model],
      "fits": [{"model", "label", "params": {name: value}, "stderr": {name: value},
                "units": {name: unit}, "conditions": {...}, "derived": {...},
                "n_params", "n_lines", "rss", "residual_rms", "aic", "bic",
                "amplitude_error", "amplitude_bias", "weights", "force",
                "wheel_mass_kg", "speed_m_s", "message", "at_bound"}, ...],
      "problems": {model name: [one sentence per problem of that fit]}
    }

``amplitude_error`` is the paper's Table 1 figure as defined in
:mod:`tyredamp.lateral.fit`: the mean over the fitted lines of
``| |A_model| - |A_meas| | / |A_meas|`` (a fraction; the table shows %), and
``amplitude_bias`` its signed version (positive: over-estimation).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError
from ..lateral.fit import LateralData
from ..lateral.ranking import Ranking
from ..virtual.lateral_rig import KMH
from .jsonfile import read_json, write_json

__all__ = [
    "LATERAL_FIT_KIND",
    "LATERAL_FIT_VERSION",
    "lateral_fit_document",
    "lateral_fit_from_document",
    "read_lateral_fit",
    "write_lateral_fit",
]

LATERAL_FIT_KIND = "lateral-fit"
LATERAL_FIT_VERSION = 1


def lateral_fit_document(
    ranking: Ranking, data: LateralData, *, source: str = "", frf_kind: str | None = None
) -> dict[str, Any]:
    """The JSON-ready lateral-fit document (layout in the module docstring).

    Parameters
    ----------
    ranking : Ranking
        Every model fitted to ``data``, best first.
    data : LateralData
        The measurement (its conditions are written).
    source : str
        Name of the FRF file.
    frf_kind : str, optional
        Kind of the measured FRF; default that of ``data``.
    """
    best = ranking.best
    return {
        "tyredamp": LATERAL_FIT_KIND,
        "kind": LATERAL_FIT_KIND,
        "version": LATERAL_FIT_VERSION,
        "input": {
            "file": str(source),
            "kind": data.frf.kind if frf_kind is None else frf_kind,
            "n_lines": best.n_lines,
            "band_hz": [float(best.frequency[0]), float(best.frequency[-1])],
        },
        "conditions": {
            "speed_m_s": data.speed,
            "speed_kmh": None if data.speed is None else data.speed / KMH,
            "force": data.force,
            "wheel_mass_kg": data.wheel_mass,
            "pressure_bar": data.frf.meta.get("pressure_bar"),
        },
        **ranking.to_dict(),
        "problems": {f.name: f.problems() for f in ranking.fits},
    }


def lateral_fit_from_document(doc: dict[str, Any]) -> dict[str, Any]:
    """Check a parsed lateral-fit document and return it (a plain ``dict``)."""
    if LATERAL_FIT_KIND not in (doc.get("kind"), doc.get("tyredamp")):
        raise FileFormatError('expected a lateral-fit document with "kind": "lateral-fit"')
    for key in ("table", "fits", "conditions"):
        if key not in doc:
            raise FileFormatError(f"missing key {key!r}")
    return doc


def write_lateral_fit(
    path: str | os.PathLike[str],
    ranking: Ranking,
    data: LateralData,
    *,
    source: str = "",
    frf_kind: str | None = None,
) -> Path:
    """Write the lateral-fit JSON atomically (no partial file on error); returns the path."""
    doc = lateral_fit_document(ranking, data, source=source, frf_kind=frf_kind)
    return write_json(doc, path, indent=2)


def read_lateral_fit(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a lateral-fit JSON file (checked, as a ``dict``).

    Raises
    ------
    FileFormatError
        Not strict JSON or not a lateral-fit document.
    """
    p = Path(path)
    try:
        return lateral_fit_from_document(read_json(p))
    except FileFormatError as exc:
        msg = str(exc)
        raise FileFormatError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
