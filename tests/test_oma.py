"""Operational modal analysis (tyredamp.oma) on synthetic output-only data with a known truth."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.mechanics import MCKSystem, time_response
from tyredamp.oma import correlations, oma, resolve_rotating, wave_content
from tyredamp.oma.harmonics import (
    band_kurtosis,
    detect_wheel_speed,
    harmonic_tests,
    order_evidence,
)
from tyredamp.oma.identify import oma_deferred
from tyredamp.oma.selection import otsu_threshold
from tyredamp.oma.ssi import ShiftProjection, block_toeplitz, poles_at_order, ssi_cov
from tyredamp.oma.uncertainty import jackknife_variance


def _chain(n: int = 3) -> MCKSystem:
    M = np.eye(n)
    k = 4e4
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += 2 * k
        if i:
            K[i, i - 1] = K[i - 1, i] = -k
    K[-1, -1] = k
    return MCKSystem(M, 2e-4 * K + 0.5 * M, K)


@pytest.fixture(scope="module")
def chain_record() -> tuple[np.ndarray, float, MCKSystem]:
    s = _chain()
    fs = 200.0
    rng = np.random.default_rng(7)
    f = rng.standard_normal((3, int(900 * fs)))
    y = time_response(s, f, fs, inputs=[0, 1, 2]).acceleration
    return y + 0.02 * y.std() * rng.standard_normal(y.shape), fs, s


def test_correlations_equal_direct_sums() -> None:
    rng = np.random.default_rng(0)
    y = rng.standard_normal((3, 5003))
    y[1] += 0.5 * np.roll(y[0], 3)
    c = correlations(y, 100.0, 12, [0, 2], block=50)
    n = y.shape[1]
    m = y.mean(axis=1)
    direct = np.array([y[:, i:] @ y[[0, 2], : n - i].T / (n - i) for i in range(12)])
    direct -= m[None, :, None] * m[None, None, [0, 2]]
    assert_allclose(c.R, direct, atol=1e-12)  # the same sums in another order: round-off only
    assert c.n_groups >= 16


def test_block_toeplitz_layout() -> None:
    R = np.arange(6)[:, None, None] * np.ones((6, 1, 1))
    T = block_toeplitz(R, 3)
    # Peeters & De Roeck (1999) eq. 16: row a, column b holds R_{i + a - b}
    assert_allclose(T[:, :, ...] if T.ndim == 3 else T, [[3, 2, 1], [4, 3, 2], [5, 4, 3]])


def test_ssi_exact_correlations_give_exact_poles() -> None:
    # R_k = C A^k G of a known 2-mode discrete system: SSI returns its poles exactly
    fs = 100.0
    lam = np.array([-0.3 + 2j * np.pi * 5, -0.8 + 2j * np.pi * 17])
    mu = np.exp(np.concatenate([lam, lam.conj()]) / fs)
    rng = np.random.default_rng(1)
    C = rng.standard_normal((3, 2)) + 1j * rng.standard_normal((3, 2))
    C = np.concatenate([C, C.conj()], axis=1)
    G = rng.standard_normal((2, 4)) + 1j * rng.standard_normal((2, 4))
    G = np.concatenate([G, G.conj()], axis=0)
    R = np.array([(C * mu**k) @ G for k in range(30)]).real
    op, _ = ssi_cov(R, fs, 10, [4])
    assert_allclose(np.sort_complex(op.poles), np.sort_complex(lam), rtol=1e-8)  # exact data


def test_shift_projection_equals_least_squares_at_every_order() -> None:
    # the QR shared by all orders against one least squares per order (eq. 19 of
    # Peeters & De Roeck 1999, computed independently by lstsq)
    rng = np.random.default_rng(3)
    T = rng.standard_normal((60, 40))
    U, s, _ = np.linalg.svd(T, full_matrices=False)
    proj = ShiftProjection(U, 30, 3)
    for n in (4, 11, 30):
        lam, sh = proj.poles(n, 50.0)
        lam0, sh0 = poles_at_order(U, s, n, 3, 50.0)
        i, i0 = np.argsort(lam.imag + 1e-3 * lam.real), np.argsort(lam0.imag + 1e-3 * lam0.real)
        assert_allclose(lam[i], lam0[i0], rtol=1e-8)  # the same matrix up to similarity
        mac = np.abs(np.sum(np.conj(sh[:, i]) * sh0[:, i0], axis=0)) ** 2
        assert_allclose(mac, 1.0, atol=1e-8)  # unit shapes, equal up to a phase


def test_shift_projection_falls_back_where_the_shift_is_rank_deficient() -> None:
    # a singular vector living in the last block row only makes U_up rank-deficient:
    # the minimum-norm least squares (lstsq, computed independently) takes over
    rng = np.random.default_rng(4)
    U = np.linalg.qr(rng.standard_normal((30, 6)))[0]
    U[:, 5] = 0.0
    U[-3:, 5] = [1.0, 0.0, 0.0]
    proj = ShiftProjection(U, 6, 3)
    lam, _ = proj.poles(6, 10.0)
    O = U[:, :6]
    mu = np.linalg.eigvals(np.linalg.lstsq(O[:-3], O[3:], rcond=None)[0])
    lam0 = np.log(mu[mu.imag > 0]) * 10.0
    assert np.all(np.isfinite(lam))
    assert_allclose(np.sort_complex(lam), np.sort_complex(lam0), rtol=1e-8)  # the same solve


def test_ssi_chain_modes(chain_record: tuple[np.ndarray, float, MCKSystem]) -> None:
    y, fs, s = chain_record
    truth = s.complex_modes().poles
    res = oma(y, fs)
    f_true = np.abs(truth) / (2 * np.pi)
    z_true = -truth.real / np.abs(truth)
    assert res.n_modes == 3
    assert_allclose(res.frequency_hz, f_true, rtol=0.005)  # the brief: f within 0.5 %
    assert_allclose(res.damping_ratio, z_true, rtol=0.10)  # the brief: zeta within 10 %
    # the jackknife errors cover the truth at 3 sigma
    assert np.all(np.abs(res.frequency_hz - f_true) < 3 * res.std_frequency_hz + 1e-12)
    assert np.all(np.isfinite(res.std_damping_ratio))
    phi = s.complex_modes().Psi
    for j in range(3):
        mac = abs(np.vdot(phi[:, j], res.shapes[:, j])) ** 2 / (
            np.vdot(phi[:, j], phi[:, j]).real * np.vdot(res.shapes[:, j], res.shapes[:, j]).real
        )
        assert mac > 0.99  # acceleration shapes = displacement shapes up to a factor


def test_deferred_errors_equal_the_jackknife_of_oma(
    chain_record: tuple[np.ndarray, float, MCKSystem],
) -> None:
    y, fs, _ = chain_record
    y = y[:, :40000]
    res = oma(y, fs)
    r2, later = oma_deferred(y, fs)
    # the same modes, and those oma dropped for their jackknife scatter (left to the caller)
    idx = [int(np.argmin(np.abs(r2.frequency_hz - f))) for f in res.frequency_hz]
    assert_allclose(r2.frequency_hz[idx], res.frequency_hz, rtol=1e-12)  # identical: round-off
    assert np.all(np.isnan(r2.std_frequency_hz))
    sf, sz = later.std(idx)
    assert_allclose(sf, res.std_frequency_hz, rtol=1e-10)  # the same jackknife, run later
    assert_allclose(sz, res.std_damping_ratio, rtol=1e-10)
    sf1, _ = later.std(idx[-1:])
    assert_allclose(sf1, res.std_frequency_hz[-1:], rtol=1e-10)  # one mode alone: the same


def test_plscf_chain_modes(chain_record: tuple[np.ndarray, float, MCKSystem]) -> None:
    y, fs, s = chain_record
    truth = s.complex_modes().poles
    res = oma(y, fs, method="plscf")
    assert_allclose(res.frequency_hz, np.abs(truth) / (2 * np.pi), rtol=0.005)  # f 0.5 %
    assert_allclose(res.damping_ratio, -truth.real / np.abs(truth), rtol=0.15)  # windowed spectra


def _travelling_field(
    angles: np.ndarray, fs: float, n_samples: int, rng: np.random.Generator
) -> tuple[np.ndarray, list[tuple[float, float, int, str]]]:
    """w(theta, t) = Re sum_n psi_n(theta) q_n(t), psi = e^{-+ i n theta}: forward/backward."""
    modes = [(12.0, 0.01, 2, "forward"), (19.0, 0.015, 3, "backward"), (27.0, 0.01, 1, "forward")]
    th = np.deg2rad(angles)
    w = np.zeros((angles.size, n_samples))
    for f0, z, n, d in modes:
        lam = 2 * np.pi * f0 * (-z + 1j * np.sqrt(1 - z * z))
        a = np.exp(lam / fs)
        e = rng.standard_normal(n_samples) + 1j * rng.standard_normal(n_samples)
        from scipy.signal import lfilter

        q = lfilter([1.0], [1.0, -a], e)
        psi = np.exp(-1j * n * th) if d == "forward" else np.exp(1j * n * th)
        w += np.real(psi[:, None] * q[None, :])
    return w + 0.05 * w.std() * rng.standard_normal(w.shape), modes


def test_travelling_wave_directions() -> None:
    rng = np.random.default_rng(3)
    angles = np.arange(8) * 45.0
    fs = 100.0
    w, modes = _travelling_field(angles, fs, int(600 * fs), rng)
    res = oma(w, fs)
    assert res.n_modes == 3
    for j, (f0, _z, n, d) in enumerate(modes[:0] + sorted(modes)):
        assert_allclose(res.frequency_hz[j], f0, rtol=0.005)  # f 0.5 %
        wc = wave_content(res.shapes[:, j], angles)
        assert wc.wave_number == n
        assert wc.direction == d
        assert 8 - n in wc.aliases


def test_wave_content_closed_form() -> None:
    th = np.arange(6) * 60.0
    psi = 2 * np.exp(-2j * np.deg2rad(th)) + 1 * np.exp(2j * np.deg2rad(th))
    wc = wave_content(psi, th)
    assert wc.wave_number == 2
    assert_allclose(wc.forward_share, 4 / 5, rtol=1e-12)  # |b|^2 / (|a|^2 + |b|^2), exact
    standing = wave_content(np.cos(3 * np.deg2rad(np.arange(8) * 45.0)), np.arange(8) * 45.0)
    assert standing.direction == "standing"


def test_rotating_sensor_pairs_and_ambiguity() -> None:
    fw = 2.0
    # one mode at 50 Hz, n = 3: forward seen at 44, backward at 56; a lone peak at 71
    out = resolve_rotating([44.0, 56.0, 71.0], fw)
    assert out[0].resolved
    assert out[0].wave_number == 3
    assert out[0].direction == "forward"
    assert out[1].direction == "backward"
    assert_allclose(out[0].frequency_fixed_hz, 50.0, rtol=1e-12)  # the mean of the pair
    assert not out[2].resolved
    assert out[2].candidates
    fixed = resolve_rotating([71.0], fw, fixed_hz=[79.0], n_max=4)
    assert fixed[0].resolved
    assert fixed[0].wave_number == 4
    assert fixed[0].direction == "forward"


def test_harmonic_test_tells_orders_from_modes() -> None:
    rng = np.random.default_rng(5)
    s = _chain()
    fs = 200.0
    y = time_response(s, rng.standard_normal((3, int(600 * fs))), fs, inputs=[0, 1, 2]).acceleration
    t = np.arange(y.shape[1]) / fs
    fw = 4.0
    for k in (5, 10):  # wheel orders 5 and 10 at 20 and 40 Hz, away from the modes
        y = y + 0.5 * y.std(axis=1, keepdims=True) * np.sin(2 * np.pi * k * fw * t)[None, :]
    truth = s.complex_modes().poles
    f = np.r_[np.abs(truth) / (2 * np.pi), 20.0, 40.0]
    z = np.r_[-truth.real / np.abs(truth), 1e-4, 1e-4]
    shapes = np.ones((f.size, 3), complex)
    tests = harmonic_tests(y, fs, f, z, shapes, wheel_speed_hz=fw)
    assert [t.harmonic for t in tests] == [False, False, False, True, True]
    assert [t.wheel_order for t in tests[3:]] == [5, 10]
    assert_allclose(detect_wheel_speed(np.array([20.0, 40.0, 60.0])), 20.0, rtol=1e-12)


def test_order_evidence_keeps_the_loss_of_modes_at_the_free_level() -> None:
    # sparse orders (a 0.1 Hz band around orders every 10 Hz: p = 2 %): the 5 % level,
    # whose one-sided normal quantile is 1.6449 (tables)
    assert_allclose(order_evidence(0.1, 10.0), 1.6449, atol=1e-4)  # 4 printed decimals
    # orders covering the axis (p = 1): the 0.1 % level of a peak anywhere, 3.0902 (tables)
    assert_allclose(order_evidence(3.0, 4.0), 3.0902, atol=1e-4)  # same
    # in between, p alpha = 0.1 %: p = 0.4 gives alpha = 0.25 %, quantile 2.8070 (tables)
    assert_allclose(order_evidence(0.2, 1.0), 2.8070, atol=1e-4)  # same


def test_band_kurtosis_sine_and_noise() -> None:
    fs = 100.0
    t = np.arange(200_000) / fs
    k_sine, _ = band_kurtosis(np.sin(2 * np.pi * 10 * t), fs, 10.0, 0.5)
    assert_allclose(k_sine, 1.5, atol=0.01)  # a sinusoid's kurtosis is 3/2
    k_noise, n_eff = band_kurtosis(np.random.default_rng(0).standard_normal(t.size), fs, 10, 2)
    assert abs(k_noise - 3) < 4 * np.sqrt(24 / n_eff)  # Gaussian: 3 within 4 standard errors


def test_jackknife_of_the_mean_is_the_classical_error() -> None:
    x = np.random.default_rng(2).standard_normal(40)
    loo = (x.sum() - x) / (x.size - 1)
    assert_allclose(jackknife_variance(loo[:, None])[0], x.var(ddof=1) / x.size, rtol=1e-12)


def test_otsu_splits_two_groups() -> None:
    x = np.r_[np.full(5, 1.0), np.full(7, 10.0)]
    assert 1.0 < otsu_threshold(x) < 10.0


@pytest.mark.parametrize(
    ("data", "kwargs", "match"),
    [
        (np.full((2, 10), np.nan), {}, "NaN"),
        (np.random.default_rng(0).standard_normal((1, 5000)), {}, "at least 2"),
        (np.random.default_rng(0).standard_normal((3, 100)), {}, "too short"),
        (np.zeros((2, 0)), {}, "samples"),
    ],
)
def test_bad_input_one_line(data: np.ndarray, kwargs: dict, match: str) -> None:
    with pytest.raises(InputError, match=match) as exc:
        oma(data, 100.0, **kwargs)
    assert "\n" not in str(exc.value)


def test_mode_estimate_from_the_lowest_stable_orders() -> None:
    from tyredamp.oma.identify import _near_orders
    from tyredamp.oma.selection import ModeCluster
    from tyredamp.oma.ssi import OrderPoles

    # one pole per order 10, 20, .., 100, stored in a shuffled order: the estimate
    # takes the members of the five lowest orders, whatever their storage order
    orders = np.array([70, 10, 100, 40, 20, 90, 30, 60, 50, 80])
    poles = -1.0 + 2j * np.pi * (50.0 + orders / 1000)
    op = OrderPoles(orders, poles, np.ones((10, 2), complex), np.sort(orders))
    c = ModeCluster(np.arange(10, dtype=np.intp), 2, 10)
    assert sorted(op.order[_near_orders(op, c)].tolist()) == [10, 20, 30, 40, 50]
