"""Time of ``rank_models`` (the four default lateral models) against the number of lines.

The FRF is the virtual rolling-tyre rig's exact ground accelerance at 5 km/h and
1.7 bar with 3 % relative noise, on 0.25-9 Hz with ``n`` lines. Prints the wall
time, the time per line and the peak traced memory per line (``tracemalloc``,
above the FRF itself), so that the cost can be checked to grow in proportion to
the data (issue 15: "cost bounded by the data").

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/lateral_fit_scaling.py [n_max]``.
"""

from __future__ import annotations

import sys
import time
import tracemalloc

import numpy as np

from tyredamp.frf import FRF
from tyredamp.lateral import LateralData, rank_models
from tyredamp.virtual.lateral_rig import KMH, VirtualLateralRig


def main(n_max: int = 1_000_000) -> None:
    rig = VirtualLateralRig()
    truth = rig.truth(5.0, 1.7)
    rng = np.random.default_rng(0)
    print(f"{'lines':>9} {'time [s]':>9} {'us/line':>8} {'peak B/line':>11}  best")
    n = 1_000
    while n <= n_max:
        f = np.linspace(0.25, 9.0, n)
        h = truth.response(f, "accelerance", "ground", rig.wheel_mass)
        h = h * (1 + 0.03 * rng.standard_normal(n))
        frf = FRF(f, h, kind="accelerance", meta={"speed_m_s": 5.0 * KMH})
        data = LateralData.from_frf(frf)
        tracemalloc.start()
        t0 = time.perf_counter()
        r = rank_models(data)
        dt = time.perf_counter() - t0
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        print(f"{n:>9} {dt:>9.3f} {1e6 * dt / n:>8.2f} {peak / n:>11.0f}  {r.best.name}")
        n *= 10


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 1_000_000)
