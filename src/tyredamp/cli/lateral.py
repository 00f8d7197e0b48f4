"""``tyredamp lateral``: fit lateral tyre models to an FRF, simulate the virtual rig.

``tyredamp lateral fit FRF_FILE --out LATERAL_JSON`` fits the chosen models
(default the paper's four: classic, Maxwell, visco-plastic, proposed
hysteretic) to the lateral accelerance in ``FRF_FILE`` (UFF, CSV or NPZ, read
with :func:`tyredamp.io.read_frf`), prints the ranking table and writes the
lateral-fit JSON. ``tyredamp lateral simulate --out FILE`` writes a noisy FRF of the
virtual rolling-tyre rig (:mod:`tyredamp.virtual.lateral_rig`) with
:func:`tyredamp.io.write_frf`; its ``meta`` carries the speed, force and
wheel mass, which ``fit`` uses when the options are not given.

LATERAL_JSON: :mod:`tyredamp.documents.lateral` (layout in its docstring).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ..exceptions import InputError
from ..io import format_of, read_frf, write_frf
from ..io._safety import check_output_file
from ..studies.steps import LateralFitSettings, LateralFitStep
from ._common import format_option, out_file_option, pressure_option, seed_option
from ._settings import settings_from_options, settings_options

__all__ = ["lateral_group"]


#: How the command line names the channel and the speed in messages.
_LABELS = {
    "channel": "--channel",
    "channel_form": "--channel OUT IN",
    "speed": "--speed",
    "speed_form": "give --speed KMH",
}


def _with_unit(name: str, value: float, unit: str) -> str:
    """``"sigma = 0.5933 m"``; dimensionless values (unit ``-``) without a unit."""
    return f"{name} = {value:.4g}" + ("" if unit in ("", "-") else f" {unit}")


@click.group("lateral")
def lateral_group() -> None:
    """Lateral tyre dynamics: fit spring-damper models, simulate the rolling-tyre rig.

    \b
    Example:
      tyredamp lateral simulate --out rig.npz --speed 5 --pressure 1.7
      tyredamp lateral fit rig.npz --out lateral.json
    """


@lateral_group.command("fit")
@click.argument("frf_file", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("JSON file to write (layout in the module docs).")
@settings_options(
    LateralFitSettings, skip=("force", "wheel_mass_kg", "band", "weights", "criterion", "channel")
)
@click.option(
    "--speed",
    type=float,
    metavar="KMH",
    help="Travel speed in km/h (default from the file's meta). Needed by the "
    "relaxation and string models.",
)
@settings_options(LateralFitSettings, skip=("models",))
def fit_command(frf_file: Path, out: Path, speed: float | None, **options: Any) -> None:
    """Fit lateral tyre models to a measured FRF and rank them.

    FRF_FILE holds lateral acceleration (or displacement/velocity) per lateral
    force at the ground (contact patch) or at the wheel axle.

    \b
    Example:
      tyredamp lateral fit rig.npz --out lateral.json --models proposed,maxwell \\
          --speed 5 --force axle --wheel-mass 100
    """
    check_output_file(out, [frf_file])
    settings = settings_from_options(LateralFitSettings, options)
    frf = read_frf(frf_file)
    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed: expected a speed > 0 km/h, got {speed}")
    (ranking, data), _ = LateralFitStep.run(
        frf, settings, speed_kmh=speed, source=str(frf_file), labels=_LABELS
    )
    best = ranking.best
    from ..documents.lateral import write_lateral_fit

    write_lateral_fit(out, ranking, data, source=str(frf_file), frf_kind=frf.kind)
    assumed = []
    if settings.force is None and "force" not in frf.meta:
        assumed.append(
            "the file does not say which force the FRF refers to: ground assumed "
            "(give --force axle for an axle-force FRF)"
        )
    if settings.wheel_mass_kg is None and "wheel_mass_kg" not in frf.meta and data.force == "axle":
        assumed.append("the file gives no wheel mass: 0 kg assumed (give --wheel-mass KG)")
    for a in assumed:
        click.echo(f"note: {a}", err=True)
    from ..virtual.lateral_rig import KMH

    sp = "?" if data.speed is None else f"{data.speed / KMH:g} km/h"
    click.echo(
        f"{frf_file}: {best.n_lines} lines {best.frequency[0]:.3g}-{best.frequency[-1]:.3g} Hz, "
        f"{data.force} force, wheel mass {data.wheel_mass:g} kg, speed {sp}, "
        f"weights {best.weights_name}"
    )
    click.echo(ranking.format_table())
    click.echo(
        "best parameters ("
        + best.name
        + "): "
        + ", ".join(
            f"{n} = {v:.4g} +- {best.stderr[n]:.2g} {u}"
            for n, v, u in zip(
                best.model.param_names, best.params.values(), best.model.param_units, strict=True
            )
        )
    )
    for p in best.problems():
        click.echo(f"note: {p}")
    click.echo(f"wrote {out}")


@lateral_group.command("simulate")
@out_file_option("FRF file to write (.npz, .csv, .uff or .unv).")
@click.option(
    "--speed", type=float, default=5.0, show_default=True, metavar="KMH", help="Travel speed, km/h."
)
@pressure_option(1.7)
@seed_option("Noise seed.")
@click.option(
    "--force",
    type=click.Choice(["ground", "axle"]),
    default="ground",
    show_default=True,
    help="Force the FRF refers to.",
)
@click.option(
    "--noise",
    type=float,
    default=None,
    metavar="REL",
    help="Relative noise per line (default 0.03).",
)
@format_option()
def simulate_command(
    out: Path,
    speed: float,
    pressure: float,
    seed: int,
    force: str,
    noise: float | None,
    fmt: str | None,
) -> None:
    """Write the lateral accelerance FRF of the virtual rolling-tyre rig.

    The truth is a viscoelastic stretched-string tyre with contact length and
    a 100 kg wheel (see tyredamp.virtual.lateral_rig); the FRF covers 0.25-9 Hz.

    \b
    Example:
      tyredamp lateral simulate --out rig_axle.npz --speed 10 --pressure 2.4 \\
          --force axle --seed 3
    """
    check_output_file(out)
    fmt = format_of(out, fmt)
    from ..virtual.lateral_rig import VirtualLateralRig

    rig = VirtualLateralRig() if noise is None else VirtualLateralRig(relative_noise=noise)
    data = rig.measure(speed, pressure, force, seed)  # type: ignore[arg-type]
    path = write_frf(data.frf, out, fmt)
    truth = data.frf.meta["truth"]["params"]
    units = data.frf.meta["truth"].get("units", {})
    click.echo(
        f"virtual rig: {data.label}, {force} force, wheel mass {rig.wheel_mass:g} kg, "
        f"{data.frf.n_freq} lines {data.frf.frequency[0]:g}-{data.frf.frequency[-1]:g} Hz; "
        "truth " + ", ".join(_with_unit(k, v, units.get(k, "")) for k, v in truth.items())
    )
    click.echo(f"wrote {path}")
