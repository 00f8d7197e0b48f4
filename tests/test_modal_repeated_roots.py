"""Repeated roots with several inputs (issue 16: "repeated roots with several inputs").

A structure with a symmetry (a perfect ring, a disc) has pairs of modes at one
pole whose shapes differ: with several inputs their residues add to one of rank
two at that pole. The diagram gives two poles per order there, with
participation vectors that turn from order to order within the plane they span;
the stability, clustering and merging rules must see one place and two modes.
"""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.poles.lscf import PoleSet
from tyredamp.modal.poles.selection import cluster_poles, same_place_distinct, stability_flags


def _repeated_system(n_in: int, seed: int) -> ModalModel:
    """Four roots, each twice (independent shapes and participation), 6 outputs."""
    rng = np.random.default_rng(seed)
    f = np.array([52.0, 88.0, 131.0, 170.0])
    z = np.array([0.02, 0.006, 0.04, 0.012])
    w = 2 * np.pi * f
    p = -z * w + 1j * w * np.sqrt(1 - z**2)
    poles = np.concatenate([p, p])
    psi_out = rng.normal(size=(6, 8)) + 1j * rng.normal(size=(6, 8))
    psi_in = rng.normal(size=(n_in, 8)) + 0.2j * rng.normal(size=(n_in, 8))
    return ModalModel(poles, psi_out, psi_in)


@pytest.mark.parametrize("n_in", [2, 3])
def test_repeated_roots_of_several_inputs_found_without_a_mode_count(n_in: int) -> None:
    mdl = _repeated_system(n_in, 7 + n_in)
    freq = np.linspace(5.0, 220.0, 1500)
    frf = mdl.frf(freq, "receptance")
    rng = np.random.default_rng(1)
    h = frf.H
    noise = 1e-9 * np.sqrt(np.mean(np.abs(h) ** 2))
    frf = frf.with_H(h + noise * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)))
    res = identify_modes(frf, band=(20.0, 200.0), model="complex")
    c = res.models["complex"]
    got = np.sort(c.frequency_hz)
    f_true = np.abs(mdl.poles) / (2 * np.pi)
    assert got.size == 8  # both modes of every root
    np.testing.assert_allclose(got, np.sort(f_true), rtol=1e-7)
    assert c.meta["relative_error"] < 1e-7
    # at each root the two identified residues add to the true rank-two residue
    for f0 in np.unique(np.round(f_true, 6)):
        ids = np.flatnonzero(np.abs(c.frequency_hz - f0) < 1e-3)
        true = np.flatnonzero(np.abs(f_true - f0) < 1e-3)
        assert ids.size == true.size == 2
        r_id = np.einsum("jn,kn->jk", c.psi_out[:, ids], c.psi_in[:, ids])
        r_true = np.einsum("jn,kn->jk", mdl.psi_out[:, true], mdl.psi_in[:, true])
        assert np.linalg.matrix_rank(r_true, tol=1e-6 * np.abs(r_true).max()) == 2
        np.testing.assert_allclose(r_id, r_true, rtol=0, atol=1e-6 * np.abs(r_true).max())


def _turning_pairs(n_orders: int = 10) -> PoleSet:
    """Two poles per order at one place (a repeated root), their participation
    vectors an orthonormal pair turning within one plane of C^3 from order to order;
    and one simple mode of fixed participation."""
    rng = np.random.default_rng(3)
    plane = np.linalg.qr(rng.normal(size=(3, 2)) + 1j * rng.normal(size=(3, 2)))[0]
    simple = np.array([1.0, 0.5j, -0.3])
    p0 = complex(-0.02 * 2 * np.pi * 60, 2 * np.pi * 60)
    p1 = complex(-0.01 * 2 * np.pi * 90, 2 * np.pi * 90)
    order, poles, lv = [], [], []
    for k in range(n_orders):
        a = rng.uniform(0, np.pi)
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        pair = (plane @ rot).T  # two orthonormal vectors of the plane
        jitter = 1 + 1e-6 * rng.normal(size=3)
        poles += [p0 * jitter[0], p0 * jitter[1], p1 * jitter[2]]
        lv += [pair[0], pair[1], simple / np.linalg.norm(simple)]
        order += [10 + 2 * k] * 3
    return PoleSet(
        order=np.array(order),
        poles=np.array(poles),
        participation=np.array(lv),
        orders=np.arange(10, 10 + 2 * n_orders, 2),
        band_hz=(20.0, 200.0),
    )


def test_a_repeated_root_is_stable_and_gives_two_clusters_spanning_its_plane() -> None:
    ps = _turning_pairs()
    flags = stability_flags(ps)
    first = ps.at_order(int(ps.orders[0]))
    later = np.setdiff1d(np.arange(ps.poles.size), first)
    assert flags.vector[later].all()  # the pairwise MAC of turning vectors is random
    kept, rejected = cluster_poles(ps, flags)
    assert not rejected
    at_root = [c for c in kept if abs(c.frequency_hz - 60) < 1]
    assert len(at_root) == 2
    assert all(c.fraction == pytest.approx(0.9) for c in kept)  # all but the first order
    l2 = np.array([c.participation for c in at_root])
    s = np.linalg.svd(l2, compute_uv=False)
    assert s[1] / s[0] > 0.5  # the two starts span the plane (not one vector twice)


def test_modes_at_one_place_merge_only_with_parallel_participation() -> None:
    part = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1e-3]], complex)
    distinct = same_place_distinct(part)
    assert distinct[0, 1]
    assert distinct[1, 2]
    assert not distinct[0, 2]  # MAC 0.999999: one mode held twice


def test_residual_search_adds_the_second_mode_of_a_repeated_root() -> None:
    # the second mode of a root holds its own participation: its residual is not
    # in the span of the first's column, and a trial mode near the first's pole
    # takes it; the joint refit keeps both (different participation: no merge)
    from tyredamp.modal.fit.fit import ModalFitter
    from tyredamp.modal.problem.problem import build_problem
    from tyredamp.modal.search.search import ModeSet, fit_checked, residual_search
    from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold

    mdl = _repeated_system(2, 9)
    frf = mdl.frf(np.linspace(5.0, 220.0, 1500), "receptance")
    rng = np.random.default_rng(2)
    h = frf.H
    sd = 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2))
    frf = frf.with_H(h + sd * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)))
    pr = build_problem(frf, (20.0, 200.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    fn = np.abs(mdl.poles) / (2 * np.pi)
    drop = int(np.flatnonzero(np.abs(fn - 88.0) < 1)[1])  # one mode of the 88 Hz root
    keep = np.arange(fn.size) != drop
    modes = ModeSet(
        mdl.poles[keep],
        mdl.psi_in.T[keep].astype(complex),
        np.zeros(0, complex),
        np.zeros((0, 2), complex),
    )
    res, cur, _ = fit_checked(fit, modes, True, (20.0, 200.0), passes=1, uncertainty=False)
    assert cur.m == 7
    thr = mode_threshold(mode_parameters(6, 2, "complex"), pr.shape[2], 0.01)
    _, got, _ = residual_search(fit, res, cur, [], (20.0, 200.0), thr)
    f_got = np.abs(got.poles) / (2 * np.pi)
    assert got.m == 8
    assert np.count_nonzero(np.abs(f_got - 88.0) < 0.01) == 2
