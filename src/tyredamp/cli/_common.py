"""Shared pieces of the command line: error reporting and output options."""

from __future__ import annotations

import contextlib
import functools
import gc
import logging
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, NoReturn, TypeVar

import click

from ..exceptions import InputError

__all__ = [
    "EXIT_INPUT",
    "EXIT_INTERNAL",
    "EXIT_RUNTIME",
    "EXIT_SIGINT",
    "EXIT_SIGTERM",
    "Interrupted",
    "OutPath",
    "channel_map",
    "channel_map_options",
    "echo_read_notes",
    "fail",
    "out_file_option",
    "parse_drive_points",
    "quiet_run",
    "seed_option",
    "snr_option",
]

F = TypeVar("F", bound=Callable[..., Any])

#: Exit code for usage and input errors (bad options, bad or corrupt files).
EXIT_INPUT = 2
#: Exit code for a numerical method that failed on valid input (a fit that failed).
EXIT_RUNTIME = 3
#: Exit code for an unexpected error (a bug in tyredamp): ``internal error (...)``.
EXIT_INTERNAL = 70
#: Exit code after SIGINT (Ctrl-C): 128 + 2.
EXIT_SIGINT = 130
#: Exit code after SIGTERM (``kill``, ``timeout``, CI cancellation): 128 + 15.
EXIT_SIGTERM = 143


class Interrupted(BaseException):
    """Raised by the CLI's SIGINT/SIGTERM handler so that every ``finally`` cleans up."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def fail(message: str, code: int = EXIT_INPUT) -> NoReturn:
    """Print ``tyredamp: error: message`` as one line on stderr and exit with ``code``."""
    line = " ".join(str(message).split())
    click.echo(f"tyredamp: error: {line}", err=True)
    sys.exit(code)


class _LogAsWarning(logging.Handler):
    """Library log records (WARNING and above) as Python warnings: the command line
    prints them as its own one-line ``tyredamp: warning:`` after a successful run."""

    def emit(self, record: logging.LogRecord) -> None:
        text = " ".join(record.getMessage().split())
        warnings.warn(f"{record.name}: {text[:200]}", RuntimeWarning, stacklevel=2)


@contextlib.contextmanager
def quiet_run(debug: bool) -> Iterator[None]:
    """Keep library output off stderr while a command runs (unless ``debug``).

    Log records of the libraries (matplotlib's font cache, npTDMS, scipy ...)
    become warnings, printed as one-line ``tyredamp: warning:`` lines after a
    successful run and dropped after an error; what destructors raise (a
    library's cleanup of a file it failed to open) is dropped, after a garbage
    collection that runs them before the error line is printed.
    """
    if debug:
        yield
        return
    root = logging.getLogger()
    handler = _LogAsWarning(logging.WARNING)
    root.addHandler(handler)
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _unraisable: None
    try:
        yield
    finally:
        gc.collect()
        sys.unraisablehook = hook
        root.removeHandler(handler)


class OutPath(click.Path):
    """A click path for outputs: an empty string is refused (``Path('')`` would mean ``.``)."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, str) and value == "":
            self.fail("empty path; expected a name", param, ctx)
        return super().convert(value, param, ctx)


def out_file_option(help_text: str) -> Callable[[F], F]:
    """The ``--out/-o FILE`` option (required) that every file-writing command shares."""
    return click.option(
        "--out",
        "-o",
        "out",
        required=True,
        type=OutPath(dir_okay=False, path_type=Path),
        help=help_text,
    )


def format_option(help_text: str = "File format (default from the extension).") -> Callable[[F], F]:
    """The ``--format NAME`` option of the file-writing commands (the io registry's names)."""
    from ..io import FORMATS  # the registry's names only; the writers load on use

    return click.option("--format", "fmt", type=click.Choice(FORMATS), help=help_text)


def seed_option(help_text: str = "Noise seed.") -> Callable[[F], F]:
    """The ``--seed N`` option (integer >= 0, default 0)."""
    return click.option(
        "--seed", type=click.IntRange(min=0), default=0, show_default=True, help=help_text
    )


class Pressure(click.ParamType):
    """An inflation pressure in bar: a finite number above 0 and at most ``max_bar``."""

    name = "pressure"

    def __init__(self, max_bar: float = 20.0) -> None:
        self.max_bar = float(max_bar)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, float):
            p = value
        else:
            try:
                p = float(value)
            except (TypeError, ValueError):
                self.fail(f"expected an inflation pressure in bar, got {value!r}", param, ctx)
        if not 0.0 < p <= self.max_bar:  # also refuses NaN
            self.fail(
                f"expected an inflation pressure above 0 and at most {self.max_bar:g} bar "
                f"(gauge), got {value} bar",
                param,
                ctx,
            )
        return p


def pressure_option(default: float, max_bar: float = 20.0) -> Callable[[F], F]:
    """The ``--pressure BAR`` option of the virtual rigs (gauge pressure in bar)."""
    return click.option(
        "--pressure",
        type=Pressure(max_bar),
        default=default,
        show_default=True,
        metavar="BAR",
        help=f"Inflation (gauge) pressure, bar (above 0, at most {max_bar:g}).",
    )


def snr_option() -> Callable[[F], F]:
    """The ``--snr DB`` option of the virtual rigs (default 40 dB, ``inf`` for no noise)."""
    return click.option(
        "--snr",
        type=float,
        default=40.0,
        show_default=True,
        metavar="DB",
        help="Signal-to-noise ratio of every channel, dB ('inf' for no noise).",
    )


def parse_drive_points(values: tuple[str, ...]) -> tuple[int, ...]:
    """Point numbers of ``--drive-points`` (``1,5``, repeatable); default ``(1,)``."""
    out: list[int] = []
    for v in values:
        for s in v.replace(";", ",").split(","):
            if not s.strip():
                continue
            try:
                out.append(int(s))
            except ValueError:
                raise InputError(
                    f"--drive-points: expected point numbers like 1,5, got {v!r}"
                ) from None
    return tuple(out) or (1,)


_MAP_KEY = "tyredamp.channel_map"


def channel_map_options(fn: F) -> F:
    """``--channel``, ``--sensitivity`` and ``--channel-map`` for a command that reads data.

    The three options are parsed into one :class:`~tyredamp.io.ChannelMap`
    before the command runs (a bad string is a one-line error); the command
    gets it with :func:`channel_map` and passes it to the reader.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        from ..io.channelmap import ChannelMap

        cmap = ChannelMap.parse(
            kwargs.pop("channel_specs", ()),
            kwargs.pop("sensitivity_specs", ()),
            kwargs.pop("channel_map_file", None),
        )
        click.get_current_context().meta[_MAP_KEY] = cmap
        return fn(*args, **kwargs)

    options = [
        click.option(
            "--channel",
            "channel_specs",
            multiple=True,
            metavar="NAME=ROLE[:UNIT][@POINT]",
            help="What a channel of the file is, when the file does not say (or says it "
            "wrongly): 'Kanal 3=force:N', '1=force' (by position), 'm_1=acceleration:g@2+Z', "
            "'Trigger=ignore'. Roles: force, acceleration, velocity, displacement, pressure, "
            "voltage, ignore. Repeatable.",
        ),
        click.option(
            "--sensitivity",
            "sensitivity_specs",
            multiple=True,
            metavar="NAME=VALUE UNIT",
            help="Sensitivity of a channel stored in volts: 'Kanal 3=2.25 mV/N', "
            "'2=100 mV/g' (or a calibration factor such as '444.8 N/V'). Repeatable.",
        ),
        click.option(
            "--channel-map",
            "channel_map_file",
            type=click.Path(dir_okay=False, path_type=Path),
            help="TOML or JSON file of channel roles, units and sensitivities "
            "(docs/file-formats.md); --channel and --sensitivity override it.",
        ),
    ]
    out: Any = wrapper
    for opt in reversed(options):
        out = opt(out)
    return out


def channel_map() -> Any:
    """The :class:`~tyredamp.io.ChannelMap` of the running command (empty when none given)."""
    from ..io.channelmap import ChannelMap

    ctx = click.get_current_context(silent=True)
    cmap = None if ctx is None else ctx.meta.get(_MAP_KEY)
    return cmap if cmap is not None else ChannelMap()


def echo_read_notes(obj: Any) -> None:
    """Print what a reader assumed or left out (``meta["read_notes"]``), one ``note:`` line each."""
    meta = getattr(obj, "meta", {}) or {}
    for note in meta.get("read_notes", []) or []:
        click.echo(f"note: {note}")
    if meta.get("text_encoding"):
        click.echo(f"note: header text read as {meta['text_encoding']} (not UTF-8)")
