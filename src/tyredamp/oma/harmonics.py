"""Harmonics of the rotation told from structural modes.

A structural mode driven by broadband random forces has a Gaussian response in
its narrow band (kurtosis 3); a harmonic (a wheel order) is a sinusoid there,
whose amplitude distribution is bimodal with kurtosis 1.5 (Brandt, *Noise and
Vibration Analysis*, Wiley 2011, sec. 3.3.4 and 10.6.3; Jacobsen, Andersen &
Brincker, IMAC 2006). The kurtosis of the band-passed record is compared with
3 under its sampling standard error ``sqrt(24 / N_eff)`` (Kendall & Stuart,
*The Advanced Theory of Statistics* vol. 1, eq. 10.5 for a normal sample), with
``N_eff = 2 B T`` independent samples in a band ``B`` over a record of ``T`` s.
A peak elsewhere is called a harmonic at the one-sided 0.1 % level. A peak
within ``tol`` of a multiple of a given wheel speed ``f_w`` needs weaker
evidence, the one-sided level ``alpha = min(5 %, 0.1 % / p)`` with
``p = 2 tol / f_w`` the share of the frequency axis that lies that close to
some order: a mode at a random frequency is near an order with probability
``p`` and then called a harmonic with probability ``alpha``, so at most
``p alpha <= 0.1 %`` of modes are lost, as away from the orders. Where the
orders are sparse (low orders, ``p`` small) the order is evidence and 5 %
suffices; where they are dense (high orders: at order 39 a tolerance of
0.5 % covers 39 % of the axis) being near one says little, and the level
tends to 0.1 %.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "HarmonicTest",
    "band_kurtosis",
    "detect_wheel_speed",
    "harmonic_tests",
    "order_evidence",
]

#: one-sided levels: at most 5 % near a wheel order (module docstring), 0.1 % elsewhere
_ALPHA_ORDER = 0.05
_ALPHA_FREE = 0.001
_Z_FREE = 3.09  # the one-sided normal quantile of _ALPHA_FREE


@dataclass(frozen=True)
class HarmonicTest:
    """Evidence that one identified peak is a harmonic.

    Attributes
    ----------
    kurtosis : float
        Kurtosis of the band-passed record (3 Gaussian, 1.5 a pure sinusoid).
    z : float
        ``(3 - kurtosis) / sqrt(24 / N_eff)``.
    wheel_order : int or None
        The multiple of the wheel speed within the tolerance, if any.
    harmonic : bool
        The verdict.
    """

    kurtosis: float
    z: float
    wheel_order: int | None
    harmonic: bool


def order_evidence(tol_hz: float, wheel_speed_hz: float) -> float:
    """The ``z`` a peak within ``tol_hz`` of a wheel order needs to be called a harmonic.

    The one-sided normal quantile of ``alpha = min(5 %, 0.1 % / p)``,
    ``p = min(1, 2 tol / f_w)`` (module docstring: a mode is lost at most
    0.1 % of the time, near an order or not).

    Parameters
    ----------
    tol_hz : float
        Half-width (Hz) of "near an order".
    wheel_speed_hz : float
        ``f_w > 0``, Hz.

    Returns
    -------
    float
        From 1.645 (sparse orders) to 3.09 (orders covering the axis).
    """
    from scipy.stats import norm

    near = min(1.0, 2.0 * float(tol_hz) / float(wheel_speed_hz))
    return float(norm.isf(min(_ALPHA_ORDER, _ALPHA_FREE / near)))


def band_kurtosis(
    y: NDArray[np.float64], sample_rate: float, f0: float, half_band: float
) -> tuple[float, float]:
    """Kurtosis of ``y`` band-passed to ``f0 +- half_band`` (Hz) and its ``N_eff``.

    The band-pass is an ideal (FFT mask) filter of the whole record.
    """
    n = y.size
    Y = np.fft.rfft(y - y.mean())
    f = np.fft.rfftfreq(n, 1 / sample_rate)
    mask = (f >= f0 - half_band) & (f <= f0 + half_band)
    x = np.fft.irfft(Y * mask, n)
    v = np.mean(x**2)
    kurt = float(np.mean(x**4) / v**2) if v > 0 else float("nan")
    n_eff = max(2.0 * (2 * half_band) * n / sample_rate, 1.0)
    return kurt, n_eff


def harmonic_tests(
    y: NDArray[np.float64],
    sample_rate: float,
    frequency_hz: NDArray[np.float64],
    damping_ratio: NDArray[np.float64],
    shapes: NDArray[np.complex128],
    wheel_speed_hz: float | None = None,
    std_frequency_hz: NDArray[np.float64] | None = None,
) -> list[HarmonicTest]:
    """The harmonic test of every identified peak.

    Parameters
    ----------
    y : ndarray, shape (n_out, n_samples)
        The records the modes were identified from.
    sample_rate : float
        Hz.
    frequency_hz, damping_ratio : ndarray, shape (m,)
    shapes : ndarray, shape (m, n_out)
        The band-passed channel is the one of largest ``|shape|``.
    wheel_speed_hz : float, optional
        Rotation frequency of the wheel (Hz).
    std_frequency_hz : ndarray, shape (m,), optional
        Standard errors of the frequencies (widen the wheel-order tolerance).
    """
    T = y.shape[1] / sample_rate
    out: list[HarmonicTest] = []
    for j, f0 in enumerate(frequency_hz):
        ch = int(np.argmax(np.abs(shapes[j])))
        # half band: the mode's half-power width, wide enough for N_eff >= 200 (a test
        # that can reach its level: the kurtosis is bounded below by 1.5), at most f0 / 5
        half = min(max(2 * float(damping_ratio[j]) * f0, 50.0 / T), 0.2 * f0)
        kurt, n_eff = band_kurtosis(y[ch], sample_rate, float(f0), half)
        z = (3.0 - kurt) / np.sqrt(24.0 / n_eff)
        order = None
        need = _Z_FREE
        if wheel_speed_hz:
            k = round(f0 / wheel_speed_hz)
            sf = 0.0 if std_frequency_hz is None else float(np.nan_to_num(std_frequency_hz[j]))
            tol = max(3 * sf, 0.005 * f0, 2.0 / T)
            if k >= 1 and abs(f0 - k * wheel_speed_hz) <= tol:
                order = k
                need = order_evidence(tol, wheel_speed_hz)
        out.append(HarmonicTest(kurt, float(z), order, bool(z > need)))
    return out


def detect_wheel_speed(harmonic_hz: NDArray[np.float64], tol: float = 0.01) -> float | None:
    """The wheel speed (Hz) that makes most of the harmonics integer multiples of it.

    Candidates are ``f_h / k`` for each harmonic ``f_h`` and ``k = 1..6``; the
    largest candidate explaining the most harmonics (relative tolerance ``tol``)
    wins. ``None`` when fewer than two harmonics agree.
    """
    h = np.sort(np.asarray(harmonic_hz, float))
    if h.size < 2:
        return None
    best, best_n = None, 1
    for fh in h:
        for k in range(1, 7):
            c = fh / k
            m = h / c
            n = int(np.sum(np.abs(m - np.round(m)) <= tol * m))
            if n > best_n or (n == best_n and best is not None and c > best):
                best, best_n = c, n
    return best
