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

import click

from ..documents.lateral import write_lateral_fit
from ..exceptions import InputError
from ..io import FORMATS, format_of, read_frf, write_frf
from ..io._safety import check_output_file
from ..lateral.fit import DEFAULT_MODELS
from ..lateral.models import MODELS, get_model_class
from ..studies.lateral import fit_models, lateral_data
from ..virtual.lateral_rig import KMH, VirtualLateralRig
from ._common import out_file_option, seed_option

__all__ = ["lateral_group"]


def _model_list(values: tuple[str, ...]) -> list[str]:
    names: list[str] = []
    for v in values:
        names += [s.strip() for s in v.split(",") if s.strip()]
    if not names:
        return list(DEFAULT_MODELS)
    return [get_model_class(n).name for n in names]


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
@click.option(
    "--models",
    "models",
    multiple=True,
    metavar="NAMES",
    help=f"Models to compare, comma-separated or repeated; from {sorted(MODELS)} "
    "or aliases (proposed, lines ...). Default: classic, maxwell, viscoplastic, "
    "hysteretic.",
)
@click.option(
    "--speed",
    type=float,
    metavar="KMH",
    help="Travel speed in km/h (default from the file's meta). Needed by the "
    "relaxation and string models.",
)
@click.option(
    "--wheel-mass",
    "wheel_mass",
    type=float,
    metavar="KG",
    help="Wheel mass for axle-force FRFs, kg (default from the file's meta, else 0).",
)
@click.option(
    "--force",
    type=click.Choice(["ground", "axle"]),
    help="Force the FRF refers to (default from the file's meta, else ground).",
)
@click.option(
    "--band", nargs=2, type=float, metavar="F_LO F_HI", help="Fit only lines in this band (Hz)."
)
@click.option(
    "--weights",
    type=click.Choice(["auto", "relative", "coherence", "uniform"]),
    default="auto",
    show_default=True,
    help="Residual weights: auto = coherence if the FRF has it, else relative.",
)
@click.option(
    "--criterion",
    type=click.Choice(["bic", "aic"]),
    default="bic",
    show_default=True,
    help="Information criterion used for the ranking.",
)
@click.option(
    "--channel",
    nargs=2,
    type=click.IntRange(min=1),
    default=None,
    metavar="OUT IN",
    help="Output and input of the FRF to fit, counted from 1 like every other option "
    "(needed when the file holds more than one FRF).",
)
def fit_command(
    frf_file: Path,
    out: Path,
    models: tuple[str, ...],
    speed: float | None,
    wheel_mass: float | None,
    force: str | None,
    band: tuple[float, float] | None,
    weights: str,
    criterion: str,
    channel: tuple[int, int] | None,
) -> None:
    """Fit lateral tyre models to a measured FRF and rank them.

    FRF_FILE holds lateral acceleration (or displacement/velocity) per lateral
    force at the ground (contact patch) or at the wheel axle.

    \b
    Example:
      tyredamp lateral fit rig.npz --out lateral.json --models proposed,maxwell \\
          --speed 5 --force axle --wheel-mass 100
    """
    check_output_file(out, [frf_file])
    frf = read_frf(frf_file)
    names = _model_list(models)
    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed: expected a speed > 0 km/h, got {speed}")
    if channel is not None and (channel[0] > frf.n_out or channel[1] > frf.n_in):
        raise InputError(
            f"--channel: expected an output 1..{frf.n_out} and an input 1..{frf.n_in} of "
            f"{frf_file}, got {channel[0]} {channel[1]}"
        )
    if channel is None and frf.n_out * frf.n_in != 1:
        raise InputError(
            f"--channel: {frf_file} holds {frf.n_out}x{frf.n_in} FRFs and a lateral fit takes "
            "one; choose it with --channel OUT IN (counted from 1)"
        )
    data = lateral_data(
        frf,
        speed_kmh=speed,
        force=force,  # type: ignore[arg-type]
        wheel_mass=wheel_mass,
    )
    if data.speed is None:
        need = [n for n in names if "speed" in get_model_class(n).condition_names]
        if need:
            raise InputError(
                f"--speed: the {', '.join(need)} model{'s' if len(need) > 1 else ''} "
                f"need{'' if len(need) > 1 else 's'} the travel speed and {frf_file} does not "
                "store it; give --speed KMH"
            )
    ranking = fit_models(
        data,
        names,
        criterion=criterion,  # type: ignore[arg-type]
        band=band,
        weights=weights,
        channel=None if channel is None else (channel[0] - 1, channel[1] - 1),
    )
    ranking.check()  # no model fits: exit 3 with the reasons, nothing written
    best = ranking.best
    write_lateral_fit(out, ranking, data, source=str(frf_file), frf_kind=frf.kind)
    assumed = []
    if force is None and "force" not in frf.meta:
        assumed.append(
            "the file does not say which force the FRF refers to: ground assumed "
            "(give --force axle for an axle-force FRF)"
        )
    if wheel_mass is None and "wheel_mass_kg" not in frf.meta and data.force == "axle":
        assumed.append("the file gives no wheel mass: 0 kg assumed (give --wheel-mass KG)")
    for a in assumed:
        click.echo(f"note: {a}", err=True)
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
@click.option(
    "--pressure",
    type=float,
    default=1.7,
    show_default=True,
    metavar="BAR",
    help="Inflation pressure, bar.",
)
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
@click.option(
    "--format", "fmt", type=click.Choice(FORMATS), help="File format (default from the extension)."
)
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
