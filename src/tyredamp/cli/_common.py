"""Shared pieces of the command line: error reporting and output options."""

from __future__ import annotations

import sys
from typing import NoReturn

import click

__all__ = ["EXIT_INPUT", "EXIT_RUNTIME", "fail"]

#: Exit code for usage and input errors (bad options, bad or corrupt files).
EXIT_INPUT = 2
#: Exit code for a numerical method that failed on valid input.
EXIT_RUNTIME = 3


def fail(message: str, code: int = EXIT_INPUT) -> NoReturn:
    """Print ``tyredamp: error: message`` as one line on stderr and exit with ``code``."""
    line = " ".join(str(message).split())
    click.echo(f"tyredamp: error: {line}", err=True)
    sys.exit(code)
