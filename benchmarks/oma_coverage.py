"""Monte Carlo coverage of the jackknife standard errors of tyredamp's OMA.

A 3-DOF chain (tests/test_oma.py's system, modes 11.1, 31.8, 48.8 Hz with
damping 1.1-3.1 %) is driven by independent white forces at every mass for
``--seconds`` seconds at 200 Hz, ``--runs`` times with new seeds; the
acceleration records (2 % noise) go through ``tyredamp.oma.oma``. For each
mode, the share of runs whose interval ``estimate +- 1.96 std`` holds the true
frequency (damping ratio) is printed: a valid standard error gives 90-97 %
for the nominal 95 %. The mean bias over the runs is printed as well (a bias
larger than the standard error lowers the coverage whatever the error).

Run: ``python benchmarks/oma_coverage.py --runs 100``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tyredamp._blas import single_threaded_blas
from tyredamp.mechanics import MCKSystem, time_response
from tyredamp.oma import oma


def _chain() -> MCKSystem:
    M = np.eye(3)
    k = 4e4
    K = np.array([[2 * k, -k, 0], [-k, 2 * k, -k], [0, -k, k]], float)
    return MCKSystem(M, 2e-4 * K + 0.5 * M, K)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--seconds", type=float, default=300.0)
    a = ap.parse_args()
    s = _chain()
    p = s.complex_modes().poles
    f_true = np.abs(p) / (2 * np.pi)
    z_true = -p.real / np.abs(p)
    fs = 200.0
    hit_f = np.zeros(3)
    hit_z = np.zeros(3)
    n_ok = np.zeros(3)
    bias_f, bias_z, se_f, se_z = [], [], [], []
    t0 = time.perf_counter()
    with single_threaded_blas():
        for r in range(a.runs):
            rng = np.random.default_rng(1000 + r)
            force = rng.standard_normal((3, int(a.seconds * fs)))
            y = time_response(s, force, fs, inputs=[0, 1, 2]).acceleration
            y = y + 0.02 * y.std() * rng.standard_normal(y.shape)
            res = oma(y, fs)
            for j in range(3):
                k = int(np.argmin(np.abs(res.frequency_hz - f_true[j]))) if res.n_modes else -1
                if k < 0 or abs(res.frequency_hz[k] - f_true[j]) > 0.02 * f_true[j]:
                    continue
                n_ok[j] += 1
                hit_f[j] += abs(res.frequency_hz[k] - f_true[j]) <= 1.96 * res.std_frequency_hz[k]
                hit_z[j] += abs(res.damping_ratio[k] - z_true[j]) <= 1.96 * res.std_damping_ratio[k]
                bias_f.append((j, res.frequency_hz[k] - f_true[j]))
                bias_z.append((j, res.damping_ratio[k] - z_true[j]))
                se_f.append((j, res.std_frequency_hz[k]))
                se_z.append((j, res.std_damping_ratio[k]))
    print(f"{a.runs} runs of {a.seconds:g} s in {time.perf_counter() - t0:.0f} s")
    print(
        f"{'mode':>4} {'f [Hz]':>8} {'found':>6} {'cover f':>8} {'cover zeta':>10} "
        f"{'bias f/se':>10} {'bias z/se':>10}"
    )
    for j in range(3):
        bf = np.mean([b for i, b in bias_f if i == j])
        bz = np.mean([b for i, b in bias_z if i == j])
        sf = np.mean([v for i, v in se_f if i == j])
        sz = np.mean([v for i, v in se_z if i == j])
        print(
            f"{j + 1:>4} {f_true[j]:>8.3f} {int(n_ok[j]):>6} {100 * hit_f[j] / n_ok[j]:>7.1f}% "
            f"{100 * hit_z[j] / n_ok[j]:>9.1f}% {bf / sf:>10.2f} {bz / sz:>10.2f}"
        )


if __name__ == "__main__":
    main()
