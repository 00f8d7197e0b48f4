"""Wave-number channels of equally spaced fixed sensors (oma.spatial)."""

import numpy as np
from numpy.testing import assert_allclose
from scipy.signal import lfilter

from tyredamp.oma import spatial


def _two_waves(K: int = 16, n: int = 3, N: int = 4096, fs: float = 256.0):
    """A backward and a forward wave of one wave number on bin frequencies."""
    th = 2 * np.pi * np.arange(K) / K
    t = np.arange(N) / fs
    f1, f2 = 40 * fs / N * 10, 52 * fs / N * 10  # exact FFT bins
    back = 1.3 * np.cos(2 * np.pi * f1 * t[None, :] + n * th[:, None] + 0.4)
    fwd = 0.7 * np.cos(2 * np.pi * f2 * t[None, :] - n * th[:, None] - 1.1)
    return np.rad2deg(th), back, fwd


def test_travelling_channels_separate_directions_exactly() -> None:
    ang, back, fwd = _two_waves()
    b, f = spatial.travelling_channels(back + fwd, ang, 3)
    # a backward wave cos(w t + n theta + p) gives q_n = K/2 e^{i(w t + p)} in f > 0:
    # Re of the backward pair is (K/2) cos(w t + p), the sum of the K samples halved
    assert_allclose(b[0], 8 * back[0], atol=1e-9)  # round-off of 4096-point FFTs
    assert_allclose(f[0], 8 * fwd[0], atol=1e-9)  # same
    # the other wave numbers hold nothing of either wave
    b2, f2 = spatial.travelling_channels(back + fwd, ang, 2)
    assert np.max(np.abs(b2)) + np.max(np.abs(f2)) < 1e-9  # round-off only


def test_spatial_spectra_put_each_wave_in_its_channel() -> None:
    ang, back, fwd = _two_waves()
    f, S = spatial.spatial_spectra(back + fwd, 256.0, ang)
    k1, k2 = np.argmin(np.abs(f - 25.0)), np.argmin(np.abs(f - 32.5))
    assert S[0, 3, k1] > 1e6 * S[1, 3, k1]  # backward only at +n
    assert S[1, 3, k2] > 1e6 * S[0, 3, k2]  # forward only at -n


def test_equally_spaced() -> None:
    assert spatial.equally_spaced(np.arange(16) * 22.5)
    assert spatial.equally_spaced((np.arange(8) * 45.0 + 10) % 360)
    assert not spatial.equally_spaced([0, 30, 90, 180])


def _ar_waves(n: int, K: int, fs: float, N: int, poles: list[complex], seed: int) -> np.ndarray:
    """Random stationary travelling waves: complex AR(1) of each pole, shape (K, N)."""
    rng = np.random.default_rng(seed)
    th = 2 * np.pi * np.arange(K) / K
    y = np.zeros((K, N))
    for sign, lam in zip((+1, -1), poles, strict=True):
        a = np.exp(lam / fs)
        e = rng.standard_normal(N) + 1j * rng.standard_normal(N)
        x = lfilter([1.0], [1.0, -a], e)
        y += np.real(x[None, :] * np.exp(1j * sign * n * th[:, None]))
    return y


def test_same_frequency_opposite_directions_different_decay() -> None:
    fs, K, n, f0 = 128.0, 8, 1, 20.0
    zb, zf = 0.010, 0.020
    poles = [complex(-z * 2 * np.pi * f0, 2 * np.pi * f0 * np.sqrt(1 - z**2)) for z in (zb, zf)]
    y = _ar_waves(n, K, fs, 2**18, poles, seed=1)
    b, f = spatial.travelling_channels(y, np.arange(K) * 360 / K, n)
    from tyredamp.oma import oma

    rb = oma(b, fs, band=(10.0, 30.0), uncertainty=False)
    rf = oma(f, fs, band=(10.0, 30.0), uncertainty=False)
    jb, jf = np.argmin(abs(rb.frequency_hz - f0)), np.argmin(abs(rf.frequency_hz - f0))
    # natural frequency of both within 0.1 % (the brief's closed-form target)
    assert_allclose(rb.frequency_hz[jb], f0, rtol=1e-3)
    assert_allclose(rf.frequency_hz[jf], f0, rtol=1e-3)
    # damping: each wave its own, within 10 % (2048 s of random response)
    assert_allclose(rb.damping_ratio[jb], zb, rtol=0.1)
    assert_allclose(rf.damping_ratio[jf], zf, rtol=0.1)
