"""``tyredamp demo``: both studies on the built-in virtual tyres, report in a directory."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

if TYPE_CHECKING:
    from ..studies.results import DemoResult

from ._common import OutPath

__all__ = ["demo_command", "demo_summary_rows"]


def _damping_row(dmp: dict[str, Any]) -> str:
    """C' against the truth; led by the modes the points can tell apart when some cannot."""
    det = dmp.get("modal_error_determined")
    if dmp.get("undetermined_pairs") and det is not None:
        return (
            f"{100 * det:.3g} % on the modes the points can tell apart; the pairs whose "
            "shapes coincide at the points (e.g. the band's and the air's n = 1) are "
            f"undetermined (all modes: {100 * dmp['modal_error']:.3g} %, "
            f"{dmp['definiteness_modal']})"
        )
    return (
        f"{100 * dmp['modal_error']:.3g} % (symmetric part "
        f"{100 * dmp['modal_error_symmetric']:.3g} %), {dmp['definiteness_modal']}"
    )


def demo_summary_rows(result: DemoResult, doc: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows of the summary table printed at the end: (quantity, value)."""
    rad, lat = doc["radial"], doc["lateral"]
    r = result.radial
    rows = [
        (
            "radial pressures",
            ", ".join(
                f"{p['pressure_bar']:g} bar: {sum(1 for m in p['modes'] if m['complex'])}/"
                f"{sum(1 for m in p['modes'] if m['true'])} modes"
                for p in rad["pressures"]
            ),
        ),
        (
            f"RMSD real / complex ({rad['pressure_bar']:g} bar)",
            f"{rad['rmsd_real']:.3g} / {rad['rmsd_complex']:.3g} (ratio {rad['rmsd_ratio']:.3g})",
        ),
        (
            "checks",
            f"linearity {'PASS' if r.linearity.passed else 'FAIL'} "
            f"{100 * r.linearity.figure:.2g} %, reciprocity "
            f"{'PASS' if r.reciprocity.passed else 'FAIL'} {100 * r.reciprocity.figure:.2g} %, "
            f"quality {'PASS' if r.quality.passed else 'FAIL'} {100 * r.quality.figure:.2g} % "
            "low-coherence lines",
        ),
        *_verdict_rows(doc),
        ("damping C' vs truth", _damping_row(rad["damping"])),
        ("tyre model", _tyre_model_row(rad["tyre_model"])),
        (
            "lateral ranking",
            " > ".join(x["model"] for x in lat["ranking"]),
        ),
        (
            "corner frequency f0",
            ", ".join(
                f"{c['corner_frequency_hz']:.3g} Hz at {c['label']} (its C_r = "
                f"{c['road_damping']['ratio']:.3g} x the rig's C_alpha/V)"
                for c in lat["conditions"]
            ),
        ),
        (
            f"{lat['time_response']['frequency_hz']:g} Hz response error",
            ", ".join(
                f"{k} {100 * v:.3g} %" for k, v in lat["time_response"]["relative_error"].items()
            )
            + f" (rig's exact response {100 * lat['time_response']['truth_error']:.3g} %: "
            "the rest is model error)",
        ),
    ]
    # the warnings that are not failures shown above, each with its stage
    warns = [w for w in doc.get("warnings", []) if w["severity"] == "warning"]
    for k, w in enumerate(warns):
        rows.append((f"warning {k + 1} ({w['stage']})", w["message"]))
    return rows


def _tyre_model_row(tm: dict[str, Any]) -> str:
    """EI and the tension and k_r at the first pressure beside the truth, or FAILED and why."""
    from ..studies.tyremodel import ring_verdict_groups

    if tm["status"] != "ok":
        return f"FAILED: {tm['error']}"
    par = {p["name"]: p for p in tm["parameters"]}
    pp = tm["per_pressure"][0] if tm["per_pressure"] else None
    items = [("EI", par.get("EI"))]
    if pp is not None:
        items += [(f"T0 {pp['pressure_bar']:g} bar", pp["T0"]), ("k_r", pp["k_r"])]
    parts = [
        f"{name} {100 * c['relative_gap']:+.2g} %"
        for name, c in items
        if c is not None and c["relative_gap"] is not None
    ]
    return (
        f"flexible ring at {len(tm['pressures_bar'])} pressures, against the virtual tyre: "
        + ", ".join(parts)
        + "".join(
            f"; {what}: {', '.join(names)}"
            for what, names in ring_verdict_groups(tm).items()
            if names
        )
    )


def _verdict_rows(doc: dict[str, Any]) -> list[tuple[str, str]]:
    """One row per finding of the fits: each genuine failure alone (``FAILED`` and why),
    the fits that share an outcome and its cause together (``expected`` and why, or
    ``within noise``); the failed checks and tyre model have rows of their own."""
    from ..studies.findings import outcome_groups

    return [(g.title, g.detail) for g in outcome_groups(doc) if not g.stage]


@click.command("demo")
@click.option(
    "--out",
    "-o",
    "out",
    default="tyredamp-demo",
    show_default=True,
    type=OutPath(path_type=Path),
    metavar="DIR",
    help="Directory to write (replaced only if empty or an earlier demo output).",
)
@click.option(
    "--quick",
    is_flag=True,
    help="Reduced setting: 2 radial pressures, 4 averages, 1 lateral pressure (about a third "
    "of the time).",
)
@click.option(
    "--seed",
    type=click.IntRange(min=0),
    default=0,
    show_default=True,
    help="Seed of every noise generator (same seed, same results).",
)
def demo_command(out: Path, quick: bool, seed: int) -> None:
    """Run both studies on the built-in virtual tyres and write a report.

    Radial study (Popov & Geng 2005): modal test of the virtual truck tyre at 7.5
    bar and two other pressures, FRFs, linearity (two force levels) and
    reciprocity (two drive points) checks, real- and complex-mode fits with
    RMSD, damping matrix. Lateral study (Peng et al.): the rolling-tyre rig at
    5 and 10 km/h and 1.28, 1.7 and 2.4 bar, every model fitted and ranked,
    corner frequency, vehicle model and the 2.73 Hz time response. Every
    identified value is shown beside the truth of the virtual tyre.

    Writes OUT/report.html (self-contained), OUT/results.json, OUT/figures/*.png,
    OUT/data/*.uff (UFF 58) and the modes and damping JSON files; nothing is
    left behind when an error occurs. Progress goes to stderr (on a
    terminal), a summary table to stdout.

    \b
    Example:
      tyredamp demo
      tyredamp demo --out demo-quick --quick --seed 3
    """
    from ..io._safety import private_matplotlib_config

    with private_matplotlib_config():
        _demo(out, quick, seed)


def _demo(out: Path, quick: bool, seed: int) -> None:
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    from ..report.demo import check_output_dir, save_demo
    from ..studies.demo import DemoSettings, run_demo, single_threaded_blas
    from ..studies.document import build_results

    check_output_dir(out)
    settings = DemoSettings.quick_preset(seed) if quick else DemoSettings.full(seed)
    err = Console(stderr=True)
    t0 = time.perf_counter()
    with (
        single_threaded_blas(),
        Progress(
            TextColumn("{task.description:<62}"),
            BarColumn(bar_width=24),
            TextColumn("{task.fields[count]}"),  # blank until the total is known
            TimeElapsedColumn(),
            console=err,
            disable=not err.is_terminal,
        ) as prog,
    ):
        task = prog.add_task("starting", total=None, count="")

        def report(desc: str, done: int, total: int) -> None:
            prog.update(
                task, description=desc, completed=done, total=total, count=f"{done}/{total}"
            )

        result = run_demo(settings, report)
        wtask = prog.add_task("writing", total=None, count="")

        def report_w(desc: str, done: int, total: int) -> None:
            prog.update(
                wtask,
                description=f"writing {desc}",
                completed=done,
                total=total,
                count=f"{done}/{total}",
            )

        files = save_demo(result, out, report_w)
    wall = time.perf_counter() - t0
    doc = build_results(result)
    table = Table(title=f"tyredamp demo{' (quick)' if quick else ''}, seed {seed}", box=None)
    table.add_column("result", style="bold", no_wrap=True)
    table.add_column("value")
    for k, v in demo_summary_rows(result, doc):
        table.add_row(k, v)
    table.add_row("time", f"{wall:.1f} s ({result.elapsed_s:.1f} s computing)")
    table.add_row("files", f"{len(files)} in {out}")
    table.add_row("report", str(files["report.html"].resolve()))
    Console(soft_wrap=False).print(table)
