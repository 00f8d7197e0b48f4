"""Shared pieces of the command line: error reporting and output options."""

from __future__ import annotations

import sys
from collections.abc import Callable
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
    "fail",
    "out_file_option",
    "parse_drive_points",
    "seed_option",
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


def seed_option(help_text: str = "Noise seed.") -> Callable[[F], F]:
    """The ``--seed N`` option (integer >= 0, default 0)."""
    return click.option(
        "--seed", type=click.IntRange(min=0), default=0, show_default=True, help=help_text
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
