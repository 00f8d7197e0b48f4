"""The ``tyredamp`` command line: parses options, calls the API, writes files.

Every subcommand lives in a module of this package and is registered on
:data:`cli` below. Errors raised on purpose (:class:`TyredampError`) and
usage errors become one line on stderr and exit code 2; ``--debug`` shows the
traceback instead.
"""

from __future__ import annotations

import sys

import click
from threadpoolctl import threadpool_limits

from .. import __version__
from ..exceptions import ConvergenceError, TyredampError
from ._common import EXIT_INPUT, EXIT_RUNTIME, fail

__all__ = ["cli", "main"]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
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


def _register() -> None:
    """Attach the subcommands; each subcommand module adds its lines here."""
    from .campaign import campaign_command
    from .check import check_group
    from .damping import damping_command
    from .demo import demo_command
    from .frf import frf_command
    from .lateral import lateral_group
    from .modal import modal_command
    from .report import report_command
    from .simulate import simulate_group
    from .simulate_campaign import simulate_campaign_command

    cli.add_command(frf_command)
    cli.add_command(check_group)
    cli.add_command(damping_command)
    cli.add_command(lateral_group)
    cli.add_command(modal_command)
    cli.add_command(demo_command)
    cli.add_command(simulate_group)
    cli.add_command(report_command)
    cli.add_command(campaign_command)
    simulate_group.add_command(simulate_campaign_command)


_register()


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script."""
    args = sys.argv[1:] if argv is None else argv
    debug = "--debug" in args
    try:
        # Small dense solves dominate; several BLAS threads on busy cores make them
        # 10-15x slower (benchmarks/demo_timing.py), so the CLI uses one.
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
