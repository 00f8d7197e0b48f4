"""Gram blocks of several-input complex fits from per-line sums (modal/fit/_gram_lines)."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from typing import Literal

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.frf import FRF
from tyredamp.modal.fit import _added, _basis, _gram_lines
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.identify import identify_modes

from .helpers import chain_system

F = np.linspace(2.0, 40.0, 300)


def _fitter(
    n_in: int,
    power: int,
    upper: bool,
    lower: bool,
    weights: bool,
    seed: int = 0,
    kind: Literal["complex", "real"] = "complex",
) -> tuple[ModalFitter, np.ndarray, int, np.ndarray]:
    """A fitter of complex (or real) modes on random data, and a parameter vector of
    4 modes (real participation for real modes)."""
    rng = np.random.default_rng(seed)
    n_out, m = 5, 4
    H = rng.normal(size=(n_out, n_in, F.size)) + 1j * rng.normal(size=(n_out, n_in, F.size))
    lw = rng.uniform(0.5, 2.0, F.size) if weights else None
    drive = [(k, k) for k in range(n_in)]
    fit = ModalFitter(F, H, power, kind, drive, upper=upper, lower=lower, line_weights=lw)
    poles = 2 * np.pi * np.array([5.0, 12.0, 12.5, 30.0]) * (-0.03 + 1j)
    part = rng.normal(size=(m, n_in)) + 0j
    if kind == "complex":
        part = part + 1j * rng.normal(size=(m, n_in))
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    return fit, fit.pack(poles, part, ref), m, ref


def _cases() -> Iterator[tuple[int, int, bool, bool, bool, bool]]:
    # every residual-term choice and power, with and without line weights and
    # derivative columns, for 2 and 3 inputs (half of the products: seconds in all)
    for n_in, power, (up, lo), lw, der in itertools.product(
        (2, 3),
        (0, 1, 2),
        ((True, True), (False, True), (True, False), (False, False)),
        (False, True),
        (True, False),
    ):
        if (power + up + 2 * lo + lw + der) % 2 == 0 or (up and lo):
            yield n_in, power, up, lo, lw, der


@pytest.mark.parametrize(("n_in", "power", "upper", "lower", "weights", "der"), list(_cases()))
def test_gram_blocks_equal_those_of_the_basis(
    n_in: int, power: int, upper: bool, lower: bool, weights: bool, der: bool
) -> None:
    fit, th, m, ref = _fitter(n_in, power, upper, lower, weights)
    B = fit._basis_ek(th, m, ref, der)[0]  # the explicit basis, all lines
    G0, P0 = B.T @ B, B.T @ fit.Y
    n_f = F.size  # three blocks of unequal size: the sums over blocks
    parts = [slice(0, 70), slice(70, 200), slice(200, n_f)]
    G, P = _gram_lines.gram(fit, fit.unpack(th, m, ref), ref, der, parts)
    assert G.shape == G0.shape
    assert P.shape == P0.shape
    assert np.array_equal(G, G.T)
    d = np.sqrt(np.diag(G0))
    # both sums are exact up to rounding: each entry to 1e-12 of the product of the
    # two columns' norms (Cauchy-Schwarz bound; near-orthogonal pairs have entries
    # far below it, so an entry-wise rtol would test rounding, not the formula)
    assert np.all(np.abs(G - G0) <= 1e-12 * np.outer(d, d))
    assert np.all(np.abs(P - P0) <= 1e-12 * np.outer(d, np.sqrt(fit._yss)))
    # the diagonal (squared column norms, no cancellation) entry-wise
    assert_allclose(np.diag(G), np.diag(G0), rtol=1e-12)  # rounding of sums of squares


def test_atoms_are_the_sums_and_differences_of_the_conjugate_terms() -> None:
    fit, th, m, ref = _fitter(2, 1, True, True, True)
    poles, _ = fit.unpack(th, m, ref)
    s, kap, kap_low = _basis.factors(fit)
    ft = _gram_lines.atoms(fit, poles, True, (s, kap, kap_low))
    for n, p in enumerate(poles):
        # the definitions (module docstring), by direct complex division
        g, gb = kap / (s - p), kap / (s - np.conj(p))
        dg, dgb = g / (s - p), gb / (s - np.conj(p))
        want = [g + gb, 1j * (g - gb), dg + dgb, 1j * (dg - dgb)]
        for j, w in enumerate(want):
            # one reciprocal instead of two divisions: rounding of a few operations
            assert_allclose(ft[4 * n + j], w, rtol=1e-12, atol=1e-12 * np.abs(w).max())
    assert_allclose(ft[4 * m], kap, rtol=0)  # the residual terms' columns as they are
    assert_allclose(ft[4 * m + 1], kap_low, rtol=0)


def test_coefficients_rebuild_the_basis() -> None:
    fit, th, m, ref = _fitter(3, 2, True, True, False)
    pp = fit.unpack(th, m, ref)
    idx, val, n_phi = _gram_lines.coefficients(fit, pp[1], ref, True)
    ft = _gram_lines.atoms(fit, pp[0], True, _basis.factors(fit))
    assert n_phi == ft.shape[0]
    B = fit._basis_ek(th, m, ref, True)[0]
    bc = B.T.reshape(B.shape[1], fit.n_in, F.size, 2)  # (column, input, line, re/im)
    for k in range(fit.n_in):
        col = val[k, :, 0, None] * ft[idx[k, :, 0]] + val[k, :, 1, None] * ft[idx[k, :, 1]]
        got = bc[:, k, :, 0] + 1j * bc[:, k, :, 1]
        # the same columns from the same atoms: rounding of one product and sum
        assert_allclose(col, got, rtol=0, atol=1e-12 * np.abs(got).max())


@pytest.mark.parametrize("residual", [False, True])
def test_solve_is_the_same_by_either_route(residual: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    fit, th, m, ref = _fitter(2, 2, True, True, True, seed=4)
    w = fit.weights(None)
    sols = []
    for use in (False, True):
        monkeypatch.setattr(_gram_lines, "USE", use)
        sols.append(fit._solve(th, m, ref, w, residual=residual))
    old, new = sols
    assert new["qr"] == old["qr"] == residual
    # the QR route forms the same basis (bit for bit); the Gram route's sums differ
    # by rounding, which the projection carries to the cost of random data at 1e-12
    tol = 0.0 if residual else 1e-12
    assert_allclose(new["cost"], old["cost"], rtol=tol)
    assert_allclose(new["C"], old["C"], rtol=1e-9 if not residual else 0.0, atol=0)
    assert_allclose(new["Etr"], old["Etr"], rtol=1e-9 if not residual else 0.0, atol=0)


def test_identify_modes_finds_the_same_modes_by_either_route(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # strongly non-proportional damping and 1 % noise: the refinements move (a
    # basis column changed by 1e-4 moves the damping ratios found by 1e-7)
    sys_ = chain_system(c_local=(20.0, 0.0, 10.0))
    f = np.linspace(0.5, 40.0, 400)
    rng = np.random.default_rng(7)
    frf = sys_.frf(f, kind="accelerance", inputs=[0, 3])
    h = np.asarray(frf.H)
    noise = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    frf = FRF(f, h + 1e-2 * np.abs(h).mean() * noise, kind="accelerance")
    found = []
    for use in (False, True):
        monkeypatch.setattr(_gram_lines, "USE", use)
        model = identify_modes(frf, model="complex").models["complex"]
        found.append((np.asarray(model.frequency_hz), np.asarray(model.damping_ratio)))
    (f0, z0), (f1, z1) = found
    assert f0.size == f1.size >= 4
    # the same refinements from sums equal to rounding: the same optimum to 1e-9
    assert_allclose(f1, f0, rtol=1e-9)
    assert_allclose(z1, z0, rtol=1e-9)


@pytest.mark.parametrize(
    ("n_in", "n_out", "weights", "same_pole"),
    [(2, 4, True, False), (3, 4, False, True), (2, 16, False, False), (2, 16, True, True)],
)
def test_fit_added_is_the_same_by_either_route(
    n_in: int, n_out: int, weights: bool, same_pole: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    # several blocks of lines (the per-line route of fit_added needs them); with 16
    # outputs the fixed basis is no larger than the data and the fixed part keeps its
    # orthonormal rows of every line (FixedPart.qr: the basis route's evaluations)
    monkeypatch.setattr(_basis, "BLOCK_BYTES", 20_000)
    rng = np.random.default_rng(5)
    f = np.linspace(5.0, 200.0, 600)
    H = rng.normal(size=(n_out, n_in, f.size)) + 1j * rng.normal(size=(n_out, n_in, f.size))
    lw = rng.uniform(0.5, 2.0, f.size) if weights else None
    fit = ModalFitter(f, H, 2, "complex", [(0, 0), (1, 1)], line_weights=lw)
    poles = 2 * np.pi * np.array([20.0, 70.0, 130.0]) * (-0.02 + 1j)
    part = rng.normal(size=(3, n_in)) + 1j * rng.normal(size=(3, n_in))
    # a trial mode next to a fixed one (2e-4 of its frequency): its columns lie nearly
    # in the fixed basis's span, which takes the QR route of the projected rows
    p1 = poles[1] * (1 + 2e-4j) if same_pole else 2 * np.pi * 100.0 * (-0.02 + 1j)
    l1 = part[1] if same_pole else rng.normal(size=n_in) + 1j * rng.normal(size=n_in)
    one, lay1, _ = fit._added_fitter()
    ref1 = np.array([int(np.argmax(np.abs(l1)))], np.intp)
    th1 = one.pack(np.array([p1]), l1[None, :], ref1)
    got = []
    for use in (False, True):
        monkeypatch.setattr(_gram_lines, "USE", use)
        fx = fit.fixed_part(poles, part)
        assert len(fx.parts) > 1
        assert (fx.atoms is not None) == use
        assert (fx.qr is not None) == (n_out == 16)
        sol = _added.added_solver(fit, one, fx, ref1, lay1)(th1)
        got.append((sol, fit.fit_added(poles, part, p1, l1, fixed=fx)))
    (a, ra), (b, rb) = got
    assert a["qr"] == b["qr"] == same_pole
    # sums equal to rounding, projected as before: the projection to 1e-10 (relative
    # to the largest entry; the QR route's rows are the same numbers)
    for key in ("GE", "Etr", "C"):
        assert_allclose(b[key], a[key], rtol=0, atol=1e-10 * np.abs(a[key]).max())
    assert_allclose(b["cost"], a["cost"], rtol=1e-12)  # a sum of squares of the residual
    # the refined added mode: the same optimum to 1e-9
    assert_allclose(rb[0], ra[0], rtol=1e-9)
    assert_allclose(rb[1], ra[1], rtol=1e-9)
    assert_allclose(rb[2], ra[2], rtol=1e-9)
