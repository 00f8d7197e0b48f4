"""Mechanics core: spec eq. [1]-[18] against closed forms and independent computations."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp import InputError, PhysicsError, ShapeError, TyredampError
from tyredamp.mechanics import (
    MCKSystem,
    continuous_periodic_lines,
    foh_fourier_lines,
    modal_damping_matrix,
    periodic_response_lines,
    pole_from_frequency_damping,
    proportional_part,
    rayleigh_coefficients,
    rayleigh_damping,
    rayleigh_damping_ratios,
    small_damping_error,
    small_damping_modes,
    time_response,
)
from tyredamp.mechanics.response import _receptance_balanced

from .helpers import chain_system, random_system


@st.composite
def systems(draw: st.DrawFn) -> MCKSystem:
    seed = draw(st.integers(0, 2**31 - 1))
    n = draw(st.integers(1, 8))
    damping = draw(st.floats(0.05, 5.0))  # up to zeta ~ 0.3; near-critical is ill-posed
    return random_system(np.random.default_rng(seed), n, damping)


# ------------------------------------------------------------------ undamped
def test_undamped_modes_mass_normalised(chain: MCKSystem) -> None:
    um = chain.undamped_modes()
    # phi^T M phi = I and phi^T K phi = diag(omega^2): eigh accuracy ~1e-12
    assert_allclose(um.phi.T @ chain.M @ um.phi, np.eye(6), atol=1e-12)
    assert_allclose(um.phi.T @ chain.K @ um.phi, np.diag(um.omega**2), atol=1e-8 * 4e4)


def test_single_dof_closed_form() -> None:
    m, c, k = 2.0, 3.0, 5.0e4
    s = MCKSystem([[m]], [[c]], [[k]])
    cm = s.complex_modes()
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    # eq. [3]: p = -zeta wn + i wn sqrt(1 - zeta^2); closed form to rounding
    assert_allclose(cm.poles[0], -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2), rtol=1e-13)
    f = np.linspace(1, 60, 50)
    w = 2 * np.pi * f
    assert_allclose(s.frf(f).H[0, 0], 1 / (k - w**2 * m + 1j * w * c), rtol=1e-12)
    assert_allclose(s.frf(f, method="modal").H[0, 0], 1 / (k - w**2 * m + 1j * w * c), rtol=1e-10)


# --------------------------------------------------------------- hypothesis
@given(systems())
@settings(max_examples=40, deadline=None)
def test_modal_sum_equals_direct_solve(sys_: MCKSystem) -> None:
    """Eq. [10] against (K - w^2 M + i w C)^-1: both exact, agree to 1e-9."""
    cm = sys_.complex_modes()
    fmax = 1.5 * cm.frequency_hz.max()
    f = np.linspace(0.0, fmax, 97)
    hd = sys_.frf(f).H
    hm = sys_.frf(f, method="modal").H
    err = np.linalg.norm(hd - hm, axis=(0, 1)) / np.linalg.norm(hd, axis=(0, 1))
    assert err.max() < 1e-9


@given(systems())
@settings(max_examples=40, deadline=None)
def test_pole_equals_minus_b_over_a(sys_: MCKSystem) -> None:
    """Eq. [9]: p_n = -b_n / a_n for the exact eigenpairs, to 1e-9."""
    cm = sys_.complex_modes()
    assert_allclose(-cm.b / cm.a, cm.poles, rtol=1e-9)


@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 8),
    alpha=st.floats(0.0, 5.0),
    beta=st.floats(0.0, 1e-3),
)
@settings(max_examples=40, deadline=None)
def test_proportional_damping_gives_real_modes(
    seed: int, n: int, alpha: float, beta: float
) -> None:
    """Proportional damping: a_n = 2 i Omega_n (spec [10]) and real modes."""
    base = random_system(np.random.default_rng(seed), n)
    s = base.with_damping(rayleigh_damping(base.M, base.K, alpha, beta))
    cm = s.complex_modes()
    # eigensolver accuracy, relative to |a| ~ 2 Omega
    assert_allclose(cm.a, 2j * cm.poles.imag, rtol=1e-8, atol=1e-8 * np.abs(cm.a).max())
    # Psi is real up to one common phase per mode; our phase fix makes it real
    assert np.max(np.abs(cm.Psi.imag)) < 1e-8
    assert s.is_proportional()


def test_nonproportional_has_complex_modes(chain: MCKSystem) -> None:
    assert not chain.is_proportional()
    cm = chain.complex_modes()
    assert np.max(np.abs(cm.Psi.imag)) > 1e-4


# ------------------------------------------------------------ proportional
def test_rayleigh_ratios_closed_form() -> None:
    alpha, beta = rayleigh_coefficients(10.0, 0.02, 100.0, 0.03)
    z = rayleigh_damping_ratios(alpha, beta, 2 * np.pi * np.array([10.0, 100.0]))
    assert_allclose(z, [0.02, 0.03], rtol=1e-12)  # 2x2 solve, rounding only


def test_rayleigh_system_damping_ratios(chain: MCKSystem) -> None:
    alpha, beta = 2.0, 1e-4
    s = chain.with_damping(rayleigh_damping(chain.M, chain.K, alpha, beta))
    cm = s.complex_modes()
    um = s.undamped_modes()
    # zeta_n = alpha/(2 w) + beta w / 2 exactly for Rayleigh damping
    assert_allclose(cm.damping_ratio, rayleigh_damping_ratios(alpha, beta, um.omega), rtol=1e-10)


def test_modal_damping_matrix_exact(chain: MCKSystem) -> None:
    zeta = np.linspace(0.01, 0.05, 6)
    s = chain.with_damping(modal_damping_matrix(chain.M, chain.K, zeta))
    assert_allclose(s.complex_modes().damping_ratio, zeta, rtol=1e-10)


def test_proportional_part_splits_damping(chain: MCKSystem) -> None:
    cp = proportional_part(chain)
    s = chain.with_damping(cp)
    assert s.is_proportional()
    diag_full = np.diag(chain.modal_damping())
    assert_allclose(np.diag(s.modal_damping()), diag_full, rtol=1e-10)


def test_eq3_factor_two() -> None:
    """Eq. [2] equals eq. [3] only with R = phi phi / (2 i Omega) (spec typo note)."""
    f_n, zeta, phi = 12.0, 0.03, 0.7
    p = pole_from_frequency_damping([f_n], [zeta])[0]
    w = 2 * np.pi * np.linspace(1, 30, 40)
    wn = 2 * np.pi * f_n
    h2 = phi**2 / (wn**2 - w**2 + 2j * zeta * wn * w)
    r = phi**2 / (2j * p.imag)
    h3 = r / (1j * w - p) + np.conj(r) / (1j * w - np.conj(p))
    assert_allclose(h3, h2, rtol=1e-12)
    r_printed = -1j * phi**2 / p.imag
    h3p = r_printed / (1j * w - p) + np.conj(r_printed) / (1j * w - np.conj(p))
    assert np.max(np.abs(h3p - h2) / np.abs(h2)) > 0.5


# ----------------------------------------------------------- perturbation
@pytest.mark.parametrize("method", ["first", "improved"])
def test_small_damping_error_is_quadratic(method: str) -> None:
    """Error of eq. [15]/[16]/[18] shrinks as (damping scale)^2: slope 2 on log-log."""
    base = chain_system(c_local=(20.0, 0.0, 8.0, 0.0, 0.0, 3.0))
    scales = np.array([1.0, 0.3, 0.1, 0.03])
    pole_err, alpha_err = [], []
    for sc in scales:
        e = small_damping_error(base.with_damping(base.C * sc), method)  # type: ignore[arg-type]
        pole_err.append(e.pole_error.max())
        alpha_err.append(e.alpha_error.max())
    sp = np.polyfit(np.log(scales), np.log(pole_err), 1)[0]
    sa = np.polyfit(np.log(scales), np.log(alpha_err), 1)[0]
    # second-order perturbation error: slope 2 (+-0.1 for higher-order terms)
    assert abs(sp - 2) < 0.1
    assert abs(sa - 2) < 0.1


def test_improved_not_worse_than_first() -> None:
    base = chain_system(c_local=(20.0, 0.0, 8.0, 0.0, 0.0, 3.0))
    e1 = small_damping_error(base, "first")
    e2 = small_damping_error(base, "improved")
    assert e2.alpha_error.max() <= e1.alpha_error.max() * 1.0001


def test_small_damping_real_part_is_undamped_mode(chain: MCKSystem) -> None:
    """Eq. [16]: alpha is purely imaginary, so Re Psi_n = phi_n exactly."""
    s = chain.with_damping(chain.C * 0.01)
    phi = chain.undamped_modes().phi
    sd = small_damping_modes(s, "first")
    assert_allclose(sd.Psi.real, phi, atol=1e-12)  # rounding only
    # eq. [18] adds a real part of second order in the damping (C' ~ 0.05 1/s here)
    sd2 = small_damping_modes(s, "improved")
    assert_allclose(sd2.Psi.real, phi, atol=1e-6)


# --------------------------------------------------------- time response
def _periodic_foh_steady_state(
    s: MCKSystem, force: np.ndarray, fs: float, out: int, inp: int, n_alias: int = 400
) -> np.ndarray:
    """Steady state of a piecewise-linear periodic force, computed in the frequency domain.

    The first-order-hold interpolant of an N-periodic sequence with DFT X[k]
    has Fourier coefficients X[k]/N * sinc^2((k + mN)/N) at harmonics k + mN;
    its response sums H over all those harmonics (sampled at the grid).
    """
    n = force.size
    x = np.fft.fft(force)
    k = np.fft.fftfreq(n, 1 / n)
    y = np.zeros(n, dtype=complex)
    for m in range(-n_alias, n_alias + 1):
        kk = k + m * n
        freq = kk * fs / n
        w = 2 * np.pi * freq
        unit = np.eye(s.n_dof)[inp]
        h = np.array([np.linalg.solve(s.K - wi**2 * s.M + 1j * wi * s.C, unit)[out] for wi in w])
        y += x * np.sinc(kk / n) ** 2 * h
    return np.real(np.fft.ifft(y))


def test_time_response_periodic_steady_state() -> None:
    """Exact discretisation vs frequency-domain steady state, 1e-6 relative."""
    s = chain_system(n=3, k=2.0e3, c_local=(3.0, 1.0, 0.5))
    fs, n = 64.0, 64  # period 1 s
    rng = np.random.default_rng(3)
    force = rng.normal(size=n)
    n_per = 40  # slowest decay ~ exp(-sigma t): settle many periods
    r = time_response(s, np.tile(force, n_per), fs, inputs=[0], outputs=[2])
    ss = _periodic_foh_steady_state(s, force, fs, out=2, inp=0, n_alias=60)
    last = r.displacement[0, -n:]
    err = np.max(np.abs(last - ss)) / np.max(np.abs(ss))
    # exact up to the truncated alias sum (~1/m^4 tail) and the transient left
    assert err < 1e-6


def test_periodic_response_lines_equal_the_settled_time_response() -> None:
    """DFT closed form of the FOH recursion (spec eq. [10]) vs stepping it to steady state."""
    s = chain_system(n=3, k=2.0e3, c_local=(3.0, 1.0, 0.5))
    fs, n = 64.0, 64
    rng = np.random.default_rng(4)
    force = rng.normal(size=(2, n))
    n_per = 60  # the slowest mode's transient decays below 1e-10 of the response
    r = time_response(s, np.tile(force, n_per), fs, inputs=[0, 2], outputs=[1, 2])
    disp, acc = periodic_response_lines(s, force, fs, [0, 2], [1, 2], n // 2 + 1)
    for got, sampled in ((disp, r.displacement), (acc, r.acceleration)):
        want = np.fft.rfft(sampled[:, -n:], axis=1)
        # the same discrete system: equal to rounding and the transient left
        assert_allclose(got, want, rtol=0, atol=1e-8 * np.abs(want).max())
    with pytest.raises(ShapeError, match="n_lines"):
        periodic_response_lines(s, force, fs, [0, 2], [1], n // 2 + 2)
    with pytest.raises(ShapeError, match="one row per input"):
        periodic_response_lines(s, force[:1], fs, [0, 2], [1], 3)


def test_foh_fourier_lines_equal_the_dense_fourier_integral() -> None:
    """``X_l sinc^2(pi l / N)``: N times the Fourier coefficients of the FOH interpolant."""
    n, dense = 16, 512  # samples per period; fine points per sample for the integral
    rng = np.random.default_rng(5)
    x = rng.normal(size=(2, n))
    t = np.arange(n * dense) / dense  # time in samples, one period
    interp = np.array([np.interp(t, np.arange(n + 1), np.append(row, row[0])) for row in x])
    # the rectangle rule on a periodic integrand: the error is the aliasing of the
    # harmonics l + m n dense, whose coefficients fall as (m n dense)^-2 (measured
    # 6.8e-7 of the largest coefficient; 2e-6 allowed)
    coeff = interp @ np.exp(-2j * np.pi * np.outer(t, np.arange(n // 2 + 1)) / n) / dense
    got = foh_fourier_lines(x, n // 2 + 1)
    assert_allclose(got, coeff, rtol=0, atol=2e-6 * np.abs(coeff).max())
    # the DFT of the samples is not it: the hold attenuates line 8 of 16 by (2/pi)^2
    assert np.max(np.abs(np.fft.rfft(x, axis=1) - coeff)) > 0.1 * np.abs(coeff).max()
    with pytest.raises(ShapeError, match="n_lines"):
        foh_fourier_lines(x, n // 2 + 2)


def test_continuous_periodic_lines_equal_a_finely_sampled_steady_state() -> None:
    """The continuous steady state against the discrete one of a linearly upsampled force.

    Linear interpolation of the FOH samples at ``R`` times the rate is the same
    piecewise-linear force; sampling the steady state at that rate folds only
    the harmonics ``l + m N R`` onto ``l`` (force ``~ (m R)^-2``, receptance
    ``~ omega^-2``), so :func:`periodic_response_lines` at the fine rate approaches
    the continuous coefficients (measured 2e-10 of the largest with ``R = 32``;
    1.7e-3 at the force's own rate, ``R = 1``).
    """
    s = chain_system(n=3, k=2.0e3, c_local=(3.0, 1.0, 0.5))
    fs, n, r = 64.0, 64, 32
    rng = np.random.default_rng(6)
    force = rng.normal(size=(2, n))
    fine_t = np.arange(n * r) / r
    fine = np.array([np.interp(fine_t, np.arange(n + 1), np.append(row, row[0])) for row in force])
    f_lines, disp, acc = continuous_periodic_lines(s, force, fs, [0, 2], [1, 2], n // 2 + 1)
    disp_fine, _ = periodic_response_lines(s, fine, fs * r, [0, 2], [1, 2], n // 2 + 1)
    assert_allclose(disp, disp_fine / r, rtol=0, atol=1e-8 * np.abs(disp).max())
    assert_allclose(f_lines, foh_fourier_lines(force, n // 2 + 1), rtol=0, atol=0)
    w = 2 * np.pi * np.arange(n // 2 + 1) * fs / n
    # the acceleration of a harmonic is -omega^2 times its displacement, exactly
    assert_allclose(acc, -(w**2) * disp, rtol=1e-14)
    # several forcings at once: the same as one by one (one receptance for all)
    many = continuous_periodic_lines(s, np.stack([force, 2 * force]), fs, [0, 2], [1, 2], 5)
    assert_allclose(many[1][1], 2 * disp[:, :5], rtol=1e-13)
    with pytest.raises(ShapeError, match="one row per input"):
        continuous_periodic_lines(s, force[:1], fs, [0, 2], [1], 3)


def test_balanced_receptance_equals_the_direct_solve() -> None:
    """The state-space eigenvalue sum of the rig's receptance against a solve per line."""
    s = chain_system(n=5, k=2.0e3, c_local=(3.0, 1.0, 0.5))
    f = np.linspace(0.0, 40.0, 161)
    got = _receptance_balanced(s, f, np.array([1, 4]), np.array([0, 2]))
    want = s.receptance_direct(f, [1, 4], [0, 2])
    # rounding of the eigen-decomposition: measured 4e-14 of the largest value
    assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    # a free chain (a rigid-body mode, Omega = 0) is solved line by line instead
    k = s.K.copy()
    k[0, 0] -= 2.0e3
    free = MCKSystem(s.M, s.C, k)
    got = _receptance_balanced(free, f[1:], np.array([1]), np.array([0]))
    assert_allclose(got, free.receptance_direct(f[1:], [1], [0]), rtol=1e-12)


def test_time_response_harmonic_matches_frf() -> None:
    s = chain_system(n=4, k=5.0e3, c_local=(4.0, 2.0))
    fs = 2000.0
    f0 = 3.0
    t = np.arange(int(40 * fs)) / fs
    r = time_response(s, np.sin(2 * np.pi * f0 * t), fs, inputs=[1], outputs=[0, 3])
    h = s.frf([f0], inputs=[1], outputs=[0, 3]).H[:, 0, 0]
    expect = np.imag(h[:, None] * np.exp(2j * np.pi * f0 * t[None, -400:]))
    # FOH error of a sampled sine ~ (w h)^2 / 12 = 1e-5 here
    assert_allclose(r.displacement[:, -400:], expect, atol=2e-5 * np.abs(h).max())


def test_time_response_free_decay_and_acceleration() -> None:
    """Free vibration of 1 DOF from x0: closed form; acceleration = -(c v + k x)/m."""
    m, c, k = 1.5, 2.0, 3.0e3
    s = MCKSystem([[m]], [[c]], [[k]])
    fs = 1000.0
    r = time_response(s, np.zeros(2000), fs, inputs=[0], x0=[0.01])
    wn = np.sqrt(k / m)
    z = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - z**2)
    t = r.time
    x = 0.01 * np.exp(-z * wn * t) * (np.cos(wd * t) + z / np.sqrt(1 - z**2) * np.sin(wd * t))
    assert_allclose(r.displacement[0], x, atol=1e-12)  # exact solution, rounding only
    assert_allclose(r.acceleration[0], -(c * r.velocity[0] + k * r.displacement[0]) / m, atol=1e-9)


# -------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("M", "C", "K", "exc", "word"),
    [
        ([[1.0, 0.1], [0.0, 1.0]], np.zeros((2, 2)), np.eye(2), PhysicsError, "symmetric"),
        ([[1.0, 0.0], [0.0, -1.0]], np.zeros((2, 2)), np.eye(2), PhysicsError, "positive definite"),
        (np.eye(2), np.zeros((3, 3)), np.eye(2), ShapeError, "shape"),
        (np.eye(2), np.zeros((2, 2)), [[1.0, np.nan], [np.nan, 1.0]], InputError, "finite"),
        (np.eye(2), -np.eye(2), np.eye(2), PhysicsError, "semi-definite"),
        (np.ones(3), np.zeros((3, 3)), np.eye(3), ShapeError, "2-D"),
    ],
)
def test_bad_matrices(M, C, K, exc, word) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc, match=word) as info:
        MCKSystem(M, C, K)
    assert isinstance(info.value, TyredampError)
    assert isinstance(info.value, ValueError)


def test_bad_frequency_and_dofs(chain: MCKSystem) -> None:
    with pytest.raises(InputError, match="increasing"):
        chain.frf([1.0, 3.0, 2.0])
    with pytest.raises(InputError, match="DOF indices"):
        chain.frf([1.0, 2.0], outputs=[9])
    with pytest.raises(ShapeError, match="rows"):
        time_response(chain, np.zeros((2, 10)), 100.0, inputs=[0])
    with pytest.raises(PhysicsError, match="sample_rate"):
        time_response(chain, np.zeros(10), -1.0, inputs=[0])


def test_overdamped_complex_modes_error() -> None:
    s = MCKSystem([[1.0]], [[100.0]], [[1.0]])
    with pytest.raises(PhysicsError, match="overdamped"):
        s.complex_modes()
