"""``tyredamp tyre-model``: flexible-ring and rigid-ring tyre models from modes files.

``tyredamp tyre-model MODES_JSON... --out DIR --radius R`` reads one modes
JSON per test pressure (``tyredamp modal``), labels every mode with its
circumferential wave number, updates the flexible ring jointly across the
pressures and writes into the new directory ``DIR``:

* ``ring.json`` -- wave numbers, ring parameters with standard errors,
  correlations and identifiability verdicts, predictions;
* ``rigid_ring.json`` -- in-plane rigid-ring (MF-Swift) parameters per
  pressure, the fields the test cannot give, lateral carcass quantities;
* ``tyre_inplane_<p>bar.tir`` -- the in-plane ``.tir`` subset per pressure
  (with ``--tangential``: the wind-up keys of that pressure too);
* ``ring_frequencies.png`` -- identified against updated-ring frequencies.

All files are written into a temporary directory beside ``DIR`` first and
moved into place only when every one is complete: all outputs or none.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ..documents.jsonfile import json_text
from ..exceptions import FileFormatError, InputError
from ..io._safety import atomic_dir, check_output_dir, private_matplotlib_config
from ._common import OutPath

if TYPE_CHECKING:
    from ..modal.model import ModalModel

__all__ = ["tyre_model_command", "write_all_or_none"]

_BAR = 1e5
_MAX_BAR = 20.0  # above any road tyre's inflation pressure
_FIGURE = "ring_frequencies.png"


def _float_list(text: str | None, name: str, top: float) -> list[float] | None:
    if text is None:
        return None
    try:
        vals = [float(x) for x in text.replace(";", ",").split(",") if x.strip()]
    except ValueError:
        raise InputError(f"{name}: expected numbers separated by commas, got {text!r}") from None
    if not vals or not all(math.isfinite(v) and 0 < v <= top for v in vals):
        raise InputError(f"{name}: expected pressures above 0 and up to {top:g} bar, got {text!r}")
    return vals


def _finite(options: dict[str, float | None]) -> None:
    """Refuse a numeric option given as nan (click's ranges let it through)."""
    for name, v in options.items():
        if v is not None and not math.isfinite(v):
            raise InputError(f"{name}: expected a finite number, got {v}")


@dataclass(frozen=True)
class _Options:
    """Uncertainty assumptions, base files ``{output name: (base name, text)}``, --force,
    the tangential modes files and their pressures (bar, text)."""

    assumptions: Any
    bases: dict[str, tuple[str, str]]
    force: bool
    tangential: tuple[Path, ...] = ()
    tangential_pressures: str | None = None


def _read_bases(paths: tuple[Path, ...]) -> dict[str, tuple[str, str]]:
    """Read and check every --merge-into base before any work: ``{output name: (name, text)}``."""
    from ..tyremodel.tir import decode_tir, parse_tir

    out: dict[str, tuple[str, str]] = {}
    for p in paths:
        try:
            data = p.read_bytes()
        except OSError as exc:
            raise InputError(f"--merge-into: cannot read {p} ({exc.strerror or exc})") from None
        text = decode_tir(data, str(p))
        try:
            parse_tir(text)
        except FileFormatError as exc:
            raise FileFormatError(f"--merge-into: {p}: {exc}") from None
        name = f"{p.stem}_tyredamp.tir"
        k = 2
        while name in out:
            name = f"{p.stem}_tyredamp_{k}.tir"
            k += 1
        out[name] = (p.name, text)
    return out


def _meta_pressure_bar(path: Path, model: ModalModel) -> float | None:
    """Pressure (bar) from the modes document or the model's meta, if recorded."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        doc = {}
    for src in (doc if isinstance(doc, dict) else {}, model.meta):
        for key, unit in (("pressure_bar", 1.0), ("pressure_pa", _BAR)):
            v = src.get(key)
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise InputError(
                    f"{path}: the recorded pressure ({key}) is {json.dumps(v)[:40]}, not a "
                    "number; give --pressure"
                )
            bar = float(v) / unit
            if not (math.isfinite(bar) and 0 < bar <= _MAX_BAR):
                raise InputError(
                    f"{path}: the recorded pressure is {bar:g} bar; expected above 0 and up to "
                    f"{_MAX_BAR:g} bar (give --pressure)"
                )
            return bar
    return None


def check_out_dir(out_dir: Path) -> Path:
    """Refuse an ``--out`` directory that cannot work or is not new or empty; before work.

    See :func:`tyredamp.io._safety.check_output_dir` (a file, the current
    directory, a missing or read-only parent are refused); a tyre-model output
    keeps no file list, so any non-empty directory is refused as well. Returns
    the real directory (links followed).
    """

    def not_empty(root: Path) -> None:
        raise InputError(
            f"--out: directory {out_dir} exists and is not empty; choose a new directory"
        )

    return check_output_dir(out_dir, not_empty)


def write_all_or_none(out_dir: Path, writers: dict[str, Callable[[Path], None]]) -> list[Path]:
    """Write every file of ``writers`` into ``out_dir``, or none of them.

    The directory is checked first (:func:`check_out_dir`: it must be new or
    empty), then every writer writes its file into a temporary directory
    beside ``out_dir`` that is flushed to disk and renamed into place only
    when all succeeded (:func:`tyredamp.io._safety.atomic_dir`); on any error
    or interruption the temporary directory is removed and ``out_dir`` is as
    it was. Nothing that this function did not write is ever removed.

    Returns
    -------
    list of Path
        The written files.
    """
    target = Path(out_dir)
    check_out_dir(target)
    written: list[str] = []
    with atomic_dir(target) as tmp_dir:
        for name, write in writers.items():
            write(tmp_dir / name)
            written.append(name)
    return [target / n for n in written]


@click.command("tyre-model")
@click.argument(
    "modes_files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path)
)
@click.option(
    "--out",
    "-o",
    "out",
    required=True,
    type=OutPath(file_okay=False, path_type=Path),
    help="New directory for the outputs (written all at once or not at all).",
)
@click.option(
    "--radius",
    type=click.FloatRange(min=0, max=5, min_open=True),
    required=True,
    metavar="M",
    help="Belt (tread-band centre line) radius in m (up to 5).",
)
@click.option(
    "--pressure",
    "pressures",
    metavar="P1,P2,...",
    help="Test pressure of each modes file in bar (default from the files' metadata).",
)
@click.option(
    "--model",
    "model_kind",
    type=click.Choice(["auto", "complex", "real"]),
    default="auto",
    show_default=True,
    help="Which modes of the files to use (auto: complex when present).",
)
@click.option(
    "--attachment-mass",
    type=click.FloatRange(min=0, max=100),
    default=0.0,
    show_default=True,
    metavar="KG",
    help="Known point mass at each drive point (transducer, drive-rod tip), kg.",
)
@click.option(
    "--attachment-damping",
    type=click.FloatRange(min=0, max=1e6),
    metavar="NS_PER_M",
    help="Known local radial damper at each drive point, N s/m (default: fitted).",
)
@click.option(
    "--mass-per-length",
    type=click.FloatRange(min=0, max=1000, min_open=True),
    metavar="KG_PER_M",
    help="Known belt mass per length (default: from the mass-normalised shapes).",
)
@click.option(
    "--foundation-law",
    type=click.Choice(["linear", "constant"]),
    default="linear",
    show_default=True,
    help="Pressure dependence of the sidewall stiffnesses k_r, k_t across pressures.",
)
@click.option(
    "--predict",
    "predict",
    metavar="P1,P2,...",
    help="Extra pressures (bar) at which to predict the ring's modes.",
)
@click.option(
    "--lateral",
    "lateral_files",
    multiple=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="Lateral-fit JSON (tyredamp lateral fit) for the lateral carcass quantities; repeatable.",
)
@click.option(
    "--lateral-pressure",
    type=click.FloatRange(min=0, max=_MAX_BAR, min_open=True),
    metavar="BAR",
    help="Pressure of the lateral tests when their files do not record it.",
)
@click.option(
    "--geometry",
    "geometry_file",
    type=click.Path(dir_okay=False, path_type=Path),
    help="UFF test geometry (data sets 15/2411) for UFF 55 modes files without their own.",
)
@click.option(
    "--merge-into",
    "merge_into",
    multiple=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="A complete .tir property file to write the identified values into (kept as it is; "
    "the merged copy goes into --out); repeatable.",
)
@click.option(
    "--tangential",
    "tangential_files",
    multiple=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="Modes JSON of a tangential test (tyredamp modal of circumferential FRFs) for "
    "FREQ_WINDUP, DAMP_WINDUP, BELT_IYY; one per pressure, repeatable.",
)
@click.option(
    "--tangential-pressure",
    "tangential_pressures",
    metavar="P1,P2,...",
    help="Pressure of each tangential modes file in bar (default from the files' metadata).",
)
@click.option(
    "--force-sensitivity-error",
    type=click.FloatRange(min=0, max=50),
    default=1.0,
    show_default=True,
    metavar="PCT",
    help="1-sigma calibration uncertainty of the force transducer, %.",
)
@click.option(
    "--acceleration-sensitivity-error",
    type=click.FloatRange(min=0, max=50),
    default=1.0,
    show_default=True,
    metavar="PCT",
    help="1-sigma calibration uncertainty of the accelerometers, %.",
)
@click.option(
    "--attachment-mass-error",
    type=click.FloatRange(min=0, max=50),
    default=10.0,
    show_default=True,
    metavar="PCT",
    help="1-sigma uncertainty of --attachment-mass, %.",
)
@click.option(
    "--attachment-damping-error",
    type=click.FloatRange(min=0, max=100),
    default=50.0,
    show_default=True,
    metavar="PCT",
    help="1-sigma uncertainty of --attachment-damping, %.",
)
@click.option(
    "--force",
    is_flag=True,
    help="Merge into a base of another pressure, keep lateral tests of another pressure "
    "(both with a warning in the files).",
)
def tyre_model_command(
    modes_files: tuple[Path, ...],
    out: Path,
    radius: float,
    pressures: str | None,
    model_kind: str,
    attachment_mass: float,
    attachment_damping: float | None,
    mass_per_length: float | None,
    foundation_law: str,
    predict: str | None,
    lateral_files: tuple[Path, ...],
    lateral_pressure: float | None,
    geometry_file: Path | None,
    merge_into: tuple[Path, ...],
    tangential_files: tuple[Path, ...],
    tangential_pressures: str | None,
    force_sensitivity_error: float,
    acceleration_sensitivity_error: float,
    attachment_mass_error: float,
    attachment_damping_error: float,
    force: bool,
) -> None:
    """Flexible-ring and rigid-ring tyre models from modes files at one or more pressures.

    Every mode gets its circumferential wave number from its shape (the
    outputs' angles); the ring on an elastic foundation (EI, T0 = p R b +
    T_c, k_r, k_t, mass per length, damping) is fitted to all pressures at
    once with the modal standard errors as weights; the in-plane rigid-ring
    parameters (BELT_MASS, FREQ_LONG, DAMP_LONG) come from the n = 1 modes.
    Fields a radial test cannot give (wind-up, lateral, yaw) are listed, not
    invented. A tangential test (--tangential: circumferential FRFs, its modes
    identified by tyredamp modal) adds the wind-up: FREQ_WINDUP, DAMP_WINDUP
    and BELT_IYY from its n = 0 rotation mode, found from the shapes'
    harmonic content. Each value carries its uncertainty budget (statistical,
    calibration of the transducers, attachment mass and damping, rigid
    translation) and the assumptions it rests on.

    Without --merge-into the .tir files are fragments (no simulator loads
    them alone); with --merge-into BASE.tir the values are written into a
    copy of a complete property file of the same tyre at the test pressure
    (every other line kept, old values in comments).

    A modes file may also be a UFF file of data sets 55 (modes from another
    program) whose nodes (data sets 15/2411 in the file, or --geometry) lie
    evenly around a circle: the radial part of each node's motion is used.
    Modes that are not a ring, or unscaled (no modal A), are refused.

    \b
    Example:
      tyredamp tyre-model m5.json m7.json m9.json --pressure 5,7,9 \\
          --radius 0.5 --attachment-mass 0.1 --out tyre_model
      tyredamp tyre-model radial.json --tangential tangential.json \\
          --pressure 7.5 --radius 0.5 --out tyre_model
    """
    from ..tyremodel.budget import Assumptions

    _finite(
        {
            "--radius": radius,
            "--attachment-mass": attachment_mass,
            "--attachment-damping": attachment_damping,
            "--mass-per-length": mass_per_length,
            "--lateral-pressure": lateral_pressure,
            "--force-sensitivity-error": force_sensitivity_error,
            "--acceleration-sensitivity-error": acceleration_sensitivity_error,
            "--attachment-mass-error": attachment_mass_error,
            "--attachment-damping-error": attachment_damping_error,
        }
    )
    check_out_dir(out)
    opts = _Options(
        Assumptions(
            force_sensitivity_error / 100,
            acceleration_sensitivity_error / 100,
            attachment_mass_error / 100,
            attachment_damping_error / 100,
        ),
        _read_bases(merge_into),
        force,
        tangential_files,
        tangential_pressures,
    )
    with private_matplotlib_config():
        _tyre_model(
            modes_files,
            out,
            radius,
            pressures,
            model_kind,
            attachment_mass,
            attachment_damping,
            mass_per_length,
            foundation_law,
            predict,
            lateral_files,
            lateral_pressure,
            geometry_file,
            opts,
        )


def _is_uff(path: Path) -> bool:
    """Is ``path`` named as a UFF file (modes from another program, data sets 55)?"""
    from ..io import FILE_FORMATS

    return path.suffix.lower() in FILE_FORMATS["uff58b"].extensions


def _read_tyre_modes(path: Path, model_kind: str, geometry_file: Path | None) -> ModalModel:
    """The modes of one file as radial shapes with their angles around the tread.

    A modes JSON (``tyredamp modal``) is used as it is (shapes at the inputs
    of a roving-hammer test taken there). A UFF file of data sets 55 (modes
    from another program) needs node coordinates (its own data sets 15/2411,
    or ``--geometry``) that make a ring: the radial part of every node's
    motion becomes its shape (:func:`tyredamp.tyremodel.layout.radial_ring_model`);
    a file that is not a ring, has no geometry or unscaled shapes is refused
    in one line.
    """
    from ..damping.modeset import at_shape_points, scaling_problem

    uff = _is_uff(path)
    from ..documents.modes import read_modes

    models = read_modes(path)  # a UFF file of data sets 55 or a modes JSON
    if model_kind == "auto":
        mdl = models.get("complex") or models["real"]
    elif model_kind not in models:
        raise FileFormatError(f"{path}: no {model_kind!r} modes in the file")
    else:
        mdl = models[model_kind]
    mdl = at_shape_points(mdl)
    if not uff:
        why = scaling_problem(mdl)
        if why:
            raise InputError(
                f"{path}: the mode shapes are unscaled ({why}); the ring's mass and stiffness "
                "come from mass-normalised shapes: identify the modes with a drive-point FRF"
            )
        return mdl
    from ..io.uff_geometry import read_uff_geometry, uff_geometry_or_none
    from ..tyremodel.layout import radial_ring_model

    geo = read_uff_geometry(geometry_file) if geometry_file else uff_geometry_or_none(path)
    if geo is None:
        raise InputError(
            f"{path}: the modes carry no node coordinates (no data set 15 or 2411); the tyre "
            "model needs the points' places around the tread: give the test geometry with "
            "--geometry"
        )
    try:
        ring = radial_ring_model(mdl, geo, bool(mdl.meta.get("drive_points_stated", True)))
    except InputError as exc:
        raise InputError(f"{path}: {exc}; no tyre model from these modes") from None
    why = scaling_problem(mdl)
    if why:
        raise InputError(
            f"{path}: the mode shapes are unscaled ({why}); the ring's mass and stiffness come "
            "from mass-normalised shapes: export the modes with modal A (or modal mass)"
        )
    return ring


def _read_tangential(
    opts: _Options | None, model_kind: str, geometry_file: Path | None
) -> list[tuple[float | None, ModalModel, str]]:
    """The tangential tests: ``(pressure in Pa or None, modes, file name)``, checked."""
    from ..tyremodel.windup import check_tangential

    if opts is None or not opts.tangential:
        return []
    files = opts.tangential
    p_list = _float_list(opts.tangential_pressures, "--tangential-pressure", _MAX_BAR)
    if p_list is not None and len(p_list) != len(files):
        raise InputError(
            f"--tangential-pressure: expected one pressure per tangential file ({len(files)}), "
            f"got {len(p_list)}"
        )
    out: list[tuple[float | None, ModalModel, str]] = []
    for i, path in enumerate(files):
        if _is_uff(path):
            raise InputError(
                f"--tangential: {path}: expected a modes JSON (tyredamp modal of the tangential "
                "FRFs), got a UFF file"
            )
        mdl = _read_tyre_modes(path, model_kind, geometry_file)
        check_tangential(mdl, str(path))
        pb = p_list[i] if p_list is not None else _meta_pressure_bar(path, mdl)
        out.append((None if pb is None else pb * _BAR, mdl, path.name))
    return out


def _tyre_model(
    modes_files: tuple[Path, ...],
    out: Path,
    radius: float,
    pressures: str | None,
    model_kind: str,
    attachment_mass: float,
    attachment_damping: float | None,
    mass_per_length: float | None,
    foundation_law: str,
    predict: str | None,
    lateral_files: tuple[Path, ...],
    lateral_pressure: float | None,
    geometry_file: Path | None = None,
    opts: _Options | None = None,
) -> None:
    from matplotlib.figure import Figure

    from ..plot.tyremodel import plot_ring_frequencies
    from ..tyremodel.lateral import read_lateral_carcass
    from ..tyremodel.pipeline import build_tyre_model

    p_list = _float_list(pressures, "--pressure", _MAX_BAR)
    if p_list is not None and len(p_list) != len(modes_files):
        raise InputError(
            f"--pressure: expected one pressure per modes file ({len(modes_files)}), "
            f"got {len(p_list)}"
        )
    inputs: list[tuple[float, ModalModel, str]] = []
    for i, path in enumerate(modes_files):
        mdl = _read_tyre_modes(path, model_kind, geometry_file)
        pb = p_list[i] if p_list is not None else _meta_pressure_bar(path, mdl)
        if pb is None:
            raise InputError(
                f"{path}: the test pressure is not recorded in the file; give --pressure"
            )
        inputs.append((pb * _BAR, mdl, path.name))
    from ..virtual.tangential import TANGENTIAL_DIRECTION

    for (_, mdl, src), path in zip(inputs, modes_files, strict=True):
        # a UFF 55 file's shapes were projected on the radius above (direction 1 there)
        if not _is_uff(path) and {abs(c.direction) for c in mdl.outputs} == {TANGENTIAL_DIRECTION}:
            raise InputError(
                f"{src}: the response channels are tangential (UFF direction "
                f"{TANGENTIAL_DIRECTION} on the ring, as tyredamp's tangential test writes "
                "them); give a tangential test with --tangential (the flexible ring needs a "
                "radial test)"
            )
    tangential = _read_tangential(opts, model_kind, geometry_file)
    preds = [p * _BAR for p in (_float_list(predict, "--predict", _MAX_BAR) or [])]
    lateral = []
    for lf in lateral_files:
        lateral += read_lateral_carcass(lf, pressure_bar=lateral_pressure)
    res = build_tyre_model(
        inputs,
        radius=radius,
        attachment_mass=attachment_mass,
        attachment_damping=attachment_damping,
        mass_per_length=mass_per_length,
        foundation_law=foundation_law,  # type: ignore[arg-type]
        predict_pressures=preds,
        lateral=lateral,
        assumptions=opts.assumptions if opts else None,
        force=bool(opts and opts.force),
        tangential=tangential,
    )
    ring_text = json_text(res.ring_document(), indent=1)
    rigid_text = json_text(res.rigid_document(), indent=1)
    tirs = res.tir_files()
    for name, (base_name, text) in (opts.bases if opts else {}).items():
        tirs[name] = res.merged_tir(text, base_name, force=opts.force if opts else False)
    fig = Figure(figsize=(6.5, 4.0), layout="constrained")
    plot_ring_frequencies(res.ring, ax=fig.subplots())

    def text_writer(text: str) -> Callable[[Path], None]:
        def write(tmp: Path) -> None:
            tmp.write_text(text, encoding="utf-8")

        return write

    def write_fig(tmp: Path) -> None:
        fig.savefig(tmp, format="png", dpi=120)

    writers: dict[str, Callable[[Path], None]] = {
        "ring.json": text_writer(ring_text),
        "rigid_ring.json": text_writer(rigid_text),
    }
    for name, text in tirs.items():
        writers[name] = text_writer(text)
    writers[_FIGURE] = write_fig
    files = write_all_or_none(out, writers)
    _echo_summary(res)
    click.echo(f"wrote {out}/: " + ", ".join(f.name for f in files))


def _echo_summary(res: Any) -> None:
    for src, p, wa in zip(res.sources, res.pressures, res.analyses, strict=True):
        click.echo(f"{src} ({p / _BAR:g} bar): wave numbers")
        for row in wa.format_table().splitlines():
            click.echo("  " + row)
        for w in wa.warnings:
            click.echo(f"  warning: {w}")
    ring = res.ring
    click.echo(
        f"flexible ring ({len(ring.observations)} modes, {ring.pressures.size} pressure(s), "
        f"weights: {ring.weights}, chi2/dof {ring.chi2 / max(ring.dof, 1):.3g}"
        f"{', covariance scaled' if ring.scaled_covariance else ''}, "
        f"{1e3 * ring.fit_time_s:.0f} ms):"
    )
    for row in ring.format_table().splitlines():
        click.echo("  " + row)
    for k, (r, b) in enumerate(zip(res.rigid, res.budgets, strict=True)):
        pb = "?" if r.pressure is None else f"{r.pressure / _BAR:g} bar"
        t = b.total
        w = res.windup(k)
        wind = (
            "FREQ_WINDUP, DAMP_WINDUP, BELT_IYY not given (wind-up needs a tangential test: "
            "--tangential)"
            if w is None
            else f"wind-up from {res.tangential_source(k)}: FREQ_WINDUP {w.freq_windup:.4g} +- "
            f"{t['FREQ_WINDUP']:.2g} Hz, DAMP_WINDUP {w.damp_windup:.4g} +- "
            f"{t['DAMP_WINDUP']:.2g}, BELT_IYY {w.belt_iyy:.4g} +- {t['BELT_IYY']:.2g} kg m^2"
        )
        click.echo(
            f"rigid ring ({pb}): BELT_MASS {r.belt_mass:.4g} +- {t['BELT_MASS']:.2g} kg, "
            f"FREQ_LONG {r.freq_long:.4g} +- {t['FREQ_LONG']:.2g} Hz, DAMP_LONG "
            f"{r.damp_long:.4g} +- {t['DAMP_LONG']:.2g} (1 sigma with calibration and "
            f"attachment; budgets in rigid_ring.json); {wind}"
        )
    for w in res.warnings:
        click.echo(f"warning: {w}")
    for c in res.lateral:
        click.echo(c.comment())
