"""Command-line options built from a step's settings class (each knob declared once).

:func:`settings_options` adds one option per field of a
:class:`~tyredamp.studies.steps.StepSettings` class, with the knob's option
name, text, default and check; :func:`settings_from_options` turns the parsed
values back into the settings (a bad value is named by its option).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

import click

from ..studies.steps import (
    Band,
    Boolean,
    Choice,
    Integer,
    Knob,
    Number,
    Pair,
    Registered,
    StepSettings,
    knobs,
)

__all__ = ["option_param", "settings_from_options", "settings_options"]

F = TypeVar("F", bound=Callable[..., Any])
S = TypeVar("S", bound=StepSettings)


def option_param(k: Knob) -> str:
    """The name of the function parameter of a knob's option (``--no-search``: ``no_search``)."""
    return k.option.lstrip("-").replace("-", "_")


def _click_type(k: Knob) -> Any:
    c = k.check
    if isinstance(c, Choice):
        return click.Choice(c.options)
    if isinstance(c, Integer | Pair):
        return click.IntRange(min=c.minimum)
    if isinstance(c, Number):
        if c.minimum is None and c.maximum is None:
            return float
        return click.FloatRange(c.minimum, c.maximum, min_open=c.open, max_open=c.open)
    if isinstance(c, Band):
        return float
    return str


def _option(name: str, k: Knob, default: Any) -> Callable[[F], F]:
    param = option_param(k)
    if isinstance(k.check, Boolean):
        return click.option(k.option, param, is_flag=True, help=k.text)
    kw: dict[str, Any] = {"type": _click_type(k), "help": k.text}
    if k.metavar or isinstance(k.check, Registered):
        kw["metavar"] = k.metavar or "NAME"
    if k.check.cli == "pair":
        kw["nargs"] = 2
    if k.check.cli == "multiple":
        kw["multiple"] = True
    elif default is not None:
        kw["default"] = default
        kw["show_default"] = k.show_default
    return click.option(k.option, param, **kw)


def settings_options(
    cls: type[StepSettings], *, skip: Iterable[str] = (), only: Iterable[str] | None = None
) -> Callable[[F], F]:
    """Decorator: the options of the fields of ``cls`` (``only`` those, but ``skip``), in
    field order."""
    left = set(skip)
    keep = None if only is None else set(only)
    defaults = {f.name: f.default for f in dataclasses.fields(cls)}
    opts = [
        _option(n, k, defaults[n])
        for n, k in knobs(cls).items()
        if n not in left and (keep is None or n in keep)
    ]

    def deco(fn: F) -> F:
        for opt in reversed(opts):
            fn = opt(fn)
        return fn

    return deco


def settings_from_options(cls: type[S], values: dict[str, Any], **fixed: Any) -> S:
    """The settings of ``cls`` from the parsed options in ``values`` (removed from it).

    A switch ``--no-X`` gives ``X = False``; options not given keep the field's
    default; ``fixed`` sets fields that have no option on this command. A bad
    value raises :class:`~tyredamp.exceptions.InputError` naming its option.
    """
    table: dict[str, Any] = dict(fixed)
    names: dict[str, str] = {}
    for name, k in knobs(cls).items():
        param = option_param(k)
        if param not in values:
            continue
        v = values.pop(param)
        names[name] = k.option
        if isinstance(k.check, Boolean):
            if v:
                table[name] = not k.option.startswith("--no-")
            continue
        if v is None or v == ():
            continue
        table[name] = v
    return cls.from_mapping(table, names=names)
