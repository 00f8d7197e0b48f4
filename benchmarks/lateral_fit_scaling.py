"""Cost of the lateral fit against the number of lines (issue 15: "cost bounded by the data").

The FRF is the virtual rolling-tyre rig's exact ground accelerance at 5 km/h and
1.7 bar with 3 % relative noise, on 0.25-9 Hz with ``n`` lines. Two tables:

* ``rank_models`` (the four default models) in this process: wall time, time
  per line, and the peak traced memory per line above the FRF itself
  (``tracemalloc``, measured in a second run so that tracing does not slow the
  timed one);
* ``tyredamp lateral fit FILE.npz -o OUT.json`` end to end (reading the file,
  fitting, writing) in a fresh process per size: wall time and the peak
  resident memory per line above that of the smallest run (``VmHWM``, Linux;
  else ``ru_maxrss``).
  The FRF file itself holds 24 bytes per line (frequency and complex H).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/lateral_fit_scaling.py [n_max] [--no-cli]``
(default ``n_max`` 2e6; sizes 1e3, 1e4, ... and 2e6 when ``n_max`` reaches it).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.lateral import LateralData, rank_models
from tyredamp.virtual.lateral_rig import KMH, VirtualLateralRig

_CHILD = """
import resource, sys, time
from tyredamp.cli import main
t0 = time.perf_counter()
try:
    main(["lateral", "fit", sys.argv[1], "-o", sys.argv[2]])
except SystemExit as exc:
    if exc.code:
        raise
try:  # the high-water mark of this process (ru_maxrss may carry the parent's after fork)
    with open("/proc/self/status") as fh:
        kb = next(int(ln.split()[1]) for ln in fh if ln.startswith("VmHWM:"))
except (OSError, StopIteration):
    kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(time.perf_counter() - t0, kb)
"""


def _frf(n: int) -> FRF:
    rig = VirtualLateralRig()
    truth = rig.truth(5.0, 1.7)
    rng = np.random.default_rng(0)
    f = np.linspace(0.25, 9.0, n)
    h = truth.response(f, "accelerance", "ground", rig.wheel_mass)
    h = h * (1 + 0.03 * rng.standard_normal(n))
    return FRF(f, h, kind="accelerance", meta={"speed_m_s": 5.0 * KMH})


def _sizes(n_max: int) -> list[int]:
    sizes = [n for n in (10**k for k in range(3, 9)) if n <= n_max]
    return [*sizes, 2_000_000] if n_max >= 2_000_000 else sizes


def in_process(n_max: int) -> None:
    print("rank_models, four default models (in process)")
    print(f"{'lines':>9} {'time [s]':>9} {'us/line':>8} {'peak B/line':>11}  best")
    for n in _sizes(n_max):
        data = LateralData.from_frf(_frf(n))
        t0 = time.perf_counter()
        r = rank_models(data)
        dt = time.perf_counter() - t0
        tracemalloc.start()
        rank_models(data)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        print(f"{n:>9} {dt:>9.3f} {1e6 * dt / n:>8.2f} {peak / n:>11.0f}  {r.best.name}")


def command_line(n_max: int) -> None:
    print("\ntyredamp lateral fit FILE.npz -o OUT.json (fresh process per size)")
    print(f"{'lines':>9} {'time [s]':>9} {'us/line':>8} {'peak RSS MB':>11} {'B/line':>7}")
    base = None
    with tempfile.TemporaryDirectory() as tmp:
        for n in _sizes(n_max):
            src, out = Path(tmp) / f"lat{n}.npz", Path(tmp) / f"lat{n}.json"
            write_frf(_frf(n), src)
            run = subprocess.run(
                [sys.executable, "-c", _CHILD, str(src), str(out)],
                capture_output=True,
                text=True,
                check=True,
            )
            dt_s, rss_kb = run.stdout.split()[-2:]
            dt, rss = float(dt_s), 1024.0 * float(rss_kb)
            base = rss if base is None else base
            per = f"{(rss - base) / n:>7.0f}" if n > _sizes(n_max)[0] else f"{'-':>7}"
            print(f"{n:>9} {dt:>9.2f} {1e6 * dt / n:>8.2f} {rss / 1e6:>11.0f} {per}")
            src.unlink()


def main(argv: list[str]) -> None:
    args = [a for a in argv if not a.startswith("--")]
    n_max = int(float(args[0])) if args else 2_000_000
    in_process(n_max)
    if "--no-cli" not in argv:
        command_line(n_max)


if __name__ == "__main__":
    main(sys.argv[1:])
