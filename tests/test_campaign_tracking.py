"""Mode tracking across conditions and trend fits (tyredamp.campaign.tracking)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from tyredamp.campaign.excitation import single_member_wave_numbers
from tyredamp.campaign.series_trend import fit_trend
from tyredamp.campaign.tracking import (
    MAC_MIN,
    ModeSet,
    group_pairs,
    mode_scatter,
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


# ---------------------------------------------------------------- without shapes to compare
def _single_point_sweep(
    rng: np.random.Generator,
    freqs: np.ndarray,
    pressures: np.ndarray,
    slope: np.ndarray,
    scatter: float,
    point: str = "P1",
) -> tuple[list[ModeSet], dict[str, list[int]]]:
    """Tests with one response point: modes ``freqs * (1 + slope (p - p0))`` with relative
    scatter ``scatter``, in a random order in each test; returns the true mode of each entry."""
    sets, labels = [], {}
    for k, p in enumerate(pressures):
        f = (
            freqs
            * (1 + slope * (p - pressures[0]))
            * np.exp(scatter * rng.standard_normal(freqs.size))
        )
        z = 0.01 * np.exp(0.1 * rng.standard_normal(freqs.size))
        order = rng.permutation(freqs.size)
        tid = f"t{k}"
        labels[tid] = [int(i) for i in order]
        sets.append(
            ModeSet(
                tid,
                {"tyre": "A", "pressure_bar": float(p)},
                f[order],
                z[order],
                np.ones((1, freqs.size), complex),
                (point,),
                np.full(freqs.size, 1e-4) * f[order],
                np.full(freqs.size, 1e-3),
            )
        )
    return sets, labels


def test_one_response_point_tracks_by_frequency_and_damping() -> None:
    rng = np.random.default_rng(11)
    freqs = np.array([50.0, 80.0, 95.0, 140.0, 200.0])
    # every mode stiffens with pressure, some twice as fast as others (1-2 %/bar)
    slope = np.array([0.01, 0.02, 0.015, 0.01, 0.02])
    sets, labels = _single_point_sweep(rng, freqs, np.linspace(5, 9, 9), slope, 2e-3)
    tr = track_modes(sets)
    by_family: dict[str, set[int]] = {}
    for s in sets:
        for q in range(freqs.size):
            by_family.setdefault(tr.family[(s.test_id, q)], set()).add(labels[s.test_id][q])
            assert tr.method[(s.test_id, q)] in ("", "frequency")
            assert np.isnan(tr.mac[(s.test_id, q)])  # no MAC with one point
    # one family per mode, no swap (80 and 95 Hz come within 10 % of each other)
    assert sorted(by_family.values(), key=min) == [{i} for i in range(freqs.size)]
    assert tr.scatter["n"] > 0


def test_a_missing_mode_is_not_replaced_by_another_one_nearby() -> None:
    # test b lacks the 100 Hz mode and has a mode at 108 Hz instead: 8 % away, far beyond
    # the scatter of the modes seen in both tests, so it starts a family of its own
    f_a = np.array([50.0, 100.0, 170.0, 240.0])
    f_b = np.array([50.02, 108.0, 170.05, 239.97])
    mk = lambda tid, f, p: ModeSet(  # noqa: E731
        tid, {"pressure_bar": p}, f, np.full(4, 0.01), np.ones((1, 4)), ("P1",)
    )
    tr = track_modes([mk("a", f_a, 6.0), mk("b", f_b, 7.0)])
    for q in (0, 2, 3):
        assert tr.family[("a", q)] == tr.family[("b", q)]
        assert tr.method[("b", q)] == "frequency"
    assert tr.family[("a", 1)] != tr.family[("b", 1)]
    assert tr.method[("b", 1)] == ""  # it started a family


def test_shapes_at_disjoint_points_fall_back_and_common_points_use_the_mac() -> None:
    f = np.array([60.0, 90.0, 130.0])
    shapes = np.column_stack([ring_shape(2), ring_shape(3), ring_shape(4)])
    a = ModeSet("a", {"pressure_bar": 6.0}, f, np.full(3, 0.02), shapes[:8], POINTS[:8])
    b = ModeSet("b", {"pressure_bar": 7.0}, f * 1.001, np.full(3, 0.02), shapes[8:], POINTS[8:])
    c = ModeSet("c", {"pressure_bar": 8.0}, f * 1.002, np.full(3, 0.02), shapes[8:], POINTS[8:])
    tr = track_modes([a, b, c])
    for q in range(3):
        assert tr.family[("a", q)] == tr.family[("b", q)] == tr.family[("c", q)]
        assert tr.method[("b", q)] == "frequency"  # b and a share no point
        assert tr.method[("c", q)] == "shape"  # c is compared with b: 8 common points
        assert_allclose(tr.mac[("c", q)], 1.0, atol=1e-12)  # the same shapes at the points


def test_the_scatter_between_tests_is_estimated_from_the_data() -> None:
    # 40 tests of 8 modes at one condition, each frequency scattered by tau = 1e-3
    # (log-normal); neighbouring tests then differ by sqrt(2) tau in ln f
    rng = np.random.default_rng(2)
    freqs = 40.0 * 1.3 ** np.arange(8)
    tau = 1e-3
    sets, _ = _single_point_sweep(rng, freqs, np.full(40, 7.0), np.zeros(8), tau)
    tau_f, tau_z, n = mode_scatter(sets)
    assert n == 39 * 8  # every mode of every test pairs with the previous test's
    # the MAD estimate of sqrt(2) tau from 312 differences: relative standard error
    # ~ 1.67 / sqrt(312) = 9 %, so 30 % is more than 3 standard errors
    assert_allclose(tau_f, np.sqrt(2) * tau, rtol=0.3)
    assert_allclose(tau_z, np.sqrt(2) * 0.1, rtol=0.3)  # damping scattered by 10 %


def test_single_member_wave_numbers_of_a_shaker_layout() -> None:
    # 90 deg apart: sin(n 90 deg) = 0 for every even n
    assert single_member_wave_numbers([0.0, 90.0], 8) == [2, 4, 6, 8]
    # one shaker never drives the member with a node at it
    assert single_member_wave_numbers([30.0], 3) == [1, 2, 3]
    # 45 deg apart: n 45 deg a multiple of 180 deg at n = 4, 8
    assert single_member_wave_numbers([10.0, 55.0], 8) == [4, 8]
    # three shakers at 0, 90 and 45 deg: n = 4 and 8 stay blind, the rest is seen
    assert single_member_wave_numbers([0.0, 90.0, 45.0], 8) == [4, 8]


def test_excitation_layout_of_a_ring_test_with_two_shakers() -> None:
    from pathlib import Path

    from tyredamp.campaign.runner import TestRun
    from tyredamp.campaign.spec import TestSpec
    from tyredamp.campaign.status import excitation_layout

    def run(inputs: list[float | None]) -> TestRun:
        outs = [{"node": k + 1, "direction": 3, "angle_deg": 22.5 * k} for k in range(16)]
        ins = [{"node": 1, "direction": 3, "angle_deg": a} for a in inputs]
        doc = {"models": {"complex": {"outputs": outs, "inputs": ins, "modes": []}}}
        r = TestRun(TestSpec("t", Path("t.uff"), "t.uff", "radial", {}))
        r.documents["modal"] = doc
        return r

    # 16 points: wave numbers up to 8; shakers 90 deg apart miss every even n
    ex = excitation_layout(run([0.0, 90.0]))
    assert ex == {"angles_deg": [0.0, 90.0], "single_member": [2, 4, 6, 8]}
    # one shaker drives only the cos member of every n: the report advises a second one
    assert excitation_layout(run([0.0])) == {
        "angles_deg": [0.0],
        "single_member": list(range(1, 9)),
    }
    assert excitation_layout(run([0.0, None])) is None  # an angle unknown: nothing said


def test_three_overlapping_modes_are_grouped_as_the_families_are() -> None:
    # a single mode of wave number 4 beside a doubled n = 1 pair; at the second pressure
    # all three half-power bands overlap and the single mode is nearer the pair's lower
    # member than the members are to each other
    f1, z1 = np.array([135.0, 144.9, 146.2]), np.array([0.005, 0.005, 0.005])
    f2, z2 = np.array([144.6, 146.1, 148.3]), np.array([0.017, 0.010, 0.015])
    pair_rot = np.column_stack([ring_shape(1, 0.3), ring_shape(1, 0.3 + np.pi / 2)])
    a = ModeSet(
        "a",
        {"tyre": "A", "pressure_bar": 7.5},
        f1,
        z1,
        np.column_stack([ring_shape(4), ring_shape(1), ring_shape(1, np.pi / 2)]),
        POINTS,
    )
    b = ModeSet(
        "b", {"tyre": "A", "pressure_bar": 9.0}, f2, z2,
        np.column_stack([ring_shape(4, 0.05), pair_rot]), POINTS,
    )  # fmt: skip
    assert group_pairs(f2, z2) == [(0, 1), (2,)]  # closest first pairs the wrong two
    tr = track_modes([a, b])
    assert tr.family[("a", 0)] == tr.family[("b", 0)]  # the n = 4 mode: one family, no slot
    assert tr.slot[("b", 0)] == ""
    # the doubled pair stays one pair family, its members in slots a and b
    assert tr.family[("a", 1)] == tr.family[("b", 1)] == tr.family[("b", 2)]
    assert [tr.slot[("b", q)] for q in (1, 2)] == ["a", "b"]
    assert tr.family[("a", 1)] in tr.pairs
    assert tr.family[("a", 0)] not in tr.pairs


def _crossing_sets(seed: int) -> tuple[list[ModeSet], dict[tuple[str, int], str]]:
    """A flat doubled pair (n = 1 mixed with n = 5) crossed by a rising n = 5 branch.

    The n = 5 branch is not seen below 8 bar and the pair not at 8 bar, as where
    the air cavity of a tyre crosses its n = 5 modes; each mode's true branch.
    """
    rng = np.random.default_rng(seed)
    hybrid = ring_shape(1) + 1.2 * ring_shape(5)  # a pair member half of n = 5
    pair = np.column_stack([hybrid, ring_shape(1, np.pi / 2)])
    sets, branch = [], {}
    for k, p in enumerate((6.0, 6.5, 7.0, 7.5, 8.0, 8.5)):
        f, z, shapes, names = [60.0 + 2 * k], [0.01], [ring_shape(2)], ["n2"]
        if p != 8.0:  # the pair: 144 and 148 Hz, flat in pressure
            f += [144.0 + 0.2 * k, 148.0 + 0.2 * k]
            z += [0.02, 0.02]
            shapes += [pair[:, 0], pair[:, 1]]
            names += ["pair", "pair"]
        if p >= 8.0:  # n = 5: 12 Hz per bar, above the pair from 8 bar
            f.append(158.0 + 12 * (p - 8.0))
            z.append(0.01)
            shapes.append(ring_shape(5))
            names.append("n5")
        f_noisy = np.array(f) * (1 + 2e-4 * rng.standard_normal(len(f)))
        tid = f"t{k}"
        sets.append(ModeSet(tid, {"tyre": "A", "pressure_bar": p}, f_noisy, np.array(z),
                            np.column_stack(shapes), POINTS))  # fmt: skip
        branch.update({(tid, q): name for q, name in enumerate(names)})
    return sets, branch


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_family_does_not_jump_off_its_course_to_a_crossing_branch(seed: int) -> None:
    sets, branch = _crossing_sets(seed)
    # the n = 5 mode lies half in the pair's subspace: its shape alone does not tell them apart
    mac = subspace_mac(np.column_stack([sets[0].shapes[:, 1], sets[0].shapes[:, 2]]),
                       sets[4].shapes[:, 1])  # fmt: skip
    assert mac >= MAC_MIN
    tr = track_modes(sets)
    held: dict[str, set[str]] = {}
    for key, fam in tr.family.items():
        held.setdefault(fam, set()).add(branch[key])
    assert all(len(b) == 1 for b in held.values()), held  # no family holds two branches
    # the flat pair keeps one family through all its pressures
    assert len({tr.family[(s.test_id, 1)] for s in sets if s.test_id != "t4"}) == 1
