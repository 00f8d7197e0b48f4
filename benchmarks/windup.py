"""The wind-up from the virtual tangential test: accuracy and interval coverage over seeds.

For each noise seed the virtual truck tyre (free, no cavity, default shaker
tip 0.01 kg and 2 N s/m) is tested tangentially (``run_modal_test(...,
direction="tangential")``, chirp 0-100 Hz, 40 dB SNR on every channel, the
settings of ``tests/test_tyremodel_windup.py``), the H1 FRFs are fitted
(``identify_modes``, complex modes, 5-100 Hz) and ``windup_from_modes``
(attachment removed) is compared with the exact rotation mode
(``windup_truth``: bare frequency and damping, belt inertia). Prints per
seed the relative errors and the errors in units of the statistical
standard errors, then the largest relative errors, the share of seeds whose
1-sigma statistical interval covers the truth and the share whose fit split
the rotation into two poles (noted by ``windup_from_modes``).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/windup.py [N_SEEDS] [N_PERIODS]``
(default 20 seeds, 2 periods).
"""

from __future__ import annotations

import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from tyredamp.studies.radial import frf_from_time, modes_from_frf
from tyredamp.tyremodel import windup_from_modes
from tyredamp.virtual import RingTyre, run_modal_test, windup_truth


def main() -> None:
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    n_periods = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    tyre = RingTyre()
    lay = tyre.layout
    wt = windup_truth(tyre)
    truth = {"f": wt.bare_frequency_hz, "z": wt.bare_damping_ratio, "I": wt.inertia}
    print(
        f"truth: FREQ_WINDUP {truth['f']:.5f} Hz, DAMP_WINDUP {truth['z']:.6f}, "
        f"BELT_IYY {truth['I']:.5f} kg m^2 (tested with the tip: {wt.frequency_hz:.5f} Hz, "
        f"zeta {wt.damping_ratio:.6f})"
    )
    print(" seed   rel f      rel zeta   rel I      z_f    z_zeta  z_I    split  s")
    rel: dict[str, list[float]] = {"f": [], "z": [], "I": []}
    cover: dict[str, list[bool]] = {"f": [], "z": [], "I": []}
    zall: dict[str, list[float]] = {"f": [], "z": [], "I": []}
    splits = 0
    for seed in range(1, n_seeds + 1):
        t0 = time.perf_counter()
        test = run_modal_test(
            tyre,
            direction="tangential",
            seed=seed,
            n_periods=n_periods,
            band=(0.0, 100.0),
            oversample=4,
        )
        frf = frf_from_time(test.data, "H1")
        mdl = modes_from_frf(frf, band=(5.0, 100.0), model="complex").models["complex"]
        w = windup_from_modes(
            mdl,
            radius=tyre.params.radius,
            attachment_mass=lay.attachment_mass,
            attachment_damping=lay.attachment_damping,
        )
        got = {"f": w.freq_windup, "z": w.damp_windup, "I": w.belt_iyy}
        std = {"f": w.freq_windup_std, "z": w.damp_windup_std, "I": w.belt_iyy_std}
        split = any("split" in n for n in w.notes)
        splits += split
        zs = {}
        for k in got:
            rel[k].append(got[k] / truth[k] - 1)
            zs[k] = (got[k] - truth[k]) / std[k] if std[k] > 0 else np.nan
            cover[k].append(bool(abs(zs[k]) <= 1))
            zall[k].append(zs[k])
        print(
            f" {seed:4d} {rel['f'][-1]:+.2e}  {rel['z'][-1]:+.2e}  {rel['I'][-1]:+.2e}  "
            f"{zs['f']:+6.2f} {zs['z']:+6.2f} {zs['I']:+6.2f}  {'yes' if split else 'no':5s}"
            f"  {time.perf_counter() - t0:.1f}"
        )
    for k, name in (("f", "FREQ_WINDUP"), ("z", "DAMP_WINDUP"), ("I", "BELT_IYY")):
        r = np.abs(rel[k])
        print(
            f"{name:12s} largest |relative error| {r.max():.2e}, median {np.median(r):.2e}; "
            f"1-sigma statistical interval covers the truth in {100 * np.mean(cover[k]):.0f} %, "
            f"rms z {np.sqrt(np.nanmean(np.square(zall[k]))):.2f}"
        )
    print(f"fits that split the rotation into two poles: {splits} of {n_seeds}")


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
