"""Modal identification on the virtual truck tyre: accuracy, real vs complex, honesty of errors.

Run: ``python benchmarks/modal_tyre.py [--seeds 50]``. Prints tables; takes a
few minutes on two cores. FRFs are the exact accelerances of the tyre at its
16 points plus complex Gaussian noise of ``rms(FRF) * 10^(-SNR/20)`` per FRF
(independent per line), 0.25 Hz lines in 0.25-200 Hz; nothing is given to
the identification but the FRFs and the band.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tyredamp.frf import FRF
from tyredamp.modal.identify import identify_modes
from tyredamp.modal.statistics.indicators import mac
from tyredamp.virtual import Imperfection, MeasurementLayout, RingTyre

F = np.arange(0.25, 200.01, 0.25)


def exact_frf(tyre: RingTyre) -> FRF:
    return tyre.system.frf(
        F,
        kind="accelerance",
        outputs=list(tyre.point_dofs),
        inputs=list(tyre.drive_dofs),
        output_channels=tyre.output_channels,
        input_channels=tyre.input_channels,
    )


def noisy(frf: FRF, seed: int, snr_db: float = 40.0) -> FRF:
    rng = np.random.default_rng(seed)
    h = frf.H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    e = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    return frf.with_H(h + 10 ** (-snr_db / 20) * rms * e / np.sqrt(2))


def match(f_id: np.ndarray, f_true: np.ndarray) -> np.ndarray:
    """Index of the nearest identified mode for every true mode."""
    return np.array([int(np.argmin(np.abs(f_id - f))) for f in f_true])


def accuracy(label: str, tyre: RingTyre, seed: int = 1) -> None:
    tr = tyre.truth((0.0, 200.0))
    vis = tr.select("visible")
    t0 = time.perf_counter()
    res = identify_modes(noisy(exact_frf(tyre), seed), band=(0.0, 200.0))
    dt = time.perf_counter() - t0
    print(f"\n== {label}: {vis.size} visible modes in 0-200 Hz, identify {dt:.2f} s")
    for kind, m in res.models.items():
        idx = match(m.frequency_hz, tr.frequency_hz[vis])
        ef = np.abs(m.frequency_hz[idx] / tr.frequency_hz[vis] - 1)
        ez = np.abs(m.damping_ratio[idx] / tr.damping_ratio[vis] - 1)
        mm = np.diag(mac(m.psi_out[:, idx], tr.psi_points[:, vis]))
        print(
            f"  {kind:8s} found {m.n_modes:2d} (unique matches {np.unique(idx).size:2d}), "
            f"max |df/f| {ef.max():.2e}, max |dzeta/zeta| {ez.max():.2e}, "
            f"min MAC {mm.min():.6f}, RMSD {m.meta['rmsd']:.3e}, "
            f"rel. error {m.meta['relative_error']:.4f}, residual modes "
            f"{m.meta['n_residual_modes']}"
        )
    if len(res.models) == 2:
        r = res.models["real"].meta["rmsd"] / res.models["complex"].meta["rmsd"]
        print(f"  RMSD real / complex = {r:.3f}")


def virtual_test() -> None:
    """The full chain: simulated chirp test (time data, 40 dB on every channel), H1 FRFs."""
    from tyredamp.signal.estimators import estimate_frf
    from tyredamp.virtual import run_modal_test

    t0 = time.perf_counter()
    vt = run_modal_test(seed=0)
    frf = estimate_frf(vt.data, band=(0.0, 200.0))
    t1 = time.perf_counter()
    res = identify_modes(frf, band=(0.0, 200.0))
    t2 = time.perf_counter()
    tr = vt.truth
    vis = tr.select("visible")
    print(
        f"\n== virtual test from time data (simulation + H1 {t1 - t0:.1f} s, identify "
        f"{t2 - t1:.2f} s): {frf}"
    )
    for kind, m in res.models.items():
        idx = match(m.frequency_hz, tr.frequency_hz[vis])
        ef = np.abs(m.frequency_hz[idx] / tr.frequency_hz[vis] - 1)
        ez = np.abs(m.damping_ratio[idx] / tr.damping_ratio[vis] - 1)
        mm = np.diag(mac(m.psi_out[:, idx], tr.psi_points[:, vis]))
        print(
            f"  {kind:8s} found {m.n_modes:2d}, max |df/f| {ef.max():.2e}, max |dzeta/zeta| "
            f"{ez.max():.2e}, min MAC {mm.min():.6f}, RMSD {m.meta['rmsd']:.3e}, "
            f"rel. error {m.meta['relative_error']:.4f}"
        )
    r = res.models["real"].meta["rmsd"] / res.models["complex"].meta["rmsd"]
    print(f"  RMSD real / complex = {r:.3f}")


def honesty(n_seeds: int) -> None:
    tyre = RingTyre()
    tr = tyre.truth((0.0, 200.0))
    vis = tr.select("visible")
    exact = exact_frf(tyre)
    fs, zs, ps, sf, sz, sp = [], [], [], [], [], []
    t0 = time.perf_counter()
    for seed in range(n_seeds):
        m = identify_modes(noisy(exact, 1000 + seed), band=(0.0, 200.0), model="complex")
        m = m.models["complex"]
        if m.n_modes != vis.size:
            print(f"  seed {seed}: {m.n_modes} modes found, skipped")
            continue
        # fix the arbitrary sign of each shape against the truth
        psi = m.psi_out * np.sign(
            np.real(np.sum(np.conj(tr.psi_points[:, vis]) * m.psi_out, axis=0))
        )
        fs.append(m.frequency_hz)
        zs.append(m.damping_ratio)
        ps.append(psi)
        sf.append(m.std["frequency_hz"])
        sz.append(m.std["damping_ratio"])
        sp.append(m.std["psi_out"])
    dt = time.perf_counter() - t0
    fs_a, zs_a, ps_a = np.array(fs), np.array(zs), np.array(ps)
    print(f"\n== honesty of the standard errors, complex model, {len(fs)} seeds ({dt:.1f} s)")
    print("  ratio = empirical spread over seeds / mean reported standard error (ideal 1)")
    print(
        f"  {'mode':>4} {'f [Hz]':>9} {'ratio f':>8} {'ratio zeta':>10} "
        f"{'shape ratio (median, range)':>28}"
    )
    spread_p = np.sqrt(np.mean(np.abs(ps_a - ps_a.mean(axis=0)) ** 2, axis=0))
    rp = spread_p / np.mean(sp, axis=0)
    for n in range(fs_a.shape[1]):
        rf = fs_a[:, n].std(ddof=1) / np.mean(np.array(sf)[:, n])
        rz = zs_a[:, n].std(ddof=1) / np.mean(np.array(sz)[:, n])
        print(
            f"  {n + 1:>4} {fs_a[:, n].mean():>9.3f} {rf:>8.3f} {rz:>10.3f} "
            f"{np.median(rp[:, n]):>10.3f} ({rp[:, n].min():.2f}-{rp[:, n].max():.2f})"
        )
    bias_f = np.abs(fs_a.mean(axis=0) / tr.frequency_hz[vis] - 1)
    print(f"  max |mean f / true - 1| = {bias_f.max():.2e}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=50)
    args = ap.parse_args()
    accuracy("default tyre (nonproportionality 0.5), 1 drive point, 40 dB", RingTyre())
    accuracy("proportional damping (nonproportionality 0)", RingTyre(nonproportionality=0.0))
    imp = (Imperfection(angle_deg=30.0, mass=1.0),)
    accuracy(
        "imperfect tyre (1 kg at 30 deg), drive points 1 and 4",
        RingTyre(layout=MeasurementLayout(drive_points=(1, 4)), imperfections=imp),
    )
    virtual_test()
    honesty(args.seeds)


if __name__ == "__main__":
    main()
