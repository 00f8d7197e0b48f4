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


def test_welch_dof_matches_the_scatter_of_white_noise() -> None:
    # the spread of a Welch PSD of white noise over its bins, independently of the formula:
    # var(S) / mean(S)^2 = 2 / nu for an estimate S chi2_nu / nu
    from scipy.signal import welch

    rng = np.random.default_rng(5)
    x = rng.standard_normal(64 * 1024)
    _, p = welch(x, nperseg=1024)
    p = p[20:-20]  # away from DC and Nyquist, whose bins have half the dof
    nu = 2 * np.mean(p) ** 2 / np.var(p)
    # 10 %: the variance of a variance over ~470 bins scatters by sqrt(2 / 470) ~ 7 %
    assert_allclose(spatial.welch_dof(x.size, 1024), nu, rtol=0.1)
    assert spatial.welch_dof(1024, 1024) == 2.0  # one segment: the periodogram


def test_power_threshold_is_the_f_quantile() -> None:
    # the share of ratios of two independent chi2_nu / nu estimates above the threshold
    rng = np.random.default_rng(6)
    nu = 40
    r = rng.chisquare(nu, 200_000) / rng.chisquare(nu, 200_000)
    q = spatial.power_threshold(nu, alpha=0.01)
    # 0.2 % absolute: binomial scatter of a 1 % share over 2e5 draws is 0.02 %
    assert_allclose(np.mean(r > q), 0.01, atol=0.002)


def test_peak_contrast_of_one_resonance_and_of_a_skirt() -> None:
    f = np.arange(0, 100, 0.05)
    f0, z = 40.0, 0.02
    s = 1 / ((1 - (f / f0) ** 2) ** 2 + (2 * z * f / f0) ** 2)
    # the closed form 5 of the docstring holds to first order in zeta: 2 % at zeta = 0.02
    assert_allclose(spatial.peak_contrast(s, f, f0, z), 5.0, rtol=0.05)
    # a pole on the skirt 6 half-bandwidths below the resonance: its upper flank is higher
    assert spatial.peak_contrast(s, f, f0 * (1 - 6 * z), 0.005) < 1.0
    assert spatial.peak_contrast(s, f, 0.1, z) == 0.0  # a flank beyond the axis


#: (wave number, direction seen from a fixed point, natural frequency Hz, damping ratio)
WAVES = [(2, "backward", 20.0, 0.02), (2, "forward", 27.0, 0.015), (3, "forward", 35.0, 0.01)]
WHEEL_HZ = 2.0


def _rolling_record(seed: int, angles_deg=None, n_samples: int = 2**15, waves=None):
    """Eight equally spaced fixed sensors seeing the travelling waves of WAVES, each a
    complex AR(1) of its pole (a random stationary wave), plus 10 % white sensor noise."""
    from tyredamp.frf import Channel
    from tyredamp.timedata import TimeData

    fs, K = 128.0, 8
    rng = np.random.default_rng(seed)
    ang = np.arange(K) * 360.0 / K if angles_deg is None else np.asarray(angles_deg, float)
    th = np.deg2rad(ang)
    y = np.zeros((K, n_samples))
    for n, d, f, z in WAVES if waves is None else waves:
        lam = complex(-z * 2 * np.pi * f, 2 * np.pi * f * np.sqrt(1 - z * z))
        e = rng.standard_normal(n_samples + 2000) + 1j * rng.standard_normal(n_samples + 2000)
        x = lfilter([1.0], [1.0, -np.exp(lam / fs)], e)[2000:] * np.sqrt(z)
        # e^{i(w t + n theta)} travels towards -theta: backward; e^{i(w t - n theta)} forward
        y += np.real(x[None, :] * np.exp(1j * (1 if d == "backward" else -1) * n * th[:, None]))
    y += 0.1 * np.std(y) * rng.standard_normal(y.shape)
    ch = [Channel(k + 1, angle_deg=float(a), name=f"F{k + 1}") for k, a in enumerate(ang)]
    return TimeData(y, fs, ch, ["acceleration"] * K, meta={"rotation_hz": WHEEL_HZ})


def test_rolling_modes_spatial_finds_each_wave_and_nothing_else() -> None:
    from tyredamp.oma.rolling import rolling_modes, rotating_frequency

    m = rolling_modes(_rolling_record(1), uncertainty=False, spatial=True)
    assert len(m.fixed) == len(WAVES), [(w.wave_number, w.fixed_hz) for w in m.fixed]
    for n, d, f, z in WAVES:
        (w,) = [w for w in m.fixed if (w.wave_number, w.fixed_direction) == (n, d)]
        # 0.5 %: a 256 s record fixes a resonance of half-bandwidth zeta f to ~sqrt(zeta f / T)
        # (< 0.1 %); SSI of a 2-channel record splits some clusters, off by up to 0.4 % over
        # eight draws of this record
        assert_allclose(w.fixed_hz, f, rtol=5e-3)
        # 30 %: the damping of one 256 s record of a 2-channel SSI, 6 of 8 draws within it
        assert_allclose(w.damping_ratio, z, rtol=0.3)
        f_rot, d_rot = rotating_frequency(f, n, d, WHEEL_HZ)  # closed form f -+ n f_w
        assert w.direction == d_rot
        # same 0.5 % as the fixed frame, carried through f_rot = f_fixed - s n f_w
        assert_allclose(w.rotating_hz, f_rot, rtol=5e-3 * f / f_rot)
    # the campaign's document: each wave a mode whose shape splits back into its n and direction
    from tyredamp.oma import wave_content
    from tyredamp.studies.steps.rolling import RollingStep

    doc = RollingStep.document(m, "ring.npz")
    got = set()
    for mode in doc["modes"]:
        shape = np.array(mode["shape"]) @ np.array([1.0, 1j])
        wc = wave_content(shape, doc["angles_deg"])
        got.add((wc.wave_number, wc.direction))
    assert got == {(n, d) for n, d, _, _ in WAVES}


def test_rolling_modes_spatial_refuses_an_irregular_layout() -> None:
    import pytest

    from tyredamp.exceptions import InputError
    from tyredamp.oma.rolling import rolling_modes

    td = _rolling_record(0, angles_deg=[0, 40, 90, 135, 180, 225, 270, 315], n_samples=4096)
    with pytest.raises(InputError, match="every 45 deg"):
        rolling_modes(td, uncertainty=False, spatial=True)


def test_cli_rolling_spatial(tmp_path, capsys) -> None:
    from tyredamp.io import write_timedata

    from .test_rolling_oma import _run

    src = write_timedata(_rolling_record(2, n_samples=2**13), tmp_path / "ring.npz")
    out = tmp_path / "waves.json"
    code, text, err = _run(capsys, "rolling", str(src), "-o", str(out), "--spatial",
                           "--no-uncertainty")  # fmt: skip
    assert code == 0, err
    assert "identified apart" in text
    import json

    got = {(w["wave_number"], w["fixed_direction"]) for w in json.loads(out.read_text())["waves"]}
    # a 64 s record: what it finds are waves of WAVES (accuracy is the test above)
    assert got
    assert got <= {(n, d) for n, d, _, _ in WAVES}
    # an irregular layout: one line naming the file and the layout, exit 2, nothing written
    bad = _rolling_record(2, angles_deg=[0, 40, 90, 135, 180, 225, 270, 315], n_samples=4096)
    src2 = write_timedata(bad, tmp_path / "irregular.npz")
    out2 = tmp_path / "x.json"
    code, _, err = _run(capsys, "rolling", str(src2), "-o", str(out2), "--spatial")
    assert code == 2
    assert err.startswith("tyredamp: error: irregular.npz: angles:")
    assert "every 45 deg" in err
    assert len(err.strip().splitlines()) == 1
    assert not out2.exists()


def test_select_spatial_poles_rules() -> None:
    from tyredamp.oma.rolling import SpatialPole, select_spatial_poles

    def pole(f, z=0.01, ratio=100.0, contrast=5.0, orders=30, n=2, d="forward"):
        return SpatialPole(n, d, f, z, np.nan, np.nan, ratio, 1.0, contrast, orders)

    dof = spatial.welch_dof(64 * 512, 1024)
    q = spatial.power_threshold(dof)
    poles = [
        pole(50.0),  # a clean wave: kept
        pole(50.6, orders=20),  # 0.6 Hz away, within 0.5 + 0.506 Hz, fewer orders: merged
        pole(80.0, ratio=0.9 * q),  # below the noise threshold
        pole(90.0, contrast=0.9 * q),  # no peak above its flanks
        pole(197.0),  # its flank at 197 + 2 zeta f = 200.94 Hz is beyond the 200 Hz band
        pole(50.6, d="backward"),  # the other direction's channel: its own wave
    ]
    got = select_spatial_poles(poles, (0.0, 200.0), 0.5, dof)
    assert sorted((p.frequency_hz, p.direction) for p in got) == [
        (50.0, "forward"),
        (50.6, "backward"),
    ]
    # a fixed threshold replaces only the noise test
    got = select_spatial_poles(poles, (0.0, 200.0), 0.5, dof, floor_ratio=0.5 * q)
    assert (80.0, "forward") in {(p.frequency_hz, p.direction) for p in got}


CLOSE = [(2, "forward", 40.0, 0.02), (3, "backward", 40.6, 0.02)]
"""Two waves 0.6 Hz apart, less than their half-power half-bandwidth zeta f = 0.8 Hz."""


def test_close_waves_of_two_wave_numbers_resolved_by_default() -> None:
    from tyredamp.oma.rolling import rolling_modes

    td = _rolling_record(5, waves=CLOSE)
    m = rolling_modes(td, uncertainty=False)  # equally spaced, 256 s: the wave-number route
    assert any("identified apart" in n for n in m.notes)
    for n, d, f, z in CLOSE:
        got = [w for w in m.fixed if (w.wave_number, w.fixed_direction) == (n, d)]
        assert len(got) == 1, [(w.wave_number, w.fixed_direction, w.fixed_hz) for w in m.fixed]
        # 0.5 %: the target; one channel holds one wave, so its neighbour does not pull it
        assert_allclose(got[0].fixed_hz, f, rtol=5e-3)
        # 30 %: the damping of one 256 s record of a 2-channel SSI (as above)
        assert_allclose(got[0].damping_ratio, z, rtol=0.3)
    assert len(m.fixed) == 2
    # all sensors together: the two resonances overlap in every channel
    g = rolling_modes(td, uncertainty=False, spatial=False)
    assert g.fixed_result is not None
    assert m.fixed_result is None


def test_default_route_follows_the_layout_and_the_record() -> None:
    from tyredamp.oma.rolling import _default_route, rolling_modes

    even = list(np.arange(8) * 45.0)
    assert _default_route(even, 2**15) == (True, "")
    short, why = _default_route(even, 2**12)
    assert not short
    assert "too short" in why
    odd, why = _default_route([0, 40, 90, 135, 180, 225, 270, 315], 2**15)
    assert not odd
    assert "not equally spaced" in why
    td = _rolling_record(0, angles_deg=[0, 40, 90, 135, 180, 225, 270, 315], n_samples=4096)
    m = rolling_modes(td, uncertainty=False)  # an irregular layout: the general route, no error
    assert m.fixed_result is not None
    assert any("not equally spaced" in n for n in m.notes)


def test_peak_test_power_against_monte_carlo() -> None:
    from scipy.stats import f as f_dist

    rng = np.random.default_rng(11)
    for dof, expect in ((21.0, False), (120.0, True)):
        q = spatial.power_threshold(dof)
        # a resonance's contrast estimate: 5 x the ratio of two independent chi2 / dof
        x = 5 * rng.chisquare(dof, 200_000) / rng.chisquare(dof, 200_000)
        miss = float(np.mean(x < q))
        # the closed form of the same probability, F(dof, dof) below q / 5
        assert_allclose(miss, f_dist.cdf(q / 5, dof, dof), atol=3e-3)  # MC: 4 sigma of 2e5
        assert spatial.peak_test_has_power(dof) is expect
        assert (miss <= 0.01) is expect
