"""Two independent readers of ``.tir`` files that a merged file must satisfy (for tests).

* :func:`tyredyn_problems` restates the validation rules of TyreDyn's
  ``tyredyn/io/tir_validation.py`` (N. van Rossem, TU Delft, version 1.1,
  2026; not on PyPI): every section of its ``TIRValidation`` model present,
  the required keys of each section for the file's FITTYP (MF5.2, MF6.1,
  MF6.2; here the in-plane and structural sections and the ranges), numbers
  where it expects numbers, ``[UNITS]`` with LENGTH, FORCE, ANGLE, MASS,
  TIME and ``[MODEL]`` with FITTYP, TYRESIDE, LONGVL, VXLOW.
* :func:`mfeval_style_read` reads as MFeval's ``readTIR`` does: every
  ``KEY = value`` line into one flat dictionary, whatever its section (but
  ``[UNITS]``, whose names MASS, LENGTH... are not parameters), the value up
  to the first ``$``; and it is strict where MFeval is lenient: a
  key given twice with different values is an error, and
  :func:`mfeval_required` names the keys it would otherwise fill with
  defaults.
"""

from __future__ import annotations

import re
from typing import Any

_SECTIONS = (
    "UNITS",
    "MODEL",
    "DIMENSION",
    "OPERATING_CONDITIONS",
    "INERTIA",
    "VERTICAL",
    "STRUCTURAL",
    "CONTACT_PATCH",
    "INFLATION_PRESSURE_RANGE",
    "VERTICAL_FORCE_RANGE",
    "LONG_SLIP_RANGE",
    "SLIP_ANGLE_RANGE",
    "INCLINATION_ANGLE_RANGE",
    "SCALING_COEFFICIENTS",
    "LONGITUDINAL_COEFFICIENTS",
    "OVERTURNING_COEFFICIENTS",
    "LATERAL_COEFFICIENTS",
    "ROLLING_COEFFICIENTS",
    "ALIGNING_COEFFICIENTS",
    "TURNSLIP_COEFFICIENTS",
)
_ANY = {
    "UNITS": {"LENGTH", "FORCE", "ANGLE", "MASS", "TIME"},
    "MODEL": {"FITTYP", "TYRESIDE", "LONGVL", "VXLOW"},
    "DIMENSION": {"UNLOADED_RADIUS", "WIDTH", "RIM_RADIUS", "RIM_WIDTH", "ASPECT_RATIO"},
    "VERTICAL_FORCE_RANGE": {"FZMIN", "FZMAX"},
    "LONG_SLIP_RANGE": {"KPUMIN", "KPUMAX"},
    "SLIP_ANGLE_RANGE": {"ALPMIN", "ALPMAX"},
    "INCLINATION_ANGLE_RANGE": {"CAMMIN", "CAMMAX"},
}
_MF6 = {
    "OPERATING_CONDITIONS": {"INFLPRES", "NOMPRES"},
    "INERTIA": {"MASS", "IXX", "IYY"},
    "STRUCTURAL": {
        "LONGITUDINAL_STIFFNESS",
        "LATERAL_STIFFNESS",
        "YAW_STIFFNESS",
        "DAMP_RESIDUAL",
        "DAMP_VLOW",
        "PCFX1",
        "PCFX2",
        "PCFX3",
        "PCFY1",
        "PCFY2",
        "PCFY3",
        "PCMZ1",
    },
    "INFLATION_PRESSURE_RANGE": {"PRESMIN", "PRESMAX"},
    "VERTICAL": {"FNOMIN", "VERTICAL_STIFFNESS", "VERTICAL_DAMPING", "BREFF", "DREFF", "FREFF"},
}
_MF52 = {"VERTICAL": {"FNOMIN", "VERTICAL_STIFFNESS", "VERTICAL_DAMPING", "BREFF", "DREFF"}}
_STRING_OK = {"UNITS", "MODEL"}


def _fittyp(doc: dict[str, dict[str, Any]]) -> str:
    f = str(doc.get("MODEL", {}).get("FITTYP", "")).replace(".0", "")
    return {"52": "MF5.2", "61": "MF6.1", "62": "MF6.2"}.get(f, "UNKNOWN")


def tyredyn_problems(doc: dict[str, dict[str, Any]]) -> set[str]:
    """What TyreDyn's validator would reject in a parsed file (module docstring)."""
    out: set[str] = set()
    model = _fittyp(doc)
    if model == "UNKNOWN":
        out.add("FITTYP not MF5.2, MF6.1 or MF6.2")
    rules = _MF6 if model in ("MF6.1", "MF6.2") else _MF52
    for sec in _SECTIONS:
        if sec not in doc:
            out.add(f"[{sec}] missing")
            continue
        for key in _ANY.get(sec, set()) | rules.get(sec, set()):
            if key not in doc[sec]:
                out.add(f"[{sec}] {key} missing")
        if sec not in _STRING_OK:
            for key, v in doc[sec].items():
                if not key.startswith("_") and not isinstance(v, float):
                    out.add(f"[{sec}] {key} not a number")
    return out


_LINE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^$!]*)")


def mfeval_style_read(text: str) -> dict[str, Any]:
    """Every ``KEY = value`` line into one flat dictionary (module docstring).

    Raises
    ------
    ValueError
        A key given twice with different values.
    """
    out: dict[str, Any] = {}
    units = False
    for line in text.splitlines():
        if line.strip().startswith("["):
            units = line.strip().upper().startswith("[UNITS]")
        m = _LINE.match(line)
        if not m or units:
            continue
        raw = m.group(2).strip()
        try:
            v: Any = float(raw)
        except ValueError:
            v = raw.strip("'\"")
        if m.group(1) in out and out[m.group(1)] != v:
            raise ValueError(f"{m.group(1)} given twice: {out[m.group(1)]!r} and {v!r}")
        out[m.group(1)] = v
    return out


#: Keys MFeval's MF 6.1/6.2 evaluation needs for the rigid-ring in-plane model and pressure.
MFEVAL_IN_PLANE = ("NOMPRES", "INFLPRES", "BELT_MASS", "FREQ_LONG", "DAMP_LONG", "FNOMIN")


def mfeval_required(flat: dict[str, Any]) -> list[str]:
    """The in-plane keys MFeval would fill with defaults because the file lacks them."""
    return [k for k in MFEVAL_IN_PLANE if not isinstance(flat.get(k), float)]
