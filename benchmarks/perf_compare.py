"""tyredamp against sdypy-EMA (LSCF + LSFD): speed and accuracy on the same FRFs.

Run: ``python benchmarks/perf_compare.py [--quick] [--blas-threads 1]
[--set all|tyre|random|physical|long|million] [--json PATH]`` (needs the ``bench`` extra:
``pip install -e ".[bench]"``).

For each case both tools get the same FRFs, the same band and the same
highest polynomial order (tyredamp ``max_order = 2 P``, sdypy-EMA
``pol_order_high = P``, i.e. orders 2, 4, ..., 2P). The runs alternate
(tyredamp, sdypy-EMA, sdypy-EMA, tyredamp, ...) in one process; the times
are medians over the repeats. Three runs per repeat:

* ``tyredamp``: :func:`~tyredamp.modal.identify_modes` as a user calls it
  (automatic pole selection with no frequencies given, variable-projection
  refinement, out-of-band residual modes, standard errors), complex model;
* ``tyredamp no search``: the same call with ``search=False`` (no residual
  search for missed modes; every other stage as a user gets it): what the
  search costs on a case where, as on the tyre, it finds nothing;
* ``tyredamp lscf+lsfd``: the same function reduced to what sdypy-EMA does
  (``frequencies`` = true natural frequencies, ``refine=False``,
  ``max_helpers=0``);
* ``sdypy-EMA``: ``Model.get_poles("lscf")``, ``select_closest_poles`` with
  the true natural frequencies and a search window of half the smallest mode
  spacing (both in its favour: it is told where the modes are, and its
  default 50 Hz window jumps to a neighbouring mode on the tyre), then
  ``get_constants("lsfd")`` with lower and upper residuals. SIMO: first input.

Pole time = LSCF + stabilisation + selection; residue time = the rest.
Accuracy is against the exact modes and noise-free FRFs
(:func:`perf_common.accuracy`).
"""

from __future__ import annotations

import argparse
import functools
import time
from typing import Any

import numpy as np
from perf_common import (
    RESULTS_DIR,
    Case,
    RunResult,
    accuracy,
    limit_blas,
    machine_info,
    mimo_case,
    physical_case,
    print_table,
    run_sdypy,
    run_tyredamp,
    sdypy_available,
    synthetic_case,
    tyre_case,
    tyre_test_case,
    write_json,
)

from tyredamp.exceptions import TyredampError

#: random MIMO cases (n_out, n_in, n_lines, n_modes, SNR dB) of --set random
RANDOM = [(4, 1, 1000, 10, 60.0), (16, 2, 3000, 20, 35.0), (32, 2, 4000, 20, 50.0)]
#: larger random cases of --set long, with their orders: many outputs and inputs,
#: and a long record (a million lines)
LONG = [((64, 3, 8000, 20, 30.0), 80), ((4, 1, 1_000_000, 10, 40.0), 40)]

#: random physical structures (n_out, n_in, n_lines, n_modes, SNR dB) of --set physical
#: (perf_common.physical_case), with their orders (four per mode, at least 40)
PHYSICAL = [
    ((4, 1, 1000, 8, 60.0), 40),
    ((8, 1, 2000, 12, 50.0), 48),
    ((16, 2, 3000, 20, 40.0), 80),
    ((32, 2, 4000, 24, 35.0), 96),
    ((64, 3, 8000, 30, 30.0), 120),
]

TOOLS = ("tyredamp", "tyredamp no search", "tyredamp lscf+lsfd", "sdypy-EMA")


def _failed(tool: str, case: Case, error: Exception) -> RunResult:
    """A run that raised: no modes, a zero model, no time; the message in ``extra["error"]``."""
    f = case.frf.frequency
    lines = np.flatnonzero((f >= case.band[0]) & (f <= case.band[1]))
    nan = float("nan")
    return RunResult(
        tool=tool,
        t_poles=nan,
        t_residues=nan,
        poles=np.zeros(0, dtype=complex),
        shapes=np.zeros((case.frf.n_out, 0), dtype=complex),
        reconstruction=np.zeros((case.frf.n_out, case.frf.n_in, lines.size), dtype=complex),
        lines=lines,
        extra={"error": f"{type(error).__name__}: {error}"},
    )


def _run(tool: str, case: Case, order: int) -> RunResult:
    """One run of ``tool``; a tyredamp error (e.g. a given frequency without a pole) is recorded."""
    if tool.startswith("tyredamp"):
        try:
            return _run_tyredamp(tool, case, order)
        except TyredampError as e:
            return _failed(tool, case, e)
    return run_sdypy(case, pol_order_high=order // 2)


def _run_tyredamp(tool: str, case: Case, order: int) -> RunResult:
    if tool == "tyredamp":
        return run_tyredamp(case, max_order=order)
    if tool == "tyredamp no search":
        r = run_tyredamp(case, max_order=order, search=False)
        r.tool = tool
        return r
    if tool == "tyredamp lscf+lsfd":
        r = run_tyredamp(
            case, max_order=order, frequencies=case.frequency_hz, refine=False, max_helpers=0
        )
        r.tool = tool
        return r
    raise ValueError(f"unknown tool {tool!r}")


def compare_case(case: Case, order: int, repeats: int, tools: tuple[str, ...]) -> dict[str, Any]:
    """Alternating runs of every tool on one case; medians of the times, accuracy of run 1."""
    runs: dict[str, list[RunResult]] = {t: [] for t in tools}
    for r in range(repeats):
        for tool in tools if r % 2 == 0 else tools[::-1]:
            runs[tool].append(_run(tool, case, order))
    out: dict[str, Any] = {
        "case": case.name,
        "n_out": case.frf.n_out,
        "n_in": case.frf.n_in,
        "n_lines": int(runs[tools[0]][0].lines.size),
        "n_modes": int(case.poles.size),
        "band_hz": list(case.band),
        "max_order": order,
        "noise": case.noise,
        "repeats": repeats,
        "tools": {},
    }
    if "physics" in case.meta:
        out["physics"] = case.meta["physics"]
    for tool, rs in runs.items():
        acc = accuracy(case, rs[0])
        out["tools"][tool] = {
            "t_poles_s": float(np.median([x.t_poles for x in rs])),
            "t_residues_s": float(np.median([x.t_residues for x in rs])),
            "t_total_s": float(np.median([x.t_total for x in rs])),
            "t_total_all_s": [x.t_total for x in rs],
            "t_cpu_s": float(np.median([x.t_cpu for x in rs])),
            "t_cpu_all_s": [x.t_cpu for x in rs],
            "accuracy": acc,
            "extra": rs[0].extra,
        }
    return out


def better_or_equal(a: dict[str, Any], b: dict[str, Any]) -> dict[str, bool]:
    """Is accuracy ``a`` at least as good as ``b``, figure by figure?"""
    return {
        "modes_found": a["n_found"] >= b["n_found"],
        "max_freq_error": a["max_freq_error"] <= b["max_freq_error"],
        "max_damping_error": a["max_damping_error"] <= b["max_damping_error"],
        "min_mac": a["min_mac"] >= b["min_mac"],
        "rel_error_true": a["rel_error_true"] <= b["rel_error_true"],
    }


def print_physics(res: dict[str, Any]) -> None:
    """One line on the structure of a physical case (``perf_physical.describe``)."""
    p = res.get("physics")
    if not p:
        return
    snr = np.asarray(p["peak_snr_db"], dtype=float)
    print(
        f"\n{p['n_dof']} DOF, damping {100 * p['zeta_min']:.2g}-{100 * p['zeta_max']:.2g} %, "
        f"MPC median {p['mpc_median']:.4f} (min {p['mpc_min']:.3f}), off-diagonal share of "
        f"C' {p['offdiag_share']:.2f}; close pair {p['pair_hz'][0]:.1f}/{p['pair_hz'][1]:.1f} Hz "
        f"{p['pair_bandwidths']:.2f} half-power bandwidths apart; weak mode {p['weak_hz']:.1f} Hz "
        f"{p['weak_below_median_db']:.1f} dB below the median peak and "
        f"{p['weak_peak_snr_db']:.0f} dB over the noise; peaks over the noise "
        f"{snr.min():.0f}-{snr.max():.0f} dB",
        flush=True,
    )


def print_case(res: dict[str, Any]) -> None:
    print_physics(res)
    ref = res["tools"].get("sdypy-EMA")
    rows = []
    for tool, d in res["tools"].items():
        a = d["accuracy"]
        speed = ref["t_total_s"] / d["t_total_s"] if ref else None
        speed_cpu = ref["t_cpu_s"] / d["t_cpu_s"] if ref else None
        rows.append(
            [
                tool,
                d["t_poles_s"],
                d["t_residues_s"],
                d["t_total_s"],
                speed,
                d["t_cpu_s"],
                speed_cpu,
                f"{a['n_found']}/{a['n_true']}",
                a["max_freq_error"],
                a["max_damping_error"],
                a["min_mac"],
                a["rel_error_true"],
                a["rel_error_data"],
            ]
        )
    print_table(
        [
            "tool",
            "poles s",
            "residues s",
            "total s",
            "sdypy/this",
            "cpu s",
            "sdypy/this cpu",
            "found",
            "max|df/f|",
            "max|dz/z|",
            "min MAC",
            "err(true)",
            "err(data)",
        ],
        rows,
        title=(
            f"\n== {res['case']}: {res['n_lines']} lines in {res['band_hz'][0]:g}-"
            f"{res['band_hz'][1]:g} Hz, order {res['max_order']}, median of {res['repeats']}"
        ),
    )
    for tool, d in res["tools"].items():
        if "error" in d["extra"]:
            print(f"{tool} raised: {d['extra']['error']}", flush=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats, no 1024-output case")
    ap.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument("--json", default=str(RESULTS_DIR / "compare.json"), help="output JSON")
    ap.add_argument(
        "--set",
        choices=("all", "tyre", "random", "physical", "long", "million"),
        default="all",
        help="the tyre and 128-output cases, the random MIMO cases, or both; physical: "
        "random physical structures (M, C, K; 4-64 outputs, 1-3 inputs, 8-30 modes); long: "
        "64 outputs x 3 inputs x 8000 lines and 4 outputs x 1e6 lines; million: the 1e6-line "
        "record alone, tyredamp's default and sdypy-EMA only",
    )
    a = ap.parse_args(argv)
    pool = limit_blas(a.blas_threads)
    if not sdypy_available():
        raise SystemExit('sdypy-EMA is not installed: pip install -e ".[bench]"')
    rep = 3 if a.quick else 7
    t_start = time.perf_counter()
    specs: list[tuple[Any, int, int]] = []
    if a.set in ("all", "tyre"):
        specs += [
            (lambda: tyre_case(40.0, seed=1), 60, rep),
            (lambda: tyre_test_case(seed=0), 60, rep),
            (lambda: synthetic_case(128, 4000, 20, seed=0), 120, max(1, rep // 2)),
        ]
        if not a.quick:
            specs.append((lambda: synthetic_case(1024, 4000, 20, seed=0), 120, 1))
    if a.set == "long":
        specs += [(functools.partial(mimo_case, *spec), order, rep) for spec, order in LONG]
    tools = TOOLS
    if a.set == "million":
        spec, order = LONG[1]
        specs += [(functools.partial(mimo_case, *spec), order, 1 if a.quick else 3)]
        tools = ("tyredamp", "sdypy-EMA")
    if a.set in ("all", "random"):
        # random structures (perf_common.mimo_case): sdypy-EMA sees the first input
        specs += [
            (functools.partial(mimo_case, *spec), order, rep)
            for spec, order in zip(RANDOM, (40, 80, 80), strict=True)
        ]
    if a.set == "physical":
        # random physical structures (perf_common.physical_case): sdypy-EMA sees the first input
        specs += [(functools.partial(physical_case, *spec), order, rep) for spec, order in PHYSICAL]
    results = []
    for make, order, n in specs:
        case = make()
        res = compare_case(case, order, n, tools)
        print_case(res)
        results.append(res)
    summary = []
    for res in results:
        t, s = res["tools"]["tyredamp"], res["tools"]["sdypy-EMA"]
        ll = res["tools"].get("tyredamp lscf+lsfd", {"t_total_s": float("nan")})
        ns = res["tools"].get("tyredamp no search", {"t_total_s": float("nan")})
        be = better_or_equal(t["accuracy"], s["accuracy"])
        summary.append(
            {
                "case": res["case"],
                "speedup_total": s["t_total_s"] / t["t_total_s"],
                "speedup_cpu": s["t_cpu_s"] / t["t_cpu_s"],
                "speedup_poles": s["t_poles_s"] / max(t["t_poles_s"], 1e-9),
                "speedup_residues": s["t_residues_s"] / max(t["t_residues_s"], 1e-9),
                "speedup_total_lscf_lsfd": s["t_total_s"] / ll["t_total_s"],
                "speedup_total_no_search": s["t_total_s"] / ns["t_total_s"],
                "accuracy_better_or_equal": be,
                "target_met": bool(s["t_total_s"] / t["t_total_s"] >= 2.0 and all(be.values())),
            }
        )
    print_table(
        [
            "case",
            "sdypy/tyredamp total",
            "cpu",
            "poles",
            "residues",
            "sdypy/no search",
            "sdypy/lscf+lsfd",
            "accuracy >= sdypy",
            "2x & accuracy",
        ],
        [
            [
                s["case"],
                s["speedup_total"],
                s["speedup_cpu"],
                s["speedup_poles"],
                s["speedup_residues"],
                s["speedup_total_no_search"],
                s["speedup_total_lscf_lsfd"],
                ",".join(k for k, v in s["accuracy_better_or_equal"].items() if not v) or "all",
                s["target_met"],
            ]
            for s in summary
        ],
        title="\n== speed ratio (sdypy-EMA time / tyredamp time; > 1: tyredamp faster); "
        "accuracy column lists the figures where tyredamp is worse",
    )
    doc = {
        "benchmark": "perf_compare",
        "quick": a.quick,
        "machine": machine_info(a.blas_threads),
        "elapsed_s": time.perf_counter() - t_start,
        "cases": results,
        "summary": summary,
    }
    print(f"\nwrote {write_json(doc, a.json)} ({doc['elapsed_s']:.0f} s)")
    del pool
    return doc


if __name__ == "__main__":
    main()
