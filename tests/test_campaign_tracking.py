"""Mode tracking across conditions and trend fits (tyredamp.campaign.tracking)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp.campaign.tracking import (
    MAC_MIN,
    ModeSet,
    fit_trend,
    group_pairs,
    subspace_mac,
    track_modes,
)
from tyredamp.exceptions import InputError

THETA = np.arange(16) * 2 * np.pi / 16
POINTS = tuple(f"P{k + 1}" for k in range(16))


def ring_shape(n: int, phase: float = 0.0) -> np.ndarray:
    """cos(n (theta - phase)) at the 16 points (a ring mode of wave number n)."""
    return np.cos(n * (THETA - phase)).astype(complex)


def test_mac_of_two_vectors_is_the_closed_form() -> None:
    rng = np.random.default_rng(1)
    u = rng.standard_normal(16) + 1j * rng.standard_normal(16)
    v = rng.standard_normal(16) + 1j * rng.standard_normal(16)
    expected = abs(np.vdot(u, v)) ** 2 / (np.vdot(u, u).real * np.vdot(v, v).real)
    assert_allclose(subspace_mac(u, v), expected, rtol=1e-12)
    assert_allclose(subspace_mac(u, (2 - 3j) * u), 1.0, rtol=1e-12)  # scale-free


def test_subspace_mac_of_a_rotated_pair_is_one() -> None:
    # cos/sin pair of wave number 3, and the same subspace rotated by 17 degrees
    a = np.column_stack([ring_shape(3), ring_shape(3, np.pi / 6)])
    b = np.column_stack([ring_shape(3, 0.3), ring_shape(3, 0.3 + np.pi / 6)])
    assert_allclose(subspace_mac(a, b), 1.0, atol=1e-12)
    # a single rotated mode lies in the pair's plane: MAC 1 against the pair
    assert_allclose(subspace_mac(a, ring_shape(3, 0.77)), 1.0, atol=1e-12)
    # against another wave number the circular harmonics are orthogonal at 16 points
    assert subspace_mac(a, np.column_stack([ring_shape(2), ring_shape(2, 0.5)])) < 1e-20
    # the ordinary MAC of cos 3(theta - 0.3) with cos 3 theta is cos^2(0.9)
    assert_allclose(subspace_mac(ring_shape(3), ring_shape(3, 0.3)), np.cos(0.9) ** 2, rtol=1e-12)


def test_group_pairs_uses_overlapping_half_power_bands() -> None:
    f = np.array([50.0, 50.5, 80.0, 100.0, 104.5])
    z = np.array([0.02, 0.02, 0.02, 0.02, 0.02])
    # 50/50.5: 0.5 < 1 + 1.01 -> pair; 100/104.5: 4.5 > 2 + 2.09 -> not a pair
    assert group_pairs(f, z) == [(0, 1), (2,), (3,), (4,)]
    # order of the input does not matter
    assert group_pairs(f[::-1], z) == [(4, 3), (2,), (1,), (0,)]


def _sweep(pressures: np.ndarray, labels: dict[str, list[int]], tyre: str = "A") -> list[ModeSet]:
    """Ring modes n = 2, a close cos/sin pair n = 3 (its plane rotating from test to test)
    and n = 4, moving with pressure, listed in a random order in each test; ``labels``
    gets the true wave number of every listed mode."""
    sets = []
    rng = np.random.default_rng(5)
    for k, p in enumerate(pressures):
        freqs = np.array([60 + 4 * p, 100 + 3 * p, 100.4 + 3 * p, 140 + 2 * p])
        shapes = np.column_stack(
            [
                ring_shape(2),
                ring_shape(3, 0.2 * k),
                ring_shape(3, 0.2 * k + np.pi / 6),
                ring_shape(4),
            ]
        )
        order = rng.permutation(4)
        noise = 1e-3 * (rng.standard_normal((16, 4)) + 1j * rng.standard_normal((16, 4)))
        tid = f"{tyre}{k}"
        labels[tid] = [[2, 3, 3, 4][i] for i in order]
        sets.append(
            ModeSet(
                tid,
                {"tyre": tyre, "pressure_bar": float(p)},
                freqs[order],
                np.full(4, 0.02),
                shapes[:, order] + noise,
                POINTS,
            )
        )
    return sets


def test_tracking_keeps_families_and_pairs_without_swaps() -> None:
    labels: dict[str, list[int]] = {}
    p = np.linspace(5, 9, 5)
    sets = _sweep(p, labels) + _sweep(p[::-1], labels, tyre="B")
    tr = track_modes(sets)
    # every mode gets a family; the families are the wave numbers, across both tyres
    by_family: dict[str, set[int]] = {}
    for s in sets:
        for q in range(4):
            by_family.setdefault(tr.family[(s.test_id, q)], set()).add(labels[s.test_id][q])
    assert by_family == {"F1": {2}, "F2": {3}, "F3": {4}}  # no swap anywhere
    assert tr.pairs == {"F2"}
    for s in sets:  # the pair: slot a is the lower frequency
        i = [q for q in range(4) if tr.family[(s.test_id, q)] == "F2"]
        lo, hi = sorted(i, key=lambda q: s.frequency_hz[q])
        assert (tr.slot[(s.test_id, lo)], tr.slot[(s.test_id, hi)]) == ("a", "b")


def test_tracking_follows_a_mode_by_shape_when_frequencies_cross() -> None:
    # n = 2 rises from 70 to 100 Hz and n = 5 falls from 100 to 70 Hz across the sweep;
    # shapes tell them apart, so each keeps its family (ordering by frequency would swap)
    sets = []
    for k, t in enumerate(np.linspace(0, 1, 7)):
        fa, fb = 70 + 30 * t, 100 - 30 * t + (0.5 if k == 3 else 0.0)
        sets.append(
            ModeSet(
                f"t{k}",
                {"tyre": "A", "pressure_bar": float(k)},
                np.array([fa, fb]),
                np.array([0.001, 0.001]),
                np.column_stack([ring_shape(2), ring_shape(5)]),
                POINTS,
            )
        )
    tr = track_modes(sets)
    fam_a = {tr.family[(s.test_id, 0)] for s in sets}
    fam_b = {tr.family[(s.test_id, 1)] for s in sets}
    assert len(fam_a) == 1
    assert len(fam_b) == 1
    assert fam_a != fam_b


def test_a_mode_with_another_shape_starts_a_new_family() -> None:
    a = ModeSet(
        "a", {"tyre": "A", "pressure_bar": 6.0}, [50.0], [0.02], ring_shape(2)[:, None], POINTS
    )
    b = ModeSet(
        "b", {"tyre": "A", "pressure_bar": 7.0}, [51.0], [0.02], ring_shape(4)[:, None], POINTS
    )
    tr = track_modes([a, b])
    assert subspace_mac(ring_shape(2), ring_shape(4)) < MAC_MIN
    assert tr.family[("a", 0)] != tr.family[("b", 0)]


def test_modeset_checks_shapes() -> None:
    with pytest.raises(InputError, match="shapes"):
        ModeSet("x", {}, [1.0, 2.0], [0.1, 0.1], np.ones((16, 3)), POINTS)


def test_trend_recovers_a_line_and_its_standard_error() -> None:
    # y = 3 + 2 x with independent errors of sigma 0.1: a straight line is chosen; the
    # standard error of the fitted value at x is sigma sqrt(1/n + (x - xm)^2 / Sxx)
    x = np.repeat(np.linspace(0.0, 4.0, 5), 4)
    rng = np.random.default_rng(3)
    y = 3 + 2 * x + 0.1 * rng.standard_normal(x.size)
    fit = fit_trend(x, y, np.full(x.size, 0.1))
    assert fit.degree == 1
    val, se = fit.predict([2.0, 4.0])
    sxx = np.sum((x - x.mean()) ** 2)
    # the reduced chi-square is near 1; the band is never below the stated errors
    s = max(1.0, np.sqrt(np.sum((y - (fit.predict(x)[0])) ** 2) / 0.01 / (x.size - 2)))
    assert_allclose(se, s * 0.1 * np.sqrt(1 / x.size + (np.array([2.0, 4.0]) - 2) ** 2 / sxx))
    assert np.all(np.abs(val - [7.0, 11.0]) < 4 * se)  # within 4 standard errors


def test_trend_degree_follows_the_data() -> None:
    x = np.linspace(-1, 1, 15)
    rng = np.random.default_rng(0)
    y = 1 + x - 2 * x**2 + 0.01 * rng.standard_normal(x.size)
    assert fit_trend(x, y, np.full(x.size, 0.01)).degree == 2
    assert fit_trend(x, 5 + 0.01 * rng.standard_normal(x.size)).degree == 0


def test_square_transform_is_exact_for_f_squared_linear_in_pressure() -> None:
    p = np.array([6.0, 6.75, 7.5, 8.25, 9.0])
    f = np.sqrt(1500 + 120 * p)
    fit = fit_trend(p, f, np.full(p.size, 1e-3), transform="square")
    val, _ = fit.predict([6.375, 8.625])
    assert_allclose(val, np.sqrt(1500 + 120 * np.array([6.375, 8.625])), rtol=1e-10)


def test_trend_rejects_too_little_data() -> None:
    with pytest.raises(InputError, match="at least 3"):
        fit_trend([1.0, 2.0], [1.0, 2.0])
    with pytest.raises(InputError, match="transform"):
        fit_trend([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], transform="log")


@settings(max_examples=25, deadline=None)
@given(st.permutations(list(range(10))))
def test_tracking_does_not_depend_on_the_order_of_the_tests(perm: list[int]) -> None:
    labels: dict[str, list[int]] = {}
    p = np.linspace(5, 9, 5)
    sets = _sweep(p, labels) + _sweep(p[::-1], labels, tyre="B")
    ref = track_modes(sets)
    got = track_modes([sets[i] for i in perm])
    assert got.family == ref.family
    assert got.slot == ref.slot
