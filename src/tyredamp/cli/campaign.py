"""``tyredamp campaign``: every test of a campaign file, on Dask, with modes tracked."""

from __future__ import annotations

import importlib.util
import sys
import time
from pathlib import Path
from typing import Any

import click

from ..exceptions import InputError
from ._common import OutPath

__all__ = ["EXIT_FAILED_TESTS", "campaign_command"]

#: Exit code when the campaign ran but some tests failed (listed on stdout).
EXIT_FAILED_TESTS = 1


def _need(modules: list[str]) -> None:
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise InputError(
            f"the campaign needs {', '.join(missing)}: install tyredamp[campaign] "
            "(pip install 'tyredamp[campaign]')"
        )


class _Progress:
    """Tests done, failed and time left on stderr (rich), when stderr is a terminal."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self._p: Any = None
        self._task: Any = None

    def start(self, total: int) -> None:
        if not self.enabled or total == 0:
            return
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self._p = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("failed {task.fields[failed]}"),
            TimeElapsedColumn(),
            TextColumn("left"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,
        )
        self._p.start()
        self._task = self._p.add_task("tests", total=total, failed=0)

    def update(self, run: Any, done: int, failed: int, total: int) -> None:
        if self._p is not None:
            self._p.update(self._task, completed=done, failed=failed)

    def stop(self) -> None:
        if self._p is not None:
            self._p.stop()


@click.command("campaign")
@click.argument("campaign_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--out",
    "-o",
    "out",
    type=OutPath(path_type=Path),
    help="Output folder (default: 'output' of the campaign file). Holds the cache, so a "
    "rerun recomputes only what changed.",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    help="Local Dask workers (processes, one thread each; default: the cores).",
)
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on an existing dask.distributed cluster (e.g. tcp://host:8786).",
)
@click.option("--serial", is_flag=True, help="Run in this process, without Dask.")
@click.option("--no-report", is_flag=True, help="Skip the HTML report.")
def campaign_command(
    campaign_file: Path,
    out: Path | None,
    workers: int | None,
    scheduler: str | None,
    serial: bool,
    no_report: bool,
) -> None:
    """Process every test of CAMPAIGN_FILE and track the modes across conditions.

    CAMPAIGN_FILE (TOML, docs/campaign.md) lists the test files (globs
    allowed) with their conditions (tyre, pressure, load, speed,
    temperature) and the processing settings per study. Each test runs
    through the same steps as the single-test commands (modal, damping;
    lateral fit), on a local Dask cluster by default. Each step's result is
    cached in DIR/cache by the hash of its input file, settings and tyredamp
    version: a rerun recomputes only what changed, and an interrupted
    campaign resumes. A test that fails is reported with its reason and does
    not stop the others (exit code 1 when any failed, after every result is
    written). A step that cannot run on a test's data (e.g. the damping
    matrix of a test with one response point) is skipped with its reason,
    and the test's other results are kept. Writes the tidy mode table (Parquet and CSV), the mode
    families' trends, each test's documents and report.html.

    \b
    Example:
      tyredamp simulate campaign --out virtual --quick
      tyredamp campaign virtual/campaign.toml --out results --workers 2
    """
    from ..campaign.outputs import check_campaign_output, write_outputs
    from ..campaign.runner import run_tests
    from ..campaign.spec import load_campaign

    if serial and scheduler is not None:
        raise InputError("--serial and --scheduler: choose one")
    if serial and workers is not None:
        raise InputError("--serial and --workers: choose one")
    if scheduler is not None and workers is not None:
        raise InputError("--scheduler and --workers: choose one (the cluster has its workers)")
    _need(["pyarrow"] if serial else ["pyarrow", "dask", "distributed"])
    campaign = load_campaign(campaign_file)
    out_dir = out if out is not None else campaign.output
    if out_dir is None:
        raise InputError(f"--out: not given and {campaign_file} has no 'output'")
    check_campaign_output(out_dir, [campaign_file, *(t.path for t in campaign.tests)])
    mode = "serial" if serial else ("scheduler" if scheduler else "local")
    progress = _Progress(sys.stderr.isatty())
    t0 = time.perf_counter()
    try:
        runs = run_tests(
            campaign,
            out_dir,
            mode=mode,  # type: ignore[arg-type]
            workers=workers,
            scheduler=scheduler,
            on_start=progress.start,
            on_outcome=progress.update,
        )
    finally:
        progress.stop()
    results = write_outputs(campaign, runs, out_dir, report=not no_report)
    if not no_report:
        from ..report.campaign import write_campaign_report

        write_campaign_report(results, out_dir)
    s = results.summary
    dt = time.perf_counter() - t0
    partial = f" ({s['n_partial']} with skipped steps)" if s["n_partial"] else ""
    checks = f"; {s['n_checks_failed']} with a failed quality check" if s["n_checks_failed"] else ""
    click.echo(
        f"campaign {campaign.name}: {s['n_tests']} tests, {s['n_ok']} ok{partial}, "
        f"{s['n_failed']} failed{checks}; "
        f"{s['steps_computed']} steps computed, {s['steps_reused']} from the cache; "
        f"{len(s['families'])} mode families; {dt:.1f} s ({mode})"
    )
    for t in s["tests"]:
        for reason in t["skipped"].values():  # the data cannot give this result: not an error
            click.echo(f"skipped: {t['file']}: {reason}")
    for t in s["tests"]:
        if t["status"] == "failed":
            reason = str(t["reason"])
            # the reason names the file when the reader raised it; say it once
            click.echo(
                f"failed: {reason if reason.startswith(t['file']) else t['file'] + ': ' + reason}"
            )
    click.echo(
        f"wrote {out_dir}/ (modes.parquet, modes.csv, steps.csv, trends.csv, campaign.json"
        + ("" if no_report else ", report.html")
        + ")"
    )
    if s["n_failed"]:
        # everything else is written; the exit code tells scripts that some tests failed
        click.get_current_context().exit(EXIT_FAILED_TESTS)
