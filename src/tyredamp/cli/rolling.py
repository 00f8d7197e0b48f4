"""``tyredamp rolling``: travelling waves of a rolling tyre from output-only time data."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ..documents.jsonfile import write_json
from ..exceptions import InputError
from ..studies.steps.rolling import RollingSettings
from ._common import channel_map, channel_map_options, out_file_option
from ._settings import settings_from_options, settings_options

__all__ = ["rolling_command"]


def _channel_list(text: str | None, n: int, option: str) -> list[int] | None:
    if text is None:
        return None
    try:
        vals = [int(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise InputError(f"{option}: expected channel numbers like 17, got {text!r}") from None
    if not vals or any(not 1 <= v <= n for v in vals):
        raise InputError(f"{option}: expected channel numbers 1..{n}, got {text!r}")
    return [v - 1 for v in vals]


@click.command("rolling")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("Waves JSON file to write (wave number, direction, both frames).")
@click.option(
    "--wheel-speed",
    type=float,
    default=None,
    help="Wheel rotation frequency in Hz (default: from the file's metadata).",
)
@click.option(
    "--in-tyre",
    default=None,
    help="Channels of the sensors inside the tyre, e.g. 17 (default: channels named T..).",
)
@settings_options(RollingSettings)
@channel_map_options
def rolling_command(file: Path, out: Path, **o: Any) -> None:
    """Travelling waves of a rolling tyre from output-only time data in FILE.

    The sensors fixed around the tyre (at least 3, with their angles in the
    direction of rotation) give every mode's wave number and its direction;
    the first sensor inside the tyre gives the rotating-frame frequencies,
    each resolved to a wave through f_fixed = f_in_tyre +- n f_wheel and the
    fixed-frame waves. A peak no fixed-frame wave explains is listed as
    unresolved with its candidates.

    \b
    Example:
      tyredamp rolling rolling.uff --out waves.json --wheel-speed 3.54
    """
    from ..io import read_timedata
    from ..io._safety import check_output_file
    from ..oma.rolling import rolling_modes

    settings = settings_from_options(RollingSettings, o)
    check_output_file(out, [file])
    td = read_timedata(file, channel_map=channel_map())
    rot = _channel_list(o["in_tyre"], td.n_channels, "--in-tyre")
    try:
        m = rolling_modes(
            td,
            o["wheel_speed"],
            rotating_channels=rot,
            band=settings.band,
            uncertainty=settings.uncertainty,
            spatial=settings.route,
        )
    except InputError as exc:
        raise InputError(f"{file.name}: {exc}") from None
    write_json(
        {
            "kind": "rolling_waves",
            "source": file.name,
            "wheel_speed_hz": m.wheel_speed_hz,
            "waves": m.table(),
            "notes": m.notes,
        },
        out,
    )
    click.echo(m.format())
    for n in m.notes:
        click.echo(f"note: {n}")
    click.echo(f"wrote {out}")
