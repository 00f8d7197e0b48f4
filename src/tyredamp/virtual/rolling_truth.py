"""The exact travelling waves of a rolling ring tyre, in the rotating and the fixed frame.

Each oscillating state-space mode of :class:`~tyredamp.virtual.RotatingRing`
(pole ``p = -sigma + i omega``, ``omega > 0``) is a travelling wave
``e^{i(k theta + omega t)}`` on the tyre, ``k`` its signed wave number from
the Fourier analysis of its shape (radial and tangential power). ``k > 0``
travels against the rotation (backward), ``k < 0`` with it (forward),
``k = 0`` is a standing (breathing or rotation) mode. Seen from a fixed point
(material angle ``theta = phi - Omega t``) the same wave is
``e^{i(k phi + (omega - k Omega) t)}``: the fixed-frame frequency is
``|omega - k Omega| / 2 pi`` (Doppler; :mod:`.rotation`), and its direction
in space is that of ``-k (omega - k Omega)``. The decay rate ``sigma`` is the
same in both frames.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import as_band
from ..exceptions import InputError
from ..mechanics.gyroscopic import StateModes
from .rotation import RotatingRing

__all__ = ["RADIAL_OBSERVABLE", "RollingTruth", "signed_wave_numbers"]

#: Radial share of a wave's shape below which a radial force and radial
#: sensors leave its response 60 dB or more under that of an all-radial wave
#: of the same modal mass and damping (the response scales with the share).
RADIAL_OBSERVABLE = 1e-3


def signed_wave_numbers(
    radial: NDArray[np.complex128], tangential: NDArray[np.complex128]
) -> tuple[NDArray[np.int_], NDArray[np.float64]]:
    """Dominant signed wave number ``k`` of complex ring shapes ``~ e^{i k theta}``.

    Parameters
    ----------
    radial, tangential : ndarray, complex, shape (n_ring, m)
        Radial shapes at the nodes and tangential shapes at the mid-points
        (the half-step shift changes only the phase of each harmonic).

    Returns
    -------
    k : ndarray of int, shape (m,)
        In ``-n_ring/2 .. n_ring/2``.
    purity : ndarray, shape (m,)
        Share of the shape's power in that harmonic.
    """
    n = radial.shape[0]
    power = np.abs(np.fft.fft(radial, axis=0)) ** 2 + np.abs(np.fft.fft(tangential, axis=0)) ** 2
    idx = np.argmax(power, axis=0)
    k = np.where(idx <= n // 2, idx, idx - n)
    total = power.sum(axis=0)
    purity = power[idx, np.arange(power.shape[1])] / np.where(total > 0, total, 1.0)
    return k.astype(int), purity


def _direction(sign: NDArray[np.float64]) -> tuple[str, ...]:
    return tuple("forward" if s > 0 else "backward" if s < 0 else "standing" for s in sign)


@dataclass(frozen=True)
class RollingTruth:
    """The waves of a rolling ring tyre in a band, with both frames (the rolling truth).

    Attributes
    ----------
    speed_kmh : float
        Rolling speed in km/h.
    rotation_hz : float
        Wheel rotation frequency ``Omega / 2 pi`` in Hz.
    band : (float, float)
        Band in Hz; a wave is listed when its rotating- or fixed-frame
        frequency lies in it.
    wave_number : ndarray of int, shape (m,)
        ``n = |k| >= 0``.
    rotating_hz : ndarray, shape (m,)
        Damped frequency in the rotating frame (seen by a sensor in the tyre), Hz.
    fixed_hz : ndarray, shape (m,)
        Frequency seen at a fixed point, ``|omega - k Omega| / 2 pi``, Hz.
    direction : tuple of str
        ``"forward"`` (with the rotation), ``"backward"`` or ``"standing"``,
        relative to the tyre (rotating frame).
    fixed_direction : tuple of str
        The direction of travel seen from a fixed point.
    decay_rate : ndarray, shape (m,)
        ``sigma`` in 1/s (both frames).
    purity : ndarray, shape (m,)
        Share of the shape's power in its harmonic (1 for the perfect ring).
    poles : ndarray, complex, shape (m,)
        Rotating-frame poles in rad/s.
    radial_share : ndarray, shape (m,)
        Share of the shape's power in the radial displacements. A radial road
        force excites a wave in proportion to its radial amplitude and a
        radial sensor sees it in the same proportion, so the wave's response
        there scales with this share: the ``n = 0`` rotation (wind-up) mode
        has none at rest and about 1e-5 at 120 km/h (Coriolis coupling).
    """

    speed_kmh: float
    rotation_hz: float
    band: tuple[float, float]
    wave_number: NDArray[np.int_]
    rotating_hz: NDArray[np.float64]
    fixed_hz: NDArray[np.float64]
    direction: tuple[str, ...]
    fixed_direction: tuple[str, ...]
    decay_rate: NDArray[np.float64]
    purity: NDArray[np.float64]
    poles: NDArray[np.complex128]
    radial_share: NDArray[np.float64]

    @classmethod
    def from_modes(
        cls, ring: RotatingRing, modes: StateModes, band: tuple[float, float] = (0.0, 250.0)
    ) -> RollingTruth:
        """The truth from the state modes of ``ring`` (``ring.system.state_modes()``)."""
        lo, hi = as_band(band)
        n = ring.n_ring
        k, purity = signed_wave_numbers(modes.displacement[:n], modes.displacement[n:])
        w = modes.poles.imag
        w_fix = w - k * ring.omega
        f_rot = w / (2 * np.pi)
        f_fix = np.abs(w_fix) / (2 * np.pi)
        keep = ((f_rot >= lo) & (f_rot <= hi)) | ((f_fix >= lo) & (f_fix <= hi))
        order = np.flatnonzero(keep)[np.argsort(f_fix[keep], kind="stable")]
        rad = np.sum(np.abs(modes.displacement[:n]) ** 2, axis=0)
        tan = np.sum(np.abs(modes.displacement[n:]) ** 2, axis=0)
        return cls(
            speed_kmh=ring.speed_kmh,
            rotation_hz=ring.rotation_hz,
            band=(lo, hi),
            wave_number=np.abs(k[order]),
            rotating_hz=f_rot[order],
            fixed_hz=f_fix[order],
            direction=_direction(-np.sign(k[order])),
            fixed_direction=_direction(-np.sign(k[order] * w_fix[order])),
            decay_rate=-modes.poles.real[order],
            purity=purity[order],
            poles=modes.poles[order],
            radial_share=(rad / np.where(rad + tan > 0, rad + tan, 1.0))[order],
        )

    @classmethod
    def from_ring(
        cls, ring: RotatingRing, band: tuple[float, float] = (0.0, 250.0)
    ) -> RollingTruth:
        """The truth of ``ring`` in ``band`` (Hz)."""
        return cls.from_modes(ring, ring.system.state_modes(), band)

    @property
    def n_waves(self) -> int:
        """Number of listed waves."""
        return int(self.wave_number.size)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``sigma / |p|`` in the rotating frame, shape (m,)."""
        return np.asarray(self.decay_rate / np.abs(self.poles), dtype=np.float64)

    @property
    def fixed_damping_ratio(self) -> NDArray[np.float64]:
        """``sigma / sqrt(sigma^2 + (2 pi f_fixed)^2)``: the damping ratio a fixed observer fits."""
        wf = 2 * np.pi * self.fixed_hz
        return np.asarray(self.decay_rate / np.hypot(self.decay_rate, wf), dtype=np.float64)

    def wave(self, n: int, direction: str) -> dict[str, Any]:
        """The row of :meth:`table` of the lowest wave with wave number ``n`` and ``direction``."""
        rows = [r for r in self.table() if r["wave_number"] == n and r["direction"] == direction]
        if not rows:
            raise InputError(f"no {direction} wave with wave number {n} in {self.band} Hz")
        return min(rows, key=lambda r: r["rotating_hz"])

    def table(self) -> list[dict[str, Any]]:
        """One dict per wave, ascending in fixed-frame frequency (JSON-compatible).

        Keys: ``wave_number``, ``direction``, ``rotating_hz``, ``fixed_hz``,
        ``fixed_direction``, ``damping_ratio`` (rotating frame),
        ``fixed_damping_ratio``, ``decay_rate`` (1/s), ``purity``,
        ``radial_share`` and ``radially_observable``: a radial share of at
        least :data:`RADIAL_OBSERVABLE` (below it the wave's response to a
        radial force at a radial sensor is 60 dB or more under that of a wave
        of the same modal mass and damping whose shape is all radial: under
        the noise of any test here).
        """
        zr, zf = self.damping_ratio, self.fixed_damping_ratio
        return [
            {
                "wave_number": int(self.wave_number[i]),
                "direction": self.direction[i],
                "rotating_hz": float(self.rotating_hz[i]),
                "fixed_hz": float(self.fixed_hz[i]),
                "fixed_direction": self.fixed_direction[i],
                "damping_ratio": float(zr[i]),
                "fixed_damping_ratio": float(zf[i]),
                "decay_rate": float(self.decay_rate[i]),
                "purity": float(self.purity[i]),
                "radial_share": float(self.radial_share[i]),
                "radially_observable": bool(self.radial_share[i] >= RADIAL_OBSERVABLE),
            }
            for i in range(self.n_waves)
        ]

    def format(self) -> str:
        """The table as text (one line per wave)."""
        lines = [
            f"rolling at {self.speed_kmh:g} km/h (rotation {self.rotation_hz:.3f} Hz)",
            "   n  direction  rotating Hz  fixed Hz  seen moving  zeta %",
        ]
        for r in self.table():
            lines.append(
                f"{r['wave_number']:4d}  {r['direction']:9s}  {r['rotating_hz']:11.3f}  "
                f"{r['fixed_hz']:8.3f}  {r['fixed_direction']:11s}  "
                f"{100 * r['damping_ratio']:6.2f}"
            )
        return "\n".join(lines)
