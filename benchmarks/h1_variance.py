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

``... h1_variance.py --process``: the limitation of the line averaging. A
lightly damped digital resonance (pole radius 0.995 at 20/256 cycles per
sample) driven by a periodic multisine plus force fluctuations that excite it
(5 % of the force, measured), 0.2 % measurement noise on both channels, 40
runs: the mean of ``|H - H_exact|^2 / variance`` within 3 lines of the
resonance and elsewhere, with the variance of the cyclic estimate
(``periods, lines``) and with the per-line H1 residual (``per line``).
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.signal
from threadpoolctl import threadpool_limits

import tyredamp.signal.estimators as est
from tyredamp.signal import estimate_frf
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
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    n_seeds = int(args[0]) if args else 3
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


def process_noise() -> None:
    """Ratios near and away from a sharp resonance under measured force fluctuations."""
    a, b, period = [1.0, -2 * 0.995 * np.cos(2 * np.pi * 20 / 256), 0.995**2], [1.0], 256
    rng = np.random.default_rng(1)
    spec = np.zeros(period // 2 + 1, complex)
    spec[1:-1] = np.exp(2j * np.pi * rng.random(period // 2 - 1))
    one = np.fft.irfft(spec, period)
    one /= one.std()
    band = (0.5 / period, (period // 2 - 0.5) / period)
    cyclic = est.cyclic_variance_on_lines
    for n in (2, 4, 8):
        for name, hook in (("per line", lambda *_a, **_k: None), ("periods, lines", cyclic)):
            est.cyclic_variance_on_lines = hook  # type: ignore[assignment]
            rr = np.random.default_rng(7)
            ratios = []
            for _ in range(40):
                xa = np.tile(one, n + 30) + 0.05 * rr.standard_normal(period * (n + 30))
                y = scipy.signal.lfilter(b, a, xa)[-period * n :]
                x = xa[-period * n :] + 0.002 * rr.standard_normal(period * n)
                y = y + 0.002 * np.std(y) * rr.standard_normal(period * n)
                td = TimeData(np.vstack([x, y]), 1.0, [1, 2], ["force", "displacement"])
                frf = estimate_frf(td, method="cyclic", period_samples=period, band=band)
                _, h = scipy.signal.freqz(b, a, worN=2 * np.pi * frf.frequency)
                ratios.append(np.abs(frf.H[0, 0] - h) ** 2 / frf.variance[0, 0])
            r = np.array(ratios)
            near = np.abs(frf.frequency - 20 / 256) <= 3.5 / period
            print(
                f"{n:2d} periods, {name:15s}: mean ratio within 3 lines of the resonance "
                f"{np.mean(r[:, near]):.2f}, elsewhere {np.mean(r[:, ~near]):.2f}"
            )
    est.cyclic_variance_on_lines = cyclic


if __name__ == "__main__":
    with threadpool_limits(1):
        if "--process" in sys.argv:
            process_noise()
        else:
            main()
