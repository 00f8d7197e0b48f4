"""The mode test's false-alarm rate, measured: how often the automatic
identification keeps a noise mode beside strong, well-separated modes (issue 16).

Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/modal_false_alarm.py [--fits 1800]
        [--alpha 0.01 0.2] [--jobs 2]

Each fit is one random system (generated from its seed, truth known): 3-6
modes in 25-180 Hz, every one strong (amplitudes 0.3-1, far above the noise at
every SNR) and separated from its neighbours by at least six times the sum of
their half-power half-widths, so that anything else the identification keeps
is a noise mode; complex (non-proportionally damped) shapes, damping ratios
0.5-4 %, 1-4 inputs, 2-8 outputs, 0.1-0.2 half-power bandwidths per line, SNR
20, 40 or 60 dB (complex Gaussian noise per output relative to its RMS),
receptance, mobility or accelerance in turn. The identification gets the FRF
alone (noise from the residual) and the false-alarm rate ``alpha`` of its
mode test (``identify_modes(..., false_alarm=alpha)``: the probability that a
fit of noise keeps a noise mode).

Per ``alpha`` the table prints, per SNR, per input count and in all: the
fits, the fits that kept at least one in-band mode farther than half a
half-power half-width (``0.5 zeta f``) from every true mode, that share with
its exact 95 % (Clopper-Pearson) interval, and the missed true modes. A share
at or below ``alpha`` is a test that keeps its stated rate; far below, a
conservative one (less power for weak modes than the rate allows).
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from typing import Any

import numpy as np
from scipy import stats as sps

KINDS = ("receptance", "mobility", "accelerance")
SNRS = (20.0, 40.0, 60.0)


def system(seed: int) -> dict[str, Any]:
    """One system (module docstring): poles, shapes and data settings of ``seed``."""
    rng = np.random.default_rng(77_000 + seed)
    m = int(rng.integers(3, 7))
    n_in = int(rng.integers(1, 5))
    n_out = int(rng.integers(2, 9))
    zeta = np.exp(rng.uniform(np.log(0.005), np.log(0.04), m))
    f = np.sort(rng.uniform(25.0, 175.0, m))
    for i in range(1, m):  # six times the sum of the half-widths apart, at least
        f[i] = max(f[i], f[i - 1] * (1 + 6 * (zeta[i - 1] + zeta[i])))
    keep = f < 180.0
    f, zeta = f[keep], zeta[keep]
    m = f.size
    w = 2 * np.pi * f
    amp = np.exp(rng.uniform(np.log(0.3), 0.0, m))
    df = max(float(np.min(zeta * f) * rng.uniform(0.2, 0.4)), 160.0 / 6000)
    return {
        "poles": -zeta * w + 1j * w * np.sqrt(1 - zeta**2),
        "psi_out": (rng.normal(size=(n_out, m)) + 1j * rng.normal(size=(n_out, m))) * amp,
        "psi_in": rng.normal(size=(n_in, m)) + 0.3j * rng.normal(size=(n_in, m)),
        "kind": KINDS[seed % 3],
        "snr": SNRS[(seed // 3) % 3],
        "freq": np.arange(10.0, 195.0, df),
        "band": (15.0, 190.0),
    }


def one_fit(seed: int, alpha: float) -> dict[str, Any]:
    """Identify system ``seed`` at false-alarm rate ``alpha``; its noise modes."""
    from tyredamp.modal import ModalModel, identify_modes

    s = system(seed)
    frf = ModalModel(s["poles"], s["psi_out"], s["psi_in"]).frf(s["freq"], s["kind"])
    h = frf.H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2), keepdims=True))
    rng = np.random.default_rng(5 + seed)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    out: dict[str, Any] = {
        "seed": seed,
        "snr": s["snr"],
        "n_in": int(s["psi_in"].shape[0]),
        "n_out": int(s["psi_out"].shape[0]),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = identify_modes(
                frf.with_H(h + 10 ** (-s["snr"] / 20) * rms * e),
                band=s["band"],
                model="complex",
                false_alarm=alpha,
            )
        except Exception as exc:  # a failed fit is reported, not counted
            return {**out, "error": f"{type(exc).__name__}: {exc}"}
    c = res.models["complex"]
    ft = np.abs(s["poles"]) / (2 * np.pi)
    hw = -s["poles"].real / (2 * np.pi)  # half-power half-width zeta f (Hz)
    fi = np.asarray(c.frequency_hz)
    d = np.abs(fi[:, None] - ft[None, :]) / hw[None, :]  # (identified, true)
    noise = np.flatnonzero(np.all(d > 0.5, axis=1)) if fi.size else np.zeros(0, int)
    q = c.quality
    out["noise_modes"] = [
        {
            "frequency_hz": float(fi[j]),
            "damping_ratio": float(c.damping_ratio[j]),
            "statistic": float(q.statistic[j]),
            "threshold": float(q.thresholds[j]),
        }
        for j in noise
    ]
    out["missed"] = int(np.sum(np.all(d > 0.5, axis=0))) if fi.size else int(ft.size)
    return out


def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Exact binomial interval of a share ``k / n``."""
    a = 1 - level
    lo = 0.0 if k == 0 else float(sps.beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(sps.beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi


def table(alpha: float, rows: list[dict[str, Any]]) -> list[str]:
    ok = [r for r in rows if "error" not in r]
    lines = [
        f"== false-alarm rate alpha = {alpha:g}: {len(ok)} fits ({len(rows) - len(ok)} failed)",
        f"{'group':>10} {'fits':>6} {'with noise mode':>16} {'share':>7} "
        f"{'95 % interval':>17} {'missed':>7}",
    ]
    groups: list[tuple[str, list[dict[str, Any]]]] = [
        (f"{snr:g} dB", [r for r in ok if r["snr"] == snr]) for snr in SNRS
    ]
    groups += [(f"{k} input", [r for r in ok if r["n_in"] == k]) for k in (1, 2, 3, 4)]
    groups.append(("all", ok))
    for name, g in groups:
        if not g:
            continue
        k = sum(1 for r in g if r["noise_modes"])
        lo, hi = clopper_pearson(k, len(g))
        lines.append(
            f"{name:>10} {len(g):>6} {k:>16} {k / len(g):>7.4f} "
            f"{f'{lo:.4f}-{hi:.4f}':>17} {sum(r['missed'] for r in g):>7}"
        )
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fits", type=int, default=1800, help="fits per false-alarm rate")
    ap.add_argument("--alpha", type=float, nargs="+", default=[0.01, 0.2])
    ap.add_argument("--jobs", type=int, default=1, help="processes (BLAS threads 1 each)")
    args = ap.parse_args()
    for alpha in args.alpha:
        if not 0 < alpha < 1:
            raise SystemExit(f"--alpha: expected probabilities in (0, 1), got {alpha}")
        t0 = time.perf_counter()
        seeds = list(range(args.fits))
        if args.jobs <= 1:
            rows = [one_fit(s, alpha) for s in seeds]
        else:
            import multiprocessing as mp
            from functools import partial

            os.environ["OPENBLAS_NUM_THREADS"] = os.environ["OMP_NUM_THREADS"] = "1"
            with mp.get_context("spawn").Pool(args.jobs) as pool:
                rows = pool.map(partial(one_fit, alpha=alpha), seeds, chunksize=4)
        for line in table(alpha, rows):
            print(line)
        noise = [(r, nm) for r in rows for nm in r.get("noise_modes", [])]
        for r, nm in noise if len(noise) <= 20 else []:  # the few of a small alpha
            print(
                f"  seed {r['seed']} ({r['snr']:g} dB, {r['n_out']}x{r['n_in']}): "
                f"{nm['frequency_hz']:.3f} Hz, zeta {nm['damping_ratio']:.4f}, "
                f"T = {nm['statistic']:.3g} > {nm['threshold']:.3g}"
            )
        print(f"({time.perf_counter() - t0:.0f} s)\n")


if __name__ == "__main__":
    main()
