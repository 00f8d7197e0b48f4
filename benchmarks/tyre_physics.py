"""The physical virtual tyre: damping sources, hub stiffness, load, cavity and the RMSD ratio.

Prints

1. the off-diagonal share of the in-band modal damping ``C'`` (radial spec
   eq. [14]) and its split by physical source (``damping_decomposition``) for
   the bare ring, the demo tyre (free, cavity), the same with a splice, and
   loaded on a road (25 kN), with the old 350 N s/m drive-point damper for
   comparison;
2. the static hub stiffness (rigid hub, ring condensed) at 2.76 / 4.14 /
   6.5 / 7.5 / 9 bar and 20 / 25 / 30 kN beside the Goodyear 335/65R22.5
   .tir values (Project Chrono ``feda``: 406.5 / 565.2 / 644.5 / 848.6 kN/m
   at 2.7 / 4.14 / 4.8 / 6.5 bar), with the patch length;
3. the undamped in-band frequencies free and loaded (25 kN) and the loaded
   n = 1 vertical mode against the rigid-ring estimate;
4. the n = 1 cavity pair free and loaded and its split against the
   first-order estimate ``2 dV / V``;
5. the RMSD ratio (real / complex fit) of the demo's 7.5 bar test at SNR
   20, 30, 40 dB (``run_pressure``, 8 periods, seeds 1-3).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/tyre_physics.py [--quick]``
(``--quick``: no RMSD runs).
"""

from __future__ import annotations

import math
import sys

import numpy as np
from threadpoolctl import threadpool_limits

from tyredamp.studies.radial import run_pressure, virtual_tyre
from tyredamp.virtual import (
    Cavity,
    ContactPatch,
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    damping_decomposition,
)
from tyredamp.virtual.cavity import loaded_split_estimate
from tyredamp.virtual.contact import patch_intrusion

BAR = 1e5


def sources() -> None:
    print("1. non-proportional damping by source (share of C'_off; 'alone': norm ratio)")
    cases = {
        "bare ring, 30 N s/m tip": RingTyre(),
        "bare ring, 350 N s/m tip (old)": RingTyre(
            layout=MeasurementLayout(attachment_damping=350.0)
        ),
        "demo: free + cavity": virtual_tyre(7.5),
        "free + cavity + splice": virtual_tyre(7.5, splice=True),
        "loaded 25 kN + cavity": virtual_tyre(7.5, load_n=25e3),
        "loaded 25 kN + cavity + splice": virtual_tyre(7.5, load_n=25e3, splice=True),
    }
    for name, tyre in cases.items():
        print(f"-- {name}")
        print(damping_decomposition(tyre).format())


def hub() -> None:
    print("\n2. hub stiffness (MN/m) and patch length (mm); .tir 335/65R22.5: 0.41/0.57/0.64/0.85")
    loads = (20e3, 25e3, 30e3)
    print("  bar " + " ".join(f"{f / 1e3:8.0f} kN       " for f in loads))
    for pb in (2.76, 4.14, 6.5, 7.5, 9.0):
        cells = []
        for f in loads:
            st = RingTyre(RingTyreParameters(pressure=pb * BAR), contact=ContactPatch(f)).patch
            assert st is not None
            cells.append(f"{st.hub_stiffness / 1e6:6.3f} {2e3 * st.half_length:5.0f} mm  ")
        print(f"{pb:5.2f} " + " ".join(cells))


def load_effect() -> None:
    print("\n3. undamped in-band frequencies (Hz), free and loaded 25 kN (no cavity, bare layout)")
    bare = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    p = RingTyreParameters()
    free = RingTyre(p, bare)
    loaded = RingTyre(p, bare, contact=ContactPatch(25e3))
    ff = free.physical_system.undamped_modes().frequency_hz
    fl = loaded.physical_system.undamped_modes().frequency_hz
    print("  free  ", np.round(ff[ff < 200], 1))
    print("  loaded", np.round(fl[fl < 200], 1))
    assert loaded.patch is not None
    k_sw = math.pi * p.radius * (p.radial_stiffness + p.tangential_stiffness)
    est = ff[1] * math.sqrt(1 + loaded.patch.hub_stiffness / k_sw)
    print(
        f"  hub stiffness {loaded.patch.hub_stiffness / 1e6:.3f} MN/m, sidewall translation "
        f"stiffness pi R (k_r + k_t) = {k_sw / 1e6:.2f} MN/m: rigid-ring n = 1 estimate "
        f"{est:.1f} Hz (+{100 * (est / ff[1] - 1):.1f} %)"
    )


def cavity() -> None:
    print("\n4. cavity n = 1 pair (Hz): free and loaded")
    for load in (0.0, 20e3, 25e3, 30e3):
        tyre = virtual_tyre(7.5, load_n=load)
        um = tyre.physical_system.undamped_modes()
        air = np.sum(um.phi[tyre.cavity_dofs] ** 2, axis=0)
        air[(um.frequency_hz < 100) | (um.frequency_hz > 200)] = 0
        pair = np.sort(um.frequency_hz[np.argsort(air)[-2:]])
        est = float("nan")
        if tyre.patch is not None and tyre.contact is not None:
            da = -tyre.params.width * patch_intrusion(tyre.patch, tyre.contact, 0.5, tyre.n_ring)
            est = loaded_split_estimate(Cavity(), da)[1]
        print(
            f"  {load / 1e3:4.0f} kN: {pair[0]:7.2f} {pair[1]:7.2f}  split {pair[1] - pair[0]:5.2f}"
            f" Hz (rigid-walled first-order estimate {est:.2f} Hz)"
        )


def rmsd_vs_snr() -> None:
    print("\n5. RMSD real / complex of the 7.5 bar demo test (8 periods, 10 N)")
    for snr in (20.0, 30.0, 40.0, 50.0):
        ratios = []
        for seed in (1, 2, 3):
            run = run_pressure(7.5, 8, force_rms=10.0, snr_db=snr, seed=seed)
            m = run.identification.models
            ratios.append(m["real"].meta["rmsd"] / m["complex"].meta["rmsd"])
        print(f"  SNR {snr:4.0f} dB: " + " ".join(f"{r:6.2f}" for r in ratios))


def main() -> None:
    with threadpool_limits(1):
        sources()
        hub()
        load_effect()
        cavity()
        if "--quick" not in sys.argv:
            rmsd_vs_snr()


if __name__ == "__main__":
    main()
