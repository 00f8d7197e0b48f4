"""Excitation detection from the data: verdicts over many generated records of each kind.

Run:  OPENBLAS_NUM_THREADS=1 python benchmarks/signal_detection.py [--quick]

Prints, for each kind of force signal, how many records were classified
periodic (with the right period), random or impact, and the time per record;
then how often a start transient is wrongly found in steady periodic records
whose force noise reaches every response (coloured, shared by the channels).
The response is the two-mode digital system of ``tests/excitation_records.py``.
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import scipy.signal

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from excitation_records import impact_record, random_record, respond
from tyredamp.signal import burst_random, periodic_chirp, pseudo_random, swept_chirp
from tyredamp.signal.periodicity import detect_excitation


def cases(rng: np.random.Generator):  # type: ignore[no-untyped-def]
    n = int(rng.integers(3000, 30000))
    yield "band-limited random", "random", None, *random_record(n, rng)
    w, z = rng.uniform(0.02, 0.4), 10 ** rng.uniform(-3, -1.5)
    r = np.exp(-z * 2 * np.pi * w)
    x = scipy.signal.lfilter(
        [1.0], [1, -2 * r * np.cos(2 * np.pi * w), r * r], rng.standard_normal(n + 5000)
    )[5000:]
    yield "narrow-band random (zeta 0.1-3 %)", "random", None, x, respond(x)
    x = rng.standard_normal(n) + 0.1 * np.sin(2 * np.pi * np.arange(n) / 20)
    yield "random + 1 % mains hum", "random", None, x, respond(x)
    e = swept_chirp(1000.0, n, (10.0, 400.0))
    yield "one sweep over the record", "random", None, e.signal, respond(e.signal)
    yield "impact hits", "impact", None, *impact_record(n, rng)
    e = burst_random(1000.0, 1000, (5.0, 300.0), n_records=max(3, n // 1000), rng=rng)
    yield "burst random", "impact", None, e.signal, respond(e.signal)
    p = int(rng.integers(64, 3000))
    e = pseudo_random(1000.0, p, (1.0, 400.0), n_periods=max(4, n // p), rng=rng)
    yield (
        "pseudo-random multisine, 10 dB",
        "periodic",
        p,
        e.signal + 0.3 * rng.standard_normal(e.signal.size),
        respond(e.signal),
    )
    p = int(rng.integers(200, 2000))
    e = periodic_chirp(1000.0, p, (50.0, 60.0), n_periods=max(4, n // p))
    yield "narrow-band periodic chirp", "periodic", p, e.signal, respond(e.signal)
    p = int(rng.integers(100, 2000))
    m = max(4, 20000 // p)
    x = np.tile(rng.standard_normal(p), m)
    sos = scipy.signal.butter(2, 0.5 / p, output="sos")
    drift = scipy.signal.sosfilt(sos, rng.standard_normal(x.size + 20000))[20000:]
    xn = x + drift * np.sqrt(0.05) / np.std(drift) + 0.1 * rng.standard_normal(x.size)
    yield "periodic + 5 % drift + 1 % noise", "periodic", p, xn, respond(x)


def main(n_records: int) -> None:
    rng = np.random.default_rng(2026)
    table: dict[str, Counter[str]] = {}
    times: dict[str, float] = {}
    for _ in range(n_records):
        for name, truth, period, x, y in cases(rng):
            t0 = time.perf_counter()
            d = detect_excitation(x, y)
            times[name] = times.get(name, 0.0) + time.perf_counter() - t0
            verdict = d.kind
            if d.kind == "periodic":
                verdict += " (right period)" if d.period_samples == period else " (WRONG period)"
            ok = d.kind == truth and (period is None or d.period_samples == period)
            table.setdefault(name, Counter())["ok" if ok else verdict] += 1
    print(f"{'force signal':<36} {'records':>7} {'right':>6}  wrong verdicts          ms/record")
    for name, c in table.items():
        total = sum(c.values())
        wrong = ", ".join(f"{k}: {v}" for k, v in c.items() if k != "ok") or "-"
        print(f"{name:<36} {total:>7} {c['ok']:>6}  {wrong:<24} {1e3 * times[name] / total:8.1f}")


def transient_false_flags(n_records: int) -> None:
    """Steady periodic records whose force noise reaches every response (coloured, shared)."""
    from excitation_records import periodic_record
    from tyredamp.signal.periodicity import ALPHA, transient_periods

    rng = np.random.default_rng(9)
    flags = 0
    for _ in range(n_records):
        p = int(rng.integers(100, 1500))
        x, y, _ = periodic_record("multisine", p, 10, rng, False)
        fn = 0.05 * rng.standard_normal(x.size)
        coloured = scipy.signal.lfilter([1.0], [1.0, -0.9], rng.standard_normal(x.size))
        yn = y + respond(fn) + 0.01 * np.std(y) * coloured
        flags += transient_periods(np.vstack([x + fn, yn, 2 * yn]), p) > 0
    print(
        f"start transient wrongly found in {flags} of {n_records} steady records "
        f"(nominal false-alarm level {ALPHA:g} per record)"
    )


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    main(20 if quick else 100)
    transient_false_flags(40 if quick else 200)
