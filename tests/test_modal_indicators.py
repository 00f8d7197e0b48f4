"""Indicators: RMSD (eq. [19]), relative error, MAC, MPC, MPD, equivalent real modes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp.exceptions import ShapeError
from tyredamp.modal.statistics.indicators import (
    auto_mac,
    discrepancy,
    equivalent_real_modes,
    mac,
    mean_phase_deviation,
    modal_phase_collinearity,
    relative_error,
    rmsd,
)


def test_rmsd_is_eq19_with_one_over_m_outside_root() -> None:
    # hand value: differences 3 and 4i on m = 2 lines -> (1/2) sqrt(9 + 16) = 2.5
    assert_allclose(rmsd(np.array([0.0, 0.0]), np.array([3.0, 4j])), 2.5, rtol=1e-15)
    h = np.zeros((2, 1, 4), complex)
    t = np.ones((2, 1, 4), complex)
    # per FRF: (1/4) sqrt(4) = 0.5; all together: (1/8) sqrt(8)
    assert_allclose(rmsd(h, t, axis=-1), np.full((2, 1), 0.5), rtol=1e-15)
    assert_allclose(rmsd(h, t), np.sqrt(8) / 8, rtol=1e-15)


def test_relative_error_is_scale_free() -> None:
    rng = np.random.default_rng(0)
    a = rng.normal(size=50) + 1j * rng.normal(size=50)
    b = a * 1.01
    assert_allclose(relative_error(a, b), 0.01, rtol=1e-12)  # exact by construction
    assert_allclose(relative_error(1e6 * a, 1e6 * b), 0.01, rtol=1e-12)
    with pytest.raises(ShapeError, match="h_th"):
        relative_error(a, b[:3])


def test_discrepancy_per_line() -> None:
    h = np.zeros((2, 1, 3), complex)
    t = np.zeros((2, 1, 3), complex)
    t[0, 0, 1] = 2.0
    # RMS over the 2 FRFs: sqrt((4 + 0) / 2)
    assert_allclose(discrepancy(h, t), [0.0, np.sqrt(2.0), 0.0], atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1), st.floats(-3.0, 3.0), st.floats(0.1, 10.0))
def test_mac_invariant_to_complex_scale(seed: int, phase: float, scale: float) -> None:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(8, 3)) + 1j * rng.normal(size=(8, 3))
    b = a * scale * np.exp(1j * phase)
    m = mac(a, b)
    assert_allclose(np.diag(m), 1.0, rtol=1e-12)  # same shapes up to a complex factor
    assert np.all((m >= 0) & (m <= 1 + 1e-12))
    assert_allclose(auto_mac(a), auto_mac(b), atol=1e-12)


def test_mac_orthogonal_and_shape_check() -> None:
    e = np.eye(4)
    assert_allclose(mac(e, e), np.eye(4), atol=1e-15)
    with pytest.raises(ShapeError, match="phi_b"):
        mac(e, np.eye(3))


def test_mpc_mpd_real_and_travelling() -> None:
    phi = np.array([1.0, -2.0, 0.5, 3.0])
    rotated = phi * np.exp(1j * 0.7)
    assert_allclose(modal_phase_collinearity(rotated), [1.0], rtol=1e-12)  # monophase
    assert_allclose(mean_phase_deviation(rotated), [0.0], atol=1e-6)
    n = np.arange(16)
    wave = np.exp(2j * np.pi * 2 * n / 16)  # travelling wave: Re and Im equal energy
    assert_allclose(modal_phase_collinearity(wave), [0.0], atol=1e-12)
    assert mean_phase_deviation(wave)[0] > 40.0  # mean angle from any line ~ 45 deg


def test_equivalent_real_modes_recover_rotated_real_shape() -> None:
    phi = np.array([[1.0, 0.2], [-2.0, 1.0], [0.5, -0.3]])
    psi = phi * np.exp(1j * np.array([0.3, -1.1]))
    out = equivalent_real_modes(psi)
    sign = np.sign(out[np.argmax(np.abs(out), axis=0), [0, 1]])
    ref = phi * np.sign(phi[np.argmax(np.abs(phi), axis=0), [0, 1]])
    assert_allclose(out * sign, ref, atol=1e-12)  # exact up to the sign convention
