"""Damping identification on the virtual truck tyre: exact modes and the whole chain.

Part 1 (exact modes): the visible exact complex modes of the ring tyre
(``TyreTruth.modal_model()``) for several values of the non-proportionality
knob; relative Frobenius error of ``C'`` (raw and symmetric part) against the
truth ``C'`` of the same modes (eq. [14]), and of the physical matrix against
the truth reduced to the 16 points (``TyreTruth.reduced_damping``).

Part 2 (whole chain): virtual modal test (periodic chirp, 16 accelerometers,
one radial shaker, noise at the given SNR) -> H1 FRFs -> automatic complex-mode
fit (pLSCF + LSFD + refinement) -> damping. Same error measures, with the
identified modes matched to the truth by frequency, plus the Monte Carlo
standard errors against the actual error.

Run: ``python benchmarks/damping_tyre.py [n_seeds] [snr_db ...]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from tyredamp.damping import DampingModel, identify_damping
from tyredamp.signal.estimators import estimate_frf
from tyredamp.virtual import RingTyre, TyreTruth, run_modal_test

METHODS = ("first", "improved", "refined")


def truth_block(truth: TyreTruth, dm: DampingModel) -> tuple[np.ndarray, np.ndarray]:
    """Truth C' and phi at the points for the identified modes (matched by frequency), signed."""
    cand = truth.select("visible")
    idx = np.array([cand[np.argmin(np.abs(truth.frequency_hz[cand] - f))] for f in dm.frequency_hz])
    phi = truth.phi_points[:, idx]
    sign = np.sign(np.sum(dm.basis * phi, axis=0))
    return truth.modal_damping[np.ix_(idx, idx)] * np.outer(sign, sign), phi * sign


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def reduced(truth: TyreTruth, ct: np.ndarray, phi: np.ndarray) -> np.ndarray:
    pu = np.linalg.pinv(phi)
    return pu.T @ ct @ pu


def part1() -> None:
    print("Part 1: exact visible modes (6 modes, n = 1..6, at 16 points)")
    print(f"{'nu':>5} {'method':>9} | {'C_raw':>7} {'C_sym':>7} {'asym':>7} | {'phys_sym':>8}")
    for nu in (0.25, 0.5, 1.0):
        truth = RingTyre(nonproportionality=nu).truth()
        for method in METHODS:
            dm = identify_damping(truth.modal_model(), method, n_samples=0)  # type: ignore[arg-type]
            ct, phi = truth_block(truth, dm)
            print(
                f"{nu:5.2f} {method:>9} | {rel(dm.modal, ct):7.3f} "
                f"{rel(dm.modal_symmetric, ct):7.3f} {dm.diagnostics.symmetry_modal:7.3f} | "
                f"{rel(dm.physical_symmetric, reduced(truth, ct, phi)):8.3f}"
            )


def part2(n_seeds: int, snrs: list[float]) -> None:
    from tyredamp.modal.identify import identify_modes

    print("\nPart 2: whole chain (virtual test -> H1 FRF -> complex-mode fit -> damping)")
    print(
        f"{'snr':>4} {'seed':>4} {'modes':>5} {'method':>9} | {'C_raw':>7} {'C_sym':>7} "
        f"{'asym':>6} {'phys_sym':>8} | {'err/std':>7} {'time':>6}"
    )
    last = None
    for snr in snrs:
        for seed in range(n_seeds):
            t0 = time.perf_counter()
            vt = run_modal_test(seed=seed, snr_db=snr)
            frf = estimate_frf(vt.data, "H1")
            model = identify_modes(frf, model="complex").models["complex"]
            for method in METHODS:
                dm = identify_damping(model, method, n_samples=200, seed=0)  # type: ignore[arg-type]
                ct, phi = truth_block(vt.truth, dm)
                off = ~np.eye(dm.n_modes, dtype=bool)
                z = np.abs(dm.modal - ct)[off] / dm.std["modal"][off] if dm.std else np.nan
                print(
                    f"{snr:4.0f} {seed:4d} {dm.n_modes:5d} {method:>9} | "
                    f"{rel(dm.modal, ct):7.3f} {rel(dm.modal_symmetric, ct):7.3f} "
                    f"{dm.diagnostics.symmetry_modal:6.3f} "
                    f"{rel(dm.physical_symmetric, reduced(vt.truth, ct, phi)):8.3f} | "
                    f"{np.median(z):7.2f} {time.perf_counter() - t0:6.1f}"
                )
                last = (dm, ct)
    if last is not None:
        dm, ct = last
        np.set_printoptions(precision=2, suppress=True, linewidth=160)
        print("\nlast run: truth C' (1/s)\n", ct)
        print("identified C'\n", dm.modal)
        print("Monte Carlo standard error\n", dm.std.get("modal"))
        print("findings:")
        for f in dm.findings:
            print(" -", f)


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    snr_list = [float(x) for x in sys.argv[2:]] or [40.0]
    t = time.perf_counter()
    part1()
    part2(n, snr_list)
    print(f"\n({time.perf_counter() - t:.1f} s)")
