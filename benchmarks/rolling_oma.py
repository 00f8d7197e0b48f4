"""Rolling-tyre OMA on the rotating virtual tyre: accuracy, false modes, coverage.

For each speed and noise draw: a road-excited rolling test (16 fixed sensors,
one in-tyre sensor), :func:`tyredamp.oma.rolling.rolling_modes`, and the
comparison with the exact waves that radial sensors can see (the ``n = 0``
rotation mode, with no radial motion, is left out). Prints, per speed: the in-band waves found
with their direction, how many within 0.5 % in frequency and 10 % in damping,
the false fixed-frame modes (no exact wave of that n and direction, at any
frequency, within 2 % of it), the coverage of the +-1.96 sigma frequency
intervals over the draws, and the in-tyre peaks resolved within 0.5 %.
``--cache DIR`` keeps the simulated tests, so that the routes can be
compared on the same records without simulating them again.

The default is the route ``rolling_modes`` takes by default; ``--spatial``
forces the wave-number route (one identification per wave number and
direction), ``--general`` the route of all fixed sensors together. ``s/run``
is the wall time of the identification, ``cpu s/run`` its CPU time (the
simulation excluded). ``--thresholds 3,10,30`` prints instead, per speed,
the waves of the wave-number route found and the false ones when the channel-power threshold of
:func:`tyredamp.oma.rolling.select_spatial_poles` takes each value (the poles
identified once per draw).

``no dir`` counts the fixed-frame waves found with the wave number of an
exact wave within 2 % but no direction (a Nyquist wave whose direction the
in-tyre sensor does not tell, :mod:`tyredamp.oma.nyquist`); ``rms f/sd`` and
``rms z/sd`` are the rms errors of the found waves in units of their
standard errors, ``med sd(z)/z`` the median reported relative standard
error of the damping ratio. ``--sample-rate`` sets the acquisition rate.

Usage: python benchmarks/rolling_oma.py [--draws 5] [--duration 16] [--spatial | --general]
       [--thresholds 3,10,30] [--sample-rate 512] [--cache DIR]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tyredamp._blas import single_threaded_blas
from tyredamp.oma.rolling import (
    RollingWave,
    compare_waves,
    rolling_modes,
    rotating_pole,
    select_spatial_poles,
    spatial_poles,
)
from tyredamp.virtual import rolling_test


def _seen(test) -> list[dict]:  # type: ignore[no-untyped-def]
    """The truth waves radial sensors can see under a radial road force (the
    ``n = 0`` rotation mode has no radial motion: ``radially_observable``)."""
    return [r for r in test.truth.table() if r["radially_observable"]]


def _split_errors(waves: list[RollingWave], truth: list[dict]) -> list[float]:
    """|error of f_backward - f_forward| / f_mean (rotating frame) for each n both found."""
    out = []
    for n in sorted({r["wave_number"] for r in truth if r["wave_number"] > 0}):
        t = {r["direction"]: r["rotating_hz"] for r in truth if r["wave_number"] == n}
        w: dict[str, list[float]] = {}
        for x in waves:
            if x.wave_number == n and x.direction in t and np.isfinite(x.rotating_hz):
                w.setdefault(x.direction, []).append(x.rotating_hz)
        if len(t) < 2 or len(w) < 2:
            continue
        est = {d: min(v, key=lambda f: abs(f - t[d])) for d, v in w.items()}
        d_est = est["backward"] - est["forward"]
        d_true = t["backward"] - t["forward"]
        out.append(abs(d_est - d_true) / (0.5 * (t["backward"] + t["forward"])))
    return out


def _test(
    speed: float,
    seed: int,
    duration: float,
    band: tuple[float, float],
    cache: str,
    sample_rate: float = 512.0,
):
    """The virtual test, simulated or read from ``cache`` (a folder; written there)."""
    import pickle
    from pathlib import Path

    rate = "" if sample_rate == 512 else f"_{sample_rate:g}Hz"
    path = Path(cache) / f"rolling_{speed:g}_{seed}_{duration:g}{rate}.pkl" if cache else None
    if path is not None and path.exists():
        with path.open("rb") as fh:
            return pickle.load(fh)
    test = rolling_test(speed, duration=duration, sample_rate=sample_rate, band=band, seed=seed)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("wb") as fh:
            pickle.dump(test, fh)
    return test


def _run(
    speed: float,
    seed: int,
    duration: float,
    band: tuple[float, float],
    spatial: bool | None = False,
    cache: str = "",
    sample_rate: float = 512.0,
) -> dict:
    test = _test(speed, seed, duration, band, cache, sample_rate)
    t0, c0 = time.perf_counter(), time.process_time()
    m = (
        rolling_modes(test.data, spatial=spatial)
        if spatial is not None
        else rolling_modes(test.data)
    )
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    truth = [r for r in _seen(test) if band[0] + 5 <= r["fixed_hz"] <= band[1] - 10]
    cmp = compare_waves(m.fixed, truth, "fixed")
    false = 0
    undirected = 0
    for w in m.fixed:  # a wave is false when no exact wave, at any frequency, is near it
        near = [
            r
            for r in _seen(test)
            if r["wave_number"] == w.wave_number
            and (r["direction"] == w.direction or r["wave_number"] == 0 or w.direction is None)
            and abs(r["fixed_hz"] / w.fixed_hz - 1) < 0.02
        ]
        false += not near
        undirected += bool(near) and w.direction is None  # a Nyquist wave left unresolved
    rot_truth = [r for r in _seen(test) if band[0] + 5 <= r["rotating_hz"] <= band[1] - 10]
    rot = compare_waves(m.rotating, rot_truth, "rotating")
    cover = [
        abs(c["frequency_hz"] - c["truth"]["fixed_hz"]) <= 1.96 * c["std_frequency_hz"]
        for c in cmp
        if c["found"] and np.isfinite(c["std_frequency_hz"])
    ]
    zcover = [
        abs(c["damping_ratio"] - c["truth"]["fixed_damping_ratio"]) <= 1.96 * c["std_damping_ratio"]
        for c in cmp
        if c["found"] and np.isfinite(c["std_damping_ratio"])
    ]
    zf = [
        (c["frequency_hz"] - c["truth"]["fixed_hz"]) / c["std_frequency_hz"]
        for c in cmp
        if c["found"] and np.isfinite(c["std_frequency_hz"]) and c["std_frequency_hz"] > 0
    ]
    zz = [
        (c["damping_ratio"] - c["truth"]["fixed_damping_ratio"]) / c["std_damping_ratio"]
        for c in cmp
        if c["found"] and np.isfinite(c["std_damping_ratio"]) and c["std_damping_ratio"] > 0
    ]
    rel_sz = [
        c["std_damping_ratio"] / c["damping_ratio"]
        for c in cmp
        if c["found"] and np.isfinite(c["std_damping_ratio"]) and c["damping_ratio"] > 0
    ]
    rot_split = [r for r in _seen(test) if band[0] + 5 <= r["rotating_hz"] <= band[1] - 10]
    return {
        "n": len(cmp),
        "found": sum(c["found"] for c in cmp),
        "f_ok": sum(c["found"] and abs(c["f_error"]) <= 0.005 for c in cmp),
        "z_ok": sum(c["found"] and abs(c["zeta_error"]) <= 0.10 for c in cmp),
        "false": false,
        "undirected": undirected,
        "cover": cover,
        "zcover": zcover,
        "split_fixed": _split_errors(m.fixed, rot_split),
        "split_rot": _split_errors(m.rotating, rot_split),
        "zerr": [c["zeta_error"] for c in cmp if c["found"]],
        "zf": zf,
        "zz": zz,
        "rel_sz": rel_sz,
        "rot_n": len(rot),
        "rot_ok": sum(c["found"] and abs(c["f_error"]) <= 0.005 for c in rot),
        "unresolved": sum(w.wave_number is None for w in m.rotating),
        "time": dt,
        "cpu": cpu,
    }


def _thresholds(
    speed: float,
    seed: int,
    duration: float,
    band: tuple[float, float],
    values: list[float | None],
) -> list[tuple[int, int, int]]:
    """(truth waves, found, false) of the wave-number route for each threshold of the
    channel power (``None``: the F-test threshold of ``select_spatial_poles``); the
    poles identified once, without standard errors."""
    test = rolling_test(speed, duration=duration, sample_rate=512, band=band, seed=seed)
    d = test.data
    fix = [i for i in d.response_indices if not (d.channels[i].name or "").upper().startswith("T")]
    ang = [float(d.channels[i].angle_deg or 0.0) for i in fix]
    fw = float(d.meta["rotation_hz"])
    kw = {"band": d.acquisition.band_hz, "uncertainty": False, "wheel_speed_hz": fw or None}
    poles, res, dof = spatial_poles(d.data[fix], d.sample_rate, ang, kw)
    truth = [r for r in _seen(test) if band[0] + 5 <= r["fixed_hz"] <= band[1] - 10]
    out = []
    for v in values:
        waves = []
        for p in select_spatial_poles(poles, d.acquisition.band_hz or band, res, dof, v):
            f, z, n, fd = p.frequency_hz, p.damping_ratio, p.wave_number, p.direction
            fr, _, dt = rotating_pole(f, z, n, fd, fw)
            waves.append(RollingWave("fixed", n, dt, fd, f, fr, z, np.nan, np.nan))
        cmp = compare_waves(waves, truth, "fixed")
        false = sum(
            not any(
                r["wave_number"] == w.wave_number
                and (r["direction"] == w.direction or r["wave_number"] == 0)
                and abs(r["fixed_hz"] / w.fixed_hz - 1) < 0.02
                for r in truth
            )
            for w in waves
        )
        out.append((len(cmp), sum(c["found"] for c in cmp), false))
    return out


def _rms(x: list) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x else float("nan")


def _pct(x: list) -> str:
    return f"{100 * np.mean(x):.0f}%" if x else "-"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=5)
    ap.add_argument("--duration", type=float, default=16.0)
    ap.add_argument("--speeds", default="0,40,80,120")
    ap.add_argument("--spatial", action="store_true", help="one identification per wave number")
    ap.add_argument("--general", action="store_true", help="all fixed sensors together")
    ap.add_argument("--cache", default="", help="folder keeping the simulated tests")
    ap.add_argument("--sample-rate", type=float, default=512.0, help="Hz (default 512)")
    ap.add_argument("--thresholds", default="", help="channel-power thresholds to compare")
    a = ap.parse_args()
    if a.thresholds:
        _threshold_table(a)
        return
    band = (0.0, 200.0)
    print(f"band {band} Hz, {a.duration:g} s records at {a.sample_rate:g} Hz, 16 fixed + 1 "
          f"in-tyre sensor, {a.draws} draws")  # fmt: skip
    print(
        "speed  waves  found  f<0.5%  z<10%  med|dz|  false/run  cover f  cover z  "
        "in-tyre ok  unresolved  split<0.5% fixed  in-tyre  no dir  rms f/sd  rms z/sd  "
        "med sd(z)/z  s/run  cpu s/run"
    )
    for v in [float(s) for s in a.speeds.split(",")]:
        with single_threaded_blas():
            route = True if a.spatial else (False if a.general else None)
            runs = [
                _run(v, seed, a.duration, band, route, a.cache, a.sample_rate)
                for seed in range(a.draws)
            ]
        cov = [c for r in runs for c in r["cover"]]
        zcov = [c for r in runs for c in r["zcover"]]
        sf = [e <= 0.005 for r in runs for e in r["split_fixed"]]
        sr = [e <= 0.005 for r in runs for e in r["split_rot"]]
        zerr = [abs(e) for r in runs for e in r["zerr"]]
        print(
            f"{v:5.0f}  {sum(r['n'] for r in runs):5d}  {sum(r['found'] for r in runs):5d}  "
            f"{sum(r['f_ok'] for r in runs):6d}  {sum(r['z_ok'] for r in runs):5d}  "
            f"{100 * np.median(zerr) if zerr else float('nan'):6.1f}%  "
            f"{np.mean([r['false'] for r in runs]):9.1f}  {_pct(cov):>7s}  {_pct(zcov):>7s}  "
            f"{sum(r['rot_ok'] for r in runs):4d}/{sum(r['rot_n'] for r in runs):<5d}  "
            f"{sum(r['unresolved'] for r in runs):10d}  "
            f"{sum(sf):5d}/{len(sf):<5d}  {sum(sr):5d}/{len(sr):<5d}  "
            f"{sum(r['undirected'] for r in runs):6d}  "
            f"{_rms([e for r in runs for e in r['zf']]):8.2f}  "
            f"{_rms([e for r in runs for e in r['zz']]):8.2f}  "
            f"{100 * np.median([e for r in runs for e in r['rel_sz']] or [np.nan]):10.1f}%  "
            f"{np.mean([r['time'] for r in runs]):5.1f}  {np.mean([r['cpu'] for r in runs]):9.1f}",
            flush=True,
        )


def _threshold_table(a: argparse.Namespace) -> None:
    values: list[float | None] = [
        None if v == "auto" else float(v) for v in a.thresholds.split(",")
    ]
    print(f"wave-number route, {a.duration:g} s records, {a.draws} draws: found / false per run")
    heads = ["F-test" if v is None else f"x{v:g}" for v in values]
    print("speed  waves  " + "  ".join(f"{h:<11s}" for h in heads))
    for v in [float(s) for s in a.speeds.split(",")]:
        with single_threaded_blas():
            runs = [_thresholds(v, s, a.duration, (0.0, 200.0), values) for s in range(a.draws)]
        cells = [
            f"{sum(r[i][1] for r in runs):3d} / {np.mean([r[i][2] for r in runs]):4.1f}"
            for i in range(len(values))
        ]
        print(f"{v:5.0f}  {sum(r[0][0] for r in runs):5d}  " + "  ".join(cells), flush=True)


if __name__ == "__main__":
    main()
