"""The campaign's tidy tables: their columns, and their rows built from the test results.

One row per identified mode (with its family and slot from the tracking),
per entry of a modal damping matrix, per fitted lateral parameter, and per
point of a fitted trend (:mod:`.series_trend`). The files they are written to
are listed in :mod:`.outputs`.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from typing import Any

import numpy as np

from . import steps
from .families import FamilyName, ModeWave, family_names, mode_wave
from .runner import TestRun
from .series_trend import TrendFit, fit_trend
from .spec import CONDITIONS, NUMERIC_CONDITIONS
from .tracking import ModeSet, Tracking, track_modes

__all__ = [
    "DAMPING_COLUMNS",
    "LATERAL_COLUMNS",
    "MODE_COLUMNS",
    "TREND_COLUMNS",
    "damping_rows",
    "lateral_rows",
    "lateral_trend_rows",
    "mode_rows",
    "mode_sets",
    "row_family_names",
    "track_by_study",
    "trend_fits",
    "trend_rows",
]

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
