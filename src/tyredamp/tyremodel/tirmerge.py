"""Identified values merged into a complete ``.tir`` property file.

A radial modal test gives a few in-plane rigid-ring values (``BELT_MASS``,
``FREQ_LONG``, ``DAMP_LONG``); a vehicle simulation needs a whole property
file (``[MODEL]``, ``[DIMENSION]``, ``[VERTICAL]``, the Magic Formula
coefficients...). :func:`merge_tir` puts the identified values into a base
file the user trusts (a supplier's or a public ``.tir``):

* every line of the base is kept, byte for byte, except the lines of the
  identified keys (in whatever section the base has them), whose value is
  replaced and whose old value is kept in the trailing ``$`` comment beside
  the new value's uncertainty and assumptions;
* a key the base lacks is added at the end of its section, a section the
  base lacks at the end of the file;
* ``INFLPRES`` is set to the test pressure and ``NOMPRES`` kept (it is the
  reference of the base's pressure coefficients) or, when the base has none,
  set to the base's own pressure (``INFLATION_PRESSURE``, ``IP_NOM``...) or
  the test's;
* a ``$`` header after ``[MDI_HEADER]`` (or at the top) says what was
  identified from which test.

The result is read back with :func:`~tyredamp.tyremodel.tir.parse_tir` and
compared with the values before it is returned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from .. import __version__
from ..exceptions import FileFormatError, InputError
from .rigid import NOT_FROM_RADIAL_TEST
from .tir import parse_tir, scan_tir

__all__ = ["TirValue", "base_pressure", "merge_tir", "merged_text"]

_BAR = 1e5
#: Relative difference between the base's and the test's pressure above which a merge is refused.
PRESSURE_TOLERANCE = 0.1

#: Keys that may hold a base file's inflation pressure, in the order they are trusted.
_PRESSURE_KEYS = (
    ("OPERATING_CONDITIONS", "NOMPRES"),
    ("OPERATING_CONDITIONS", "INFLPRES"),
    ("TIRE_CONDITIONS", "IP_NOM"),
    ("TIRE_CONDITIONS", "IP"),
    ("GOODYEAR", "INFLATION_PRESSURE"),
)


@dataclass(frozen=True)
class TirValue:
    """One value to write: ``[section] KEY = value  $ comment``."""

    section: str
    key: str
    value: float
    comment: str = ""


def _pressure_pa(x: Any) -> float | None:
    """A pressure value in Pa: numbers below 30 read as bar, above 1000 as Pa, else unknown."""
    if not isinstance(x, float) or not math.isfinite(x) or x <= 0:
        return None
    if x < 30:
        return x * 1e5
    if x > 1000:
        return x
    return None


def base_pressure(doc: dict[str, dict[str, Any]]) -> float | None:
    """The inflation pressure (Pa) a parsed base file was made for, if it says.

    Looks at ``NOMPRES``, ``INFLPRES`` (``[OPERATING_CONDITIONS]``),
    ``IP_NOM``, ``IP`` (``[TIRE_CONDITIONS]``, PAC2002 files) and
    ``INFLATION_PRESSURE`` (supplier sections) in that order; a value below
    30 is taken as bar, above 1000 as Pa (anything between is ambiguous and
    ignored).
    """
    for sec, key in _PRESSURE_KEYS:
        for name, d in doc.items():
            if name == sec or key == "INFLATION_PRESSURE":
                p = _pressure_pa(d.get(key))
                if p is not None:
                    return p
    return None


def _fmt(x: float) -> str:
    return f"{x:.7g}"


def _value_line(raw: str | None, key: str, v: TirValue, old: Any) -> str:
    """``KEY = value  $ comment`` keeping the base line's layout up to its ``=``."""
    lead = raw[: raw.index("=") + 1] if raw is not None and "=" in raw else f"{key:<24} ="
    comment = v.comment.replace("\n", " ").replace("\r", " ")
    if old is not None:
        comment += f"; base value {old!r}" if isinstance(old, str) else f"; base value {old:.7g}"
        was = raw.split("$", 1)[1].strip() if raw is not None and "$" in raw else ""
        comment += f" ({was})" if was else ""
    return f"{lead} {_fmt(v.value):<14} $ {comment}".rstrip()


def _check_values(values: Sequence[TirValue]) -> None:
    seen = set()
    for v in values:
        if not (isinstance(v.value, (int, float)) and math.isfinite(v.value)):
            raise InputError(f"{v.key}: expected a finite number to write, got {v.value!r}")
        if (v.section, v.key) in seen:
            raise InputError(f"{v.key}: given twice for [{v.section}]")
        seen.add((v.section, v.key))


def merge_tir(
    base_text: str, values: Sequence[TirValue], *, header: Sequence[str], name: str = "base .tir"
) -> str:
    """``base_text`` with ``values`` written into it (module docstring).

    Parameters
    ----------
    base_text : str
        The base property file (any ``.tir`` :func:`~tyredamp.tyremodel.tir.parse_tir` reads).
    values : sequence of TirValue
        What to write (sections upper case, values finite, SI as ``[UNITS]``
        of the base must say: see :func:`check_si_units`).
    header : sequence of str
        Comment lines (without the ``$``) saying what was identified from which test.
    name : str
        The base's name for messages.

    Returns
    -------
    str
        The merged file, with the base's line endings.

    Raises
    ------
    FileFormatError
        The base is not a ``.tir`` file (as :func:`~tyredamp.tyremodel.tir.parse_tir`).
    InputError
        A value that is not a finite number, given twice.
    """
    _check_values(values)
    try:
        doc = parse_tir(base_text)
    except FileFormatError as exc:
        raise FileFormatError(f"{name}: {exc}") from None
    check_si_units(doc, name)
    nl = "\r\n" if "\r\n" in base_text else "\n"
    lines = base_text.splitlines()
    key_lines: dict[str, list[tuple[str, int]]] = {}
    last_in: dict[str, int] = {}
    for ln in scan_tir(base_text):
        i = ln.lineno - 1
        assert ln.section is not None
        last_in[ln.section] = i
        if ln.kind == "key":
            key_lines.setdefault(ln.key, []).append((ln.section, i))
    after: dict[int, list[str]] = {}
    new_sections: dict[str, list[str]] = {}
    for v in values:
        where = key_lines.get(v.key, [])
        for sec, i in where:  # in every section, so that a reader of keys alone agrees
            lines[i] = _value_line(lines[i], v.key, v, doc[sec][v.key])
        if any(sec == v.section for sec, _ in where):
            continue
        if v.section in last_in:
            after.setdefault(last_in[v.section], []).append(_value_line(None, v.key, v, None))
        else:
            new_sections.setdefault(v.section, []).append(_value_line(None, v.key, v, None))
    head = [f"$ {h}".rstrip() for h in header]
    at = last_in.get("MDI_HEADER", -1)  # after the [MDI_HEADER] block, else at the top
    after.setdefault(at, [])[:0] = head
    for i in sorted(after, reverse=True):
        lines[i + 1 : i + 1] = after[i]
    for sec, rows in new_sections.items():
        lines += [f"$------------------------------------------------{sec.lower()} (tyredamp)"]
        lines += [f"[{sec}]", *rows]
    text = nl.join(lines) + nl
    _verify(text, values, name)
    return text


def check_si_units(doc: dict[str, dict[str, Any]], name: str) -> None:
    """Refuse a base whose ``[UNITS]`` are not SI (the written values are in kg, m, s).

    Raises
    ------
    InputError
        ``MASS`` not kg, ``LENGTH`` not meter, ``TIME`` not second, ``FORCE``
        not newton (a base without ``[UNITS]`` is taken as SI, the ADAMS default).
    """
    want = {"MASS": ("kg", "kilogram"), "LENGTH": ("meter", "m", "metre")}
    want.update({"TIME": ("second", "s", "sec"), "FORCE": ("newton", "n")})
    units = doc.get("UNITS", {})
    for key, ok in want.items():
        got = units.get(key)
        if got is not None and str(got).strip().lower() not in ok:
            raise InputError(
                f"{name}: [UNITS] {key} = {got!r}; the identified values are SI ({ok[0]}): "
                "convert the base file to SI units first"
            )


def _verify(text: str, values: Sequence[TirValue], name: str) -> None:
    doc = parse_tir(text)
    for v in values:
        got = doc.get(v.section, {}).get(v.key)
        if not isinstance(got, float) or not math.isclose(got, v.value, rel_tol=1e-6):
            raise FileFormatError(
                f"{name}: the merged file reads {v.key} = {got!r}, not {v.value!r}; not written"
            )


def _choose_test(res: Any, doc: dict[str, dict[str, Any]], name: str, force: bool) -> int:
    """Index of the test whose pressure is nearest the base's (refusals in :func:`merged_text`)."""
    pressures = list(res.pressures)
    pb = base_pressure(doc)
    if pb is None:
        if len(pressures) == 1:
            return 0
        raise InputError(
            f"{name}: the file does not state its inflation pressure (NOMPRES, INFLPRES, "
            "INFLATION_PRESSURE); with tests at several pressures, which one to write is not "
            "clear: run tyre-model on the modes file of the base's pressure"
        )
    k = min(range(len(pressures)), key=lambda i: abs(pressures[i] - pb))
    if abs(pressures[k] - pb) > PRESSURE_TOLERANCE * pb and not force:
        raise InputError(
            f"{name}: made for {pb / _BAR:.3g} bar, the nearest test is at "
            f"{pressures[k] / _BAR:.3g} bar; a tyre's structural values change with the "
            "pressure: merge into a base of the test's pressure, or give --force"
        )
    return k


def _same_tyre(doc: dict[str, dict[str, Any]], radius: float, name: str, force: bool) -> str:
    """Refuse (unless ``force``) a base whose radii cannot hold the tested belt; a warning or "".

    The belt (tread-band centre line) radius of the test lies between the
    base's ``RIM_RADIUS`` and its ``UNLOADED_RADIUS`` (5 % allowed above it
    for the radius's own uncertainty) when both describe the same tyre.
    """
    dim = doc.get("DIMENSION", {})
    r0, rr = dim.get("UNLOADED_RADIUS"), dim.get("RIM_RADIUS")
    r0 = r0 if isinstance(r0, float) and r0 > 0 else None
    rr = rr if isinstance(rr, float) and rr > 0 else None
    if (r0 is None or radius <= 1.05 * r0) and (rr is None or radius > rr):
        return ""
    msg = (
        f"{name}: a tyre of unloaded radius {r0 if r0 is not None else '?'} m and rim radius "
        f"{rr if rr is not None else '?'} m cannot have the tested belt radius {radius:g} m: "
        "another tyre"
    )
    if not force:
        raise InputError(msg + "; merge into the tested tyre's file, or give --force")
    return msg + " (merged with --force)"


def merged_text(res: Any, base_text: str, name: str, *, force: bool = False) -> str:
    """A tyre-model result merged into a base ``.tir`` (module docstring).

    Parameters
    ----------
    res : TyreModelResult
        From :func:`~tyredamp.tyremodel.build_tyre_model`.
    base_text : str
    name : str
        The base file's name (header and messages).
    force : bool
        Merge even when the base's pressure differs from every test's by
        more than 10 % (the header says so).

    Raises
    ------
    FileFormatError
        The base is not a ``.tir`` file.
    InputError
        The base's pressure is unknown with tests at several pressures, or
        differs from every test's (without ``force``); non-SI ``[UNITS]``.
    """
    try:
        doc = parse_tir(base_text)
    except FileFormatError as exc:
        raise FileFormatError(f"{name}: {exc}") from None
    k = _choose_test(res, doc, name, force)
    other_tyre = _same_tyre(doc, float(res.ring.radius), name, force)
    p, rigid, budget = res.pressures[k], res.rigid[k], res.budgets[k]
    pb = base_pressure(doc)
    test = f"{res.sources[k]} at {p / _BAR:g} bar"
    values = [
        TirValue(
            "INERTIA", "BELT_MASS", rigid.belt_mass, f"tyredamp: {budget.comment('BELT_MASS')}"
        ),
        TirValue(
            "STRUCTURAL", "FREQ_LONG", rigid.freq_long, f"tyredamp: {budget.comment('FREQ_LONG')}"
        ),
        TirValue(
            "STRUCTURAL", "DAMP_LONG", rigid.damp_long, f"tyredamp: {budget.comment('DAMP_LONG')}"
        ),
        TirValue("OPERATING_CONDITIONS", "INFLPRES", p, f"tyredamp: pressure of the test {test}"),
    ]
    wu = res.windup(k)
    if wu is not None:
        values += [
            TirValue("INERTIA", "BELT_IYY", wu.belt_iyy, f"tyredamp: {budget.comment('BELT_IYY')}"),
            TirValue(
                "STRUCTURAL",
                "FREQ_WINDUP",
                wu.freq_windup,
                f"tyredamp: {budget.comment('FREQ_WINDUP')}",
            ),
            TirValue(
                "STRUCTURAL",
                "DAMP_WINDUP",
                wu.damp_windup,
                f"tyredamp: {budget.comment('DAMP_WINDUP')}",
            ),
        ]
    given = ["BELT_MASS", "FREQ_LONG", "DAMP_LONG"] + (
        [] if wu is None else ["BELT_IYY", "FREQ_WINDUP", "DAMP_WINDUP"]
    )
    if "NOMPRES" not in doc.get("OPERATING_CONDITIONS", {}):
        nom = pb if pb is not None else p
        values.append(
            TirValue(
                "OPERATING_CONDITIONS",
                "NOMPRES",
                nom,
                "tyredamp: the pressure the base file was made for"
                if pb is not None
                else "tyredamp: the base states no pressure; the test's",
            )
        )
    header = [
        f"tyredamp {__version__}: {', '.join(given)} identified from the radial "
        f"modal test {test}"
        + ("" if wu is None else f" and the tangential test {res.tangential_source(k)}"),
        f"(tests: {', '.join(res.sources)}); INFLPRES set to the test's pressure. Base file: "
        f"{name}" + ("" if pb is None else f" ({pb / _BAR:.3g} bar)") + ", every other line kept.",
        "Each identified line gives +- 1 sigma with its sources and what it assumes; the base's "
        "value follows in its comment.",
        "Not given by this test (base values kept): "
        + ", ".join(sorted(k for k in NOT_FROM_RADIAL_TEST if k not in given))
        + ".",
    ]
    if pb is not None and abs(p - pb) > PRESSURE_TOLERANCE * pb:
        header.append(
            f"WARNING: the test ({p / _BAR:g} bar) and the base ({pb / _BAR:.3g} bar) differ in "
            "pressure (merged with --force)"
        )
    if other_tyre:
        header.append(f"WARNING: {other_tyre}")
    disc = res.ring.model_discrepancy()
    if disc["model_limited"]:
        header.append(
            f"Flexible ring (ring.json): model-limited, chi2/dof {disc['chi2_per_dof']:.3g}, "
            f"frequencies to {100 * disc['frequency_rms_relative']:.2g} % RMS."
        )
    header += [c.comment() for c in res.lateral] + [f"WARNING: {w}" for w in res.warnings]
    return merge_tir(base_text, values, header=header, name=name)
