"""Groupings of overlapping modes into pairs (tyredamp.campaign.pairing)."""

from __future__ import annotations

import numpy as np

from tyredamp.campaign.pairing import group_pairs, pairings


def test_pairings_list_every_matching_of_a_chain_closest_first() -> None:
    # four modes in a row, all neighbours overlapping: a chain of 3 links has
    # F(5) = 5 matchings (none, each link alone, the outer two links)
    f = np.array([100.0, 101.0, 102.5, 103.2])
    z = np.full(4, 0.01)
    got = list(pairings(f, z))
    assert got[0] == group_pairs(f, z) == [(0, 1), (2, 3)]
    expected = [
        [(0, 1), (2, 3)],
        [(0,), (1,), (2,), (3,)],
        [(0, 1), (2,), (3,)],
        [(0,), (1, 2), (3,)],
        [(0,), (1,), (2, 3)],
    ]
    assert sorted(got) == sorted(expected)
    assert len(got) == len({tuple(g) for g in got})  # each once


def test_separate_modes_have_one_grouping() -> None:
    f = np.array([50.0, 80.0, 120.0])
    assert list(pairings(f, np.full(3, 0.01))) == [[(0,), (1,), (2,)]]
