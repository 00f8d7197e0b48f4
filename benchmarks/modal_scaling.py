"""Speed of the modal identification for large tests (outputs x lines x modes).

Run: ``python benchmarks/modal_scaling.py [--outputs 1024] [--lines 4000] [--modes 20]``.
The FRFs are synthesised from a random complex-mode model (spec eq. [10]):
``modes`` modes spread over 10-190 Hz with 0.5-3 % damping, two more just
above the band, one drive point, accelerance, 40 dB complex noise. Prints the
time of each stage and the accuracy of the identified poles.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tyredamp.frf import FRF
from tyredamp.mechanics import modal_sum_receptance, pole_from_frequency_damping
from tyredamp.modal.identify import identify_modes
from tyredamp.modal.poles.lscf import plscf


def synthetic(n_out: int, n_lines: int, n_modes: int, seed: int = 0) -> tuple[FRF, np.ndarray]:
    rng = np.random.default_rng(seed)
    f_n = np.sort(np.concatenate([np.linspace(10, 190, n_modes), [215.0, 240.0]]))
    f_n[:n_modes] *= 1 + 0.01 * rng.uniform(-1, 1, n_modes)
    zeta = rng.uniform(0.005, 0.03, f_n.size)
    p = pole_from_frequency_damping(f_n, zeta)
    psi = (rng.normal(size=(n_out, f_n.size)) + 0.2j * rng.normal(size=(n_out, f_n.size))) * 1e-2
    psi[0] = np.abs(psi[0]) + 0.01  # drive point: every mode excited
    f = np.linspace(200.0 / n_lines, 200.0, n_lines)
    h = modal_sum_receptance(f, p, psi, psi[:1]) * (2j * np.pi * f) ** 2
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    h = h + 0.01 * rms * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(f, h, kind="accelerance", outputs=range(1, n_out + 1), inputs=[1]), p[:n_modes]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--outputs", type=int, default=1024)
    ap.add_argument("--lines", type=int, default=4000)
    ap.add_argument("--modes", type=int, default=20)
    a = ap.parse_args()
    t0 = time.perf_counter()
    frf, p_true = synthetic(a.outputs, a.lines, a.modes)
    print(f"synthesis {time.perf_counter() - t0:.2f} s: {frf}")
    t0 = time.perf_counter()
    ps = plscf(frf.frequency, frf.H, 60)
    print(f"pLSCF orders 1-60 alone: {time.perf_counter() - t0:.2f} s, {ps.poles.size} poles")
    for model in ("complex", "both"):
        t0 = time.perf_counter()
        res = identify_modes(frf, band=(0.0, 200.0), model=model)  # type: ignore[arg-type]
        dt = time.perf_counter() - t0
        m = res.models["complex"]
        near = np.array([np.min(np.abs(m.poles - p) / np.abs(p)) for p in p_true])
        print(
            f"identify_modes(model={model!r}): {dt:.2f} s; {m.n_modes} modes found of "
            f"{p_true.size}; max |dp|/|p| {near.max():.2e}; rel. error "
            f"{m.meta['relative_error']:.4f}"
        )


if __name__ == "__main__":
    main()
