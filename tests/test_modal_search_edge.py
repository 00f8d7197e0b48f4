"""Residual modes outside the band behind in-band structure at the edge
(:mod:`tyredamp.modal.search.out_of_band`): the starts of a side's trials are the
scan's distinct maxima, and a side whose trials all ran into the band edge (a
missed mode just inside it) is searched again once the residual search adds
that mode.
"""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.modal import ModalModel
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


@pytest.mark.parametrize("f_out", [215.0, 260.0])
def test_an_edge_side_is_searched_again_once_the_missed_mode_is_added(f_out: float) -> None:
    """Modes at 60, 120 and 192 Hz in the band 20-200 Hz and a strong one at ``f_out``
    above it, 60 dB; the search starts from the first two. The missed 192 Hz
    mode's residual pulls every upper trial to the band edge (the side is
    recorded, no residual mode added); the residual search adds it, searches the
    side again and holds the mode above the band with a residual mode."""
    from tyredamp.modal.fit.fit import ModalFitter
    from tyredamp.modal.problem.problem import build_problem
    from tyredamp.modal.search.out_of_band import search_helpers
    from tyredamp.modal.search.search import FixedParts, ModeSet, reject_by_test, residual_search
    from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold

    fn, zeta = np.array([60.0, 120.0, 192.0, f_out]), np.full(4, 0.01)
    w = 2 * np.pi * fn
    p = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    psi = np.array([[1.0, 0.8, 1.0, 3.0], [0.5, -1.0, 0.7j, -2.0]])
    frf = ModalModel(p, psi, np.ones((1, 4))).frf(np.linspace(20.0, 200.0, 901), "receptance")
    rng = np.random.default_rng(1)
    h = frf.H
    sd = 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2))
    frf = frf.with_H(h + sd * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)))
    band = (20.0, 200.0)
    pr = build_problem(frf, band)
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    none = np.zeros(0, complex)
    modes = ModeSet(p[:2], np.ones((2, 1), complex), none, none.reshape(0, 1))
    thr = mode_threshold(mode_parameters(3, 1, "complex"), pr.shape[2], 0.01)
    fixed = FixedParts(fit)
    res, cur, _ = search_helpers(fit, modes, band, band, 4, thr, fixed)
    assert cur.hp.size == 0
    assert fixed.at_edge == {1.0}
    res, cur, _ = reject_by_test(fit, cur, band, thr, True, start=res, max_damping=0.2)
    _, got, _ = residual_search(fit, res, cur, [], band, thr, fixed=fixed)
    f_got = np.sort(np.abs(got.poles)) / (2 * np.pi)
    # the three in-band modes, unbiased by the tail above: 60 dB data, the standard
    # error of these frequencies is ~1e-6 relative; 1e-4 holds the search's tolerance
    assert f_got.size == 3
    np.testing.assert_allclose(f_got, fn[:3], rtol=1e-4)
    # a residual mode at the mode above the band (its pole set by its tail: within
    # 1 %), and the side no longer recorded
    f_hp = np.abs(got.hp) / (2 * np.pi)
    assert np.min(np.abs(f_hp / f_out - 1)) < 0.01
    assert fixed.at_edge == set()
