"""tyredamp oma against pyOMA2 (SSIcov and pLSCF) on the same real data and band, in one run.

Data (../shared/real-data, see CATALOGUE.md there):

* the pyOMA steel-frame tower, ``measurement_1.npy`` (256 Hz, 240 s; columns 0-4,
  column 5 excluded as its ``setup_info.txt`` says; references 3 and 4 as it says),
  decimated by 6 to 42.7 Hz, band 0.5-15 Hz;
* the pyuff ``MPSTD#Set001...uff`` ambient recording (4 accelerations, 3200 Hz,
  69.5 s), band 1-400 Hz.

pyOMA2 (``pip install pyOMA_2``, the ``bench`` extra) has no automatic selection
in its SSI: its modes are picked at tyredamp's frequencies with its own
``mpe(sel_freq=..., order_in="find_min")``, and its pLSCF likewise with
``mpe(sel_freq=...)``. Printed: frequency and damping per mode from each, the
differences, and the run times (one BLAS thread for both).

Run: ``python benchmarks/oma_compare.py``
"""

from __future__ import annotations

import logging
import time
import warnings
from pathlib import Path

import numpy as np

from tyredamp._blas import single_threaded_blas
from tyredamp.io import read_timedata
from tyredamp.oma import oma

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
TOWER = REAL / "pyOMA-dev_pyOMA" / "tests" / "files" / "measurement_1" / "measurement_1.npy"
MPSTD = REAL / "ladisk_pyuff" / "data" / "MPSTD#Set001_2024_10_08_10_27_07.uff"


def _pyoma2(y: np.ndarray, fs: float, q: int, sel: np.ndarray, refs: list[int], br: int):
    """pyOMA2 SSIcov and pLSCF at the frequencies ``sel`` (None when not installed)."""
    try:
        from pyoma2.algorithms import SSI, pLSCF
        from pyoma2.setup import SingleSetup
    except ImportError:
        return None
    logging.disable(logging.WARNING)
    out = {}
    for name, make in (
        ("SSIcov", lambda: SSI(name="SSIcov", method="cov", br=br, ordmax=80, ref_ind=refs)),
        ("pLSCF", lambda: pLSCF(name="pLSCF", ordmax=40)),
    ):
        ss = SingleSetup(y.T.copy(), fs=fs)
        if q > 1:
            ss.decimate_data(q=q)
        alg = make()
        ss.add_algorithms(alg)
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ss.run_by_name(name)
            dt = time.perf_counter() - t0
            kw = {"order_in": "find_min"} if name == "SSIcov" else {}
            ss.mpe(name, sel_freq=list(sel), **kw)
        r = dict(alg.result)
        out[name] = (np.asarray(r["Fn"], float), np.asarray(r["Xi"], float), dt)
    return out


def _table(label: str, res, other) -> None:
    print(f"\n{label}: tyredamp {res.method} found {res.n_modes} modes")
    head = f"{'#':>3} {'f [Hz]':>9} {'+-':>7} {'zeta %':>7} {'+-':>6}"
    if other:
        head += "".join(f" | {k:>7} f {'df %':>6} {'zeta %':>7}" for k in other)
    print(head)
    for j in range(res.n_modes):
        row = (
            f"{j + 1:>3} {res.frequency_hz[j]:>9.4f} {res.std_frequency_hz[j]:>7.2g} "
            f"{100 * res.damping_ratio[j]:>7.3f} {100 * res.std_damping_ratio[j]:>6.2g}"
        )
        for f, z, _ in (other or {}).values():
            k = int(np.argmin(np.abs(f - res.frequency_hz[j])))
            df = 100 * (f[k] - res.frequency_hz[j]) / res.frequency_hz[j]
            row += f" | {f[k]:>9.4f} {df:>6.2f} {100 * z[k]:>7.3f}"
        print(row)


def main() -> None:
    if not REAL.is_dir():
        print(f"no real data at {REAL}")
        return
    cases = []
    if TOWER.is_file():
        y = np.load(TOWER).T[:5]
        cases.append(("tower measurement_1 (pyOMA)", y, 256.0, 6, (0.5, 15.0), [3, 4], 40))
    if MPSTD.is_file():
        td = read_timedata(MPSTD)
        cases.append(("MPSTD#Set001 (pyuff)", td.data, td.sample_rate, 3, (1.0, 400.0), None, 40))
    for label, y, fs, q, band, refs, br in cases:
        with single_threaded_blas():
            t0 = time.perf_counter()
            res = oma(y, fs, band=band, decimate=q, references=refs)
            t_ssi = time.perf_counter() - t0
            t0 = time.perf_counter()
            res_pl = oma(y, fs, band=band, decimate=q, references=refs, method="plscf")
            t_pl = time.perf_counter() - t0
            other = _pyoma2(y, fs, q, res.frequency_hz, list(res.references), br)
        _table(label, res, other)
        print(f"time: tyredamp SSI {t_ssi:.2f} s (with jackknife), pLSCF {t_pl:.2f} s", end="")
        if other:
            print("".join(f"; pyOMA2 {k} {v[2]:.2f} s" for k, v in other.items()))
        else:
            print("; pyOMA2 not installed (pip install pyOMA_2)")
        f_pl = res_pl.frequency_hz
        print("tyredamp pLSCF modes [Hz]:", np.array2string(f_pl, precision=4))
        for n in res.notes:
            print("note:", n)


if __name__ == "__main__":
    main()
