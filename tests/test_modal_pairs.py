"""Which fitted modes stand for a close pair (issue 16, ``modal.pairs``).

* the pair statistic equals the least-squares extra sum of squares of the
  second-order column ``kappa / (s - p)^2`` added to the fitted modes' columns
  within the mode's window, computed independently per FRF;
* a mode standing for two close modes stands out of its level, and no mode of
  the complete fit does;
* a pair too weak for the local dispersion of the residual is split by the
  pair search (``search._split``) through this statistic.
"""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose
from scipy import stats as sps

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel
from tyredamp.modal._basis import factors, residual_lines
from tyredamp.modal.fit import FitResult, ModalFitter
from tyredamp.modal.pairs import HALF, pair_screen, pair_statistic
from tyredamp.modal.problem import build_problem
from tyredamp.modal.residual_peaks import local_ratio, model_of, power_of
from tyredamp.modal.search import ModeSet, ModeTest, _split
from tyredamp.modal.stats import mode_parameters, mode_threshold


def _data(
    f_true: np.ndarray, amp: np.ndarray, noise: float, seed: int
) -> tuple[ModalFitter, np.ndarray, tuple[float, float], float, ModeTest]:
    z = np.full(f_true.size, 0.01)
    w = 2 * np.pi * f_true
    p = -z * w + 1j * w * np.sqrt(1 - z * z)
    rng = np.random.default_rng(seed)
    psi = (rng.normal(size=(5, f_true.size)) + 0.3j * rng.normal(size=(5, f_true.size))) * amp
    fr = np.arange(10.0, 100.0, 0.02)
    h = ModalModel(p, psi, np.ones((1, f_true.size))).frf(fr, "receptance").H
    sd = noise * np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    pr = build_problem(FRF(fr, h + sd * e, kind="receptance"), (12.0, 95.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    n_out, n_in, n_f = pr.shape
    k = mode_parameters(n_out, n_in, "complex")
    return fit, p, pr.band, mode_threshold(k, n_f, 0.01), ModeTest(k, n_f)


def _modes(res: FitResult) -> ModeSet:
    return ModeSet(res.poles, res.participation, np.zeros(0, complex), np.zeros((0, 1), complex))


PAIR = np.array([20.0, 41.0, 41.5, 80.0])


def test_pair_statistic_is_the_extra_sum_of_squares_of_the_second_order_column() -> None:
    fit, p, _, _, _ = _data(PAIR, np.ones(4), 1e-3, 3)
    merged = np.array([p[0], 0.5 * (p[1] + p[2]), p[3]])
    res = fit.fit(merged, np.ones((3, 1), complex), refine=True)
    got = pair_statistic(fit, res, 3)
    poles, residues, terms, s2 = model_of(fit, res)
    f = fit.f
    for i in range(3):
        pi = complex(res.poles[i])
        fc, hw = abs(pi.imag) / (2 * np.pi), -pi.real / (2 * np.pi)
        sel = np.flatnonzero(np.abs(f - fc) <= max(HALF * hw, 3 * (f[1] - f[0])) + 1e-9)
        sl = slice(int(sel[0]), int(sel[-1]) + 1)
        s, kap, _ = factors(fit, sl)
        e = residual_lines(fit, poles, residues, terms, sl) / np.sqrt(s2)[:, None, None]
        fn = np.abs(res.poles) / (2 * np.pi)
        near = res.poles[(fn >= f[sl][0]) & (fn <= f[sl][-1])]
        base = np.stack([kap / (s - q) for q in near], axis=1)  # the fitted columns
        both = np.concatenate([base, (kap / (s - pi) ** 2)[:, None]], axis=1)
        extra = 0.0
        for j in range(e.shape[0]):  # per FRF (one input): lstsq with and without
            y = e[j, 0]
            r0 = y - base @ np.linalg.lstsq(base, y, rcond=None)[0]
            r1 = y - both @ np.linalg.lstsq(both, y, rcond=None)[0]
            extra += np.sum(np.abs(r0) ** 2) - np.sum(np.abs(r1) ** 2)
        assert_allclose(got[i], extra, rtol=1e-6)


def test_a_mode_standing_for_a_pair_stands_out_and_a_complete_fit_does_not() -> None:
    fit, p, _, _, _ = _data(PAIR, np.ones(4), 1e-3, 3)
    merged = np.array([p[0], 0.5 * (p[1] + p[2]), p[3]])
    res = fit.fit(merged, np.ones((3, 1), complex), refine=True)
    sc = pair_screen(fit, res, 3)
    assert sc[1] > 10.0
    assert np.all(sc[[0, 2]] < 1.0)
    full = fit.fit(p, np.ones((4, 1), complex), refine=True)
    assert np.all(pair_screen(fit, full, 4) < 1.0)


def test_a_weak_pair_is_split_where_the_dispersion_does_not_show_it() -> None:
    # a mode of 3 % of its neighbour's amplitude one half-power bandwidth above it,
    # noise 10 % of each FRF's RMS: the merged mode's local residual power is within
    # its noise level, its second-order column is not
    f_true = np.array([20.0, 41.0, 41.82, 80.0])
    fit, p, band, thr, test = _data(f_true, np.array([1.0, 1.0, 0.03, 1.0]), 0.1, 8)
    res = fit.fit(p[[0, 1, 3]], np.ones((3, 1), complex), refine=True)
    rho, n = local_ratio(fit.f, power_of(fit, res), res.poles[:3])
    k = 2 * fit.n_out * fit.n_in
    level = sps.chi2.isf(0.05 / 3, k * n) / (k * n)
    assert rho[1] < level[1]  # the dispersion alone would not try the pair
    assert pair_screen(fit, res, 3)[1] > 1.0
    tried: list[complex] = []
    got = _split(fit, res, _modes(res), power_of(fit, res), band, thr, 0.02, 0.2, test, tried)
    assert got is not None
    fs = np.sort(np.abs(got[0].poles) / (2 * np.pi))
    assert fs.size == 4
    assert_allclose(fs, f_true, atol=0.15)
