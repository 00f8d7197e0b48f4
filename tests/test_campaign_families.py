"""Names of the campaign's mode families: wave number and member (campaign.families)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tyredamp.campaign.families import MIN_FRACTION, ModeWave, family_names, mode_wave

ANGLES = [22.5 * k for k in range(16)]  # the paper's 16 equally spaced points


def _ring_shape(n: int, antinode_deg: float, phase: float = 0.3) -> np.ndarray:
    """cos n(theta - theta_0) at the 16 points, with an arbitrary complex phase."""
    th = np.radians(ANGLES)
    return np.cos(n * (th - math.radians(antinode_deg))) * np.exp(1j * phase)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 5, 7, 8])
def test_every_resolved_wave_number_is_recognised(n: int) -> None:
    w = mode_wave(ANGLES, _ring_shape(n, 0.0), reference_deg=0.0)
    assert w is not None
    assert w.n == n
    # an exact single harmonic: the fraction is 1 to rounding
    assert w.fraction == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("n", [1, 2, 3, 6])
def test_member_follows_the_antinode_relative_to_the_shaker(n: int) -> None:
    ref = 22.5  # the shaker at point 2
    # antinode at the shaker, or a small offset from it: cos
    assert mode_wave(ANGLES, _ring_shape(n, ref), ref).member == "cos"
    assert mode_wave(ANGLES, _ring_shape(n, ref + 30.0 / n), ref).member == "cos"
    # antinode a quarter wave away (a node at the shaker), or near it: sin
    assert mode_wave(ANGLES, _ring_shape(n, ref + 90.0 / n), ref).member == "sin"
    assert mode_wave(ANGLES, _ring_shape(n, ref - 60.0 / n), ref).member == "sin"
    # antinodes repeat every 180/n deg
    assert mode_wave(ANGLES, _ring_shape(n, ref + 180.0 / n), ref).member == "cos"


def test_a_mixed_shape_is_not_a_single_harmonic() -> None:
    th = np.radians(ANGLES)
    x = np.cos(2 * th) + np.cos(3 * th)  # half the energy in each
    w = mode_wave(ANGLES, x)
    assert w is not None
    assert w.n in (2, 3)
    assert w.fraction == pytest.approx(0.5, abs=1e-12)
    assert not w.single
    assert w.member is None


def test_shapes_without_enough_angles_are_not_labelled() -> None:
    assert mode_wave([0.0, 90.0, None, None], [1, 0, 1, 0]) is None
    assert mode_wave([0.0, 0.0, 360.0], [1, 1, 1]) is None  # one point three times
    assert mode_wave(ANGLES, np.zeros(16)) is None
    # points without an angle are left out, the rest still label the shape
    x = _ring_shape(2, 0.0)
    partial = [a if k % 4 else None for k, a in enumerate(ANGLES)]
    w = mode_wave(partial, x)
    assert w is not None
    assert w.n == 2


def _w(n: int, member: str | None = "cos", fraction: float = 0.99) -> ModeWave:
    return ModeWave(n, fraction, member)


def test_family_takes_the_majority_wave_number_and_member() -> None:
    names = family_names(
        {
            "F1": [_w(1), _w(1), _w(1), _w(2)],  # 3 of 4 agree
            "F2": [_w(2), _w(3)],  # no majority
            "F3": [_w(3, fraction=MIN_FRACTION / 2), None],  # nothing labelled
            "F4": [_w(4, "cos"), _w(4, "sin")],  # tracked as a pair
            "F5": [None, None],  # no shape analysed
            # mixed shapes (a loaded patch): harmonic 1 carries 0.45 + 0.5 + 0.3 = 1.25 of
            # the summed best fractions, harmonic 2 0.6
            "F6": [_w(1, None, 0.45), _w(2, None, 0.6), _w(1, None, 0.5), _w(1, None, 0.3)],
        },
        pairs=["F4"],
    )
    assert names["F1"].wave_number == 1
    assert names["F1"].label == "n=1 cos"
    assert names["F1"].agreement == pytest.approx(0.75)
    assert names["F2"].wave_number is None
    assert names["F2"].label == "F2"
    # no single harmonic: the dominant one, said to be mixed
    assert names["F3"].wave_number == 3
    assert names["F3"].n_labelled == 0
    assert names["F3"].mixed
    assert names["F3"].label == "n=3 mixed"
    assert names["F5"].wave_number is None
    assert math.isnan(names["F5"].agreement)
    assert names["F6"].wave_number == 1
    assert names["F6"].agreement == pytest.approx(3 / 4)  # 3 of 4 modes have 1 as best
    assert names["F6"].fraction == pytest.approx((0.45 + 0.5 + 0.3) / 3)  # closed form
    assert names["F6"].to_dict()["wave_mixed"] is True
    assert not names["F1"].mixed
    assert names["F4"].member == "pair"
    assert names["F4"].label == "n=4"


def test_families_sharing_a_name_are_told_apart_in_frequency_order() -> None:
    names = family_names(
        {"F1": [_w(2, "cos")], "F2": [_w(2, "sin")], "F3": [_w(2, "cos")], "F4": [_w(0, None)]}
    )
    assert [names[f].label for f in ("F1", "F2", "F3", "F4")] == [
        "n=2 cos",
        "n=2 sin",
        "n=2 cos (2nd)",
        "n=0",
    ]
    assert names["F4"].to_dict()["wave_number"] == 0
