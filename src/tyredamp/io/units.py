"""Units labels as vendors write them: parsed to SI factor and physical dimension.

A label such as ``(1/N)*(m/s²)``, ``g/N``, ``m/s2/N``, ``mm/s/N``, ``ms^-2``
or ``lbf`` is read by a small grammar::

    label  := product
    product:= power (op power)*          op: "/", "*", ".", "·", "×" or a space
    power  := atom exponent?             exponent: "^n", "**n", "n", "⁻²", "-n"
    atom   := unit symbol | number | "(" product ")"

evaluated left to right (``m/s/N`` is ``(m/s)/N``). The result is a factor
to SI and the exponents of length (m), time (s) and force (N); a label
whose dimension is a displacement, velocity, acceleration or force (or one of
those per force, an FRF) is accepted, anything else is refused with an
:class:`~tyredamp.exceptions.InputError` that names the label.

Unit symbols (case as written; upper-case variants such as ``MM/S^2`` are
accepted where they are unambiguous): ``m``, ``mm``, ``cm``, ``um``/``µm``/
``μm``/``micron``, ``nm``, ``km``, ``in``/``inch``, ``ft``, ``mil``; ``s``/
``sec``; ``N``, ``kN``, ``mN``, ``lbf``, ``kgf``, ``kg``; ``g`` and ``gn``
(standard gravity 9.80665 m/s^2, as in vibration practice, not the gram);
``ips`` (inch per second). Assumptions stated: ``lb`` is taken as the
pound-force ``lbf`` (vibration labels such as ``g/lb`` mean force), and
``ms`` directly followed by an exponent or at the start of a label is metre
times second (``ms^-2``, ``ms-1``), never the millisecond.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Literal

from ..exceptions import InputError

__all__ = [
    "MOTION",
    "QUANTITY_DIMENSIONS",
    "Sensitivity",
    "Unit",
    "frf_units",
    "parse_sensitivity",
    "parse_unit",
    "quantity_units",
]

#: Longest units label read (characters); the grammar is bounded by it and by the two below.
MAX_LABEL = 100
#: Deepest nesting of parentheses in a units label.
MAX_NESTING = 4
#: Largest exponent magnitude (``m^4`` is the largest a vibration unit needs; 12 leaves room).
MAX_EXPONENT = 12

_G = 9.80665
_LBF = 4.4482216152605
_IN = 0.0254

# symbol -> (factor to SI, (length, time, force[, voltage]) exponents)
_ATOMS3: dict[str, tuple[float, tuple[int, ...]]] = {
    "m": (1.0, (1, 0, 0)),
    "mm": (1e-3, (1, 0, 0)),
    "cm": (1e-2, (1, 0, 0)),
    "um": (1e-6, (1, 0, 0)),
    "µm": (1e-6, (1, 0, 0)),
    "μm": (1e-6, (1, 0, 0)),
    "micron": (1e-6, (1, 0, 0)),
    "microns": (1e-6, (1, 0, 0)),
    "nm": (1e-9, (1, 0, 0)),
    "km": (1e3, (1, 0, 0)),
    "in": (_IN, (1, 0, 0)),
    "inch": (_IN, (1, 0, 0)),
    "inches": (_IN, (1, 0, 0)),
    "ft": (0.3048, (1, 0, 0)),
    "mil": (_IN * 1e-3, (1, 0, 0)),
    "meter": (1.0, (1, 0, 0)),
    "metre": (1.0, (1, 0, 0)),
    "s": (1.0, (0, 1, 0)),
    "sec": (1.0, (0, 1, 0)),
    "N": (1.0, (0, 0, 1)),
    "kN": (1e3, (0, 0, 1)),
    "mN": (1e-3, (0, 0, 1)),
    "newton": (1.0, (0, 0, 1)),
    "lbf": (_LBF, (0, 0, 1)),
    "lb": (_LBF, (0, 0, 1)),
    "kgf": (_G, (0, 0, 1)),
    "kg": (1.0, (-1, 2, 1)),  # N s^2 / m
    "g": (_G, (1, -2, 0)),
    "gn": (_G, (1, -2, 0)),
    "ips": (_IN, (1, -1, 0)),
    "newtons": (1.0, (0, 0, 1)),
    "lbs": (_LBF, (0, 0, 1)),
    # pressure: N/m^2
    "Pa": (1.0, (-2, 0, 1)),
    "hPa": (1e2, (-2, 0, 1)),
    "kPa": (1e3, (-2, 0, 1)),
    "MPa": (1e6, (-2, 0, 1)),
    "mPa": (1e-3, (-2, 0, 1)),
    "uPa": (1e-6, (-2, 0, 1)),
    "µPa": (1e-6, (-2, 0, 1)),
    "μPa": (1e-6, (-2, 0, 1)),
    "pascal": (1.0, (-2, 0, 1)),
    "bar": (1e5, (-2, 0, 1)),
    "mbar": (1e2, (-2, 0, 1)),
    "psi": (_LBF / _IN**2, (-2, 0, 1)),
    # frequency (PSD labels such as g^2/Hz)
    "Hz": (1.0, (0, -1, 0)),
    "kHz": (1e3, (0, -1, 0)),
    # electric potential: its own dimension (a sensor's output before its sensitivity)
    "V": (1.0, (0, 0, 0, 1)),
    "mV": (1e-3, (0, 0, 0, 1)),
    "uV": (1e-6, (0, 0, 0, 1)),
    "µV": (1e-6, (0, 0, 0, 1)),
    "μV": (1e-6, (0, 0, 0, 1)),
    "kV": (1e3, (0, 0, 0, 1)),
    "volt": (1.0, (0, 0, 0, 1)),
    "volts": (1.0, (0, 0, 0, 1)),
}
Dims = tuple[int, int, int, int]
_ATOMS: dict[str, tuple[float, Dims]] = {
    k: (f, (d[0], d[1], d[2], d[3] if len(d) > 3 else 0)) for k, (f, d) in _ATOMS3.items()
}
# case-insensitive look-up where unambiguous (MN, mN clash: neither taken from upper case)
_LOWER: dict[str, str] = {}
for _k in _ATOMS:
    _LOWER.setdefault(_k.lower(), _k)
_LOWER["n"] = "N"
_LOWER["kn"] = "kN"
_LOWER.pop("mn", None)
for _k in ("pa", "kpa", "hpa", "mpa", "upa", "µpa", "μpa", "v", "mv", "uv", "µv", "μv", "kv"):
    _LOWER.pop(_k, None)
# upper/lower case as DAQ software writes them (mPa/MPa and mV/MV clash: only the
# spellings below are taken case-insensitively)
_LOWER.update({"pa": "Pa", "kpa": "kPa", "hpa": "hPa", "v": "V", "mv": "mV", "uv": "uV"})
_LOWER.update({"µv": "µV", "μv": "μV", "hz": "Hz", "khz": "kHz"})

_SUPERSCRIPT = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺", "0123456789-+")
_TOKEN = re.compile(
    r"\s*(?:(?P<num>\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)|(?P<sup>[⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺]+)"
    r"|(?P<word>[A-Za-zµμ]+)|(?P<op>\*\*|[/*·×^().\-+]))"
)

Quantity = Literal["displacement", "velocity", "acceleration", "force", "pressure", "voltage"]
#: (length, time, force) exponents of each measured quantity (no voltage).
QUANTITY_DIMENSIONS: dict[str, tuple[int, int, int]] = {
    "displacement": (1, 0, 0),
    "velocity": (1, -1, 0),
    "acceleration": (1, -2, 0),
    "force": (0, 0, 1),
    "pressure": (-2, 0, 1),
}
#: The quantities that make an FRF (a motion per force).
MOTION = ("displacement", "velocity", "acceleration")
_KIND = {"displacement": "receptance", "velocity": "mobility", "acceleration": "accelerance"}


@dataclass(frozen=True)
class Unit:
    """A parsed units label.

    Attributes
    ----------
    label : str
        The label as written.
    factor : float
        Multiply values in this unit by ``factor`` to get SI (m, s, N, V).
    dimensions : (int, int, int)
        Exponents of length, time and force.
    voltage : int
        Exponent of the volt (1 for ``V``, ``mV``; -1 for a calibration in
        ``N/V``; 0 for physical units).
    """

    label: str
    factor: float
    dimensions: tuple[int, int, int]
    voltage: int = 0

    @property
    def quantity(self) -> str | None:
        """``"displacement"``, ``"velocity"``, ``"acceleration"``, ``"force"``,
        ``"pressure"``, ``"voltage"`` or None."""
        if self.voltage == 1 and self.dimensions == (0, 0, 0):
            return "voltage"
        if self.voltage != 0:
            return None
        for q, d in QUANTITY_DIMENSIONS.items():
            if d == self.dimensions:
                return q
        return None

    @property
    def frf_kind(self) -> str | None:
        """``"receptance"``, ``"mobility"`` or ``"accelerance"`` for a response per force."""
        if self.voltage != 0:
            return None
        le, t, f = self.dimensions
        for q in MOTION:
            if QUANTITY_DIMENSIONS[q] == (le, t, f + 1):
                return _KIND[q]
        return None


class _Parser:
    def __init__(self, label: str) -> None:
        self.label = label
        self.toks: list[tuple[str, str]] = []
        text = label.strip()
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                if text[pos:].strip() == "":
                    break
                raise self.error(f"unexpected character {text[pos]!r}")
            kind = m.lastgroup or ""
            self.toks.append((kind, m.group(kind)))
            pos = m.end()
        self.i = 0
        self.depth = 0

    def error(self, why: str) -> InputError:
        shown = self.label if len(self.label) <= 60 else self.label[:57] + "..."
        return InputError(f"units label {shown!r}: {why}")

    def peek(self) -> tuple[str, str] | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self) -> tuple[str, str]:
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def parse(self) -> tuple[float, Dims]:
        if not self.toks:
            raise self.error("empty")
        out = self.product()
        if self.peek() is not None:
            raise self.error(f"unexpected {self.peek()[1]!r}")  # type: ignore[index]
        return out

    def product(self) -> tuple[float, Dims]:
        fac, dim = self.power()
        while True:
            tok = self.peek()
            if tok is None or tok[1] == ")":
                return fac, dim
            if tok[0] == "op" and tok[1] in ("/", "*", ".", "·", "×"):
                self.take()
                sign = -1 if tok[1] == "/" else 1
            elif tok[0] in ("word", "num") or tok[1] == "(":
                sign = 1  # implicit product: "N m", "m s^-2"
            else:
                raise self.error(f"unexpected {tok[1]!r}")
            f2, d2 = self.power()
            fac = self._finite(fac * f2 if sign > 0 else fac / f2)
            dim = tuple(a + sign * b for a, b in zip(dim, d2, strict=True))  # type: ignore[assignment]

    def power(self) -> tuple[float, Dims]:
        fac, dim, is_number = self.atom()
        n = None if is_number else self.exponent()
        if n is None:
            return fac, dim
        try:
            return self._finite(fac**n), tuple(d * n for d in dim)  # type: ignore[return-value]
        except OverflowError:
            raise self.error(f"factor {fac:g} to the power {n} is out of range") from None

    def _finite(self, value: float) -> float:
        """A scale factor that is a finite, non-zero number (else the label is refused)."""
        if not (math.isfinite(value) and value != 0.0):
            raise self.error("its scale factor is zero or out of range")
        return value

    def exponent(self) -> int | None:
        tok = self.peek()
        if tok is None:
            return None
        kind, text = tok
        if kind == "sup":
            self.take()
            return self._int(text.translate(_SUPERSCRIPT))
        if kind == "op" and text in ("^", "**"):
            self.take()
            sign = ""
            nxt = self.peek()
            if nxt is not None and nxt[1] in ("-", "+"):
                sign = self.take()[1]
            if nxt is not None and nxt[1] == "(":
                raise self.error("parenthesised exponents are not supported")
            num = self.peek()
            if num is None or num[0] != "num":
                raise self.error(f"expected an integer exponent after {text!r}")
            return self._int(sign + self.take()[1])
        if kind == "op" and text == "-":  # "s-2", "ms-1"
            self.take()
            num = self.peek()
            if num is None or num[0] != "num":
                raise self.error("expected an integer exponent after '-'")
            return self._int("-" + self.take()[1])
        if kind == "num":  # "s2"
            self.take()
            return self._int(text)
        return None

    def _int(self, text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise self.error(f"exponent {text[:20]!r} is not an integer") from None
        if abs(n) > MAX_EXPONENT:
            raise self.error(
                f"exponent {text[:20]} is not a power a unit is raised to "
                f"(expected -{MAX_EXPONENT} to {MAX_EXPONENT})"
            )
        return n

    def atom(self) -> tuple[float, Dims, bool]:
        if self.peek() is None:
            raise self.error("ends where a unit was expected")
        kind, text = self.take()
        if kind == "num":
            return self._finite(float(text)), (0, 0, 0, 0), True
        if text == "(":
            self.depth += 1
            if self.depth > MAX_NESTING:
                raise self.error(f"parentheses nested deeper than {MAX_NESTING}")
            fac, dim = self.product()
            self.depth -= 1
            tok = self.peek()
            if tok is None or tok[1] != ")":
                raise self.error("unbalanced parenthesis")
            self.take()
            return fac, dim, False
        if kind == "word":
            return (*self.word(text), False)
        raise self.error(f"unexpected {text!r}")

    def word(self, text: str) -> tuple[float, Dims]:
        key = text if text in _ATOMS else _LOWER.get(text.lower())
        if key is None and text.lower() == "ms":
            # metre times second ("ms^-2", "ms-1"), never the millisecond: the
            # exponent that follows belongs to the second
            self.toks.insert(self.i, ("word", "s"))
            return _ATOMS["m"]
        if key is None:
            raise self.error(
                f"unknown unit {text!r}; known: m, mm, cm, um, nm, in, ft, mil, s, Hz, N, kN, "
                "lbf, kgf, kg, g (gravity), ips, Pa, kPa, bar, mbar, psi, V, mV"
            )
        return _ATOMS[key]


def parse_unit(label: str) -> Unit:
    """Parse a units label (module docstring); raise :class:`InputError` naming it."""
    if not isinstance(label, str):
        raise InputError(f"units label: expected text, got {type(label).__name__}")
    if len(label) > MAX_LABEL:
        raise InputError(
            f"units label {label[:40]!r}...: {len(label)} characters; a units label has at "
            f"most {MAX_LABEL}"
        )
    fac, dim = _Parser(label).parse()
    return Unit(label=label, factor=float(fac), dimensions=dim[:3], voltage=dim[3])


def _blank(label: object) -> bool:
    return label is None or str(label).strip().upper() in ("", "NONE", "-")


def quantity_units(label: object) -> tuple[str, float] | None:
    """``(quantity, factor to SI)`` of a measured signal's label; None when blank/``NONE``.

    Raises
    ------
    InputError
        The label cannot be read, or its dimension is not a displacement,
        velocity, acceleration or force.
    """
    if _blank(label):
        return None
    u = parse_unit(str(label))
    q = u.quantity
    if q is None:
        raise InputError(
            f"units label {label!r}: dimension {_dimension(u)} is not a displacement, "
            "velocity, acceleration, force, pressure or voltage"
        )
    return q, u.factor


def _dimension(u: Unit) -> str:
    """``m^1 s^-2 N^0`` (and ``V^n`` when the volt appears) of a parsed label."""
    le, t, f = u.dimensions
    return f"m^{le} s^{t} N^{f}" + (f" V^{u.voltage}" if u.voltage else "")


@dataclass(frozen=True)
class Sensitivity:
    """A transducer sensitivity such as ``2.25 mV/N`` or ``100 mV/g``.

    Attributes
    ----------
    text : str
        As written.
    quantity : str
        The physical quantity the transducer measures (``"force"``,
        ``"acceleration"``, ``"pressure"`` ...).
    volts_per_si : float
        Volts per SI unit of ``quantity`` (V/N, V/(m/s^2), V/Pa ...): a
        channel in volts divided by it is in SI units.
    """

    text: str
    quantity: str
    volts_per_si: float


def parse_sensitivity(text: object) -> Sensitivity:
    """Read a sensitivity: a number and a units label of volts per physical unit.

    ``"2.25 mV/N"``, ``"100 mV/g"``, ``"10.2mV/(m/s^2)"``, ``"50 mV/Pa"``;
    the inverse, a calibration factor in physical units per volt (``"444.8
    N/V"``, ``"9.81 m/s^2/V"``), is accepted too.

    Raises
    ------
    InputError
        Not a positive number followed by such a label.
    """
    raw = str(text).strip()
    m = re.match(r"^([-+]?\d+(?:[.,]\d*)?(?:[eE][-+]?\d+)?)\s*(.*)$", raw)
    if m is None or not m.group(2).strip():
        raise InputError(
            f"sensitivity {raw!r}: expected a number and a unit, such as '2.25 mV/N', "
            "'100 mV/g' or '444.8 N/V'"
        )
    value = float(m.group(1).replace(",", "."))
    if not value > 0 or value == float("inf"):
        raise InputError(f"sensitivity {raw!r}: expected a positive number")
    u = parse_unit(m.group(2).strip())
    phys = Unit(u.label, 1.0, u.dimensions, 0)
    if u.voltage == 1:
        phys = Unit(u.label, 1.0, tuple(-d for d in u.dimensions), 0)  # type: ignore[arg-type]
        per = value * u.factor
    elif u.voltage == -1:
        per = 1.0 / (value * u.factor)
    else:
        per = 0.0
    q = phys.quantity
    if per == 0.0 or q is None or q == "voltage":
        raise InputError(
            f"sensitivity {raw!r}: expected volts per physical unit (mV/N, mV/g, V/Pa) or "
            f"physical unit per volt (N/V), got dimension {_dimension(u)}"
        )
    return Sensitivity(raw, q, per)


def frf_units(label: object, denominator: object = None) -> tuple[str | None, float] | None:
    """``(FRF kind, factor to SI)`` of an FRF's units label(s); None when both are blank.

    ``label`` may hold the whole ratio (``(m/s^2)/N``, ``g/lbf``,
    ``(1/N)*(m/s²)``) or only the response (``m/s^2``), with the force in
    ``denominator`` (a UFF denominator label); a response without any force
    is taken per newton. With a blank ``label`` and a force denominator the
    kind is None (unknown response) and the factor converts the force.

    Raises
    ------
    InputError
        A label that cannot be read, a denominator that is not a force, or a
        ratio that is not a displacement, velocity or acceleration per force.
    """
    if _blank(label) and _blank(denominator):
        return None
    d_factor, d_force = 1.0, 0
    if not _blank(denominator):
        d = parse_unit(str(denominator))
        if d.quantity != "force":
            raise InputError(f"units label {denominator!r}: an FRF denominator must be a force")
        d_factor, d_force = d.factor, 1
    if _blank(label):
        return None, 1.0 / d_factor
    u = parse_unit(str(label))
    dims = (u.dimensions[0], u.dimensions[1], u.dimensions[2] - d_force)
    ratio = Unit(u.label, u.factor / d_factor, dims, u.voltage)
    kind = ratio.frf_kind
    if kind is not None:
        return kind, ratio.factor
    q = ratio.quantity
    if q in MOTION and d_force == 0:
        return _KIND[q], ratio.factor  # response only: per newton
    raise InputError(
        f"units label {label!r}"
        + (f" over {denominator!r}" if d_force else "")
        + f": dimension {_dimension(ratio)} is not a displacement, velocity "
        "or acceleration per force"
    )
