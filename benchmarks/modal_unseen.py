"""Systems unlike the issue-16 corpus: does the automatic identification hold up?

Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/modal_unseen.py [--systems 40] [--jobs 2]
        [--snr 200] [--old-src /path/to/other/src]

The corpus of ``modal_statistics.py`` draws its systems from one family
(modes in 20-180 Hz, a band that holds them, 0.1-0.2 half-power bandwidths
per line, distinct poles). Each family here breaks one of those habits, with
nearly noise-free data by default (complex noise at 1e-10 of each output's
RMS), so that every mode in the band is significant and the fit should reach
the noise:

* ``repeated``: 2-3 inputs, every root twice with its own shapes and
  participation (a symmetric structure: a perfect ring, a disc; the residue at
  the root has rank two);
* ``sub-band``: strong modes below and above the band analysed (its tails
  in the band, one mode just outside an edge);
* ``coarse``: 0.7-1.5 lines per half-power bandwidth of the narrowest mode;
* ``damped``: damping ratios 2-15 %, overlapping modes;
* ``many outputs``: 40 outputs, 1-3 inputs.

``--snr`` (dB, default 200: noise at 1e-10) sets the noise of every family;
at a realistic SNR the weakest modes may not be significant.

Printed per family: the share of the true in-band modes identified (within
``max(0.5 zeta f, 1e-4 f)``), the share of fits whose relative fit error is
below 1e-6 or within 10 % of the noise's own relative level in the band (the
model explains the data to the noise: every mode found, none extra; a
sub-band's response is weaker than the whole axis's, so its relative noise is
higher than the SNR says), the identified modes per true mode, fits that
raised an error, and the median and largest time per fit. With ``--old-src``
the same systems are identified by the code at that path as well (a second
table).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import warnings
from typing import Any

import numpy as np

FAMILIES = ("repeated", "sub-band", "coarse", "damped", "many outputs")
#: default SNR (dB): noise at 1e-10 of each output's RMS
SNR = 200.0


def system(seed: int) -> dict[str, Any]:
    """System ``seed`` (family ``seed % 5``): poles, shapes, lines and band."""
    rng = np.random.default_rng(70_000 + seed)
    fam = FAMILIES[seed % len(FAMILIES)]
    n_in = int(rng.integers(2, 4)) if fam == "repeated" else int(rng.integers(1, 4))
    n_out = 40 if fam == "many outputs" else int(rng.integers(2, 7))
    m = int(rng.integers(3, 9)) if fam == "repeated" else int(rng.integers(4, 16))
    zlo, zhi = (0.02, 0.15) if fam == "damped" else (0.003, 0.03)
    zeta = np.exp(rng.uniform(np.log(zlo), np.log(zhi), m))
    f = np.sort(rng.uniform(60.0, 940.0, m))
    band = (50.0, 950.0)
    if fam == "sub-band":  # a third of the modes outside (300, 700) Hz, one near each edge
        band = (300.0, 700.0)
        f[0], f[-1] = 300.0 * (1 - rng.uniform(0.005, 0.05)), 700.0 * (1 + rng.uniform(0.005, 0.05))
    w = 2 * np.pi * f
    poles = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    amp = np.exp(rng.uniform(np.log(0.03), 0.0, m))
    if fam == "sub-band":
        amp[(f < band[0]) | (f > band[1])] = 1.0  # strong tails in the band
    psi_out = (rng.normal(size=(n_out, m)) + 1j * rng.normal(size=(n_out, m))) * amp
    psi_in = rng.normal(size=(n_in, m)) + 0.3j * rng.normal(size=(n_in, m))
    if fam == "repeated":
        poles = np.concatenate([poles, poles])
        psi_out = np.concatenate([psi_out, rng.normal(size=psi_out.shape) * amp + 0j], axis=1)
        psi_in = np.concatenate([psi_in, rng.normal(size=psi_in.shape) + 0j], axis=1)
    per_bw = rng.uniform(0.7, 1.5) if fam == "coarse" else rng.uniform(5.0, 10.0)
    df = float(np.min(2 * zeta * f) / per_bw)
    n = int(np.clip(1000.0 / df, 200, 8000))
    return {
        "family": fam,
        "poles": poles,
        "psi_out": psi_out,
        "psi_in": psi_in,
        "kind": ("receptance", "mobility", "accelerance")[(seed // 5) % 3],
        "freq": np.linspace(1000.0 / n, 1000.0, n),
        "band": band,
    }


def identify(seed: int, snr: float = SNR) -> dict[str, Any]:
    """Identified in-band modes of system ``seed`` at ``snr`` dB, its fit error and time."""
    from tyredamp.modal import ModalModel, identify_modes

    s = system(seed)
    frf = ModalModel(s["poles"], s["psi_out"], s["psi_in"]).frf(s["freq"], s["kind"])
    h = frf.H
    rng = np.random.default_rng(seed)
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2), keepdims=True))
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    noise = 10 ** (-snr / 20) * rms * e
    frf = frf.with_H(h + noise)
    # the noise relative to the data in the band analysed (a sub-band's response is
    # weaker than the whole axis's, so its relative noise is higher)
    inb = (s["freq"] >= s["band"][0]) & (s["freq"] <= s["band"][1])
    level = float(np.linalg.norm(noise[..., inb]) / np.linalg.norm(frf.H[..., inb]))
    t = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c = identify_modes(frf, band=s["band"], model="complex").models["complex"]
    except Exception as exc:  # a failed fit counts as nothing found
        return {"seed": seed, "error": f"{type(exc).__name__}: {exc}", "time": 0.0}
    return {
        "seed": seed,
        "f": c.frequency_hz.tolist(),
        "relerr": float(c.meta["relative_error"]),
        "noise": level,
        "time": time.perf_counter() - t,
    }


def score(r: dict[str, Any]) -> dict[str, Any]:
    """Found and extra modes of one result against its system's in-band truth."""
    s = system(int(r["seed"]))
    fn = np.abs(s["poles"]) / (2 * np.pi)
    z = -s["poles"].real / np.abs(s["poles"])
    inb = (fn >= s["band"][0]) & (fn <= s["band"][1])
    got = np.asarray(r.get("f", []), float)
    free = np.ones(got.size, bool)
    found = 0
    for i in np.flatnonzero(inb)[np.argsort(fn[inb])]:  # each identified mode once
        d = np.where(free, np.abs(got - fn[i]), np.inf)
        if d.size and d.min() <= max(0.5 * z[i] * fn[i], 1e-4 * fn[i]):
            free[int(np.argmin(d))] = False
            found += 1
    return {
        "family": s["family"],
        "true": int(np.count_nonzero(inb)),
        "found": found,
        "n_id": int(got.size),
        "exact": bool(r.get("relerr", 1.0) < max(1e-6, 1.1 * r.get("noise", 0.0))),
        "error": "error" in r,
        "time": float(r["time"]),
    }


def table(title: str, results: list[dict[str, Any]]) -> list[str]:
    rows = [score(r) for r in results]
    out = [
        title,
        f"{'family':>13} {'fits':>5} {'found':>7} {'fit to noise':>12} "
        f"{'id/true':>8} {'errors':>6} {'median s':>8} {'max s':>7}",
    ]
    for fam in FAMILIES:
        sel = [r for r in rows if r["family"] == fam]
        if not sel:
            continue
        true = sum(r["true"] for r in sel)
        out.append(
            f"{fam:>13} {len(sel):>5} {100 * sum(r['found'] for r in sel) / max(true, 1):>6.1f}% "
            f"{100 * np.mean([r['exact'] for r in sel]):>11.0f}% "
            f"{sum(r['n_id'] for r in sel) / max(true, 1):>8.2f} {sum(r['error'] for r in sel):>6} "
            f"{np.median([r['time'] for r in sel]):>8.2f} {max(r['time'] for r in sel):>7.1f}"
        )
    return out


def _run(seeds: list[int], jobs: int, snr: float) -> list[dict[str, Any]]:
    if jobs <= 1:
        return [identify(s, snr) for s in seeds]
    import multiprocessing as mp
    from functools import partial

    with mp.get_context("spawn").Pool(jobs) as pool:
        return pool.map(partial(identify, snr=snr), seeds, chunksize=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--systems", type=int, default=40, help="systems (8 per family by default)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--snr", type=float, default=SNR, help="SNR in dB (default 200)")
    ap.add_argument("--old-src", help="src directory of other code, identified as well")
    ap.add_argument("--identify-only", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    seeds = list(range(args.systems))
    if args.identify_only:  # subprocess of --old-src
        json.dump(_run(seeds, args.jobs, args.snr), sys.stdout)
        return
    t0 = time.perf_counter()
    title = f"{args.systems} systems, {args.snr:g} dB"
    lines = table(f"this code, {title}", _run(seeds, args.jobs, args.snr))
    if args.old_src:
        env = {**os.environ, "PYTHONPATH": os.path.abspath(args.old_src)}
        cmd = [sys.executable, __file__, "--systems", str(args.systems), "--jobs", str(args.jobs)]
        cmd += ["--snr", str(args.snr)]
        got = subprocess.run([*cmd, "--identify-only"], env=env, capture_output=True, text=True)
        if got.returncode != 0:
            sys.exit(f"--old-src: the other code failed: {got.stderr.strip().splitlines()[-1]}")
        lines += ["", *table(f"code at {args.old_src}, {title}", json.loads(got.stdout))]
    print("\n".join(lines))
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
