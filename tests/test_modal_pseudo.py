"""Pseudo-lines of the trials on long records (tyredamp.modal.fit._pseudo)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.special import psi

from tyredamp.mechanics import pole_from_frequency_damping
from tyredamp.modal.fit import _basis, _pseudo
from tyredamp.modal.fit.fit import ModalFitter


def _fitter(n_in: int, n_f: int, seed: int = 0) -> tuple[ModalFitter, np.ndarray]:
    """A fitter on random FRFs of a few modes (accelerance), and the modes' poles."""
    rng = np.random.default_rng(seed)
    f = np.linspace(1.0, 200.0, n_f)
    p = pole_from_frequency_damping(np.array([40.0, 90.0, 150.0]), np.array([0.01, 0.02, 0.005]))
    s = 2j * np.pi * f
    r = rng.normal(size=(4, n_in, p.size)) + 1j * rng.normal(size=(4, n_in, p.size))
    h = np.einsum("jkn,nf->jkf", r, 1 / (s - p[:, None])) + np.einsum(
        "jkn,nf->jkf", np.conj(r), 1 / (s - np.conj(p)[:, None])
    )
    h = h * s**2
    h += 0.01 * np.std(h) * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    return ModalFitter(f, h, 2, "complex", [], upper=True, lower=True), p


def test_lagrange_reproduces_polynomials_and_sums():
    # the Lagrange rows of the nodes interpolate a polynomial of degree < NODES exactly
    x = np.linspace(-1, 1, 1001)
    ell = _pseudo.lagrange(x)
    xj = _pseudo._cheb_nodes(_pseudo.NODES)[0]
    poly = np.polynomial.Polynomial(np.arange(1.0, 12.0))
    assert_allclose(poly(xj) @ ell, poly(x), rtol=1e-12)  # rounding of 32-point sums
    # a point on a node gets that node's row
    assert_allclose(_pseudo.lagrange(xj[:3].copy())[:3], np.eye(3), atol=0)


def test_far_sum_matches_digamma_closed_form():
    # sum_{k=a}^{b-1} 1 / (i d k - p) = (psi(b - z) - psi(a - z)) / (i d), z = p / (i d):
    # the quadrature W_j of one bin far from p against the closed form
    d, a, b = 0.05, 4000, 6048  # lines w_k = d k (rad/s), one bin of 2048 lines
    p = complex(-3.0, 90.0)  # the pole lies 110 rad/s below the bin's lower end
    w = d * np.arange(a, b)
    c, h = (w[0] + w[-1]) / 2, (w[-1] - w[0]) / 2
    assert _pseudo.bernstein_rho(np.array([(complex(p.imag, -p.real) - c) / h])) > _pseudo.RHO_MIN
    wj = _pseudo.lagrange((w - c) / h).sum(axis=1)
    nodes = c + h * _pseudo._cheb_nodes(_pseudo.NODES)[0]
    got = np.sum(wj / (1j * nodes - p))
    z = p / (1j * d)
    exact = (psi(b - z) - psi(a - z)) / (1j * d)
    assert_allclose(got, exact, rtol=1e-13)  # rounding of the sums (and of psi)


@pytest.mark.parametrize("n_in", [1, 2])
def test_gram_blocks_equal_sums_over_lines(n_in):
    fit, p = _fitter(n_in, 10 * _pseudo.BIN_LINES)
    assert _pseudo.applies(fit)
    th_f, m, ref, _ = fit._fixed_modes(p[:2], np.ones((2, n_in), complex), 0)
    one, _lay, _n1 = fit._added_fitter()
    pl = _pseudo.pseudo_lines(fit, lambda sl: fit._basis_ek(th_f, m, ref, False, sl)[0])
    for pole, n_near in ((p[2], 2), (complex(-40.0, 2 * np.pi * 120.0), 0)):
        assert _pseudo.near_bins(pl, pole).sum() >= n_near  # lines of near bins taken too
        l1 = np.ones((1, n_in), complex)
        ref1 = np.zeros(1, np.intp)
        th = one.pack(np.array([pole]), l1, ref1)
        pp1 = one.unpack(th, 1, ref1)
        got = _pseudo.gram_blocks(
            fit,
            pl,
            lambda fac, sl, th=th, pp1=pp1, r1=ref1: one._basis_ek(th, 1, r1, True, sl, (fac, pp1))[
                0
            ],
            lambda sl: fit._basis_ek(th_f, m, ref, False, sl)[0],
            complex(pp1[0][0]),
        )
        b = one._basis_ek(th, 1, ref1, True)[0]
        phi = fit._basis_ek(th_f, m, ref, False)[0]
        exact = (phi.T @ b, b.T @ b, b.T @ _basis.ydata(fit))
        for g, e in zip(got, exact, strict=True):
            # rounding of sums of 2e4 lines, relative to the largest entry
            assert_allclose(g, e, rtol=0, atol=1e-12 * np.abs(e).max())


def test_trial_same_with_and_without_pseudo_lines(monkeypatch):
    # enough lines that the fixed basis of two modes is not kept (FixedPart.keep)
    fit, p = _fitter(1, 45 * _pseudo.BIN_LINES, seed=1)
    part = np.ones((2, 1), complex)
    got = []
    for mb in (_pseudo.MIN_BINS, 10**9):
        monkeypatch.setattr(_pseudo, "MIN_BINS", mb)
        fx = fit.fixed_part(p[:2], part)
        assert (fx.pseudo is not None) == (mb < 10**9)
        w0 = abs(p[2].imag)
        got.append(
            fit.fit_added(
                p[:2], part, p[2] * 1.003, np.ones(1, complex), fixed=fx,
                omega_bounds=(0.97 * w0, 1.03 * w0),
            )
        )  # fmt: skip
    assert_allclose(got[0][0], got[1][0], rtol=1e-12)  # the same optimum to rounding
    assert_allclose(got[0][2], got[1][2], rtol=1e-9)  # residual RMS: a difference of sums


@pytest.mark.parametrize(("n_in", "power"), [(1, 2), (2, 0)])
def test_gram_full_equals_sums_over_lines(n_in, power, monkeypatch):
    # every mode and both residual terms; receptance (power 0) puts a pole of the
    # lower term's column at 0, whose bins are then taken on the lines; the far
    # bins in several pieces
    monkeypatch.setattr(_pseudo, "FAR_BINS", 3)
    fit, p = _fitter(n_in, 10 * _pseudo.BIN_LINES, seed=2)
    fit = ModalFitter(fit.f, fit.H, power, "complex", [], upper=True, lower=True)
    part = np.ones((p.size, n_in), complex)
    th, m, ref, _ = fit._fixed_modes(p, part, 0)
    pl = fit._pseudo_lines()
    assert pl is not None
    pp = fit.unpack(th, m, ref)
    at_zero = [0j] if power < 2 else []
    G, P = _pseudo.gram_full(
        fit,
        pl,
        lambda fac, sl: fit._basis_ek(th, m, ref, True, sl, (fac, pp))[0],
        np.concatenate([pp[0], at_zero]),
    )
    b = fit._basis_ek(th, m, ref, True)[0]
    for g, e in ((G, b.T @ b), (P, b.T @ _basis.ydata(fit))):
        # rounding of sums of 2e4 lines, relative to the largest entry
        assert_allclose(g, e, rtol=0, atol=1e-12 * np.abs(e).max())


def test_fit_same_with_and_without_pseudo_lines(monkeypatch):
    fit, p = _fitter(2, 10 * _pseudo.BIN_LINES, seed=3)
    part = np.ones((p.size, 2), complex)
    got = []
    for mb in (_pseudo.MIN_BINS, 10**9):
        monkeypatch.setattr(_pseudo, "MIN_BINS", mb)
        fit._pl = None
        got.append(fit.fit(p * (1 + 1e-3), part, passes=1, uncertainty=False, max_nfev=4))
        assert (fit._pl is not None) == (mb < 10**9)  # the fit went through them
    assert_allclose(got[0].poles, got[1].poles, rtol=1e-11)  # the same optimum to rounding
    assert_allclose(got[0].sigma_out, got[1].sigma_out, rtol=1e-9)  # a difference of sums


def test_scan_sums_equal_sums_over_lines(monkeypatch):
    # a scan's inner products with smooth values (a residual's moments stand for it
    # on far bins) against the sums over the lines, poles beyond and inside the band
    monkeypatch.setattr(_pseudo, "FAR_BINS", 3)
    fit, _p = _fitter(1, 10 * _pseudo.BIN_LINES, seed=4)
    pl = fit._pseudo_lines()
    assert pl is not None
    rng = np.random.default_rng(5)
    v = rng.normal(size=(3, fit.n_f)) + 1j * rng.normal(size=(3, fit.n_f))  # noise-like
    pg = pole_from_frequency_damping(np.array([201.0, 230.0, 300.0, 120.0]), 0.01)
    cols = lambda s, kap, p: kap[None, :] / (s[None, :] - p[:, None])  # noqa: E731
    m, n2 = _pseudo.scan_sums(fit, pl, lambda sl: v[:, sl], cols, pg, chunk=2)
    s, kap, _ = _basis.factors(fit)
    c = cols(s, kap, pg)
    # rounding of sums of 2e4 lines, relative to the largest entry
    assert_allclose(m, v @ c.conj().T, rtol=0, atol=1e-12 * np.abs(v @ c.conj().T).max())
    assert_allclose(n2, np.sum(np.abs(c) ** 2, axis=1), rtol=1e-12)


@pytest.mark.parametrize("n_in", [1, 2])
def test_fixed_far_equals_moments_over_lines(n_in, monkeypatch):
    # the fixed basis's moments, Gram blocks and products with the data from its
    # values at the nodes (far bins, in several pieces) against those summed over
    # every line
    monkeypatch.setattr(_pseudo, "FAR_BINS", 3)
    fit, p = _fitter(n_in, 10 * _pseudo.BIN_LINES, seed=6)
    th, m, ref, _ = fit._fixed_modes(p, np.ones((p.size, n_in), complex), 0)
    base = fit._pseudo_lines()
    assert base is not None
    rows = lambda sl: fit._basis_ek(th, m, ref, False, sl)[0]  # noqa: E731
    exact = _pseudo.fixed_lines(fit, rows, base)
    got = _pseudo.fixed_far(
        fit, base, rows, lambda fac: fit._basis_ek(th, m, ref, False, None, (fac, None))[0], p
    )
    for g, e in ((got[0].phi, exact[0].phi), (got[1], exact[1]), (got[2], exact[2])):
        # rounding of sums of 2e4 lines, relative to the largest entry
        assert_allclose(g, e, rtol=0, atol=1e-12 * np.abs(e).max())
