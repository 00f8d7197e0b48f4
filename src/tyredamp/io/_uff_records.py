"""The UFF 58 record conventions tyredamp's reader and writer share.

What the data set fields mean to tyredamp (the layout is described in
:mod:`tyredamp.io.uff`): the specific data types of records 8-10 and the
quantities, SI units labels and units exponents they stand for; the channel
name and angle on ID lines 4 and 5; the metadata on ID lines 3 and 5 (keys the
estimators use first, evenly spaced runs in short form); the exact frequency
axis or sample rate as ``tyredamp1`` tokens on ID line 2.
"""

from __future__ import annotations

import itertools
import json
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..frf import Channel, FRFKind
from ._common import meta_to_json

_MARK = "tyredamp1"
# specific data types (record 8): 15 pressure, 21 sound pressure, 1 general (volts)
_SDT = {
    "displacement": 8,
    "velocity": 11,
    "acceleration": 12,
    "force": 13,
    "pressure": 15,
    "voltage": 1,
}
_SDT_QUANTITY = {
    8: "displacement",
    11: "velocity",
    12: "acceleration",
    13: "force",
    9: "force",
    15: "pressure",
    21: "pressure",
}
_KIND_QUANTITY = {
    "receptance": "displacement",
    "mobility": "velocity",
    "accelerance": "acceleration",
}
_QUANTITY_KIND: dict[str, FRFKind] = {v: k for k, v in _KIND_QUANTITY.items()}  # type: ignore[misc]
_SI_LABEL = {
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "force": "N",
    "pressure": "Pa",
    "voltage": "V",
}
_AXIS_LABEL = {
    "displacement": "Displacement",
    "velocity": "Velocity",
    "acceleration": "Acceleration",
    "force": "Force",
    "pressure": "Pressure",
    "voltage": "Voltage",
}
# (length exponent, force exponent) of each quantity in SI
_EXP = {
    "displacement": (1, 0),
    "velocity": (1, 0),
    "acceleration": (1, 0),
    "force": (0, 1),
    "pressure": (-2, 1),
    "voltage": (0, 0),
}


# ------------------------------------------------------------------ channels
def _extras_line(c: Channel) -> str:
    d: dict[str, Any] = {}
    if c.name:
        d["name"] = c.name
    if c.angle_deg is not None:
        d["angle_deg"] = float(c.angle_deg)
    if not d:
        return "NONE"
    text = json.dumps(d, separators=(",", ":"), ensure_ascii=True)
    if len(text) > 80:
        raise InputError(
            f"channel {c.label!r}: name and angle need {len(text)} characters, an UFF ID line "
            "holds 80; shorten the name or write CSV/NPZ"
        )
    return text


def _extras(line: Any) -> dict[str, Any]:
    text = str(line or "").strip()
    if not text.startswith("{"):
        return {}
    try:
        d = json.loads(text)
    except (json.JSONDecodeError, RecursionError):
        return {}
    return d if isinstance(d, dict) else {}


# ------------------------------------------------------------------ metadata
#: Metadata the estimators use: stored first when ``meta`` does not fit an ID line.
_PRIORITY = (
    "period_samples",
    "settle_samples",
    "record_samples",
    "run_starts",
    "band_hz",
    "n_averages",
    "excitation",
    "estimator",
    "method",
    "n_averages",
    "exponential_tau_s",
    # operating conditions of a lateral rig FRF, readable in the ID lines by other programs
    "speed_m_s",
    "force",
    "wheel_mass_kg",
    "pressure_bar",
    "description",
)


def _meta_lines(meta: dict[str, Any], n_lines: int) -> list[str]:
    """Up to ``n_lines`` JSON objects of <= 80 characters holding as much of ``meta`` as fits.

    Keys the estimators use go first; a key whose value alone needs more than
    80 characters is left out.
    """
    order = [k for k in _PRIORITY if k in meta] + [k for k in meta if k not in _PRIORITY]
    lines: list[str] = []
    left = order
    for _ in range(n_lines):
        kept: dict[str, Any] = {}
        rest = []
        for k in left:
            trial = {**kept, k: meta[k]}
            if len(meta_to_json(trial)) <= 80:
                kept = trial
            else:
                rest.append(k)
        lines.append(meta_to_json(kept) if kept else "NONE")
        left = rest
    return lines


def _meta_fits(meta: dict[str, Any], lines: list[str]) -> bool:
    """True when the ID ``lines`` written by :func:`_meta_lines` hold every key of ``meta``."""
    kept: dict[str, Any] = {}
    for line in lines:
        kept.update(_extras(line))
    return all(k in kept for k in meta)


def _compact_acquisition(acq: dict[str, Any]) -> dict[str, Any]:
    """Evenly spaced ``run_starts`` as ``run_every`` (fits an ID line for many runs)."""
    runs = acq.get("run_starts")
    if runs is not None and len(runs) > 2:
        step = runs[1] - runs[0]
        if all(b - a == step for a, b in itertools.pairwise(runs)):
            acq = {k: v for k, v in acq.items() if k != "run_starts"}
            acq["run_every"] = [int(step), len(runs)]
    return acq


# ------------------------------------------------------------------ ID line 2
def _even_axis(f: np.ndarray) -> str | None:
    """ID-line tokens that rebuild ``f`` (bit for bit where possible), None if uneven."""
    n = f.size
    if n == 1:
        return f"f0={float(f[0])!r} df=1.0"
    d0 = (f[-1] - f[0]) / (n - 1)
    if d0 <= 0 or np.max(np.abs(f[0] + d0 * np.arange(n) - f)) > 1e-9 * d0:
        return None
    k0 = round(f[0] / d0)
    if abs(f[0] / d0 - k0) < 1e-6:
        for d in (f[-1] / (k0 + n - 1), d0, f[1] - f[0]):
            if np.array_equal((k0 + np.arange(n)) * d, f):
                return f"k0={k0} df={float(d)!r}"
    return f"f0={float(f[0])!r} df={float(d0)!r}"


def _rebuild_axis(tokens: dict[str, str], n: int) -> np.ndarray | None:
    try:
        df = float(tokens["df"])
        if "k0" in tokens:
            return (int(tokens["k0"]) + np.arange(n)) * df
        if "f0" in tokens:
            return float(tokens["f0"]) + df * np.arange(n)
    except (KeyError, ValueError):
        return None
    return None


def _tokens(s: dict[str, Any]) -> dict[str, str] | None:
    parts = str(s.get("id2", "")).split()
    if not parts or parts[0] != _MARK:
        return None
    out = {"_what": parts[1] if len(parts) > 1 else "", "_q": parts[2] if len(parts) > 2 else ""}
    for tok in parts[3:]:
        if "=" in tok:
            k, v = tok.split("=", 1)
            out[k] = v
    return out
