"""``tyredamp modal``: real and complex modes from an FRF file."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click
import numpy as np

from ..exceptions import InputError
from ..modal.statistics.quality import rejected_summary
from ..studies.steps import ModalSettings, ModalStep
from ._common import channel_map, channel_map_options, out_file_option
from ._settings import settings_from_options, settings_options

if TYPE_CHECKING:
    from ..frf import FRF
    from ..modal.model import ModalModel

__all__ = ["modal_command", "modes_table"]

_NOISE = {
    "variance": "per-line variance carried by the FRF",
    "coherence": "per-line variance from the coherence and the number of averages",
    "residual": "noise level per output estimated from the residual of the fit",
}


def modes_table(name: str, model: ModalModel) -> list[str]:
    """Text table of one model: frequency, damping (with standard errors), MPC, the
    mode test's statistic ``T`` and the threshold applied to each mode (the base
    one, raised where the noise lies along the response), RMSD and the
    goodness-of-fit verdict."""
    sf = model.std.get("frequency_hz", np.full(model.n_modes, np.nan))
    sz = model.std.get("damping_ratio", np.full(model.n_modes, np.nan))
    mpc = np.asarray(model.meta.get("mpc", np.full(model.n_modes, np.nan)), float)
    q = model.quality
    stat = q.statistic if q is not None else np.full(model.n_modes, np.nan)
    each = q.thresholds if q is not None else np.full(model.n_modes, np.nan)
    thr = f" (base threshold {q.threshold:.3g}, false-alarm rate {q.false_alarm:g})" if q else ""
    labels = model.meta.get("wave_number_label")
    if not isinstance(labels, list) or len(labels) != model.n_modes:
        labels = None
    rows = [
        f"{name} modes ({model.n_modes}):",
        f"  {'#':>3} {'f [Hz]':>10} {'+-':>8} {'zeta [%]':>9} {'+-':>8} {'MPC':>7} "
        f"{'T':>9} {'thr':>9}" + ("  wave number" if labels else "") + thr,
    ]
    for n in range(model.n_modes):
        rows.append(
            f"  {n + 1:>3} {model.frequency_hz[n]:>10.3f} {sf[n]:>8.3g} "
            f"{100 * model.damping_ratio[n]:>9.4f} {100 * sz[n]:>8.3g} {mpc[n]:>7.4f} "
            f"{stat[n]:>9.3g} {each[n]:>9.3g}" + (f"  {labels[n]}" if labels else "")
        )
    if q is not None:
        raised = [str(n + 1) for n in range(model.n_modes) if each[n] > q.threshold]
        if raised:
            rows.append(
                f"  thr raised from {q.threshold:.3g} (noise along the response) "
                f"for mode(s) {', '.join(raised)}"
            )
    rows += _likelihood_rows(model)
    rmsd = model.meta.get("rmsd", float("nan"))
    rel = model.meta.get("relative_error", float("nan"))
    rows.append(f"  RMSD (eq. 19) {rmsd:.4g}, relative error {100 * rel:.3g} %")
    if q is not None:
        rows.append(f"  goodness of fit (ML): {q.verdict}")
        if q.rejected:
            rows.append(f"  {rejected_summary(q.rejected)} (every reason in the modes JSON)")
    for w in model.meta.get("warnings", []):
        rows.append(f"  warning: {w}")
    return rows


def _likelihood_rows(model: ModalModel) -> list[str]:
    """The 95 % likelihood intervals of the modes that have one (a weak mode, whose
    linearised interval would be too short; :mod:`tyredamp.modal.fit.profile`): the
    +- columns hold the half-width of the symmetric interval around them."""
    how = model.meta.get("interval_method")
    fi, zi = model.meta.get("interval_frequency_hz"), model.meta.get("interval_damping_ratio")
    if not isinstance(how, list) or len(how) != model.n_modes or fi is None or zi is None:
        return []
    fa, za = np.asarray(fi, float), np.asarray(zi, float)
    return [
        f"  mode {n + 1}: 95 % likelihood interval f [{fa[n, 0]:.4f}, {fa[n, 1]:.4f}] Hz, "
        f"zeta [{100 * za[n, 0]:.4f}, {100 * za[n, 1]:.4f}] % (+- holds it)"
        + ("; the data do not tell it from a neighbour" if how[n] != "likelihood" else "")
        for n in range(model.n_modes)
        if str(how[n]).startswith("likelihood")
    ]


def _replicate(path: Path, frf: FRF, frf_file: Path) -> FRF:
    """A replicate's FRFs, refused unless they have the channels of the FRF file."""
    from ..io import read_frf

    rep = read_frf(path, channel_map=channel_map())
    if (rep.n_out, rep.n_in, rep.kind) != (frf.n_out, frf.n_in, frf.kind):
        raise InputError(
            f"--replicate: {path} holds {rep.n_out} output(s) x {rep.n_in} input(s) of "
            f"{rep.kind}; a replicate of {frf_file.name} has its {frf.n_out} output(s) x "
            f"{frf.n_in} input(s) of {frf.kind}"
        )
    return rep


def _with_geometry(frf: FRF, path: Path) -> FRF:
    """The FRF with channel angles from the geometry when its points lie on a circle."""
    from dataclasses import replace

    from ..frf import Channel
    from ..io.uff_geometry import read_uff_geometry

    geo = read_uff_geometry(path)
    missing = sorted({c.node for c in (*frf.outputs, *frf.inputs)} - set(geo.nodes))
    if missing:
        raise InputError(
            f"--geometry: {path} has no node {missing[0]} ({len(missing)} channel node(s) missing)"
        )
    outs = geo.with_angles(frf.outputs)
    angle = {(c.node, abs(c.direction)): c.angle_deg for c in outs}
    ins = tuple(
        Channel(c.node, c.direction, angle.get((c.node, abs(c.direction)), c.angle_deg), c.name)
        for c in frf.inputs
    )
    return replace(frf, outputs=outs, inputs=ins)


@click.command("modal")
@click.argument("frf_file", type=click.Path(dir_okay=False, path_type=Path))
@out_file_option("Modes JSON file to write (schema: docs/modes-json.md).")
@settings_options(ModalSettings, skip=("estimator",))
@click.option(
    "--geometry",
    "geometry_file",
    type=click.Path(dir_okay=False, path_type=Path),
    help="UFF geometry (nodes 15/2411, trace lines 82, systems 18/2420): every channel's node "
    "must be in it; points on a circle get their angles from it (ring views).",
)
@click.option(
    "--replicate",
    "replicate_files",
    type=click.Path(dir_okay=False, path_type=Path),
    multiple=True,
    help="An independent measurement of the same FRFs (one hit of an impact test, one "
    "repeat of the test), identified alone: each mode is marked as found again in each "
    "replicate or as undecidable. Repeat for each replicate.",
)
@settings_options(ModalSettings, only=("estimator",))
@channel_map_options
def modal_command(
    frf_file: Path,
    out: Path,
    geometry_file: Path | None,
    replicate_files: tuple[Path, ...] = (),
    **options: Any,
) -> None:
    """Identify real and complex modes of the FRFs in FRF_FILE.

    Poles come from a poly-reference LSCF stabilisation diagram with automatic
    selection (no frequencies needed); residues, poles and participation are
    then refined together over all FRFs, shapes are mass-normalised from the
    drive point(s), and every frequency, damping ratio and shape entry gets a
    standard error. The mode count is decided by a likelihood-ratio test
    against the noise (statistic T per mode, threshold from --false-alarm),
    and a search of the residual adds missed modes that pass it. Prints a
    table per model with the RMSD of eq. 19 and a goodness-of-fit verdict.

    \b
    Example:
      tyredamp modal tyre_frf.uff --out modes.json --band 0 200
      tyredamp modal tyre_frf.npz -o modes.json --model complex --modes 6
      tyredamp modal frf.uff -o modes.json --replicate hit1.uff --replicate hit2.uff
    """
    from ..documents.jsonfile import write_json  # imported when the command runs
    from ..io import read_frf
    from ..io._safety import check_output_file

    settings = settings_from_options(ModalSettings, options)
    check_output_file(out, [frf_file, *replicate_files])
    frf = read_frf(frf_file, channel_map=channel_map())
    replicates = [_replicate(p, frf, frf_file) for p in replicate_files]
    if geometry_file is not None:
        frf = _with_geometry(frf, geometry_file)
    try:
        res, verdicts = ModalStep.run(frf, settings)
    except InputError as e:  # the limits of the data, named by the option that set them
        msg = str(e)
        for arg, opt in (("n_modes:", "--modes:"), ("frequencies:", "--frequencies:")):
            if msg.startswith(arg):
                raise InputError(opt + msg[len(arg) :]) from None
        raise
    support = ModalStep.replicates(res, replicates, settings) if replicates else []
    write_json(ModalStep.document(res, verdicts, source=frf_file.name), out)
    click.echo(
        f"FRF {frf_file.name}: {frf.n_out} output(s) x {frf.n_in} input(s), {res.frf_kind}, "
        f"band {res.band_hz[0]:g}-{res.band_hz[1]:g} Hz, {res.frequency.size} lines"
    )
    click.echo(f"noise model: {res.noise_source} ({_NOISE[res.noise_source]})")
    for name in ("complex", "real"):
        if name in res.models:
            for row in modes_table(name, res.models[name]):
                click.echo(row)
    if "complex" in res.models and "real" in res.models:
        rc = res.models["complex"].meta["rmsd"]
        rr = res.models["real"].meta["rmsd"]
        ratio = rr / rc if rc > 0 else float("inf")
        click.echo(f"RMSD real / complex = {ratio:.3g}")
    for w in res.warnings:
        click.echo(f"warning: {w}")
    for sup in support:
        if not sup.confirmed:
            click.echo(f"warning: mode at {sup.frequency_hz:.5g} Hz: {sup.text()}")
    if support:
        n = sum(sup.confirmed for sup in support)
        click.echo(
            f"replicates: {n} of {len(support)} modes found again in each of the "
            f"{len(replicates)} replicates"
        )
    for v in verdicts.values():
        click.echo(f"verdict: {v.summary()}")
        for c in v.cautions:
            click.echo(f"  caution: {c}")
    click.echo(f"wrote {out}")
