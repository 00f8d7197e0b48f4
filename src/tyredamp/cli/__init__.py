"""The ``tyredamp`` command line: parses options, calls the API, writes files.

Every subcommand lives in a module of this package and is listed in
:data:`COMMANDS` below (imported only when it runs). Errors raised on purpose
(:class:`TyredampError`) and usage errors become one line on stderr and exit
code 2; anything else becomes one ``internal error`` line and exit code 70
(:func:`main`); ``--debug`` shows the traceback as well, with the same exit code.
"""

from __future__ import annotations

import importlib
import signal
import sys
import threading
import traceback
import warnings
from typing import Any

import click

from .. import __version__
from ..exceptions import ConvergenceError, TyredampError
from ._common import (
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_RUNTIME,
    EXIT_SIGINT,
    EXIT_SIGTERM,
    Interrupted,
    fail,
    quiet_run,
)

__all__ = ["COMMANDS", "LazyGroup", "cli", "main"]


#: Every subcommand: name -> (module, attribute, one-line summary). A module is
#: imported only when its command runs or its own help is shown, so that
#: ``tyredamp --help`` and ``--version`` start fast (benchmarks/startup.py);
#: the summary is the first sentence of the command's docstring (a test checks).
COMMANDS: dict[str, tuple[str, str, str]] = {
    "campaign": (
        "campaign",
        "campaign_command",
        "Process every test of CAMPAIGN_FILE and track the modes across conditions.",
    ),
    "check": (
        "check",
        "check_group",
        "Linearity, reciprocity and data-quality checks, with numbers and a verdict.",
    ),
    "damping": (
        "damping",
        "damping_command",
        "Identify the viscous damping matrix from the complex modes in MODES_JSON.",
    ),
    "demo": (
        "demo",
        "demo_command",
        "Run both studies on the built-in virtual tyres and write a report.",
    ),
    "frf": (
        "frf",
        "frf_command",
        "Estimate FRFs (with coherence) from TIME_FILE and write them to --out.",
    ),
    "lateral": (
        "lateral",
        "lateral_group",
        "Lateral tyre dynamics: fit spring-damper models, simulate the rolling-tyre rig.",
    ),
    "modal": (
        "modal",
        "modal_command",
        "Identify real and complex modes of the FRFs in FRF_FILE.",
    ),
    "oma": (
        "oma",
        "oma_command",
        "Identify modes from output-only time data in FILES (operational modal analysis).",
    ),
    "report": (
        "report",
        "report_command",
        "Build one HTML report from RESULT_FILES of the other commands.",
    ),
    "rolling": (
        "rolling",
        "rolling_command",
        "Travelling waves of a rolling tyre from output-only time data in FILE.",
    ),
    "simulate": (
        "simulate",
        "simulate_group",
        "Simulate tests on the built-in virtual tyres and write them as files.",
    ),
    "tyre-model": (
        "tyremodel",
        "tyre_model_command",
        "Flexible-ring and rigid-ring tyre models from modes files at one or more pressures.",
    ),
}


def _shorten(text: str, limit: int) -> str:
    """``text`` cut at a word to at most ``limit`` characters with ``...`` (as click does)."""
    if len(text) <= limit:
        return text
    words = text.split()
    out = ""
    for word in words:
        cand = f"{out} {word}" if out else word
        if len(cand) + 3 > limit:
            break
        out = cand
    return out + "..."


class LazyGroup(click.Group):
    """A group whose subcommands (see :data:`COMMANDS`) are imported on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*self.commands, *COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            module, attr, _summary = COMMANDS[cmd_name]
            mod = importlib.import_module(f"{__name__}.{module}")
            self.add_command(getattr(mod, attr), cmd_name)
        return self.commands.get(cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The command list of ``--help`` from the summaries, without importing anything."""
        names = self.list_commands(ctx)
        if not names:
            return
        limit = formatter.width - 6 - max(len(n) for n in names)
        rows = []
        for name in names:
            if name in COMMANDS:
                summary = _shorten(COMMANDS[name][2], limit)
            else:
                summary = self.commands[name].get_short_help_str(limit)
            rows.append((name, summary))
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="tyredamp")
@click.option("--debug", is_flag=True, help="Show full tracebacks on errors.")
@click.pass_context
def cli(ctx: click.Context, debug: bool) -> None:
    """Measure, identify and model vibration damping in pneumatic tyres.

    \b
    Example:
      tyredamp demo --out tyredamp-demo
    """
    ctx.ensure_object(dict)
    ctx.obj["debug"] = debug


class _NeverRaised(Exception):
    """Stand-in for exception classes an older click does not have."""


#: raised by click >= 8.2 for a group called without a subcommand
_NoArgsIsHelp: type[Exception] = getattr(click.exceptions, "NoArgsIsHelpError", _NeverRaised)


def _install_signal_handlers() -> dict[int, Any]:
    """Make SIGINT and SIGTERM raise :class:`Interrupted` (cleanup runs); return the old ones."""
    if threading.current_thread() is not threading.main_thread():
        return {}

    def handler(signum: int, frame: Any) -> None:
        # a second signal must not cut the cleanup short
        for s in (signal.SIGINT, signal.SIGTERM):
            signal.signal(s, signal.SIG_IGN)
        raise Interrupted(signum)

    old: dict[int, Any] = {}
    for s in (signal.SIGINT, signal.SIGTERM):
        old[s] = signal.getsignal(s)
        signal.signal(s, handler)
    return old


def _restore_signal_handlers(old: dict[int, Any]) -> None:
    for s, h in old.items():
        signal.signal(s, h if h is not None else signal.SIG_DFL)


def _warning_lines(caught: list[warnings.WarningMessage]) -> list[str]:
    lines: list[str] = []
    for w in caught:
        line = " ".join(f"{w.category.__name__}: {w.message}".split())
        if line not in lines:
            lines.append(line)
    return lines


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script.

    Every failure ends in one line ``tyredamp: error: ...`` on stderr and an exit
    code (see docs/reference/safety.md): 2 bad input or output path, 3 a
    numerical method failed on valid input, 70 an internal error (a bug),
    130/143 interrupted by SIGINT/SIGTERM (temporaries removed). ``--debug``
    prints the traceback as well; the exit code stays the same. Warnings are
    collected and printed after a successful run as ``tyredamp: warning: ...``
    lines (dropped when the run fails, so the error is the only line).
    """
    args = sys.argv[1:] if argv is None else argv
    debug = "--debug" in args
    old = _install_signal_handlers()
    caught: list[warnings.WarningMessage] = []
    code = 0
    message = ""
    error: BaseException | None = None
    try:
        with warnings.catch_warnings(record=not debug) as rec:
            if not debug:
                warnings.simplefilter("default")
            try:
                # Small dense solves dominate; several BLAS threads on busy cores make them
                # 10-15x slower (benchmarks/demo_timing.py), so the CLI uses one
                # (imported here so that --help and --version start fast).
                from .._blas import single_threaded_blas

                with single_threaded_blas(), quiet_run(debug):
                    rv = cli.main(args=args, prog_name="tyredamp", standalone_mode=False)
                if isinstance(rv, int) and rv != 0:
                    # ctx.exit(n) hands its code back as the return value here
                    code = rv
            finally:
                caught = list(rec or [])
    except click.exceptions.Exit as exc:
        code = exc.exit_code
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except Interrupted as exc:
        error = sys.exc_info()[1]
        name = signal.Signals(exc.signum).name
        code = EXIT_SIGTERM if exc.signum == signal.SIGTERM else EXIT_SIGINT
        message = f"interrupted by {name}; no partial output left"
    except _NoArgsIsHelp as exc:
        # a group called without a subcommand: its help, as --help would show it
        ctx = getattr(exc, "ctx", None)
        click.echo(ctx.get_help() if ctx is not None else cli.get_help(click.Context(cli)))
        code = 0
    except click.exceptions.Abort:
        error = sys.exc_info()[1]
        code, message = EXIT_SIGINT, "aborted"
    except click.ClickException as exc:
        error = sys.exc_info()[1]
        code, message = EXIT_INPUT, exc.format_message()
    except ConvergenceError as exc:
        error = sys.exc_info()[1]
        code, message = EXIT_RUNTIME, str(exc)
    except TyredampError as exc:
        error = sys.exc_info()[1]
        code, message = EXIT_INPUT, str(exc)
    except OSError as exc:
        error = sys.exc_info()[1]
        code = EXIT_INPUT
        text = exc.strerror or str(exc)
        message = f"{exc.filename}: {text}" if exc.filename else text
    except (OverflowError, FloatingPointError) as exc:
        # values of the input beyond what double precision computes with (|H| near 1e300
        # squared): the input's fault (a ZeroDivisionError stays a bug, exit 70)
        error = sys.exc_info()[1]
        code = EXIT_INPUT
        message = (
            f"numbers out of the range of double precision ({type(exc).__name__}: {exc}); "
            "the input's values are too large or too small to compute with: check its units"
        )
    except (MemoryError, RecursionError) as exc:
        error = sys.exc_info()[1]
        code = EXIT_INTERNAL
        what = "not enough memory" if isinstance(exc, MemoryError) else "input nested too deeply"
        message = f"internal error ({type(exc).__name__}: {what}); rerun with --debug"
    except Exception as exc:  # the last resort: no traceback reaches the user
        error = sys.exc_info()[1]
        code = EXIT_INTERNAL
        message = f"internal error ({type(exc).__name__}: {exc}); rerun with --debug"
    finally:
        _restore_signal_handlers(old)
    if message:
        if debug and error is not None:
            traceback.print_exception(error)
        fail(message, code)
    for line in _warning_lines(caught):
        click.echo(f"tyredamp: warning: {line}", err=True)
    if code:
        sys.exit(code)
