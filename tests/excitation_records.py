"""Generated test records for the excitation detection: periodic, random and impact.

The response of every record is a digital resonant filter ``y = B(z)/A(z) x``
(two lightly damped modes), so the exact FRF on DFT line ``k`` of a period of
``P`` samples is ``B/A`` at ``z = exp(2 pi i k / P)`` (scipy.signal.freqz).
"""

from __future__ import annotations

import numpy as np
import scipy.signal

__all__ = ["SYSTEM", "exact_frf", "impact_record", "periodic_record", "random_record", "respond"]


def _system() -> tuple[np.ndarray, np.ndarray]:
    # two modes at 0.06 and 0.17 of the sample rate, 2 % and 1 % damping (decay per sample)
    poles = []
    for f, zeta in ((0.06, 0.02), (0.17, 0.01)):
        w = 2 * np.pi * f
        r = np.exp(-zeta * w)
        poles += [
            r * np.exp(1j * w * np.sqrt(1 - zeta**2)),
            r * np.exp(-1j * w * np.sqrt(1 - zeta**2)),
        ]
    a = np.real(np.poly(poles))
    b = np.array([0.3, 0.1, -0.2])
    return b, a


SYSTEM = _system()


def exact_frf(lines: np.ndarray, period: int) -> np.ndarray:
    """``B/A`` at ``exp(2 pi i k / P)`` for the DFT lines ``k``."""
    _, h = scipy.signal.freqz(*SYSTEM, worN=2 * np.pi * np.asarray(lines, float) / period)
    return h


def respond(
    x: np.ndarray, steady_periods: int | None = None, period: int | None = None
) -> np.ndarray:
    """Response from rest; with ``steady_periods`` leading periods run first and dropped."""
    b, a = SYSTEM
    if steady_periods and period:
        lead = np.tile(x[:period], steady_periods)
        return scipy.signal.lfilter(b, a, np.concatenate([lead, x]))[lead.size :]
    return scipy.signal.lfilter(b, a, x)


def periodic_record(
    kind: str, period: int, n_periods: int, rng: np.random.Generator, transient: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(force, response, excited lines) of a periodic multisine or chirp."""
    k_lo, k_hi = max(1, period // 40), int(0.4 * period)
    lines = np.arange(k_lo, k_hi + 1)
    if kind == "multisine":
        spec = np.zeros(period // 2 + 1, complex)
        spec[lines] = np.exp(2j * np.pi * rng.random(lines.size))
        one = np.fft.irfft(spec, period)
    else:  # periodic linear chirp from line k_lo to k_hi, phase continuous
        t = np.arange(period) / period
        one = np.sin(2 * np.pi * (k_lo * t + 0.5 * (k_hi - k_lo) * t**2))
    one = one / np.std(one)
    x = np.tile(one, n_periods)
    y = respond(x, None if transient else 400, period)
    return x, y, lines


def random_record(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Band-limited (random band and colour) Gaussian noise force and its response."""
    lo, hi = sorted(rng.uniform(0.005, 0.45, 2))
    if hi - lo < 0.01:
        hi = lo + 0.01
    sos = scipy.signal.butter(int(rng.integers(2, 8)), [lo, hi], "bandpass", fs=1.0, output="sos")
    x = scipy.signal.sosfilt(sos, rng.standard_normal(n + 2000))[2000:]
    return x, respond(x)


def impact_record(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Hammer hits (half-sine pulses of random width, height, time) with small noise."""
    x = np.zeros(n)
    n_hits = int(rng.integers(1, 6))
    times = np.sort(rng.choice(np.arange(20, n - 60), n_hits, replace=False))
    for t0 in times:
        w = int(rng.integers(3, 30))
        x[t0 : t0 + w] += rng.uniform(0.5, 2.0) * np.sin(np.pi * np.arange(w) / w)
    y = respond(x)
    x = x + 1e-3 * rng.standard_normal(n)
    y = y + 1e-3 * np.std(y) * rng.standard_normal(n)
    return x, y
