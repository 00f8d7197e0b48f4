"""Excitation signals and windows: spectra, periodicity, RMS, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp import InputError
from tyredamp.signal import (
    amplitude_spectrum,
    band_lines,
    burst_random,
    exponential_window,
    periodic_chirp,
    pseudo_random,
    segment_window,
    swept_chirp,
)


def test_amplitude_spectrum_of_a_sine() -> None:
    fs, n = 100.0, 400
    t = np.arange(n) / fs
    x = 0.5 + 2.0 * np.sin(2 * np.pi * 7.5 * t)
    f, a = amplitude_spectrum(x, fs)
    assert_allclose(f[30], 7.5)
    # a sine of amplitude 2 on a DFT line gives 2 there, DC gives its mean
    assert_allclose(a[30], 2.0, rtol=1e-12)
    assert_allclose(a[0], 0.5, rtol=1e-12)
    assert_allclose(np.delete(a, [0, 30]), 0.0, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    period=st.integers(64, 2048),
    lo=st.floats(0.0, 20.0),
    width=st.floats(5.0, 25.0),
    rms=st.floats(0.1, 100.0),
)
def test_pseudo_random_flat_band_spectrum(seed, period, lo, width, rms) -> None:
    fs = 100.0
    exc = pseudo_random(fs, period, (lo, lo + width), rms=rms, n_periods=3, rng=seed)
    lines = band_lines(fs, period, (lo, lo + width))
    assert exc.n_samples == 3 * period
    assert_allclose(exc.signal[:period], exc.signal[2 * period :], rtol=0, atol=0)  # periodic
    assert exc.rms == pytest.approx(rms, rel=1e-12)
    _f, a = exc.amplitude_spectrum()
    # flat: every band line carries rms * sqrt(2 / n_lines); nothing outside the band
    assert_allclose(a[lines], rms * np.sqrt(2.0 / lines.size), rtol=1e-9)
    assert_allclose(np.delete(a, lines), 0.0, atol=1e-9 * rms)
    assert exc.meta()["period_samples"] == period


def test_pseudo_random_reproducible_by_seed() -> None:
    a = pseudo_random(200.0, 512, (5, 50), rng=7).signal
    b = pseudo_random(200.0, 512, (5, 50), rng=np.random.default_rng(7)).signal
    assert_allclose(a, b, rtol=0, atol=0)


def test_periodic_chirp() -> None:
    fs, p = 512.0, 1024
    exc = periodic_chirp(fs, p, (10.0, 100.0), rms=3.0, n_periods=2)
    assert exc.rms == pytest.approx(3.0, rel=2e-3)  # sine of amplitude 3 sqrt(2), whole period
    assert_allclose(exc.signal[:p], exc.signal[p:], rtol=0, atol=0)
    f, a = exc.amplitude_spectrum()
    inband = (f >= 15) & (f <= 95)
    # a linear chirp spreads its power nearly evenly over the swept band
    flat = a[inband]
    assert flat.max() / flat.min() < 2.5
    assert a[f > 160].max() < 0.05 * flat.mean()
    # phase continuous over the period wrap (k1 + k2 even): no jump at the seam
    x = np.concatenate([exc.signal[p - 2 : p], exc.signal[:2]])
    assert np.max(np.abs(np.diff(x))) < 2 * np.pi * 100 / fs * 3 * np.sqrt(2) * 1.01


def test_swept_chirp_and_burst_random() -> None:
    exc = swept_chirp(1000.0, 5000, (5.0, 200.0), rms=1.0, taper=0.1)
    assert exc.period_samples is None
    assert exc.signal[0] == 0.0
    assert np.max(np.abs(exc.signal)) <= np.sqrt(2) + 1e-12
    b = burst_random(1000.0, 1000, (10.0, 100.0), rms=2.0, burst_fraction=0.3, n_records=3, rng=1)
    rec = b.signal.reshape(3, 1000)
    assert_allclose(rec[:, 300:], 0.0, atol=0)  # silent after the burst
    assert_allclose(np.sqrt(np.mean(rec[:, :300] ** 2, axis=1)), 2.0, rtol=1e-12)
    assert not np.allclose(rec[0], rec[1])  # new noise in every record
    assert b.meta()["record_samples"] == 1000
    assert b.meta()["band_hz"] == [10.0, 100.0]


def test_windows() -> None:
    w, tau = exponential_window(101, 100.0, 0.05)
    assert w[0] == 1.0
    assert w[-1] == pytest.approx(0.05, rel=1e-12)
    assert tau == pytest.approx(1.0 / np.log(20.0))
    assert_allclose(segment_window("rect", 8), 1.0)
    assert segment_window("hann", 8)[0] == 0.0


def test_errors() -> None:
    with pytest.raises(InputError, match="Nyquist"):
        pseudo_random(100.0, 256, (10.0, 60.0))
    with pytest.raises(InputError, match="no DFT line"):
        pseudo_random(100.0, 16, (1.0, 2.0))
    with pytest.raises(InputError, match="period_samples"):
        pseudo_random(100.0, 100.5, (1.0, 20.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="band"):
        periodic_chirp(100.0, 256, (20.0, 10.0))
    with pytest.raises(InputError, match="burst_fraction"):
        burst_random(100.0, 256, (1.0, 20.0), burst_fraction=0.0)
    with pytest.raises(InputError, match="window"):
        segment_window("nonsense", 16)
    with pytest.raises(InputError, match="end_value"):
        exponential_window(16, 10.0, 0.0)
