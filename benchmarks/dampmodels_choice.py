"""Which damping model? Model choice and standard-error coverage on virtual systems.

For a 3-DOF system whose damping is, in turn, each model of
:data:`tyredamp.dampmodels.MODELS`, ``n_draws`` noisy FRF sets (one input at
mass 1, all three responses, 200 lines from 2 to 40 Hz) at 40 dB (complex
noise of standard deviation 1 % of ``|H|`` per line) are fitted with every
model and ranked by BIC. Printed per truth:

* how often the true model is chosen (``best``) and how often the verdict
  ties it with another (``tied``);
* the coverage of the 95 % intervals ``est +- 1.96 std`` of the true model's
  natural frequencies, damping matrix entries and ``mu`` / ``alpha`` (should
  be 90-97 %);
* the median likelihood-ratio statistic and BIC gap by which each wrong
  model is rejected.

The fits start from the exact modes of the truth converted to a viscous
modal model (the part-1 estimate), as a modal fit would give them.

Last, the virtual tyre with its tread rubber (a fractional Zener law on the
sidewalls and the band), reduced to its three modes between 40 and 110 Hz
(:func:`tyredamp.studies.dampmodels.tyre_band_data`, the demo's data: 16
responses, one drive point, 60 lines, 40 dB): how often the fractional
model (the rubber in this band, to first order in ``(s tau)^alpha``) is
chosen, and the coverage of its natural frequencies, ``C'`` and ``alpha``.

Run: ``python benchmarks/dampmodels_choice.py [n_draws]`` (default 40).
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.linalg as sla

from tyredamp.dampmodels import (
    MODELS,
    DampedSystem,
    DampingLaw,
    Exponential,
    Fractional,
    Hysteretic,
    Viscous,
    compare_models,
    start_from_modes,
)
from tyredamp.studies.dampmodels import TRUE_MODEL, identified_start, tyre_band_data

M = np.diag([1.0, 2.0, 1.5])
K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) * 1e4
C = np.array([[1.5, -0.6, 0.4], [-0.6, 1.2, 0.3], [0.4, 0.3, 0.9]])
TRUTHS: dict[str, DampingLaw] = {
    "proportional": Viscous(2e-4 * K + 0.3 * M),
    "viscous": Viscous(C),
    "hysteretic": Hysteretic.loss_factor(K, 0.04),
    "exponential": Exponential(2 * C, np.array([60.0])),
    "fractional": Fractional(8 * C, 0.5),
}
F = np.linspace(2.0, 40.0, 200)


def _true_params(name: str, law: DampingLaw, phi_fit: np.ndarray) -> dict[str, np.ndarray]:
    w2, phi = sla.eigh(K, M)
    phi = phi * np.sign(np.sum(phi * phi_fit, axis=0))
    mat = {"hysteretic": "D"}.get(name, "C")
    cm = getattr(law, mat)
    cm = cm[0] if cm.ndim == 3 else cm
    cp = phi.T @ cm @ phi
    iu = (np.arange(3), np.arange(3)) if name == "proportional" else np.triu_indices(3)
    out = {"omega": np.sqrt(w2), "C": cp[iu]}
    if name == "exponential":
        out["extra"] = np.log(np.asarray(law.mu))  # type: ignore[attr-defined]
    if name == "fractional":
        out["extra"] = np.array([law.alpha])  # type: ignore[attr-defined]
    return out


def main(n_draws: int) -> None:
    rng = np.random.default_rng(2026)
    print(f"{n_draws} draws per truth at 40 dB, {F.size} lines, models {', '.join(MODELS)}")
    for truth, law in TRUTHS.items():
        t0 = time.perf_counter()
        sys_ = DampedSystem(M, K, law)
        md = sys_.modes()
        start = start_from_modes(md.poles, md.shapes * np.sqrt(2j * md.poles.imag))
        H0 = sys_.receptance(F)[:, [0], :]
        sig = 0.01 * np.abs(H0) / np.sqrt(2)
        best = tied = 0
        inside = total = 0
        lr: dict[str, list[float]] = {m: [] for m in MODELS if m != truth}
        for _ in range(n_draws):
            H = H0 + sig * (rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape))
            cmp = compare_models(F, H, sig, [0], start)
            best += cmp.best == truth
            tied += len(cmp.tied) > 1
            fit = cmp.fits[truth]
            tp = _true_params(truth, law, fit.shapes)
            m, n = 3, 3
            k = tp["C"].size
            est = np.concatenate([fit.params[:m], fit.params[m + n * m : m + n * m + k]])
            std = np.concatenate([fit.std[:m], fit.std[m + n * m : m + n * m + k]])
            ref = np.concatenate([tp["omega"], tp["C"]])
            if "extra" in tp:
                e = np.log(fit.extra["mu"]) if truth == "exponential" else fit.extra["alpha"]
                est, std, ref = (
                    np.append(est, e),
                    np.append(std, fit.std[-1]),
                    np.append(ref, tp["extra"]),
                )
            inside += int(np.sum(np.abs(est - ref) < 1.96 * std))
            total += est.size
            for other in lr:
                lr[other].append(cmp.fits[other].chi2 - fit.chi2)
        dt = time.perf_counter() - t0
        print(
            f"\ntruth {truth:<12} chosen {100 * best / n_draws:5.1f} %"
            f"  tied {100 * tied / n_draws:5.1f} %"
            f"  95 % coverage {100 * inside / total:5.1f} % ({total} intervals)"
            f"  {dt / n_draws:.2f} s/draw"
        )
        for other, vals in lr.items():
            v = np.array(vals)
            dk = (len(cmp.fits[other].params) - len(cmp.fits[truth].params)) * np.log(
                cmp.fits[truth].n_data
            )
            print(
                f"   {other:<12} chi2 - chi2_true: median {np.median(v):10.1f},"
                f" min {v.min():10.1f};"
                f" BIC gap median {np.median(v) + dk:10.1f}"
            )


def tyre(n_draws: int) -> None:
    rng = np.random.default_rng(7)
    band, *_ = tyre_band_data(rng)
    m, n = band.omega.size, band.shapes.shape[0]
    iu = np.triu_indices(m)
    best = inside = total = found = 0
    lr: dict[str, list[float]] = {k: [] for k in MODELS if k != TRUE_MODEL}
    t0 = time.perf_counter()
    for _ in range(n_draws):
        _, f, H, sig = tyre_band_data(rng, band=band)
        # the start from the modes identified in this draw (the demo's chain)
        start = identified_start(band, f, H, sig)
        found += start.omega.size == m
        cmp = compare_models(f, H, sig, [band.drive], start)
        best += cmp.best == TRUE_MODEL
        fit = cmp.fits[TRUE_MODEL]
        sgn = np.sign(np.sum(band.shapes * fit.shapes, axis=0))
        c_true = (band.c_fractional * np.outer(sgn, sgn))[iu]
        k = c_true.size
        est = np.concatenate(
            [fit.params[:m], fit.params[m + n * m : m + n * m + k], [fit.params[-1]]]
        )
        std = np.concatenate([fit.std[:m], fit.std[m + n * m : m + n * m + k], [fit.std[-1]]])
        ref = np.concatenate([band.omega, c_true, [band.alpha]])
        inside += int(np.sum(np.abs(est - ref) < 1.96 * std))
        total += est.size
        for other in lr:
            lr[other].append(cmp.fits[other].chi2 - fit.chi2)
    dt = time.perf_counter() - t0
    print(
        f"\nvirtual tyre, rubber (truth {TRUE_MODEL}, alpha {band.alpha:g}), "
        f"{m} modes {np.round(band.omega / (2 * np.pi), 1)} Hz: chosen "
        f"{100 * best / n_draws:5.1f} %  95 % coverage {100 * inside / total:5.1f} % "
        f"({total} intervals)  {dt / n_draws:.2f} s/draw; all {m} modes identified in "
        f"{found} of {n_draws} draws"
    )
    for other, vals in lr.items():
        v = np.array(vals)
        print(f"   {other:<12} chi2 - chi2_true: median {np.median(v):10.1f}, min {v.min():10.1f}")


if __name__ == "__main__":
    draws = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    main(draws)
    tyre(draws)
