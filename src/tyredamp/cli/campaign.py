"""``tyredamp campaign``: every test of a campaign file, on Dask, with modes tracked."""

from __future__ import annotations

import importlib.util
import math
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
    type=click.IntRange(min=1, max=4096),
    help="Local worker processes (default: the usable cores).",
)
@click.option("--serial", is_flag=True, help="Run in this process, without worker processes.")
@click.option(
    "--dask",
    "use_dask",
    is_flag=True,
    help="Run on a new local Dask cluster (127.0.0.1 only, no dashboard) instead of the "
    "local process pool.",
)
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on an existing, trusted dask.distributed cluster: tcp://host:8786 or "
    "tls://host:8786. Its scheduler and workers can run code in this process "
    "(docs/campaign.md).",
)
@click.option(
    "--tls-ca",
    type=click.Path(path_type=Path),
    metavar="FILE",
    help="tls:// scheduler: the CA certificate (PEM) that signed the cluster's certificates.",
)
@click.option(
    "--tls-cert",
    type=click.Path(path_type=Path),
    metavar="FILE",
    help="tls:// scheduler: this client's certificate (PEM), signed by the cluster's CA.",
)
@click.option(
    "--tls-key",
    type=click.Path(path_type=Path),
    metavar="FILE",
    help="tls:// scheduler: the private key of --tls-cert (PEM; default: in that file).",
)
@click.option(
    "--connect-timeout",
    type=click.FloatRange(min=0.1, max=3600.0),
    default=10.0,
    show_default=True,
    metavar="SECONDS",
    help="--scheduler: time to connect and get the scheduler's greeting.",
)
@click.option(
    "--worker-timeout",
    type=click.FloatRange(min=0.1, max=86400.0),
    default=60.0,
    show_default=True,
    metavar="SECONDS",
    help="--scheduler: time to wait for a worker to join the cluster.",
)
@click.option("--no-report", is_flag=True, help="Skip the HTML report.")
def campaign_command(
    campaign_file: Path,
    out: Path | None,
    workers: int | None,
    serial: bool,
    use_dask: bool,
    scheduler: str | None,
    tls_ca: Path | None,
    tls_cert: Path | None,
    tls_key: Path | None,
    connect_timeout: float,
    worker_timeout: float,
    no_report: bool,
) -> None:
    """Process every test of CAMPAIGN_FILE and track the modes across conditions.

    CAMPAIGN_FILE (TOML, docs/campaign.md) lists the test files (globs
    allowed) with their conditions (tyre, pressure, load, speed,
    temperature) and the processing settings per study. Each test runs
    through the same steps as the single-test commands (modal, damping;
    lateral fit), in parallel on local processes by default (--serial: in
    this process; --dask or --scheduler: on Dask). Each step's result is
    cached in DIR/cache by the hash of its input file, settings and tyredamp
    version: a rerun recomputes only what changed, and an interrupted
    campaign resumes; when nothing changed, the outputs are kept as they
    are. A test that fails is reported with its reason and does
    not stop the others (exit code 1 when any failed, after every result is
    written). A step that cannot run on a test's data (e.g. the damping
    matrix of a test with one response point) is skipped with its reason,
    and the test's other results are kept. Writes the tidy mode table (Parquet and CSV), the mode
    families' trends, each test's documents and report.html. An output file
    edited since the campaign wrote it is never replaced.

    \b
    Example:
      tyredamp simulate campaign --out virtual --quick
      tyredamp campaign virtual/campaign.toml --out results --workers 2
    """
    from ..campaign.spec import load_campaign

    for name, value in (
        ("--connect-timeout", connect_timeout),
        ("--worker-timeout", worker_timeout),
    ):
        if not math.isfinite(value):
            raise InputError(f"{name}: expected a number of seconds, got {value}")
    mode = _mode(serial, use_dask, scheduler, workers, (tls_ca, tls_cert, tls_key))
    _need(["pyarrow"] if mode in ("serial", "local") else ["pyarrow", "dask", "distributed"])
    client = None
    if mode == "scheduler":
        from ..campaign.cluster import parse_scheduler, scheduler_security

        address = parse_scheduler(scheduler or "")
        security = scheduler_security(address, tls_ca, tls_cert, tls_key)
    campaign = load_campaign(campaign_file)
    out_dir = out if out is not None else campaign.output
    if out_dir is None:
        raise InputError(f"--out: not given and {campaign_file} has no 'output'")
    from ..campaign.outputs import check_campaign_output

    check_campaign_output(out_dir, [campaign_file, *(t.path for t in campaign.tests)])
    if mode == "scheduler":
        from ..campaign.cluster import connect_scheduler

        client = connect_scheduler(address, security, connect_timeout, worker_timeout)
    try:
        _run(campaign, out_dir, mode, workers, client, no_report)
    finally:
        if client is not None:
            client.close()


def _mode(
    serial: bool,
    use_dask: bool,
    scheduler: str | None,
    workers: int | None,
    tls: tuple[Path | None, ...],
) -> str:
    chosen = [n for n, on in (("--serial", serial), ("--dask", use_dask)) if on]
    if scheduler is not None:
        chosen.append("--scheduler")
    if len(chosen) > 1:
        raise InputError(f"{chosen[0]} and {chosen[1]}: choose one")
    if serial and workers is not None:
        raise InputError("--serial and --workers: choose one")
    if scheduler is not None and workers is not None:
        raise InputError("--scheduler and --workers: choose one (the cluster has its workers)")
    if scheduler is None and any(x is not None for x in tls):
        raise InputError("--tls-ca, --tls-cert and --tls-key go with --scheduler tls://...")
    if scheduler is not None:
        return "scheduler"
    return "serial" if serial else ("dask" if use_dask else "local")


def _run(
    campaign: Any, out_dir: Path, mode: str, workers: int | None, client: Any, no_report: bool
) -> None:
    from ..campaign.manifest import begin_outputs, outputs_key, reusable_summary, seal_outputs
    from ..campaign.outputs import write_outputs
    from ..campaign.runner import run_tests

    progress = _Progress(sys.stderr.isatty())
    t0 = time.perf_counter()
    try:
        runs = run_tests(
            campaign,
            out_dir,
            mode=mode,  # type: ignore[arg-type]
            workers=workers,
            client=client,
            on_start=progress.start,
            on_outcome=progress.update,
            on_warning=lambda text: click.echo(f"tyredamp: warning: {text}", err=True),
        )
    finally:
        progress.stop()
    key = outputs_key(campaign, runs, not no_report)
    s = reusable_summary(out_dir, key)
    kept = s is not None
    if s is None:
        begin_outputs(out_dir)
        results = write_outputs(campaign, runs, out_dir, report=not no_report)
        if not no_report:
            from ..report.campaign import write_campaign_report

            write_campaign_report(results, out_dir)
        seal_outputs(out_dir, key)
        s = results.summary
    dt = time.perf_counter() - t0
    computed = sum(len(r.computed) for r in runs)
    reused = sum(len(r.reused) for r in runs)
    partial = f" ({s['n_partial']} with skipped steps)" if s["n_partial"] else ""
    checks = f"; {s['n_checks_failed']} with a failed quality check" if s["n_checks_failed"] else ""
    click.echo(
        f"campaign {campaign.name}: {s['n_tests']} tests, {s['n_ok']} ok{partial}, "
        f"{s['n_failed']} failed{checks}; "
        f"{computed} steps computed, {reused} from the cache; "
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
    if kept:
        click.echo(f"{out_dir}/: nothing changed since the last run; the outputs are kept")
    else:
        click.echo(
            f"wrote {out_dir}/ (modes.parquet, modes.csv, steps.csv, trends.csv, campaign.json"
            + ("" if no_report else ", report.html")
            + ")"
        )
    if s["n_failed"]:
        # everything else is written; the exit code tells scripts that some tests failed
        click.get_current_context().exit(EXIT_FAILED_TESTS)
