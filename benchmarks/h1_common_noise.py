"""H1 noise with input (force) noise: common to the outputs, along the response.

Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/h1_common_noise.py [--draws 3]

The virtual tyre at 9 bar (campaign tyre T1, 20 kN, drives at points 1 and
5, 4 periods, 40 dB on every channel) is simulated without noise, then noise
of that level is added (a) to every channel, (b) to the accelerations only;
H1 is estimated from each. With the error ``E = H1 - H1_clean`` and the
H1's own variance ``V`` (the separable weights the identification uses)
the script prints per draw:

* ``in/off``: the median over the lines of the noise variance per complex
  direction in the span of ``H(f)`` over that off it (17-line windows; 1 for
  independent outputs, :mod:`tyredamp.modal.search.span_noise`);
* ``T max``: the largest statistic of one mode fitted to the noise alone
  (pole on a grid of 0.05 Hz and damping ratios 0.15-2.5 %, rank-one
  residue, separable weights) -- what a noise mode reaches;
* for (a) also the base threshold of the mode test and the raised threshold
  at that pole (:func:`tyredamp.modal.statistics.stats.span_threshold`, from ``E``).
"""

from __future__ import annotations

import argparse

import numpy as np


def _tmax(E: np.ndarray, V: np.ndarray, f: np.ndarray) -> tuple[float, complex]:
    so2 = np.mean(V, axis=(1, 2))
    g = np.mean(V / so2[:, None, None], axis=(0, 1))
    g /= g.mean()
    ew = E / np.sqrt(so2)[:, None, None] / np.sqrt(g)
    s2 = np.mean(np.abs(ew) ** 2)
    w = 2 * np.pi * f
    best = (0.0, 0j)
    for z in (0.0015, 0.003, 0.006, 0.012, 0.025):
        for fc in np.arange(f[0] + 1, f[-1] - 1, 0.05):
            p = complex(-z * 2 * np.pi * fc, 2 * np.pi * fc * np.sqrt(1 - z * z))
            b = 1 / (1j * w - p) / np.sqrt(g)
            m = (ew @ b.conj()) / np.sqrt(np.sum(np.abs(b) ** 2))
            t = 2 * np.linalg.svd(m, compute_uv=False)[0] ** 2 / s2
            if t > best[0]:
                best = (float(t), p)
    return best


def main() -> None:
    from tyredamp.campaign.virtual import campaign_tyre, tyre_parameters
    from tyredamp.modal.fit.fit import ModalFitter
    from tyredamp.modal.problem.problem import build_problem
    from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold, span_threshold
    from tyredamp.signal import estimate_frf
    from tyredamp.timedata import TimeData
    from tyredamp.virtual import run_modal_test

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=3)
    args = ap.parse_args()
    tyre = campaign_tyre(tyre_parameters(0, 0), 9.0, 20000.0, (1, 5))
    clean = run_modal_test(tyre, n_periods=4, seed=3, snr_db=None).data
    h0 = estimate_frf(clean, "H1")
    sel = (h0.frequency >= 30) & (h0.frequency <= 180)
    f = h0.frequency[sel]
    rms = np.sqrt(np.mean(clean.data**2, axis=1))
    std = rms * 10 ** (-40 / 20)
    n_force = 2
    rng = np.random.default_rng(0)
    k = mode_parameters(16, 2, "complex")
    print("draw  noise on     in/off   T max   at (Hz)  base thr  raised thr")
    for d in range(args.draws):
        noise = std[:, None] * rng.standard_normal(clean.data.shape)
        only = np.r_[np.zeros(n_force), np.ones(clean.data.shape[0] - n_force)][:, None]
        for name, nz in (("every channel", noise), ("outputs only", noise * only)):
            td = TimeData(
                clean.data + nz,
                clean.sample_rate,
                clean.channels,
                clean.quantities,
                clean.meta,
                clean.acquisition,
            )
            h1 = estimate_frf(td, "H1")
            E, V = h1.H[:, :, sel] - h0.H[:, :, sel], h1.variance[:, :, sel]
            so2 = np.mean(V, axis=(1, 2))
            g = np.mean(V / so2[:, None, None], axis=(0, 1))
            lw = 1 / np.sqrt(g / g.mean())
            fit = ModalFitter(f, h1.H[:, :, sel], 2, "complex", [], line_weights=lw)
            # the error as the residual (of the true model), in units of a real row
            s2 = np.mean(np.abs(E * lw) ** 2, axis=(1, 2)) / 2
            sp = _span_of_error(fit, E, lw, s2)
            lam = [sp.at(complex(-1.0, 2 * np.pi * x)) for x in f[::4]]
            ratio = float(np.median([a / b for a, b, _ in lam]))
            t, p = _tmax(E, V, f)
            thr = mode_threshold(k, f.size, 0.01, build_problem(h1, (30.0, 180.0)).weight_dof)
            line = f"{d:>4}  {name:<13} {ratio:>6.2f} {t:>7.1f} {p.imag / 2 / np.pi:>9.2f}"
            if name == "every channel":
                up = span_threshold(thr, k, 2, f.size, sp.at(p))
                line += f" {thr:>9.1f} {up:>11.1f}"
            print(line, flush=True)


def _span_of_error(fit: object, E: np.ndarray, lw: np.ndarray, s2: np.ndarray) -> object:
    """:func:`~tyredamp.modal.search.span_noise.span_noise` with the error ``E`` as the
    residual (the span of the noisy data, as the identification sees it)."""
    from tyredamp.modal.search.span_noise import SpanNoise

    H = fit.H  # type: ignore[attr-defined]
    n_out, n_in = H.shape[:2]
    isd = 1 / np.sqrt(s2)
    u = (H * lw * isd[:, None, None]).transpose(2, 0, 1)
    e = (E * lw * isd[:, None, None]).transpose(2, 0, 1)
    q = np.linalg.qr(u)[0]
    p = np.conj(q).transpose(0, 2, 1) @ e
    e_in = np.sum(np.abs(p) ** 2, axis=(1, 2))
    e_all = np.sum(np.abs(e) ** 2, axis=(1, 2))
    a = e_in / (2 * n_in**2)
    b = (e_all - e_in) / (2 * (n_out - n_in) * n_in)
    z = np.zeros(1)
    return SpanNoise(fit.f, np.r_[z, np.cumsum(a)], np.r_[z, np.cumsum(b)], n_in, n_out)  # type: ignore[attr-defined]


if __name__ == "__main__":
    main()
