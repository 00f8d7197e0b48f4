"""``tyredamp damping``: the damping matrix from identified complex modes (spec step 7).

Reads a modes JSON file (:mod:`tyredamp.documents.modes`), identifies the
damping with :func:`tyredamp.studies.radial.damping_from_modes` and writes a
damping JSON file (layout in :mod:`tyredamp.documents.damping`, full
description in ``docs/damping-json.md``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click
import numpy as np

from ..exceptions import InputError
from ..io._common import check_input_file
from ..io._safety import check_output_file
from ..studies.steps import DampingSettings, DampingStep
from ._common import out_file_option
from ._settings import settings_from_options, settings_options

if TYPE_CHECKING:
    from ..damping import DampingModel

__all__ = ["damping_command", "damping_summary"]


def damping_summary(dm: DampingModel) -> list[str]:
    """Text summary: size, C' diagonal and largest coupling, diagnostics, findings."""
    d = dm.diagnostics
    cp = dm.modal
    off = cp - np.diag(np.diag(cp))
    k, n = np.unravel_index(int(np.argmax(np.abs(off))), off.shape) if dm.n_modes > 1 else (0, 0)
    rows = [
        f"damping ({dm.method}): {dm.n_modes} modes at {dm.n_points} points",
        *_used_rows(dm),
        "modes [Hz]: " + ", ".join(f"{f:.2f}" for f in dm.frequency_hz),
        "C'_nn [1/s]: " + ", ".join(f"{c:.4g}" for c in np.diag(cp)),
    ]
    if dm.n_modes > 1:
        rows.append(
            f"largest coupling C'[{k + 1},{n + 1}] = {cp[k, n]:.4g} 1/s; "
            f"asymmetry {100 * d.symmetry_modal:.2g} %, C' {d.definiteness_modal}"
        )
    rows += [f"- {s}" for s in dm.findings]
    return rows


def _used_rows(dm: DampingModel) -> list[str]:
    """Which modes of the file and which points (inputs of a roving-hammer test) were used."""
    rows = []
    used = dm.meta.get("modes_used")
    avail = dm.meta.get("n_modes_available")
    if isinstance(used, list) and isinstance(avail, int) and len(used) < avail:
        rows.append(f"modes used: {_ranges(used)} of 1-{avail}")
    if dm.meta.get("shape_points") == "inputs":
        rows.append(
            "points: the inputs (" + ", ".join(c.label for c in dm.points) + "); one response, "
            "the excitation roving over the points (shapes by reciprocity)"
        )
    return rows


def _ranges(nums: list[int]) -> str:
    """``[1, 2, 3, 5]`` as ``"1-3, 5"``."""
    out: list[str] = []
    for k in sorted(nums):
        if out and k == int(out[-1].split("-")[-1]) + 1:
            out[-1] = out[-1].split("-")[0] + f"-{k}"
        else:
            out.append(str(k))
    return ", ".join(out)


def _with_models(
    dm: DampingModel, mm: Any, models_text: str, frf_path: Path | None
) -> tuple[DampingModel, list[str]]:
    """The damping-model comparison (``--models``) added to ``dm.meta["damping_models"]``."""
    from dataclasses import replace

    from ..dampmodels.study import models_report, parse_models
    from ..io import read_frf

    try:
        names = parse_models(models_text)
    except InputError as exc:
        raise InputError(f"--{exc}") from None
    frf = read_frf(check_input_file(frf_path)) if frf_path is not None else None
    used = dm.meta.get("modes_used")
    doc, rows = models_report(
        mm,
        names,
        modes=used if isinstance(used, list) else None,
        at_inputs=dm.meta.get("shape_points") == "inputs",
        frf=frf,
    )
    return replace(dm, meta={**dm.meta, "damping_models": doc}), ["damping models:", *rows]


@click.command("damping")
@click.argument("modes_json", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("Damping JSON file to write.")
@settings_options(DampingSettings)
@click.option(
    "--models",
    "models_text",
    default=None,
    metavar="LIST",
    help="Compare damping models, e.g. viscous,hysteretic,exponential,fractional "
    "(also proportional): the Adhikari-Woodhouse part 2 test from the modes and, "
    "with --frf, a likelihood ranking on the FRFs.",
)
@click.option(
    "--frf",
    "frf_path",
    default=None,
    type=click.Path(dir_okay=False, path_type=Path),
    help="The FRF file the modes came from, with the variance of each value (for --models).",
)
def damping_command(
    modes_json: Path,
    out: Path,
    models_text: str | None = None,
    frf_path: Path | None = None,
    **options: Any,
) -> None:
    """Identify the viscous damping matrix from the complex modes in MODES_JSON.

    MODES_JSON is a modes JSON file (tyredamp modal) or a UFF file (.uff,
    .unv) of data sets 55 from another program (real or complex modes,
    scaled by their modal mass or modal A; see tyredamp.io.uff55).

    The shapes are taken where they are: at the responses, or at the
    excitation points of a roving-hammer test (one response, several
    inputs). The points must be at least as many as the modes: choose a
    subset with --modes or --band. Unscaled modes (no drive point in the
    FRFs, no modal A or modal mass in a UFF 55 file) are refused: the
    matrices would have no meaning.

    Writes C' (modal coordinates) and C, M, K at the measured points, the
    point labels, diagnostics (symmetry, definiteness, truncation), the best
    proportional models, Monte Carlo standard errors and plain-English
    findings to --out (JSON, schema in docs/damping-json.md). A summary is
    printed. Nothing is written when an error occurs.

    \b
    Example:
      tyredamp damping tyre_modes.json --out tyre_damping.json
      tyredamp damping tyre_modes.json -o damping.json --method refined --samples 500
      tyredamp damping beam_modes.uff -o beam_damping.json --modes 1-3,5
    """
    check_output_file(out, [modes_json])
    settings = settings_from_options(DampingSettings, options)
    from ..documents.damping import write_damping_json
    from ..documents.modes import read_modes

    models = read_modes(check_input_file(modes_json))
    if settings.model not in models:
        raise InputError(
            f"--model: {modes_json} holds models {sorted(models)}, not {settings.model!r}"
        )
    meta: dict[str, Any] = {"source": str(modes_json), "model": settings.model}
    try:
        dm, _ = DampingStep.run(models, settings, meta)
    except InputError as exc:  # the option's name, as the user typed it
        if str(exc).startswith(("modes:", "band:")):
            raise InputError(f"--{exc}") from None
        raise
    extra_rows: list[str] = []
    if models_text is not None:
        dm, extra_rows = _with_models(dm, models[settings.model], models_text, frf_path)
    elif frf_path is not None:
        raise InputError("--frf: only used with --models")
    write_damping_json(out, dm)
    for row in damping_summary(dm) + extra_rows:
        click.echo(row)
    click.echo(f"wrote {out}")
    from ..damping import no_std_note

    gap = no_std_note("")[: no_std_note("").index("for ")]
    for note in dm.findings:  # the run goes on; the gap is said where scripts look
        if note.startswith(gap):
            click.echo(f"tyredamp: warning: {note}", err=True)
