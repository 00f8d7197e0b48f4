"""``tyredamp frf``: FRFs from a time-data file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from ..exceptions import InputError
from ..frf import FRF
from ..io import format_of, read_timedata, write_frf
from ..io._safety import atomic_paths, check_output_file
from ..studies.steps import FrfSettings, FrfStep, samples
from ..timedata import TimeData
from ._common import (
    channel_map,
    channel_map_options,
    echo_read_notes,
    format_option,
    out_file_option,
)
from ._settings import settings_from_options, settings_options

__all__ = ["frf_command", "frf_summary", "samples"]


def frf_summary(frf: FRF, coherence_min: float = 0.9) -> list[str]:
    """Short text summary of an estimated FRF: size, lines, estimator, coherence."""
    f = frf.frequency
    df = f" (df {f[1] - f[0]:.4g} Hz)" if f.size > 1 else ""
    m = frf.meta
    rows = [
        f"FRF: {frf.n_out} output(s) x {frf.n_in} input(s), {frf.kind} [{frf.unit}], "
        f"{frf.n_freq} lines {f[0]:.4g}-{f[-1]:.4g} Hz{df}",
        f"estimator {m.get('estimator', '?')}, method {m.get('method', '?')}, "
        f"{m.get('n_averages', '?')} averages of {m.get('segment_samples', '?')} samples",
    ]
    det = m.get("detection")
    if isinstance(det, dict) and det.get("reason"):
        rows.append(f"detected {det['reason']}")
    if frf.coherence is not None:
        coh = frf.coherence
        i_out, i_line = np.unravel_index(int(np.argmin(coh)), coh.shape)
        rows.append(
            f"multiple coherence: mean {coh.mean():.4f}, min {coh.min():.4f} "
            f"(output {frf.outputs[i_out].label} at {f[i_line]:.4g} Hz), "
            f"{100 * np.mean(coh < coherence_min):.3g} % of lines below {coherence_min:g}"
        )
    return rows


def _refuse_dependent_forces(td: TimeData) -> None:
    """Every force channel would be an input: refuse when one follows from the others."""
    from ..signal.checks import dependent_forces

    dep = dependent_forces(td)
    if not dep:
        return
    k, r2, uses = dep[0]
    lab = td.channels
    forces = ", ".join(f"{lab[i].label}" for i in td.force_indices)
    raise InputError(
        f"--reference: every force channel would be an input ({forces}), but "
        f"{lab[k].label} is {100 * r2:.4g} % a linear combination of "
        f"{' and '.join(lab[i].label for i in uses)}: the forces are not independent "
        "excitations (one is a reaction, such as the ground force under a driven body, "
        "F_ground = F_body - m a); choose the excitation with --reference, for example "
        f"--reference '{lab[td.force_indices[0]].label}'"
    )


@click.command("frf")
@click.argument("time_file", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("FRF file to write (.uff, .unv, .csv, .npz or .nc).")
@settings_options(FrfSettings)
@format_option("Output format; default from the extension (.uff/.unv: binary UFF 58b).")
@channel_map_options
@click.option(
    "--each-record",
    is_flag=True,
    help="Also write one FRF per record it averages (each hit of an impact test alone), "
    "as OUT's name with .record1, .record2, ... before the extension: independent "
    "measurements for tyredamp modal --replicate.",
)
def frf_command(
    time_file: Path, out: Path, fmt: str | None, each_record: bool, **options: Any
) -> None:
    """Estimate FRFs (with coherence) from TIME_FILE and write them to --out.

    TIME_FILE holds force and response channels (UFF 58 function type 1,
    tyredamp or plain CSV, NPZ, NI TDMS, ASAM MDF4, LabVIEW LVM, MATLAB
    .mat, WAV); channels the file does not name are given with --channel,
    --sensitivity or --channel-map. The FRF kind follows the
    response channels (acceleration gives accelerance). Without a stated
    period or record length the excitation is detected from the force
    (periodic: cyclic averaging over whole periods after any start
    transient; impact/burst: records from each hit; random: Welch) and the
    verdict with its reason is printed with the coherence figures. Nothing
    is written when an error occurs.

    \b
    Example:
      tyredamp frf tyre_test.uff --out tyre_frf.uff --estimator H1
      tyredamp frf rig.npz --out frf.csv --reference 1+Z --method welch --segment 4096
      tyredamp frf daq.unv --out frf.nc --period 0.5s --settle 2s
      tyredamp frf impact.tdms -o frf.uff --channel F=force:N --channel 2=acceleration:m/s^2
      tyredamp frf impact.lvm -o frf.uff --channel F=force:N --each-record
    """
    check_output_file(out, [time_file])
    out_format = format_of(out, fmt)
    settings = settings_from_options(FrfSettings, options)
    td = read_timedata(time_file, channel_map())
    echo_read_notes(td)
    td.require_force("an FRF", time_file)
    td.require_response("an FRF", time_file)
    if not settings.reference and len(td.force_indices) > 1:
        _refuse_dependent_forces(td)
    if not each_record:
        frf, _ = FrfStep.run(td, settings, "--")
        write_frf(frf, out, out_format)
        for row in frf_summary(frf):
            click.echo(row)
        click.echo(f"wrote {out} ({out_format})")
        return
    frf, records = FrfStep.records(td, settings, "--")
    paths = [out.with_name(f"{out.stem}.record{k}{out.suffix}") for k in range(1, len(records) + 1)]
    for p in paths:
        check_output_file(p, [time_file], "--each-record")
    # every file or none: a failure leaves no new file and every replaced one as it was
    with atomic_paths([out, *paths]) as tmps:
        for obj, tmp in zip([frf, *records], tmps, strict=True):
            write_frf(obj, tmp, out_format)
    for row in frf_summary(frf):
        click.echo(row)
    click.echo(f"wrote {out} ({out_format})")
    click.echo(
        f"wrote {len(paths)} records, one FRF each: {paths[0].name} ... {paths[-1].name} "
        f"(for tyredamp modal {out.name} --replicate {paths[0].name} ...)"
    )
