"""Block size of the modal fits: time and modes of ``identify_modes`` at two sizes.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/modal_blocks.py [--repeat 3]
[--sizes 1e6 8e6]``.

The fits accumulate their Gram blocks over blocks of lines of
``tyredamp.modal.fit._basis.BLOCK_BYTES`` (a constant cap: the memory of a block
does not grow with the lines). Each case (:func:`perf_common.mimo_case`) is
identified with every block size in turn, alternating the order between
repeats (one BLAS thread; the machine is shared, so medians and ratios count,
not single times). Printed per case and size: the median time, its ratio to
the first size, and whether the modes (frequencies, damping ratios and their
standard errors) agree with those of the first size to 1e-6 relative.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from perf_common import limit_blas, mimo_case

from tyredamp.modal import identify_modes
from tyredamp.modal.fit import _basis

CASES = [(4, 1, 1000, 10, 60.0), (16, 2, 3000, 20, 35.0), (32, 2, 4000, 20, 50.0)]


def _modes(res: object) -> np.ndarray:
    m = res.models["complex"]  # type: ignore[attr-defined]
    o = np.argsort(m.frequency_hz)
    cols = [m.frequency_hz, m.damping_ratio, m.std["frequency_hz"], m.std["damping_ratio"]]
    return np.stack([np.asarray(c, float)[o] for c in cols])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e6, 8e6])
    a = ap.parse_args()
    pool = limit_blas(1)
    sizes = [int(s) for s in a.sizes]
    print(f"{'case':<44} {'block MB':>8} {'median s':>9} {'/ first':>8} {'same modes':>10}")
    for spec in CASES:
        case = mimo_case(*spec)
        times: dict[int, list[float]] = {s: [] for s in sizes}
        modes: dict[int, np.ndarray] = {}
        for r in range(a.repeat):
            for s in sizes if r % 2 == 0 else sizes[::-1]:
                _basis.BLOCK_BYTES = s
                t0 = time.perf_counter()
                res = identify_modes(case.frf, band=case.band, model="complex")
                times[s].append(time.perf_counter() - t0)
                modes.setdefault(s, _modes(res))
        base = statistics.median(times[sizes[0]])
        for s in sizes:
            med = statistics.median(times[s])
            a0, a1 = modes[sizes[0]], modes[s]
            same = a0.shape == a1.shape and bool(np.allclose(a1, a0, rtol=1e-6, atol=0))
            print(f"{case.name:<44} {s / 1e6:8.1f} {med:9.3f} {med / base:8.2f} {same!s:>10}")
    del pool


if __name__ == "__main__":
    main()
