"""``tyredamp report``: one self-contained HTML report from result files."""

from __future__ import annotations

from pathlib import Path

import click

from ..exceptions import InputError
from ..io._safety import atomic_path, check_output_file, private_matplotlib_config
from ._common import out_file_option

__all__ = ["report_command"]


@click.command("report")
@click.argument("result_files", nargs=-1, type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("HTML file to write (self-contained, figures embedded).")
@click.option("--title", help="Page title (default 'tyredamp report').")
def report_command(result_files: tuple[Path, ...], out: Path, title: str | None) -> None:
    """Build one HTML report from RESULT_FILES of the other commands.

    Accepts modes JSON (tyredamp modal), damping JSON (tyredamp damping),
    lateral JSON (tyredamp lateral fit), the demo's results.json and FRF or
    time-data files (.uff .unv .csv .npz). Modes are drawn against the FRF
    file they came from (measured vs fitted, discrepancy), damping matrices
    as heat maps with the diagnostics in words, lateral fits as a ranking
    table with parameters; a modes file from 'simulate radial --truth' is
    shown beside the identified modes. Nothing is written when an error
    occurs.

    \b
    Example:
      tyredamp report modes.json damping.json tyre_frf.uff --out report.html
      tyredamp report lateral.json rig.npz truth.json -o all.html --title "Tyre A"
    """
    if not result_files:
        raise InputError("RESULT_FILES: expected at least one result file")
    check_output_file(out, result_files)
    with private_matplotlib_config():
        from ..report.files import build_files_report

        html = build_files_report(list(result_files), title)
    with atomic_path(out) as tmp:
        tmp.write_text(html, encoding="utf-8")
    click.echo(f"report of {len(result_files)} file(s): {', '.join(p.name for p in result_files)}")
    click.echo(f"wrote {out}")
