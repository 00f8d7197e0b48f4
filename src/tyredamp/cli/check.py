"""``tyredamp check``: linearity, reciprocity and data-quality checks with numbers.

Each subcommand prints the verdict line, the figures and notes. The exit code
is 0 whether the check passes or fails (the verdict is in the output); with
``--strict`` a failed check exits with 1. Bad input exits with 2.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..exceptions import InputError
from ..io import read, read_frf
from ..studies.steps import QualitySettings, QualityStep
from ._common import channel_map, channel_map_options, echo_read_notes
from ._settings import settings_from_options, settings_options

if TYPE_CHECKING:
    from ..signal.checks import CheckResult

__all__ = ["check_group"]

_FILE = click.Path(dir_okay=False, path_type=Path)


def _finish(ctx: click.Context, result: CheckResult, strict: bool) -> None:
    click.echo(result.report())
    if strict and not result.passed:
        # SystemExit, not ctx.exit: click returns ctx.exit codes from main() when
        # standalone_mode=False, and tyredamp.cli.main does not pass them on
        sys.exit(1)


_strict = click.option(
    "--strict", is_flag=True, help="Exit with code 1 when the check fails (default: 0)."
)
_band = click.option(
    "--band", nargs=2, type=float, metavar="F_LO F_HI", help="Check only lines in this band (Hz)."
)


@click.group("check")
def check_group() -> None:
    """Linearity, reciprocity and data-quality checks, with numbers and a verdict.

    Every check prints one verdict line (PASS/FAIL), its figures and notes.
    The exit code is 0 whether it passes or fails unless --strict is given
    (then a failed check exits with 1); unreadable input exits with 2.

    \b
    Example:
      tyredamp check linearity frf_10N.uff frf_40N.uff --threshold 0.05
      tyredamp check reciprocity frf_mimo.uff
      tyredamp check quality tyre_test.uff --strict
    """


@check_group.command("linearity")
@click.argument("frf_files", nargs=-1, type=_FILE)
@click.option(
    "--threshold",
    type=click.FloatRange(min=0),
    default=0.05,
    show_default=True,
    help="Largest accepted overall relative deviation (0.05 = 5 %).",
)
@_band
@_strict
@click.pass_context
def linearity_cmd(
    ctx: click.Context,
    frf_files: tuple[Path, ...],
    threshold: float,
    band: tuple[float, float] | None,
    strict: bool,
) -> None:
    """Compare FRFs measured at two or more force levels (first file = reference).

    The figure is the RMS over all lines of the difference to the first FRF
    relative to the first FRF; the largest line deviation is also shown.

    \b
    Example:
      tyredamp check linearity frf_10N.uff frf_20N.uff frf_40N.uff --threshold 0.05
    """
    if len(frf_files) < 2:
        raise InputError(
            f"check linearity: expected two or more FRF files (one per force level), got "
            f"{len(frf_files)}"
        )
    from ..studies.radial import check_linearity

    frfs = [read_frf(p) for p in frf_files]
    _finish(ctx, check_linearity(frfs, threshold, band or None), strict)


@check_group.command("reciprocity")
@click.argument("frf_files", nargs=-1, type=_FILE)
@click.option(
    "--threshold",
    type=click.FloatRange(min=0),
    default=0.05,
    show_default=True,
    help="Largest accepted overall relative difference (0.05 = 5 %).",
)
@_band
@_strict
@click.pass_context
def reciprocity_cmd(
    ctx: click.Context,
    frf_files: tuple[Path, ...],
    threshold: float,
    band: tuple[float, float] | None,
    strict: bool,
) -> None:
    """Compare H_jk with H_kj in one MIMO FRF file (or several tests, inputs joined).

    \b
    Example:
      tyredamp check reciprocity frf_mimo.uff
      tyredamp check reciprocity frf_shaker_at_1.uff frf_shaker_at_5.uff
    """
    if not frf_files:
        raise InputError("check reciprocity: expected one or more FRF files, got none")
    from ..studies.radial import check_reciprocity

    frfs = [read_frf(p) for p in frf_files]
    _finish(ctx, check_reciprocity(frfs, threshold, band or None), strict)


@check_group.command("quality")
@click.argument("data_file", type=_FILE)
@settings_options(QualitySettings)
@_strict
@channel_map_options
@click.pass_context
def quality_cmd(ctx: click.Context, data_file: Path, strict: bool, **options: Any) -> None:
    """Clipping, dead channels, low-coherence bands and drive-point passivity.

    DATA_FILE holds time data (all checks; the FRF is estimated with H1 and
    the default method) or an FRF (coherence and passivity only).

    \b
    Example:
      tyredamp check quality tyre_test.uff --coherence-min 0.9 --band 30 200 --strict
    """
    settings = settings_from_options(QualitySettings, options)
    obj = read(data_file, channel_map())
    echo_read_notes(obj)
    if getattr(obj, "output_only", False):
        click.echo(
            "note: output-only data (no force channel): clipping and dead channels are "
            "checked; coherence and passivity need a force (name it with --channel NAME=force:N)"
        )
    result, _ = QualityStep.run(obj, settings)
    _finish(ctx, result, strict)
