"""The Levenberg-Marquardt stop on the parameters of interest (nuisance profiled out)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.modal.fit._linalg import _levenberg_marquardt, interest_decrement
from tyredamp.modal.fit.fit import ModalFitter


def _spd(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    return a @ a.T + 0.5 * np.eye(n)


def _profile_decrement(A: np.ndarray, g: np.ndarray, i1: np.ndarray) -> float:
    """The decrement of the profile cost (the quadratic model minimised over the
    nuisance parameters): ``g1'^T S^-1 g1'`` with the Schur complement ``S``."""
    i2 = np.setdiff1d(np.arange(A.shape[0]), i1)
    a11, a12, a22 = A[np.ix_(i1, i1)], A[np.ix_(i1, i2)], A[np.ix_(i2, i2)]
    s = a11 - a12 @ np.linalg.solve(a22, a12.T)
    g1 = g[i1] - a12 @ np.linalg.solve(a22, g[i2])
    return float(g1 @ np.linalg.solve(s, g1))


def test_interest_decrement_is_the_profile_cost_decrement() -> None:
    A = _spd(7, 1)
    g = np.random.default_rng(2).normal(size=7)
    i1 = np.array([0, 2, 5])
    got = interest_decrement(None, A, g, i1)
    # the Schur-complement form is an independent computation (1e-12 of 1e-16
    # rounding on a 7 x 7 system of condition about 1e2)
    assert_allclose(got, _profile_decrement(A, g, i1), rtol=1e-10)
    full = float(g @ np.linalg.solve(A, g))
    assert got <= full * (1 + 1e-12)
    # every parameter of interest: the full decrement (same rounding)
    assert_allclose(interest_decrement(None, A, g, np.arange(7)), full, rtol=1e-10)


def test_interest_decrement_of_free_parameters_only() -> None:
    # A and g are those of the free parameters (2, 3, 5, 6): interest 0 and 3 are
    # held (not among them), so only 5 of interest remains
    A = _spd(4, 3)
    g = np.random.default_rng(4).normal(size=4)
    free = np.array([2, 3, 5, 6])
    got = interest_decrement(free, A, g, np.array([0, 3, 5]))
    assert_allclose(got, _profile_decrement(A, g, np.array([1, 2])), rtol=1e-10)
    assert interest_decrement(free, A, g, np.array([0, 1])) == 0.0


def _creeping(x: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, None]:
    """Residuals ``[1, 10 (x0 - 1) + e^x1, 10 e^x1]``: ``x0`` is found at once, the
    nuisance ``x1`` creeps toward -inf by about one per Gauss-Newton step."""
    e = np.exp(x[1])
    r = np.array([1.0, 10.0 * (x[0] - 1.0) + e, 10.0 * e])
    J = np.array([[0.0, 0.0], [10.0, e], [0.0, 10.0 * e]])
    return float(r @ r), J.T @ J, J.T @ r, None


def test_the_stop_on_interest_leaves_the_nuisance_creeping() -> None:
    lb, ub = np.full(2, -50.0), np.full(2, 50.0)
    x0 = np.array([0.0, 0.0])
    x_all, n_all, ok_all, _ = _levenberg_marquardt(_creeping, x0, lb, ub, 200, dof=1, tol=1e-4)
    x_int, n_int, ok_int, _ = _levenberg_marquardt(
        _creeping, x0, lb, ub, 200, dof=1, tol=1e-4, interest=np.array([0])
    )
    assert ok_all
    assert ok_int
    assert n_int < n_all
    # x0 within sqrt(tol) = 0.01 of its standard deviation (about 0.1 here) of its
    # Gauss-Newton optimum at the stop, which is the converged value 1 as the
    # nuisance creeps to -inf; 2x margin for the valley's curvature beyond the
    # quadratic model
    assert abs(x_int[0] - x_all[0]) <= 0.02 * 0.1
    assert abs(x_all[0] - 1.0) <= 1e-3 * 0.1


def test_interest_indices_of_the_first_modes() -> None:
    f = np.linspace(1.0, 10.0, 20)
    H = np.ones((2, 3, f.size), complex)
    fit_c = ModalFitter(f, H, 0, "complex", [])
    # 4 modes, 3 inputs: poles 0..7, then 4 participation entries per mode
    assert fit_c.interest(4, 2).tolist() == [0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 14, 15]
    assert fit_c.interest(4, 4) is None
    # no in-band mode: every parameter must converge; a negative count is refused
    assert fit_c.interest(4, 0) is None
    with pytest.raises(InputError, match="n_interest"):
        fit_c.interest(4, -1)
    fit_r = ModalFitter(f, H, 0, "real", [])
    # real modes: 2 participation entries per mode
    assert fit_r.interest(3, 1).tolist() == [0, 1, 6, 7]
