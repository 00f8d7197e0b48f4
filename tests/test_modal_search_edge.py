"""Residual modes outside the band (:mod:`tyredamp.modal.search.out_of_band`): the
starts of a side's trials are the scan's distinct maxima, best first.
"""

from __future__ import annotations

import numpy as np

from tyredamp.modal.search.out_of_band import distinct_maxima


def _bumps(f: np.ndarray, centres: list[float], heights: list[float], width: float) -> np.ndarray:
    """A statistic made of Lorentzian bumps (heights at the centres, half-width ``width``)."""
    t = np.zeros_like(f)
    for c, h in zip(centres, heights, strict=True):
        t += h / (1 + ((f - c) / width) ** 2)
    return t


def test_distinct_maxima_best_first_above_threshold_once_each() -> None:
    # two damping grids over 200-400 Hz (zeta 1 % and 2 %, step zeta f): bumps of
    # height 900 at the edge (200 Hz), 300 at 260 Hz, 120 at 330 Hz and 40 at 370 Hz; the
    # threshold 50 keeps the first three; each bump is seen on both grids
    zetas = [0.01, 0.02]
    fg = [200.0 * (1 + z) ** np.arange(int(np.log(2) / np.log1p(z)) + 1) for z in zetas]
    pg = np.concatenate([f * (1j - z) for f, z in zip(fg, zetas, strict=True)])
    f = np.concatenate(fg)
    t = _bumps(f, [200.0, 260.0, 330.0, 370.0], [900.0, 300.0, 120.0, 40.0], 3.0)
    got = distinct_maxima(t, [g.size for g in fg], pg, zetas, 50.0)
    # the best first (the grid's first point, nearest the edge's bump), then the
    # bumps in order of height, each once, at the grid point nearest its centre:
    # the grid steps are 1-2 % of f, so within a step of the centre
    assert int(got[0]) == int(np.argmax(t))
    assert f[got[0]] < 205.0
    assert len(got) == 3
    assert np.all(np.abs(f[got[1:]] / np.array([260.0, 330.0]) - 1) < 0.02)
    # at most ``most``; with a threshold above every further bump, the best alone
    assert len(distinct_maxima(t, [g.size for g in fg], pg, zetas, 50.0, most=2)) == 2
    assert distinct_maxima(t, [g.size for g in fg], pg, zetas, 1e4) == [int(np.argmax(t))]
