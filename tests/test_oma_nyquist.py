"""The Nyquist wave number of an even number of equally spaced fixed sensors (oma.nyquist)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.signal import lfilter

from tyredamp.oma import spatial
from tyredamp.oma.nyquist import nyquist_candidates, resolve_nyquist

FS, K, WHEEL_HZ = 128.0, 8, 2.0
NYQ = K // 2


def test_nyquist_wave_number_and_its_pattern() -> None:
    assert spatial.nyquist_wave_number(16) == 8
    assert spatial.nyquist_wave_number(8) == 4
    assert spatial.nyquist_wave_number(15) is None  # odd K: every n <= 7 keeps its direction
    # at theta_k = theta_0 + 2 pi k / K both waves of n = K / 2 are e^{+-i n theta_0} (-1)^k
    th = np.deg2rad(10.0 + np.arange(K) * 360.0 / K)
    fwd, bwd = np.exp(-1j * NYQ * th), np.exp(1j * NYQ * th)
    alt = (-1.0) ** np.arange(K)
    assert_allclose(fwd, np.exp(-1j * NYQ * th[0]) * alt, atol=1e-12)  # round-off
    assert_allclose(bwd, np.exp(1j * NYQ * th[0]) * alt, atol=1e-12)  # round-off


def test_candidates_follow_the_exact_rolling_ring() -> None:
    # the n = 8 backward wave at 120 km/h (the Nyquist wave of 16 sensors): the truth's
    # in-tyre pole against the hypothesis 'against the rotation in space', from the exact
    # gyroscopic ring modes, independently of eq. (1)
    from tyredamp.virtual import RotatingRing
    from tyredamp.virtual.rolling_truth import RollingTruth

    truth = RollingTruth.from_ring(RotatingRing(speed_kmh=120.0), (150.0, 300.0))
    row = truth.wave(8, "backward")
    f_nat = float(abs(truth.poles[list(truth.rotating_hz).index(row["rotating_hz"])]))
    sigma = row["decay_rate"]
    f_fix = float(np.hypot(row["fixed_hz"] * 2 * np.pi, sigma)) / (2 * np.pi)
    fwd, bwd = nyquist_candidates(f_fix, sigma / (2 * np.pi * f_fix), 8, truth.rotation_hz)
    assert (bwd.fixed_direction, bwd.direction) == (row["fixed_direction"], row["direction"])
    # the damped frequency moves exactly, the decay rate is kept: rounding only
    assert_allclose(bwd.rotating_hz, f_nat / (2 * np.pi), rtol=1e-9)
    assert_allclose(bwd.rotating_damping_ratio, row["damping_ratio"], rtol=1e-9)
    # the other hypothesis: 8 f_w below the damped fixed frequency, forward on the tyre
    f_d = row["fixed_hz"] - 8 * truth.rotation_hz
    assert fwd.direction == "forward"
    assert_allclose(fwd.rotating_hz, np.hypot(f_d, sigma / (2 * np.pi)), rtol=1e-12)  # rounding


def _ring(tyre_k: int, f_rot: float, zeta: float, n_samples: int, seed: int, wheel=WHEEL_HZ):
    """K fixed sensors and one in-tyre sensor seeing one random stationary wave
    ``x(t) e^{i k theta}`` of the tyre (``x`` a complex AR(1) of the rotating-frame pole),
    at material angle ``theta = phi - Omega t``, plus 5 % white sensor noise."""
    from tyredamp.frf import Channel
    from tyredamp.timedata import TimeData

    rng = np.random.default_rng(seed)
    lam = complex(-zeta * 2 * np.pi * f_rot, 2 * np.pi * f_rot * np.sqrt(1 - zeta**2))
    e = rng.standard_normal(n_samples + 2000) + 1j * rng.standard_normal(n_samples + 2000)
    x = lfilter([1.0], [1.0, -np.exp(lam / FS)], e)[2000:]
    t = np.arange(n_samples) / FS
    phi = np.deg2rad(np.arange(K) * 360.0 / K)
    turn = np.exp(-1j * tyre_k * 2 * np.pi * wheel * t)  # theta = phi - Omega t
    y = np.real(x[None, :] * turn[None, :] * np.exp(1j * tyre_k * phi[:, None]))
    y = np.vstack([y, x.real[None, :]])  # the in-tyre sensor at theta = 0
    y += 0.05 * np.std(y) * rng.standard_normal(y.shape)
    ch = [Channel(k + 1, angle_deg=float(a), name=f"A{k + 1}")
          for k, a in enumerate(np.rad2deg(phi))] + [Channel(101, name="T1")]  # fmt: skip
    return TimeData(y, FS, ch, ["displacement"] * (K + 1), meta={"rotation_hz": wheel})


#: The same fixed-frame frequency, 30 Hz, both ways: k = +4 (backward on the tyre, 38 Hz
#: in it, seen against the rotation) and k = -4 (forward on the tyre, 22 Hz in it, seen
#: with the rotation): f_fixed = f_rot - k f_w.
CASES = [(+4, 38.0, "backward", "backward"), (-4, 22.0, "forward", "forward")]


@pytest.mark.parametrize(("tyre_k", "f_rot", "direction", "fixed_direction"), CASES)
def test_nyquist_wave_direction_from_the_in_tyre_sensor(
    tyre_k: int, f_rot: float, direction: str, fixed_direction: str
) -> None:
    from tyredamp.oma.rolling import rolling_modes

    zeta = 0.02
    td = _ring(tyre_k, f_rot, zeta, 2**15, seed=3)
    m = rolling_modes(td, uncertainty=False, spatial=True)
    got = [w for w in m.fixed if w.wave_number == NYQ]
    assert len(got) == 1, [(w.wave_number, w.fixed_hz) for w in m.fixed]
    (w,) = got
    assert (w.direction, w.fixed_direction) == (direction, fixed_direction), w.reason
    # 0.5 %: the brief's target; 256 s of a 2 % damped wave fixes it to ~sqrt(zeta f / T)
    assert_allclose(w.fixed_hz, f_rot - tyre_k * WHEEL_HZ, rtol=5e-3)
    assert_allclose(w.rotating_hz, f_rot, rtol=5e-3)  # same, carried through eq. (1)
    assert "Nyquist" in w.reason
    # nothing else: the one wave, in its channel only
    assert len(m.fixed) == 1


def test_nyquist_wave_without_an_in_tyre_sensor_is_unresolved() -> None:
    from tyredamp.oma.rolling import rolling_modes

    td = _ring(+4, 38.0, 0.02, 2**15, seed=4)
    m = rolling_modes(td, fixed_channels=list(range(K)), rotating_channels=[],
                      uncertainty=False, spatial=True)  # fmt: skip
    (w,) = [w for w in m.fixed if w.wave_number == NYQ]
    assert w.direction is None
    assert w.fixed_direction is None
    assert_allclose(w.fixed_hz, 30.0, rtol=5e-3)  # 0.5 %, as above
    # both hypotheses listed with their in-tyre frequencies (30 -+ 4 f_w, to 0.5 %)
    assert sorted(d for _, d, _ in w.candidates) == ["backward", "forward"]
    f_c = sorted(f for _, _, f in w.candidates)
    assert_allclose(f_c, [22.0, 38.0], rtol=5e-3)
    for words in ("no in-tyre sensor", "odd number of sensors", "unequal spacing"):
        assert words in w.reason
    assert w.to_dict()["direction"] is None


def test_nyquist_wave_at_rest_stands_for_both_waves() -> None:
    from tyredamp.oma.rolling import rolling_modes

    m = rolling_modes(_ring(+4, 30.0, 0.02, 2**15, seed=5, wheel=0.0), uncertainty=False,
                      spatial=True)  # fmt: skip
    got = sorted((w.direction, w.fixed_direction) for w in m.fixed if w.wave_number == NYQ)
    # at rest the two waves of n share one frequency: both listed, as for a standing shape
    assert got == [("backward", "backward"), ("forward", "forward")]
    for w in m.fixed:
        assert_allclose(w.fixed_hz, 30.0, rtol=5e-3)  # 0.5 %, as above
        assert w.rotating_hz == w.fixed_hz


def test_resolve_nyquist_rules() -> None:
    f, z, n = 30.0, 0.02, NYQ
    fwd, bwd = nyquist_candidates(f, z, n, WHEEL_HZ)
    sig = z * f  # the decay rate (Hz units), the same in both frames

    def tyre(*poles: tuple[float, float]):
        fr = np.array([p[0] for p in poles])
        zr = np.array([p[1] for p in poles])
        return fr, zr, np.full(fr.size, np.nan), (0.0, 60.0)

    # one in-tyre pole at the backward hypothesis with the wave's decay rate: resolved
    r = resolve_nyquist(f, z, np.nan, n, K, WHEEL_HZ, tyre((bwd.rotating_hz, sig / 38.0)))
    assert r.candidate == bwd
    # a pole there with four times the decay rate is another wave: unresolved
    r = resolve_nyquist(f, z, np.nan, n, K, WHEEL_HZ, tyre((bwd.rotating_hz, 4 * sig / 38.0)))
    assert r.candidate is None
    assert "neither" in r.reason
    # poles at both hypotheses: unresolved
    both = tyre((bwd.rotating_hz, sig / 38.0), (fwd.rotating_hz, sig / 22.0))
    r = resolve_nyquist(f, z, np.nan, n, K, WHEEL_HZ, both)
    assert r.candidate is None
    assert "both" in r.reason
    # the pole at the forward hypothesis is nearer another wave's in-tyre frequency: not counted
    r = resolve_nyquist(f, z, np.nan, n, K, WHEEL_HZ,
                        tyre((bwd.rotating_hz, sig / 38.0), (fwd.rotating_hz + 0.1, sig / 22.0)),
                        others_rotating_hz=[fwd.rotating_hz + 0.1])  # fmt: skip
    assert r.candidate == bwd
