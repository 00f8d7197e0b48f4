"""Saving a demo run: report, results.json, figures, data and JSON files.

:func:`save_demo` writes what :func:`tyredamp.studies.demo.run_demo`
returned: ``report.html`` (self-contained), ``results.json`` (schema
``tyredamp/schemas/results.schema.json``, described in ``docs/reference/results-json.md``), the
figures as PNG, the generated data as UFF 58 (binary 58b), the modes and
damping JSON files of the main pressure and the tyre model of all pressures
(``tyre_model/``: ``ring.json``, ``rigid_ring.json``, ``.tir`` subsets; none
when its fit failed). It writes into a temporary directory
beside the target and renames it into place at the end
(:func:`tyredamp.io._safety.atomic_dir`), so a failure leaves no partial
output; an existing directory is replaced only when it is empty or an earlier
demo output holding nothing but its own files.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ..documents.damping import damping_document
from ..documents.demo import RESULTS_KIND
from ..documents.jsonfile import json_text
from ..documents.modes import modes_document
from ..frf import FRF
from ..io import write_frf, write_timedata
from ..io._safety import MANIFEST_NAME, atomic_dir
from ..io._safety import check_output_dir as _check_output_dir
from ..studies.demo import ProgressCallback, single_threaded_blas
from ..studies.document import build_results
from ..studies.results import DemoResult
from ..studies.tyremodel import tyre_model_files
from ..timedata import TimeData
from ._cells import ReportImage
from .build import build_demo_report
from .plots import demo_figures

__all__ = ["check_output_dir", "save_demo"]


def check_output_dir(out: Path) -> Path:
    """Refuse to replace anything but an empty directory or an earlier demo output.

    An earlier demo output (a ``results.json`` of kind ``tyredamp-demo-results``)
    is replaced only when the directory holds nothing but the files listed in
    that results.json, each unchanged since it was written (the directory's
    SHA-256 manifest); links are followed (see
    :func:`tyredamp.io._safety.check_output_dir`). Returns the real directory.

    Raises
    ------
    InputError
        ``out`` is a file, the current directory, has no parent directory, or is a
        non-empty directory that is not an earlier demo output, holds other files,
        or holds a file changed since the demo wrote it.
    """
    return _check_output_dir(out, _demo_files, what="tyredamp demo output")


def _demo_files(root: Path) -> list[str] | None:
    """The files an earlier demo wrote in ``root`` (its results.json's list), or None."""
    try:
        doc = json.loads((root / "results.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(doc, dict) or doc.get("kind") != RESULTS_KIND:
        return None
    files = doc.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    ok = [f for f in files if not Path(f).is_absolute() and ".." not in Path(f).parts]
    return [*ok, "results.json"]


def save_demo(
    result: DemoResult,
    out_dir: str | os.PathLike[str],
    progress: ProgressCallback | None = None,
    *,
    dpi: int = 100,
) -> dict[str, Path]:
    """Write the report, results.json, figures, data and JSON files of a demo run.

    Everything is written into a temporary directory beside ``out_dir`` that
    is renamed to ``out_dir`` at the end; an existing ``out_dir`` is replaced
    only if it is empty or an earlier demo output. On any error nothing is
    left behind and an existing ``out_dir`` is unchanged.

    Parameters
    ----------
    result : DemoResult
    out_dir : path-like
        Target directory.
    progress : callable, optional
        ``progress(description, done, total)``.
    dpi : int
        Resolution of the PNG figures.

    Returns
    -------
    dict of str to Path
        ``"report"``, ``"results"`` and every other file written, by name
        relative to ``out_dir`` (``"report.html"``, ``"results.json"``, ...);
        the paths point into ``out_dir``.
    """
    with single_threaded_blas():
        return _save(result, Path(out_dir), progress, dpi)


def _save(
    result: DemoResult, out: Path, progress: ProgressCallback | None, dpi: int
) -> dict[str, Path]:
    check_output_dir(out)
    written: list[str] = []
    with atomic_dir(out) as tmp:
        figs = demo_figures(result)
        total = len(figs) + 5
        done = 0

        def step(name: str) -> None:
            nonlocal done
            if progress is not None:
                progress(name, done, total)
            done += 1

        images: dict[str, ReportImage] = {}
        for name, built in figs.items():
            step(f"figure {name}.png")
            buf = _png(built[0], dpi)
            images[name] = ReportImage(buf, built[1], getattr(built, "section", ""))
            (tmp / "figures").mkdir(exist_ok=True)
            (tmp / "figures" / f"{name}.png").write_bytes(buf)
            written.append(f"figures/{name}.png")

        step("data files (UFF 58)")
        data_dir = tmp / "data"
        data_dir.mkdir()
        for rel, obj in _data_files(result).items():
            if isinstance(obj, FRF):
                write_frf(obj, tmp / rel)
            else:
                write_timedata(obj, tmp / rel)
            written.append(rel)

        step("modes and damping JSON")
        main = result.radial.main
        p0 = f"{main.pressure_bar:g}bar"
        doc = modes_document(
            main.models,
            source=f"data/radial_{p0}_frf.uff",
            band_hz=main.identification.band_hz,
            frf_kind=main.identification.frf_kind,
        )
        (tmp / f"modes_{p0}.json").write_text(json_text(doc), encoding="utf-8")
        written.append(f"modes_{p0}.json")
        (tmp / f"damping_{p0}.json").write_text(
            json_text(damping_document(result.radial.damping)),
            encoding="utf-8",
        )
        written.append(f"damping_{p0}.json")

        step("tyre model (ring, rigid ring, .tir)")
        for rel, content in tyre_model_files(result.radial.tyre_model).items():
            (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
            text = content if isinstance(content, str) else json_text(content, indent=1)
            (tmp / rel).write_text(text, encoding="utf-8")
            written.append(rel)

        step("results.json")
        files = sorted([*written, "report.html", "results.json", MANIFEST_NAME])
        results = build_results(result, files=files)
        (tmp / "results.json").write_text(json_text(results), encoding="utf-8")

        step("report.html")
        html = build_demo_report(result, results, images)
        (tmp / "report.html").write_text(html, encoding="utf-8")
        if progress is not None:
            progress("done", total, total)
    return {name: out / name for name in files}


def _png(fig: Any, dpi: int) -> bytes:
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def _data_files(result: DemoResult) -> dict[str, FRF | TimeData]:
    """Generated data by relative path (UFF 58b: time data type 1, FRFs type 4)."""
    files: dict[str, FRF | TimeData] = {}
    r = result.radial
    main = r.main
    p0 = f"{main.pressure_bar:g}bar"
    files[f"data/radial_{p0}_time.uff"] = main.test.data
    for run in r.runs:
        files[f"data/radial_{run.pressure_bar:g}bar_frf.uff"] = run.frf
    hi = result.settings.force_levels_n[1]
    files[f"data/radial_{p0}_{hi:g}N_frf.uff"] = r.linearity_frfs[1]
    files[f"data/radial_{p0}_reciprocity_frf.uff"] = r.reciprocity_frf
    for c in result.lateral.conditions:
        tag = f"{c.pressure_bar:g}bar_{c.speed_kmh:g}kmh"
        files[f"data/lateral_{tag}_ground_frf.uff"] = c.ground.frf
        files[f"data/lateral_{tag}_axle_frf.uff"] = c.axle.frf
    tt = result.lateral.time_test
    files[f"data/lateral_time_{tt.frequency_hz:g}Hz.uff"] = tt.data
    return files
