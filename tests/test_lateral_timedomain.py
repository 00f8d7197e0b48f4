"""Time domain: exact steady states, non-causal precursor, causal approximation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.lateral import (
    ClassicModel,
    GeneralizedMaxwellTyre,
    HystereticModel,
    LateralVehicle,
    MaxwellModel,
    RelaxationLengthModel,
    StretchedStringModel,
    ViscoPlasticModel,
    causal_error,
    fit_generalized_maxwell,
    harmonic_response,
    impulse_response,
    periodic_response,
    precursor,
    state_space,
    transient_response,
)

K = 260e3
SPEC_OSCILLATOR = LateralVehicle(HystereticModel(K, 0.077 * K, math.inf), 600.0)


def test_precursor_of_spec_oscillator_is_about_two_percent() -> None:
    p = precursor(SPEC_OSCILLATOR, sample_rate=1000.0, duration=64.0)
    # Spec: "about 2 % of the peak". Ours: 2.02 %; converged to 1e-4 between 200 and
    # 2000 samples/s (checked offline), so 0.0195-0.0210 bounds the discretisation.
    assert 0.0195 < p.ratio < 0.0210
    assert -0.01 < p.time_of_max < 0
    # A causal (viscous) oscillator with the same resonance has no precursor beyond the
    # FFT's aliasing (< 1e-3 of the peak).
    causal = LateralVehicle(ClassicModel(K, 2 * 0.0385 * math.sqrt(K * 600.0)), 600.0)
    assert precursor(causal).ratio < 1e-3


def test_impulse_response_with_series_damper() -> None:
    # Maxwell tyre under a body: causal, with a permanent offset V(0) = 1/c per unit impulse.
    veh = LateralVehicle(MaxwellModel(K, 3e5), 600.0)
    ir = impulse_response(veh, 1000.0, 64.0)
    # Settles to 1/c (exact final value). The 0 Hz line of the regular part is extrapolated
    # quadratically from three lines (error O(df^3)); measured 2.7e-6, bound 1e-5.
    assert_allclose(ir.response[-1], 1 / 3e5, rtol=1e-5)
    # Against the exact state-space impulse response (x(0+) = B). The response has a kink at
    # t = 0 (slope 0 -> 1/M) that the band-limited FFT rounds off: error O(1/fs) there
    # (2.1e-3 of the peak at 1000 samples/s, 4.2e-3 at 500), far smaller elsewhere.
    from scipy.signal import lsim

    sys = state_space(veh)
    pos = ir.time >= 0
    _, y, _ = lsim(sys, np.zeros(pos.sum()), ir.time[pos], X0=sys.B[:, 0])
    peak = np.max(np.abs(ir.response))
    err = np.abs(y[:, 0] - ir.response[pos])
    assert np.max(err) < 3e-3 * peak
    assert np.max(err[ir.time[pos] > 0.05]) < 1e-4 * peak
    assert np.max(np.abs(ir.response[~pos])) < 1e-3 * peak


def test_harmonic_equals_periodic_steady_state() -> None:
    veh = LateralVehicle(HystereticModel(K, 20e3, 3e5), 600.0)
    fs, f0 = 200.0, 2.5  # 80 samples per period; 400 samples = 5 periods
    t = np.arange(400) / fs
    force = 1000.0 * np.cos(2 * np.pi * f0 * t + 0.3)
    for out in ("displacement", "velocity", "acceleration"):
        a = harmonic_response(veh, f0, 1000.0, t, out, phase=0.3)  # type: ignore[arg-type]
        b = periodic_response(veh, force, fs, out)  # type: ignore[arg-type]
        # One FFT line against the closed form: rounding relative to the amplitude.
        assert_allclose(b, a, atol=1e-10 * np.max(np.abs(a)))
    with pytest.raises(InputError, match="non-zero mean"):
        periodic_response(veh, force + 10.0, fs, "displacement")


@pytest.mark.parametrize(
    "tyre",
    [
        ClassicModel(K, 2e3),
        MaxwellModel(K, 3e5),
        ViscoPlasticModel(K, 2e3, 3e5),
        RelaxationLengthModel(8e4, 0.4, 1.39),
        GeneralizedMaxwellTyre(2e5, (3e4, 2e4), (0.1, 0.01), 3e5),
        GeneralizedMaxwellTyre(2e5, (3e4,), (0.05,), math.inf),
    ],
    ids=lambda t: t.name,
)
def test_state_space_frf_matches_model(tyre: object) -> None:
    veh = LateralVehicle(tyre, 600.0)  # type: ignore[arg-type]
    sys = state_space(veh)
    f = np.array([0.1, 1.0, 3.3, 9.0, 40.0])
    h = np.array(
        [
            sys.C @ np.linalg.solve(2j * np.pi * fi * np.eye(sys.A.shape[0]) - sys.A, sys.B) + sys.D
            for fi in f
        ]
    )[:, :, 0]
    # Transfer function of the state-space model against the frequency-domain model:
    # linear solves of size <= 6, rounding.
    assert_allclose(h[:, 0], veh.receptance(f), rtol=1e-9)
    assert_allclose(h[:, 2], veh.accelerance(f), rtol=1e-9)
    # Tyre force = F - M a.
    assert_allclose(h[:, 3], 1 - 600.0 * veh.accelerance(f), rtol=1e-9)


def test_state_space_rejects_non_rational_tyres() -> None:
    with pytest.raises(InputError, match="not causal"):
        state_space(LateralVehicle(HystereticModel(K, 2e4, 3e5), 600.0))
    with pytest.raises(InputError, match="rational"):
        state_space(LateralVehicle(StretchedStringModel(8e4, 0.4, 0.2, 1.39), 600.0))


def test_transient_reaches_exact_periodic_steady_state() -> None:
    # Causal model: the exact transient from rest converges to the frequency-domain steady
    # state (damping time ~ 1 s; after 30 s the difference is e^-30 of the start-up).
    veh = LateralVehicle(ViscoPlasticModel(K, 3e3, 3e5), 600.0)
    fs, f0 = 200.0, 2.73
    t = np.arange(int(35 * fs)) / fs
    force = 1000.0 * np.sin(2 * np.pi * f0 * t)
    tr = transient_response(veh, force, fs)
    exact = harmonic_response(veh, f0, 1000.0, t, "acceleration", phase=-np.pi / 2)
    late = t > 30
    # The simulation is exact for the piecewise-linear force, which differs from the sine by
    # O((f0/fs)^2): measured 9.1e-4 of the amplitude at 200 samples/s, falling as 1/fs^2
    # (3.6e-3, 2.3e-4, 5.7e-5 at 100, 400, 800 samples/s).
    assert_allclose(tr.acceleration[late], exact[late], atol=1.5e-3 * np.max(np.abs(exact)))


def test_generalized_maxwell_approximation() -> None:
    m = HystereticModel(K, 0.077 * K, 3e5)
    gm = fit_generalized_maxwell(m, (0.3, 30.0), per_decade=3, f_ref=3.3)
    f = np.logspace(np.log10(0.3), np.log10(30), 200)
    z = gm.carcass_stiffness(f)
    # Loss matched over the band by NNLS with 3 arms/decade: ripple < 1 % of h.
    assert_allclose(z.imag, m.h, rtol=1e-2)
    # Storage equals K at f_ref by construction (rounding).
    assert_allclose(gm.carcass_stiffness(3.3).real, K, rtol=1e-12)
    # Causal storage must rise through the band (Kramers-Kronig): ~ (2 h/pi) ln(100) = 0.23 K.
    assert z.real[-1] - z.real[0] > 0.15 * K
    assert all(k >= 0 for k in gm.stiffness)
    assert gm.k0 > 0
    with pytest.raises(InputError, match="HystereticModel"):
        fit_generalized_maxwell(MaxwellModel(K, 3e5), (0.3, 30.0))  # type: ignore[arg-type]


def test_causal_error_report() -> None:
    rep = causal_error(SPEC_OSCILLATOR, (0.3, 30.0), sample_rate=250.0, duration=32.0, settle=20.0)
    # The ideal model's precursor (2 %) cannot be reproduced by any causal model, so the
    # impulse error is a few % (3.7 % measured); the 2.73 Hz sine is within 3 % (the storage
    # is matched at the 3.31 Hz resonance and differs by KK at 2.73 Hz).
    assert 0.0195 < rep.precursor_ratio < 0.021
    assert rep.impulse_error < 0.06
    assert rep.sine_error < 0.05
    assert rep.n_arms >= 5
    assert rep.stiffness_error > 0  # reported, not hidden
