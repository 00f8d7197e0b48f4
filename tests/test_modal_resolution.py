"""Two poles the lines cannot tell apart (tyredamp.modal.search.resolution)."""

from __future__ import annotations

import numpy as np

from tyredamp.mechanics.modal_sum import pole_from_frequency_damping
from tyredamp.modal.search.resolution import unresolved_pair, unresolved_pair_text


def _poles(fn: list[float], zeta: list[float]) -> np.ndarray:
    return np.array(
        [complex(pole_from_frequency_damping(f, z)) for f, z in zip(fn, zeta, strict=True)]
    )


def test_a_ringing_mode_and_a_pole_within_one_line_are_one_resonance() -> None:
    # 1 Hz lines: the modes at 958.5 and 958.9 Hz are 0.4 Hz apart, the first
    # 2 * 1.5e-4 * 958.5 = 0.29 Hz wide (below the lines): one resonance; the
    # weaker pole (T = 40) is named first
    p = _poles([142.2, 958.5, 958.9], [4e-4, 1.5e-4, 9e-4])
    t = np.array([9e3, 7e3, 40.0])
    assert unresolved_pair(p, t, 1.0) == (2, 1)
    assert "958.5 Hz" in unresolved_pair_text(958.5, 1.0)


def test_a_pair_resolved_by_fine_lines_or_wide_bands_is_left_alone() -> None:
    # a close pair 0.5 Hz apart (1 % damping, 0.82 Hz wide) on 0.02 Hz lines:
    # 25 lines apart, both wider than the lines
    p = _poles([41.0, 41.5], [0.01, 0.01])
    t = np.array([500.0, 400.0])
    assert unresolved_pair(p, t, 0.02) is None
    # 2 % damping, both 1.64 Hz wide on 1 Hz lines, 0.5 Hz apart: neither rings
    # beyond a record, the fit resolves them through their half-power bands
    assert unresolved_pair(_poles([41.0, 41.5], [0.02, 0.02]), t, 1.0) is None
    # 0.82 Hz wide on 1 Hz lines: they ring through the record, one resonance
    assert unresolved_pair(p, t, 1.0) == (1, 0)
    # two ringing modes 1.5 lines apart: resolved by the record
    q = _poles([500.0, 501.5], [1e-4, 1e-4])
    assert unresolved_pair(q, t, 1.0) is None


def test_the_closest_unresolved_pair_comes_first() -> None:
    p = _poles([100.0, 100.6, 300.0, 300.2], [1e-4, 1e-4, 1e-4, 1e-4])
    t = np.array([50.0, 60.0, 80.0, 70.0])
    assert unresolved_pair(p, t, 1.0) == (3, 2)  # 0.2 Hz before 0.6 Hz
    assert unresolved_pair(p[:1], t[:1], 1.0) is None
    assert unresolved_pair(p, t, 0.0) is None
