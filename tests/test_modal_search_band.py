"""A narrow band of a long FRF (issue 15): the residual search's candidates get the
reason the joint refit gives, a trial rejected there is not refitted again, and
broad structure from outside the band is not reported as a mode.

The system of ``benchmarks/modal_memory.py``: six modes over 20-190 Hz, a 1 x 1
accelerance with noise at 1 % of its RMS, the band 40-60 Hz holding one mode
(48 Hz, 2 %) and the tails of its neighbours at 25 and 71 Hz.
"""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.search.search import MERGE

FN = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
ZETA = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
#: the selection rule's admissible damping (Diagram.max_damping, residual_search)
MAX_DAMPING = 0.2


def _long_frf(n: int) -> FRF:
    w = 2 * np.pi * FN
    p = -ZETA * w + 1j * w * np.sqrt(1 - ZETA**2)
    m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
    f = np.linspace(0.0, 200.0, n)[1:]
    h = m.frf(f, "accelerance").H
    rng = np.random.default_rng(0)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(f, h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e, kind="accelerance")


@pytest.mark.parametrize("n", [4001, 25001])
def test_narrow_band_reports_its_mode_and_why_candidates_were_rejected(n: int) -> None:
    res = identify_modes(_long_frf(n), band=(40.0, 60.0), model="complex")
    model = res.models["complex"]
    fn, zeta = np.abs(model.poles) / (2 * np.pi), -model.poles.real / np.abs(model.poles)
    # no mode damped beyond the admissible limit is reported (a broad pole that
    # takes the tails of the modes outside the band is a residual term, not a mode)
    assert np.all(zeta <= MAX_DAMPING), (fn, zeta)
    # the one true mode of the band, found (its frequency to 0.1 %: 2000 and more
    # lines at 40 dB determine it far better)
    assert model.n_modes == 1
    assert abs(fn[0] - 48.0) < 0.048
    # a reason that says "not significant" has a statistic at or below the threshold
    for r in res.rejected:
        if "not significant" in r["reason"]:
            assert r["statistic"] <= r["threshold"], r
    # a trial rejected in the joint refit is not refitted again (distinct poles)
    joint = [r for r in res.rejected if r["reason"].startswith("joint refit")]
    f_j = np.array([r["frequency_hz"] for r in joint])
    z_j = np.array([r["damping_ratio"] for r in joint])
    p_j = -z_j * f_j + 1j * f_j * np.sqrt(1 - z_j**2)
    for i in range(p_j.size):
        for j in range(i):
            assert abs(p_j[i] - p_j[j]) >= 2 * MERGE * abs(p_j[i]), (joint[i], joint[j])


def _tails_below(seed: int) -> tuple[FRF, np.ndarray]:
    """A receptance of 3 outputs with 4-10 strong modes in 100-495 Hz and 5-12 in
    550-1850 Hz, nearly noise-free (1e-10 of its RMS): the band 500-1900 Hz holds the
    tails of modes just below its edge."""
    rng = np.random.default_rng(seed)
    nb, ni = int(rng.integers(4, 11)), int(rng.integers(5, 13))
    f_below = np.sort(rng.uniform(100, 495, nb))
    f_in = np.sort(rng.uniform(550, 1850, ni))
    f = np.concatenate([f_below, f_in])
    z = np.exp(rng.uniform(np.log(0.003), np.log(0.03), f.size))
    w = 2 * np.pi * f
    amp = np.concatenate(
        [np.exp(rng.uniform(np.log(0.1), 0, nb)), np.exp(rng.uniform(np.log(0.01), 0, ni))]
    )
    psi = (rng.normal(size=(3, f.size)) + 1j * rng.normal(size=(3, f.size))) * amp
    m = ModalModel(-z * w + 1j * w * np.sqrt(1 - z**2), psi, np.ones((1, f.size)) + 0j)
    h = m.frf(np.linspace(0.87, 2000.0, 2300), "receptance")
    e = rng.normal(size=h.H.shape) + 1j * rng.normal(size=h.H.shape)
    return h.with_H(h.H + 1e-10 * np.sqrt(np.mean(np.abs(h.H) ** 2)) * e), f_in


@pytest.mark.parametrize("seed", [18, 19, 27])
def test_residual_modes_take_the_tails_of_modes_below_the_band(seed: int) -> None:
    # the diagram's in-band poles stand partly for the tails; once a residual mode
    # below the band holds them, those poles leave the band and are dropped, and the
    # residual mode is kept (it was discarded with every in-band mode it moved: 2-4
    # of the 8-10 modes were found, the fit 6-59 % off); residual modes that meet
    # below the band shape the tails together and are not merged. The 4-10 strong
    # modes below outnumber the residual modes a side may hold, so the fit keeps
    # structure of about 0.3-0.5 % (seed 19: 0.30 % before a side was tried again,
    # 0.52 % now, one frequency 0.10 % off, with a residual mode above the band)
    frf, f_in = _tails_below(seed)
    res = identify_modes(frf, band=(500.0, 1900.0), model="complex")
    model = res.models["complex"]
    got = np.sort(np.abs(model.poles) / (2 * np.pi))
    assert got.size == f_in.size
    np.testing.assert_allclose(got, f_in, rtol=2e-3)
    assert model.meta["relative_error"] < 1e-2


def test_a_joint_refit_that_loses_every_mode_leaves_the_search_going() -> None:
    # the band holds only the tail of a mode below it; the one in-band start is
    # dragged out of the band by the joint refit: the mode test goes on from the
    # residues at the current poles (it raised "every mode crossed the band edge",
    # and so did a few modes of a band that holds many)
    from tyredamp.modal.fit.fit import ModalFitter
    from tyredamp.modal.problem.problem import build_problem
    from tyredamp.modal.search.search import ModeSet, reject_by_test

    w = 2 * np.pi * 97.0
    p = complex(-0.02 * w, w * np.sqrt(1 - 0.02**2))
    frf = ModalModel(np.array([p]), np.array([[1.0], [0.5j]]), np.ones((1, 1))).frf(
        np.linspace(50, 250, 801), "receptance"
    )
    pr = build_problem(frf, (100.0, 200.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    w0 = 2 * np.pi * 130.0
    start = ModeSet(
        np.array([complex(-0.02 * w0, w0)]),
        np.ones((1, 1), complex),
        np.zeros(0, complex),
        np.zeros((0, 1), complex),
    )
    res, cur, _ = reject_by_test(fit, start, (100.0, 200.0), 30.0, True)
    assert cur.m == 1
    assert abs(cur.poles[0] - start.poles[0]) < 1e-6 * abs(start.poles[0])
    assert np.isfinite(res.cost)


def _strong_at_both_edges(seed: int) -> tuple[FRF, float]:
    """Strong modes just below (293 Hz) and just above (734, 827 Hz) the band 300-700 Hz,
    four weaker ones in it; 2 x 1 mobility, noise at 1 % of each output's RMS. Also the
    noise's relative level in the band (higher: the band's response is weaker)."""
    rng = np.random.default_rng(seed)
    f = np.array([293.0, 375.5, 537.2, 577.0, 659.4, 734.4, 827.0])
    z = np.array([0.0036, 0.017, 0.0042, 0.013, 0.025, 0.0035, 0.008])
    amp = np.array([1.0, 0.3, 0.1, 0.5, 0.2, 1.0, 1.0])
    w = 2 * np.pi * f
    psi = (rng.normal(size=(2, 7)) + 1j * rng.normal(size=(2, 7))) * amp
    part = np.ones((1, 7)) + 0.3j * rng.normal(size=(1, 7))
    frf = ModalModel(-z * w + 1j * w * np.sqrt(1 - z**2), psi, part).frf(
        np.linspace(0.25, 1000.0, 4000), "mobility"
    )
    h = frf.H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2), keepdims=True))
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    noisy = frf.with_H(h + 0.01 * rms * e)
    inb = (frf.frequency >= 300.0) & (frf.frequency <= 700.0)
    level = np.linalg.norm(0.01 * rms * e[..., inb]) / np.linalg.norm(noisy.H[..., inb])
    return noisy, float(level)


@pytest.mark.parametrize("seed", [0, 1, 3])
def test_strong_modes_at_both_edges_are_held_by_residual_modes(seed: int) -> None:
    # the first residual mode above the band fails while the strong mode just below
    # it is unmodelled (its tail is better fitted by a broad pole far away); once a
    # residual mode below holds it, the side above is tried again (before: no
    # residual mode above, a mode of the band lost or moved, the fit 10-19 % off).
    # A trial in the band whose joint refit takes it across the edge to the second
    # mode above is kept as a residual mode (before: rejected, and the mode at
    # 659 Hz moved 5 Hz toward the edge to hold that tail, seed 0)
    frf, level = _strong_at_both_edges(seed)
    res = identify_modes(frf, band=(300.0, 700.0), model="complex")
    model = res.models["complex"]
    np.testing.assert_allclose(model.frequency_hz, [375.5, 537.2, 577.0, 659.4], rtol=2e-3)
    assert model.residual_modes is not None
    f_res = np.abs(model.residual_modes.poles) / (2 * np.pi)
    assert np.any(f_res < 300.0)
    assert np.any((f_res > 700.0) & (np.abs(f_res - 734.4) < 15.0))
    # the model explains the band to its noise
    assert model.meta["relative_error"] < 1.1 * level


@pytest.mark.parametrize("f_out", [760.0, 1080.0, 1330.0])
def test_a_residual_mode_starts_where_the_residual_asks_for_it(f_out: float) -> None:
    """Residual modes outside the band start where the residual asks for a pole
    (out_of_band._scan_starts): the band 300-700 Hz holds one mode, a strong mode lies
    at ``f_out`` above it, noise-free. The out-of-band search holds it with a residual
    mode at its pole wherever it lies within a factor 2 of the edge, and the start
    just beyond the edge lies within 5 % of the mode there."""
    from tyredamp.modal.fit.fit import ModalFitter
    from tyredamp.modal.problem.problem import build_problem
    from tyredamp.modal.search.out_of_band import _scan_starts, search_helpers
    from tyredamp.modal.search.search import ModeSet

    fn, zeta = np.array([480.0, f_out]), np.array([0.01, 0.01])
    w = 2 * np.pi * fn
    p = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    psi = np.array([[0.3, 1.0], [0.2j, -1.0], [0.1, 0.5]])
    frf = ModalModel(p, psi, np.ones((1, 2))).frf(np.linspace(250.0, 750.0, 2001), "mobility")
    pr = build_problem(frf, (300.0, 700.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    modes = ModeSet(
        p[:1], np.ones((1, 1), complex), np.zeros(0, complex), np.zeros((0, 1), complex)
    )
    res, cur, _ = search_helpers(fit, modes, (300.0, 700.0), (250.0, 750.0), 4, 30.0)
    assert cur.m == 1
    assert abs(cur.poles[0] - p[0]) < 1e-6 * abs(p[0])
    near = np.abs(np.abs(cur.hp) / (2 * np.pi) / f_out - 1)
    assert near.size
    # a mode near twice the edge reaches the band with a smooth tail that fixes its
    # pole loosely (1330 Hz: 0.14 %, beside two more residual modes sharing it)
    assert near.min() < (1e-6 if f_out < 1200.0 else 5e-3)
    if f_out < 800.0:  # just beyond the edge: the scan starts the trial at the mode
        first = fit.fit(p[:1], np.ones((1, 1), complex), refine=False, uncertainty=False)
        start = _scan_starts(fit, first, (700.0, 1400.0), 1.0, 0.01, 30.0)[0]
        assert abs(abs(start) / (2 * np.pi) / f_out - 1) < 0.05
    # below the band the start keeps to that side's range (natural frequency)
    low = _scan_starts(fit, res, (150.0, 300.0), -1.0, 0.01, 30.0)
    assert low
    assert all(150.0 - 1e-9 <= abs(q) / (2 * np.pi) <= 300.0 for q in low)
