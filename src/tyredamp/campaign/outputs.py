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
"""

from __future__ import annotations

import json
import math
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
from . import steps
from .families import FamilyName, ModeWave, family_names, mode_wave
from .runner import TestRun
from .series_trend import TrendFit, fit_trend
from .spec import CONDITIONS, NUMERIC_CONDITIONS, Campaign
from .status import STEP_COLUMNS, quality_checks, step_rows, summary_entry
from .tracking import ModeSet, Tracking, track_modes

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

_COND_TYPES = {c: ("string" if CONDITIONS[c][1] == "text" else "float") for c in CONDITIONS}
#: Columns of the tidy mode table and their types.
MODE_COLUMNS: dict[str, str] = {
    "test_id": "string",
    "file": "string",
    **_COND_TYPES,
    "model": "string",
    "mode": "int",
    "family": "string",
    "family_label": "string",
    "slot": "string",
    "wave_number": "int",
    "wave_fraction": "float",
    "member": "string",
    "match": "string",
    "match_mac": "float",
    "match_z": "float",
    "frequency_hz": "float",
    "frequency_std_hz": "float",
    "damping_ratio": "float",
    "damping_ratio_std": "float",
    "mpc": "float",
    "modal_damping": "float",
    "modal_damping_std": "float",
}
#: Columns of the trend table.
TREND_COLUMNS: dict[str, str] = {
    "family": "string",
    "slot": "string",
    "quantity": "string",
    "condition": "string",
    "series": "string",
    "tyre": "string",
    "x": "float",
    "n": "int",
    "mean": "float",
    "std_error": "float",
    "trend": "float",
    "trend_std": "float",
    "degree": "int",
}
#: Columns of the damping-matrix table.
DAMPING_COLUMNS: dict[str, str] = {
    "test_id": "string",
    "file": "string",
    **_COND_TYPES,
    "mode_k": "int",
    "mode_n": "int",
    "family_k": "string",
    "slot_k": "string",
    "family_n": "string",
    "slot_n": "string",
    "value": "float",
    "std": "float",
}
LATERAL_COLUMNS: dict[str, str] = {
    "test_id": "string",
    "file": "string",
    **_COND_TYPES,
    "model": "string",
    "rank": "int",
    "aic": "float",
    "bic": "float",
    "amplitude_error": "float",
    "parameter": "string",
    "value": "float",
    "stderr": "float",
    "unit": "string",
    "at_bound": "int",
}
_QUANTITIES = (
    ("frequency_hz", "frequency_std_hz"),
    ("damping_ratio", "damping_ratio_std"),
    ("modal_damping", "modal_damping_std"),
)


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


def _float(v: Any) -> float:
    return math.nan if v is None else float(v)


def mode_sets(runs: Sequence[TestRun], model: str) -> list[ModeSet]:
    """The identified modes of every successful radial or rolling test, for :func:`track_modes`."""
    out = []
    for r in runs:
        recs = steps.mode_records(r.spec.study, r.documents, model)
        if not recs or not ("modal" in r.documents or "rolling" in r.documents):
            continue
        out.append(
            ModeSet(
                r.spec.test_id,
                r.spec.conditions,
                np.array([_float(m["frequency_hz"]) for m in recs]),
                np.array([_float(m["damping_ratio"]) for m in recs]),
                np.column_stack([m["shape"] for m in recs]),
                tuple(recs[0]["points"]),
                np.array([_float(m["frequency_std_hz"]) for m in recs]),
                np.array([_float(m["damping_ratio_std"]) for m in recs]),
            )
        )
    return out


def track_by_study(runs: Sequence[TestRun], model: str) -> Tracking:
    """:func:`track_modes` per study (radial, rolling), families numbered on across studies.

    A rolling test's travelling waves and a standing test's modes are not one
    family even at one frequency, so each study is tracked on its own; the
    rolling study's families follow the radial study's (``F{k+1}``, ...), and
    the scatter is the first study's.
    """
    sets = mode_sets(runs, model)
    study = {r.spec.test_id: r.spec.study for r in runs}
    groups: dict[str, list[ModeSet]] = defaultdict(list)
    for m in sets:
        groups[study[m.test_id]].append(m)
    if len(groups) <= 1:
        return track_modes(sets)
    out = Tracking()
    offset = 0
    for name in sorted(groups):  # radial before rolling
        t = track_modes(groups[name])
        fams = sorted(set(t.family.values()), key=lambda f: int(f[1:]))
        ren = {f: f"F{offset + i + 1}" for i, f in enumerate(fams)}
        offset += len(fams)
        out.family.update({k: ren[v] for k, v in t.family.items()})
        out.slot.update(t.slot)
        out.mac.update(t.mac)
        out.method.update(t.method)
        out.distance.update(t.distance)
        out.pairs |= {ren[p] for p in t.pairs}
        if not out.scatter:
            out.scatter = dict(t.scatter)
    return out


def mode_rows(
    runs: Sequence[TestRun], model: str = "complex", tracking: Tracking | None = None
) -> list[dict[str, Any]]:
    """The tidy table: one row per mode of every test, with conditions and family.

    ``tracking`` is :func:`~.tracking.track_modes` of :func:`mode_sets` (computed
    when not given).
    """
    if tracking is None:
        tracking = track_by_study(runs, model)
    rows = []
    for r in runs:
        for m in steps.mode_records(r.spec.study, r.documents, model):
            q = (r.spec.test_id, m["mode"] - 1)
            wave = mode_wave(m["angles_deg"], m["shape"], m["reference_deg"])
            fam = tracking.family.get(q)
            row: dict[str, Any] = {"test_id": r.spec.test_id, "file": r.spec.rel}
            row.update({c: r.spec.conditions.get(c) for c in CONDITIONS})
            row.update(
                {
                    "model": m["model"],
                    "mode": m["mode"],
                    "family": fam,
                    "family_label": None,
                    "slot": tracking.slot.get(q, ""),
                    "wave_number": None if wave is None else wave.n,
                    "wave_fraction": math.nan if wave is None else wave.fraction,
                    "member": None if wave is None else wave.member,
                    "match": tracking.method.get(q, ""),
                    "match_mac": tracking.mac.get(q),
                    "match_z": tracking.distance.get(q),
                }
            )
            for k in (
                "frequency_hz",
                "frequency_std_hz",
                "damping_ratio",
                "damping_ratio_std",
                "mpc",
                "modal_damping",
                "modal_damping_std",
            ):
                row[k] = _float(m[k])
            rows.append(row)
    names = row_family_names(rows)
    for row in rows:
        if row["family"] is not None:
            row["family_label"] = names[row["family"]].label
    return rows


def row_family_names(rows: Sequence[dict[str, Any]]) -> dict[str, FamilyName]:
    """The name of every family of the mode table (:func:`.families.family_names`)."""
    waves: dict[str, list[ModeWave | None]] = {}
    for r in sorted(rows, key=lambda r: _family_number(r["family"] or "F0")):
        if r["family"] is None:
            continue
        n = r["wave_number"]
        waves.setdefault(r["family"], []).append(
            None if n is None else ModeWave(int(n), float(r["wave_fraction"]), r["member"])
        )
    pairs = {r["family"] for r in rows if r["family"] is not None and r["slot"]}
    return family_names(waves, sorted(pairs))


def _family_number(name: str) -> int:
    """``F12`` -> 12 (the tracking's names, in order of frequency)."""
    return int(name[1:]) if name[1:].isdigit() else 0


def damping_rows(runs: Sequence[TestRun], modes: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """The modal damping matrix ``C'`` of every test, one row per entry, by mode family.

    ``C'_kn`` (1/s) with its Monte Carlo standard error, for the modes ``k``
    and ``n`` of the tracked model, labelled by their families and slots, so
    the change of the damping matrix (couplings included) across conditions
    can be followed.
    """
    label = {(r["test_id"], r["mode"]): (r["family"], r["slot"]) for r in modes}
    model = {r["test_id"]: r["model"] for r in modes}
    out = []
    for run in runs:
        doc = run.documents.get("damping")
        tid = run.spec.test_id
        if doc is None or doc.get("meta", {}).get("model") != model.get(tid):
            continue
        cp = np.asarray(doc["modal"], dtype=float)
        std = doc.get("std", {}).get("modal")
        sd = np.full(cp.shape, np.nan) if std is None else np.asarray(std, dtype=float)
        for k in range(cp.shape[0]):
            for n in range(cp.shape[1]):
                fk, sk = label.get((tid, k + 1), (None, ""))
                fn, sn = label.get((tid, n + 1), (None, ""))
                row: dict[str, Any] = {"test_id": tid, "file": run.spec.rel}
                row.update({c: run.spec.conditions.get(c) for c in CONDITIONS})
                row.update(
                    {
                        "mode_k": k + 1,
                        "mode_n": n + 1,
                        "family_k": fk,
                        "slot_k": sk,
                        "family_n": fn,
                        "slot_n": sn,
                        "value": float(cp[k, n]),
                        "std": float(sd[k, n]),
                    }
                )
                out.append(row)
    return out


def lateral_rows(runs: Sequence[TestRun]) -> list[dict[str, Any]]:
    """One row per fitted parameter of every lateral model of every lateral test."""
    rows = []
    for r in runs:
        for rec in steps.lateral_records(r.documents):
            for p, v in rec["params"].items():
                row: dict[str, Any] = {"test_id": r.spec.test_id, "file": r.spec.rel}
                row.update({c: r.spec.conditions.get(c) for c in CONDITIONS})
                row.update(
                    {
                        "at_bound": int(p in rec.get("at_bound", ())),
                        "model": rec["model"],
                        "rank": rec["rank"],
                        "aic": _float(rec["aic"]),
                        "bic": _float(rec["bic"]),
                        "amplitude_error": _float(rec["amplitude_error"]),
                        "parameter": p,
                        "value": _float(v),
                        "stderr": _float(rec["stderr"].get(p)),
                        "unit": rec["units"].get(p, ""),
                    }
                )
                rows.append(row)
    return rows


def _series_key(row: dict[str, Any], condition: str) -> tuple[Any, ...]:
    others = tuple(
        (c, row.get(c)) for c in NUMERIC_CONDITIONS if c != condition and row.get(c) is not None
    )
    return (row.get("tyre") or "", others)


def _series_label(key: tuple[Any, ...]) -> str:
    tyre, others = key
    parts = [f"tyre {tyre}"] if tyre else []
    parts += [f"{c} {v:g}" for c, v in others]
    return ", ".join(parts) or "all"


def trend_fits(
    rows: Sequence[dict[str, Any]],
    quantities: Sequence[tuple[str, str]] = _QUANTITIES,
) -> list[tuple[dict[str, Any], TrendFit, list[dict[str, Any]]]]:
    """Fit every (family, slot, quantity, condition, series) with >= 3 distinct condition values.

    ``quantities`` lists ``(value key, standard-error key)`` of the rows
    (default: frequency, damping ratio and modal damping of the mode table).
    Returns ``(about, fit, points)`` for each: ``about`` names the family,
    slot, quantity (and its ``std_key``), condition and series; ``points``
    are the rows used.
    """
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        if r.get("family") is None:
            continue
        for cond in NUMERIC_CONDITIONS:
            if r.get(cond) is None:
                continue
            groups[(r["family"], r["slot"], cond, _series_key(r, cond))].append(r)
    out = []
    for (fam, slot, cond, key), pts in sorted(groups.items(), key=lambda kv: str(kv[0])):
        if len({p[cond] for p in pts}) < 3:
            continue
        for q, qs in quantities:
            use = [p for p in pts if p.get(q) is not None and math.isfinite(p[q])]
            if len({p[cond] for p in use}) < 3:
                continue
            transform = "square" if (q == "frequency_hz" and cond == "pressure_bar") else "none"
            fit = fit_trend(
                [p[cond] for p in use],
                [p[q] for p in use],
                [_float(p.get(qs)) for p in use],
                transform=transform,
            )
            about = {
                "family": fam,
                "slot": slot,
                "quantity": q,
                "std_key": qs,
                "condition": cond,
                "series": _series_label(key),
                "tyre": key[0],
                "fixed": dict(key[1]),
            }
            out.append((about, fit, use))
    return out


def trend_rows(
    fits: Sequence[tuple[dict[str, Any], TrendFit, list[dict[str, Any]]]],
) -> list[dict[str, Any]]:
    """The trend table: per fit and distinct condition value, observed mean +- s.e. and trend."""
    out = []
    for about, fit, pts in fits:
        cond, q = about["condition"], about["quantity"]
        qs = about["std_key"]
        by_x: dict[float, list[dict[str, Any]]] = defaultdict(list)
        for p in pts:
            by_x[float(p[cond])].append(p)
        for x in sorted(by_x):
            obs = by_x[x]
            vals = np.array([p[q] for p in obs])
            ses = np.array([_float(p.get(qs)) for p in obs])
            if len(obs) > 1:
                se = float(np.std(vals, ddof=1) / math.sqrt(len(obs)))
            else:
                se = float(ses[0]) if math.isfinite(ses[0]) else math.nan
            y, sy = fit.predict([x])
            out.append(
                {
                    "family": about["family"],
                    "slot": about["slot"],
                    "quantity": q,
                    "condition": cond,
                    "series": about["series"],
                    "tyre": about["tyre"],
                    "x": x,
                    "n": len(obs),
                    "mean": float(np.mean(vals)),
                    "std_error": se,
                    "trend": float(y[0]),
                    "trend_std": float(sy[0]),
                    "degree": fit.degree,
                }
            )
    return out


def lateral_trend_rows(lrows: Sequence[dict[str, Any]]) -> tuple[list[dict[str, Any]], list]:
    """Lateral parameters as trend observations: family ``lateral <model>``, one key per parameter.

    Returns the rows and their ``(value key, standard-error key)`` quantities
    for :func:`trend_fits` (so each model parameter gets its trend against
    speed, pressure, ... like the modal quantities).
    """
    out: dict[tuple[str, str], dict[str, Any]] = {}
    params: list[str] = []
    for r in lrows:
        row = out.setdefault(
            (r["test_id"], r["model"]),
            {
                "test_id": r["test_id"],
                "family": f"lateral {r['model']}",
                "slot": "",
                **{c: r.get(c) for c in CONDITIONS},
            },
        )
        # a parameter the fit left on the bound of its search is not an estimate:
        # it is kept out of the trends (its row in lateral.csv stays)
        row[r["parameter"]] = None if r.get("at_bound") else r["value"]
        row[f"{r['parameter']}_std"] = r["stderr"]
        if r["parameter"] not in params:
            params.append(r["parameter"])
    return list(out.values()), [(p, f"{p}_std") for p in params]


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
