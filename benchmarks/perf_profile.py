"""Where the time of :func:`~tyredamp.modal.identify_modes` goes, stage by stage.

Run: ``python benchmarks/perf_profile.py [--quick] [--blas-threads 1] [--json PATH]
[--set tyre|random] [--lines 5e4]``.

Profiles one call (``cProfile``, complex model, default options) on the
virtual tyre (16 outputs, 799 lines), the synthetic structure with 128
outputs and with 1024 outputs (4000 lines, 20 modes; 1024 not in
``--quick``) and prints the cumulative time of the main stages as a share of
the call: pLSCF, stabilisation and clustering, output compression, the
search for out-of-band residual modes, the checked fits of the final models,
and, across all fits, the projection (``ModalFitter._solve``; inside it the
Cholesky route from the Gram blocks ``_vp_solve`` and the QR fallback
``_orth`` for ill-conditioned bases), the normal equations (``_normal``), the
basis with its distinct derivative columns (``_basis_ek``) and the result
assembly (``_result``, standard errors and contributions included). Stages nest
(a fit inside the search also counts in ``_solve``), so the rows do not
add up to 100 %.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time
from pathlib import Path
from typing import Any

from perf_common import (
    RESULTS_DIR,
    limit_blas,
    machine_info,
    mimo_case,
    print_table,
    synthetic_case,
    tyre_case,
    write_json,
)

from tyredamp.modal import identify_modes

#: (label, file suffix, function name)
STAGES = (
    ("pLSCF (plscf)", "lscf.py", "plscf"),
    ("  companion eigenvalues", "lscf.py", "_companion_eigvals"),
    ("stability + clustering", "selection.py", "stability_flags|cluster_poles"),
    ("output compression", "compress.py", "_compress"),
    ("out-of-band residual modes (search_helpers)", "out_of_band.py", "search_helpers"),
    ("  scan for their starts (_scan_starts)", "out_of_band.py", "_scan_starts"),
    ("mode test (reject_by_test)", "search.py", "reject_by_test"),
    ("residual search (residual_search)", "search.py", "residual_search"),
    ("  residual peaks", "residual_peaks.py", "residual_peaks"),
    ("  coherent scan", "residual_peaks.py", "coherent_scan"),
    ("  trials (_trial)", "trials.py", "_trial"),
    ("  trial evaluations, one block (solve_one)", "_added.py", "solve_one"),
    ("  trial evaluations, blocks (solve_blocks)", "_added.py", "solve_blocks"),
    ("  trial evaluations, Q_r kept (solve_all)", "_added.py", "solve_all"),
    ("  joint refits (_joint)", "joint.py", "_joint"),
    ("final fit and drop rule (final_complex)", "final.py", "final_complex"),
    ("  maximum-likelihood stage", "final.py", "maximum_likelihood"),
    ("all fits (ModalFitter.fit)", "fit.py", "fit"),
    ("  trial fits (fit_added)", "fit.py", "fit_added"),
    ("  Levenberg-Marquardt (all refinements)", "_linalg.py", "_levenberg_marquardt"),
    ("  basis and derivative columns (basis_ek)", "_basis.py", "basis_ek"),
    ("  long records: pseudo-line sums (_sums, scan_sums)", "_pseudo.py", "_sums|scan_sums"),
    ("  long records: fixed parts' pseudo-lines (fixed_far)", "_pseudo.py", "fixed_far"),
    ("  result assembly (_results.assemble)", "_results.py", "assemble"),
    ("model object and indicators (to_model)", "assemble.py", "to_model"),
)


def check_stages() -> None:
    """Every stage's functions are defined in its file (a renamed or moved function
    would otherwise show as a stage that takes no time)."""
    import tyredamp.modal

    root = Path(tyredamp.modal.__file__).parent
    for label, file, funcs in STAGES:
        # the stages' modules sit in the subpackages of tyredamp.modal (poles/, fit/, ...)
        found = sorted(root.rglob(file))
        if len(found) != 1:
            raise SystemExit(f"perf_profile: stage {label.strip()!r}: {len(found)} files {file}")
        text = found[0].read_text(encoding="utf-8")
        for fn in funcs.split("|"):
            if f"def {fn}(" not in text:
                raise SystemExit(f"perf_profile: stage {label.strip()!r}: no {fn}() in {file}")


def profile_case(name: str, case: Any, order: int | None = None) -> dict[str, Any]:
    identify_modes(case.frf, band=case.band, model="complex", max_order=order)  # warm-up
    pr = cProfile.Profile()
    t0 = time.perf_counter()
    pr.enable()
    identify_modes(case.frf, band=case.band, model="complex", max_order=order)
    pr.disable()
    total = time.perf_counter() - t0
    stats = pstats.Stats(pr).stats  # type: ignore[attr-defined]
    out: dict[str, Any] = {"case": name, "total_s": total, "stages": {}}
    for label, file, funcs in STAGES:
        names = set(funcs.split("|"))
        ct = 0.0
        calls = 0
        for (fname, _line, func), (_cc, nc, _tt, cum, _callers) in stats.items():
            if func in names and fname.endswith(file):
                ct += cum
                calls += nc
        out["stages"][label] = {"s": ct, "calls": calls, "share": ct / total}
    return out


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="without the 1024-output case")
    ap.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument("--json", default=str(RESULTS_DIR / "profile.json"), help="output JSON")
    ap.add_argument(
        "--set",
        choices=("tyre", "random"),
        default="tyre",
        help="the tyre and synthetic cases (default), or the random MIMO cases of "
        "perf_compare (16x2x3000 35 dB, 32x2x4000 50 dB, order 80) and a long record "
        "(4 outputs, --lines lines, order 40)",
    )
    ap.add_argument("--lines", type=float, default=5e4, help="lines of the long record")
    a = ap.parse_args(argv)
    check_stages()
    pool = limit_blas(a.blas_threads)
    t_start = time.perf_counter()
    cases: list[tuple[str, Any, int | None]] = [
        ("tyre 16x799x6", lambda: tyre_case(40.0, seed=1), None),
        ("synthetic 128x4000x20", lambda: synthetic_case(128, 4000, 20, seed=0), None),
    ]
    if not a.quick:
        cases.append(
            ("synthetic 1024x4000x20", lambda: synthetic_case(1024, 4000, 20, seed=0), None)
        )
    if a.set == "random":
        n = int(a.lines)
        cases = [
            ("16x2x3000 35 dB", lambda: mimo_case(16, 2, 3000, 20, 35.0), 80),
            ("32x2x4000 50 dB", lambda: mimo_case(32, 2, 4000, 20, 50.0), 80),
            (f"4x1x{n} 40 dB", lambda: mimo_case(4, 1, n, 10, 40.0), 40),
        ]
    results = [profile_case(name, make(), order) for name, make, order in cases]
    rows = []
    for label, _f, _n in STAGES:
        row: list[Any] = [label]
        for r in results:
            st = r["stages"][label]
            row.append(f"{st['s']:.2f} s {100 * st['share']:3.0f} % ({st['calls']})")
        rows.append(row)
    rows.append(["total identify_modes", *(f"{r['total_s']:.2f} s" for r in results)])
    print_table(
        ["stage (cumulative, calls)", *(r["case"] for r in results)],
        rows,
        title=f"\n== identify_modes time by stage (cProfile, BLAS threads {a.blas_threads})",
    )
    doc = {
        "benchmark": "perf_profile",
        "quick": a.quick,
        "machine": machine_info(a.blas_threads),
        "elapsed_s": time.perf_counter() - t_start,
        "cases": results,
    }
    print(f"wrote {write_json(doc, a.json)} ({doc['elapsed_s']:.0f} s)")
    del pool
    return doc


if __name__ == "__main__":
    main()
