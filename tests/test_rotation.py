"""The rotating ring: closed-form dispersion, its limits and the discretised gyroscopic ring."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, PhysicsError, ShapeError
from tyredamp.mechanics import GyroscopicSystem, MCKSystem
from tyredamp.virtual import (
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    RollingTruth,
    RotatingRing,
    analytic_ring_frequencies,
    critical_speed_kmh,
    inextensible_rotating_frequencies,
    ring_dispersion,
    rotating_ring_dispersion,
    rotating_ring_roots,
)
from tyredamp.virtual.rolling_truth import signed_wave_numbers
from tyredamp.virtual.rotation import spin_rate, trig_interpolation

N_WAVES = np.arange(1, 7)
BARE = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)


def _bare_ring(speed_kmh: float, params: RingTyreParameters | None = None) -> RotatingRing:
    tyre = RingTyre(params, BARE, nonproportionality=1.0)
    return RotatingRing(tyre, speed_kmh)


def _discrete_waves(ring: RotatingRing) -> np.ndarray:
    """Forward and backward rotating-frame frequencies (Hz) of n = 1..6, shape (6, 2).

    At rest the two members of a double mode are any mix of +-n (standing waves), so
    they are taken as the lower and upper of the two lowest modes of |k| = n.
    """
    modes = ring.system.state_modes()
    n = ring.n_ring
    k, _ = signed_wave_numbers(modes.displacement[:n], modes.displacement[n:])
    out = np.empty((N_WAVES.size, 2))
    for i, nn in enumerate(N_WAVES):
        idx = np.flatnonzero(np.abs(k) == nn)[:2]
        f, kk = modes.frequency_hz[idx], k[idx]
        out[i] = [f[kk < 0][0], f[kk > 0][0]] if ring.omega > 0 else np.sort(f)
    return out


def _undamped() -> RingTyreParameters:
    return RingTyreParameters(radial_damping=0.0, tangential_damping=0.0, band_loss_factor=0.0)


def _companion_roots(params: RingTyreParameters, n: int, speed_kmh: float) -> np.ndarray:
    """The 2x2 quadratic eigenproblem solved as a 4x4 generalised eigenproblem (independent)."""
    om = speed_kmh / 3.6 / params.radius
    r, m = params.radius, params.mass_per_length
    ea, ei, t0 = params.membrane_stiffness, params.bending_stiffness, params.hoop_tension
    # static ring (Soedel's extensible ring energy, as in ring.py) plus rotation, written out
    k11 = (ea + t0) / r**2 + ei * n**4 / r**4 + t0 * (n**2 - 1) / r**2 + params.radial_stiffness
    k12 = (ea + t0) * n / r**2 + ei * n**3 / r**4
    k22 = (ea + t0) * n**2 / r**2 + ei * n**2 / r**4 + params.tangential_stiffness
    n0 = m * r**2 * om**2
    green = n0 / r**2 * np.array([[n**2 + 1, 2 * n], [2 * n, n**2 + 1]])
    k = np.array([[k11, k12], [k12, k22]]) + green - m * om**2 * np.eye(2)
    g = 2 * m * om * np.array([[0.0, 1.0], [1.0, 0.0]])
    # (K - omega g - omega^2 m I) y = 0, linearised in omega = sc * lam with the
    # scale sc = sqrt(max|K| / m) (balances the companion matrix)
    sc = np.sqrt(np.max(np.abs(k)) / m)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [k / (m * sc**2), -g / (m * sc)]])
    return np.sort(sla.eigvals(a).real * sc)


@pytest.mark.parametrize("speed", [0.0, 40.0, 80.0, 120.0])
def test_discrete_ring_matches_closed_form_within_one_percent(speed: float) -> None:
    ring = _bare_ring(speed)
    discrete = _discrete_waves(ring)
    closed = rotating_ring_dispersion(ring.tyre.params, N_WAVES, speed)
    # 1 %: the task's bound; the discretisation (n_ring = 64, order 4) and the damping of the
    # default tyre (zeta^2/2 < 0.05 %) stay well inside it
    assert_allclose(discrete, closed, rtol=0.01)
    if speed > 0:
        # forward below backward in the rotating frame (Coriolis), by more than the tolerance
        assert np.all(closed[:, 1] - closed[:, 0] > 0.02 * closed[:, 0] / N_WAVES)


def test_undamped_discrete_ring_is_the_discrete_symbol_dispersion() -> None:
    p = _undamped()
    ring = _bare_ring(80.0, p)
    discrete = _discrete_waves(ring)
    closed = rotating_ring_dispersion(p, N_WAVES, 80.0, n_ring=ring.n_ring)
    # 1e-7: the axisymmetric discrete waves are exact harmonics; only rounding is left
    assert_allclose(discrete, closed, rtol=1e-7)


@pytest.mark.parametrize("speed", [0.0, 40.0, 120.0])
def test_quartic_roots_match_the_linearised_2x2_eigenproblem(speed: float) -> None:
    p = RingTyreParameters()
    roots = rotating_ring_roots(p, N_WAVES, speed)
    for i, n in enumerate(N_WAVES):
        # 1e-8: two exact solutions of one polynomial problem, rounding only
        assert_allclose(roots[i], _companion_roots(p, int(n), speed), rtol=1e-8)


def test_zero_speed_is_the_static_ring() -> None:
    p = RingTyreParameters()
    f = rotating_ring_dispersion(p, N_WAVES, 0.0)
    # 1e-10: the same 2x2 problem without rotation terms
    assert_allclose(f[:, 0], ring_dispersion(p, N_WAVES), rtol=1e-10)
    assert_allclose(f[:, 1], ring_dispersion(p, N_WAVES), rtol=1e-10)


def test_inextensible_limit_is_bryans_formula() -> None:
    p = RingTyreParameters(membrane_stiffness=1e13)
    for speed in (10.0, 80.0):
        ext = rotating_ring_dispersion(p, N_WAVES, speed)
        # 1e-5: EA / (k R^2) ~ 1e7, the extensible correction is of that order
        assert_allclose(ext, inextensible_rotating_frequencies(p, N_WAVES, speed), rtol=1e-5)
    # at rest the inextensible formula is the static one of the spec
    assert_allclose(
        inextensible_rotating_frequencies(p, N_WAVES, 0.0)[:, 0],
        analytic_ring_frequencies(p, N_WAVES),
        rtol=1e-12,  # the same expression
    )


def test_bryan_factor_of_the_slowly_spinning_free_ring() -> None:
    # a nearly free ring: no pressure, foundation 1e-6 of the default
    p = RingTyreParameters(
        pressure=0.0,
        radial_stiffness_base=1.0,
        tangential_stiffness_base=1.0,
        membrane_stiffness=1e12,
    )
    speed = 0.5  # km/h: Omega << omega_0
    om = spin_rate(speed, p.radius)
    f = rotating_ring_dispersion(p, np.arange(2, 6), speed)
    n = np.arange(2, 6)
    # Bryan (1890): the pattern lags the ring at 2 Omega/(n^2+1), the split is 4 n Omega/(n^2+1)
    expected = 4 * n * om / (n**2 + 1) / (2 * np.pi)
    # 1e-4: second-order terms in Omega / omega_0 ~ 1e-3 are left
    assert_allclose(f[:, 1] - f[:, 0], expected, rtol=1e-4)


def test_translation_mode_is_not_doppler_shifted() -> None:
    # n = 1 of the inextensible ring is the rigid translation of the belt: in the fixed frame
    # it sits at its static frequency whatever the speed (omega = Omega -+ omega_0)
    p = RingTyreParameters(membrane_stiffness=1e13)
    f0 = analytic_ring_frequencies(p, [1])[0]
    for speed in (20.0, 120.0):
        fixed = rotating_ring_dispersion(p, [1], speed, frame="fixed")[0]
        # 1e-6: exact in the inextensible limit; EA = 1e13 leaves ~1e-7
        assert_allclose(fixed, [f0, f0], rtol=1e-6)


def test_fixed_frame_split_at_10_kmh() -> None:
    p = RingTyreParameters()
    f_rot = spin_rate(10.0, p.radius) / (2 * np.pi)
    fixed = rotating_ring_dispersion(p, [3], 10.0, frame="fixed")[0]
    half = 0.5 * (fixed[0] - fixed[1])
    # the reference estimate +- n f_rot (pure Doppler) is 2.65 Hz; the Coriolis split in the
    # rotating frame takes 2 n f_rot/(n^2+1) off it: n f_rot (n^2-1)/(n^2+1) = 2.12 Hz
    assert 2.0 < half < 2.65
    # 2 %: EA, the foundation and the Omega^2 terms move it slightly from the Bryan value
    assert_allclose(half, 3 * f_rot * 8 / 10, rtol=0.02)
    truth = RollingTruth.from_ring(_bare_ring(10.0), (0.0, 150.0))
    fwd, bwd = truth.wave(3, "forward"), truth.wave(3, "backward")
    # 0.5 %: the discrete damped ring against the continuous closed form
    assert_allclose([fwd["fixed_hz"], bwd["fixed_hz"]], fixed, rtol=0.005)
    assert fwd["fixed_direction"] == "forward"
    assert bwd["fixed_direction"] == "backward"


def test_rolling_truth_table_frames_are_doppler_related() -> None:
    ring = _bare_ring(60.0)
    truth = RollingTruth.from_ring(ring, (0.0, 200.0))
    rows = truth.table()
    assert rows
    assert rows == sorted(rows, key=lambda r: r["fixed_hz"])
    for r in rows:
        k = {"forward": -1, "backward": 1, "standing": 0}[r["direction"]] * r["wave_number"]
        # 1e-9: the definition |f_rot - k f_spin|, rounding only
        assert_allclose(r["fixed_hz"], abs(r["rotating_hz"] - k * ring.rotation_hz), rtol=1e-9)
        assert r["purity"] > 0.99  # the perfect ring's waves are pure harmonics
    assert "rotating Hz" in truth.format()
    with pytest.raises(InputError, match="no forward wave with wave number 30"):
        truth.wave(30, "forward")


def test_critical_speed_and_bad_speeds() -> None:
    p = RingTyreParameters()
    v_c = critical_speed_kmh(p)
    # (T0 + 2 sqrt(k_r EI)) / rho A with T0 = 9e4 N, k_r = 1.5e6, EI = 50, rho A = 11
    assert_allclose(v_c, 3.6 * np.sqrt((9e4 + 2 * np.sqrt(1.5e6 * 50)) / 11), rtol=1e-12)
    assert critical_speed_kmh(p.with_pressure(2e5)) < v_c  # less tension, lower speed
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="speed"):
            spin_rate(bad, 0.5)
    with pytest.raises(InputError, match="wave numbers"):
        rotating_ring_dispersion(p, [0], 10.0)
    with pytest.raises(InputError, match="frame"):
        rotating_ring_dispersion(p, [1], 10.0, frame="moving")


def test_trig_interpolation_is_exact_for_harmonics() -> None:
    n = 16
    theta = 2 * np.pi * (np.arange(n) + 0.5) / n
    x = np.linspace(0, 2 * np.pi, 37)
    for k in (0, 3, 7):
        f = np.cos(k * theta + 0.3)
        w0 = trig_interpolation(x, n, offset=0.5)
        w1 = trig_interpolation(x, n, offset=0.5, derivative=1)
        w2 = trig_interpolation(x, n, offset=0.5, derivative=2)
        # 1e-12: the interpolant reproduces harmonics below n/2 exactly
        assert_allclose(w0 @ f, np.cos(k * x + 0.3), atol=1e-12)
        assert_allclose(w1 @ f, -k * np.sin(k * x + 0.3), atol=1e-11)
        assert_allclose(w2 @ f, -(k**2) * np.cos(k * x + 0.3), atol=1e-10)


def test_gyroscopic_system_without_rotation_is_the_mck_system() -> None:
    rng = np.random.default_rng(3)
    a = rng.standard_normal((4, 4))
    k = a @ a.T + 4 * np.eye(4)
    m = np.diag([1.0, 2.0, 1.5, 0.5])
    c = 0.01 * k
    modes = GyroscopicSystem(m, c, k).state_modes()
    ref = MCKSystem(m, c, k).complex_modes().poles
    # 1e-10: two eigen-solvers of one problem
    assert_allclose(np.sort_complex(modes.poles), np.sort_complex(ref), rtol=1e-10)
    with pytest.raises(ShapeError):
        GyroscopicSystem(m, c[:3, :3], k)
    with pytest.raises(PhysicsError, match="positive definite"):
        GyroscopicSystem(-m, c, k)
    with pytest.raises(PhysicsError, match="non-oscillating"):
        GyroscopicSystem(m, 100 * np.eye(4), k).state_modes()


def test_rotating_ring_matrices() -> None:
    ring = _bare_ring(50.0)
    # Coriolis is skew-symmetric, the rotation stiffness symmetric
    assert_allclose(ring.G, -ring.G.T, atol=0)
    assert_allclose(ring.K_rotation, ring.K_rotation.T, atol=0)
    p = ring.tyre.params
    om = spin_rate(50.0, p.radius)
    assert_allclose(ring.hoop_tension, p.hoop_tension + p.mass_per_length * (p.radius * om) ** 2)
    assert "50 km/h" in repr(ring)
    with pytest.raises(InputError, match="RingTyre"):
        RotatingRing("tyre", 10.0)  # type: ignore[arg-type]
