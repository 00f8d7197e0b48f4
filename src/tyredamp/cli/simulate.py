"""``tyredamp simulate``: test data from the virtual rigs, for the other commands.

``simulate radial`` runs the virtual modal test of the truck tyre
(:func:`tyredamp.virtual.run_modal_test`) and writes its time data (UFF 58
function type 1) or, with ``--frf``, the H1 FRFs estimated from it (function
type 4); ``--truth`` also writes the exact modes as a modes JSON file.
``simulate lateral`` is the rolling-tyre rig; it is the same command as
``tyredamp lateral simulate`` (same options, same output). ``simulate
campaign`` (:mod:`.simulate_campaign`) writes a whole virtual test campaign
and its campaign file for ``tyredamp campaign``. ``simulate rolling``
(:mod:`.simulate_rolling`) records the rolling radial tyre with fixed and
in-tyre sensors.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ..documents.jsonfile import json_text
from ..exceptions import InputError
from ..io import format_of, write_frf, write_timedata
from ..io._safety import atomic_paths, check_distinct, check_output_file
from ._common import (
    OutPath,
    format_option,
    out_file_option,
    parse_drive_points,
    pressure_option,
    seed_option,
    snr_option,
)
from .lateral import lateral_group
from .simulate_campaign import simulate_campaign_command
from .simulate_rolling import simulate_rolling_command

__all__ = ["simulate_group"]


@click.group("simulate")
def simulate_group() -> None:
    """Simulate tests on the built-in virtual tyres and write them as files.

    The files are what a test rig would give (noise included) and feed the
    other commands; the exact answer is known (--truth for the radial test).

    \b
    Example:
      tyredamp simulate radial --out tyre_test.uff --pressure 7.5 --seed 1
      tyredamp simulate radial --out tyre_frf.uff --frf --truth truth.json
      tyredamp simulate lateral --out rig.npz --speed 5 --pressure 1.7
      tyredamp simulate rolling --out rolling.uff --speed 40
      tyredamp simulate campaign --out virtual
    """


@simulate_group.command("radial")
@out_file_option("File to write (.uff/.unv: UFF 58b binary, or .csv, .npz).")
@pressure_option(7.5)
@snr_option()
@seed_option("Noise seed.")
@click.option(
    "--drive-points",
    "drive_points",
    multiple=True,
    metavar="P1,P2,...",
    help="Shaker points (1-16), comma-separated or repeated; one run per point. Default 1.",
)
@click.option(
    "--frf",
    "as_frf",
    is_flag=True,
    help="Write the H1 FRFs (function type 4) instead of the time data (type 1).",
)
@click.option(
    "--periods",
    type=click.IntRange(min=1, max=64),
    default=8,
    show_default=True,
    help="Chirp periods (averages) per drive point, 4 s each.",
)
@click.option(
    "--force-rms",
    "force_rms",
    type=click.FloatRange(min=0, min_open=True),
    default=10.0,
    show_default=True,
    metavar="N",
    help="RMS shaker force, N.",
)
@click.option(
    "--truth",
    "truth_out",
    type=OutPath(dir_okay=False, path_type=Path),
    help="Also write the exact modes of the tyre as a modes JSON (for tyredamp report).",
)
@click.option(
    "--load",
    "load_kn",
    type=click.FloatRange(min=0, max=100),
    default=0.0,
    show_default=True,
    metavar="KN",
    help="Vertical load pressing the tyre on a flat road opposite point 1, kN "
    "(0: the free tyre on a rigid wheel, as in paper 000).",
)
@click.option(
    "--cavity/--no-cavity",
    default=True,
    show_default=True,
    help="Couple the air cavity (first mode near 140 Hz) to the tread band.",
)
@click.option(
    "--splice/--no-splice",
    default=False,
    show_default=True,
    help="Include a tread splice (a 4 cm arc of extra mass, stiffness and loss).",
)
@click.option(
    "--attachment-damping",
    "attachment_damping",
    type=click.FloatRange(min=0),
    default=2.0,
    show_default=True,
    metavar="NS_M",
    help="Local tread loss under each shaker tip, N s/m (the tread between the gauge's "
    "base and the band; 2: 10 g on a 2 x 2 cm tip at 200 Hz).",
)
@click.option(
    "--microphone",
    "microphone_deg",
    type=float,
    default=None,
    metavar="DEG",
    help="Add a rim microphone at this angle (deg, a multiple of 5.625): a last channel P1 "
    "with the cavity's acoustic pressure in Pa (time data only; needs the cavity).",
)
@click.option(
    "--direction",
    type=click.Choice(["radial", "tangential"]),
    default="radial",
    show_default=True,
    help="Drive and measure radially, or along the circumference (the tangential test "
    "that sees the belt's wind-up mode, for tyredamp tyre-model --tangential).",
)
@format_option()
def radial_command(
    out: Path,
    pressure: float,
    snr: float,
    seed: int,
    drive_points: tuple[str, ...],
    as_frf: bool,
    periods: int,
    force_rms: float,
    truth_out: Path | None,
    load_kn: float,
    cavity: bool,
    splice: bool,
    attachment_damping: float,
    microphone_deg: float | None,
    direction: str,
    fmt: str | None,
) -> None:
    """Run the virtual modal test of the truck tyre and write time data or FRFs.

    The virtual 295/80R22.5 tyre (in-plane ring on an elastic foundation) is
    driven radially by a periodic chirp of 0-200 Hz at the drive point(s) and
    the radial accelerations at 16 points (22.5 deg apart) are recorded with
    the forces, sampled at 1024 Hz with noise of the given SNR on every
    channel. Nothing is written when an error occurs.

    \b
    Example:
      tyredamp simulate radial --out tyre_test.uff
      tyredamp simulate radial --out tyre_frf.uff --frf --pressure 9 --snr 30 --seed 2
      tyredamp simulate radial --out mimo.uff --drive-points 1,5 --periods 4
      tyredamp simulate radial --out loaded.uff --load 25 --splice
      tyredamp simulate radial --out with_mic.uff --microphone 0
      tyredamp simulate radial --out tangential.uff --frf --direction tangential
    """
    from ..studies.demo import single_threaded_blas
    from ..studies.radial import frf_from_time, virtual_tyre
    from ..virtual import run_modal_test

    check_output_file(out)
    if truth_out is not None:
        check_output_file(truth_out, option="--truth")
        check_distinct([("--out", out), ("--truth", truth_out)])
    out_format = format_of(out, fmt)
    points = parse_drive_points(drive_points)
    if microphone_deg is not None and (as_frf or not cavity):
        raise InputError(
            "--microphone: expected time data of a tyre with its cavity; the microphone "
            "records pressure, which --frf (motion over force) and --no-cavity leave out"
        )
    tyre = virtual_tyre(
        pressure,
        points,
        load_n=1e3 * load_kn,
        cavity=cavity,
        splice=splice,
        attachment_damping=attachment_damping,
    )
    with single_threaded_blas():
        test = run_modal_test(
            tyre,
            n_periods=periods,
            force_rms=force_rms,
            snr_db=snr,
            seed=seed,
            microphone_deg=microphone_deg,
            direction=direction,  # type: ignore[arg-type]
        )
    truth_text = None if truth_out is None else _truth_text(test, pressure)
    # both files or neither: a replaced --out is put back when --truth fails
    with atomic_paths([out] if truth_out is None else [out, truth_out]) as tmps:
        if as_frf:
            frf = frf_from_time(test.data, "H1")
            write_frf(frf, tmps[0], out_format)
            what = f"FRFs {frf.n_out} x {frf.n_in}, {frf.n_freq} lines (function type 4)"
        else:
            write_timedata(test.data, tmps[0], out_format)
            td = test.data
            what = f"time data, {td.n_channels} channels x {td.n_samples} samples (function type 1)"
        if truth_text is not None:
            tmps[1].write_text(truth_text, encoding="utf-8")
    click.echo(
        f"virtual truck tyre at {pressure:g} bar: {tyre.layout.n_points} points, drive point(s) "
        f"{', '.join(str(p) for p in points)}, {periods} periods of "
        f"{test.period_samples / test.data.sample_rate:g} s at {test.data.sample_rate:g} Hz, "
        f"SNR {snr:g} dB, seed {seed}"
    )
    click.echo(_true_modes_line(test))
    if direction == "tangential":
        click.echo(_windup_line(test.tyre))
    click.echo(_sources_line(test.tyre))
    click.echo(f"wrote {out} ({out_format}, {what})")
    if truth_out is not None:
        click.echo(f"wrote {truth_out} (exact modes, modes JSON)")


def _truth_text(test: Any, pressure: float) -> str:
    """The exact visible modes of a virtual test as a modes JSON text."""
    from ..documents.modes import modes_document

    doc = modes_document(
        {"complex": test.truth.modal_model(_truth_modes(test))},
        source=f"truth: virtual ring tyre at {pressure:g} bar",
        band_hz=test.truth.band,
        frf_kind="receptance",
    )
    return json_text(doc)


def _windup_line(tyre: Any) -> str:
    """``true wind-up (n = 0): ...`` of a tangential test."""
    from ..virtual import windup_truth

    w = windup_truth(tyre)
    return (
        f"true wind-up (n = 0 rotation): {w.frequency_hz:.3f} Hz (zeta {100 * w.damping_ratio:.3f} "
        f"%) with the shaker tip, {w.bare_frequency_hz:.3f} Hz (zeta "
        f"{100 * w.bare_damping_ratio:.3f} %) without; belt inertia {w.inertia:.4g} kg m^2"
    )


def _sources_line(tyre: Any) -> str:
    """``non-proportional damping ...``: the off-diagonal share of C' and its sources."""
    from ..virtual import damping_decomposition

    dd = damping_decomposition(tyre)
    parts = sorted(dd.as_dict().items(), key=lambda kv: -abs(kv[1]))
    load = (
        ""
        if tyre.patch is None
        else (
            f"; hub stiffness {tyre.patch.hub_stiffness / 1e6:.2f} MN/m, "
            f"patch {2e3 * tyre.patch.half_length:.0f} mm"
        )
    )
    return (
        f"non-proportional damping: {100 * dd.offdiagonal_share:.1f} % of the in-band modal "
        "damping is off-diagonal; from "
        + ", ".join(f"{name} {100 * v:.0f} %" for name, v in parts if abs(v) >= 0.005)
        + load
    )


def _true_modes_line(test: Any) -> str:
    """``true modes (Hz): f (zeta %), ...`` of the visible modes."""
    tr = test.truth
    return "true modes (Hz): " + ", ".join(
        f"{tr.frequency_hz[i]:.2f} (zeta {100 * tr.damping_ratio[i]:.2f} %)"
        for i in tr.select(_truth_modes(test))
    )


def _truth_modes(test: Any) -> Any:
    """The truth's modes a test sees: every in-band mode for a tangential one (wind-up too)."""
    tangential = getattr(test.tyre, "measured_direction", "radial") == "tangential"
    return "all" if tangential else "visible"


_LATERAL = lateral_group.commands["simulate"]


def _lateral_callback(**kwargs: Any) -> None:
    assert _LATERAL.callback is not None
    seed = kwargs.get("seed")
    if isinstance(seed, int) and seed < 0:
        # numpy refuses negative seeds; say so in one line like every other input error
        raise InputError(f"--seed: expected an integer >= 0, got {seed}")
    _LATERAL.callback(**kwargs)


simulate_group.add_command(
    click.Command(
        "lateral",
        callback=_lateral_callback,
        params=list(_LATERAL.params),
        help="""Write the lateral accelerance FRF of the virtual rolling-tyre rig.

    The same command as 'tyredamp lateral simulate': the truth is a
    viscoelastic stretched-string tyre with contact length and a 100 kg
    wheel; the FRF covers 0.25-9 Hz with 3 % noise per line.

    \b
    Example:
      tyredamp simulate lateral --out rig.npz --speed 5 --pressure 1.7
      tyredamp simulate lateral --out rig_axle.uff --speed 10 --pressure 2.4 --force axle
    """,
        short_help="Write the lateral FRF of the virtual rolling-tyre rig.",
    )
)
simulate_group.add_command(simulate_campaign_command)
simulate_group.add_command(simulate_rolling_command)
