"""Accuracy of the damping identification against exact complex modes.

Prints two tables:

1. Random MCK systems (6 DOF, SPD ``M`` and ``K``, random rank-3 PSD ``C``,
   non-proportional) with the complete modal set, damping scaled so that the
   largest modal damping ratio is ``zeta_max``: relative Frobenius error of the
   physical ``C`` for eq. [16] ("first"), eq. [18] ("improved") and the
   bias-corrected iteration ("refined"); median and worst over the systems.
2. The 6-DOF fixed-free spring-mass chain of the spec check (m = 1 kg,
   k = 1e4 N/m, dampers to ground of 5 and 2 N s/m at masses 1 and 3),
   with the dampers scaled by a factor.

Run: ``python benchmarks/damping_accuracy.py [n_systems]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from tyredamp.damping import modal_damping_from_modes, physical_matrices
from tyredamp.mechanics import MCKSystem
from tyredamp.modal import ModalModel

METHODS = ("first", "improved", "refined")


def random_mck(rng: np.random.Generator, n: int = 6) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a = rng.normal(size=(n, n))
    m = a @ a.T + n * np.eye(n)
    b = rng.normal(size=(n, n))
    k = (b @ b.T + n * np.eye(n)) * 1e4
    d = rng.normal(size=(n, n // 2))
    return m, d @ d.T, k


def chain(factor: float, n: int = 6) -> MCKSystem:
    k = 1e4
    kk = np.diag(np.full(n, 2 * k)) - k * (np.eye(n, k=1) + np.eye(n, k=-1))
    kk[-1, -1] = k
    c = np.zeros((n, n))
    c[0, 0], c[2, 2] = 5.0 * factor, 2.0 * factor
    return MCKSystem(np.eye(n), c, kk)


def errors(sys_: MCKSystem) -> list[float]:
    cm = sys_.complex_modes()
    model = ModalModel(cm.poles, cm.psi, cm.psi)
    out = []
    for method in METHODS:
        est = modal_damping_from_modes(model.poles, model.second_order_shapes(), method)
        c = physical_matrices(est.basis, est.c_modal, est.omega)[1]
        out.append(float(np.linalg.norm(c - sys_.C) / np.linalg.norm(sys_.C)))
    return out


def main(n_systems: int = 20) -> None:
    t0 = time.perf_counter()
    levels = (0.02, 0.01, 0.005, 0.002, 0.001, 0.0005)
    print(f"Random 6-DOF systems, complete modal set, {n_systems} systems per level")
    print(f"{'zeta_max':>9} | " + " | ".join(f"{m + ' med':>13} {'max':>9}" for m in METHODS))
    rng = np.random.default_rng(2024)
    base = [random_mck(rng) for _ in range(n_systems)]
    for zmax in levels:
        errs = []
        for m, c, k in base:
            z1 = MCKSystem(m, c, k).complex_modes().damping_ratio.max()
            errs.append(errors(MCKSystem(m, c * zmax / z1, k)))
        e = np.array(errs)
        cells = [f"{np.median(e[:, j]):13.2e} {e[:, j].max():9.2e}" for j in range(3)]
        print(f"{zmax:9.4f} | " + " | ".join(cells))
    print()
    print("6-DOF chain (dampers 5 and 2 N s/m at masses 1 and 3, times factor)")
    print(f"{'factor':>7} {'zeta_max':>9} | " + " | ".join(f"{m:>9}" for m in METHODS))
    for factor in (2.0, 1.0, 0.5, 0.45, 0.25, 0.1):
        s = chain(factor)
        z = s.complex_modes().damping_ratio.max()
        print(f"{factor:7.2f} {z:9.4f} | " + " | ".join(f"{x:9.2e}" for x in errors(s)))
    print(f"\n({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
