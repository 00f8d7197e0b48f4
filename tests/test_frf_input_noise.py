"""The relative input-noise variance of an FRF (FRF.input_noise): the data object and
its estimate from the periods of a cyclic test (signal.cyclic_variance)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import InputError, ShapeError
from tyredamp.frf import FRF
from tyredamp.signal import estimate_frf
from tyredamp.signal.cyclic_variance import cyclic_input_noise
from tyredamp.timedata import TimeData

B, A = [0.5, 0.3, -0.2, 0.1], [1.0, -0.5, 0.3]  # a digital test system


def test_input_noise_is_validated_read_only_and_carried() -> None:
    rng = np.random.default_rng(0)
    f = np.arange(1.0, 11.0)
    h = rng.normal(size=(2, 1, 10)) + 1j * rng.normal(size=(2, 1, 10))
    r = rng.random((1, 10))
    frf = FRF(f, h, variance=rng.random((2, 1, 10)), input_noise=r)
    assert frf.input_noise is not None
    with pytest.raises(ValueError, match="read-only"):
        frf.input_noise[0, 0] = 1.0
    with pytest.raises(ShapeError, match="input_noise"):
        FRF(f, h, input_noise=np.ones((1, 9)))
    with pytest.raises(InputError, match="input_noise"):
        FRF(f, h, input_noise=-r)
    assert_array_equal(FRF(f, h, input_noise=r[0]).input_noise, r)  # (n_freq,) for one input
    assert_array_equal(frf.band(3.0, 6.0).input_noise, r[:, 2:6])
    assert_array_equal(frf.select(outputs=[1]).input_noise, r)  # the same force
    # relative to H: unchanged by a change of kind
    assert_array_equal(frf.to("accelerance").input_noise, r)
    assert frf.with_H(frf.H * 2).input_noise is None
    assert FRF(f, h).input_noise is None


def test_cyclic_input_noise_is_the_sample_variance_of_the_periods_force() -> None:
    """``r = var_k(X_k) / (n |Xbar|^2)`` with the sample variance (``n - 1``) of the
    periods' force spectra, computed here by np.var; 12 periods give ``L = 1`` (no
    line averaging). Same arithmetic in another order: rtol 1e-10."""
    rng = np.random.default_rng(3)
    n, n_f, c = 12, 5, 0.37
    xk = 2.0 + 0.1 * (rng.normal(size=(n, n_f)) + 1j * rng.normal(size=(n, n_f)))
    got = cyclic_input_noise(
        c * np.mean(np.abs(xk) ** 2, axis=0), xk.mean(axis=0), np.full(n_f, c), n
    )
    assert got is not None
    want = np.var(xk, axis=0, ddof=1) / (n * np.abs(xk.mean(axis=0)) ** 2)
    assert_allclose(got[0], want, rtol=1e-10)
    assert cyclic_input_noise(np.ones(3), np.ones(3, complex), np.ones(3), 1) is None


def test_cyclic_estimate_carries_the_force_part_of_its_variance() -> None:
    """With noise on the force alone and the response noise-free in steady state, the
    whole errors-in-variables variance is the force's: ``V = r |H|^2`` (module
    docstring of signal.cyclic_variance), whatever the line averaging; the responses'
    noise alone gives ``r = 0``. Rounding only: rtol 1e-9 and atol 1e-12 of the
    force's relative noise (0.05^2 / 63 per line)."""
    period, n_per = 128, 4
    rng = np.random.default_rng(8)
    spec = np.zeros(period // 2 + 1, dtype=complex)
    spec[1:-1] = np.exp(2j * np.pi * rng.random(period // 2 - 1))
    one = np.fft.irfft(spec, period)
    one /= one.std()
    y = scipy.signal.lfilter(B, A, np.tile(one, n_per + 20))[-period * n_per :]
    x = np.tile(one, n_per)
    band = (0.5 / period, (period // 2 - 0.5) / period)
    for noisy_force in (True, False):
        xn = x + (0.05 * rng.standard_normal(x.size) if noisy_force else 0.0)
        yn = y + (0.0 if noisy_force else 0.05 * np.std(y) * rng.standard_normal(y.size))
        td = TimeData(np.vstack([xn, yn]), 1.0, [1, 2], ["force", "displacement"])
        frf = estimate_frf(td, method="cyclic", period_samples=period, band=band)
        assert frf.input_noise is not None
        assert frf.variance is not None
        assert frf.input_noise.shape == (1, frf.n_freq)
        if noisy_force:
            want = frf.input_noise[0] * np.abs(frf.H[0, 0]) ** 2
            assert_allclose(frf.variance[0, 0], want, rtol=1e-9)
            assert np.all(frf.input_noise > 0)
        else:
            assert_allclose(frf.input_noise, 0.0, atol=1e-12)
