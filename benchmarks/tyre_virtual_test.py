"""The default virtual truck tyre and one virtual modal test: modes, pressure, timing.

Prints

1. the in-band modes of the default tyre (295/80R22.5, 7.5 bar, drive at point
   1, 2 N s/m tip loss, ``nonproportionality`` 1): natural frequency, damping ratio, wave
   number, visibility from the drive point and modal phase collinearity (MPC)
   of the exact complex modes at the 16 points;
2. the pressure dependence at 5, 7.5 and 9 bar (analytic formula and the
   visible modes of the discrete tyre);
3. the wall time of ``run_modal_test`` (default: 16 points, 0-200 Hz chirp,
   1024 Hz, 8 periods of 4 s, 16x oversampling) and the error of its
   noise-free cyclic FRF against the true accelerance;
4. how much better a complex-mode than a real-mode model fits the noisy FRF
   (40 dB SNR) for several ``nonproportionality`` values of the bare ring and
   for the demo tyre (with its cavity), free and loaded at 25 kN. Proxy fit: the true
   poles (visible modes to 300 Hz) held fixed, residues by linear least
   squares plus a constant and a ``1/s^2`` residual per output; real-mode
   residues ``A_jn / (2 i Omega_n)`` with real ``A`` (eq. [3]) against free
   complex residues (eq. [10]). RMSD as eq. [19] on the receptance, 20-200 Hz.

Run: ``python benchmarks/tyre_virtual_test.py`` (set ``OPENBLAS_NUM_THREADS=1``
for single-core timings).
"""

from __future__ import annotations

import time

import numpy as np

from tyredamp.studies.radial import virtual_tyre
from tyredamp.timedata import TimeData
from tyredamp.virtual import RingTyre, RingTyreParameters, analytic_ring_frequencies, run_modal_test


def cyclic_h1(data: TimeData) -> tuple[np.ndarray, np.ndarray]:
    """Single-input H1 over whole periods: (frequency (Hz), H (n_out, n_lines))."""
    acq = data.acquisition
    p = int(acq.period_samples or 0)
    x = data.data[:, acq.settle_samples :]
    x = x[:, : (x.shape[1] // p) * p]
    spec = np.fft.rfft(x.reshape(data.n_channels, -1, p), axis=2)
    f, y = spec[0], spec[1:]
    lo, hi = acq.band_hz if acq.band_hz is not None else (0.0, data.sample_rate / 2)
    k = np.arange(p // 2 + 1) * data.sample_rate / p
    lines = np.flatnonzero((k > lo) & (k <= hi))
    h = np.mean(y * np.conj(f), axis=1) / np.mean(np.abs(f) ** 2, axis=0)
    return lines * data.sample_rate / p, h[:, lines]


def proxy_fit(f: np.ndarray, acc: np.ndarray, poles: np.ndarray, kind: str) -> np.ndarray:
    """Least-squares receptance fit with fixed poles; returns the fitted receptance."""
    s = 2j * np.pi * f
    rec = acc / s**2
    cols = []
    for p in poles:
        if kind == "real":
            w = 1 / (2j * p.imag)
            cols.append(w / (s - p) + np.conj(w) / (s - np.conj(p)))
        else:
            cols.append(1 / (s - p) + 1 / (s - np.conj(p)))
            cols.append(1j / (s - p) - 1j / (s - np.conj(p)))
    cols += [np.ones_like(s), 1 / s**2]
    b = np.array(cols).T
    bri = np.vstack([b.real, b.imag])
    out = np.empty_like(rec)
    for j in range(rec.shape[0]):
        c, *_ = np.linalg.lstsq(bri, np.concatenate([rec[j].real, rec[j].imag]), rcond=None)
        out[j] = b @ c
    return out


def rmsd(a: np.ndarray, b: np.ndarray) -> float:
    """Eq. [19] as printed: (1/m) sqrt(sum |a - b|^2)."""
    return float(np.sqrt(np.sum(np.abs(a - b) ** 2)) / a.size)


def main() -> None:
    tyre = RingTyre()
    tr = tyre.truth()
    print(f"=== default tyre: {tyre!r}")
    print(" f (Hz)  zeta (%)   n  visible   MPC")
    for row in tr.table("all"):
        vis = "yes" if row["visible"] else "no"
        print(
            f"{row['frequency_hz']:7.2f}  {100 * row['damping_ratio']:7.2f}  "
            f"{row['wave_number']:3d}  {vis:>7s}  {row['mpc']:.4f}"
        )

    print("\n=== pressure dependence (visible modes n = 1..6: f Hz / zeta %) ===")
    for bar in (5.0, 7.5, 9.0):
        prm = RingTyreParameters().with_pressure(bar * 1e5)
        an = analytic_ring_frequencies(prm, np.arange(1, 7))
        t = RingTyre(prm).truth()
        vis = t.select("visible")
        cells = " ".join(
            f"{f:6.1f}/{100 * z:3.1f}"
            for f, z in zip(t.frequency_hz[vis], t.damping_ratio[vis], strict=True)
        )
        print(
            f"{bar:4.1f} bar  T0 = {prm.hoop_tension / 1e3:5.1f} kN  k_r = "
            f"{prm.radial_stiffness / 1e6:4.2f} MN/m2  analytic "
            + " ".join(f"{x:6.1f}" for x in an)
            + f"\n          discrete {cells}"
        )

    print("\n=== one virtual modal test (defaults) ===")
    times = []
    for seed in range(3):
        t0 = time.perf_counter()
        vt = run_modal_test(tyre, seed=seed)
        times.append(time.perf_counter() - t0)
    print(f"wall time: {', '.join(f'{t:.2f}' for t in times)} s  ({vt.data!r})")
    clean = run_modal_test(tyre, snr_db=None)
    f, h = cyclic_h1(clean.data)
    true = clean.true_frf(f).H[:, 0, :]
    rel = np.abs(h - true) / np.abs(true)
    print(
        f"noise-free cyclic FRF vs true accelerance: max rel {rel.max():.2e}, "
        f"max abs / max|A| {np.abs(h - true).max() / np.abs(true).max():.2e}"
    )

    print("\n=== real- vs complex-mode fit of the noisy FRF (40 dB, proxy with true poles) ===")
    print("  nu   min MPC   RMSD real   RMSD complex   real/complex   noise RMSD")
    tyres = {f"{nu:5.2f}": RingTyre(nonproportionality=nu) for nu in (0.0, 0.1, 0.25, 0.5, 1.0)}
    tyres["demo (cavity)"] = virtual_tyre(7.5)
    tyres["loaded 25 kN"] = virtual_tyre(7.5, load_n=25e3)
    for name, t in tyres.items():
        vt = run_modal_test(t, seed=1)
        f, h = cyclic_h1(vt.data)
        keep = f >= 20.0
        f, h = f[keep], h[:, keep]
        exact = vt.true_frf(f).H[:, 0, :]
        wide = t.truth((0.0, 300.0))
        poles = wide.poles[wide.select("visible")]
        s2 = (2j * np.pi * f) ** 2
        rec = h / s2
        r_real = rmsd(rec, proxy_fit(f, h, poles, "real"))
        r_cplx = rmsd(rec, proxy_fit(f, h, poles, "complex"))
        vis = vt.truth.select("visible")
        print(
            f"{name:>5s}   {vt.truth.mpc[vis].min():.4f}   {r_real:.3e}   {r_cplx:.3e}"
            f"      {r_real / r_cplx:7.2f}       {rmsd(rec, exact / s2):.3e}"
        )


if __name__ == "__main__":
    main()
