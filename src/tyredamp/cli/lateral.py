"""``tyredamp lateral``: fit lateral tyre models to an FRF, simulate the virtual rig.

``tyredamp lateral fit FRF_FILE --out LATERAL_JSON`` fits the chosen models
(default the paper's four: classic, Maxwell, visco-plastic, proposed
hysteretic) to the lateral accelerance in ``FRF_FILE`` (UFF, CSV or NPZ, read
with :func:`tyredamp.io.read_frf`), prints the ranking table and writes the
JSON below. ``tyredamp lateral simulate --out FILE`` writes a noisy FRF of the
virtual rolling-tyre rig (:mod:`tyredamp.lateral.rig`) with
:func:`tyredamp.io.write_frf`; its ``meta`` carries the speed, force and
wheel mass, which ``fit`` uses when the options are not given.

LATERAL_JSON layout (version 1; SI units; non-finite numbers as ``null``)::

    {
      "tyredamp": "lateral-fit", "version": 1,
      "input": {"file": str, "kind": str, "n_lines": int, "band_hz": [lo, hi]},
      "conditions": {"speed_m_s": float|null, "speed_kmh": float|null,
                     "force": "ground"|"axle", "wheel_mass_kg": float,
                     "pressure_bar": float|null (from the FRF's meta)},
      "criterion": "bic"|"aic",
      "order": [model names, best first],
      "table": [{"rank", "model", "n_params", "rss", "aic", "bic", "delta",
                 "weight", "amplitude_error_pct", "amplitude_bias_pct"}, ...],
      "reasons": [one sentence per model],
      "fits": [{"model", "label", "params": {name: value}, "stderr": {name: value},
                "units": {name: unit}, "conditions": {...}, "derived": {...},
                "n_params", "n_lines", "rss", "residual_rms", "aic", "bic",
                "amplitude_error", "amplitude_bias", "weights", "force",
                "wheel_mass_kg", "speed_m_s", "message"}, ...]
    }

``amplitude_error`` is the paper's Table 1 figure as defined in
:mod:`tyredamp.lateral.fit`: the mean over the fitted lines of
``| |A_model| - |A_meas| | / |A_meas|`` (a fraction; the table shows %), and
``amplitude_bias`` its signed version (positive: over-estimation).
"""

from __future__ import annotations

import math
from pathlib import Path

import click

from ..exceptions import InputError
from ..io import FORMATS, read_frf, write_frf
from ..io._atomic import atomic_path
from ..io.jsonfile import json_text
from ..lateral.fit import DEFAULT_MODELS, LateralData, rank_models
from ..lateral.models import MODELS, get_model_class
from ..lateral.rig import KMH, VirtualLateralRig
from ._common import out_file_option, seed_option

__all__ = ["lateral_group"]


def _model_list(values: tuple[str, ...]) -> list[str]:
    names: list[str] = []
    for v in values:
        names += [s.strip() for s in v.split(",") if s.strip()]
    if not names:
        return list(DEFAULT_MODELS)
    return [get_model_class(n).name for n in names]


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
    type=int,
    default=(0, 0),
    show_default=True,
    metavar="OUT IN",
    help="Output and input positions of the FRF to fit.",
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
    channel: tuple[int, int],
) -> None:
    """Fit lateral tyre models to a measured FRF and rank them.

    FRF_FILE holds lateral acceleration (or displacement/velocity) per lateral
    force at the ground (contact patch) or at the wheel axle.

    \b
    Example:
      tyredamp lateral fit rig.npz --out lateral.json --models proposed,maxwell \\
          --speed 5 --force axle --wheel-mass 100
    """
    frf = read_frf(frf_file)
    names = _model_list(models)
    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed: expected a speed > 0 km/h, got {speed}")
    data = LateralData.from_frf(
        frf,
        speed=None if speed is None else speed * KMH,
        force=force,  # type: ignore[arg-type]
        wheel_mass=wheel_mass,
    )
    ranking = rank_models(
        data,
        names,
        criterion=criterion,  # type: ignore[arg-type]
        band=band,
        weights=weights,
        channel=channel,
    )
    best = ranking.best
    doc = {
        "tyredamp": "lateral-fit",
        "version": 1,
        "input": {
            "file": str(frf_file),
            "kind": frf.kind,
            "n_lines": best.n_lines,
            "band_hz": [float(best.frequency[0]), float(best.frequency[-1])],
        },
        "conditions": {
            "speed_m_s": data.speed,
            "speed_kmh": None if data.speed is None else data.speed / KMH,
            "force": data.force,
            "wheel_mass_kg": data.wheel_mass,
            "pressure_bar": frf.meta.get("pressure_bar"),
        },
        **ranking.to_dict(),
    }
    with atomic_path(out) as tmp:
        tmp.write_text(json_text(doc, indent=2), encoding="utf-8")
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
    a 100 kg wheel (see tyredamp.lateral.rig); the FRF covers 0.25-9 Hz.

    \b
    Example:
      tyredamp lateral simulate --out rig_axle.npz --speed 10 --pressure 2.4 \\
          --force axle --seed 3
    """
    rig = VirtualLateralRig() if noise is None else VirtualLateralRig(relative_noise=noise)
    data = rig.measure(speed, pressure, force, seed)  # type: ignore[arg-type]
    path = write_frf(data.frf, out, fmt)
    truth = data.frf.meta["truth"]["params"]
    click.echo(
        f"virtual rig: {data.label}, {force} force, wheel mass {rig.wheel_mass:g} kg, "
        f"{data.frf.n_freq} lines {data.frf.frequency[0]:g}-{data.frf.frequency[-1]:g} Hz; "
        "truth " + ", ".join(f"{k} = {v:.4g}" for k, v in truth.items())
    )
    click.echo(f"wrote {path}")
