"""Speed and memory of tyredamp's OMA: against pyOMA2 SSIcov, and an hour streamed.

1. A 32-channel, 120 s, 1 kHz synthetic record (12 modes 20-400 Hz, random
   excitation, 5 % noise): tyredamp ``oma`` (SSI-cov, same block rows, model
   orders and references as pyOMA2, jackknife off as pyOMA2's ``calc_unc`` is;
   then with it) against pyOMA2 ``SSI(method="cov")`` on the same data. Both on
   one BLAS thread.
2. Linear in the record length: the correlation step on 30, 60 and 120 s.
3. One hour of 32 channels at 1 kHz (3.6 M samples, 0.92 GB as float64 in
   memory), generated and fed in 10 s chunks to
   :class:`tyredamp.oma.CorrelationAccumulator`, then SSI and selection: the peak
   resident memory of the process is printed (``resource.getrusage``).

Run: ``python benchmarks/oma_speed.py`` (``--skip-hour`` for parts 1-2 only).
"""

from __future__ import annotations

import argparse
import logging
import resource
import time
import warnings

import numpy as np
from scipy.signal import lfilter

from tyredamp._blas import single_threaded_blas
from tyredamp.oma import CorrelationAccumulator, oma
from tyredamp.oma.identify import choose_references
from tyredamp.oma.selection import select_modes, stabilisation
from tyredamp.oma.ssi import ssi_cov

N_CH = 32
FS = 1000.0
F_MODES = np.linspace(20, 400, 12)
ZETA = 0.01


class Source:
    """Output-only records of 12 modes, generated chunk by chunk (filter states kept)."""

    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)
        lam = 2 * np.pi * F_MODES * (-ZETA + 1j * np.sqrt(1 - ZETA**2))
        self.a = np.exp(lam / FS)
        self.shapes = self.rng.standard_normal((N_CH, F_MODES.size))
        self.zi = [np.zeros(1, complex) for _ in F_MODES]

    def chunk(self, n: int) -> np.ndarray:
        q = np.empty((F_MODES.size, n), complex)
        for k, a in enumerate(self.a):
            e = self.rng.standard_normal(n) + 1j * self.rng.standard_normal(n)
            q[k], self.zi[k] = lfilter([1.0], [1.0, -a], e, zi=self.zi[k])
        y = np.real(self.shapes @ q)
        return y + 0.05 * y.std() * self.rng.standard_normal(y.shape)


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _pyoma2_time(y: np.ndarray, br: int, ordmax: int, refs: list[int]) -> float | None:
    try:
        from pyoma2.algorithms import SSI
        from pyoma2.setup import SingleSetup
    except ImportError:
        return None
    logging.disable(logging.WARNING)
    ss = SingleSetup(y.T.copy(), fs=FS)
    alg = SSI(name="SSIcov", method="cov", br=br, ordmax=ordmax, ref_ind=refs)
    ss.add_algorithms(alg)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ss.run_by_name("SSIcov")
    return time.perf_counter() - t0


def compare(br: int = 30, ordmax: int = 120) -> None:
    y = Source(1).chunk(int(120 * FS))
    refs = choose_references(y)
    with single_threaded_blas():
        t0 = time.perf_counter()
        res = oma(y, FS, references=refs, block_rows=br, max_order=ordmax, uncertainty=False)
        t_td = time.perf_counter() - t0
        t0 = time.perf_counter()
        res_u = oma(y, FS, references=refs, block_rows=br, max_order=ordmax)
        t_tdu = time.perf_counter() - t0
        t_py = _pyoma2_time(y, br, ordmax, refs)
    err = np.max(np.abs(res.frequency_hz[:, None] - F_MODES[None, :]).min(axis=0) / F_MODES)
    print(f"32 ch x 120 s at 1 kHz, {br} block rows, orders to {ordmax}, refs {refs}")
    print(
        f"  tyredamp SSI-cov (no jackknife): {t_td:.2f} s, {res.n_modes} modes, "
        f"largest |df|/f to the truth {100 * err:.3f} %"
    )
    print(f"  tyredamp SSI-cov + jackknife:    {t_tdu:.2f} s, {res_u.n_modes} modes")
    if t_py is None:
        print("  pyOMA2 not installed (pip install pyOMA_2)")
    else:
        print(
            f"  pyOMA2 SSI cov:                  {t_py:.2f} s  -> tyredamp {t_py / t_td:.1f}x "
            f"faster ({t_py / t_tdu:.1f}x with its jackknife)"
        )


def linear() -> None:
    src = Source(2)
    y = src.chunk(int(120 * FS))
    refs = choose_references(y)
    for sec in (30, 60, 120):
        acc = CorrelationAccumulator(N_CH, refs, 61, FS)
        t0 = time.perf_counter()
        acc.add(y[:, : int(sec * FS)])
        acc.result()
        print(f"  correlations of {sec:>3} s: {time.perf_counter() - t0:.3f} s")


def hour() -> None:
    src = Source(3)
    first = src.chunk(int(10 * FS))
    refs = choose_references(first)
    acc = CorrelationAccumulator(N_CH, refs, 61, FS)
    acc.add(first)
    t0 = time.perf_counter()
    for _ in range(359):
        acc.add(src.chunk(int(10 * FS)))
    corr = acc.result()
    with single_threaded_blas():
        op, _ = ssi_cov(corr.R, FS, 30, np.arange(2, 121, 2))
        clusters, _ = select_modes(op, stabilisation(op, (0, 450)))
    f = np.sort([op.frequency_hz[c.representative] for c in clusters])
    print(
        f"1 hour, 32 ch at 1 kHz streamed in 10 s chunks: {time.perf_counter() - t0:.1f} s "
        f"(generation included), {len(f)} modes, peak RSS {_rss_mb():.0f} MB"
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-hour", action="store_true")
    a = ap.parse_args()
    compare()
    linear()
    if not a.skip_hour:
        hour()


if __name__ == "__main__":
    main()
