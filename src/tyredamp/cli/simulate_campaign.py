"""``tyredamp simulate campaign``: a virtual test campaign with its truth and campaign file."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import click

from ._common import OutPath, parse_drive_points, seed_option

__all__ = ["simulate_campaign_command"]


@click.command("campaign")
@click.option(
    "--out",
    "-o",
    "out",
    required=True,
    type=OutPath(path_type=Path),
    help="Folder to write (data/, truth.json, campaign.toml).",
)
@click.option(
    "--quick",
    is_flag=True,
    help="Small campaign for tests: 2 tyres x 3 pressures x 1 load, 2 lateral speeds.",
)
@click.option(
    "--drive-points",
    "drive_points",
    default="1",
    show_default=True,
    metavar="P1,P2,...",
    help="Shaker points of the radial tests; 1,5 sees both members of the doubled modes.",
)
@click.option(
    "--rolling",
    is_flag=True,
    help="Add output-only rolling tests of tyre 1 at 0, 40, 80 and 120 km/h at every pressure "
    "(the tyre of 'tyredamp simulate rolling': no air cavity, no contact patch).",
)
@seed_option("Seed of the manufacturing scatter and of the noise.")
def simulate_campaign_command(
    out: Path, quick: bool, drive_points: str, rolling: bool, seed: int
) -> None:
    """Write a virtual test campaign of the truck tyre, its truth and a campaign file.

    3 tyres with manufacturing scatter x 5 pressures (6-9 bar) x 3 loads
    (10-30 kN, on the contact patch of the physical virtual tyre of
    'tyredamp simulate radial'; see tyredamp.campaign.virtual):
    radial modal tests as UFF FRF files (16 points, drive point 1, 40 dB);
    the lateral rolling rig at 5, 10 and 15 km/h; truth.json with the exact
    modes of every test and at held-out pressures; campaign.toml for
    'tyredamp campaign'.

    \b
    Example:
      tyredamp simulate campaign --out virtual
      tyredamp campaign virtual/campaign.toml --out results
      tyredamp simulate campaign --out pairs --quick --drive-points 1,5
      tyredamp simulate campaign --out speeds --quick --rolling
    """
    from ..campaign.virtual import VirtualCampaign, check_virtual_output, write_virtual_campaign

    points = parse_drive_points((drive_points,))
    check_virtual_output(out)
    spec = VirtualCampaign.quick(seed) if quick else VirtualCampaign(seed=seed)
    spec = dataclasses.replace(spec, drive_points=points)
    if rolling:
        from ..campaign.virtual_rolling import ROLLING_SPEEDS_KMH

        spec = dataclasses.replace(spec, rolling_speeds_kmh=ROLLING_SPEEDS_KMH)

    def progress(done: int, total: int) -> None:
        if sys.stderr.isatty():
            click.echo(f"\rtest {done}/{total}", nl=done == total, err=True)

    doc = write_virtual_campaign(out, spec, progress)
    n_r = sum(t["study"] == "radial" for t in doc["tests"])
    n_o = sum(t["study"] == "rolling" for t in doc["tests"])
    n_l = len(doc["tests"]) - n_r - n_o
    click.echo(
        f"virtual campaign: {spec.n_tyres} tyres x {len(spec.pressures_bar)} pressures x "
        f"{len(spec.loads_n)} loads = {n_r} radial tests, {n_l} lateral tests"
        + (f", {n_o} rolling tests" if n_o else "")
    )
    click.echo(f"wrote {out}/ (data/, truth.json, campaign.toml)")
