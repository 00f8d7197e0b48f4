"""The demo's ``results.json``: assembly from a :class:`~.demo.DemoResult` and its schema.

The document (``"kind": "tyredamp-demo-results"``, ``"version": 1``) holds
the settings, the radial study at the main pressure (RMSD of the real and
complex fits, the modes identified beside the true ones, the checks, the
damping matrix against the truth), the other pressures, the tyre model
(flexible ring across the pressures and rigid ring per pressure beside the
virtual tyre's values), and the lateral
study (ranking per condition and overall, corner frequencies, the vehicle
model and the time test). SI units unless a key says otherwise (``_hz``,
``_bar``, ``_kmh``, ``_pct``); non-finite numbers are written as ``null``.
The layout is described key by key in ``docs/reference/results-json.md`` and
formally in ``tyredamp/schemas/results.schema.json`` (JSON Schema draft
2020-12), which :func:`tyredamp.documents.demo.validate_results` applies;
reading and writing the file is :mod:`tyredamp.documents.demo`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__
from ..documents.demo import RESULTS_KIND, RESULTS_VERSION
from ..documents.jsonfile import finite
from ..exceptions import InputError
from .findings import DemoFindings, demo_findings, lateral_key, radial_key
from .tyremodel import tyre_model_section

if TYPE_CHECKING:
    from ..lateral.fit import LateralFit
    from .results import DampingComparison, DemoResult, LateralCondition, PressureRun

__all__ = [
    "build_results",
    "corner_frequency_std",
    "equivalent_models",
    "lateral_overall_ranking",
    "time_test_truth",
]


def _tyre_physics(tyre: Any) -> dict[str, Any]:
    """Cavity, load, tip loss and the sources of the tyre's non-proportional damping."""
    from ..virtual import damping_decomposition

    dd = damping_decomposition(tyre)
    fk, fn, alpha = dd.largest_coupling()
    return {
        "cavity": tyre.cavity is not None,
        "load_n": 0.0 if tyre.contact is None else tyre.contact.load,
        "attachment_damping_ns_m": tyre.layout.attachment_damping,
        "offdiagonal_share": dd.offdiagonal_share,
        "nonproportional_sources": dd.as_dict(),
        "largest_coupling": {"frequencies_hz": [fk, fn], "value": alpha},
    }


def _matrix(a: Any) -> list[list[float]]:
    return [[float(x) for x in row] for row in np.asarray(a, dtype=float)]


def _check(res: Any) -> dict[str, Any]:
    return {
        "passed": bool(res.passed),
        "figure": float(res.figure),
        "threshold": float(res.threshold),
        "summary": str(res.summary),
        "figures": {k: float(v) for k, v in res.figures.items()},
        "notes": list(res.notes),
    }


def _mode_entry(model: Any, i: int) -> dict[str, Any]:
    sf = model.std.get("frequency_hz")
    sz = model.std.get("damping_ratio")
    mpc = model.meta.get("mpc")
    return {
        "frequency_hz": float(model.frequency_hz[i]),
        "frequency_std_hz": None if sf is None else float(sf[i]),
        "damping_ratio": float(model.damping_ratio[i]),
        "damping_ratio_std": None if sz is None else float(sz[i]),
        "mpc": None if mpc is None else float(np.asarray(mpc, dtype=float)[i]),
    }


def _modes(run: PressureRun) -> list[dict[str, Any]]:
    """One entry per visible true mode or identified mode (identified and true side by side)."""
    truth = run.truth
    vis = truth.select("visible")
    rows: dict[tuple[str, int], dict[str, Any]] = {}
    order: list[tuple[str, int]] = []
    for t in range(vis.size):
        key: tuple[str, int] = ("t", t)
        j = int(vis[t])
        rows[key] = {
            "wave_number": int(truth.wave_number[j]),
            "true": {
                "frequency_hz": float(truth.frequency_hz[j]),
                "damping_ratio": float(truth.damping_ratio[j]),
                "mpc": float(truth.mpc[j]),
            },
            "complex": None,
            "real": None,
        }
        order.append(key)
    for name in ("complex", "real"):
        if name not in run.models:
            continue
        model = run.models[name]
        for it, m in run.matches[name].pairs:
            if m is None:
                continue
            if it is not None:
                rows[("t", it)][name] = _mode_entry(model, m)
            else:
                key = (name, int(m))
                rows[key] = {"wave_number": None, "true": None, "complex": None, "real": None}
                rows[key][name] = _mode_entry(model, m)
                order.append(key)

    def freq(key: tuple[str, int]) -> float:
        r = rows[key]
        src = r["true"] or r["complex"] or r["real"]
        return float(src["frequency_hz"])

    return [rows[k] for k in sorted(order, key=freq)]


def _fit_quality(run: PressureRun) -> dict[str, Any]:
    m = run.models
    rr = float(m["real"].meta["rmsd"]) if "real" in m else math.nan
    rc = float(m["complex"].meta["rmsd"]) if "complex" in m else math.nan
    return {
        "rmsd_real": rr,
        "rmsd_complex": rc,
        "rmsd_ratio": rr / rc if rc > 0 else math.nan,
        "relative_error_real": float(m["real"].meta["relative_error"]) if "real" in m else None,
        "relative_error_complex": (
            float(m["complex"].meta["relative_error"]) if "complex" in m else None
        ),
    }


def time_test_truth(result: DemoResult) -> tuple[NDArray[np.float64], dict[str, float]]:
    """The rig's own steady-state body acceleration in the time test and the gaps it shows.

    Returns
    -------
    (ndarray, dict)
        The exact body acceleration of the rig's vehicle (m/s^2, on
        ``time_test.data.time``) and ``{"truth_vs_measured": e, <model>: g}``:
        RMS of truth minus measurement over RMS of the measurement in the
        window (the noise alone), and for each fitted model the RMS of its
        prediction minus the truth over RMS of the truth (its own error,
        free of noise).
    """
    from ..lateral import harmonic_response

    tt = result.lateral.time_test
    t = tt.data.time
    truth = harmonic_response(
        result.lateral.vehicle.truth, tt.frequency_hz, tt.force_amplitude, t, "acceleration"
    )
    win = (t >= tt.window_s[0]) & (t <= tt.window_s[1])
    meas = tt.data.data[1]

    def rel(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
        return float(np.sqrt(np.mean((a[win] - b[win]) ** 2) / np.mean(b[win] ** 2)))

    gaps = {"truth_vs_measured": rel(truth, meas)}
    for name, pred in tt.predictions.items():
        gaps[name] = rel(pred, truth)
    return np.asarray(truth, dtype=float), gaps


def equivalent_models(conditions: Sequence[LateralCondition]) -> list[list[str]]:
    """Groups of fitted models that are the same model in other parameters.

    Two fits are the same model when they have the same number of parameters
    and their fitted FRFs agree to 1e-6 (relative, every line) at every
    condition: for example the first-order relaxation-length model with the
    speed known is the Maxwell model with ``k = C_alpha/sigma``,
    ``c = C_alpha/V`` (:meth:`~tyredamp.lateral.models.RelaxationLengthModel.maxwell`).
    Their ranking order is then decided by rounding alone.
    """
    if not conditions:
        return []
    names = [f.name for f in conditions[0].ranking.fits]
    groups: list[list[str]] = []
    seen: set[str] = set()
    for i, a in enumerate(names):
        if a in seen:
            continue
        group = [a]
        for b in names[i + 1 :]:
            if b in seen:
                continue
            same = True
            for c in conditions:
                fa, fb = c.fit(a), c.fit(b)
                scale = float(np.max(np.abs(fa.fitted)))
                if fa.n_params != fb.n_params or not np.all(
                    np.abs(fa.fitted - fb.fitted) <= 1e-6 * scale
                ):
                    same = False
                    break
            if same:
                group.append(b)
        if len(group) > 1:
            groups.append(sorted(group))
            seen.update(group)
    return groups


def corner_frequency_std(fit: LateralFit) -> float:
    """Standard error of ``f0 = K / (2 pi C_r)`` of a hysteretic fit (delta method), Hz.

    Uses the standard errors of ``log K`` and ``log C_r`` and their
    correlation (``fit.correlation`` is of the log-parameters):
    ``var(log f0) = s_K^2 + s_C^2 - 2 rho s_K s_C``.
    """
    names = list(fit.model.param_names)
    if "K" not in names or "C_r" not in names:
        raise InputError(f"fit: expected a model with K and C_r, got {names}")
    iK, iC = names.index("K"), names.index("C_r")
    sK = fit.stderr["K"] / fit.params["K"]
    sC = fit.stderr["C_r"] / fit.params["C_r"]
    rho = float(np.asarray(fit.correlation)[iK, iC])
    var = sK**2 + sC**2 - 2.0 * rho * sK * sC
    f0 = float(getattr(fit.model, "corner_frequency")())  # noqa: B009 - K and C_r checked
    return f0 * math.sqrt(var) if var >= 0 and math.isfinite(var) else math.nan


def _axle_errors(cond: LateralCondition, fit: LateralFit) -> tuple[float, float]:
    """Amplitude error and bias (fractions) of a ground fit predicting the axle-force FRF."""
    f = cond.axle.frf.frequency
    meas = cond.axle.frf.H[0, 0]
    pred = fit.model.response(f, "accelerance", "axle", cond.axle.wheel_mass)
    keep = np.abs(meas) > 0
    rel = (np.abs(pred[keep]) - np.abs(meas[keep])) / np.abs(meas[keep])
    return float(np.mean(np.abs(rel))), float(np.mean(rel))


def _condition(cond: LateralCondition) -> dict[str, Any]:
    rows = []
    for row, fit in zip(cond.ranking.rows(), cond.ranking.fits, strict=True):
        err, bias = _axle_errors(cond, fit)
        rows.append(
            {**row, "axle_amplitude_error_pct": 100 * err, "axle_amplitude_bias_pct": 100 * bias}
        )
    hy = cond.fit("hysteretic")
    params = {
        f.name: {
            n: {"value": f.params[n], "stderr": f.stderr[n], "unit": u}
            for n, u in zip(f.model.param_names, f.model.param_units, strict=True)
        }
        for f in cond.ranking.fits
    }
    return {
        "pressure_bar": cond.pressure_bar,
        "speed_kmh": cond.speed_kmh,
        "label": cond.label,
        "best": cond.ranking.best.name,
        "criterion": cond.ranking.criterion,
        "order": list(cond.ranking.order),
        "table": rows,
        "corner_frequency_hz": cond.corner_frequency_hz,
        "corner_frequency_std_hz": corner_frequency_std(hy),
        "road_damping": {
            "fitted": hy.params["C_r"],
            "stderr": hy.stderr["C_r"],
            "true": cond.true_road_damping,
            "ratio": hy.params["C_r"] / cond.true_road_damping,
            "unit": "N s/m",
        },
        "params": params,
        "truth": cond.truth.to_dict(),
    }


def lateral_overall_ranking(conditions: Sequence[LateralCondition]) -> list[dict[str, Any]]:
    """Models ranked over all conditions: by mean rank, then mean amplitude error.

    Returns
    -------
    list of dict
        ``model``, ``mean_rank``, ``wins`` (conditions where it is best),
        ``n_conditions``, ``mean_delta``, ``mean_amplitude_error_pct``,
        ``mean_amplitude_bias_pct``, ``mean_axle_amplitude_error_pct``,
        ``equivalent`` (the models of the entry: models that are the same
        model in other parameters, :func:`equivalent_models`, share one
        entry named ``"a = b"`` with their best mean rank, so that rounding
        cannot order them).
    """
    stats: dict[str, dict[str, list[float]]] = {}  # per model, one value per condition
    for c in conditions:
        for row, fit in zip(c.ranking.rows(), c.ranking.fits, strict=True):
            s = stats.setdefault(
                row["model"], {"rank": [], "delta": [], "err": [], "bias": [], "axle": []}
            )
            s["rank"].append(row["rank"])
            s["delta"].append(row["delta"])
            s["err"].append(row["amplitude_error_pct"])
            s["bias"].append(row["amplitude_bias_pct"])
            s["axle"].append(100 * _axle_errors(c, fit)[0])
    groups = equivalent_models(conditions)
    for group in groups:  # one model in other parameters: one entry, its best rank per condition
        parts = [stats.pop(g) for g in group if g in stats]
        if not parts:
            continue
        merged = {k: list(v) for k, v in parts[0].items()}
        merged["rank"] = [float(min(x)) for x in zip(*(p["rank"] for p in parts), strict=True)]
        merged["delta"] = [float(min(x)) for x in zip(*(p["delta"] for p in parts), strict=True)]
        stats[" = ".join(group)] = merged
    out: list[dict[str, Any]] = [
        {
            "model": name,
            "equivalent": next((list(g) for g in groups if " = ".join(g) == name), [name]),
            "mean_rank": float(np.mean(s["rank"])),
            "wins": int(sum(1 for r in s["rank"] if r == 1)),
            "n_conditions": len(s["rank"]),
            "mean_delta": float(np.mean(s["delta"])),
            "mean_amplitude_error_pct": float(np.mean(s["err"])),
            "mean_amplitude_bias_pct": float(np.mean(s["bias"])),
            "mean_axle_amplitude_error_pct": float(np.mean(s["axle"])),
        }
        for name, s in stats.items()
    ]
    out.sort(key=lambda r: (r["mean_rank"], r["mean_amplitude_error_pct"]))
    for i, r in enumerate(out):
        r["rank"] = i + 1
    return out


def _determined_error(
    dc: DampingComparison, pairs: Sequence[tuple[int, int, float]]
) -> float | None:
    """``||C'_id - C'_true||_F / ||C'_true||_F`` without the rows and columns of the modes
    the points cannot tell apart (:func:`tyredamp.damping.diagnostics.collinear_pairs`:
    their modal coordinates are mixed, so every term of theirs is); None when nothing
    is left."""
    mi = [int(k) for k in dc.model_index]
    out = {int(k) for i, j, _ in pairs for k in (i, j)}
    rows = np.array([k not in out for k in mi], dtype=bool)
    keep = np.outer(rows, rows)
    ref = float(np.linalg.norm(dc.modal_true[keep]))
    if ref == 0 or not np.any(keep):
        return None
    return float(np.linalg.norm((dc.modal - dc.modal_true)[keep])) / ref


def _radial_section(result: DemoResult, fnd: DemoFindings) -> dict[str, Any]:
    """``radial``: the main pressure, its checks, modes and damping, and every pressure."""
    s = result.settings
    r = result.radial
    main = r.main
    tyre = main.test.tyre
    dc = r.damping_truth
    dm = r.damping
    d = dm.diagnostics
    return {
        "pressure_bar": main.pressure_bar,
        "n_averages": main.n_periods,
        "snr_db": s.snr_db,
        "band_hz": [float(x) for x in main.identification.band_hz],
        "frf_kind": main.identification.frf_kind,
        "n_lines": int(main.identification.frequency.size),
        "tyre": {
            "description": "in-plane ring on an elastic foundation (virtual 295/80R22.5)",
            "radius_m": tyre.params.radius,
            "width_m": tyre.params.width,
            "n_points": tyre.layout.n_points,
            "drive_points": list(tyre.layout.drive_points),
            "n_dof": int(tyre.n_dof),
            "nonproportionality": tyre.nonproportionality,
            **_tyre_physics(tyre),
        },
        **_fit_quality(main),
        "verdict": {k: v.to_dict() for k, v in fnd.radial[radial_key(main)].items()},
        "checks": {
            "linearity": _check(r.linearity),
            "reciprocity": _check(r.reciprocity),
            "quality": _check(r.quality),
        },
        "modes": _modes(main),
        "damping": {
            "method": dm.method,
            "n_modes": dm.n_modes,
            "n_points": dm.n_points,
            "modal": _matrix(dc.modal),
            "modal_true": _matrix(dc.modal_true),
            "modal_error": dc.modal_error,
            "modal_error_symmetric": dc.modal_error_symmetric,
            "modal_error_determined": _determined_error(dc, d.collinear_pairs),
            "undetermined_pairs": [[i + 1, j + 1] for i, j, _ in d.collinear_pairs],
            "diagonal_error": dc.diagonal_error,
            "physical_error": dc.physical_error,
            "symmetry_modal": d.symmetry_modal,
            "definiteness_modal": d.definiteness_modal,
            "non_proportionality": d.non_proportionality,
            "negative_offdiagonal_fraction": d.negative_offdiagonal_fraction,
            "findings": list(dm.findings),
        },
        "pressures": [
            {
                "pressure_bar": run.pressure_bar,
                "n_averages": run.n_periods,
                **_fit_quality(run),
                "verdict": {k: v.to_dict() for k, v in fnd.radial[radial_key(run)].items()},
                "modes": _modes(run),
            }
            for run in r.runs
        ],
        "tyre_model": tyre_model_section(r.tyre_model),
    }


def _lateral_section(result: DemoResult, fnd: DemoFindings) -> dict[str, Any]:
    """``lateral``: every condition, the ranking, Figure 7, the vehicle and the time test."""
    from ..lateral.characteristics import corner_differences

    lat = result.lateral
    conds = [_condition(c) for c in lat.conditions]
    for c, cd_ in zip(lat.conditions, conds, strict=True):
        vs = fnd.lateral[lateral_key(c)]
        cd_["verdict"] = vs[c.ranking.best.name].to_dict()
        cd_["verdicts"] = {k: v.to_dict() for k, v in vs.items()}
    fig7 = lat.figure7.model
    cd = corner_differences(fig7)
    veh = lat.vehicle
    tt = lat.time_test
    ce = tt.causal
    ref = lat.reference
    _, tt_gaps = time_test_truth(result)
    return {
        "models": list(result.settings.lateral_models),
        "criterion": lat.conditions[0].ranking.criterion,
        "wheel_mass_kg": lat.rig.wheel_mass,
        "body_mass_kg": lat.rig.body_mass,
        "band_hz": [float(lat.rig.f_min), float(lat.rig.f_max)],
        "conditions": conds,
        "ranking": lateral_overall_ranking(lat.conditions),
        "corner_frequency_hz": [
            {
                "pressure_bar": c["pressure_bar"],
                "speed_kmh": c["speed_kmh"],
                "value": c["corner_frequency_hz"],
                "std": c["corner_frequency_std_hz"],
            }
            for c in conds
        ],
        "figure7": {
            "K": fig7.K,
            "h": fig7.h,
            "C_r": fig7.C_r,
            "f0_hz": cd.f0,
            "delta_ar_asymptote_db": cd.vs_high_asymptote,
            "delta_ar_maxwell_db": cd.vs_maxwell,
        },
        "vehicle": {
            "pressure_bar": ref.pressure_bar,
            "speed_kmh": ref.speed_kmh,
            "body_mass_kg": veh.body_mass,
            "resonance_hz": {
                k: (None if v is None else v.frequency) for k, v in veh.resonances.items()
            },
            "true_resonance_hz": (
                None if veh.truth_resonance is None else veh.truth_resonance.frequency
            ),
        },
        "equivalent_models": equivalent_models(lat.conditions),
        "time_response": {
            "frequency_hz": tt.frequency_hz,
            "truth_error": tt_gaps["truth_vs_measured"],
            "error_to_truth": {k: v for k, v in tt_gaps.items() if k != "truth_vs_measured"},
            "force_amplitude_n": tt.force_amplitude,
            "window_s": list(tt.window_s),
            "relative_error": dict(tt.errors),
            "causal": {
                "band_hz": list(ce.band),
                "n_arms": ce.n_arms,
                "stiffness_error": ce.stiffness_error,
                "frf_error": ce.frf_error,
                "impulse_error": ce.impulse_error,
                "precursor_ratio": ce.precursor_ratio,
                "sine_error": ce.sine_error,
            },
        },
    }


def build_results(result: DemoResult, files: Sequence[str] | None = None) -> dict[str, Any]:
    """The results.json document of a demo run (strict JSON types).

    Its layout, key by key, is in ``docs/reference/results-json.md``.

    Parameters
    ----------
    result : DemoResult
    files : sequence of str, optional
        Files written beside results.json (relative paths), listed under
        ``"files"``.

    Returns
    -------
    dict
        Valid against :func:`tyredamp.documents.demo.load_schema` (checked in the tests).
    """
    s = result.settings
    fnd = demo_findings(result)
    doc = {
        "kind": RESULTS_KIND,
        "version": RESULTS_VERSION,
        "tyredamp_version": __version__,
        "quick": s.quick,
        "seed": s.seed,
        "settings": s.to_dict(),
        "elapsed_s": result.elapsed_s,
        "timings_s": dict(result.timings),
        "files": list(files or []),
        "radial": _radial_section(result, fnd),
        "lateral": _lateral_section(result, fnd),
        "warnings": [f.to_dict() for f in fnd.findings],
    }
    if result.rolling is not None:
        from .rolling import rolling_section

        doc["rolling"] = rolling_section(result.rolling)
    if result.damping_models is not None:
        from .dampmodels import dampmodels_section

        doc["damping_models"] = dampmodels_section(result.damping_models)
    out = finite(doc)
    assert isinstance(out, dict)
    return out
