"""How often the fit verdict calls a correct model FAILED, and how small a misfit it catches.

Run: ``python benchmarks/verdict_calibration.py [--trials N]``.

A two-mode FRF (30 and 80 Hz, 2 % damping, 400 lines 5-100 Hz) is measured
as an analyser does it: ``n_d`` averages of a fixed periodic force (or of a
new random force each) with Gaussian noise on the response (SNR 300 on the
peak), H1 and coherence from the averages. The verdict
(:func:`tyredamp.studies.verdicts.modal_fit_verdict`, test level
``alpha = 1e-3``) judges

* the true model: the share of FAILED verdicts is the false-alarm rate
  (should be about ``alpha``);
* the model with the second natural frequency shifted by ``df/f``: the share
  of FAILED verdicts is the power to see that misfit.

Prints one row per force and number of averages.
"""

from __future__ import annotations

import argparse

import numpy as np

from tyredamp import Channel
from tyredamp.frf import FRF
from tyredamp.modal.model import ModalModel
from tyredamp.studies.verdicts import modal_fit_verdict

F = np.linspace(5.0, 100.0, 400)


def two_modes(f2: float = 80.0) -> ModalModel:
    """Two modes (30 Hz and ``f2``, 2 % damping), one output, one input."""
    wn = 2 * np.pi * np.array([30.0, f2])
    z = np.array([0.02, 0.02])
    poles = -z * wn + 1j * wn * np.sqrt(1 - z**2)
    psi = (1.0 / np.sqrt(2j * poles.imag))[None, :]
    return ModalModel(poles, psi, psi.copy(), meta={"band_hz": [5.0, 100.0]})


def measured(
    model: ModalModel, n_avg: int, snr: float, seed: int, random_force: bool = False
) -> FRF:
    """H1 and coherence from ``n_avg`` averages, noise on the response.

    A fixed periodic force repeated in every average, or a new random force
    in every average.
    """
    rng = np.random.default_rng(seed)
    h = model.frf(F, "receptance").H[0, 0]
    sd = np.abs(h).max() / snr
    shape = (n_avg, F.size)
    if random_force:
        force = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / np.sqrt(2)
    else:
        force = np.tile(np.exp(1j * rng.uniform(0, 2 * np.pi, F.size)), (n_avg, 1))
    noise = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    x = h * force + sd * noise / np.sqrt(2)
    gff = np.sum(np.abs(force) ** 2, axis=0)
    gxf = np.sum(x * np.conj(force), axis=0)
    gxx = np.sum(np.abs(x) ** 2, axis=0)
    coh = np.abs(gxf) ** 2 / (gff * gxx)
    ch = [Channel(1, 3)]
    meta = {"n_averages": n_avg, "method": "welch" if random_force else "cyclic"}
    return FRF(F, (gxf / gff)[None, None, :], "receptance", ch, ch, coh[None, :], meta)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=300)
    args = ap.parse_args()
    true = two_modes()
    shifts = (1e-3, 3e-3, 1e-2)
    print(
        f"{'force':>8} {'n_d':>4} {'mean q':>8} {'false alarms':>13} "
        + " ".join(f"{'FAIL at df/f=' + format(s, 'g'):>17}" for s in shifts)
    )
    for random_force in (False, True):
        for nd in (2, 4, 8, 16):
            q, fa = [], 0
            hits = dict.fromkeys(shifts, 0)
            for seed in range(args.trials):
                meas = measured(true, nd, 300.0, seed, random_force)
                v = modal_fit_verdict(true, meas)
                assert v.test is not None
                q.append(v.test.ratio)
                fa += v.status == "failed"
                for s in shifts:
                    wrong = two_modes(80.0 * (1 + s))
                    hits[s] += modal_fit_verdict(wrong, meas).status == "failed"
            n = args.trials
            print(
                f"{'random' if random_force else 'periodic':>8} {nd:>4} {np.mean(q):>8.3f} "
                f"{fa / n:>13.4f} " + " ".join(f"{hits[s] / n:>17.3f}" for s in shifts)
            )


if __name__ == "__main__":
    main()
