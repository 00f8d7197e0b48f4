"""The ``tyredamp`` command line: parses options, calls the API, writes files.

Every subcommand lives in a module of this package and is listed in
:data:`COMMANDS` below (imported only when it runs). Errors raised on purpose
(:class:`TyredampError`) and usage errors become one line on stderr and exit
code 2; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import importlib
import sys

import click

from .. import __version__
from ..exceptions import ConvergenceError, TyredampError
from ._common import EXIT_INPUT, EXIT_RUNTIME, fail

__all__ = ["COMMANDS", "LazyGroup", "cli", "main"]


#: Every subcommand: name -> (module, attribute, one-line summary). A module is
#: imported only when its command runs or its own help is shown, so that
#: ``tyredamp --help`` and ``--version`` start fast (benchmarks/startup.py);
#: the summary is the first sentence of the command's docstring (a test checks).
COMMANDS: dict[str, tuple[str, str, str]] = {
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
    "report": (
        "report",
        "report_command",
        "Build one HTML report from RESULT_FILES of the other commands.",
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


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script."""
    args = sys.argv[1:] if argv is None else argv
    debug = "--debug" in args
    try:
        # Small dense solves dominate; several BLAS threads on busy cores make them
        # 10-15x slower (benchmarks/demo_timing.py), so the CLI uses one.
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            rv = cli.main(args=args, prog_name="tyredamp", standalone_mode=False)
        if isinstance(rv, int) and rv != 0:
            # ctx.exit(n) hands its code back as the return value here
            sys.exit(rv)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.exceptions.Abort:
        fail("aborted", 130)
    except click.ClickException as exc:
        if debug:
            raise
        fail(exc.format_message(), EXIT_INPUT)
    except ConvergenceError as exc:
        if debug:
            raise
        fail(str(exc), EXIT_RUNTIME)
    except TyredampError as exc:
        if debug:
            raise
        fail(str(exc), EXIT_INPUT)
    except OSError as exc:
        if debug:
            raise
        fail(f"{exc.strerror or exc}: {exc.filename}" if exc.filename else str(exc), EXIT_INPUT)
