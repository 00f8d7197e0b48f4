"""Gram blocks of several-input real-mode fits from per-line sums (modal/fit/_gram_lines)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.modal.fit import _basis, _gram_lines
from tyredamp.modal.fit.fit import ModalFitter

from .test_modal_fit_gram_lines import F
from .test_modal_fit_gram_lines import _fitter as _any_fitter


def _fitter(
    n_in: int, power: int, upper: bool, lower: bool, weights: bool, seed: int = 0
) -> tuple[ModalFitter, np.ndarray, int, np.ndarray]:
    """A real-mode fitter on random data, and a parameter vector of 4 modes."""
    return _any_fitter(n_in, power, upper, lower, weights, seed, kind="real")


CASES = [
    c
    for c in itertools.product(
        (2, 3), (0, 2), ((True, True), (False, True), (False, False)), (False, True), (True, False)
    )
    if (c[1] // 2 + c[3] + c[4] + c[2][0]) % 2 == 0
]


@pytest.mark.parametrize(("n_in", "power", "terms", "weights", "der"), CASES)
def test_real_gram_blocks_equal_those_of_the_basis(
    n_in: int, power: int, terms: tuple[bool, bool], weights: bool, der: bool
) -> None:
    fit, th, m, ref = _fitter(n_in, power, *terms, weights)
    B = fit._basis_ek(th, m, ref, der)[0]  # the explicit real-mode basis [Phi | D]
    G0, P0 = B.T @ B, B.T @ fit.Y
    parts = [slice(0, 70), slice(70, 200), slice(200, F.size)]  # sums over blocks
    G, P = _gram_lines.gram(fit, fit.unpack(th, m, ref), ref, der, parts)
    assert G.shape == G0.shape
    assert P.shape == P0.shape
    assert np.array_equal(G, G.T)
    d = np.sqrt(np.diag(G0))
    # exact up to rounding: each entry to 1e-12 of the product of the two columns'
    # norms (Cauchy-Schwarz bound), the diagonal entry-wise
    assert np.all(np.abs(G - G0) <= 1e-12 * np.outer(d, d))
    assert np.all(np.abs(P - P0) <= 1e-12 * np.outer(d, np.sqrt(fit._yss)))
    assert_allclose(np.diag(G), np.diag(G0), rtol=1e-12)


def test_real_atoms_are_the_column_and_its_derivatives() -> None:
    # spec eq. [2]: a real mode's column kappa / ((s - p)(s - conj p)); its atoms by
    # x1 (sigma = w_ref e^x1) and x2 (Omega = w_ref x2) against central differences
    fit, th, m, ref = _fitter(2, 1, True, True, True)
    poles, _ = fit.unpack(th, m, ref)
    s, kap, kap_low = _basis.factors(fit)
    ft = _gram_lines.real_atoms(fit, poles, True, (s, kap, kap_low))
    wr = fit.w_ref

    def col(x1: float, x2: float) -> np.ndarray:
        sig, om = wr * np.exp(x1), wr * x2
        return kap / ((s + sig) ** 2 + om**2)

    for n, p in enumerate(poles):
        x1, x2 = np.log(-p.real / wr), p.imag / wr
        g = kap / ((s - p) * (s - np.conj(p)))  # by direct division
        assert_allclose(ft[3 * n], g, rtol=1e-12, atol=1e-13 * np.abs(g).max())
        for j, (e1, e2) in enumerate(((1e-6, 0.0), (0.0, 1e-7)), start=1):
            fd = (col(x1 + e1, x2 + e2) - col(x1 - e1, x2 - e2)) / (2 * (e1 + e2))
            # central differences: truncation O(h^2) and rounding O(eps / h)
            assert_allclose(ft[3 * n + j], fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    assert_allclose(ft[3 * m], kap, rtol=0)
    assert_allclose(ft[3 * m + 1], kap_low, rtol=0)


def test_real_coefficients_rebuild_the_basis() -> None:
    fit, th, m, ref = _fitter(3, 2, True, True, False)
    pp = fit.unpack(th, m, ref)
    idx, val, n_phi = _gram_lines.real_coefficients(fit, pp[1], ref, True)
    assert np.all(val[:, :, 1] == 0.0)  # one atom per column and input
    ft = _gram_lines.real_atoms(fit, pp[0], True, _basis.factors(fit))
    assert n_phi == ft.shape[0]
    B = fit._basis_ek(th, m, ref, True)[0]
    bc = B.T.reshape(B.shape[1], fit.n_in, F.size, 2)  # (column, input, line, re/im)
    for k in range(fit.n_in):
        col = val[k, :, 0, None] * ft[idx[k, :, 0]]
        got = bc[:, k, :, 0] + 1j * bc[:, k, :, 1]
        assert_allclose(col, got, rtol=0, atol=1e-12 * np.abs(got).max())


@pytest.mark.parametrize("residual", [False, True])
def test_real_solve_is_the_same_by_either_route(
    residual: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    fit, th, m, ref = _fitter(2, 2, True, True, True, seed=4)
    w = fit.weights(None)
    sols = []
    for use in (False, True):
        monkeypatch.setattr(_gram_lines, "USE", use)
        sols.append(fit._solve(th, m, ref, w, residual=residual))
    old, new = sols
    assert new["qr"] == old["qr"] == residual
    tol = 0.0 if residual else 1e-12  # the QR route forms the same basis
    assert_allclose(new["cost"], old["cost"], rtol=tol)
    assert_allclose(new["C"], old["C"], rtol=1e-9 if not residual else 0.0, atol=0)
    assert_allclose(new["Etr"], old["Etr"], rtol=1e-9 if not residual else 0.0, atol=0)
