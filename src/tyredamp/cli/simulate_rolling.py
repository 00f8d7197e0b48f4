"""``tyredamp simulate rolling``: a recording of the virtual rolling tyre.

Calls :func:`tyredamp.virtual.rolling_test` and writes its time data through
the file writers; ``--truth`` also writes the rolling truth (the forward and
backward waves in the rotating and the fixed frame) as JSON.
"""

from __future__ import annotations

import math
from pathlib import Path

import click

from ..documents.jsonfile import json_text
from ..exceptions import InputError
from ..io import format_of, write_timedata
from ..io._safety import atomic_paths, check_distinct, check_output_file
from ._common import (
    OutPath,
    format_option,
    out_file_option,
    pressure_option,
    seed_option,
    snr_option,
)

__all__ = ["simulate_rolling_command"]


def _check_speed(speed: float, pressure_bar: float) -> tuple[float, object]:
    """The speed (km/h) checked against NaN, sign and the tyre's critical speed."""
    from ..virtual import RingTyreParameters, critical_speed_kmh

    params = RingTyreParameters().with_pressure(pressure_bar * 1e5)
    if not math.isfinite(speed) or speed < 0:
        raise InputError(f"--speed: expected a finite speed >= 0 km/h, got {speed:g}")
    v_c = critical_speed_kmh(params)
    if speed >= v_c:
        raise InputError(
            f"--speed: expected a speed below the critical (standing-wave) speed of the tyre at "
            f"{pressure_bar:g} bar, {v_c:.0f} km/h; got {speed:g} km/h"
        )
    return speed, params


@click.command("rolling")
@out_file_option("File to write (.uff/.unv: UFF 58b binary, or .csv, .npz).")
@click.option(
    "--speed", type=float, required=True, metavar="KMH", help="Rolling speed, km/h (>= 0)."
)
@pressure_option(7.5)
@click.option(
    "--duration",
    type=click.FloatRange(min=0.5, max=600),
    default=16.0,
    show_default=True,
    metavar="S",
    help="Recorded seconds (1024 samples per second).",
)
@click.option(
    "--sensors",
    type=click.IntRange(min=0, max=64),
    default=16,
    show_default=True,
    help="Fixed sensors around the tyre (equally spaced from the contact point).",
)
@click.option(
    "--tyre-sensors",
    "tyre_sensors",
    type=click.IntRange(min=0, max=16),
    default=1,
    show_default=True,
    help="Sensors inside the tyre, turning with it (equally spaced).",
)
@click.option(
    "--excitation",
    type=click.Choice(["road", "impulse", "chirp"]),
    default="road",
    show_default=True,
    help="Random road force only, or with recorded impulses (one a second) or a chirp.",
)
@click.option(
    "--road-force",
    "road_force",
    type=click.FloatRange(min=0),
    default=100.0,
    show_default=True,
    metavar="N",
    help="RMS of the random road force, N.",
)
@snr_option()
@seed_option("Seed of the road force and the noise.")
@click.option(
    "--truth",
    "truth_out",
    type=OutPath(dir_okay=False, path_type=Path),
    help="Also write the forward and backward waves (both frames) as JSON.",
)
@format_option()
def simulate_rolling_command(
    out: Path,
    speed: float,
    pressure: float,
    duration: float,
    sensors: int,
    tyre_sensors: int,
    excitation: str,
    road_force: float,
    snr: float,
    seed: int,
    truth_out: Path | None,
    fmt: str | None,
) -> None:
    """Record the virtual truck tyre rolling at a speed, with fixed and in-tyre sensors.

    The ring tyre spins at the speed (Coriolis, centrifugal and centrifugal
    tension terms) and a random radial road force acts at the contact point,
    fixed in space. Fixed sensors (A1..) see the material move past them, so
    each wave of wave number n appears shifted by n times the rotation
    frequency: forward waves higher, backward waves lower. In-tyre sensors
    (T1..) see the waves at their rotating-frame frequencies. Speeds at or
    above the tyre's critical speed are refused. Nothing is written when an
    error occurs.

    \b
    Example:
      tyredamp simulate rolling --out rolling.uff --speed 40
      tyredamp simulate rolling --out rolling.npz --speed 80 --excitation impulse --truth waves.json
    """
    from ..studies.demo import single_threaded_blas
    from ..virtual import MeasurementLayout, RingTyre, rolling_test

    v, params = _check_speed(speed, pressure)
    check_output_file(out)
    if truth_out is not None:
        check_output_file(truth_out, option="--truth")
        check_distinct([("--out", out), ("--truth", truth_out)])
    out_format = format_of(out, fmt)
    layout = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    tyre = RingTyre(params, layout, nonproportionality=1.0)  # type: ignore[arg-type]
    with single_threaded_blas():
        test = rolling_test(
            v,
            tyre=tyre,
            n_sensors=sensors,
            rotating_deg=[k * 360.0 / tyre_sensors for k in range(tyre_sensors)],
            duration=duration,
            road_force_rms=road_force,
            known_excitation="none" if excitation == "road" else excitation,  # type: ignore[arg-type]
            snr_db=None if math.isinf(snr) else snr,
            seed=seed,
        )
    truth_text = None
    if truth_out is not None:
        doc = {
            "kind": "rolling_truth",
            "source": f"virtual ring tyre at {pressure:g} bar rolling at {v:g} km/h",
            "speed_kmh": v,
            "rotation_hz": test.truth.rotation_hz,
            "band_hz": list(test.truth.band),
            "waves": test.truth.table(),
        }
        truth_text = json_text(doc)
    with atomic_paths([out] if truth_out is None else [out, truth_out]) as tmps:
        write_timedata(test.data, tmps[0], out_format)
        if truth_text is not None:
            tmps[1].write_text(truth_text, encoding="utf-8")
    td = test.data
    click.echo(
        f"virtual truck tyre at {pressure:g} bar rolling at {v:g} km/h "
        f"(rotation {test.truth.rotation_hz:.3f} Hz): {sensors} fixed and {tyre_sensors} in-tyre "
        f"sensors, {excitation} excitation, {duration:g} s at {td.sample_rate:g} Hz, seed {seed}"
    )
    for n in (2, 3):
        try:
            fw, bw = test.truth.wave(n, "forward"), test.truth.wave(n, "backward")
        except InputError:
            continue
        click.echo(
            f"n = {n}: forward {fw['rotating_hz']:.2f} Hz in the tyre, {fw['fixed_hz']:.2f} Hz "
            f"fixed; backward {bw['rotating_hz']:.2f} Hz in the tyre, {bw['fixed_hz']:.2f} Hz fixed"
        )
    click.echo(f"wrote {out} ({out_format}, {td.n_channels} channels x {td.n_samples} samples)")
    if truth_out is not None:
        click.echo(f"wrote {truth_out} (rolling truth, JSON)")
