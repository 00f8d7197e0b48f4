"""Travelling waves of a rolling tyre: wave number and direction of each mode.

With the time dependence ``e^{i omega t}`` of a pole ``Im lambda > 0``, a
complex mode shape measured at fixed angles ``theta_j`` around the tyre,
``psi(theta) = a e^{+i n theta} + b e^{-i n theta}``, holds a wave
``b e^{i(omega t - n theta)}`` travelling towards ``+theta`` (forward) and
``a e^{i(omega t + n theta)}`` travelling towards ``-theta`` (backward); a
standing wave has ``|a| = |b|`` (Huang & Soedel, J. Sound Vib. 118(2) (1987)
253-270, eq. 21 for the rotating ring; the decomposition is the spatial
Fourier series of the shape). With ``K`` equally spaced sensors, wave numbers
``n`` and ``K - n`` give the same samples (spatial aliasing), so only
``n <= (K - 1) / 2`` is resolved.

From one sensor turning with the wheel at ``f_w`` (towards ``+theta``), the
fixed-frame wave ``e^{i(omega t -+ n theta)}`` is seen at
``f_rot = f_fixed -+ n f_w`` (the sensor's angle is ``theta = 2 pi f_w t``):
a forward wave appears lower, a backward wave higher. One peak alone does not
tell ``n`` and the direction; a pair of peaks that are the two waves of one
mode (``f_b - f_a = 2 n f_w``) does, and so does a fixed-frame mode list.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..exceptions import InputError

__all__ = ["RotatingPeak", "WaveContent", "resolve_rotating", "wave_content"]


@dataclass(frozen=True)
class WaveContent:
    """Wave content of one mode shape.

    Attributes
    ----------
    wave_number : int
        ``n`` whose pair of waves explains most of the shape.
    forward_share : float
        ``|b|^2 / (|a|^2 + |b|^2)``: 1 pure forward, 0 pure backward, 1/2 standing.
    direction : str
        ``"forward"`` (share >= 3/4), ``"backward"`` (<= 1/4) or ``"standing"``.
    explained : float
        Fraction of ``|psi|^2`` the two waves of ``n`` explain.
    aliases : tuple of int
        Other wave numbers the sensor layout cannot tell from ``n`` (``K -+ n``).
    """

    wave_number: int
    forward_share: float
    direction: str
    explained: float
    aliases: tuple[int, ...]


def _direction(share: float) -> str:
    if share >= 0.75:
        return "forward"
    if share <= 0.25:
        return "backward"
    return "standing"


def wave_content(shape: ArrayLike, angles_deg: ArrayLike, n_max: int | None = None) -> WaveContent:
    """Split a complex mode shape at angles ``theta_j`` into forward and backward waves.

    Parameters
    ----------
    shape : array_like, complex, shape (K,)
        Mode shape at the sensors (radial motion), any scaling.
    angles_deg : array_like, shape (K,)
        Sensor angles in degrees, in the direction of ``+theta``.
    n_max : int, optional
        Largest wave number tried; default ``(K - 1) // 2`` (no aliasing for
        equally spaced sensors).

    Returns
    -------
    WaveContent
    """
    psi = np.asarray(shape, complex).ravel()
    th = np.deg2rad(np.asarray(angles_deg, float).ravel())
    K = psi.size
    if th.size != K:
        raise InputError(f"angles: expected {K} angles (one per channel), got {th.size}")
    if K < 3:
        raise InputError(f"angles: travelling waves need at least 3 points around, got {K}")
    n_hi = (K - 1) // 2 if n_max is None else int(n_max)
    total = float(np.sum(np.abs(psi) ** 2))
    best = (0, 0.5, -1.0)
    for n in range(0, n_hi + 1):
        if n == 0:
            E = np.ones((K, 1), complex)
        else:
            E = np.stack([np.exp(1j * n * th), np.exp(-1j * n * th)], axis=1)
        c, *_ = np.linalg.lstsq(E, psi, rcond=None)
        expl = 1 - float(np.sum(np.abs(psi - E @ c) ** 2)) / total if total > 0 else 0.0
        if expl > best[2] + 1e-9:
            share = 0.5 if n == 0 else float(abs(c[1]) ** 2 / (abs(c[0]) ** 2 + abs(c[1]) ** 2))
            best = (n, share, expl)
    n, share, expl = best
    spacing = np.allclose(np.diff(np.sort(np.mod(th, 2 * np.pi))), 2 * np.pi / K, atol=1e-6)
    aliases = tuple(sorted({K - n, K + n} - {n})) if spacing and n > 0 else ()
    return WaveContent(n, share, _direction(share) if n > 0 else "standing", expl, aliases)


@dataclass(frozen=True)
class RotatingPeak:
    """What a peak seen by a sensor turning with the wheel is in the fixed frame.

    Attributes
    ----------
    frequency_rot_hz : float
        Frequency in the rotating frame.
    resolved : bool
        Whether wave number and direction follow from the data.
    wave_number : int or None
    direction : str or None
        ``"forward"`` or ``"backward"``.
    frequency_fixed_hz : float or None
    candidates : list of (int, str, float)
        Every ``(n, direction, f_fixed)`` the peak could be, when unresolved.
    reason : str
        How it was resolved, or why not.
    """

    frequency_rot_hz: float
    resolved: bool
    wave_number: int | None
    direction: str | None
    frequency_fixed_hz: float | None
    candidates: list[tuple[int, str, float]]
    reason: str


def _candidates(f: float, fw: float, n_max: int) -> list[tuple[int, str, float]]:
    out = []
    for n in range(1, n_max + 1):
        out.append((n, "forward", f + n * fw))
        if f - n * fw > 0:
            out.append((n, "backward", f - n * fw))
    return out


def resolve_rotating(
    frequency_rot_hz: ArrayLike,
    wheel_speed_hz: float,
    *,
    n_max: int = 8,
    fixed_hz: ArrayLike | None = None,
    tol: float = 0.005,
) -> list[RotatingPeak]:
    """Wave number and direction of peaks seen by one sensor turning with the wheel.

    Parameters
    ----------
    frequency_rot_hz : array_like, shape (m,)
        Identified frequencies in the rotating frame (Hz).
    wheel_speed_hz : float
        Wheel rotation frequency (Hz), positive towards ``+theta``.
    n_max : int
        Largest wave number considered.
    fixed_hz : array_like, optional
        Frequencies of the same modes known in the fixed frame (Hz).
    tol : float
        Relative frequency tolerance of a match.

    Returns
    -------
    list of RotatingPeak
        One per peak, in the order given; a peak is resolved from a partner
        (``f_b - f_a = 2 n f_w``, the two waves of one mode at the mean frequency)
        or from one fixed-frame frequency it matches (``f_rot -+ n f_w``); the
        other peaks carry their candidates.
    """
    f = np.asarray(frequency_rot_hz, float).ravel()
    fw = float(wheel_speed_hz)
    if not fw > 0:
        raise InputError(f"wheel speed: expected a positive frequency in Hz, got {wheel_speed_hz}")
    fixed = None if fixed_hz is None else np.asarray(fixed_hz, float).ravel()
    done: dict[int, RotatingPeak] = {}
    for a in range(f.size):
        for b in range(a + 1, f.size):
            lo, hi = (a, b) if f[a] < f[b] else (b, a)
            n = round((f[hi] - f[lo]) / (2 * fw))
            if n < 1 or n > n_max or lo in done or hi in done:
                continue
            if abs((f[hi] - f[lo]) - 2 * n * fw) <= tol * f[hi]:
                fm = 0.5 * (f[lo] + f[hi])
                why = f"pair with {f[hi]:.4g} Hz: 2 n f_w apart, n = {n}"
                done[lo] = RotatingPeak(float(f[lo]), True, n, "forward", fm, [], why)
                why = f"pair with {f[lo]:.4g} Hz: 2 n f_w apart, n = {n}"
                done[hi] = RotatingPeak(float(f[hi]), True, n, "backward", fm, [], why)
    out: list[RotatingPeak] = []
    for j in range(f.size):
        if j in done:
            out.append(done[j])
            continue
        cands = _candidates(float(f[j]), fw, n_max)
        if fixed is not None:
            hits = [c for c in cands if np.any(np.abs(fixed - c[2]) <= tol * c[2])]
            if len(hits) == 1:
                n, d, ff = hits[0]
                out.append(
                    RotatingPeak(float(f[j]), True, n, d, ff, [], "matches a fixed-frame mode")
                )
                continue
        why = "one peak alone: wave number and direction not resolved (no partner 2 n f_w away" + (
            ", no single fixed-frame match)" if fixed is not None else ")"
        )
        out.append(RotatingPeak(float(f[j]), False, None, None, None, cands, why))
    return out
