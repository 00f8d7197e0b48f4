"""Time and peak memory of the modal identification as outputs, lines and modes grow; the demo.

Run: ``python benchmarks/perf_scaling.py [--quick] [--blas-threads 1] [--json PATH]``.

Each case is one fresh subprocess: the parent synthesises the FRFs
(:func:`perf_common.synthetic_case`: complex modes in 10-190 Hz, two more
above 200 Hz, 40 dB complex noise, accelerance, one drive point) and saves
them to a temporary ``.npz``; the child loads them, limits BLAS to
``--blas-threads`` and times :func:`~tyredamp.modal.identify_modes` with its
defaults (automatic selection, complex model). Peak memory is the child's
peak resident set size, ``VmHWM`` of ``/proc/self/status`` read by the
child at its end (Python, NumPy, the loaded data and the identification;
``ru_maxrss`` of a child is not used: Linux folds the parent's RSS at the
fork into it); ``data MB`` is the child's RSS after loading the data, before
the identification.

Sweeps (``--quick`` in brackets): outputs 16, 128, 1024 at 4000 lines and
20 modes; lines 1000, 2000, 4000, 8000 at 1024 outputs [1000, 4000, 8000 at
128 outputs]; modes 6, 12, 20, 30 at 1024 outputs [6, 20, 30 at 128] and
4000 lines; when the automatic selection misses modes, the case is run
again with ``n_modes`` given (marked in the table). The growth exponent between two sizes is
``log(t2 / t1) / log(n2 / n1)`` (1 = linear), printed per step and from the
smallest to the largest size (the target's figure, less noisy). The full mode also runs the
1024 x 4000 x 20 case with two BLAS threads. ``--busy-check`` (not part of
``run_all.py``: it loads the shared machine) runs that case with one and two
BLAS threads while two CPU-bound processes compete for the cores.

Demo: ``tyredamp demo --out DIR`` (and ``--quick`` in the full mode) in a
subprocess, wall time and peak RSS (``/usr/bin/time -f %M`` when GNU time is
there, else ``ru_maxrss``, an upper bound).
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from perf_common import RESULTS_DIR, machine_info, print_table, synthetic_case, write_json


def _status_kb(field: str) -> float | None:
    """A ``kB`` field of ``/proc/self/status`` (Linux), else None."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(field + ":"):
                return float(line.split()[1])
    except OSError:
        pass
    return None


def _child(path: str, blas_threads: int, n_modes: int | None) -> None:
    """Load one case, identify, print one JSON line."""
    from perf_common import limit_blas, match_modes

    from tyredamp.frf import FRF
    from tyredamp.modal import identify_modes

    pool = limit_blas(blas_threads)
    with np.load(path) as z:
        f, H = z["f"], z["H"]
        band = (float(z["band"][0]), float(z["band"][1]))
        poles = z["poles"]
    frf = FRF(f, H, kind="accelerance", outputs=range(1, H.shape[0] + 1), inputs=[1])
    del H
    rss_data = _status_kb("VmRSS")
    c0, t0 = time.process_time(), time.perf_counter()
    m = identify_modes(frf, band=band, model="complex", n_modes=n_modes).models["complex"]
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    f_true = np.abs(poles) / (2 * np.pi)
    idx = match_modes(m.frequency_hz, f_true)
    ok = idx >= 0
    ef = np.abs(m.frequency_hz[idx[ok]] / f_true[ok] - 1)
    zt = -poles.real / np.abs(poles)
    ez = np.abs(m.damping_ratio[idx[ok]] / zt[ok] - 1)
    out = {
        "t_s": dt,
        "cpu_s": cpu,
        "rss_data_kb": rss_data,
        "n_found": int(ok.sum()),
        "n_identified": int(m.n_modes),
        "max_freq_error": float(ef.max()) if ef.size else None,
        "max_damping_error": float(ez.max()) if ez.size else None,
        "max_order": m.meta.get("max_order"),
        "peak_rss_kb": _status_kb("VmHWM") or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
    }
    del pool
    print(json.dumps(out))


def run_case(
    n_out: int,
    n_lines: int,
    n_modes: int,
    blas_threads: int,
    tmp: Path,
    repeats: int,
    hint: bool = False,
) -> dict[str, Any]:
    case = synthetic_case(n_out, n_lines, n_modes, seed=0)
    path = tmp / "case.npz"
    np.savez(path, f=case.frf.frequency, H=case.frf.H, band=np.array(case.band), poles=case.poles)
    del case
    runs = []
    for _ in range(repeats):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=str(blas_threads), OMP_NUM_THREADS="1")
        cmd = [sys.executable, __file__, "--child", str(path), "--blas-threads", str(blas_threads)]
        if hint:
            cmd += ["--n-modes", str(n_modes)]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
        _, status, _ = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        out = proc.stdout.read().decode() if proc.stdout else ""
        err = proc.stderr.read().decode() if proc.stderr else ""
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            raise RuntimeError(f"case {n_out}x{n_lines}x{n_modes} failed:\n{err}")
        d = json.loads(out.strip().splitlines()[-1])
        d["peak_rss_mb"] = d.pop("peak_rss_kb") / 1024
        d["rss_data_mb"] = (d.pop("rss_data_kb") or np.nan) / 1024
        d["process_wall_s"] = wall
        runs.append(d)
    path.unlink()
    best = sorted(runs, key=lambda r: r["t_s"])[len(runs) // 2]
    return {
        "n_out": n_out,
        "n_lines": n_lines,
        "n_modes": n_modes,
        "blas_threads": blas_threads,
        "n_modes_given": hint,
        "t_s": float(np.median([r["t_s"] for r in runs])),
        "t_all_s": [r["t_s"] for r in runs],
        "cpu_s": best["cpu_s"],
        "peak_rss_mb": max(r["peak_rss_mb"] for r in runs),
        "rss_data_mb": best["rss_data_mb"],
        "n_found": best["n_found"],
        "n_identified": best["n_identified"],
        "max_freq_error": best["max_freq_error"],
        "max_damping_error": best["max_damping_error"],
        "max_order": best["max_order"],
    }


@contextlib.contextmanager
def busy_load(n: int) -> Any:
    """``n`` CPU-bound Python processes for the duration of the block (killed by pid)."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
            p.wait()


def exponents(rows: list[dict[str, Any]], key: str) -> list[float]:
    """Growth exponents ``log(t2/t1) / log(n2/n1)`` between consecutive sizes."""
    return [
        float(np.log(b["t_s"] / a["t_s"]) / np.log(b[key] / a[key]))
        for a, b in itertools.pairwise(rows)
    ]


def overall_exponent(rows: list[dict[str, Any]], key: str) -> float:
    """Growth exponent from the smallest to the largest size (the target's figure:
    a step exponent of a linear cost scatters by about +-0.15 with the timing
    noise of a shared machine, the end-to-end one by a third of that)."""
    a, b = rows[0], rows[-1]
    return float(np.log(b["t_s"] / a["t_s"]) / np.log(b[key] / a[key]))


def run_demo(args: list[str], tmp: Path) -> dict[str, Any]:
    exe = shutil.which("tyredamp")
    cmd = [exe] if exe else [sys.executable, "-c", "from tyredamp.cli import main; main()"]
    gnu_time = shutil.which("time") or "/usr/bin/time"
    timed = Path(gnu_time).exists()
    out = tmp / "demo"
    rss_file = tmp / "demo.rss"
    full = [*cmd, "demo", "--out", str(out), *args]
    if timed:  # GNU time waits for the demo itself: its %M is the demo's own peak RSS
        full = [gnu_time, "-f", "%M", "-o", str(rss_file), *full]
    t0 = time.perf_counter()
    proc = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    err = proc.stderr.read().decode() if proc.stderr else ""
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise RuntimeError(f"tyredamp demo {' '.join(args)} failed ({code}):\n{err[-2000:]}")
    shutil.rmtree(out, ignore_errors=True)
    peak = float(ru.ru_maxrss)
    if timed and rss_file.exists():
        peak = float(rss_file.read_text().split()[-1])
    return {
        "command": " ".join(["tyredamp", "demo", "--out", "DIR", *args]),
        "wall_s": wall,
        "cpu_s": ru.ru_utime + ru.ru_stime,
        "peak_rss_mb": peak / 1024,
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sweeps, one run per case")
    ap.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument("--json", default=str(RESULTS_DIR / "scaling.json"), help="output JSON")
    ap.add_argument(
        "--busy-check",
        action="store_true",
        help="also time 1024x4000x20 with 1 and 2 BLAS threads beside 2 CPU-bound processes",
    )
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--n-modes", type=int, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        _child(a.child, a.blas_threads, a.n_modes)
        return {}
    bt = a.blas_threads
    rep = 1 if a.quick else 2
    big = 128 if a.quick else 1024
    sweeps: dict[str, list[tuple[int, int, int]]] = {
        "outputs": [(n, 4000, 20) for n in (16, 128, 1024)],
        "lines": [
            (big, n, 20) for n in ((1000, 4000, 8000) if a.quick else (1000, 2000, 4000, 8000))
        ],
        "modes": [(big, 4000, n) for n in ((6, 20, 30) if a.quick else (6, 12, 20, 30))],
    }
    t_start = time.perf_counter()
    done: dict[tuple[int, int, int, int], dict[str, Any]] = {}
    res: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="tyredamp-perf-") as td:
        tmp = Path(td)
        for name, cases in sweeps.items():
            rows = []
            extra = []
            for c in cases:
                key = (*c, bt)
                if key not in done:
                    done[key] = run_case(*c, bt, tmp, rep)
                rows.append(done[key])
                if name == "modes" and done[key]["n_found"] < c[2]:
                    extra.append(run_case(*c, bt, tmp, rep, hint=True))
            axis = {"outputs": "n_out", "lines": "n_lines", "modes": "n_modes"}[name]
            res[name] = {
                "rows": rows,
                "exponents": exponents(rows, axis),
                "overall_exponent": overall_exponent(rows, axis),
            }
            if extra:
                res[name]["rows_n_modes_given"] = extra
                given = {r["n_modes"]: r for r in extra}
                eff = [given.get(r["n_modes"], r) for r in rows]
                res[name]["exponents_n_modes_given_where_missed"] = exponents(eff, axis)
            print_table(
                [
                    "outputs",
                    "lines",
                    "modes",
                    "time s",
                    "CPU s",
                    "peak MB",
                    "data MB",
                    "found",
                    "max|df/f|",
                    "max|dz/z|",
                ],
                [
                    [
                        r["n_out"],
                        r["n_lines"],
                        f"{r['n_modes']}{' given' if r['n_modes_given'] else ''}",
                        r["t_s"],
                        r["cpu_s"],
                        r["peak_rss_mb"],
                        r["rss_data_mb"],
                        f"{r['n_found']}/{r['n_modes']} ({r['n_identified']})",
                        r["max_freq_error"],
                        r["max_damping_error"],
                    ]
                    for r in rows + extra
                ],
                title=(
                    f"\n== identify_modes vs {name} (BLAS threads {bt}); growth exponents "
                    + ", ".join(f"{e:.2f}" for e in res[name]["exponents"])
                    + f" (overall {res[name]['overall_exponent']:.2f})"
                ),
            )
        target_case = done.get((1024, 4000, 20, bt))
        if not a.quick:
            two = run_case(1024, 4000, 20, 2, tmp, rep)
            res["blas_two_threads"] = two
            print(
                f"\n1024 x 4000 x 20 with 2 BLAS threads: {two['t_s']:.1f} s "
                f"(1 thread: {target_case['t_s'] if target_case else float('nan'):.1f} s)"
            )
        if a.busy_check:
            with busy_load(2):
                busy = {n: run_case(1024, 4000, 20, n, tmp, 1) for n in (1, 2)}
            res["busy"] = {f"blas_{n}": r for n, r in busy.items()}
            print(
                f"\n1024 x 4000 x 20 beside two CPU-bound processes: {busy[1]['t_s']:.1f} s "
                f"(1 BLAS thread), {busy[2]['t_s']:.1f} s (2 BLAS threads)"
            )
        demos = [run_demo([], tmp)]
        if not a.quick:
            demos.append(run_demo([], tmp))
            demos.append(run_demo(["--quick"], tmp))
        res["demo"] = demos
        print_table(
            ["command", "wall s", "CPU s", "peak MB"],
            [[d["command"], d["wall_s"], d["cpu_s"], d["peak_rss_mb"]] for d in demos],
            title="\n== tyredamp demo (subprocess)",
        )
    exp_out = res["outputs"]["overall_exponent"]
    exp_lines = res["lines"]["overall_exponent"]
    full_demo = [d["wall_s"] for d in demos if d["command"].endswith("DIR")]
    targets = {
        "big_case_time_s": target_case["t_s"] if target_case else None,
        "big_case_peak_rss_mb": target_case["peak_rss_mb"] if target_case else None,
        "big_case_met": bool(
            target_case and target_case["t_s"] < 30 and target_case["peak_rss_mb"] < 4096
        ),
        "exponent_outputs": exp_out,
        "exponent_lines": exp_lines,
        "max_step_exponent_outputs": max(res["outputs"]["exponents"]),
        "max_step_exponent_lines": max(res["lines"]["exponents"]),
        "linear_met": bool(exp_out <= 1.0 and exp_lines <= 1.0),
        "demo_wall_s": float(np.median(full_demo)),
        "demo_met": bool(np.median(full_demo) < 60),
    }
    print(
        f"\ntargets: 1024x4000x20 {targets['big_case_time_s']:.1f} s, "
        f"{targets['big_case_peak_rss_mb']:.0f} MB (< 30 s, < 4 GB: "
        f"{'met' if targets['big_case_met'] else 'NOT met'}); growth exponents "
        f"{exp_out:.2f} (outputs), {exp_lines:.2f} (lines) (<= 1: "
        f"{'met' if targets['linear_met'] else 'NOT met'}); demo {targets['demo_wall_s']:.1f} s "
        f"(< 60 s: {'met' if targets['demo_met'] else 'NOT met'})"
    )
    doc = {
        "benchmark": "perf_scaling",
        "quick": a.quick,
        "machine": machine_info(bt),
        "elapsed_s": time.perf_counter() - t_start,
        "sweeps": res,
        "targets": targets,
    }
    print(f"wrote {write_json(doc, a.json)} ({doc['elapsed_s']:.0f} s)")
    return doc


if __name__ == "__main__":
    main()
