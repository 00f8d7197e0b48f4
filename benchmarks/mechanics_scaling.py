"""Time of the mechanics core against the number of DOF.

Run: ``python benchmarks/mechanics_scaling.py``. Prints a table: DOF,
complex-mode solve, FRF by direct solve and by modal sum (200 lines at 4
outputs x 1 input), and the time response to 10 000 force samples.
"""

from __future__ import annotations

import time

import numpy as np

from tyredamp.mechanics import MCKSystem, time_response


def chain(n: int) -> MCKSystem:
    k = 1.0e6
    K = 2 * k * np.eye(n) - k * np.eye(n, k=1) - k * np.eye(n, k=-1)
    M = np.eye(n)
    C = 1e-5 * K + 0.5 * M
    C[0, 0] += 50.0
    return MCKSystem(M, C, K)


def main() -> None:
    head = ("DOF", "eig (s)", "FRF direct (s)", "FRF modal (s)", "time resp (s)")
    print(f"{head[0]:>6} {head[1]:>9} {head[2]:>15} {head[3]:>14} {head[4]:>14}")
    for n in (50, 200, 500, 1000, 2000):
        s = chain(n)
        t0 = time.perf_counter()
        cm = s.complex_modes()
        t1 = time.perf_counter()
        f = np.linspace(1.0, cm.frequency_hz.max() * 0.2, 200)
        s.frf(f, outputs=[0, 1, 2, 3], inputs=[0])
        t2 = time.perf_counter()
        s.frf(f, outputs=[0, 1, 2, 3], inputs=[0], method="modal")
        t3 = time.perf_counter()
        force = np.random.default_rng(0).normal(size=10_000)
        time_response(s, force, 20_000.0, inputs=[0], outputs=[0, n // 2])
        t4 = time.perf_counter()
        print(f"{n:6d} {t1 - t0:9.2f} {t2 - t1:15.2f} {t3 - t2:14.3f} {t4 - t3:14.2f}")


if __name__ == "__main__":
    main()
