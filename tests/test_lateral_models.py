"""Lateral tyre models: eq. 38-40, model identities, axle force, Fiala/brush."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, PhysicsError
from tyredamp.frf import FRF
from tyredamp.lateral import (
    MODELS,
    ClassicModel,
    FialaTyre,
    HystereticModel,
    LateralModel,
    MaxwellModel,
    RelaxationLengthModel,
    StretchedStringModel,
    ViscoPlasticModel,
    axle_from_ground_accelerance,
    corner_differences,
    delta_ar_asymptote,
    delta_ar_maxwell,
    figure7_curves,
    get_model_class,
    ground_from_axle_accelerance,
)
from tyredamp.lateral.response import string_impedance

F = np.linspace(0.0, 9.0, 46)
FPOS = F[1:]

EXAMPLES: list[LateralModel] = [
    ClassicModel(k=1.3e5, c=2e3),
    MaxwellModel(k=1.3e5, c=5e4),
    ViscoPlasticModel(k=1.3e5, c1=1.5e3, c2=5e4),
    HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4),
    RelaxationLengthModel(C_alpha=8e4, sigma=0.4, speed=1.39),
    StretchedStringModel(C_alpha=8e4, sigma=0.4, a=0.2, speed=1.39),
]


# ------------------------------------------------------------------ eq. 38-40, Figure 7
def test_eq39_eq40_from_model_curves_at_h_over_k_02() -> None:
    # Evaluated from the receptance curves at f0, not from the closed forms.
    d = corner_differences(HystereticModel(K=260e3, h=0.2 * 260e3, C_r=300e3))
    # Paper/spec values to their printed digits: 3.874 dB (eq. 39), 0.6933 dB (eq. 40).
    assert round(d.vs_high_asymptote, 3) == 3.874
    assert round(d.vs_maxwell, 4) == 0.6933
    # The high-frequency asymptote gives the larger of the two asymptote errors.
    assert d.vs_asymptotes == d.vs_high_asymptote > d.vs_low_asymptote
    # Curves and closed forms agree to rounding (1e-12 dB).
    assert_allclose(d.vs_high_asymptote, delta_ar_asymptote(0.2), atol=1e-12)
    assert_allclose(d.vs_maxwell, delta_ar_maxwell(0.2), atol=1e-12)
    assert_allclose(d.f0, 260e3 / (2 * np.pi * 300e3), rtol=1e-15)  # eq. 38


@settings(max_examples=60, deadline=None)
@given(
    r=st.floats(0.0, 3.0),
    k=st.floats(1e3, 1e7),
    c=st.floats(1e2, 1e7),
)
def test_eq39_eq40_any_ratio(r: float, k: float, c: float) -> None:
    d = corner_differences(HystereticModel(K=k, h=r * k, C_r=c))
    # Same numbers from the curves as from eq. 39/40, for any h/K and scale (1e-9 dB).
    assert_allclose(d.vs_high_asymptote, delta_ar_asymptote(r), atol=1e-9)
    assert_allclose(d.vs_maxwell, delta_ar_maxwell(r), atol=1e-9)
    assert_allclose(d.vs_low_asymptote, delta_ar_asymptote(r) - 10 * np.log10(1 + r**2), atol=1e-9)


def test_figure7_curves_asymptotes() -> None:
    c = figure7_curves()
    assert_allclose(c.f0, 260e3 / (2 * np.pi * 300e3))
    # The model approaches each asymptote far from f0. At 0.01 Hz (q = f/f0 = 0.0725) the
    # model/low-asymptote ratio is |1 + i q (1 - i h/K)/(1 + (h/K)^2)| ~ 1 + q h/K + q^2/2,
    # i.e. 0.07 dB; at 100 Hz the high asymptote is off by ~ (f0/f)^2/2 in power: < 1e-5 dB.
    assert abs(c.model_db[0] - c.low_asymptote_db[0]) < 0.08
    assert abs(c.model_db[-1] - c.high_asymptote_db[-1]) < 1e-3
    # Low asymptote falls 20 dB/decade; the high one is flat at -20 log10|K + ih|.
    slope = (c.low_asymptote_db[-1] - c.low_asymptote_db[0]) / 4.0
    assert_allclose(slope, -20.0, rtol=1e-12)
    assert_allclose(c.high_asymptote_db, -20 * np.log10(abs(260e3 + 20e3j)), rtol=1e-12)


# ---------------------------------------------------------------- identities between models
@settings(max_examples=50, deadline=None)
@given(
    ca=st.floats(1e3, 1e6),
    sigma=st.floats(0.01, 3.0),
    v=st.floats(0.1, 40.0),
)
def test_maxwell_equals_relaxation_length(ca: float, sigma: float, v: float) -> None:
    r = RelaxationLengthModel(C_alpha=ca, sigma=sigma, speed=v)
    m = MaxwellModel(k=ca / sigma, c=ca / v)
    f = np.linspace(0, 20, 41)
    # Same expression rearranged: agreement to rounding.
    assert_allclose(r.mobility(f), m.mobility(f), rtol=1e-12)
    assert_allclose(r.accelerance(f), m.accelerance(f), rtol=1e-12, atol=0)
    assert r.maxwell() == MaxwellModel(k=ca / sigma, c=ca / v)


@settings(max_examples=40, deadline=None)
@given(
    ca=st.floats(1e3, 1e6),
    sigma=st.floats(0.01, 3.0),
    v=st.floats(0.1, 40.0),
)
def test_string_without_contact_length_is_relaxation_model(
    ca: float, sigma: float, v: float
) -> None:
    s = StretchedStringModel(C_alpha=ca, sigma=sigma, a=0.0, speed=v)
    r = RelaxationLengthModel(C_alpha=ca, sigma=sigma, speed=v)
    f = np.linspace(0, 20, 41)
    # a = 0 reduces the closed form exactly (series branch phi1 = 1, phi2 = 1/2): rounding.
    assert_allclose(s.mobility(f), r.mobility(f), rtol=1e-12)


def test_string_limits_and_direct_quadrature() -> None:
    s = StretchedStringModel(C_alpha=8e4, sigma=0.4, a=0.2, speed=1.39)
    # Low frequency: a damper C_alpha/V (exact at 0 Hz).
    assert_allclose(s.mobility(0.0), 1.39 / 8e4, rtol=1e-14)
    # High frequency: spring C_alpha/(sigma + a); corrections O(V/(sigma w)) ~ 6e-5 at 1e4 Hz.
    assert_allclose(s.dynamic_stiffness(1e4).real, 8e4 / 0.6, rtol=1e-3)
    # Closed form against the force integral c_c [sigma u1 + int u dx + sigma u2] with
    # u(x) = Y (1 - g e^{-s (a - x)/V}) evaluated by Simpson's rule on 4001 points.
    from scipy.integrate import simpson

    cc, sg, a, v = s.c_c, s.sigma, s.a, s.speed
    for f in (0.3, 2.0, 7.5):
        sv = 2j * np.pi * f
        g = 1 / (1 + sv * sg / v)
        x = np.linspace(-a, a, 4001)
        u = 1 - g * np.exp(-sv * (a - x) / v)
        force = cc * (sg * (1 - g) + simpson(u, x=x) + sg * u[0])
        direct = sv / force  # mobility = s Y / F with Y = 1
        # Simpson error ~ h^4 |u''''| ~ (1e-4)^4 (s/V)^4 a: below 1e-10 relative.
        assert_allclose(s.mobility(f), direct, rtol=1e-10)


def test_string_series_branch_is_continuous() -> None:
    # phi1/phi2 switch from series to closed form at |x| = 0.1; x = 2 a omega / V.
    a, v = 0.2, 1.39
    w0 = 0.1 * v / (2 * a)
    w = w0 * np.array([1 - 1e-9, 1 + 1e-9])
    z = string_impedance(w, 1e5, 0.4, a, v)
    # A jump would show as a relative difference far above the 2e-9 change of omega.
    assert_allclose(z[0], z[1], rtol=1e-8)


def test_hysteretic_asymptotes_and_limits() -> None:
    m = HystereticModel(K=260e3, h=20e3, C_r=300e3)
    y = m.receptance(FPOS)
    assert_allclose(
        y, m.low_frequency_asymptote(FPOS) + m.high_frequency_asymptote(FPOS), rtol=1e-14
    )
    # h = 0 is the Maxwell model; C_r = inf is the standing carcass 1/(K + i h).
    assert_allclose(
        HystereticModel(260e3, 0.0, 300e3).receptance(FPOS),
        MaxwellModel(260e3, 300e3).receptance(FPOS),
        rtol=1e-14,
    )
    stand = HystereticModel(260e3, 20e3, math.inf)
    assert_allclose(stand.receptance(FPOS), 1 / (260e3 + 20e3j), rtol=1e-14)
    assert stand.receptance(0.0) == 1 / 260e3  # h sign(0) = 0 at exactly 0 Hz


# ------------------------------------------------------------------ kinds, 0 Hz, validation
@pytest.mark.parametrize("model", EXAMPLES, ids=lambda m: m.name)
def test_kinds_are_consistent(model: LateralModel) -> None:
    w = 2 * np.pi * FPOS
    y = model.receptance(FPOS)
    # Exact algebra between kinds: rounding only.
    assert_allclose(model.mobility(FPOS), 1j * w * y, rtol=1e-12)
    assert_allclose(model.accelerance(FPOS), -(w**2) * y, rtol=1e-12)
    assert_allclose(model.dynamic_stiffness(FPOS), 1 / y, rtol=1e-12)
    assert model.accelerance(0.0) == 0
    assert np.isfinite(model.mobility(0.0))
    frf = model.frf(F, force="axle", wheel_mass=100.0)
    assert isinstance(frf, FRF)
    assert frf.kind == "accelerance"
    assert frf.meta["force"] == "axle"


def test_receptance_at_zero_hz() -> None:
    assert ClassicModel(1e5, 1e3).receptance(0.0) == 1e-5
    with pytest.raises(InputError, match="infinite at 0 Hz"):
        MaxwellModel(1e5, 1e3).receptance(F)


@pytest.mark.parametrize(
    ("cls", "kw", "exc"),
    [
        (ClassicModel, {"k": -1.0, "c": 1.0}, PhysicsError),
        (MaxwellModel, {"k": 1.0, "c": 0.0}, PhysicsError),
        (ViscoPlasticModel, {"k": 1.0, "c1": 0.0, "c2": 1.0}, PhysicsError),
        (HystereticModel, {"K": 1.0, "h": -0.1, "C_r": 1.0}, PhysicsError),
        (HystereticModel, {"K": 1.0, "h": 0.1, "C_r": float("nan")}, InputError),
        (
            StretchedStringModel,
            {"C_alpha": 1.0, "sigma": 0.1, "a": -0.1, "speed": 1.0},
            PhysicsError,
        ),
        (RelaxationLengthModel, {"C_alpha": 1.0, "sigma": 0.1, "speed": 0.0}, PhysicsError),
    ],
)
def test_parameters_are_validated(cls: type, kw: dict[str, float], exc: type) -> None:
    with pytest.raises(exc):
        cls(**kw)


def test_negative_frequency_rejected() -> None:
    with pytest.raises(InputError, match="freq_hz"):
        EXAMPLES[0].receptance([-1.0, 1.0])


@pytest.mark.parametrize("model", EXAMPLES, ids=lambda m: m.name)
def test_dict_round_trip(model: LateralModel) -> None:
    back = LateralModel.from_dict(model.to_dict())
    assert back == model
    assert type(back) is MODELS[model.name]


def test_model_names_and_aliases() -> None:
    assert get_model_class("proposed") is HystereticModel
    assert get_model_class("Lines") is ViscoPlasticModel
    assert get_model_class("kelvin-voigt") is ClassicModel
    with pytest.raises(InputError, match="expected one of"):
        get_model_class("magic-formula")


# ---------------------------------------------------------------------------- axle force
def test_axle_accelerance_against_two_dof_solution() -> None:
    # Independent check of A_axle = A_g/(1 + M A_g): wheel mass M on a Maxwell tyre with
    # internal node z (spring k between wheel and z, damper c between z and ground).
    # Frequency-domain equations for unit axle force:
    #   -M w^2 y + k (y - z) = 1 ;  k (z - y) + i w c z = 0.
    k, c, mass = 1.3e5, 5e4, 100.0
    model = MaxwellModel(k=k, c=c)
    w = 2 * np.pi * FPOS
    acc = []
    for wi in w:
        a = np.array([[-mass * wi**2 + k, -k], [-k, k + 1j * wi * c]])
        y, _ = np.linalg.solve(a, np.array([1.0, 0.0]))
        acc.append(-(wi**2) * y)
    # 2x2 solve against the closed form: rounding.
    assert_allclose(model.axle_accelerance(FPOS, mass), np.array(acc), rtol=1e-11)


@settings(max_examples=50, deadline=None)
@given(
    re=st.floats(-1.0, 1.0),
    im=st.floats(-1.0, 1.0),
    mass=st.floats(0.0, 500.0),
)
def test_axle_ground_round_trip(re: float, im: float, mass: float) -> None:
    a = np.array([complex(re, im) * 1e-2])
    ax = axle_from_ground_accelerance(a, mass)
    if abs(1 + mass * a[0]) < 1e-6:
        return
    # Inverse maps: rounding (conditioned by |1 + M A| >= 1e-6).
    assert_allclose(ground_from_axle_accelerance(ax, mass), a, rtol=1e-8, atol=1e-14)


# ----------------------------------------------------------------------- Fiala / brush
def test_fiala_small_slip_slope_is_cornering_stiffness() -> None:
    t = FialaTyre(K_alpha=8e4, mu=0.8, load=12e3)
    da = 1e-9
    slope = (t.lateral_force(da) - t.lateral_force(-da)) / (2 * da)
    # The odd psi|psi|/3 term makes the central difference first order: relative error
    # K_alpha da / (3 mu W) = 2.8e-9 (rounding is far smaller).
    assert_allclose(slope, 8e4, rtol=1e-8)
    # Damper form: c(0) = K_alpha / V, and the describing function tends to it.
    assert_allclose(t.damper_coefficient(0.0, 1.39), 8e4 / 1.39, rtol=1e-15)
    # First-harmonic damping at U = 1e-6 m/s: the cubic corrections are O(K U/(mu W V)) ~ 1e-5.
    assert_allclose(t.equivalent_damping(1e-6, 1.39), 8e4 / 1.39, rtol=1e-4)


def test_fiala_saturation_and_symmetry() -> None:
    t = FialaTyre(K_alpha=8e4, mu=0.8, load=12e3)
    a_sl = t.sliding_slip_angle
    # Continuous at full sliding (psi = 3): the polynomial reaches mu W (rounding).
    assert_allclose(t.lateral_force(a_sl * (1 - 1e-12)), 0.8 * 12e3, rtol=1e-9)
    assert t.lateral_force(2 * a_sl) == 0.8 * 12e3
    a = np.linspace(-0.5, 0.5, 41)
    assert_allclose(t.lateral_force(-a), -t.lateral_force(a), rtol=1e-15)
    assert np.all(np.diff(t.lateral_force(a)) >= 0)
    with pytest.raises(InputError):
        t.lateral_force(2.0)


@settings(max_examples=50, deadline=None)
@given(ydot=st.floats(-3.0, 3.0), v=st.floats(0.5, 20.0))
def test_fiala_damper_forms_agree(ydot: float, v: float) -> None:
    t = FialaTyre(K_alpha=8e4, mu=0.8, load=12e3)
    # c(y') y' (eq. 5-6) and Fy(tan alpha = y'/V) are the same function: rounding.
    assert_allclose(
        t.damper_coefficient(ydot, v) * ydot, t.damper_force(ydot, v), rtol=1e-10, atol=1e-9
    )
