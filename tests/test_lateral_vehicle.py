"""Single-degree-of-freedom lateral vehicle (spec eq. 41-44)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, PhysicsError
from tyredamp.lateral import (
    ClassicModel,
    HystereticModel,
    LateralVehicle,
    MaxwellModel,
    StretchedStringModel,
)
from tyredamp.lateral.vehicle import eq42_receptance, eq43_receptance, eq44_receptance

K, H, C, M = 260e3, 20e3, 300e3, 600.0
F = np.linspace(0.05, 20.0, 400)


def test_general_vehicle_equals_eq42_closed_form() -> None:
    v = LateralVehicle(HystereticModel(K, H, C), M)
    # Two algebraically equal forms: rounding.
    assert_allclose(v.receptance(F), eq42_receptance(K, H, C, M, F), rtol=1e-12)


def test_eq43_limit_large_road_damping() -> None:
    exact = eq43_receptance(K, H, M, F)
    # C = inf is eq. 43 exactly (rounding).
    assert_allclose(
        LateralVehicle(HystereticModel(K, H, math.inf), M).receptance(F), exact, rtol=1e-12
    )
    # Numerically approaching the limit: the relative change is O(|Y_t| K / (omega C)); with
    # C = 1e12 N s/m and f >= 0.05 Hz this is below 2e-6 of the response.
    for c_big, tol in ((1e9, 3e-3), (1e12, 3e-6)):
        assert_allclose(eq42_receptance(K, H, c_big, M, F), exact, rtol=tol)


def test_eq44_limit_small_hysteresis() -> None:
    exact = eq44_receptance(K, C, M, F)
    assert_allclose(eq42_receptance(K, 0.0, C, M, F), exact, rtol=1e-12)
    # h/K = 1e-7: the relative change is of order h/K times the resonance amplification
    # (|Y| K <~ 50 here), so 1e-5 bounds it.
    assert_allclose(eq42_receptance(K, 1e-7 * K, C, M, F), exact, rtol=1e-5)
    # And the general vehicle with a Maxwell tyre is eq. 44 too.
    assert_allclose(LateralVehicle(MaxwellModel(K, C), M).receptance(F), exact, rtol=1e-12)


def test_resonance_of_eq43_oscillator() -> None:
    # |1/(K - M w^2 + i h)| peaks exactly at w^2 = K/M with height 1/h.
    r = LateralVehicle(HystereticModel(K, H, math.inf), M).resonance()
    assert_allclose(r.frequency, math.sqrt(K / M) / (2 * math.pi), rtol=1e-7)  # search tol
    assert_allclose(r.peak, 1 / H, rtol=1e-12)
    # The rolling tyre (finite C) moves the peak a little: third-order system.
    r2 = LateralVehicle(HystereticModel(K, H, C), M).resonance()
    assert 3.0 < r2.frequency < 3.4
    acc = LateralVehicle(HystereticModel(K, H, C), M).resonance(quantity="accelerance")
    assert acc.quantity == "accelerance"


def test_resonance_errors() -> None:
    heavy = LateralVehicle(ClassicModel(k=1e5, c=1e6), 10.0)
    with pytest.raises(PhysicsError, match="no interior peak"):
        heavy.resonance()
    with pytest.raises(InputError, match="f_range"):
        heavy.resonance((5.0, 1.0))


def test_vehicle_is_the_axle_formula_with_body_mass() -> None:
    tyre = StretchedStringModel(C_alpha=8e4, sigma=0.4, a=0.2, speed=1.39)
    v = LateralVehicle(tyre, 280.0)
    f = np.linspace(0, 9, 50)
    # Same formula A/(1 + M A): rounding.
    assert_allclose(v.accelerance(f), tyre.axle_accelerance(f, 280.0), rtol=1e-13, atol=0)
    frf = v.frf(f, "mobility")
    assert frf.kind == "mobility"
    assert frf.meta["mass_kg"] == 280.0
    with pytest.raises(InputError):
        LateralVehicle(tyre, 0.0)
