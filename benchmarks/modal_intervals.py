"""Coverage of the 95 % intervals of f and zeta: likelihood against linearised.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/modal_intervals.py [--draws 300] [--jobs 2]
[--kind real]`` (about 5 minutes with 2 jobs).

Two modes one half-power half-width apart (damping 1 %, 4 outputs, one input,
0.15 half-widths per line, receptance), the second weaker by the factor
``weak``, and an isolated weak mode; white complex Gaussian noise, a new draw
per fit. ``--kind real``: the modes are real (proportional damping) and the
first table scores the real-mode model (``model="both"``).
:func:`~tyredamp.modal.identify_modes` as a user calls it (automatic mode
count, noise from the residual), once with the likelihood intervals of
:mod:`tyredamp.modal.fit.profile` (the default) and once with them switched off
(``KAPPA`` infinite: the linearised intervals of every earlier version). Per
case it prints the weak mode's median statistic ``T``, the share of draws
that found both modes, and the share of those whose interval holds the true
value: the likelihood interval itself (``lik``), the symmetric interval
``+-1.96 std`` reported in the ``std`` fields (``sym``, which holds it) and
the linearised interval (``lin``).

A second table checks the rule of which modes are profiled (``KAPPA``): one
mode at noise levels where its pole's standard error is 0.3-10 % of the
half-width, every mode profiled, and the largest gap between an end of the
likelihood interval and of the linearised one, in units of the linearised
half-width (median over the draws).
"""

from __future__ import annotations

import argparse
import time
from multiprocessing import Pool
from typing import Any

import numpy as np

from tyredamp.frf import FRF
from tyredamp.modal import identify_modes
from tyredamp.modal.fit import profile as prof
from tyredamp.modal.model import ModalModel

F = np.arange(40.0, 60.0, 0.075)
W1 = 2 * np.pi * 50.0
ZETA = 0.01
NOISE = 0.05  # noise RMS per line (complex), against residues of order 1


def poles_of(sep: float) -> np.ndarray:
    p = complex(-ZETA * W1, W1)
    return np.array([p, p * (1 + sep * ZETA)])


def clean(weak: float, sep: float, kind: str = "complex") -> np.ndarray:
    """The two modes' FRFs: complex modes, or real ones (residues ``-i phi phi``, real
    ``phi``: proportional damping, scaled to the complex case's size)."""
    rng = np.random.default_rng(1)
    p = poles_of(sep)
    if kind == "complex":
        psi = (rng.normal(size=(4, 2)) + 1j * rng.normal(size=(4, 2))) * np.array([1.0, weak])
        part = np.ones((1, 2)) + 0j
    else:
        unit = np.abs(np.sqrt(2j * p.imag)) / np.sqrt(2j * p.imag)
        psi = rng.normal(size=(4, 2)) * np.array([1.0, weak]) * unit
        part = np.ones((1, 2)) * unit
    return ModalModel(p, psi, part).frf(F, "receptance").H


def one(args: tuple[float, float, int, float, str]) -> dict[str, Any] | None:
    """One draw: the weak mode's coverage by each interval of the ``kind`` model, with
    profiling at ``kappa``."""
    weak, sep, seed, kappa, kind = args
    prof.KAPPA = kappa
    h0 = clean(weak, sep, kind)
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=h0.shape) + 1j * rng.normal(size=h0.shape)) / np.sqrt(2)
    try:
        m = identify_modes(
            FRF(F, h0 + NOISE * e, kind="receptance"),
            model="complex" if kind == "complex" else "both",
        )
    except Exception:  # a failed identification counts as not found
        return None
    c = m.models[kind]
    if c.n_modes != 2:
        return None
    p = poles_of(sep)
    ft, zt = abs(p[1]) / (2 * np.pi), -p[1].real / abs(p[1])
    fi = np.asarray(c.meta["interval_frequency_hz"])[1]
    zi = np.asarray(c.meta["interval_damping_ratio"])[1]
    sf, sz = float(c.std["frequency_hz"][1]), float(c.std["damping_ratio"][1])
    return {
        "T": float(c.meta["significance"][1]),
        "lik_f": bool(fi[0] <= ft <= fi[1]),
        "lik_z": bool(zi[0] <= zt <= zi[1]),
        "sym_f": bool(abs(c.frequency_hz[1] - ft) <= prof.Z95 * sf),
        "sym_z": bool(abs(c.damping_ratio[1] - zt) <= prof.Z95 * sz),
    }


def agreement(args: tuple[float, int]) -> tuple[float, float]:
    """Pole standard error over the half-width, and the largest gap between the ends
    of the likelihood and linearised intervals in linearised half-widths (the same
    data identified twice: every mode profiled, and none)."""
    noise, seed = args
    p = poles_of(0.0)[:1]
    rng = np.random.default_rng(1)
    psi = rng.normal(size=(4, 1)) + 1j * rng.normal(size=(4, 1))
    h0 = ModalModel(p, psi, np.ones((1, 1))).frf(F, "receptance").H
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=h0.shape) + 1j * rng.normal(size=h0.shape)) / np.sqrt(2)
    frf = FRF(F, h0 + noise * e, kind="receptance")
    got = {}
    for name, kappa in (("lik", 0.0), ("lin", np.inf)):
        prof.KAPPA = kappa
        got[name] = identify_modes(frf, model="complex", n_modes=1).models["complex"]
    m = got["lin"]
    sp = np.asarray(m.meta["std_pole"])[0]
    kappa = max(abs(sp.real), abs(sp.imag)) / -m.poles[0].real
    gaps = []
    for key in ("frequency_hz", "damping_ratio"):
        lin = np.asarray(got["lin"].meta[f"interval_{key}"])[0]
        lik = np.asarray(got["lik"].meta[f"interval_{key}"])[0]
        gaps.append(float(np.max(np.abs(lik - lin)) / (0.5 * (lin[1] - lin[0]))))
    return float(kappa), max(gaps)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=300)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument(
        "--kind",
        choices=("complex", "real"),
        default="complex",
        help="complex modes, or real ones (proportional damping) and the real-mode model",
    )
    args = ap.parse_args()
    cases = [(0.15, 1.0), (0.2, 1.0), (0.3, 1.0), (0.5, 1.0), (0.2, 8.0)]
    t0 = time.perf_counter()
    print(
        f"{'weak':>5} {'sep':>5} {'T med':>6} {'found':>6} | likelihood: "
        f"{'lik f':>6} {'zeta':>6} {'sym f':>6} {'zeta':>6} | linearised: {'f':>6} {'zeta':>6}"
    )
    with Pool(args.jobs) as pool:
        for weak, sep in cases:
            rows = {}
            for name, kappa in (("lik", prof.KAPPA), ("lin", np.inf)):
                jobs = [(weak, sep, 1000 + i, kappa, args.kind) for i in range(args.draws)]
                rows[name] = [r for r in pool.map(one, jobs) if r is not None]
            lik, lin = rows["lik"], rows["lin"]

            def share(rs: list[dict[str, Any]], key: str) -> float:
                return float(np.mean([r[key] for r in rs])) if rs else float("nan")

            print(
                f"{weak:>5g} {sep:>5g} {np.median([r['T'] for r in lik]):>6.0f} "
                f"{len(lik) / args.draws:>6.2f} |             {share(lik, 'lik_f'):>6.3f} "
                f"{share(lik, 'lik_z'):>6.3f} {share(lik, 'sym_f'):>6.3f} "
                f"{share(lik, 'sym_z'):>6.3f} |             {share(lin, 'sym_f'):>6.3f} "
                f"{share(lin, 'sym_z'):>6.3f}"
            )
        print("\nagreement of the two intervals (every mode profiled): ")
        print(f"{'noise':>8} {'sd/sigma':>9} {'max end gap / half-width':>26}")
        for noise in (0.003, 0.01, 0.03, 0.1):
            got = pool.map(agreement, [(noise, 2000 + i) for i in range(20)])
            k = np.median([g[0] for g in got])
            gap = np.median([g[1] for g in got])
            print(f"{noise:>8g} {k:>9.4f} {gap:>26.4f}")
    print(f"\n({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
