"""Excitation signals for test planning, with their amplitude spectra.

Every generator is a function of the sample rate, the length (period or
record), the frequency band, the RMS force and (for random signals) a random
generator, and returns an :class:`Excitation`: the force history in N and the
acquisition record the FRF estimators use (``period_samples`` for periodic
signals, ``record_samples`` for burst random, ``band_hz``), so that
``TimeData(..., acquisition=excitation.acquisition())`` selects the right
estimation method.

Signals
-------
* :func:`pseudo_random`: multisine with equal amplitudes on every DFT line of
  the band and random phases; periodic, exactly zero outside the band. With
  the cyclic estimator the FRF is leakage free.
* :func:`periodic_chirp`: one linear sweep per period, repeated.
* :func:`swept_chirp`: one linear sweep over the whole record (not periodic),
  with cosine tapers at both ends.
* :func:`burst_random`: band-limited random noise switched on for the first
  part of each record and off for the rest, so that the response decays
  inside the record (rectangular window, no leakage when it has decayed).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.signal
from numpy.typing import ArrayLike, NDArray

from .._validate import as_band, as_finite, check_positive
from ..exceptions import InputError
from ..timedata import Acquisition

__all__ = [
    "Excitation",
    "amplitude_spectrum",
    "band_lines",
    "burst_random",
    "periodic_chirp",
    "pseudo_random",
    "schroeder_multisine",
    "swept_chirp",
]


@dataclass(frozen=True, eq=False)
class Excitation:
    """A force history for a test.

    Attributes
    ----------
    signal : ndarray, shape (n_samples,)
        Force in N.
    sample_rate : float
        Samples per second (Hz).
    band : (float, float)
        Nominal excited band in Hz.
    name : str
        Generator name (``"pseudo_random"`` ...).
    period_samples : int or None
        Period of a periodic signal.
    record_samples : int or None
        Record length of a burst signal.
    """

    signal: NDArray[np.float64]
    sample_rate: float
    band: tuple[float, float]
    name: str
    period_samples: int | None = None
    record_samples: int | None = None

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.signal.size)

    @property
    def rms(self) -> float:
        """RMS of the signal in N."""
        return float(np.sqrt(np.mean(self.signal**2)))

    def meta(self) -> dict[str, Any]:
        """The acquisition fields as a dict (legacy form of :meth:`acquisition`)."""
        out: dict[str, Any] = {"excitation": self.name, "band_hz": list(self.band)}
        if self.period_samples is not None:
            out["period_samples"] = self.period_samples
        if self.record_samples is not None:
            out["record_samples"] = self.record_samples
        return out

    def acquisition(self) -> Acquisition:
        """The acquisition record for a test driven by this signal (estimator hints)."""
        return Acquisition(
            period_samples=self.period_samples,
            record_samples=self.record_samples,
            band_hz=self.band,
            excitation=self.name,
        )

    def amplitude_spectrum(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Amplitude spectrum of one period/record; see :func:`amplitude_spectrum`."""
        length = self.period_samples or self.record_samples
        return amplitude_spectrum(self.signal, self.sample_rate, length)


def amplitude_spectrum(
    signal: ArrayLike, sample_rate: float, segment_samples: int | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Single-sided amplitude spectrum (rectangular window).

    The amplitude at line ``k > 0`` is ``2 |X_k| / L`` (the amplitude of the
    sinusoid on that line), at 0 Hz ``|X_0| / L``, with ``X`` the DFT of a
    segment of ``L`` samples. With ``segment_samples`` the spectra of the
    consecutive whole segments are averaged in power (RMS over segments).

    Parameters
    ----------
    signal : array_like, shape (n_samples,)
        Signal, in its unit (N for forces).
    sample_rate : float
        Samples per second (Hz).
    segment_samples : int, optional
        Segment (period or record) length; default the whole signal.

    Returns
    -------
    frequency : ndarray, shape (L // 2 + 1,)
        Hz.
    amplitude : ndarray, shape (L // 2 + 1,)
        In the signal's unit.
    """
    x = as_finite(signal, "signal", ndim=1)
    fs = check_positive(sample_rate, "sample_rate")
    seg = x.size if segment_samples is None else int(segment_samples)
    if seg < 2 or seg > x.size:
        raise InputError(f"segment_samples: expected 2..{x.size}, got {segment_samples!r}")
    n_seg = x.size // seg
    xs = x[: n_seg * seg].reshape(n_seg, seg)
    spec = np.fft.rfft(xs, axis=1)
    amp = np.sqrt(np.mean(np.abs(spec) ** 2, axis=0)) * (2.0 / seg)
    amp[0] /= 2
    if seg % 2 == 0:
        amp[-1] /= 2
    return np.arange(amp.size) * (fs / seg), amp


def band_lines(sample_rate: float, n_samples: int, band: tuple[float, float]) -> NDArray[np.intp]:
    """DFT line indices ``k`` with ``band[0] <= k fs / n <= band[1]``, ``0 < k < n/2``.

    Parameters
    ----------
    sample_rate : float
        Hz.
    n_samples : int
        Period or record length.
    band : (float, float)
        Hz.
    """
    fs = check_positive(sample_rate, "sample_rate")
    n = _length(n_samples, "n_samples")
    lo, hi = _band(band, fs)
    k = np.arange(1, (n + 1) // 2)  # exclude DC and Nyquist
    f = k * fs / n
    sel = k[(f >= lo) & (f <= hi)]
    if sel.size == 0:
        raise InputError(
            f"band: no DFT line of spacing {fs / n:g} Hz in [{lo:g}, {hi:g}] Hz; "
            "lengthen the period or widen the band"
        )
    return sel


def pseudo_random(
    sample_rate: float,
    period_samples: int,
    band: tuple[float, float],
    rms: float = 1.0,
    n_periods: int = 1,
    rng: np.random.Generator | int | None = None,
) -> Excitation:
    """Multisine with a flat amplitude spectrum on the band and random phases.

    Parameters
    ----------
    sample_rate : float
        Hz.
    period_samples : int
        Samples per period; line spacing ``sample_rate / period_samples``.
    band : (float, float)
        Excited band in Hz (lines inside it, DC and Nyquist excluded).
    rms : float
        RMS force in N.
    n_periods : int
        Periods in the returned signal (the same period repeated).
    rng : numpy Generator, int or None
        Random phases; an int seeds a new generator, None draws fresh entropy.

    Returns
    -------
    Excitation
        Periodic; ``amplitude_spectrum()`` is ``rms * sqrt(2 / n_lines)`` on
        each band line and 0 elsewhere.
    """
    g = np.random.default_rng(rng)
    return _multisine(
        sample_rate,
        period_samples,
        band,
        rms,
        n_periods,
        lambda k: 2.0 * np.pi * g.random(k),
        "pseudo_random",
    )


def schroeder_multisine(
    sample_rate: float,
    period_samples: int,
    band: tuple[float, float],
    rms: float = 1.0,
    n_periods: int = 1,
) -> Excitation:
    """Flat-spectrum multisine with Schroeder phases (a band-limited periodic chirp).

    Equal amplitudes on every DFT line of one period in the band and phases
    ``phi_j = -pi j (j + 1) / K`` (``j = 0..K-1``, ``K`` lines; Schroeder, IEEE
    Trans. Inf. Theory 16(1), 1970): the instantaneous frequency sweeps the
    band once per period, and the spectrum is exactly flat on the band and
    zero elsewhere.

    Parameters
    ----------
    sample_rate : float
        Hz.
    period_samples : int
        Samples per period ``P`` (>= 4); line spacing ``sample_rate / P``.
    band : (float, float)
        Excited band in Hz: every DFT line inside it (DC and Nyquist
        excluded, :func:`band_lines`).
    rms : float
        RMS in N, > 0.
    n_periods : int
        Periods in the returned signal (the same period repeated), >= 1.

    Returns
    -------
    Excitation
        ``name="schroeder_multisine"``, ``period_samples=P``. Generated at a
        multiple ``r`` of a rate (``r P`` samples per period), ``x[::r]`` is
        the same signal at the lower rate, sample for sample.
    """

    def phases(k: int) -> NDArray[np.float64]:
        j = np.arange(k)
        return -np.pi * j * (j + 1) / k

    return _multisine(
        sample_rate, period_samples, band, rms, n_periods, phases, "schroeder_multisine", 4
    )


def _multisine(
    sample_rate: float,
    period_samples: int,
    band: tuple[float, float],
    rms: float,
    n_periods: int,
    phases: Callable[[int], NDArray[np.float64]],
    name: str,
    min_period: int = 2,
) -> Excitation:
    """Equal amplitudes on the band lines with ``phases(n_lines)``, scaled to ``rms``."""
    fs = check_positive(sample_rate, "sample_rate")
    p = _length(period_samples, "period_samples", minimum=min_period)
    npr = _length(n_periods, "n_periods", minimum=1)
    a = check_positive(rms, "rms")
    lines = band_lines(fs, p, band)
    spec = np.zeros(p // 2 + 1, dtype=complex)
    spec[lines] = np.exp(1j * phases(lines.size))
    one = np.fft.irfft(spec, p)
    one *= a / np.sqrt(np.mean(one**2))
    return Excitation(np.tile(one, npr), fs, _band(band, fs), name, period_samples=p)


def periodic_chirp(
    sample_rate: float,
    period_samples: int,
    band: tuple[float, float],
    rms: float = 1.0,
    n_periods: int = 1,
) -> Excitation:
    """Linear sweep from ``band[0]`` to ``band[1]`` in every period.

    The sine amplitude is ``sqrt(2) * rms`` (so the RMS is ``rms``). The band
    edges are moved to the nearest DFT lines with an even sum of line indices
    so that the phase is continuous from one period to the next.

    Parameters
    ----------
    sample_rate : float
        Hz.
    period_samples : int
        Samples per period.
    band : (float, float)
        Sweep band in Hz.
    rms : float
        RMS force in N.
    n_periods : int
        Periods in the returned signal.

    Returns
    -------
    Excitation
    """
    fs = check_positive(sample_rate, "sample_rate")
    p = _length(period_samples, "period_samples")
    a = check_positive(rms, "rms")
    npr = _length(n_periods, "n_periods", minimum=1)
    lines = band_lines(fs, p, band)
    k1, k2 = int(lines[0]), int(lines[-1])
    if (k1 + k2) % 2:
        k2 = k2 - 1 if k2 - 1 > k1 else k2 + 1
    t_per = p / fs
    t = np.arange(p) / fs
    f1, f2 = k1 / t_per, k2 / t_per
    one = np.sqrt(2.0) * a * scipy.signal.chirp(t, f1, t_per, f2, method="linear", phi=-90)
    return Excitation(np.tile(one, npr), fs, (f1, f2), "periodic_chirp", period_samples=p)


def swept_chirp(
    sample_rate: float,
    n_samples: int,
    band: tuple[float, float],
    rms: float = 1.0,
    taper: float = 0.05,
) -> Excitation:
    """One linear sweep over the whole record, cosine-tapered at both ends.

    Parameters
    ----------
    sample_rate : float
        Hz.
    n_samples : int
        Record length.
    band : (float, float)
        Sweep band in Hz.
    rms : float
        Sine amplitude ``sqrt(2) * rms`` in N (the RMS before tapering).
    taper : float
        Fraction of the record in each end taper, in [0, 0.5).

    Returns
    -------
    Excitation
        Not periodic: estimate with the Welch or transient method.
    """
    fs = check_positive(sample_rate, "sample_rate")
    n = _length(n_samples, "n_samples")
    a = check_positive(rms, "rms")
    lo, hi = _band(band, fs)
    if not 0.0 <= float(taper) < 0.5:
        raise InputError(f"taper: expected a fraction in [0, 0.5), got {taper!r}")
    t = np.arange(n) / fs
    x = np.sqrt(2.0) * a * scipy.signal.chirp(t, lo, t[-1], hi, method="linear", phi=-90)
    nt = round(taper * n)
    if nt > 0:
        ramp = 0.5 * (1 - np.cos(np.pi * np.arange(nt) / nt))
        x[:nt] *= ramp
        x[n - nt :] *= ramp[::-1]
    return Excitation(x, fs, (lo, hi), "swept_chirp")


def burst_random(
    sample_rate: float,
    record_samples: int,
    band: tuple[float, float],
    rms: float = 1.0,
    burst_fraction: float = 0.5,
    n_records: int = 1,
    rng: np.random.Generator | int | None = None,
) -> Excitation:
    """Band-limited random bursts, one per record, each followed by silence.

    Each record holds new Gaussian noise with a flat expected spectrum on the
    band lines, multiplied by a gate that is 1 for the first
    ``burst_fraction`` of the record and 0 after, with cosine fades of a
    twentieth of the burst at both ends (limits the spectrum the gate adds
    outside the band).

    Parameters
    ----------
    sample_rate : float
        Hz.
    record_samples : int
        Samples per record (the estimator's segment).
    band : (float, float)
        Hz.
    rms : float
        RMS force over the burst part, N.
    burst_fraction : float
        In (0, 1].
    n_records : int
        Records in the returned signal.
    rng : numpy Generator, int or None

    Returns
    -------
    Excitation
        ``record_samples`` set, so the transient (rectangular) method is used.
    """
    fs = check_positive(sample_rate, "sample_rate")
    n = _length(record_samples, "record_samples")
    a = check_positive(rms, "rms")
    nr = _length(n_records, "n_records", minimum=1)
    bf = float(burst_fraction)
    if not 0.0 < bf <= 1.0:
        raise InputError(f"burst_fraction: expected a fraction in (0, 1], got {burst_fraction!r}")
    lines = band_lines(fs, n, band)
    g = np.random.default_rng(rng)
    on = max(4, round(bf * n))
    fade = max(1, on // 20)
    gate = np.zeros(n)
    gate[:on] = 1.0
    ramp = 0.5 * (1 - np.cos(np.pi * (np.arange(1, fade + 1) / (fade + 1))))
    gate[:fade] = ramp
    if on < n:
        gate[on - fade : on] = ramp[::-1]
    out = np.empty(nr * n)
    for r in range(nr):
        spec = np.zeros(n // 2 + 1, dtype=complex)
        spec[lines] = g.normal(size=lines.size) + 1j * g.normal(size=lines.size)
        x = np.fft.irfft(spec, n) * gate
        x *= a / np.sqrt(np.mean(x[:on] ** 2))
        out[r * n : (r + 1) * n] = x
    return Excitation(out, fs, _band(band, fs), "burst_random", record_samples=n)


def _length(v: Any, name: str, minimum: int = 2) -> int:
    if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {v!r}")
    return int(v)


def _band(band: tuple[float, float], fs: float) -> tuple[float, float]:
    lo, hi = as_band(band)
    if hi > fs / 2:
        raise InputError(
            f"band (--band): upper edge {hi:g} Hz is above the Nyquist frequency {fs / 2:g} Hz"
        )
    return lo, hi
