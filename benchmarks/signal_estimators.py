"""FRF estimation on the virtual truck tyre: accuracy vs averages/SNR, speed vs scipy.

Run:  python benchmarks/signal_estimators.py [--quick]

Table 1: H1 (cyclic) against the exact FRF of the virtual tyre
(``tyredamp.virtual.run_modal_test``), largest relative error in the half-power
band of every visible mode at outputs whose |H| is >= 30 % of their maximum,
and the median over all lines of 1-200 Hz, for several averages and SNRs.

Table 2: time to estimate a SIMO FRF (1 force, 16 responses) with
``estimate_frf`` (Welch, Hann, 50 % overlap) against 16 calls of
``scipy.signal.csd`` + one ``scipy.signal.welch``, and the largest difference
between the two (they compute the same H1).
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.signal

from tyredamp.signal import estimate_frf
from tyredamp.timedata import TimeData
from tyredamp.virtual import run_modal_test


def near_resonance_error(vt, estimator: str = "H1") -> tuple[float, float, float]:
    frf = estimate_frf(vt.data, estimator, band=(1.0, 200.0))
    truth = vt.true_frf(frf.frequency, "accelerance").H[:, 0]
    h = frf.H[:, 0]
    mag = np.abs(truth)
    err = np.abs(h - truth) / mag
    strong = mag >= 0.3 * mag.max(axis=1, keepdims=True)
    worst = 0.0
    for fn, z in zip(vt.truth.frequency_hz, vt.truth.damping_ratio, strict=True):
        sel = strong & (np.abs(frf.frequency - fn) <= z * fn)[None, :]
        if sel.any():
            worst = max(worst, float(err[sel].max()))
    return worst, float(np.median(err)), float(frf.coherence.min())


def table_accuracy(quick: bool) -> None:
    print("Table 1: cyclic H1 on the virtual tyre vs truth (seed 1)")
    print(
        f"{'periods':>8} {'SNR dB':>7} {'max err near res':>17} {'median err':>11} "
        f"{'min coh':>8} {'sim s':>6}"
    )
    cases = [(8, 40.0), (2, 40.0), (32, 40.0), (8, 30.0), (8, 50.0), (8, None)]
    if quick:
        cases = cases[:2]
    for n_per, snr in cases:
        t0 = time.perf_counter()
        vt = run_modal_test(seed=1, n_periods=n_per, snr_db=snr)
        t_sim = time.perf_counter() - t0
        worst, med, cmin = near_resonance_error(vt)
        snr_s = "none" if snr is None else f"{snr:g}"
        print(
            f"{n_per:>8} {snr_s:>7} {100 * worst:>16.3f}% {100 * med:>10.4f}% "
            f"{cmin:>8.4f} {t_sim:>6.1f}"
        )
    vt = run_modal_test(seed=1)
    print("estimators at the defaults (8 periods, 40 dB):")
    for est in ("H1", "H2", "Hv"):
        worst, med, _ = near_resonance_error(vt, est)
        print(f"  {est}: max err near res {100 * worst:.3f} %, median {100 * med:.4f} %")


def table_speed(quick: bool) -> None:
    print("\nTable 2: SIMO Welch H1, 1 force + 16 responses, Hann, 50 % overlap")
    print(f"{'samples':>9} {'segment':>8} {'tyredamp s':>11} {'scipy s':>8} {'max rel diff':>13}")
    rng = np.random.default_rng(0)
    sizes = [(2**16, 1024), (2**20, 4096)] if not quick else [(2**16, 1024)]
    for n, seg in sizes:
        x = rng.normal(size=n)
        y = np.array([np.convolve(x, rng.normal(size=8), "same") for _ in range(16)])
        y += 0.1 * rng.normal(size=y.shape)
        td = TimeData(
            np.vstack([x, y]), 1000.0, list(range(1, 18)), ["force"] + ["acceleration"] * 16
        )
        t0 = time.perf_counter()
        frf = estimate_frf(td, method="welch", segment_samples=seg, band=(1.0, 499.0))
        t_ours = time.perf_counter() - t0
        t0 = time.perf_counter()
        _, pxx = scipy.signal.welch(x, 1000.0, nperseg=seg)
        f, pxy = scipy.signal.csd(x[None, :], y, 1000.0, nperseg=seg)
        h = pxy / pxx
        t_sp = time.perf_counter() - t0
        keep = (f >= 1.0) & (f <= 499.0)
        diff = np.max(np.abs(frf.H[:, 0] - h[:, keep]) / np.abs(h[:, keep]))
        print(f"{n:>9} {seg:>8} {t_ours:>11.3f} {t_sp:>8.3f} {diff:>13.2e}")


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    table_accuracy(quick)
    table_speed(quick)
