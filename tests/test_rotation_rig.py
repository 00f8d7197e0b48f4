"""The rolling rig: fixed and in-tyre sensors of a rolling ring, single waves and the recording."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.timedata import TimeData
from tyredamp.virtual import (
    MeasurementLayout,
    PointContact,
    RingTyre,
    RingTyreParameters,
    RotatingRing,
    rolling_response,
    rolling_test,
)
from tyredamp.virtual.rolling_truth import RADIAL_OBSERVABLE, RollingTruth, signed_wave_numbers

SPEED = 80.0
FS = 1024.0


@pytest.fixture(scope="module")
def light_ring() -> RotatingRing:
    """A lightly damped 32-node ring at 80 km/h (sharp spectral peaks, fast)."""
    p = RingTyreParameters(radial_damping=5.0, tangential_damping=5.0, band_loss_factor=0.0)
    layout = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    return RotatingRing(RingTyre(p, layout, n_ring=32, nonproportionality=1.0), SPEED)


def _single_wave(ring: RotatingRing, k: int) -> tuple[int, np.ndarray]:
    modes = ring.system.state_modes()
    n = ring.n_ring
    kk, _ = signed_wave_numbers(modes.displacement[:n], modes.displacement[n:])
    j = int(np.flatnonzero(kk == k)[0])
    q0 = np.zeros(modes.poles.size, complex)
    q0[j] = 1e-3
    return j, q0


@pytest.mark.parametrize("k", [-3, 3])
def test_single_wave_kinematics_are_exact(light_ring: RotatingRing, k: int) -> None:
    ring = light_ring
    modes = ring.system.state_modes()
    j, q0 = _single_wave(ring, k)
    n = ring.n_ring
    theta = 2 * np.pi * np.arange(n) / n
    c = np.mean(modes.displacement[:n, j] * np.exp(-1j * k * theta)) * q0[j]
    t = np.arange(512) / FS
    p = modes.poles[j]
    phi, th = np.deg2rad(40.0), np.deg2rad(100.0)
    fixed = np.exp(1j * k * (phi - ring.omega * t) + p * t)
    rot = np.exp(1j * k * th + p * t)
    for quantity, power in (("displacement", 0), ("velocity", 1), ("acceleration", 2)):
        out = rolling_response(
            ring, np.zeros(t.size), FS, fixed_deg=[40.0], rotating_deg=[100.0],
            quantity=quantity, modes=modes, q0=q0,
        )  # fmt: skip
        # a fixed point sees d/dt = p - i k Omega (convected), a material point d/dt = p
        want_fixed = 2 * np.real(c * (p - 1j * k * ring.omega) ** power * fixed)
        want_rot = 2 * np.real(c * p**power * rot)
        scale = np.max(np.abs(want_fixed))
        # 1e-6 of the amplitude: the shape is a pure harmonic to ~1e-8; the recursion is exact
        assert_allclose(out[0], want_fixed, atol=1e-6 * scale)
        assert_allclose(out[1], want_rot, atol=1e-6 * scale)


@pytest.mark.parametrize("k", [-3, 3])
def test_single_wave_spectral_peaks(light_ring: RotatingRing, k: int) -> None:
    ring = light_ring
    modes = ring.system.state_modes()
    j, q0 = _single_wave(ring, k)
    n_samples = 4096  # 4 s: 0.25 Hz lines
    out = rolling_response(
        ring, np.zeros(n_samples), FS, fixed_deg=[0.0, 67.5], rotating_deg=[30.0],
        modes=modes, q0=q0,
    )  # fmt: skip
    freq = np.fft.rfftfreq(n_samples, 1 / FS)
    peaks = freq[np.argmax(np.abs(np.fft.rfft(out * np.hanning(n_samples), axis=1)), axis=1)]
    w = modes.poles[j].imag
    f_rot = w / (2 * np.pi)
    f_fix = abs(w - k * ring.omega) / (2 * np.pi)
    line = FS / n_samples
    # within one line: fixed sensors at the Doppler-shifted frequency, the in-tyre one unshifted
    assert np.all(np.abs(peaks[:2] - f_fix) <= line)
    assert abs(peaks[2] - f_rot) <= line
    # and the shift is real: the two frequencies are many lines apart
    assert abs(f_fix - f_rot) > 10 * line
    # forward waves are seen higher from a fixed point, backward ones lower
    assert (f_fix > f_rot) == (k < 0)


def test_point_load_and_sensor_are_transposes(light_ring: RotatingRing) -> None:
    # the load at the contact is the transpose of reading the field there: a unit static
    # nodal field read at any angle equals the sum of the load weights times the field
    ring = light_ring
    turned = np.linspace(0.0, 1.0, 7)
    w = PointContact(30.0).nodal_load(turned, ring.n_ring)
    # 1e-12: the weights of a constant sum to one (the interpolant reproduces n = 0)
    assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    with pytest.raises(InputError, match="contact angle"):
        PointContact(float("nan"))


def test_rolling_test_recording() -> None:
    test = rolling_test(
        40.0, duration=1.0, settle=0.25, n_sensors=4, rotating_deg=(0.0, 90.0),
        known_excitation="impulse", seed=3,
    )  # fmt: skip
    data = test.data
    assert isinstance(data, TimeData)
    assert [c.name for c in data.channels] == ["F1", "A1", "A2", "A3", "A4", "T1", "T2"]
    assert data.quantities == ("force",) + ("acceleration",) * 6
    assert [c.angle_deg for c in data.channels[1:5]] == [0.0, 90.0, 180.0, 270.0]
    assert data.n_samples == 1024
    assert data.meta["rolling_truth"] == test.truth.table()
    assert data.meta["speed_kmh"] == 40.0
    assert np.all(np.std(data.data, axis=1) > 0)
    # the same seed gives the same recording
    again = rolling_test(
        40.0, duration=1.0, settle=0.25, n_sensors=4, rotating_deg=(0.0, 90.0),
        known_excitation="impulse", seed=3,
    )  # fmt: skip
    assert_allclose(again.data.data, data.data, rtol=0, atol=0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"speed_kmh": -5.0}, "speed: expected a finite speed >= 0"),
        ({"speed_kmh": float("nan")}, "speed: expected a finite speed >= 0"),
        ({"speed_kmh": 400.0}, "critical .* 356 km/h"),
        ({"speed_kmh": 10.0, "band": (0.0, 600.0)}, "band"),
        ({"speed_kmh": 10.0, "n_sensors": 0, "rotating_deg": ()}, "at least one"),
        ({"speed_kmh": 10.0, "known_excitation": "hammer"}, "known excitation"),
        ({"speed_kmh": 10.0, "quantity": "jerk"}, "quantity"),
    ],
)
def test_rolling_test_refuses_bad_options(kwargs: dict, match: str) -> None:
    with pytest.raises(InputError, match=match):
        rolling_test(duration=0.05, settle=0.0, **kwargs)


def test_harmonic_road_force_gives_the_fixed_frame_modal_sum() -> None:
    # heavily damped 32-node ring: the transient is gone after 0.3 s
    p = RingTyreParameters(radial_damping=3000.0, tangential_damping=3000.0)
    layout = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    ring = RotatingRing(RingTyre(p, layout, n_ring=32, nonproportionality=1.0), SPEED)
    modes = ring.system.state_modes()
    n = ring.n_ring
    k, _ = signed_wave_numbers(modes.displacement[:n], modes.displacement[n:])
    theta = 2 * np.pi * np.arange(n) / n
    # each mode is a pure harmonic: shape c e^{ik theta}, input row u e^{-ik theta}
    c = np.array(
        [np.mean(modes.displacement[:n, j] * np.exp(-1j * kk * theta)) for j, kk in enumerate(k)]
    )
    u = np.array([np.mean(modes.input[j, :n] * np.exp(1j * kk * theta)) for j, kk in enumerate(k)])
    c[np.abs(k) == n // 2] = 0.0  # the grid's standing Nyquist pattern is neither loaded nor read
    fs, nu = 8192.0, 2 * np.pi * 100.0
    t = np.arange(int(0.6 * fs)) / fs
    phi, phi_c = np.deg2rad(45.0), np.deg2rad(10.0)
    out = rolling_response(
        ring, np.cos(nu * t), fs, fixed_deg=[45.0], contact=PointContact(10.0),
        quantity="displacement", modes=modes,
    )[0]  # fmt: skip
    # load at phi_c - Omega t, read at phi - Omega t: in the fixed frame each mode answers
    # e^{+-i nu t} with the pole moved by -i k Omega (time-invariant, Doppler-shifted)
    a = c * u * np.exp(1j * k * (phi - phi_c)) / 2
    up = np.exp(1j * nu * t)[None, :] / (1j * (nu + k * ring.omega) - modes.poles)[:, None]
    down = np.exp(-1j * nu * t)[None, :] / (1j * (k * ring.omega - nu) - modes.poles)[:, None]
    want = 2 * np.real(np.sum(a[:, None] * (up + down), axis=0))
    steady = t >= 0.3
    # 5e-4 of the amplitude: the first-order hold of the moving load, (nu h)^2 / 12 = 2e-4
    scale = np.max(np.abs(want[steady]))
    assert_allclose(out[steady], want[steady], atol=5e-4 * scale)


@pytest.mark.parametrize("speed", [0.0, 120.0])
def test_the_rotation_mode_is_not_radially_observable(speed: float) -> None:
    """The n = 0 rotation of a symmetric ring is purely tangential at rest (no
    radial term couples to a uniform tangential displacement); rolling couples
    it to the radial motion only through the Coriolis forces, weakly."""
    ring = RotatingRing(speed_kmh=speed)
    truth = RollingTruth.from_ring(ring, (20.0, 200.0))
    rows = truth.table()
    rotation = [r for r in rows if r["wave_number"] == 0]
    assert len(rotation) == 1
    (rot,) = rotation
    assert not rot["radially_observable"]
    assert rot["radial_share"] < (1e-20 if speed == 0 else RADIAL_OBSERVABLE / 10)
    # every travelling wave of the band has a large radial part
    assert all(r["radially_observable"] for r in rows if r["wave_number"] > 0)
    assert min(r["radial_share"] for r in rows if r["wave_number"] > 0) > 0.3
