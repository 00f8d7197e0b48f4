"""The physical virtual tyre: damping sources, hub stiffness, load, cavity and the RMSD ratio.

Prints

1. the off-diagonal share of the in-band modal damping ``C'`` (radial spec
   eq. [14]) and its split by physical source (``damping_decomposition``) for
   the bare ring, the demo tyre (free, cavity), the same with a splice, and
   loaded on a road (25 kN), with the former 30 and 350 N s/m drive-point
   dampers for comparison, and the largest first-order coupling of two modes
   (eq. [16]);
2. the static hub stiffness (rigid hub, ring condensed) at 2.76 / 4.14 /
   6.5 / 7.5 / 9 bar and 20 / 25 / 30 kN beside the Goodyear 335/65R22.5
   .tir values (Project Chrono ``feda``: 406.5 / 565.2 / 644.5 / 848.6 kN/m
   at 2.7 / 4.14 / 4.8 / 6.5 bar), with the patch length, and at the .tir
   files' own pressures and nominal loads;
3. the undamped in-band frequencies free and loaded (25 kN) and the loaded
   n = 1 vertical mode against the rigid-ring estimate;
4. the n = 1 cavity pair free and loaded and its split against the
   first-order estimate ``2 dV / V``;
5. the RMSD ratio (real / complex fit) of the demo's 7.5 bar test at SNR
   20, 30, 40, 50 dB (``run_pressure``, 8 periods, seeds 1-3);
6. which pairs of the in-band modes the drive point excites the 16
   accelerometers cannot tell apart
   (MAC of the undamped shapes at the points above 0.9, as
   ``damping.diagnostics.collinear_pairs``), without and with a rim
   microphone (``virtual.microphone``) at 0, 90 and 101.25 deg, its row
   scaled to the RMS of an accelerometer row; and the damping identified
   (``identify_damping``, eq. [18], no noise) from the exact complex modes
   the drive point excites, at the 16 points without and with the
   microphone at 0 deg: the ``C'`` term of the band-air n = 1 pair and the
   relative error of ``C'``.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/tyre_physics.py [--quick]``
(``--quick``: no RMSD runs).
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace

import numpy as np
from threadpoolctl import threadpool_limits

from tyredamp.damping import identify_damping
from tyredamp.damping.diagnostics import collinear_pairs
from tyredamp.frf import Channel
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
from tyredamp.virtual.microphone import microphone_row

BAR = 1e5


def sources() -> None:
    print("1. non-proportional damping by source (share of C'_off; 'alone': norm ratio)")
    cases = {
        "bare ring, 2 N s/m tip": RingTyre(),
        "bare ring, 30 N s/m tip (former)": RingTyre(
            layout=MeasurementLayout(attachment_mass=0.1, attachment_damping=30.0)
        ),
        "bare ring, 350 N s/m tip (older)": RingTyre(
            layout=MeasurementLayout(attachment_mass=0.1, attachment_damping=350.0)
        ),
        "demo with the former 30 N s/m, 0.1 kg tip": RingTyre(
            layout=MeasurementLayout(attachment_mass=0.1, attachment_damping=30.0), cavity=Cavity()
        ),
        "demo: free + cavity": virtual_tyre(7.5),
        "free + cavity + splice": virtual_tyre(7.5, splice=True),
        "loaded 25 kN + cavity": virtual_tyre(7.5, load_n=25e3),
        "loaded 25 kN + cavity + splice": virtual_tyre(7.5, load_n=25e3, splice=True),
    }
    for name, tyre in cases.items():
        print(f"-- {name}")
        dd = damping_decomposition(tyre)
        fk, fn, a = dd.largest_coupling()
        print(dd.format())
        print(f"largest coupling (eq. [16]): {a:.3g} between {fk:.1f} and {fn:.1f} Hz")


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
    psi = 6894.757
    model = []
    for psig, load, k_tir in ((40, 16929.0, 406.52e3), (95, 29912.0, 848.55e3)):
        st = RingTyre(RingTyreParameters(pressure=psig * psi), contact=ContactPatch(load)).patch
        assert st is not None
        model.append(st.hub_stiffness)
        print(
            f"  .tir {psig} psi ({psig * psi / BAR:.2f} bar), FNOMIN {load / 1e3:.1f} kN: model "
            f"{st.hub_stiffness / 1e3:.0f} kN/m, file {k_tir / 1e3:.0f} kN/m "
            f"({100 * (st.hub_stiffness / k_tir - 1):+.0f} %)"
        )
    print(f"  ratio 95/40 psi: model {model[1] / model[0]:.2f}, file {848.55 / 406.52:.2f}")


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


def microphone() -> None:
    print("\n6. pairs of modes the points cannot tell apart (MAC > 0.9), without / with a mic")
    for pb in (7.5, 6.0, 9.0):
        tyre = virtual_tyre(pb)
        um = tyre.physical_system.undamped_modes()
        tr = tyre.truth()
        # the modes the drive point excites (the ones a test identifies)
        sel = [int(np.argmin(np.abs(um.frequency_hz - fv))) for fv in tr.frequency_hz[tr.select()]]
        f = um.frequency_hz[sel]
        acc = um.phi[np.ix_(tyre.point_dofs, sel)]
        print(f"  {pb:g} bar: accelerometers only: {_pairs(f, collinear_pairs(acc))}")
        for ang in (0.0, 90.0, 101.25):
            mic = microphone_row(tyre, ang) @ um.phi[:, sel]
            both = np.vstack([acc, math.sqrt(np.mean(acc**2) / np.mean(mic**2)) * mic])
            print(f"    + microphone at {ang:6.2f} deg: {_pairs(f, collinear_pairs(both))}")

    print("  damping from the exact visible modes (eq. [18]), 7.5 bar:")
    tyre = virtual_tyre(7.5)
    tr = tyre.truth()
    vis = tr.select("visible")
    mm = tr.modal_model("visible")
    cm = tyre.system.complex_modes()
    psi = cm.psi[:, [int(np.argmin(np.abs(cm.poles - p))) for p in mm.poles]]
    mic = microphone_row(tyre, 0.0) @ psi
    w = math.sqrt(np.mean(np.abs(mm.psi_out) ** 2) / np.mean(np.abs(mic) ** 2))
    with_mic = replace(
        mm,
        psi_out=np.vstack([mm.psi_out, w * mic]),
        outputs=(*mm.outputs, Channel(node=18, direction=0, name="P1")),
    )
    c_true = tr.modal_damping[np.ix_(vis, vis)]
    f = tr.frequency_hz[vis]
    i, j = int(np.argmin(np.abs(f - 46.2))), int(np.argmin(np.abs(f - 145.0)))
    for name, model in (("16 accelerometers", mm), ("16 accelerometers + microphone", with_mic)):
        c = identify_damping(model, "improved", n_samples=0).modal
        err = np.linalg.norm(c - c_true) / np.linalg.norm(c_true)
        print(
            f"    {name:31s} C'({f[i]:.1f}, {f[j]:.1f} Hz) = {c[i, j]:8.2f} / {c[j, i]:8.2f} "
            f"1/s (true {c_true[i, j]:.2f}); ||C' - C'_true|| / ||C'_true|| = {err:.3f}"
        )


def _pairs(f: np.ndarray, pairs: tuple[tuple[int, int, float], ...]) -> str:
    return ", ".join(f"{f[i]:.1f}/{f[j]:.1f} Hz" for i, j, _ in pairs) or "none"


def main() -> None:
    with threadpool_limits(1):
        sources()
        hub()
        load_effect()
        cavity()
        microphone()
        if "--quick" not in sys.argv:
            rmsd_vs_snr()


if __name__ == "__main__":
    main()
