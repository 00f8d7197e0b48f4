"""The wind-up from the virtual tangential test: accuracy and interval coverage over seeds.

For each noise seed the virtual truck tyre (free, no cavity, default shaker
tip 0.01 kg and 2 N s/m) is tested tangentially (``run_modal_test(...,
direction="tangential")``, chirp 0-100 Hz, 40 dB SNR on every channel, the
settings of ``tests/test_tyremodel_windup.py``), the H1 FRFs are fitted
(``identify_modes``, complex modes, 5-100 Hz) and ``windup_from_modes``
(attachment removed) is compared with the exact rotation mode
(``windup_truth``: bare frequency and damping, belt inertia). Prints per
seed the relative errors, the errors in units of the statistical
standard errors, the fit's noise along the response of the mode
(``noise_along_response``, 1 where not significant) and the factor of its
damping ratio's variance the fit applied (``pole_variance_ratio``: the
sandwich's where the FRF carries its input noise, else the noise along the
response), then the largest
relative errors, the share of seeds whose 1-sigma statistical interval
covers the truth and the share whose fit split
the rotation into two poles (noted by ``windup_from_modes``). First it
prints the same fit on the exact FRF (seed 1's FRF variance as weights).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/windup.py [N_SEEDS] [N_PERIODS]``
(default 20 seeds, 2 periods).

``... windup.py --radial [N_SEEDS] [N_PERIODS]``: the same honesty check on the
radial default test (``run_modal_test(seed=...)``: 0-200 Hz chirp, 40 dB SNR,
complex modes 5-200 Hz). Each visible true mode is matched to the nearest
identified pole within two half-power half-widths; per mode the script prints
the share of seeds where it was found, the mean error in standard errors
(bias / se), the rms z, the 1-sigma coverage of frequency and damping ratio,
and the error of the same fit on the exact FRF (``test.truth.frf``, weighted
with the noisy test's FRF variance): the fit's own model error, in standard
errors.

``--noise force`` or ``--noise responses`` (either mode): the test is run
without noise and the 40 dB noise added to the force channel only or to the
accelerations only (``h1_variance.noisy``), to tell which noise the
intervals miss.
"""

from __future__ import annotations

import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from tyredamp.frf import FRF
from tyredamp.studies.radial import frf_from_time, modes_from_frf
from tyredamp.tyremodel import windup_from_modes
from tyredamp.virtual import RingTyre, run_modal_test, windup_truth


def exact_fit(tyre: RingTyre, test, frf: FRF) -> None:
    """The same fit on the exact FRF (weighted with ``frf.variance``): the fit's model error.

    Once with the tip removed (against the bare truth) and once without removal
    (against the tested mode): what the removal's formula adds.
    """
    wt = windup_truth(tyre)
    lay = tyre.layout
    exact = test.true_frf(frf.frequency)
    ex = FRF(frf.frequency, exact.H, kind=frf.kind, outputs=frf.outputs, inputs=frf.inputs)
    mdl = modes_from_frf(ex, band=(5.0, 100.0), model="complex", variance=frf.variance)
    mdl = mdl.models["complex"]
    for label, (m_a, c_a), (f0, z0, i0) in (
        (
            "tip removed, bare truth",
            (lay.attachment_mass, lay.attachment_damping),
            (wt.bare_frequency_hz, wt.bare_damping_ratio, wt.inertia),
        ),
        (
            "tip kept, tested mode",
            (0.0, 0.0),
            (wt.frequency_hz, wt.damping_ratio, wt.modal_inertia),
        ),
    ):
        w = windup_from_modes(
            mdl, radius=tyre.params.radius, attachment_mass=m_a, attachment_damping=c_a
        )
        print(
            f"exact FRF, {label}: rel f {w.freq_windup / f0 - 1:+.2e} "
            f"({(w.freq_windup - f0) / w.freq_windup_std:+.2f} se), rel zeta "
            f"{w.damp_windup / z0 - 1:+.2e} ({(w.damp_windup - z0) / w.damp_windup_std:+.2f} se)"
            f", rel I {w.belt_iyy / i0 - 1:+.2e}"
        )


#: Channels that get the 40 dB noise: "both" (the rig's own), "force" or "responses".
NOISE = "both"


def tested(seed: int, **options: object):
    """``run_modal_test(seed=seed, **options)`` with the noise on :data:`NOISE`'s channels."""
    from dataclasses import replace

    from h1_variance import noisy

    if NOISE == "both":
        return run_modal_test(seed=seed, **options)  # type: ignore[arg-type]
    test = run_modal_test(seed=seed, snr_db=None, **options)  # type: ignore[arg-type]
    return replace(test, data=noisy(test.data, NOISE, np.random.default_rng(seed), 40.0))


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
    print(" seed   rel f      rel zeta   rel I      z_f    z_zeta  z_I    split along  ratio  s")
    rel: dict[str, list[float]] = {"f": [], "z": [], "I": []}
    cover: dict[str, list[bool]] = {"f": [], "z": [], "I": []}
    zall: dict[str, list[float]] = {"f": [], "z": [], "I": []}
    splits = 0
    for seed in range(1, n_seeds + 1):
        t0 = time.perf_counter()
        test = tested(
            seed,
            tyre=tyre,
            direction="tangential",
            n_periods=n_periods,
            band=(0.0, 100.0),
            oversample=4,
        )
        frf = frf_from_time(test.data, "H1")
        if seed == 1:
            exact_fit(tyre, test, frf)
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
            f" {_along(mdl, w.index):5.2f}  {_ratio(mdl, w.index):5.2f}"
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


def _along(model, k: int) -> float:
    """The fit's noise along the response of mode ``k`` (1: not significant, not used)."""
    along = model.meta.get("noise_along_response")
    return float(along[k]) if along is not None else float("nan")


def _ratio(model, k: int) -> float:
    """The sandwich's factor of the variance of mode ``k``'s damping ratio (NaN: not known)."""
    ratio = model.meta.get("pole_variance_ratio")
    return float(ratio[k][1]) if ratio is not None else float("nan")


def _matched(model, truth_f: np.ndarray, truth_z: np.ndarray) -> list[int | None]:
    """Index of the identified pole nearest each true mode within two half-widths."""
    out: list[int | None] = []
    for f, z in zip(truth_f, truth_z, strict=True):
        d = np.abs(model.frequency_hz - f)
        k = int(np.argmin(d)) if d.size else -1
        out.append(k if k >= 0 and d[k] <= 2 * z * f else None)
    return out


def _z(model, k: int, f: float, z: float) -> tuple[float, float]:
    """Errors of frequency and damping ratio of pole ``k`` in its standard errors."""
    sf = float(model.std["frequency_hz"][k])
    sz = float(model.std["damping_ratio"][k])
    return (float(model.frequency_hz[k]) - f) / sf, (float(model.damping_ratio[k]) - z) / sz


def radial(n_seeds: int, n_periods: int) -> None:
    """Per-mode z-scores of the radial default test over seeds (module docstring)."""
    band = (5.0, 200.0)
    zs: dict[int, list[tuple[float, float]]] = {}
    exact_z: dict[int, list[tuple[float, float]]] = {}
    truth = None
    for seed in range(1, n_seeds + 1):
        t0 = time.perf_counter()
        test = tested(seed, n_periods=n_periods)
        truth = test.truth
        vis = truth.select("visible")
        tf, tz = truth.frequency_hz[vis], truth.damping_ratio[vis]
        frf = frf_from_time(test.data, "H1")
        mdl = modes_from_frf(frf, band=band, model="complex").models["complex"]
        exact = test.true_frf(frf.frequency)
        ex = FRF(frf.frequency, exact.H, kind=frf.kind, outputs=frf.outputs, inputs=frf.inputs)
        ex_mdl = modes_from_frf(ex, band=band, model="complex", variance=frf.variance)
        ex_mdl = ex_mdl.models["complex"]
        for j, (k, ke) in enumerate(
            zip(_matched(mdl, tf, tz), _matched(ex_mdl, tf, tz), strict=True)
        ):
            if k is not None:
                zs.setdefault(j, []).append(_z(mdl, k, tf[j], tz[j]))
            if ke is not None:
                exact_z.setdefault(j, []).append(_z(ex_mdl, ke, tf[j], tz[j]))
        print(f"seed {seed}: {mdl.n_modes} modes, {time.perf_counter() - t0:.1f} s", flush=True)
    assert truth is not None
    vis = truth.select("visible")
    print(
        "mode  f [Hz]   zeta     found | f: bias/se rms z cover | zeta: bias/se rms z cover"
        " | exact FRF: z_f z_zeta"
    )
    all_f, all_z = [], []
    for j, i in enumerate(vis):
        got = np.array(zs.get(j, [])).reshape(-1, 2)
        ez = np.array(exact_z.get(j, [])).reshape(-1, 2)
        all_f += got[:, 0].tolist()
        all_z += got[:, 1].tolist()
        cov = np.mean(np.abs(got) <= 1, axis=0) if got.size else [np.nan, np.nan]
        rms = np.sqrt(np.mean(got**2, axis=0)) if got.size else [np.nan, np.nan]
        bias = np.mean(got, axis=0) if got.size else [np.nan, np.nan]
        exm = np.mean(ez, axis=0) if ez.size else [np.nan, np.nan]
        head = f"{j:4d} {truth.frequency_hz[i]:8.3f} {truth.damping_ratio[i]:.5f}"
        print(
            f"{head} {len(got):3d}/{n_seeds}"
            f" | {bias[0]:+6.2f} {rms[0]:6.2f} {100 * cov[0]:4.0f} %"
            f" | {bias[1]:+6.2f} {rms[1]:6.2f} {100 * cov[1]:4.0f} %"
            f" | {exm[0]:+6.2f} {exm[1]:+6.2f}"
        )
    af, az = np.array(all_f), np.array(all_z)
    for name, v in (("f", af), ("zeta", az)):
        print(
            f"all modes, {name}: 1-sigma coverage {100 * np.mean(np.abs(v) <= 1):.0f} %, "
            f"rms z {np.sqrt(np.mean(v**2)):.2f}, mean z {np.mean(v):+.2f}"
        )


if __name__ == "__main__":
    with threadpool_limits(1):
        if "--noise" in sys.argv:
            i = sys.argv.index("--noise")
            NOISE = sys.argv[i + 1]
            del sys.argv[i : i + 2]
        if "--radial" in sys.argv:
            sys.argv.remove("--radial")
            radial(
                int(sys.argv[1]) if len(sys.argv) > 1 else 8,
                int(sys.argv[2]) if len(sys.argv) > 2 else 2,
            )
        else:
            main()
