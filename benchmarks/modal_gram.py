"""The Gram blocks of several-input complex fits: per-line sums against the basis.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/modal_gram.py [--repeat 7]
[--identify]``.

``ModalFitter._solve`` with complex modes and several inputs sums ``B^T B`` and
``B^T Y`` from the per-line functions of the modes
(:mod:`tyredamp.modal.fit._gram_lines`) instead of forming the basis ``B``.
For each case (:func:`perf_common.mimo_case`, its true poles and participation,
the upper and lower residual terms, first-pass weights) this prints the median
time of one evaluation (``_solve`` with derivatives and gradient, the
refinement's) by each route (``_gram_lines.USE`` False, then True), their
ratio, the largest difference of ``G`` and ``P`` relative to ``sqrt(G_ii
G_jj)`` and ``sqrt(G_ii ||Y_j||^2)``, and the same times of one evaluation of
``fit_added`` (the last mode refined with the others fixed). ``--identify`` also runs
``identify_modes`` by each route (``USE`` covers ``fit_added``'s sums too;
the three cases and, when
``../shared/real-data`` is there, ladisk/pyuff's measured accelerances of one
response to three roving-hammer references) and prints its time and the
largest difference of the frequencies and damping ratios found, relative and
in units of the damping ratio's standard error. Times are CPU times of the
process (one BLAS thread; the machine is shared, so medians and ratios count,
not single times).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
from perf_common import limit_blas, mimo_case

from tyredamp.frf import FRF
from tyredamp.modal import identify_modes
from tyredamp.modal.fit import _added, _basis, _gram_lines
from tyredamp.modal.fit.fit import ModalFitter

CASES = [(16, 2, 3000, 20, 35.0), (32, 2, 4000, 20, 50.0), (64, 3, 8000, 20, 30.0)]


def _evaluation(spec: tuple[int, int, int, int, float], repeat: int) -> None:
    case = mimo_case(*spec)
    frf = case.frf
    f = np.asarray(frf.frequency)
    sel = (f >= case.band[0]) & (f <= case.band[1])
    H = np.ascontiguousarray(np.asarray(frf.H)[:, :, sel])
    n_in = H.shape[1]
    fitter = ModalFitter(f[sel], H, 2, "complex", [(k, k) for k in range(n_in)])
    part = case.psi[:n_in].T.astype(complex)
    m = part.shape[0]
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    th = fitter.pack(case.poles, part, ref)
    w = fitter.weights(None)
    times: dict[bool, list[float]] = {False: [], True: []}
    sums = {}
    for r in range(repeat):
        for use in (False, True) if r % 2 == 0 else (True, False):
            _gram_lines.USE = use
            t0 = time.process_time()
            fitter._solve(th, m, ref, w, residual=False)
            times[use].append(time.process_time() - t0)
    pp = fitter.unpack(th, m, ref)
    n_col = fitter.n_cols(m) + 2 * n_in * m
    parts = _basis.blocks(fitter, n_col)
    G1, P1 = _gram_lines.gram(fitter, pp, ref, True, parts)
    G0 = np.zeros_like(G1)
    P0 = np.zeros_like(P1)
    for sl in parts:
        b = fitter._basis_ek(th, m, ref, True, sl)[0]
        G0 += b.T @ b
        P0 += _basis.rows_t_data(fitter, sl, b)
    d = np.sqrt(np.diag(G0))
    sums["G"] = float(np.max(np.abs(G1 - G0) / np.outer(d, d)))
    sums["P"] = float(np.max(np.abs(P1 - P0) / np.outer(d, np.sqrt(fitter._yss))))
    t0, t1 = statistics.median(times[False]), statistics.median(times[True])
    a0, a1 = _added_times(fitter, case.poles, part, repeat)
    print(
        f"{case.name:<44} {len(parts):>6} {1e3 * t0:9.1f} {1e3 * t1:9.1f} {t0 / t1:6.2f} "
        f"{sums['G']:9.1e} {sums['P']:9.1e} {1e3 * a0:9.2f} {1e3 * a1:9.2f} {a0 / a1:6.2f}"
    )


def _added_times(
    fitter: ModalFitter, poles: np.ndarray, part: np.ndarray, repeat: int
) -> tuple[float, float]:
    """Median CPU time of one evaluation of ``fit_added`` (the last mode added to the
    others, held fixed) by each route."""
    one, lay1, _ = fitter._added_fitter()
    ref1 = np.array([int(np.argmax(np.abs(part[-1])))], np.intp)
    th1 = one.pack(poles[-1:], part[-1:], ref1)
    solvers = {}
    for use in (False, True):
        _gram_lines.USE = use
        fixed = fitter.fixed_part(poles[:-1], part[:-1])
        solvers[use] = _added.added_solver(fitter, one, fixed, ref1, lay1)
    times: dict[bool, list[float]] = {False: [], True: []}
    for r in range(3 * repeat):
        for use in (False, True) if r % 2 == 0 else (True, False):
            _gram_lines.USE = use
            t0 = time.process_time()
            solvers[use](th1)
            times[use].append(time.process_time() - t0)
    return statistics.median(times[False]), statistics.median(times[True])


def _identify(name: str, frf: FRF, band: tuple[float, float]) -> None:
    out = {}
    for use in (False, True):
        _gram_lines.USE = use
        t0 = time.process_time()
        res = identify_modes(frf, band=band, model="complex")
        dt = time.process_time() - t0
        mm = res.models["complex"]
        o = np.argsort(mm.frequency_hz)
        z_std = np.asarray(mm.std["damping_ratio"])[o]
        out[use] = (dt, np.asarray(mm.frequency_hz)[o], np.asarray(mm.damping_ratio)[o], z_std)
    (ta, fa, za, sa), (tb, fb, zb, _) = out[False], out[True]
    same = fa.shape == fb.shape
    df = float(np.max(np.abs(fb / fa - 1))) if same else np.nan
    dz = float(np.max(np.abs(zb / za - 1))) if same else np.nan
    dzs = float(np.max(np.abs(zb - za) / sa)) if same else np.nan
    print(
        f"{name:<44} {fa.size:>3} {ta:8.2f} {tb:8.2f} {ta / tb:6.2f} {df:9.1e} {dz:10.1e} "
        f"{dzs:9.1e}"
    )


def _real_case() -> tuple[str, FRF, tuple[float, float]] | None:
    """ladisk/pyuff's measured accelerances of response node 1 to references 1, 2, 3
    (``/work/shared/real-data``, CATALOGUE.md; roving hammer): 1 output x 3 inputs."""
    d = Path(__file__).resolve().parents[2] / "shared" / "real-data" / "ladisk_pyuff" / "data"
    if not d.is_dir():
        return None
    h = [np.genfromtxt(d / f"meas_point_{i}.txt", dtype=complex)[1:] for i in (1, 2, 3)]
    f = np.arange(1.0, 1001.0)
    frf = FRF(f, np.stack(h)[None], kind="accelerance")
    return "pyuff meas_point_1-3: 1 out x 3 in (real)", frf, (20.0, 950.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--identify", action="store_true")
    a = ap.parse_args()
    pool = limit_blas(1)
    print("one evaluation of _solve and of fit_added (basis, per-line sums), ms")
    head = f"{'case':<44} {'blocks':>6} {'basis':>9} {'lines':>9} {'ratio':>6}"
    print(f"{head} {'dG':>9} {'dP':>9} {'added':>9} {'lines':>9} {'ratio':>6}")
    for spec in CASES:
        _evaluation(spec, a.repeat)
    if a.identify:
        print("identify_modes, s")
        head = f"{'case':<44} {'m':>3} {'basis':>8} {'lines':>8} {'ratio':>6}"
        print(f"{head} {'df/f':>9} {'dzeta/zeta':>10} {'dzeta/std':>9}")
        for spec in CASES:
            case = mimo_case(*spec)
            _identify(case.name, case.frf, case.band)
        real = _real_case()
        if real is not None:
            _identify(*real)
    _gram_lines.USE = True
    del pool


if __name__ == "__main__":
    main()
