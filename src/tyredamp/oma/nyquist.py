"""The direction of the Nyquist wave of an even number of equally spaced fixed sensors.

With ``K`` (even) fixed sensors every ``360 / K`` degrees the two travelling
waves of ``n = K / 2`` show the same real pattern ``(-1)^k`` at the sensors
(:func:`~tyredamp.oma.spatial.nyquist_wave_number`): the wave-number route
finds the wave, its fixed-frame frequency and damping, but not whether a fixed
observer sees it travel with the rotation or against it. The two hypotheses
put the wave at different frequencies in the tyre's frame (eq. (1) of
:mod:`.frames`, ``f_rot = f_fixed - s n f_w``), so a sensor inside the tyre
tells them apart: a wave has the same decay rate in both frames, and a peak
of the in-tyre sensor with that decay rate at one hypothesis' frequency and
none at the other's settles it. Without such a peak the direction stays
unresolved, and the reason says what would resolve it: an odd number of
sensors, unequal spacing, or an in-tyre sensor that records the wave.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .frames import rotating_pole

__all__ = [
    "DECAY_FACTOR",
    "NyquistCandidate",
    "NyquistResolution",
    "nyquist_candidates",
    "resolve_nyquist",
]

DECAY_FACTOR = 2.0
"""An in-tyre pole supports a hypothesis when its decay rate lies within this
factor of the fixed-frame wave's: the decay rate is the same in both frames
(:func:`.frames.rotating_pole`), and a factor of two holds the scatter of a
damping estimate from a record of 30 s or more at 1-3 % damping (its relative
error, ``1 / sqrt(zeta omega T)`` to first order, is below 0.3 there)."""


@dataclass(frozen=True)
class NyquistCandidate:
    """One hypothesis for the direction of a Nyquist wave.

    Attributes
    ----------
    fixed_direction : str
        As a fixed observer would see it travel: ``"forward"`` (with the
        rotation) or ``"backward"``.
    direction : str
        On the tyre.
    rotating_hz : float
        Natural frequency in the tyre's frame, Hz (:func:`.frames.rotating_pole`).
    rotating_damping_ratio : float
        Damping ratio in the tyre's frame.
    """

    fixed_direction: str
    direction: str
    rotating_hz: float
    rotating_damping_ratio: float


@dataclass(frozen=True)
class NyquistResolution:
    """The direction of a Nyquist wave, or why it is not resolved.

    Attributes
    ----------
    candidate : NyquistCandidate or None
        The hypothesis the in-tyre sensor supports; ``None`` when unresolved.
    candidates : tuple of NyquistCandidate
        Both hypotheses (travelling with the rotation in space first).
    reason : str
        In words, with the frequencies of both hypotheses in the tyre.
    """

    candidate: NyquistCandidate | None
    candidates: tuple[NyquistCandidate, ...]
    reason: str


def nyquist_candidates(
    frequency_hz: float, damping_ratio: float, wave_number: int, wheel_speed_hz: float
) -> tuple[NyquistCandidate, NyquistCandidate]:
    """Both directions a fixed-frame wave of wave number ``n`` could have, in the tyre's frame.

    Eq. (1) of :mod:`.frames` applied to the damped frequency for ``s = +1``
    and ``s = -1`` (:func:`.frames.rotating_pole`).

    Parameters
    ----------
    frequency_hz, damping_ratio : float
        The fixed-frame pole (natural frequency in Hz, damping ratio).
    wave_number : int
        ``n >= 1``.
    wheel_speed_hz : float
        Wheel rotation frequency, Hz.

    Returns
    -------
    forward, backward : NyquistCandidate
        Seen from a fixed point travelling with the rotation, against it.
    """
    out = []
    for fd in ("forward", "backward"):
        fr, zr, d = rotating_pole(frequency_hz, damping_ratio, wave_number, fd, wheel_speed_hz)
        out.append(NyquistCandidate(fd, d, fr, zr))
    return out[0], out[1]


def _supported(
    c: NyquistCandidate,
    f_in: np.ndarray,
    z_in: np.ndarray,
    s_in: np.ndarray,
    std_hz: float,
    others_hz: np.ndarray,
    tol: float,
) -> bool:
    """Whether an in-tyre pole lies at ``c`` with the wave's decay rate, nearer to
    it (in units of the tolerance) than to any other fixed-frame wave's in-tyre frequency
    (an undamped wave, ``sigma = 0``, is matched by frequency alone)."""
    sigma = c.rotating_damping_ratio * c.rotating_hz
    for f, z, s in zip(f_in.tolist(), z_in.tolist(), s_in.tolist(), strict=True):
        err = float(np.hypot(s if np.isfinite(s) else 0.0, std_hz if np.isfinite(std_hz) else 0.0))
        t = max(tol * c.rotating_hz, 3.0 * err)
        d = abs(f - c.rotating_hz) / t
        if d > 1 or (sigma > 0 and not 1 / DECAY_FACTOR <= z * f / sigma <= DECAY_FACTOR):
            continue
        if any(abs(f - o) / (tol * o) < d for o in others_hz.tolist() if o > 0):
            continue
        return True
    return False


def resolve_nyquist(
    frequency_hz: float,
    damping_ratio: float,
    std_frequency_hz: float,
    wave_number: int,
    n_sensors: int,
    wheel_speed_hz: float,
    in_tyre: tuple[ArrayLike, ArrayLike, ArrayLike, tuple[float, float]] | None,
    others_rotating_hz: ArrayLike = (),
    tol: float = 0.01,
) -> NyquistResolution:
    """The direction of a wave of the Nyquist channel, from the in-tyre sensor where it can.

    Each hypothesis (:func:`nyquist_candidates`) is *supported* when an
    in-tyre pole lies within ``tol`` (or three combined standard errors) of
    its in-tyre frequency, with a decay rate within :data:`DECAY_FACTOR` of
    the wave's (equal in both frames: Huang & Soedel 1987, the change of
    frame of :mod:`.frames`), and is not nearer to the in-tyre frequency of
    another identified fixed-frame wave. The direction is resolved when
    exactly one hypothesis is supported; otherwise (neither, both, or no
    in-tyre sensor) it is left unresolved.

    Parameters
    ----------
    frequency_hz, damping_ratio, std_frequency_hz : float
        The fixed-frame pole and its frequency's standard error (NaN if none).
    wave_number : int
        ``K / 2``.
    n_sensors : int
        ``K``.
    wheel_speed_hz : float
        ``> 0``, Hz.
    in_tyre : (f, zeta, std_f, band) or None
        The in-tyre sensor's poles (Hz, damping ratios, frequency standard
        errors in Hz, each shape (m,)) and the band (Hz) they were sought in;
        ``None`` without an in-tyre sensor.
    others_rotating_hz : array_like
        In-tyre frequencies (Hz) of the other identified fixed-frame waves.
    tol : float
        Relative frequency tolerance of a match.

    Returns
    -------
    NyquistResolution
    """
    cands = nyquist_candidates(frequency_hz, damping_ratio, wave_number, wheel_speed_hz)
    where = ", ".join(
        f"{'with' if c.fixed_direction == 'forward' else 'against'} the rotation in space: "
        f"{c.rotating_hz:.4g} Hz in the tyre ({c.direction} on the tyre)"
        for c in cands
    )
    head = (f"wave number {wave_number} is the Nyquist wave number of {n_sensors} equally "
            f"spaced sensors: both of its waves show as one pattern (-1)^k there")  # fmt: skip
    fix = ("; an odd number of sensors, unequal spacing or an in-tyre sensor that records "
           "the wave would resolve its direction")  # fmt: skip
    if in_tyre is None:
        return NyquistResolution(None, cands, f"{head}, and there is no in-tyre sensor to tell "
                                 f"its direction ({where}){fix}")  # fmt: skip
    f_in, z_in, s_in = (np.asarray(a, float).ravel() for a in in_tyre[:3])
    lo, hi = in_tyre[3]
    others = np.asarray(others_rotating_hz, float).ravel()
    ok = [_supported(c, f_in, z_in, s_in, std_frequency_hz, others, tol) for c in cands]
    if sum(ok) == 1:
        c = cands[ok.index(True)]
        other = cands[1 - ok.index(True)]
        return NyquistResolution(c, cands, f"{head}; the in-tyre sensor has a peak with its "
                                 f"decay rate at {c.rotating_hz:.4g} Hz and none at "
                                 f"{other.rotating_hz:.4g} Hz")  # fmt: skip
    outside = [c for c in cands if not lo <= c.rotating_hz <= hi]
    why = (
        "the in-tyre sensor has a peak at both"
        if all(ok)
        else "the in-tyre sensor shows neither"
        + (f" (its band is {lo:.4g}-{hi:.4g} Hz)" if outside else "")
    )
    return NyquistResolution(None, cands, f"{head}; direction unresolved: {why} ({where}){fix}")
