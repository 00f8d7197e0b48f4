"""Run every performance benchmark and summarise the targets.

Run: ``python benchmarks/run_all.py [--quick] [--blas-threads 1]``
(``pip install -e ".[bench]"`` first, for sdypy-EMA).

Runs, one subprocess each, ``perf_compare.py`` (tyredamp against sdypy-EMA),
``perf_crlb.py`` (spread against the Cramér-Rao bound, Monte Carlo) and
``perf_scaling.py`` (time and memory against size, the demo) and
``perf_profile.py`` (where the identification spends its time); their tables
stream to the terminal and their JSON goes to ``benchmarks/results/``
(git-ignored). Then prints one table of the targets, measured, and writes
``results/summary.json`` and ``results/summary.md`` (the Markdown table of
the README's "Performance" section). ``--quick`` takes a few minutes on two
busy cores, the full run about a quarter of an hour.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from perf_common import RESULTS_DIR, machine_info, print_table, write_json

HERE = Path(__file__).resolve().parent
PARTS = ("perf_compare", "perf_crlb", "perf_scaling", "perf_profile")


def _f(x: float, nd: int = 2) -> str:
    return f"{x:.{nd}f}"


def targets(docs: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per target: what was asked, what was measured, met or not."""
    rows: list[dict[str, Any]] = []
    if "perf_compare" in docs:
        for s in docs["perf_compare"]["summary"]:
            worse = [k for k, v in s["accuracy_better_or_equal"].items() if not v]
            rows.append(
                {
                    "target": (
                        f"identification >= 2x faster than sdypy-EMA, accuracy >= ({s['case']})"
                    ),
                    "measured": (
                        f"sdypy/tyredamp time {_f(s['speedup_total'])} "
                        f"(poles {_f(s['speedup_poles'])}"
                        f", residues {_f(s['speedup_residues'], 3)}; without the residual "
                        f"search {_f(s['speedup_total_no_search'])}; LSCF+LSFD-only tyredamp "
                        f"{_f(s['speedup_total_lscf_lsfd'])}); accuracy "
                        + (
                            "better or equal on every figure"
                            if not worse
                            else "worse on " + ", ".join(worse)
                        )
                    ),
                    "met": s["target_met"],
                }
            )
    if "perf_crlb" in docs:
        d = docs["perf_crlb"]
        t = d["tools"].get("tyredamp", {})
        rf, rz = t.get("ratio_frequency", []), t.get("ratio_damping", [])
        rows.append(
            {
                "target": f"std of f and zeta <= 1.5 x CRLB, every mode, {d['snr_db']:g} dB",
                "measured": (
                    f"std/CRLB f {min(rf):.2f}-{max(rf):.2f}, zeta {min(rz):.2f}-{max(rz):.2f} "
                    f"({t.get('n_ok', 0)} seeds, {t.get('n_extra', 0)} of them with a noise mode "
                    f"kept beside the true ones; {t.get('n_failed', 0)} missed a true mode)"
                ),
                "met": d["target_met"],
            }
        )
    if "perf_scaling" in docs:
        g = docs["perf_scaling"]["targets"]
        if g["big_case_time_s"] is not None:
            rows.append(
                {
                    "target": "1024 outputs x 4000 lines x 20 modes < 30 s and < 4 GB",
                    "measured": (
                        f"{_f(g['big_case_time_s'], 1)} s, "
                        f"{g['big_case_peak_rss_mb']:.0f} MB peak RSS"
                    ),
                    "met": g["big_case_met"],
                }
            )
        rows.append(
            {
                "target": "time no faster than linear in outputs and lines",
                "measured": (
                    f"growth exponent smallest to largest {_f(g['exponent_outputs'])} "
                    f"(outputs 16-1024), {_f(g['exponent_lines'])} (lines); largest step "
                    f"{_f(g['max_step_exponent_outputs'])}, {_f(g['max_step_exponent_lines'])}"
                ),
                "met": g["linear_met"],
            }
        )
        rows.append(
            {
                "target": "tyredamp demo < 60 s",
                "measured": f"{_f(g['demo_wall_s'], 1)} s",
                "met": g["demo_met"],
            }
        )
    return rows


def markdown(rows: list[dict[str, Any]], command: str, machine: dict[str, Any]) -> str:
    load = machine.get("load_average") or [float("nan")]
    lines = [
        f"Measured with `{command}` on {machine.get('cpu_count')} cores shared with other jobs "
        f"(load average {load[0]:.1f} at the start), BLAS limited to "
        f"{machine.get('blas_threads')} thread(s), {machine.get('time')}:",
        "",
        "| target | measured | met |",
        "| --- | --- | --- |",
    ]
    lines += [f"| {r['target']} | {r['measured']} | {'yes' if r['met'] else 'no'} |" for r in rows]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="reduced runs (a few minutes)")
    ap.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument(
        "--only", choices=PARTS, action="append", help="run only this part (repeatable)"
    )
    a = ap.parse_args(argv)
    command = "python benchmarks/run_all.py" + (" --quick" if a.quick else "")
    machine = machine_info(a.blas_threads)
    t0 = time.perf_counter()
    docs: dict[str, dict[str, Any]] = {}
    files: dict[str, str] = {}
    failed = []
    for part in a.only or PARTS:
        out = RESULTS_DIR / f"{part.removeprefix('perf_')}{'_quick' if a.quick else ''}.json"
        cmd = [sys.executable, str(HERE / f"{part}.py"), "--json", str(out)]
        cmd += ["--blas-threads", str(a.blas_threads)] + (["--quick"] if a.quick else [])
        print(f"\n######## {part}{' --quick' if a.quick else ''}", flush=True)
        code = subprocess.call(cmd)
        if code != 0:
            failed.append(part)
            print(f"{part} failed with exit code {code}", flush=True)
            continue
        docs[part] = json.loads(out.read_text())
        files[part] = str(out)
    rows = targets(docs)
    print_table(
        ["target", "measured", "met"],
        [[r["target"], r["measured"], r["met"]] for r in rows],
        title=f"\n######## targets ({command}, {time.perf_counter() - t0:.0f} s)",
    )
    summary = {
        "command": command,
        "machine": machine,
        "elapsed_s": time.perf_counter() - t0,
        "targets": rows,
        "failed": failed,
        "files": files,
    }
    suffix = "_quick" if a.quick else ""
    write_json(summary, RESULTS_DIR / f"summary{suffix}.json")
    md = RESULTS_DIR / f"summary{suffix}.md"
    from tyredamp.io._atomic import atomic_path

    with atomic_path(md) as tmp:
        tmp.write_text(markdown(rows, command, machine))
    print(f"wrote {RESULTS_DIR / f'summary{suffix}.json'} and {md}")
    if failed:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
