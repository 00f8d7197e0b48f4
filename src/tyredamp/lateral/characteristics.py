"""Frequency characteristics of the proposed hysteretic model (spec eq. 38-40, Figure 7).

With ``r = h/K`` and ``omega0 C_r = K`` (the corner frequency, eq. 38) the
model receptance is ``K Y = 1/(1 + i r) - i``, so

* against the high-frequency asymptote ``1/(K + i h)`` the amplitude ratio
  differs by ``10 log10(2 + 2 r + r^2)`` dB (eq. 39);
* against the low-frequency asymptote ``1/(i omega C_r)`` by
  ``10 log10((2 + 2 r + r^2)/(1 + r^2))`` dB (smaller, so eq. 39 is the
  larger of the two asymptote errors);
* against the Maxwell model (``k = K``, ``c = C_r``) by
  ``10 log10[(1 + r + r^2/2)/(1 + r^2)]`` dB (eq. 40).

:func:`corner_differences` evaluates these from the model curves; the
closed forms are :func:`delta_ar_asymptote` and :func:`delta_ar_maxwell`.
Amplitude ratios are in dB re 1 m/N: ``20 log10(|Y| / (1 m/N))``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import InputError
from .models import HystereticModel
from .response import as_freq

__all__ = [
    "CornerDifferences",
    "Figure7Curves",
    "amplitude_ratio_db",
    "corner_differences",
    "corner_frequency",
    "delta_ar_asymptote",
    "delta_ar_maxwell",
    "figure7_curves",
]

FloatArray = NDArray[np.float64]


def corner_frequency(K: float, C_r: float) -> float:
    """Corner frequency ``f0 = K / (2 pi C_r)`` in Hz (spec eq. 38).

    Parameters
    ----------
    K : float
        Carcass stiffness, N/m (> 0).
    C_r : float
        Tyre-road damping, N s/m (> 0).
    """
    return check_positive(K, "K") / (2.0 * np.pi * check_positive(C_r, "C_r"))


def _ratio(h_over_K: ArrayLike) -> FloatArray:
    r = as_finite(h_over_K, "h_over_K", dtype=float)
    if np.any(r < 0):
        raise InputError("h_over_K: expected values >= 0")
    return r


def delta_ar_asymptote(h_over_K: ArrayLike) -> FloatArray:
    """Closed form of spec eq. 39: ``10 log10(2 + 2 r + r^2)`` dB, ``r = h/K``.

    Amplitude-ratio difference at ``f0`` between the model and its
    high-frequency asymptote ``1/(K + i h)``; 3.874 dB at ``r = 0.2``.
    """
    r = _ratio(h_over_K)
    return np.asarray(10.0 * np.log10(2.0 + 2.0 * r + r**2), dtype=float)


def delta_ar_maxwell(h_over_K: ArrayLike) -> FloatArray:
    """Closed form of spec eq. 40: ``10 log10[(1 + r + r^2/2)/(1 + r^2)]`` dB.

    Amplitude-ratio difference at ``f0`` between the model and the Maxwell
    model ``k = K``, ``c = C_r``; 0.6933 dB at ``r = 0.2`` (paper prints 0.694).
    """
    r = _ratio(h_over_K)
    return np.asarray(10.0 * np.log10((1.0 + r + r**2 / 2.0) / (1.0 + r**2)), dtype=float)


def amplitude_ratio_db(receptance: ArrayLike) -> FloatArray:
    """Amplitude ratio ``20 log10 |Y|`` in dB re 1 m/N."""
    y = as_finite(receptance, "receptance", dtype=complex)
    mag = np.abs(y)
    if np.any(mag == 0):
        raise InputError("receptance: amplitude 0 has no dB value")
    return np.asarray(20.0 * np.log10(mag), dtype=float)


@dataclass(frozen=True)
class CornerDifferences:
    """Amplitude-ratio differences at the corner frequency, from the model curves.

    Attributes
    ----------
    f0 : float
        Corner frequency, Hz (eq. 38).
    vs_high_asymptote : float
        ``AR_model - AR(1/(K + i h))`` at ``f0``, dB (eq. 39).
    vs_low_asymptote : float
        ``AR_model - AR(1/(i omega C_r))`` at ``f0``, dB.
    vs_maxwell : float
        ``AR_model - AR_Maxwell`` at ``f0``, dB (eq. 40).
    """

    f0: float
    vs_high_asymptote: float
    vs_low_asymptote: float
    vs_maxwell: float

    @property
    def vs_asymptotes(self) -> float:
        """The larger of the two asymptote differences (the quantity of eq. 39), dB."""
        return max(self.vs_high_asymptote, self.vs_low_asymptote)


def corner_differences(model: HystereticModel) -> CornerDifferences:
    """Evaluate the curves of ``model`` at its corner frequency (spec eq. 38-40).

    Parameters
    ----------
    model : HystereticModel
        Proposed model with finite ``C_r``.

    Returns
    -------
    CornerDifferences
    """
    if not isinstance(model, HystereticModel):
        raise InputError(f"model: expected a HystereticModel, got {type(model).__name__}")
    if not np.isfinite(model.C_r):
        raise InputError("model: C_r = inf has no corner frequency")
    f0 = model.corner_frequency()
    f = np.array([f0])
    ar = amplitude_ratio_db(model.receptance(f))[0]
    hi = amplitude_ratio_db(model.high_frequency_asymptote(f))[0]
    lo = amplitude_ratio_db(model.low_frequency_asymptote(f))[0]
    mx = amplitude_ratio_db(model.maxwell().receptance(f))[0]
    return CornerDifferences(
        f0=f0,
        vs_high_asymptote=float(ar - hi),
        vs_low_asymptote=float(ar - lo),
        vs_maxwell=float(ar - mx),
    )


@dataclass(frozen=True, eq=False)
class Figure7Curves:
    """Data of the paper's Figure 7 (all amplitude ratios in dB re 1 m/N).

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Hz.
    model_db : ndarray, shape (n,)
        Proposed model.
    low_asymptote_db, high_asymptote_db : ndarray, shape (n,)
        ``1/(i omega C_r)`` and ``1/(K + i h)``.
    maxwell_db : ndarray, shape (n,)
        Maxwell model ``k = K``, ``c = C_r`` (for eq. 40).
    f0 : float
        Corner frequency, Hz.
    model : HystereticModel
        The parameters used.
    """

    frequency: FloatArray
    model_db: FloatArray
    low_asymptote_db: FloatArray
    high_asymptote_db: FloatArray
    maxwell_db: FloatArray
    f0: float
    model: HystereticModel


def figure7_curves(
    K: float = 260e3,
    h: float = 20e3,
    C_r: float = 300e3,
    freq_hz: ArrayLike | None = None,
) -> Figure7Curves:
    """Amplitude ratio of the proposed model with its asymptotes (paper Figure 7).

    Parameters
    ----------
    K : float
        Carcass stiffness, N/m (default 260 kN/m, Figure 7).
    h : float
        Hysteretic damping, N/m (default 20 kN/m).
    C_r : float
        Tyre-road damping, N s/m (default 300 kN s/m).
    freq_hz : array_like, optional
        Frequencies in Hz (> 0); default 401 log-spaced points 0.01-100 Hz.

    Returns
    -------
    Figure7Curves
    """
    m = HystereticModel(K=K, h=h, C_r=C_r)
    f = np.logspace(-2, 2, 401) if freq_hz is None else as_freq(freq_hz)
    f = np.atleast_1d(f)
    if np.any(f == 0):
        raise InputError("freq_hz: expected frequencies > 0 Hz (the model is infinite at 0)")
    return Figure7Curves(
        frequency=f,
        model_db=amplitude_ratio_db(m.receptance(f)),
        low_asymptote_db=amplitude_ratio_db(m.low_frequency_asymptote(f)),
        high_asymptote_db=amplitude_ratio_db(m.high_frequency_asymptote(f)),
        maxwell_db=amplitude_ratio_db(m.maxwell().receptance(f)),
        f0=m.corner_frequency(),
        model=m,
    )
