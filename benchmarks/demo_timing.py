"""Wall and CPU time of the demo, stage by stage, and the effect of BLAS threads.

Run: ``python benchmarks/demo_timing.py [--quick] [--compare-threads]``.

Prints one row per stage of :func:`tyredamp.studies.demo.run_demo` and of
:func:`tyredamp.report.demo.save_demo` (figures, data files, report) with its wall
time. ``--compare-threads`` also runs the computation with the BLAS thread
pool left at its default (``run_demo`` limits it to one thread), to show why
the demo does so.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from tyredamp.report.demo import save_demo
from tyredamp.studies.demo import DemoSettings, _run, run_demo


def _timed_progress(rows: list[tuple[str, float]]) -> object:
    state = {"name": None, "t": time.perf_counter()}

    def progress(desc: str, done: int, total: int) -> None:
        now = time.perf_counter()
        if state["name"] is not None:
            rows.append((str(state["name"]), now - float(state["t"])))  # type: ignore[arg-type]
        state["name"], state["t"] = (None if desc == "done" else desc), now

    return progress


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the reduced setting")
    ap.add_argument("--compare-threads", action="store_true", help="also default BLAS threads")
    args = ap.parse_args()
    settings = DemoSettings.quick_preset() if args.quick else DemoSettings.full()

    rows: list[tuple[str, float]] = []
    c0, t0 = time.process_time(), time.perf_counter()
    result = run_demo(settings, _timed_progress(rows))  # type: ignore[arg-type]
    t_run, c_run = time.perf_counter() - t0, time.process_time() - c0
    with tempfile.TemporaryDirectory() as tmp:
        c1, t1 = time.process_time(), time.perf_counter()
        save_demo(result, Path(tmp) / "demo", _timed_progress(rows))  # type: ignore[arg-type]
        t_save, c_save = time.perf_counter() - t1, time.process_time() - c1

    print(f"tyredamp demo{' --quick' if args.quick else ''}: stages (wall time, s)")
    print(f"{'stage':<72} {'s':>7}")
    print("-" * 80)
    for name, dt in rows:
        print(f"{name[:72]:<72} {dt:>7.2f}")
    print("-" * 80)
    print(f"{'computing (run_demo): wall / CPU':<72} {t_run:>7.2f} / {c_run:.2f}")
    print(f"{'writing (save_demo): wall / CPU':<72} {t_save:>7.2f} / {c_save:.2f}")

    if args.compare_threads:
        c2, t2 = time.process_time(), time.perf_counter()
        _run(settings, None)  # the same work without the one-thread BLAS limit
        print(
            f"{'computing with default BLAS threads: wall / CPU':<72} "
            f"{time.perf_counter() - t2:>7.2f} / {time.process_time() - c2:.2f}"
        )


if __name__ == "__main__":
    main()
