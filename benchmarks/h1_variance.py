"""Calibration of the FRF variance under force noise, response noise or both.

The virtual truck tyre is tested tangentially as in ``windup.py`` (chirp
0-100 Hz) without noise (``run_modal_test(..., snr_db=None)``); Gaussian
noise of 40 dB below each channel's RMS is then added to the chosen channels
(force only, responses only, both) and the FRF is estimated with the
default estimator (``frf_from_time``: cyclic H1 on the stated periods).
Against the exact FRF (``test.true_frf``) and against the noise-free
estimate (the same estimator on the data without noise: what the noise alone
changes), the script prints, over the lines 10-95 Hz and all outputs and
seeds, the median and mean of ``|H - H_ref|^2 / variance``. For a correct
variance known exactly: mean 1, median ln 2 = 0.693; for one estimated with
``d`` real degrees of freedom (``variance_dof``) the ratio is ``F(2, d)``
distributed: median ``d (2^(2/d) - 1) / 2``, mean ``d / (d - 2)``.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/h1_variance.py [N_SEEDS]``
(default 3 seeds; 2, 4, 8 and 16 periods).
"""

from __future__ import annotations

import sys

import numpy as np
from threadpoolctl import threadpool_limits

from tyredamp.studies.radial import frf_from_time
from tyredamp.timedata import TimeData
from tyredamp.virtual import RingTyre, run_modal_test

CASES = ("force", "responses", "both")


def noisy(data: TimeData, case: str, rng: np.random.Generator, snr_db: float) -> TimeData:
    """``data`` with Gaussian noise ``snr_db`` below each chosen channel's RMS."""
    d = np.array(data.data)
    force = np.array([q == "force" for q in data.quantities])
    chosen = {"force": force, "responses": ~force, "both": np.ones_like(force)}[case]
    rms = np.sqrt(np.mean(d**2, axis=1))
    sd = np.where(chosen, rms * 10 ** (-snr_db / 20), 0.0)
    d = d + sd[:, None] * rng.standard_normal(d.shape)
    return TimeData(
        d, data.sample_rate, data.channels, data.quantities, dict(data.meta), data.acquisition
    )


def _ratios(frf, ref: np.ndarray, sel: np.ndarray) -> np.ndarray:
    """``|H - ref|^2 / variance`` on the selected lines, flattened."""
    return (np.abs(frf.H[:, :, sel] - ref) ** 2 / frf.variance[:, :, sel]).ravel()


def main() -> None:
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    tyre = RingTyre()
    print("ratio |H - H_ref|^2 / variance over 10-95 Hz; F: the F(2, dof) value it should have")
    print(
        f"{'case':10s} {'avg':>4s} {'dof':>5s} | ref exact: {'median':>7s} {'mean':>8s} | "
        f"ref noise-free: {'median':>7s} {'mean':>6s} | F: {'median':>6s} {'mean':>6s}"
    )
    for n_avg in (2, 4, 8, 16):
        test = run_modal_test(
            tyre,
            direction="tangential",
            seed=0,
            n_periods=n_avg,
            band=(0.0, 100.0),
            oversample=4,
            snr_db=None,
        )
        clean = frf_from_time(test.data, "H1")
        sel = (clean.frequency >= 10.0) & (clean.frequency <= 95.0)
        exact = test.true_frf(clean.frequency[sel], "accelerance").H
        rel = np.median(np.abs(clean.H[:, :, sel] - exact) / np.abs(exact))
        print(f"{n_avg} periods, noise-free H1 against the exact FRF: median relative {rel:.1e}")
        for case in CASES:
            r_exact, r_clean, dof = [], [], np.nan
            for seed in range(1, n_seeds + 1):
                frf = frf_from_time(noisy(test.data, case, np.random.default_rng(seed), 40.0))
                if frf.variance is None or not np.array_equal(frf.frequency, clean.frequency):
                    continue
                r_exact.append(_ratios(frf, exact, sel))
                r_clean.append(_ratios(frf, clean.H[:, :, sel], sel))
                dof = float(frf.meta["variance_dof"])
            if not r_exact:
                print(f"{case:10s} {n_avg:4d}  no variance")
                continue
            re, rc = np.concatenate(r_exact), np.concatenate(r_clean)
            f_med = dof * (2 ** (2 / dof) - 1) / 2
            f_mean = dof / (dof - 2) if dof > 2 else np.inf
            print(
                f"{case:10s} {n_avg:4d} {dof:5.1f} | {np.median(re):18.3f} {np.mean(re):8.2f} | "
                f"{np.median(rc):22.3f} {np.mean(rc):6.3f} | {f_med:9.3f} {f_mean:6.3f}",
                flush=True,
            )


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
