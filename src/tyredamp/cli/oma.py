"""``tyredamp oma``: modes from output-only time data (operational modal analysis)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from ..documents.jsonfile import write_json
from ..exceptions import FileFormatError, InputError
from ..frf import Channel
from ._common import channel_map, channel_map_options, out_file_option

__all__ = ["oma_command"]


def _read_npy(path: Path, sample_rate: float | None) -> tuple[np.ndarray, float, list[Channel]]:
    """A plain NumPy array of samples (samples x channels, or channels x samples)."""
    from ..io._common import check_input_file

    check_input_file(path)
    try:
        a = np.load(path, allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise FileFormatError(f"{path}: not a NumPy .npy array ({exc})") from None
    if a.ndim != 2 or not np.issubdtype(a.dtype, np.number):
        raise FileFormatError(f"{path}: expected a 2-D numeric array, got shape {a.shape}")
    if sample_rate is None:
        raise InputError(f"--sample-rate: {path} is a plain array; give its sampling rate in Hz")
    y = a.T if a.shape[0] > a.shape[1] else a
    return np.asarray(y, float), float(sample_rate), [Channel(i + 1) for i in range(y.shape[0])]


def _read(files: tuple[Path, ...], sample_rate: float | None) -> tuple[Any, float, list[Channel]]:
    """The response channels of every file, joined end to end."""
    from ..io import read_timedata

    parts, fs, chans = [], None, None
    for p in files:
        if p.suffix.lower() == ".npy":
            y, f, ch = _read_npy(p, sample_rate)
        else:
            td = read_timedata(p, channel_map=channel_map())
            idx = td.response_indices
            if not idx:
                td.require_response("operational modal analysis", p)
            y, f, ch = td.data[idx], td.sample_rate, [td.channels[i] for i in idx]
        if fs is not None and (abs(f - fs) > 1e-9 * fs or len(ch) != len(chans or [])):
            raise InputError(
                f"{p}: {len(ch)} channels at {f:g} Hz; the first file has {len(chans or [])} "
                f"at {fs:g} Hz (files are joined end to end: same channels and rate needed)"
            )
        parts.append(y)
        fs, chans = f, ch
    if fs is None or chans is None:  # pragma: no cover - files is never empty
        raise InputError("FILES: expected at least one file")
    return np.concatenate(parts, axis=1), fs, chans


def _channels_arg(text: str | None, n: int, option: str) -> list[int] | None:
    if text is None:
        return None
    try:
        vals = [int(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise InputError(f"{option}: expected channel numbers like 1,3, got {text!r}") from None
    bad = [v for v in vals if not 1 <= v <= n]
    if bad or not vals:
        raise InputError(f"{option}: expected channel numbers 1..{n}, got {text!r}")
    return [v - 1 for v in vals]


def _angles(text: str | None, chans: list[Channel]) -> list[float] | None:
    if text is None:
        ang = [c.angle_deg for c in chans]
        return None if any(a is None for a in ang) else [float(a) for a in ang]  # type: ignore[arg-type]
    try:
        vals = [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise InputError(
            f"--angles: expected angles in degrees like 0,45,90, got {text!r}"
        ) from None
    if len(vals) != len(chans):
        raise InputError(
            f"--angles: expected {len(chans)} angles (one per channel), got {len(vals)}"
        )
    return vals


@click.command("oma")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("Modes JSON file to write (output-only, shapes not scaled).")
@click.option(
    "--method",
    type=click.Choice(["ssi", "plscf"]),
    default="ssi",
    show_default=True,
    help="SSI-cov on the correlations, or pLSCF on the half-spectra.",
)
@click.option("--band", nargs=2, type=float, default=None, help="Band LO HI in Hz.")
@click.option(
    "--decimate",
    type=int,
    default=None,
    help="Decimation factor (default: from --band, else none).",
)
@click.option("--references", default=None, help="Reference channels, e.g. 1,2 (default: chosen).")
@click.option("--block-rows", type=int, default=None, help="SSI block rows (lags = 2 x rows).")
@click.option("--max-order", type=int, default=None, help="Largest model order.")
@click.option("--sample-rate", type=float, default=None, help="Hz, for a plain .npy array.")
@click.option("--channels", default=None, help="Channels to use, e.g. 1-based 1,2,4.")
@click.option(
    "--wheel-speed",
    type=float,
    default=None,
    help="Wheel rotation frequency in Hz (harmonics at its multiples are kept out).",
)
@click.option(
    "--angles",
    default=None,
    help="Angles in degrees of the channels around the tyre (travelling waves).",
)
@click.option(
    "--stabilisation-plot",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="PNG file of the stabilisation diagram.",
)
@channel_map_options
def oma_command(files: tuple[Path, ...], out: Path, **o: Any) -> None:
    """Identify modes from output-only time data in FILES (operational modal analysis).

    Covariance-driven SSI (or pLSCF on output half-spectra) over a range of
    model orders; the modes are selected from the stabilisation diagram by
    cuts taken from the data; frequency and damping get standard errors from a
    jackknife over segments of the record; harmonics of the rotation are told
    apart by their kurtosis and kept out. With --angles (or channel angles from
    the file) every mode gets its wave number and direction (forward, backward,
    standing). Files are joined end to end.

    \b
    Example:
      tyredamp oma ambient.uff --out modes.json --band 0 400
      tyredamp oma tower.npy --sample-rate 256 --band 0.5 15 --channels 1,2,3,4,5 -o m.json
    """
    from ..documents.oma import oma_document
    from ..io._safety import check_output_file
    from ..oma.identify import oma
    from ..oma.waves import wave_content

    check_output_file(out, list(files))
    y, fs, chans = _read(files, o["sample_rate"])
    use = _channels_arg(o["channels"], y.shape[0], "--channels")
    if use is not None:
        y, chans = y[use], [chans[i] for i in use]
    refs = _channels_arg(o["references"], y.shape[0], "--references")
    res = oma(
        y,
        fs,
        method=o["method"],
        references=refs,
        band=o["band"],
        decimate=o["decimate"],
        block_rows=o["block_rows"],
        max_order=o["max_order"],
        wheel_speed_hz=o["wheel_speed"],
    )
    ang = _angles(o["angles"], chans)
    waves = (
        None
        if ang is None or len(chans) < 3
        else [wave_content(res.shapes[:, j], ang) for j in range(res.n_modes)]
    )
    write_json(oma_document(res, chans, source=", ".join(p.name for p in files), waves=waves), out)
    if o["stabilisation_plot"] is not None:
        from ..io._atomic import atomic_path
        from ..plot.oma import plot_oma_stabilisation

        ax = plot_oma_stabilisation(res)
        fig = ax.get_figure(root=True)
        if fig is not None:
            with atomic_path(o["stabilisation_plot"]) as tmp:
                fig.savefig(tmp, format="png", dpi=110)
    _summary(res, files, y.shape, fs, waves)
    click.echo(f"wrote {out}")


def _summary(
    res: Any, files: tuple[Path, ...], shape: tuple[int, ...], fs: float, waves: Any
) -> None:
    click.echo(
        f"{', '.join(p.name for p in files)}: {shape[0]} channel(s), {shape[1] / fs:.4g} s at "
        f"{fs:g} Hz; {res.method} at {res.sample_rate:g} Hz, band {res.band_hz[0]:g}-"
        f"{res.band_hz[1]:g} Hz, references {', '.join(str(r + 1) for r in res.references)}"
    )
    click.echo(f"modes ({res.n_modes}, output-only, shapes not scaled):")
    click.echo(f"  {'#':>3} {'f [Hz]':>10} {'+-':>8} {'zeta [%]':>9} {'+-':>8} {'orders':>6}")
    for j in range(res.n_modes):
        w = f"  n={waves[j].wave_number} {waves[j].direction}" if waves else ""
        click.echo(
            f"  {j + 1:>3} {res.frequency_hz[j]:>10.4f} {res.std_frequency_hz[j]:>8.3g} "
            f"{100 * res.damping_ratio[j]:>9.3f} {100 * res.std_damping_ratio[j]:>8.3g} "
            f"{res.n_orders[j]:>6}{w}"
        )
    for h in res.harmonics:
        k = f", wheel order {h['wheel_order']}" if h["wheel_order"] else ""
        click.echo(
            f"harmonic (kept out): {h['frequency_hz']:.4f} Hz, kurtosis {h['kurtosis']:.2f}{k}"
        )
    for n in res.notes:
        click.echo(f"note: {n}")
