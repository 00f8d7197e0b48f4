"""The campaign's results: tidy tables, mode families, trends, per-test documents, report.

Files written into the output folder ``DIR`` (each atomically):

``modes.parquet``, ``modes.csv``
    One row per identified mode of every test, with the test's conditions,
    its family and slot, and its standard errors (:data:`MODE_COLUMNS`).
``trends.parquet``, ``trends.csv``
    One row per (family, slot, quantity, condition, series, condition value):
    the observed mean and standard error and the fitted trend with its
    standard error (:data:`TREND_COLUMNS`); ``trend_fits.json`` holds the
    fitted polynomials.
``damping.parquet``, ``damping.csv``
    One row per entry ``C'_kn`` of the modal damping matrix of every radial
    test, labelled by the families of modes ``k`` and ``n`` (the matrix's
    change across conditions, couplings included).
``lateral.parquet``, ``lateral.csv``
    One row per fitted parameter of every lateral model of every lateral test.
``steps.parquet``, ``steps.csv``
    One row per step of every test: its outcome (``ran``, ``skipped`` with
    the reason, ``failed`` with the error, ``not run`` after a failure,
    ``off``), whether it came from the cache, and the quality verdict of its
    result (:mod:`.status`).
``tests/<test_id>/modes.json``, ``damping.json``, ``lateral.json``
    Each test's own documents (the modes JSON of ``tyredamp modal``, the
    damping JSON of ``tyredamp damping``, the lateral-fit JSON).
``campaign.json``
    Summary: every test with its status (``ok``: every step ran;
    ``partial``: some steps could not run on its data and were skipped, with
    the reasons; ``failed``: a step failed, with the one-line error), the
    outcome of each step, its quality checks (data quality, fit verdicts),
    the steps computed and reused, and the families.
``report.html``
    One self-contained page: problems (failed tests, failed quality checks,
    skipped steps), families and their figures, trend plots, every test's
    step outcomes and verdicts, links (written by
    :mod:`tyredamp.report.campaign`, above this package).

The tables' columns and rows are built by :mod:`.tables`; this module checks
the output folder and writes the files.
"""

from __future__ import annotations

import json
import os
import re
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..documents.jsonfile import write_json
from ..exceptions import InputError
from ..io._safety import atomic_path, check_output_dir
from .runner import TestRun
from .series_trend import TrendFit
from .spec import Campaign
from .status import STEP_COLUMNS, quality_checks, step_rows, summary_entry
from .tables import (
    DAMPING_COLUMNS,
    LATERAL_COLUMNS,
    MODE_COLUMNS,
    TREND_COLUMNS,
    _family_number,
    damping_rows,
    lateral_rows,
    lateral_trend_rows,
    mode_rows,
    row_family_names,
    track_by_study,
    trend_fits,
    trend_rows,
)

__all__ = [
    "MODE_COLUMNS",
    "TREND_COLUMNS",
    "CampaignResults",
    "campaign_files",
    "check_campaign_output",
    "lateral_rows",
    "mode_rows",
    "row_family_names",
    "trend_rows",
    "write_outputs",
]

KIND = "tyredamp-campaign"


def check_campaign_output(
    out: str | os.PathLike[str], inputs: Iterable[str | os.PathLike[str]] = ()
) -> Path:
    """Refuse an output folder that is not new, empty or an earlier campaign output; before work.

    The campaign writes only its own files and never deletes or changes a
    file it did not write: a non-empty folder is accepted only when it holds
    nothing but what earlier campaign runs wrote there (:func:`campaign_files`:
    the files its ``campaign.json`` lists, cache entries, and temporaries of
    our own pattern left by a killed run). A folder that is, or holds, one
    of the ``inputs`` (the campaign file, the test files) is refused, and so
    is one where a file the campaign wrote was changed since
    (:func:`.manifest.check_edits`). The rest of the rules (not the current
    directory, a writable parent, links followed) are those of
    :func:`tyredamp.io._safety.check_output_dir`.

    Returns
    -------
    Path
        The real folder (links followed).

    Raises
    ------
    InputError
        The message names the folder and the reason.
    """
    text = os.fspath(out)
    real = Path(os.path.realpath(text)) if text else Path()
    for inp in inputs:
        r = Path(os.path.realpath(inp))
        if text and (r == real or real in r.parents):
            raise InputError(
                f"--out: {text} is or holds the input file {os.fspath(inp)}; "
                "choose another directory"
            )
    from .manifest import check_edits  # the files it lists must be as the campaign wrote them

    if text and os.path.isdir(real):
        check_edits(real, shown=text)
    return check_output_dir(out, campaign_files, what="campaign output", manifest=False)


def _listed(doc: dict[str, Any]) -> list[str]:
    """The relative paths a ``campaign.json`` says its campaign wrote."""
    files = doc.get("written")
    if not isinstance(files, list):
        files = list(doc.get("files") or [])
        for t in doc.get("tests") or []:
            if isinstance(t, dict) and isinstance(t.get("documents"), dict):
                files += list(t["documents"].values())
    ok = []
    for f in files:
        if isinstance(f, str) and f and not Path(f).is_absolute() and ".." not in Path(f).parts:
            ok.append(Path(f).as_posix())
    return ok


def _summary(root: Path) -> dict[str, Any] | None:
    try:
        doc = json.loads((root / "campaign.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return doc if isinstance(doc, dict) and doc.get("kind") == KIND else None


def _temporaries(root: Path, names: Iterable[str]) -> list[str]:
    """Temporaries of our own pattern beside ``names`` (left by a killed run)."""
    out = []
    by_dir: dict[str, list[str]] = defaultdict(list)
    for n in names:
        p = Path(n)
        by_dir[p.parent.as_posix()].append(p.name)
    for d, base in by_dir.items():
        pat = re.compile(
            r"^\.(?:"
            + "|".join(re.escape(b) for b in base)
            + r")\.tyredamp-\d+-[0-9a-f]+\.(?:tmp|old)$"
        )
        try:
            entries = [e.name for e in os.scandir(root / d)]
        except OSError:
            continue
        out += [(Path(d) / e).as_posix() for e in entries if pat.match(e)]
    return out


def campaign_files(root: Path) -> list[str] | None:
    """What earlier campaign runs wrote in ``root`` (relative paths), or None if nothing.

    The files the ``campaign.json`` of the last run lists (every file any run
    wrote there), the entries of ``cache/`` with the cache's own names, and
    temporaries of our own pattern beside them. None when ``root`` holds
    neither a campaign summary nor a cache entry (not a campaign output).
    """
    doc = _summary(root)
    owned = [] if doc is None else _listed(doc)
    cache = root / "cache"
    try:
        entries = [e.name for e in os.scandir(cache)]
    except OSError:
        entries = []
    ours = [f"cache/{n}" for n in entries if _CACHE_NAME.fullmatch(n)]
    if doc is None and not ours:
        return None
    owned += ours
    return [*owned, *_temporaries(root, owned)]


_CACHE_NAME = re.compile(r"[0-9a-f]{64}\.json|\.[0-9a-f]{64}\.json\.tyredamp-\d+-[0-9a-f]+\.tmp")


def _write_table(rows: Sequence[dict[str, Any]], columns: dict[str, str], stem: Path) -> None:
    import csv
    import io

    import pyarrow as pa
    import pyarrow.parquet as pq

    types = {"string": pa.string(), "float": pa.float64(), "int": pa.int64()}
    schema = pa.schema([(c, types[t]) for c, t in columns.items()])
    data = {c: [r.get(c) for r in rows] for c in columns}
    for c, t in columns.items():
        if t == "float":
            data[c] = [None if v is None else float(v) for v in data[c]]
    table = pa.table(data, schema=schema)
    with atomic_path(stem.with_suffix(".parquet")) as tmp:
        pq.write_table(table, tmp)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(list(columns))
    for r in rows:
        w.writerow(
            [
                "" if r.get(c) is None else (repr(float(r[c])) if columns[c] == "float" else r[c])
                for c in columns
            ]
        )
    with atomic_path(stem.with_suffix(".csv")) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8")


_FILES = (
    "modes.parquet",
    "modes.csv",
    "steps.parquet",
    "steps.csv",
    "damping.parquet",
    "damping.csv",
    "trends.parquet",
    "trends.csv",
    "lateral.parquet",
    "lateral.csv",
    "trend_fits.json",
    "campaign.json",
)
_DOC_FILES = {
    "modal": "modes.json",
    "damping": "damping.json",
    "fit": "lateral.json",
    "rolling": "waves.json",
}


def write_outputs(
    campaign: Campaign, runs: Sequence[TestRun], out_dir: str | Path, *, report: bool = True
) -> CampaignResults:
    """Write every result file but the report (module docstring); returns what it computed.

    ``report`` only lists ``report.html`` among the files of the summary; the
    page itself is written by :func:`tyredamp.report.campaign.write_campaign_report`.
    """
    out = Path(out_dir)
    earlier = _summary(out)
    written = set() if earlier is None else set(_listed(earlier))
    model = campaign.tracking.get("model", "complex")
    tracking = track_by_study(runs, model)
    rows = mode_rows(runs, model, tracking)
    lrows = lateral_rows(runs)
    lat_obs, lat_quantities = lateral_trend_rows(lrows)
    fits = trend_fits(rows) + trend_fits(lat_obs, lat_quantities)
    trows = trend_rows(fits)
    drows = damping_rows(runs, rows)
    srows = step_rows(runs, model)
    files = [*_FILES, *(["report.html"] if report else [])]
    docs = {
        (r.spec.test_id, step): f"tests/{r.spec.test_id}/{_DOC_FILES[step]}"
        for r in runs
        for step in r.documents
    }
    written |= {*files, *docs.values()}
    # claimed before any is written: an interrupted run leaves an output a rerun accepts
    write_json(
        {"kind": KIND, "version": 1, "complete": False, "written": sorted(written)},
        out / "campaign.json",
    )
    _write_table(rows, MODE_COLUMNS, out / "modes")
    _write_table(srows, STEP_COLUMNS, out / "steps")
    _write_table(drows, DAMPING_COLUMNS, out / "damping")
    _write_table(trows, TREND_COLUMNS, out / "trends")
    _write_table(lrows, LATERAL_COLUMNS, out / "lateral")
    write_json([{**about, "fit": fit.to_dict()} for about, fit, _ in fits], out / "trend_fits.json")
    tests = []
    for r in runs:
        test_docs = {}
        for step, doc in r.documents.items():
            rel = docs[(r.spec.test_id, step)]
            write_json(doc, out / rel)
            test_docs[step] = rel
        mine = [x for x in srows if x["test_id"] == r.spec.test_id]
        tests.append(summary_entry(r, mine, test_docs, model))
    names = row_family_names(rows)
    families: dict[str, dict[str, Any]] = {}
    for row in rows:
        if row["family"] is None:
            continue
        f = families.setdefault(
            row["family"], {"family": row["family"], "n_modes": 0, "tests": set(), "slots": set()}
        )
        f["n_modes"] += 1
        f["tests"].add(row["test_id"])
        f["slots"].add(row["slot"])
    fam_list = [
        {
            "family": k,
            **names[k].to_dict(),
            "n_modes": v["n_modes"],
            "n_tests": len(v["tests"]),
            "pair": bool(v["slots"] - {""}),
            "median_frequency_hz": float(
                np.median([r["frequency_hz"] for r in rows if r["family"] == k])
            ),
        }
        for k, v in sorted(families.items(), key=lambda kv: _family_number(kv[0]))
    ]
    summary = {
        "kind": KIND,
        "version": 1,
        "tyredamp_version": __version__,
        "name": campaign.name,
        "campaign_file": str(campaign.path),
        "n_tests": len(runs),
        "n_ok": sum(r.ok for r in runs),
        "n_partial": sum(r.ok and bool(r.skipped) for r in runs),
        "n_failed": sum(not r.ok for r in runs),
        "n_checks_failed": sum(bool(quality_checks(r, model)["failed"]) for r in runs),
        "n_skipped_steps": sum(len(r.skipped) for r in runs),
        "steps_computed": sum(len(r.computed) for r in runs),
        "steps_reused": sum(len(r.reused) for r in runs),
        "tracking_model": model,
        "tracking": {
            "model": model,
            "matched_by_shape": sum(r["match"] == "shape" for r in rows),
            "matched_by_frequency": sum(r["match"] == "frequency" for r in rows),
            # scatter of one mode between neighbouring tests (tracking module, step 4)
            "scatter_ln_frequency": tracking.scatter.get("tau_f"),
            "scatter_ln_damping_ratio": tracking.scatter.get("tau_zeta"),
            "scatter_pairs": int(tracking.scatter.get("n", 0)),
        },
        "families": fam_list,
        "tests": tests,
        "complete": True,
        "files": files,
        # every file any run wrote here: a later run may replace these, and nothing else
        "written": sorted(written),
    }

    write_json(summary, out / "campaign.json")
    return CampaignResults(summary, rows, fits, lrows, drows, srows)


@dataclass(frozen=True)
class CampaignResults:
    """Everything :func:`write_outputs` computed (for the report and for callers)."""

    summary: dict[str, Any]
    modes: list[dict[str, Any]]
    fits: list[tuple[dict[str, Any], TrendFit, list[dict[str, Any]]]]
    lateral: list[dict[str, Any]]
    damping: list[dict[str, Any]] = field(default_factory=list)
    steps: list[dict[str, Any]] = field(default_factory=list)
