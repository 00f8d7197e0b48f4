"""Calibration of the FRF variance under force noise, response noise or both.

The virtual truck tyre is tested tangentially as in ``windup.py`` (chirp
0-100 Hz) without noise (``run_modal_test(..., snr_db=None)``); Gaussian
noise of 40 dB below each channel's RMS is then added to the chosen channels
(force only, responses only, both) and the FRF is estimated with the
default estimator (``frf_from_time``: cyclic H1 on the detected periods).
Against the exact FRF (``test.true_frf``) the script prints, over the lines
10-95 Hz and all outputs and seeds, the median and mean of
``|H - H_true|^2 / variance`` (for a correct variance known exactly: mean 1,
median ln 2 = 0.693; for a variance estimated with ``d`` real degrees of
freedom the ratio is ``F(2, d)`` distributed: median ``d (2^(2/d) - 1) / 2``,
mean ``d / (d - 2)``), and the reported ``variance_dof``.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/h1_variance.py [N_SEEDS]``
(default 3 seeds; averages 2, 4, 8, 16).
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
    return TimeData(d, data.sample_rate, data.channels, data.quantities, dict(data.meta),
                    data.acquisition)


def main() -> None:
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    tyre = RingTyre()
    print(f"{'case':10s} {'avg':>4s} {'dof':>5s} {'median':>7s} {'F med':>6s} "
          f"{'mean':>7s} {'F mean':>6s} {'trimmed':>7s}")
    for n_avg in (2, 4, 8, 16):
        test = run_modal_test(tyre, direction="tangential", seed=0, n_periods=n_avg,
                              band=(0.0, 100.0), oversample=4, snr_db=None)
        clean = frf_from_time(test.data, "H1")
        sel0 = (clean.frequency >= 10.0) & (clean.frequency <= 95.0)
        h0 = test.true_frf(clean.frequency[sel0], "accelerance").H
        rel0 = np.median(np.abs(clean.H[:, :, sel0] - h0) / np.abs(h0))
        print(f"noise-free estimate against the exact FRF: median relative error {rel0:.1e}")
        for case in CASES:
            ratios_c = []
            ratios, dof = [], np.nan
            for seed in range(1, n_seeds + 1):
                rng = np.random.default_rng(seed)
                frf = frf_from_time(noisy(test.data, case, rng, 40.0), "H1")
                sel = (frf.frequency >= 10.0) & (frf.frequency <= 95.0)
                h_true = test.true_frf(frf.frequency[sel], "accelerance").H
                if frf.variance is None:
                    continue
                r = np.abs(frf.H[:, :, sel] - h_true) ** 2 / frf.variance[:, :, sel]
                ratios.append(r.ravel())
                rc = np.abs(frf.H[:, :, sel] - clean.H[:, :, sel]) ** 2 / frf.variance[:, :, sel]
                ratios_c.append(rc.ravel())
                dof = float(frf.meta["variance_dof"])
            if not ratios:
                print(f"{case:10s} {n_avg:4d}  no variance")
                continue
            r = np.concatenate(ratios)
            rc = np.concatenate(ratios_c)
            f_med = dof * (2 ** (2 / dof) - 1) / 2 if dof > 0 else np.nan
            f_mean = dof / (dof - 2) if dof > 2 else np.inf
            trimmed = np.mean(np.minimum(r, np.quantile(r, 0.99)))
            print(f"{case:10s} {n_avg:4d} {dof:5.1f} {np.median(r):7.3f} {f_med:6.3f} "
                  f"{np.mean(r):7.3f} {f_mean:6.3f} {trimmed:7.3f}   vs clean: median {np.median(rc):6.3f} mean {np.mean(rc):7.3f}", flush=True)


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
