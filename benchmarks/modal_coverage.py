"""Coverage of the 95 % intervals on the random-MDOF corpus, with the likelihood
intervals of :mod:`tyredamp.modal.fit.profile` and without them (issue 16).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/modal_coverage.py --snr 20 --systems 24``
(about 8 minutes with 2 jobs at 20 dB on a 2-core machine).

The systems of ``modal_statistics.py`` at one SNR (the first ``--systems`` of
that SNR), each identified twice as that benchmark identifies them: with the
likelihood intervals (the default) and with them off (``KAPPA`` infinite, the
linearised intervals of earlier versions). Scored by its :func:`score` (the
significant true modes at the true poles, matched within max(0.5 zeta f, 3
CRLB_f)), with a cheaper truth: its ``truth_stats`` without the refitted
likelihood ratio or the oracle. Printed for
each: the share of the matched significant modes whose error lies within
``1.96`` reported standard errors (``std``: the symmetric interval, which
holds the likelihood interval) and within the 95 % interval of the model's
meta (``interval``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from multiprocessing import get_context
from typing import Any

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def one(args: tuple[int, float]) -> tuple[int, float, dict[str, Any], dict[str, Any] | None]:
    """One identification (likelihood intervals at ``kappa``) and, once, the truth."""
    seed, kappa = args
    import modal_statistics as ms

    import tyredamp.modal.fit.profile as prof

    prof.KAPPA = kappa
    warnings.simplefilter("ignore")
    got = ms.identify(seed)
    return seed, kappa, got, ms.truth_stats(seed, refitted=False) if np.isfinite(kappa) else None


def main() -> None:
    import modal_statistics as ms

    import tyredamp.modal.fit.profile as prof

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--snr", type=float, default=20.0, choices=ms.SNRS)
    ap.add_argument("--systems", type=int, default=24)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--dump", help="write every identification and truth to this JSON file")
    args = ap.parse_args()
    seeds = [s for s in range(8 * args.systems) if ms.system(s)["snr"] == args.snr]
    seeds = seeds[: args.systems]
    runs = [(s, k) for s in seeds for k in (prof.KAPPA, np.inf)]
    t0 = time.perf_counter()
    out: dict[int, dict[str, Any]] = {}
    os.environ["OPENBLAS_NUM_THREADS"] = os.environ["OMP_NUM_THREADS"] = "1"
    with get_context("spawn").Pool(args.jobs) as pool:
        for seed, kappa, got, tr in pool.imap_unordered(one, runs):
            out.setdefault(seed, {})["likelihood" if np.isfinite(kappa) else "linearised"] = got
            if tr is not None:
                out[seed]["truth"] = tr
    if args.dump:
        with open(args.dump, "w", encoding="utf-8") as fh:
            json.dump(out, fh)
    print(f"{args.snr:g} dB, {len(seeds)} systems ({time.perf_counter() - t0:.0f} s)")
    print(f"{'intervals':>11} {'modes':>6} {'std f':>7} {'zeta':>7} {'interval f':>11} {'zeta':>7}")
    for name in ("likelihood", "linearised"):
        cf: list[bool] = []
        cz: list[bool] = []
        lf: list[bool] = []
        lz: list[bool] = []
        for s in seeds:
            r = ms.score(out[s]["truth"], out[s][name])
            cf, cz, lf, lz = cf + r["cf"], cz + r["cz"], lf + r["lf"], lz + r["lz"]
        print(
            f"{name:>11} {len(cf):>6} {np.mean(cf):>7.1%} {np.mean(cz):>7.1%} "
            f"{np.mean(lf):>11.1%} {np.mean(lz):>7.1%}"
        )


if __name__ == "__main__":
    main()
