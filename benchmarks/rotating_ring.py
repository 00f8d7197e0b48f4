"""The rotating ring tyre: dispersion check, Doppler split and the rolling recording.

Part 1: forward and backward rotating-frame frequencies of n = 1..6 of the
default 295/80R22.5 ring at 0-120 km/h: the closed-form quartic of the
continuous ring (``rotating_ring_dispersion``), its inextensible limit
(Bryan / Huang & Soedel), and the discretised gyroscopic ring (64 nodes, the
default tyre's damping; undamped with the discrete symbol ``s(n)``); largest
relative error.

Part 2: the fixed-frame split of n = 3 at 10 km/h against the pure-Doppler
estimate ``+- n f_rot`` and the Bryan-corrected ``+- n f_rot (n^2-1)/(n^2+1)``.

Part 3: discretisation error against ``n_ring`` at 120 km/h.

Part 4: a 64 s rolling recording at 40 km/h under the random road force:
time, and the Welch PSD of the fixed sensors and of the in-tyre sensor near
the true n = 2, 3 forward/backward frequencies (the nearest PSD maximum).

Run: ``python benchmarks/rotating_ring.py``.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.signal import find_peaks, welch

from tyredamp.virtual import (
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    RotatingRing,
    inextensible_rotating_frequencies,
    rolling_test,
    rotating_ring_dispersion,
)
from tyredamp.virtual.rolling_truth import signed_wave_numbers
from tyredamp.virtual.rotation import spin_rate

N = np.arange(1, 7)
BARE = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)


def discrete(params: RingTyreParameters, speed: float, n_ring: int = 64) -> np.ndarray:
    """Forward/backward frequencies (Hz) of n = 1..6 of the discrete gyroscopic ring."""
    ring = RotatingRing(RingTyre(params, BARE, n_ring=n_ring, nonproportionality=1.0), speed)
    modes = ring.system.state_modes()
    k, _ = signed_wave_numbers(modes.displacement[:n_ring], modes.displacement[n_ring:])
    out = np.empty((N.size, 2))
    for i, n in enumerate(N):
        idx = np.flatnonzero(np.abs(k) == n)[:2]
        f, kk = modes.frequency_hz[idx], k[idx]
        out[i] = [f[kk < 0][0], f[kk > 0][0]] if speed > 0 else np.sort(f)
    return out


def part1() -> None:
    p = RingTyreParameters()
    p0 = RingTyreParameters(radial_damping=0.0, tangential_damping=0.0, band_loss_factor=0.0)
    print("Part 1: rotating-frame frequencies (Hz), forward / backward, n = 1..6")
    for speed in (0.0, 10.0, 40.0, 80.0, 120.0):
        closed = rotating_ring_dispersion(p, N, speed)
        inext = inextensible_rotating_frequencies(p, N, speed)
        disc = discrete(p, speed)
        sym = rotating_ring_dispersion(p0, N, speed, n_ring=64)
        disc0 = discrete(p0, speed)
        print(f"\n{speed:5.0f} km/h   closed form          discrete (damped)    inextensible")
        for i, n in enumerate(N):
            print(
                f"   n={n}  {closed[i, 0]:8.3f} {closed[i, 1]:8.3f}   "
                f"{disc[i, 0]:8.3f} {disc[i, 1]:8.3f}   {inext[i, 0]:8.3f} {inext[i, 1]:8.3f}"
            )
        err = np.max(np.abs(disc - closed) / closed)
        err_sym = np.max(np.abs(disc0 - sym) / sym)
        err_inx = np.max(np.abs(inext - closed) / closed)
        print(
            f"   max |discrete - closed| / closed = {100 * err:.3f} %  (task bound 1 %); "
            f"undamped vs discrete symbol {err_sym:.1e}; inextensible vs extensible "
            f"{100 * err_inx:.3f} %"
        )


def part2() -> None:
    p = RingTyreParameters()
    f_rot = spin_rate(10.0, p.radius) / (2 * np.pi)
    fixed = rotating_ring_dispersion(p, [3], 10.0, frame="fixed")[0]
    print("\nPart 2: n = 3 at 10 km/h in the fixed frame")
    print(f"  rotation {f_rot:.4f} Hz; forward {fixed[0]:.3f} Hz, backward {fixed[1]:.3f} Hz")
    print(f"  half split {(fixed[0] - fixed[1]) / 2:.3f} Hz")
    print(f"  pure Doppler estimate n f_rot = {3 * f_rot:.3f} Hz")
    print(f"  with Coriolis (Bryan) n f_rot (n^2-1)/(n^2+1) = {3 * f_rot * 0.8:.3f} Hz")


def part3() -> None:
    p = RingTyreParameters()
    closed = rotating_ring_dispersion(p, N, 120.0)
    print("\nPart 3: discretisation error at 120 km/h (max over n = 1..6, both waves)")
    for n_ring in (32, 48, 64, 96, 128):
        err = np.max(np.abs(discrete(p, 120.0, n_ring) - closed) / closed)
        print(f"  n_ring {n_ring:4d}: {100 * err:.4f} %")


def part4() -> None:
    print("\nPart 4: 64 s rolling recording at 40 km/h, random road force 100 N RMS, 40 dB")
    t0 = time.perf_counter()
    test = rolling_test(40.0, duration=64.0, seed=1)
    print(f"  simulated in {time.perf_counter() - t0:.1f} s: {test.data}")
    d = test.data
    fr, pxx = welch(d.data, fs=d.sample_rate, nperseg=4096, axis=1)
    fixed_psd = pxx[:-1].mean(axis=0)
    tyre_psd = pxx[-1]
    for name, psd, key in (("fixed", fixed_psd, "fixed_hz"), ("in-tyre", tyre_psd, "rotating_hz")):
        peaks, _ = find_peaks(psd)
        print(f"  {name} sensors: true -> nearest PSD maximum (Hz), 0.25 Hz lines")
        for n in (2, 3):
            for direction in ("forward", "backward"):
                f = test.truth.wave(n, direction)[key]
                near = fr[peaks[np.argmin(np.abs(fr[peaks] - f))]]
                print(f"    n={n} {direction:8s} {f:8.2f} -> {near:8.2f}")


if __name__ == "__main__":
    part1()
    part2()
    part3()
    part4()
