"""``tyredamp damping``: the damping matrix from identified complex modes (spec step 7).

Reads a modes JSON file (``{"kind": "modes", "models": {"complex": {...},
"real": {...}}}``, each model in the layout of
:meth:`tyredamp.modal.ModalModel.to_dict`; read by
:func:`tyredamp.modal.io.read_modes_json`), identifies the damping with
:func:`tyredamp.damping.identify_damping` and writes a damping JSON file.

Damping JSON schema (``"kind": "damping"``, ``"version": 1``; full
description in ``docs/damping-json.md``)::

    {"kind": "damping", "version": 1,
     "method": "first" | "improved" | "refined", "normalised": bool,
     "modes": {"frequency_hz": [m], "damping_ratio": [m], "poles": [[re, im]] x m},
     "points": [{"node", "direction", "angle_deg", "name"}] x N,
     "modal": m x m (C', 1/s), "modal_symmetric": m x m,
     "physical": N x N (C, N s/m), "physical_symmetric": N x N,
     "mass": N x N (kg), "stiffness": N x N (N/m), "basis": N x m (1/sqrt(kg)),
     "lancaster_physical": N x N | null,
     "std": {"modal": m x m, "physical": N x N} | {},
     "uncertainty": {"method": "monte_carlo", "n_samples", "n_failed", "seed"} | {},
     "diagnostics": {...}, "proportional": {...}, "findings": [str],
     "meta": {"source": path, "model": "complex" | "real", ...}}
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from ..damping import METHODS, DampingModel, identify_damping
from ..exceptions import InputError
from ..io._common import check_input_file
from ..io.jsonfile import write_json
from ..modal.io import read_modes_json
from ._common import out_file_option, seed_option

__all__ = ["damping_command", "damping_summary"]


def damping_summary(dm: DampingModel) -> list[str]:
    """Text summary: size, C' diagonal and largest coupling, diagnostics, findings."""
    d = dm.diagnostics
    cp = dm.modal
    off = cp - np.diag(np.diag(cp))
    k, n = np.unravel_index(int(np.argmax(np.abs(off))), off.shape) if dm.n_modes > 1 else (0, 0)
    rows = [
        f"damping ({dm.method}): {dm.n_modes} modes at {dm.n_points} points",
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


@click.command("damping")
@click.argument("modes_json", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("Damping JSON file to write.")
@click.option(
    "--method",
    type=click.Choice(METHODS),
    default="improved",
    show_default=True,
    help="first: eq. [16]; improved: eq. [18]; refined: bias-corrected (exact for "
    "consistent modes).",
)
@click.option(
    "--model",
    "model_name",
    default="complex",
    show_default=True,
    help="Which model of the modes file to use (complex modes carry the coupling).",
)
@click.option(
    "--samples",
    type=click.IntRange(min=0),
    default=200,
    show_default=True,
    help="Monte Carlo samples for the standard errors (0 to skip).",
)
@seed_option("Monte Carlo seed.")
@click.option(
    "--no-normalise",
    is_flag=True,
    help="Skip the alpha_n^(n) = 1 phase normalisation of the complex shapes.",
)
def damping_command(
    modes_json: Path,
    out: Path,
    method: str,
    model_name: str,
    samples: int,
    seed: int,
    no_normalise: bool,
) -> None:
    """Identify the viscous damping matrix from the complex modes in MODES_JSON.

    MODES_JSON is a modes JSON file (tyredamp modal) or a UFF file (.uff,
    .unv) of data sets 55 from another program (real or complex modes,
    scaled by their modal mass or modal A; see tyredamp.io.uff55).

    Writes C' (modal coordinates) and C, M, K at the measured points, the
    point labels, diagnostics (symmetry, definiteness, truncation), the best
    proportional models, Monte Carlo standard errors and plain-English
    findings to --out (JSON, schema in docs/damping-json.md). A summary is
    printed. Nothing is written when an error occurs.

    \b
    Example:
      tyredamp damping tyre_modes.json --out tyre_damping.json
      tyredamp damping tyre_modes.json -o damping.json --method refined --samples 500
    """
    if out.resolve() == modes_json.resolve():
        raise InputError(f"--out: {out} is the input file; choose another name")
    path = check_input_file(modes_json)
    if path.suffix.lower() in (".uff", ".unv", ".uf"):
        from ..io.uff55 import read_uff55

        uff_model = read_uff55(path)
        models = {uff_model.mode_kind: uff_model}
    else:
        models = read_modes_json(path)
    if model_name not in models:
        raise InputError(f"--model: {modes_json} holds models {sorted(models)}, not {model_name!r}")
    meta: dict[str, Any] = {"source": str(modes_json), "model": model_name}
    dm = identify_damping(
        models[model_name],
        method,  # type: ignore[arg-type]
        normalise=not no_normalise,
        n_samples=samples,
        seed=seed,
        meta=meta,
    )
    write_json(dm.to_dict(), out)
    for row in damping_summary(dm):
        click.echo(row)
    click.echo(f"wrote {out}")
