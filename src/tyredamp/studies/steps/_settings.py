"""Typed step settings: each knob declared once, with its default, unit, check and text.

A step's settings are a frozen dataclass whose fields are made with
:func:`knob`. The knob carries everything every path needs:

* its **default** and **unit**, and one sentence of **text** (the CLI help,
  the campaign schema's description and the documentation);
* its **check** (:class:`Check`): turns a value as a person or a file gives it
  (a TOML number, a list, the text of a command-line option) into the typed
  value, or raises :class:`~tyredamp.exceptions.InputError` naming where it
  came from (``--order-step``, ``settings.radial.modal.order_step``); the
  same check gives the JSON-schema fragment of the campaign file;
* its **option**, the command-line option that sets it (``--order-step``;
  ``--no-residuals`` for a switch that is on by default).

:meth:`StepSettings.from_mapping` builds the settings from a table and refuses
unknown keys; :meth:`StepSettings.to_dict` gives the JSON-ready table back.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, TypeVar

from ...exceptions import InputError

__all__ = [
    "Band",
    "Boolean",
    "Check",
    "Choice",
    "Integer",
    "Knob",
    "Length",
    "Names",
    "Number",
    "Pair",
    "Positives",
    "Registered",
    "StepSettings",
    "knob",
    "knobs",
]

S = TypeVar("S", bound="StepSettings")


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


class Check:
    """Check and convert one setting's value (base class).

    ``cli`` says how the command line gives the value: ``"value"`` (one
    value), ``"pair"`` (two values, ``nargs=2``), ``"flag"`` (a switch) or
    ``"multiple"`` (a repeated option, its values joined).
    """

    cli: ClassVar[str] = "value"
    #: the type of the command-line value: "text", "integer" or "number"
    cli_type: ClassVar[str] = "text"
    #: ``None`` allowed (a setting whose default is "automatic")
    optional: bool = True

    def __call__(self, value: Any, where: str) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def schema(self) -> dict[str, Any]:
        """The JSON-schema fragment of the value (``None`` allowed is stated by the default)."""
        return {}

    def choices(self) -> tuple[str, ...] | None:
        """The allowed values of a choice (command-line completion), else None."""
        return None


@dataclass(frozen=True)
class Choice(Check):
    """One of ``options`` (text)."""

    options: tuple[str, ...]
    optional: bool = False

    def __call__(self, value: Any, where: str) -> Any:
        if value is None and self.optional:
            return None
        if value not in self.options:
            raise InputError(f"{where}: expected one of {list(self.options)}, got {value!r}")
        return value

    def schema(self) -> dict[str, Any]:
        return {"enum": list(self.options)}

    def choices(self) -> tuple[str, ...]:
        return self.options


@dataclass(frozen=True)
class Registered(Check):
    """The name of an entry of a registry (read when checked, so later entries count)."""

    registry: Callable[[], Mapping[str, Any]]
    what: str
    optional: bool = False

    def __call__(self, value: Any, where: str) -> Any:
        if value is None and self.optional:
            return None
        names = sorted(self.registry())
        if not isinstance(value, str) or value not in names:
            raise InputError(f"{where}: expected a {self.what} of {names}, got {value!r}")
        return value

    def schema(self) -> dict[str, Any]:
        return {"type": "string", "description": f"a {self.what} of {sorted(self.registry())}"}

    def choices(self) -> tuple[str, ...]:
        return tuple(sorted(self.registry()))


@dataclass(frozen=True)
class Boolean(Check):
    """True or false (on the command line a switch)."""

    cli: ClassVar[str] = "flag"
    optional: bool = False

    def __call__(self, value: Any, where: str) -> Any:
        if not isinstance(value, bool):
            raise InputError(f"{where}: expected true or false, got {value!r}")
        return value

    def schema(self) -> dict[str, Any]:
        return {"type": "boolean"}


@dataclass(frozen=True)
class Integer(Check):
    """An integer ``>= minimum`` (and ``<= maximum`` when given: the most the method can use)."""

    minimum: int
    optional: bool = True
    maximum: int | None = None
    cli_type: ClassVar[str] = "integer"

    def __call__(self, value: Any, where: str) -> Any:
        if value is None and self.optional:
            return None
        if not isinstance(value, int) or isinstance(value, bool) or value < self.minimum:
            raise InputError(f"{where}: expected an integer >= {self.minimum}, got {value!r}")
        if self.maximum is not None and value > self.maximum:
            raise InputError(f"{where}: expected an integer <= {self.maximum}, got {value!r}")
        return value

    def schema(self) -> dict[str, Any]:
        out: dict[str, Any] = {"type": "integer", "minimum": self.minimum}
        if self.maximum is not None:
            out["maximum"] = self.maximum
        return out


@dataclass(frozen=True)
class Number(Check):
    """A finite number in ``[minimum, maximum]`` (``open``: the ends excluded)."""

    minimum: float | None = None
    maximum: float | None = None
    open: bool = False
    optional: bool = True
    cli_type: ClassVar[str] = "number"

    def __call__(self, value: Any, where: str) -> Any:
        if value is None and self.optional:
            return None
        ok = _is_number(value) and math.isfinite(value)
        lo, hi = self.minimum, self.maximum
        if ok and lo is not None:
            ok = value > lo if self.open else value >= lo
        if ok and hi is not None:
            ok = value < hi if self.open else value <= hi
        if not ok:
            raise InputError(f"{where}: expected {self._range()}, got {value!r}")
        return float(value)

    def _range(self) -> str:
        lo, hi, o = self.minimum, self.maximum, self.open
        if lo is not None and hi is not None:
            return f"a number in {'(' if o else '['}{lo:g}, {hi:g}{')' if o else ']'}"
        if lo is not None:
            return f"a number {'>' if o else '>='} {lo:g}"
        if hi is not None:
            return f"a number {'<' if o else '<='} {hi:g}"
        return "a finite number"

    def schema(self) -> dict[str, Any]:
        out: dict[str, Any] = {"type": "number"}
        if self.minimum is not None:
            out["exclusiveMinimum" if self.open else "minimum"] = self.minimum
        if self.maximum is not None:
            out["exclusiveMaximum" if self.open else "maximum"] = self.maximum
        return out


@dataclass(frozen=True)
class Band(Check):
    """A band ``(f_lo, f_hi)`` in Hz, ``0 <= f_lo < f_hi``."""

    cli: ClassVar[str] = "pair"
    cli_type: ClassVar[str] = "number"

    def __call__(self, value: Any, where: str) -> Any:
        if value is None:
            return None
        if (
            not isinstance(value, list | tuple)
            or len(value) != 2
            or not all(map(_is_number, value))
        ):
            raise InputError(f"{where}: expected [f_lo, f_hi] in Hz, got {_show(value)}")
        lo, hi = float(value[0]), float(value[1])
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
            raise InputError(f"{where}: expected 0 <= f_lo < f_hi, got {_show(value)}")
        return (lo, hi)

    def schema(self) -> dict[str, Any]:
        return {"$ref": "#/$defs/band"}


@dataclass(frozen=True)
class Pair(Check):
    """Two integers ``>= minimum`` (on the command line ``nargs=2``)."""

    minimum: int = 1
    what: str = "[first, second]"
    cli: ClassVar[str] = "pair"
    cli_type: ClassVar[str] = "integer"

    def __call__(self, value: Any, where: str) -> Any:
        if value is None:
            return None
        ok = isinstance(value, list | tuple) and len(value) == 2
        ok = ok and all(isinstance(v, int) and not isinstance(v, bool) for v in value)
        if not ok or min(value) < self.minimum:
            raise InputError(f"{where}: expected {self.what}, got {_show(value)}")
        return (int(value[0]), int(value[1]))

    def schema(self) -> dict[str, Any]:
        return {
            "type": ["array", "null"],
            "items": {"type": "integer", "minimum": self.minimum},
            "minItems": 2,
            "maxItems": 2,
        }


def _show(value: Any) -> str:
    if isinstance(value, tuple):
        value = list(value)
    return repr(value)


def _split(value: Any) -> Any:
    """Text ``"a,b; c"`` (the command line) as a list; other values unchanged."""
    if isinstance(value, str):
        return [x.strip() for x in value.replace(";", ",").split(",") if x.strip()]
    if isinstance(value, tuple):  # a repeated option, each maybe comma-separated
        return [y for x in value for y in (_split(x) if isinstance(x, str) else [x])]
    return value


@dataclass(frozen=True)
class Positives(Check):
    """A non-empty list of at most ``max_items`` numbers > 0 (``"F1,F2"`` on the command line)."""

    what: str = "frequencies > 0 Hz"
    max_items: int = 1000

    def __call__(self, value: Any, where: str) -> Any:
        if value is None:
            return None
        raw = value
        value = _split(value)
        if isinstance(raw, str):
            try:
                value = [float(v) for v in value]
            except ValueError:
                raise InputError(
                    f"{where}: expected numbers separated by commas, got {raw!r}"
                ) from None
        ok = isinstance(value, list) and len(value) > 0 and all(map(_is_number, value))
        if not ok or not all(math.isfinite(v) and v > 0 for v in value):
            raise InputError(f"{where}: expected a non-empty list of {self.what}, got {raw!r}")
        if len(value) > self.max_items:
            raise InputError(f"{where}: expected at most {self.max_items} values, got {len(value)}")
        return tuple(float(v) for v in value)

    def schema(self) -> dict[str, Any]:
        return {
            "type": "array",
            "minItems": 1,
            "maxItems": self.max_items,
            "items": {"type": "number", "exclusiveMinimum": 0},
        }


@dataclass(frozen=True)
class Names(Check):
    """A non-empty list of names (comma-separated or repeated on the command line),
    each checked by ``each`` (which may translate aliases)."""

    each: Callable[[str, str], Any] | None = None
    what: str = "names"
    #: text is split at commas (false: each repetition of the option is one name)
    split: bool = True
    cli: ClassVar[str] = "multiple"

    def __call__(self, value: Any, where: str) -> Any:
        if value is None or value == ():
            return None
        if self.split:
            value = _split(value)
        elif isinstance(value, tuple | str):
            value = [value] if isinstance(value, str) else list(value)
        if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
            raise InputError(f"{where}: expected a non-empty list of {self.what}, got {value!r}")
        if self.each is None:
            return tuple(value)
        out: list[Any] = []
        for v in value:
            got = self.each(v, where)
            out += list(got) if isinstance(got, list | tuple) else [got]
        return tuple(dict.fromkeys(out))

    def schema(self) -> dict[str, Any]:
        return {"type": "array", "minItems": 1, "items": {"type": "string"}}


@dataclass(frozen=True)
class Length(Check):
    """A length in samples (an integer) or seconds (text ``"0.5s"``), kept as given:
    seconds become samples where the sample rate is known (:func:`samples`)."""

    def __call__(self, value: Any, where: str) -> Any:
        if value is None:
            return None
        if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
            return value
        if isinstance(value, str):
            samples(value, 1.0, where, whole=False)  # the form; the whole samples come later
            return value.strip()
        raise InputError(f"{where}: expected samples (4096) or seconds (0.5s), got {value!r}")

    def schema(self) -> dict[str, Any]:
        return {
            "type": ["integer", "string"],
            "minimum": 0,
            "pattern": r"^\s*([0-9]+|[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?\s*[sS])\s*$",
        }


def samples(text: Any, sample_rate: float, where: str, *, whole: bool = True) -> int:
    """A length given as samples (``4096``, ``"4096"``) or seconds (``"0.5s"``) in whole samples.

    Seconds must be a whole number of samples at ``sample_rate`` (to 1e-6 of
    a sample; not checked when ``whole`` is false); otherwise, and for text
    that is neither, :class:`InputError` names ``where``.
    """
    t = str(text).strip().lower()
    seconds = t.endswith("s")
    try:
        value = float(t[:-1]) * sample_rate if seconds else float(int(t))
    except ValueError:
        raise InputError(
            f"{where}: expected samples (4096) or seconds (0.5s), got {text!r}"
        ) from None
    n = round(value) if math.isfinite(value) else -1
    if whole and seconds and (n < 0 or abs(value - n) > 1e-6 * max(1.0, abs(value))):
        raise InputError(
            f"{where}: {text!r} is {value:.6g} samples at {sample_rate:g} Hz, not a whole "
            "non-negative number; give samples"
        )
    if n < 0 or value < 0:
        raise InputError(f"{where}: expected a non-negative length, got {text!r}")
    return int(n)


@dataclass(frozen=True)
class Knob:
    """What a settings field declares once (see the module docstring).

    Attributes
    ----------
    text : str
        One or two sentences for people: the CLI help, the schema's description
        and the documentation.
    check : Check
        Checks and converts a given value.
    option : str
        Command-line option (``"--order-step"``; ``"--no-X"`` for a switch that
        is on by default).
    unit : str
        Unit of the value (``"Hz"``, ``"samples"``; ``""`` for none).
    metavar : str or None
        Placeholder of the value in the CLI help (``"F_LO F_HI"``).
    show_default : bool
        Show the default in the CLI help.
    """

    text: str
    check: Check
    option: str
    unit: str = ""
    metavar: str | None = None
    show_default: bool = True


def knob(
    default: Any,
    text: str,
    check: Check,
    option: str,
    *,
    unit: str = "",
    metavar: str | None = None,
    show_default: bool = True,
) -> Any:
    """A settings field: its default and its :class:`Knob` (module docstring)."""
    k = Knob(text, check, option, unit, metavar, show_default)
    return field(default=default, metadata={"knob": k})


def knobs(cls: type[StepSettings] | StepSettings) -> dict[str, Knob]:
    """The knobs of a settings class, by field name, in declaration order."""
    return {f.name: f.metadata["knob"] for f in dataclasses.fields(cls) if "knob" in f.metadata}


@dataclass(frozen=True)
class StepSettings:
    """Base of the settings of a step: frozen, every field a :func:`knob`.

    Building one checks every value (``InputError`` naming the field);
    :meth:`from_mapping` also refuses unknown keys and names where each value
    came from.
    """

    #: how this step's settings are called in messages and in the campaign file
    section: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for name, k in knobs(self).items():
            object.__setattr__(self, name, k.check(getattr(self, name), name))

    @classmethod
    def from_mapping(
        cls: type[S],
        table: Mapping[str, Any] | None,
        where: str = "",
        *,
        names: Mapping[str, str] | None = None,
    ) -> S:
        """Settings from a table ``{field: value}`` (missing fields take their defaults).

        Parameters
        ----------
        table : mapping or None
            The values given.
        where : str
            Prefix of the key in messages (``"settings.radial.modal"``); the key
            is appended with a dot.
        names : mapping of str to str, optional
            How each field is called in messages instead (``{"order_step":
            "--order-step"}``, the command line).

        Raises
        ------
        InputError
            An unknown key or a bad value, named.
        """
        table = {} if table is None else table
        if not isinstance(table, Mapping):
            raise InputError(f"{where}: expected a table, got {table!r}")
        ks = knobs(cls)
        unknown = sorted(set(table) - set(ks))
        if unknown:
            raise InputError(f"{where}: unknown key {unknown[0]!r}; expected one of {sorted(ks)}")
        values: dict[str, Any] = {}
        for name, k in ks.items():
            if name not in table:
                continue
            label = (names or {}).get(name) or (f"{where}.{name}" if where else name)
            values[name] = k.check(table[name], label)
        return cls(**values)

    def replace(self: S, **changes: Any) -> S:
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready table of every field (tuples as lists)."""

        def plain(v: Any) -> Any:
            return [plain(x) for x in v] if isinstance(v, tuple | list) else v

        return {name: plain(getattr(self, name)) for name in knobs(self)}

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """JSON-ready table of the defaults."""
        return cls().to_dict()

    @classmethod
    def schema(cls) -> dict[str, Any]:
        """JSON-schema of the table (used for the campaign file's schema)."""
        props: dict[str, Any] = {}
        for f in dataclasses.fields(cls):
            k: Knob | None = f.metadata.get("knob")
            if k is None:
                continue
            p = k.check.schema()
            text = k.text + (f" Unit: {k.unit}." if k.unit else "")
            p = {**p, "description": text}
            d = f.default
            if d is not None and d is not dataclasses.MISSING:
                p["default"] = list(d) if isinstance(d, tuple) else d
            props[f.name] = p
        return {"type": "object", "additionalProperties": False, "properties": props}


def describe(cls: type[StepSettings]) -> list[str]:
    """Markdown table rows, one per setting: key, option, default, unit, text."""
    rows = ["| key | option | default | unit | meaning |", "|---|---|---|---|---|"]
    for name, k in knobs(cls).items():
        d = cls.defaults()[name]
        rows.append(f"| `{name}` | `{k.option}` | `{d!r}` | {k.unit} | {k.text} |")
    return rows


def sequence_names(values: Sequence[str]) -> str:
    """``'a', 'b' and 'c'`` for messages."""
    items = [repr(v) for v in values]
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]
