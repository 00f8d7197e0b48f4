"""LRM against Welch-H1 on random excitation of a lightly damped system, same record length.

Run:  OPENBLAS_NUM_THREADS=1 python benchmarks/signal_lrm.py [--quick]

The system is a digital filter ``B(z)/A(z)`` with two modes (0.5 % and 0.3 %
damping at 0.05 and 0.13 of the sample rate), so the exact FRF at every DFT
line is ``B/A`` at ``exp(2 pi i f / fs)``. Each realisation drives it with
white Gaussian noise for ``N`` samples from rest (a start transient and
leakage included) and adds output noise at 40 dB SNR. For each estimator the
table gives, over the lines within the half-power band of each mode:

* bias: ``max |mean_r H_r - H| / |H|`` (mean over the realisations), and
* random error: ``max std_r(H_r) / |H|``,

for Welch-H1 (Hann, 50 % overlap, ``N/8`` and ``N/4`` segments: the
estimator's default and a longer one) and the local rational method (LRM,
order 2, one record of ``N`` samples). It also prints the ratio of the LRM's
own variance estimate to the observed scatter.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.signal

from tyredamp.signal import estimate_frf
from tyredamp.timedata import TimeData

MODES = ((0.05, 0.005), (0.13, 0.003))


def system() -> tuple[np.ndarray, np.ndarray]:
    poles = []
    for f, z in MODES:
        w = 2 * np.pi * f
        r = np.exp(-z * w)
        poles += [r * np.exp(1j * w), r * np.exp(-1j * w)]
    return np.array([0.3, 0.1, -0.2]), np.real(np.poly(poles))


def run(n: int, n_real: int) -> None:
    b, a = system()
    rng = np.random.default_rng(0)
    methods = {
        "Welch-H1 N/8": {"method": "welch", "segment_samples": n // 8},
        "Welch-H1 N/4": {"method": "welch", "segment_samples": n // 4},
        "LRM": {"method": "lrm"},
    }
    est: dict[str, list[np.ndarray]] = {k: [] for k in methods}
    var_lrm = []
    freqs: dict[str, np.ndarray] = {}
    for _ in range(n_real):
        x = rng.standard_normal(n)
        y = scipy.signal.lfilter(b, a, x)
        y = y + 0.01 * np.std(y) * rng.standard_normal(n)
        td = TimeData(np.vstack([x, y]), 1.0, [1, 2], ["force", "displacement"])
        for name, kw in methods.items():
            frf = estimate_frf(td, min_relative_power=0.0, detect=False, **kw)
            est[name].append(frf.H[0, 0])
            freqs[name] = frf.frequency
            if name == "LRM" and frf.variance is not None:
                var_lrm.append(frf.variance[0, 0])
    print(f"record N = {n} samples, {n_real} realisations, output SNR 40 dB")
    print(f"{'estimator':<14} {'mode':>5} {'lines':>5} {'bias':>10} {'random':>10}")
    bias_at: dict[str, float] = {}
    for name in methods:
        f = freqs[name]
        _, h = scipy.signal.freqz(b, a, worN=2 * np.pi * f)
        hs = np.array(est[name])
        bias = np.abs(hs.mean(axis=0) - h) / np.abs(h)
        rand = hs.std(axis=0) / np.abs(h)
        worst = 0.0
        for m, (fn, z) in enumerate(MODES):
            sel = np.abs(f - fn) <= z * fn
            if not sel.any():  # no line in the half-power band: the nearest one
                sel = np.abs(f - fn) == np.min(np.abs(f - fn))
            worst = max(worst, float(bias[sel].max()))
            print(
                f"{name:<14} {m + 1:>5} {int(sel.sum()):>5} {bias[sel].max():>10.2e} "
                f"{rand[sel].max():>10.2e}"
            )
        bias_at[name] = worst
    for name in ("Welch-H1 N/8", "Welch-H1 N/4"):
        print(f"bias ratio {name} / LRM at the resonances: {bias_at[name] / bias_at['LRM']:.3g}")
    if var_lrm:
        hs = np.array(est["LRM"])
        emp = np.mean(np.abs(hs - hs.mean(axis=0)) ** 2, axis=0)
        pred = np.mean(var_lrm, axis=0)
        print(
            f"LRM variance estimate / observed scatter (median over lines): "
            f"{np.median(pred[5:-5] / emp[5:-5]):.3f}"
        )


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    run(8192 if quick else 16384, 10 if quick else 40)
