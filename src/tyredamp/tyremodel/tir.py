"""The in-plane fragment of an MF-Swift ``.tir`` property file (writer) and a ``.tir`` reader.

A ``.tir`` file (MSC ADAMS tyre property file, used by MF-Tyre/MF-Swift) is
INI-like: ``[SECTION]`` headers, ``KEY = value`` lines, strings in single
quotes, ``$`` starting a comment (also after a value) and ``!`` starting a
comment line. Units follow the ``[UNITS]`` section, written here as SI
(meter, newton, kg, second, radians), so frequencies are in Hz and damping
ratios dimensionless, as MF-Swift defines ``FREQ_*`` and ``DAMP_*``.

:func:`tir_text` writes only the fields a radial in-plane modal test gives
(``[INERTIA] BELT_MASS``, ``[STRUCTURAL] FREQ_LONG, DAMP_LONG``, the
pressure in ``[OPERATING_CONDITIONS] INFLPRES``; with a tangential test also
``[INERTIA] BELT_IYY`` and ``[STRUCTURAL] FREQ_WINDUP, DAMP_WINDUP``,
:mod:`.windup`) and lists every other
in-plane or structural field it cannot give in ``$`` comments with the
reason; derived quantities (belt stiffness and damping, lateral carcass
values) appear as comments too, since they are not ``.tir`` keys.
:func:`parse_tir` reads such a file (or any ``.tir``) back into nested
dictionaries.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from .. import __version__
from ..exceptions import FileFormatError
from .budget import UncertaintyBudget
from .rigid import RigidRingParameters
from .windup import WindupParameters

__all__ = ["TirLine", "decode_tir", "parse_tir", "scan_tir", "tir_text"]


def _fmt(x: float) -> str:
    return f"{x:.10g}"


def _windup_lines(
    windup: WindupParameters | None, budget: UncertaintyBudget | None, inertia: bool = False
) -> list[str]:
    """``BELT_IYY`` (``inertia``) or ``FREQ_WINDUP``, ``DAMP_WINDUP`` lines; none without."""
    if windup is None:
        return []

    def why(key: str, default: str) -> str:
        return budget.comment(key) if budget is not None else default

    if inertia:
        return [
            f"BELT_IYY = {_fmt(windup.belt_iyy)}  $ belt inertia from the n = 0 rotation shape, "
            + why("BELT_IYY", f"+- {windup.belt_iyy_std:.3g} kg m^2 (statistical only)")
        ]
    return [
        f"FREQ_WINDUP = {_fmt(windup.freq_windup)}  $ n = 0 belt rotation (tangential "
        "test), Hz, " + why("FREQ_WINDUP", f"+- {windup.freq_windup_std:.3g} (statistical only)"),
        f"DAMP_WINDUP = {_fmt(windup.damp_windup)}  $ its damping ratio, "
        + why("DAMP_WINDUP", f"+- {windup.damp_windup_std:.3g} (statistical only)"),
    ]


def tir_text(
    rigid: RigidRingParameters,
    *,
    source: str = "",
    extra_comments: Sequence[str] = (),
    budget: UncertaintyBudget | None = None,
    windup: WindupParameters | None = None,
) -> str:
    """The in-plane ``.tir`` fragment of one pressure as text.

    Headed as a fragment: no simulator can load it alone (it lacks
    ``[MODEL]``, ``[DIMENSION]``, ``[VERTICAL]``, ``NOMPRES``...); merge it
    into a complete file with :func:`~tyredamp.tyremodel.tirmerge.merge_tir`
    (``tyredamp tyre-model --merge-into BASE.tir``).

    Parameters
    ----------
    rigid : RigidRingParameters
        From :func:`~tyredamp.tyremodel.rigid_ring_from_modes`.
    source : str
        Where the modes came from (a comment).
    extra_comments : sequence of str
        More comment lines (for example the lateral carcass quantities).
    budget : UncertaintyBudget, optional
        The values' uncertainty budgets and assumptions (written beside
        them); without it the statistical standard errors only.
    windup : WindupParameters, optional
        The wind-up from a tangential test at the same pressure
        (:func:`~tyredamp.tyremodel.windup.windup_from_modes`): writes
        ``BELT_IYY``, ``FREQ_WINDUP`` and ``DAMP_WINDUP``.

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
        "$ FRAGMENT -- not a complete tyre property file: it lacks [MODEL], [DIMENSION],",
        "$ [VERTICAL], NOMPRES and the Magic Formula coefficients, so a simulator would fill",
        "$ them with defaults. Merge it into a complete file: tyredamp tyre-model ... "
        "--merge-into BASE.tir",
        f"$ In-plane values written by tyredamp {__version__} from a radial modal test"
        + (" and a tangential modal test." if windup is not None else "."),
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

    def why(key: str, default: str) -> str:
        return budget.comment(key) if budget is not None else default

    lines += [
        "[INERTIA]",
        f"BELT_MASS = {_fmt(rigid.belt_mass)}  $ belt mass from the n = 1 mode shape, "
        + why("BELT_MASS", f"+- {rigid.belt_mass_std:.3g} kg (statistical only)"),
    ]
    lines += _windup_lines(windup, budget, inertia=True)
    for key in ("MASS", "IXX", "IYY", "BELT_IXX", "BELT_IYY"):
        if windup is None or key != "BELT_IYY":
            lines.append(f"$ {key}: not given by this test ({ng.get(key, 'not measured')})")
    if rigid.thin_ring_iyy is not None and windup is None:
        lines.append(
            f"$   (thin-ring assumption m_b R^2 = {rigid.thin_ring_iyy:.5g} kg m^2, not measured)"
        )
    lines += [
        "[STRUCTURAL]",
        f"FREQ_LONG = {_fmt(rigid.freq_long)}  $ n = 1 belt translation, Hz, "
        + why("FREQ_LONG", f"+- {rigid.freq_long_std:.3g} (statistical only)"),
        f"DAMP_LONG = {_fmt(rigid.damp_long)}  $ its damping ratio, "
        + why("DAMP_LONG", f"+- {rigid.damp_long_std:.3g} (statistical only)"),
    ]
    lines += _windup_lines(windup, budget)
    for key in (
        *(("FREQ_WINDUP", "DAMP_WINDUP") if windup is None else ()),
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
    if windup is not None:
        lines.append(
            f"$ derived (not .tir keys): belt rotational stiffness I omega_0^2 = "
            f"{windup.k_windup:.6g} +- {windup.k_windup_std:.3g} N m/rad, damping "
            f"2 zeta_0 I omega_0 = {windup.c_windup:.6g} +- {windup.c_windup_std:.3g} N m s/rad"
        )
    for c in extra_comments:
        lines.append(f"$ {c}")
    return "\n".join(lines) + "\n"


_SECTION = re.compile(r"^\[\s*([A-Za-z0-9_ \-]+?)\s*\]$")
_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_.]*)\s*=\s*(.*)$")
_FORTRAN_EXP = re.compile(r"(?<=[0-9.])[dD](?=[+-]?[0-9])")


def _code(line: str) -> str:
    """The part of ``line`` before a comment (``$`` or ``!`` outside a quoted string)."""
    quote = ""
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "'\"":
            quote = ch
        elif ch in "$!":
            return line[:i].strip()
    return line.strip()


def _number(s: str) -> float | None:
    try:
        return float(_FORTRAN_EXP.sub("e", s))
    except ValueError:
        return None


def _value(raw: str, lineno: int) -> Any:
    """A value: a quoted string (its text), a number (float) or a bare word (str)."""
    s = raw.strip()
    if s[:1] in ("'", '"'):
        end = s.find(s[0], 1)
        if end < 0:
            raise FileFormatError(f".tir line {lineno}: unterminated string {s!r}")
        return s[1:end]
    if not s:
        raise FileFormatError(f".tir line {lineno}: a key without a value")
    x = _number(s)
    return s if x is None else x


@dataclass(frozen=True)
class TirLine:
    """One meaningful line of a ``.tir`` file (see :func:`scan_tir`).

    Attributes
    ----------
    lineno : int
        1-based line number.
    section : str or None
        The section the line is in (None before the first section).
    kind : {"section", "key", "columns", "row"}
    key : str
        The key (``kind == "key"``), the section name (``"section"``), else "".
    value : object
        The value (float, str), the row (list of float), the column names
        (list of str) or None.
    """

    lineno: int
    section: str | None
    kind: str
    key: str
    value: Any


def scan_tir(text: str) -> Iterator[TirLine]:
    """The meaningful lines of ``.tir`` text, in order (comments and blank lines skipped).

    Accepts what public property files contain (MF 5.2, PAC2002, MF 6.1/6.2,
    MF-Swift; ADAMS/MDI tyre property file format): ``[SECTION]`` headers (any
    order, repeated), ``KEY = value`` lines (quoted strings in ``'`` or
    ``"``, numbers also with a Fortran ``D`` exponent, bare words), comments
    from ``$`` or ``!`` outside a quoted string to the end of the line, and
    table sections: a ``{column names}`` line (``[SHAPE]``,
    ``[BOTTOMING_CURVE]``, ``[DEFLECTION_LOAD_CURVE]``...) and rows of numbers.

    Raises
    ------
    FileFormatError
        A line that is none of these (the message gives its number and text),
        a key or row before the first section.
    """
    section: str | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = _code(raw.replace("\ufeff", ""))
        if not line:
            continue
        m = _SECTION.match(line)
        if m:
            section = m.group(1).strip().upper().replace(" ", "_")
            yield TirLine(lineno, section, "section", section, None)
            continue
        k = _KEY.match(line)
        if k:
            if section is None:
                raise FileFormatError(
                    f".tir line {lineno}: key {k.group(1)!r} before any [SECTION]"
                )
            yield TirLine(lineno, section, "key", k.group(1), _value(k.group(2), lineno))
            continue
        if line.startswith("{") and line.endswith("}") and section is not None:
            yield TirLine(lineno, section, "columns", "", line.strip("{} ").split())
            continue
        row = [_number(x) for x in line.replace(",", " ").split()]
        if section is not None and row and all(x is not None for x in row):
            yield TirLine(lineno, section, "row", "", row)
            continue
        raise FileFormatError(
            f".tir line {lineno}: expected [SECTION], KEY = value or a row of numbers, "
            f"got {raw.strip()[:60]!r}"
        )


def parse_tir(text: str) -> dict[str, dict[str, Any]]:
    """Read ``.tir`` text into ``{section: {key: value}}`` (numbers as float).

    Lines as :func:`scan_tir` reads them. Section names are upper-cased, keys
    kept as written. A section given twice is read as one (its keys
    together); a key given twice with the same value is read once. A table
    section gives its rows as ``"_rows"`` (lists of floats) and its column
    names as ``"_columns"``.

    Raises
    ------
    FileFormatError
        As :func:`scan_tir`; a key given twice in a section with different
        values (which one a simulator takes is not defined); no section.
    """
    out: dict[str, dict[str, Any]] = {}
    where: dict[tuple[str, str], int] = {}
    for ln in scan_tir(text):
        assert ln.section is not None
        sec = out.setdefault(ln.section, {})
        if ln.kind == "row":
            sec.setdefault("_rows", []).append(ln.value)
        elif ln.kind == "columns":
            sec["_columns"] = ln.value
        elif ln.kind == "key":
            first = where.setdefault((ln.section, ln.key), ln.lineno)
            if ln.key in sec and sec[ln.key] != ln.value:
                raise FileFormatError(
                    f".tir line {ln.lineno}: key {ln.key!r} repeated in [{ln.section}] with a "
                    f"different value ({sec[ln.key]!r} on line {first}, {ln.value!r} here)"
                )
            sec[ln.key] = ln.value
    if not out:
        raise FileFormatError(".tir: no [SECTION] found")
    return out


def decode_tir(data: bytes, name: str = ".tir") -> str:
    """``.tir`` bytes as text: UTF-8 (a byte-order mark dropped), else Latin-1.

    Raises
    ------
    FileFormatError
        NUL bytes (not a text file).
    """
    if b"\x00" in data:
        raise FileFormatError(f"{name}: not a text file (NUL bytes); expected a .tir property file")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")
