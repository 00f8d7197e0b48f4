"""Convergence of the discrete ring tyre to the analytic ring-on-foundation frequencies.

For the default 295/80R22.5 at 7.5 bar (bare ring: no shaker attachment, no
imperfection), prints for each order of the staggered differences (2, 4, 6)
the lower frequency of each double mode n = 1..6 and its error against the
inextensible formula of spec ``virtual-tyre.md``, the error against the
continuous *extensible* ring (the pure discretisation error) and the observed
order of convergence, and the time to build and solve one ring.

Run: ``python benchmarks/tyre_convergence.py``.
"""

from __future__ import annotations

import time

import numpy as np

from tyredamp.virtual import RingTyre, ring_convergence

N_RINGS = (16, 32, 48, 64, 96, 128, 192, 256)


def main() -> None:
    for order in (2, 4, 6):
        t0 = time.perf_counter()
        conv = ring_convergence(n_rings=N_RINGS, n_max=6, fd_order=order)
        dt = time.perf_counter() - t0
        print(f"\n=== staggered differences of order {order} ({dt:.2f} s for the table) ===")
        print("lower member of each double mode (Hz) and |error| vs the inextensible formula")
        print(conv.format())
        print("\nerror vs the continuous extensible ring (discretisation only), n = 1..6")
        for nr, row in zip(conv.n_ring, conv.discretisation_error, strict=True):
            print(f"{nr:6d} " + " ".join(f"{e:10.2e}" for e in row))
        print("observed order between successive n_ring, n = 1..6")
        for (a, b), row in zip(
            zip(conv.n_ring[:-1], conv.n_ring[1:], strict=True), conv.observed_order, strict=True
        ):
            print(f"{a:4d}->{b:<4d} " + " ".join(f"{o:6.2f}" for o in row))
        worst = np.max(conv.relative_error, axis=1)
        ok = conv.n_ring[worst < 0.01]
        print(f"smallest n_ring with every n = 1..6 within 1 %: {ok.min() if ok.size else 'none'}")
    print("\n=== cost of the default tyre (n_ring = 64, 128 DOF) ===")
    t0 = time.perf_counter()
    tyre = RingTyre()
    t1 = time.perf_counter()
    tyre.truth()
    t2 = time.perf_counter()
    print(f"assembly {1e3 * (t1 - t0):.1f} ms, complex modes + truth {1e3 * (t2 - t1):.1f} ms")


if __name__ == "__main__":
    main()
