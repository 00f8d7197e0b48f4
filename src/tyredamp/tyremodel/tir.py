"""The in-plane subset of an MF-Swift ``.tir`` property file: writer and reader.

A ``.tir`` file (MSC ADAMS tyre property file, used by MF-Tyre/MF-Swift) is
INI-like: ``[SECTION]`` headers, ``KEY = value`` lines, strings in single
quotes, ``$`` starting a comment (also after a value) and ``!`` starting a
comment line. Units follow the ``[UNITS]`` section, written here as SI
(meter, newton, kg, second, radians), so frequencies are in Hz and damping
ratios dimensionless, as MF-Swift defines ``FREQ_*`` and ``DAMP_*``.

:func:`tir_text` writes only the fields a radial in-plane modal test gives
(``[INERTIA] BELT_MASS``, ``[STRUCTURAL] FREQ_LONG, DAMP_LONG``, the
pressure in ``[OPERATING_CONDITIONS] INFLPRES``) and lists every other
in-plane or structural field it cannot give in ``$`` comments with the
reason; derived quantities (belt stiffness and damping, lateral carcass
values) appear as comments too, since they are not ``.tir`` keys.
:func:`parse_tir` reads such a file (or any ``.tir``) back into nested
dictionaries.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from .. import __version__
from ..exceptions import FileFormatError
from .rigid import RigidRingParameters

__all__ = ["parse_tir", "tir_text"]

_SECTION = re.compile(r"^\[([A-Za-z0-9_]+)\]$")
_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.*)$")


def _fmt(x: float) -> str:
    return f"{x:.10g}"


def tir_text(
    rigid: RigidRingParameters,
    *,
    source: str = "",
    extra_comments: Sequence[str] = (),
) -> str:
    """The in-plane ``.tir`` subset of one pressure as text.

    Parameters
    ----------
    rigid : RigidRingParameters
        From :func:`~tyredamp.tyremodel.rigid_ring_from_modes`.
    source : str
        Where the modes came from (a comment).
    extra_comments : sequence of str
        More comment lines (for example the lateral carcass quantities).

    Returns
    -------
    str
        The file text (ends with a newline).
    """
    lines = [
        "[MDI_HEADER]",
        "FILE_TYPE = 'tir'",
        "FILE_VERSION = 3.0",
        "FILE_FORMAT = 'ASCII'",
        f"$ In-plane subset written by tyredamp {__version__} from a radial modal test.",
    ]
    if source:
        lines.append(f"$ source: {source}")
    lines.append("$ Only fields the test gives are set; the others are listed as comments.")
    lines += [
        "[UNITS]",
        "LENGTH = 'meter'",
        "FORCE = 'newton'",
        "ANGLE = 'radians'",
        "MASS = 'kg'",
        "TIME = 'second'",
    ]
    if rigid.pressure is not None:
        lines += [
            "[OPERATING_CONDITIONS]",
            f"INFLPRES = {_fmt(rigid.pressure)}  $ inflation pressure of the test (Pa)",
        ]
    ng = rigid.not_given
    lines += [
        "[INERTIA]",
        f"BELT_MASS = {_fmt(rigid.belt_mass)}  $ belt mass from the n = 1 mode shape "
        f"(+- {rigid.belt_mass_std:.3g} kg)",
    ]
    for key in ("MASS", "IXX", "IYY", "BELT_IXX", "BELT_IYY"):
        lines.append(f"$ {key}: not given by this test ({ng.get(key, 'not measured')})")
    if rigid.thin_ring_iyy is not None:
        lines.append(
            f"$   (thin-ring assumption m_b R^2 = {rigid.thin_ring_iyy:.5g} kg m^2, not measured)"
        )
    lines += [
        "[STRUCTURAL]",
        f"FREQ_LONG = {_fmt(rigid.freq_long)}  $ n = 1 belt translation, Hz "
        f"(+- {rigid.freq_long_std:.3g})",
        f"DAMP_LONG = {_fmt(rigid.damp_long)}  $ its damping ratio (+- {rigid.damp_long_std:.3g})",
    ]
    for key in (
        "FREQ_WINDUP",
        "DAMP_WINDUP",
        "FREQ_LAT",
        "DAMP_LAT",
        "FREQ_YAW",
        "DAMP_YAW",
        "LONGITUDINAL_STIFFNESS",
        "LATERAL_STIFFNESS",
        "YAW_STIFFNESS",
    ):
        lines.append(f"$ {key}: not given by this test ({ng.get(key, 'not measured')})")
    lines.append(
        f"$ derived (not .tir keys): belt translational stiffness m_b omega^2 = "
        f"{rigid.k_long:.6g} +- {rigid.k_long_std:.3g} N/m, damping 2 zeta m_b omega = "
        f"{rigid.c_long:.6g} +- {rigid.c_long_std:.3g} N s/m"
    )
    for c in extra_comments:
        lines.append(f"$ {c}")
    return "\n".join(lines) + "\n"


def _value(raw: str, lineno: int) -> Any:
    s = raw.strip()
    if s.startswith("'"):
        end = s.find("'", 1)
        if end < 0:
            raise FileFormatError(f".tir line {lineno}: unterminated string {s!r}")
        return s[1:end]
    s = s.split("$", 1)[0].strip()
    if not s:
        raise FileFormatError(f".tir line {lineno}: missing value")
    try:
        return float(s)
    except ValueError:
        return s


def _table_row(line: str) -> list[float] | None:
    """A row of numbers (a list), a ``{column names}`` line (empty list), else None."""
    if line.startswith("{") and line.endswith("}"):
        return []
    try:
        return [float(x) for x in line.split()] or None
    except ValueError:
        return None


def parse_tir(text: str) -> dict[str, dict[str, Any]]:
    """Read ``.tir`` text into ``{section: {key: value}}`` (numbers as float).

    Comments (``$`` anywhere outside a quoted string, lines starting with
    ``!``) and blank lines are skipped; keys are kept as written. A table
    section (``[SHAPE]``: a ``{radial width}`` line, then rows of numbers)
    gives its rows as ``"_rows"`` (lists of floats) and its column names as
    ``"_columns"``.

    Raises
    ------
    FileFormatError
        A key before the first section, a line that is neither a section,
        a ``KEY = value`` line, a table row nor a comment, a key repeated in
        a section.
    """
    out: dict[str, dict[str, Any]] = {}
    current: str | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("$") or line.startswith("!"):
            continue
        m = _SECTION.match(line.split("$", 1)[0].strip())
        if m:
            current = m.group(1)
            out.setdefault(current, {})
            continue
        k = _KEY.match(line)
        table = _table_row(line.split("$", 1)[0].strip())
        if not k and current is not None and table is not None:
            # a table section ([SHAPE]: "{radial width}" then rows of numbers)
            if table:
                out[current].setdefault("_rows", []).append(table)
            else:
                out[current]["_columns"] = line.strip("{} ").split()
            continue
        if not k:
            raise FileFormatError(
                f".tir line {lineno}: expected [SECTION] or KEY = value, got {line!r}"
            )
        if current is None:
            raise FileFormatError(f".tir line {lineno}: key {k.group(1)!r} before any [SECTION]")
        key = k.group(1)
        if key in out[current]:
            raise FileFormatError(f".tir line {lineno}: key {key!r} repeated in [{current}]")
        out[current][key] = _value(k.group(2), lineno)
    if not out:
        raise FileFormatError(".tir: no [SECTION] found")
    return out
