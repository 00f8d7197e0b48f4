"""Periodic chirp excitation for the virtual modal test (pure functions).

A *periodic chirp* here is a Schroeder-phased multisine: equal amplitudes on
every DFT line of one period inside ``[f_start, f_stop]`` and the phases
``phi_j = -pi j (j + 1) / K`` (``j = 0..K-1``, ``K`` lines; Schroeder, IEEE
Trans. Inf. Theory 16(1), 1970). Its instantaneous frequency sweeps linearly
through the band once per period, like a swept sine, but it is exactly
band-limited and periodic, so whole periods give leakage-free spectra with a
flat force spectrum (Pintelon & Schoukens, *System Identification: A
Frequency Domain Approach*, 2nd ed., 2012, section 5.2).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .._validate import check_positive
from ..exceptions import InputError

__all__ = ["chirp_lines", "hadamard_drive_matrix", "periodic_chirp"]


def chirp_lines(
    period_samples: int, sample_rate: float, f_start: float, f_stop: float
) -> NDArray[np.intp]:
    """DFT line numbers ``k`` (frequency ``k fs / P``) excited in ``[f_start, f_stop]``.

    DC is never excited (the first line is at least 1).

    Parameters
    ----------
    period_samples : int
        Samples per period ``P``.
    sample_rate : float
        Sample rate ``fs`` in Hz.
    f_start, f_stop : float
        Band edges in Hz, ``0 <= f_start < f_stop < fs/2``.

    Returns
    -------
    ndarray of int, shape (K,)
        Consecutive line numbers.
    """
    if not isinstance(period_samples, int | np.integer) or period_samples < 4:
        raise InputError(f"period_samples: expected an integer >= 4, got {period_samples!r}")
    fs = check_positive(sample_rate, "sample_rate")
    f0 = check_positive(f_start, "f_start", allow_zero=True)
    f1 = check_positive(f_stop, "f_stop")
    if not f0 < f1 < fs / 2:
        raise InputError(
            f"f_start, f_stop: expected 0 <= f_start < f_stop < sample_rate/2 = {fs / 2:g} Hz, "
            f"got {f0:g} and {f1:g}"
        )
    df = fs / period_samples
    k0 = max(1, math.ceil(f0 / df - 1e-9))
    k1 = math.floor(f1 / df + 1e-9)
    if k1 < k0:
        raise InputError(
            f"f_start, f_stop: the band {f0:g}-{f1:g} Hz holds no line of spacing {df:g} Hz"
        )
    return np.arange(k0, k1 + 1, dtype=np.intp)


def periodic_chirp(
    period_samples: int,
    sample_rate: float,
    f_start: float = 0.0,
    f_stop: float = 200.0,
    *,
    rms: float = 1.0,
    oversample: int = 1,
) -> NDArray[np.float64]:
    """One period of a periodic chirp (Schroeder multisine) over ``[f_start, f_stop]``.

    Parameters
    ----------
    period_samples : int
        Samples per period ``P`` at ``sample_rate``.
    sample_rate : float
        Sample rate in Hz.
    f_start, f_stop : float
        Band in Hz (see :func:`chirp_lines`).
    rms : float
        RMS value of the signal (any unit, e.g. N), > 0.
    oversample : int
        Return the same band-limited signal sampled ``oversample`` times
        faster (``P * oversample`` samples); ``x[::oversample]`` is the signal
        at ``sample_rate``.

    Returns
    -------
    ndarray, shape (P * oversample,)
        One period; repeat it for several periods.
    """
    lines = chirp_lines(period_samples, sample_rate, f_start, f_stop)
    a = check_positive(rms, "rms")
    if not isinstance(oversample, int | np.integer) or oversample < 1:
        raise InputError(f"oversample: expected an integer >= 1, got {oversample!r}")
    n = int(period_samples) * int(oversample)
    k = lines.size
    j = np.arange(k)
    spec = np.zeros(n // 2 + 1, dtype=complex)
    spec[lines] = np.exp(-1j * np.pi * j * (j + 1) / k)
    x = np.fft.irfft(spec, n=n)
    return x * (a / np.sqrt(np.mean(x**2)))


def hadamard_drive_matrix(n_inputs: int) -> NDArray[np.float64]:
    """Signs of each input in each run of an orthogonal multi-input test.

    Rows are runs, columns inputs: the first ``n_inputs`` columns of the
    Sylvester-Hadamard matrix of order ``2^ceil(log2 n_inputs)``. Every input
    plays the same periodic chirp times its sign, so the input cross-spectral
    matrix summed over the runs is ``n_runs |X_k|^2 I`` at every line: the
    best-conditioned multi-input estimate ("orthogonal multisines",
    Dobrowiecki, Schoukens & Guillaume, IEEE Trans. Instrum. Meas. 55(6), 2006).

    Parameters
    ----------
    n_inputs : int
        Number of simultaneously driven inputs, >= 1.

    Returns
    -------
    ndarray, shape (n_runs, n_inputs)
        Entries +1 or -1.
    """
    if not isinstance(n_inputs, int | np.integer) or n_inputs < 1:
        raise InputError(f"n_inputs: expected an integer >= 1, got {n_inputs!r}")
    h = np.ones((1, 1))
    while h.shape[0] < n_inputs:
        h = np.block([[h, h], [h, -h]])
    return h[:, :n_inputs]
