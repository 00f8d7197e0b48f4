"""The mode statistic with the neighbours' poles refitted (modal.search.refitted): a
second pole beside a strong mode passes with the other poles held but not as
the likelihood ratio of the maximised models; a true weak neighbour passes
both; separated modes are not refitted."""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.modal.fit.fit import FitResult, ModalFitter
from tyredamp.modal.model import ModalModel
from tyredamp.modal.search.refitted import OVERLAP, refit_candidates, refitted_statistics
from tyredamp.modal.search.search import ModeSet
from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold

F = np.arange(60.0, 140.0, 0.1)
P_STRONG = -0.02 * 2 * np.pi * 100 + 2j * np.pi * 100
THR = mode_threshold(mode_parameters(4, 1, "complex"), F.size, 0.01)


def _data(poles: np.ndarray, amps: list[float], seed: int) -> tuple[ModalFitter, float]:
    rng = np.random.default_rng(1)
    psi = (rng.normal(size=(4, poles.size)) + 0.3j * rng.normal(size=(4, poles.size))) * amps
    h = ModalModel(poles, psi, np.ones((1, poles.size))).frf(F, "receptance").H
    sd = 1e-2 * float(np.sqrt(np.mean(np.abs(h) ** 2)))
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return ModalFitter(F, h + sd * e, 0, "complex", []), sd


def _fit2(fit: ModalFitter, p2: np.ndarray, sd: float) -> tuple[FitResult, ModeSet]:
    r = fit.fit(p2, np.ones((2, 1)), refine=True, passes=1, sigma=np.full(4, sd))
    cur = ModeSet(r.poles, r.participation, np.zeros(0, complex), np.zeros((0, 1), complex))
    return r, cur


def test_a_second_pole_beside_a_strong_mode_fails_when_the_strong_one_is_refitted() -> None:
    # one mode in the data; a second pole started 0.3 half-widths beside it ends
    # where it takes up noise and shifts the strong pole: removing it with the
    # strong pole held leaves that shift's misfit (T 91 against 41), refitting the
    # strong pole takes it back (T 15)
    fit, sd = _data(np.array([P_STRONG]), [1.0], seed=1)
    sig = -P_STRONG.real
    r, cur = _fit2(fit, np.array([P_STRONG, P_STRONG + 0.3 * sig + 0.1j * sig]), sd)
    thr = np.full(2, THR)
    assert r.significance[1] > THR  # held: passes
    assert list(refit_candidates(r, 2, r.significance, thr)) == [1]
    t, done = refitted_statistics(fit, r, cur, r.significance, thr, np.full(4, sd))
    assert list(done) == [False, True]
    assert t[1] <= THR < r.significance[1]
    assert t[0] == r.significance[0]  # the strong mode keeps its held statistic


def test_a_true_weak_neighbour_passes_refitted_too() -> None:
    # a real mode 1.5 half-widths beside the strong one, 30 times weaker: refitting
    # the strong pole does not take it up
    sig = -P_STRONG.real
    p_weak = P_STRONG + 1.5j * sig
    fit, sd = _data(np.array([P_STRONG, p_weak]), [1.0, 0.08], seed=2)
    r, cur = _fit2(fit, np.array([P_STRONG, p_weak]), sd)
    thr = np.full(2, THR)
    t, _ = refitted_statistics(fit, r, cur, r.significance, thr, np.full(4, sd))
    assert t[1] > THR
    assert t[1] <= r.significance[1] + 1e-9  # the refitted ratio never exceeds the held one


def test_separated_modes_are_not_refitted() -> None:
    # resonances further apart than OVERLAP times the sum of their half-widths: no
    # neighbour's pole can take the other up, no refit
    sig = -P_STRONG.real
    p_far = P_STRONG + 1j * (OVERLAP * 2 * sig + 60.0)
    fit, sd = _data(np.array([P_STRONG, p_far]), [1.0, 0.05], seed=3)
    r, cur = _fit2(fit, np.array([P_STRONG, p_far]), sd)
    thr = np.full(2, THR)
    assert refit_candidates(r, 2, r.significance, thr).size == 0
    t, done = refitted_statistics(fit, r, cur, r.significance, thr, np.full(4, sd))
    assert not done.any()
    np.testing.assert_array_equal(t, r.significance)


@pytest.mark.parametrize("fails", [True, False])
def test_only_modes_that_pass_held_are_candidates(fails: bool) -> None:
    fit, sd = _data(np.array([P_STRONG]), [1.0], seed=1)
    sig = -P_STRONG.real
    r, _ = _fit2(fit, np.array([P_STRONG, P_STRONG + 0.3 * sig + 0.1j * sig]), sd)
    thr = np.full(2, r.significance[1] + (1.0 if fails else -1.0))
    assert (refit_candidates(r, 2, r.significance, thr).size == 0) == fails
