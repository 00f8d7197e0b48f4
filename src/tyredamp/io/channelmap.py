"""Channel roles, units and sensitivities given by the user: :class:`ChannelMap`.

Acquisition files often do not say what a channel measures: TDMS and MDF4
channels without a unit, a hammer recorded in volts, a channel labelled
``g`` that is really the force. A channel map says it, once, for every
time-data reader (TDMS, MDF4, plain CSV, LVM, MATLAB, WAV, UFF 58 type 1).

From the command line (both options repeatable)::

    --channel "Kanal 3=force:N"           role and unit of the stored values
    --channel "1=force"                   by position (1 = first data channel)
    --channel "m_1=acceleration:g@2+Z"    role, unit, point and direction
    --channel "Trigger=ignore"            leave a channel out
    --sensitivity "Kanal 3=2.25 mV/N"     a channel stored in volts
    --channel-map channels.toml           the same in a file

The file is TOML (or JSON with the same structure)::

    [channels."Kanal 3"]
    role = "force"                 # force, acceleration, velocity, displacement,
                                   # pressure, voltage or ignore
    unit = "V"                     # unit of the stored values (default: the file's)
    sensitivity = "2.25 mV/N"      # for channels stored in volts
    node = 1                       # point number (default: the channel's position)
    direction = "+Z"               # +X, +Y, +Z, -X, ... or the UFF code 1..3, -1..-3

    [channels]
    m_1 = "acceleration:m/s^2@2+Z" # the command-line form also works as a value

A key is a channel name as the file writes it (or another name the format
gives it, such as a UFF point label ``1+Z`` or a TDMS ``group/channel``); a
key of digits that is not a channel name is the channel's position
(1-based). A key that matches several channels (a MATLAB matrix variable
``data`` for ``data(:,1)``, ``data(:,2)`` ...) applies to each, and a key
naming one of them is laid over it. A key that matches no channel is an
error that lists the channels of the file.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError, InputError
from ._guard import guarded_read, load_toml
from .units import Sensitivity, parse_sensitivity, parse_unit

__all__ = ["ROLES", "ChannelMap", "ChannelSpec"]

#: What a channel can be named as (``"ignore"`` leaves it out).
ROLES: tuple[str, ...] = (
    "force",
    "acceleration",
    "velocity",
    "displacement",
    "pressure",
    "voltage",
    "ignore",
)
_DIRS = {"+X": 1, "+Y": 2, "+Z": 3, "-X": -1, "-Y": -2, "-Z": -3, "X": 1, "Y": 2, "Z": 3}
_POINT = re.compile(r"^\s*(\d+)\s*([+-]?[XYZxyz])?\s*$")
_SPEC_KEYS = ("role", "unit", "sensitivity", "node", "direction")


@dataclass(frozen=True)
class ChannelSpec:
    """What the user says about one channel.

    Attributes
    ----------
    key : str
        Channel name as in the file, or its 1-based position (digits).
    role : str or None
        One of :data:`ROLES`; None: from the unit.
    unit : str or None
        Units label of the stored values (overrides the file's label).
    sensitivity : Sensitivity or None
        Volts per physical unit, for a channel stored in volts.
    node : int or None
        Point number (default: the channel's position in the file).
    direction : int or None
        UFF direction code (default 3, +Z).
    """

    key: str
    role: str | None = None
    unit: str | None = None
    sensitivity: Sensitivity | None = None
    node: int | None = None
    direction: int | None = None

    def merged(self, other: ChannelSpec) -> ChannelSpec:
        """This spec with every field that ``other`` states taken from ``other``."""
        return ChannelSpec(
            self.key,
            other.role or self.role,
            other.unit or self.unit,
            other.sensitivity or self.sensitivity,
            other.node if other.node is not None else self.node,
            other.direction if other.direction is not None else self.direction,
        )


def _role(value: str, where: str) -> str:
    v = value.strip().lower()
    if v not in ROLES:
        raise InputError(f"{where}: role {value!r} is not one of {', '.join(ROLES)}")
    return v


def _unit(value: str, where: str) -> str:
    v = value.strip()
    parse_unit(v) if v else None  # an unreadable label is refused here, naming it
    return v


def _direction(value: Any, where: str) -> int:
    if isinstance(value, int) and not isinstance(value, bool) and value in (1, 2, 3, -1, -2, -3):
        return value
    code = _DIRS.get(str(value).strip().upper())
    if code is None:
        raise InputError(f"{where}: direction {value!r} is not one of +X, +Y, +Z, -X, -Y, -Z")
    return code


def _node(value: Any, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(f"{where}: node {value!r} is not a point number (integer >= 1)")
    return value


def _spec_text(key: str, text: str, where: str) -> ChannelSpec:
    """``ROLE[:UNIT][@POINT]`` or ``UNIT[@POINT]`` of one channel."""
    body, at, point = text.partition("@")
    node = direction = None
    if at:
        m = _POINT.match(point)
        if m is None:
            raise InputError(
                f"{where}: point {point!r} is not a point number and direction like 2+Z"
            )
        node = int(m.group(1))
        direction = _direction(m.group(2), where) if m.group(2) else None
    head, colon, unit = body.partition(":")
    head = head.strip()
    if not head and not at:
        raise InputError(f"{where}: nothing after '='; expected a role such as force:N")
    role: str | None = None
    if head.lower() in ROLES:
        role = head.lower()
        unit = unit.strip()
    elif colon:
        _role(head, where)  # raises: "xyz:N" has an unknown role
    else:
        unit = head  # "Kanal 3=mV": the unit alone
    if role == "ignore" and unit:
        raise InputError(f"{where}: an ignored channel takes no unit")
    try:
        unit = _unit(unit, where) if unit else ""
    except InputError as exc:
        raise InputError(
            f"{where}: {exc}; expected ROLE[:UNIT] with ROLE one of {', '.join(ROLES)}"
        ) from None
    return ChannelSpec(key, role, unit or None, None, node, direction)


def _split(text: str, option: str) -> tuple[str, str]:
    if not isinstance(text, str) or "=" not in text:
        raise InputError(
            f"{option}: expected CHANNEL=VALUE (for example 'Kanal 3=force:N' or '1=force'), "
            f"got {text!r}"
        )
    key, _, value = text.rpartition("=")
    key = key.strip()
    if not key:
        raise InputError(f"{option}: no channel name before '=' in {text!r}")
    return key, value.strip()


@dataclass(frozen=True)
class ChannelMap:
    """Roles, units and sensitivities of channels, keyed by name or position.

    Attributes
    ----------
    channels : tuple of ChannelSpec
        One entry per channel named (in the order given; a later entry for
        the same key adds to or overrides an earlier one).
    source : str
        Where the map came from (a file name, ``"--channel"``), for messages.
    """

    channels: tuple[ChannelSpec, ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        merged: dict[str, ChannelSpec] = {}
        for s in self.channels:
            if not isinstance(s, ChannelSpec):
                raise InputError(f"channels: expected ChannelSpec entries, got {type(s).__name__}")
            merged[s.key] = merged[s.key].merged(s) if s.key in merged else s
        object.__setattr__(self, "channels", tuple(merged.values()))

    def __bool__(self) -> bool:
        return bool(self.channels)

    @property
    def keys(self) -> tuple[str, ...]:
        """The channel keys named."""
        return tuple(s.key for s in self.channels)

    def merged(self, other: ChannelMap | None) -> ChannelMap:
        """This map with ``other`` laid over it (``other`` wins where both say something)."""
        if not other:
            return self
        src = " and ".join(s for s in (self.source, other.source) if s)
        return ChannelMap(self.channels + other.channels, src)

    # ------------------------------------------------------------------ parsing
    @classmethod
    def parse(
        cls,
        channels: Iterable[str] = (),
        sensitivities: Iterable[str] = (),
        file: str | os.PathLike[str] | None = None,
    ) -> ChannelMap:
        """A map from command-line strings (and a map file under them).

        Parameters
        ----------
        channels : iterable of str
            ``"NAME=ROLE[:UNIT][@POINT]"`` (``--channel``).
        sensitivities : iterable of str
            ``"NAME=VALUE UNIT"`` such as ``"Kanal 3=2.25 mV/N"`` (``--sensitivity``).
        file : path-like, optional
            A TOML or JSON map file (``--channel-map``); the strings override it.

        Raises
        ------
        InputError
            A string that is not ``NAME=...``, an unknown role, an unreadable
            unit or sensitivity, naming the option and the text.
        """
        specs: list[ChannelSpec] = []
        for text in channels:
            key, value = _split(text, "--channel")
            specs.append(_spec_text(key, value, f"--channel {text!r}"))
        for text in sensitivities:
            key, value = _split(text, "--sensitivity")
            try:
                sens = parse_sensitivity(value)
            except InputError as exc:
                raise InputError(f"--sensitivity {text!r}: {exc}") from None
            specs.append(ChannelSpec(key, sensitivity=sens))
        given = cls(tuple(specs), "--channel" if specs else "")
        if file is None:
            return given
        return cls.from_file(file).merged(given)

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> ChannelMap:
        """Read a TOML (``.toml``) or JSON (``.json``) channel-map file (module docstring)."""
        p = Path(path)
        try:
            raw = p.read_bytes()
        except FileNotFoundError:
            raise InputError(f"{p}: channel-map file not found") from None
        except OSError as exc:
            raise InputError(f"{p}: cannot read the channel-map file ({exc.strerror})") from None
        from ._text import decode_text

        text, _ = decode_text(raw, p)
        if p.suffix.lower() != ".json":
            with guarded_read(p):
                doc = load_toml(text, str(p), "a valid TOML channel map")
            return cls.from_dict(doc, str(p))
        with guarded_read(p):
            try:
                doc = json.loads(text)
            except json.JSONDecodeError as exc:
                raise FileFormatError(f"{p}: not a valid JSON channel map ({exc})") from None
        return cls.from_dict(doc, str(p))

    @classmethod
    def from_dict(cls, doc: Any, where: str = "channel map") -> ChannelMap:
        """A map from a parsed document ``{"channels": {NAME: spec, ...}}``.

        ``spec`` is a table with the keys ``role``, ``unit``, ``sensitivity``,
        ``node``, ``direction``, or the command-line text ``"ROLE[:UNIT][@POINT]"``.
        """
        if not isinstance(doc, Mapping):
            raise InputError(f"{where}: expected a table with a 'channels' table")
        bad = [k for k in doc if k != "channels"]
        if bad:
            raise InputError(f"{where}: unknown key {bad[0]!r}; expected 'channels'")
        chans = doc.get("channels", {})
        if not isinstance(chans, Mapping):
            raise InputError(f"{where}: 'channels' must be a table of channel names")
        specs = []
        for key, value in chans.items():
            w = f"{where}: channels.{key}"
            if isinstance(value, str):
                specs.append(_spec_text(str(key), value, w))
                continue
            if not isinstance(value, Mapping):
                raise InputError(f"{w}: expected a table or text such as 'force:N'")
            unknown = [k for k in value if k not in _SPEC_KEYS]
            if unknown:
                raise InputError(
                    f"{w}: unknown key {unknown[0]!r}; expected one of {', '.join(_SPEC_KEYS)}"
                )
            try:
                sens = value.get("sensitivity")
                specs.append(
                    ChannelSpec(
                        str(key),
                        _role(str(value["role"]), w) if "role" in value else None,
                        _unit(str(value["unit"]), w) or None if "unit" in value else None,
                        None if sens is None else parse_sensitivity(sens),
                        _node(value["node"], w) if "node" in value else None,
                        _direction(value["direction"], w) if "direction" in value else None,
                    )
                )
            except InputError as exc:
                msg = str(exc)
                raise InputError(msg if msg.startswith(w) else f"{w}: {msg}") from None
        return cls(tuple(specs), where)

    # ------------------------------------------------------------------ applying
    def resolve(self, names: Sequence[Sequence[str]], path: Any) -> dict[int, ChannelSpec]:
        """Position -> spec for the channels of a file.

        Parameters
        ----------
        names : sequence of sequence of str
            For each channel of the file (in order), the names it answers to
            (its name first, then aliases such as ``1+Z``).
        path : path-like
            The file, for messages.

        Raises
        ------
        InputError
            A key that names no channel (the message lists the file's channels).
        """
        found: list[tuple[ChannelSpec, list[int]]] = []
        for spec in self.channels:
            hits = [i for i, ns in enumerate(names) if ns and ns[0] == spec.key]
            if not hits:
                hits = [i for i, ns in enumerate(names) if spec.key in ns]
            if not hits and spec.key.isdigit() and 1 <= int(spec.key) <= len(names):
                hits = [int(spec.key) - 1]
            if not hits:
                listed = ", ".join(f"{k + 1}: {ns[0]!r}" for k, ns in enumerate(names))
                src = f" ({self.source})" if self.source else ""
                raise InputError(
                    f"{path}: the channel map{src} names channel {spec.key!r}, which the file "
                    f"does not have; its channels are {listed}"
                )
            found.append((spec, hits))
        # a key matching several channels (a matrix variable, a point label) applies to
        # each of them; a key naming one channel is laid over it
        out: dict[int, ChannelSpec] = {}
        for group in (True, False):
            for spec, hits in found:
                if (len(hits) > 1) == group:
                    for i in hits:
                        out[i] = out[i].merged(spec) if i in out else spec
        return out

    def to_dict(self) -> dict[str, Any]:
        """The map as a document ``{"channels": {key: {...}}}`` (inverse of :meth:`from_dict`)."""
        out: dict[str, Any] = {}
        for s in self.channels:
            d: dict[str, Any] = {}
            if s.role is not None:
                d["role"] = s.role
            if s.unit is not None:
                d["unit"] = s.unit
            if s.sensitivity is not None:
                d["sensitivity"] = s.sensitivity.text
            if s.node is not None:
                d["node"] = s.node
            if s.direction is not None:
                d["direction"] = s.direction
            out[s.key] = d
        return {"channels": out}

    @classmethod
    def from_quantities(cls, quantities: Mapping[str, str] | None) -> ChannelMap:
        """The map of the readers' older ``quantities=`` argument (name -> role)."""
        if not quantities:
            return cls()
        specs = []
        for k, v in quantities.items():
            specs.append(ChannelSpec(str(k), _role(str(v), f"quantities[{k!r}]")))
        return cls(tuple(specs), "quantities")
