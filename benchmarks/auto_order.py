"""The automatic model order on the random and physical cases of ``perf_compare.py``.

Run: ``python benchmarks/auto_order.py [--repeat 2]``.

``perf_compare.py`` gives tyredamp the order it gives sdypy-EMA; a user's
``tyredamp modal`` runs at the automatic order. This prints, per case, the CPU
time of ``identify_modes(frf, band=..., model="complex")`` at the automatic
order (one BLAS thread, the smallest of ``--repeat`` runs), the order of the
diagram it settled on and its persistent clusters, the modes found (a true
in-band mode is found when an identified one lies within half its half-power
bandwidth) and the largest damping error in units of its standard error.
"""

from __future__ import annotations

import argparse
import functools
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from perf_common import Case, limit_blas, mimo_case, physical_case

import tyredamp.modal.identify as ident
from tyredamp.modal import identify_modes

CASES: dict[str, Callable[[], Case]] = {
    "random 4x1": functools.partial(mimo_case, 4, 1, 1000, 10, 60.0),
    "random 16x2": functools.partial(mimo_case, 16, 2, 3000, 20, 35.0),
    "random 32x2": functools.partial(mimo_case, 32, 2, 4000, 20, 50.0),
    "physical 4x1": functools.partial(physical_case, 4, 1, 1000, 8, 60.0),
    "physical 8x1": functools.partial(physical_case, 8, 1, 2000, 12, 50.0),
    "physical 16x2": functools.partial(physical_case, 16, 2, 3000, 20, 40.0),
    "physical 32x2": functools.partial(physical_case, 32, 2, 4000, 24, 35.0),
    "physical 64x3": functools.partial(physical_case, 64, 3, 8000, 30, 30.0),
}


def run(case: Case, repeat: int) -> dict[str, Any]:
    """Time, settled order and accuracy of the automatic order on ``case``."""
    settled: list[Any] = []
    orig = ident.settle_order

    def watched(*a: Any, **k: Any) -> Any:
        dg = orig(*a, **k)
        settled.append(dg)
        return dg

    ident.settle_order = watched  # type: ignore[assignment]
    try:
        times = []
        with limit_blas(1):
            for _ in range(max(repeat, 1)):
                t0 = time.process_time()
                res = identify_modes(case.frf, band=case.band, model="complex")
                times.append(time.process_time() - t0)
    finally:
        ident.settle_order = orig  # type: ignore[assignment]
    m = res.models["complex"]
    tp = np.sort_complex(case.poles)
    tf, tz = np.abs(tp) / (2 * np.pi), -tp.real / np.abs(tp)
    f, z = np.asarray(m.frequency_hz), np.asarray(m.damping_ratio)
    j = np.argmin(np.abs(f[:, None] - tf[None, :]), axis=0)
    found = np.abs(f[j] - tf) < 0.5 * tz * tf
    ez = np.abs(z[j] - tz) / np.asarray(m.std["damping_ratio"])[j]
    dg = settled[-1]
    return {
        "cpu": min(times),
        "order": dg.order,
        "clusters": len(dg.kept),
        "found": int(found.sum()),
        "true": tf.size,
        "modes": m.n_modes,
        "dz": float(ez[found].max()) if found.any() else float("nan"),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    args = ap.parse_args()
    head = ("case", "cpu [s]", "order", "clusters", "found", "max dz/std")
    print(" ".join(f"{h:>{w}}" for h, w in zip(head, (14, 8, 6, 8, 7, 11), strict=True)))
    for name in args.cases:
        r = run(CASES[name](), args.repeat)
        print(
            f"{name:>14} {r['cpu']:>8.3f} {r['order']:>6} {r['clusters']:>8} "
            f"{r['found']:>3}/{r['true']:<3} {r['dz']:>11.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
