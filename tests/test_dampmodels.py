"""Damping laws, exact modes and FRFs (tyredamp.dampmodels.laws, .system)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.dampmodels import (
    DampedSystem,
    Exponential,
    Fractional,
    Hysteretic,
    Viscous,
    newton_mode,
)
from tyredamp.exceptions import InputError, PhysicsError, ShapeError
from tyredamp.mechanics import MCKSystem

M3 = np.diag([1.0, 2.0, 1.5])
K3 = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) * 1e4
C3 = np.array([[3.0, -1.0, 0.5], [-1.0, 2.0, 0.2], [0.5, 0.2, 1.0]])
F = np.linspace(1.0, 60.0, 40)


def _laws() -> list:
    return [
        Viscous(C3),
        Exponential(np.stack([C3, 0.5 * C3]), [30.0, 500.0]),
        Hysteretic.loss_factor(K3, 0.05),
        Fractional(3 * C3, 0.6),
    ]


@pytest.mark.parametrize("law", _laws(), ids=lambda law: law.name)
def test_modes_are_roots(law) -> None:
    sys = DampedSystem(M3, K3, law)
    md = sys.modes()
    assert md.poles.size == 3
    for j, p in enumerate(md.poles):
        x = md.shapes[:, j]
        r = sys.dynamic_stiffness(p) @ x
        # D(p) x = 0 to rounding relative to ||K|| ||x||
        assert np.linalg.norm(r) < 1e-10 * np.linalg.norm(K3) * np.linalg.norm(x)
        # residue normalisation x^T D'(p) x = 1 (A-W part 2, eq. (9)), to rounding
        assert_allclose(x @ sys.dstiffness(p) @ x, 1.0, rtol=1e-10)


@pytest.mark.parametrize("law", _laws()[:3], ids=lambda law: law.name)
def test_modal_sum_equals_direct_inverse(law) -> None:
    sys = DampedSystem(M3, K3, law)
    H = sys.receptance(F)
    # exact modal expansion (all roots incl. relaxation modes), to rounding
    assert_allclose(sys.modes().receptance(F), H, rtol=0, atol=1e-11 * np.abs(H).max())


def test_viscous_matches_mck_system() -> None:
    p_ref = MCKSystem(M3, C3, K3).complex_modes().poles
    # the same state-space problem solved by two codes, to rounding
    assert_allclose(DampedSystem(M3, K3, Viscous(C3)).modes().poles, p_ref, rtol=1e-12)


def test_sdof_closed_forms() -> None:
    k, c, mu, eta, alpha = 1e4, 3.0, 80.0, 0.04, 0.5
    one = np.ones((1, 1))
    # exponential: s^3 + mu s^2 + (k + c mu) s + k mu = 0 (D(s) (s + mu) for m = 1)
    roots = np.roots([1.0, mu, k + c * mu, k * mu])
    md = DampedSystem(one, k * one, Exponential(c * one, [mu])).modes()
    assert_allclose(md.poles[0], roots[roots.imag > 0][0], rtol=1e-12)  # rounding
    assert_allclose(md.relaxation_poles[0], roots[np.abs(roots.imag) < 1e-9][0].real, rtol=1e-12)
    # hysteretic: s^2 + k (1 + i eta) = 0, the root with Im > 0 and Re < 0
    md = DampedSystem(one, k * one, Hysteretic.loss_factor(k * one, eta)).modes()
    assert_allclose(md.poles[0], 1j * np.sqrt(k * (1 + 1j * eta)), rtol=1e-12)  # rounding
    # fractional alpha = 1/2: y = sqrt(s) solves y^4 + c y + k = 0, principal branch
    y = np.roots([1.0, 0.0, 0.0, c, k])
    y = y[(np.angle(y) > 0) & (np.angle(y) < np.pi / 2)][0]
    md = DampedSystem(one, k * one, Fractional(c * one, alpha)).modes()
    assert_allclose(md.poles[0], y**2, rtol=1e-12)  # Newton converged to rounding


def test_newton_agrees_with_augmented_state_space() -> None:
    law = Exponential(np.stack([C3, 0.5 * C3]), [30.0, 500.0])
    sys = DampedSystem(M3, K3, law)
    md = sys.modes()
    for j, p in enumerate(md.poles):
        s, _ = newton_mode(sys, p * (1 + 1e-3), md.shapes[:, j].real)
        # two independent solvers of the same nonlinear eigenproblem, to rounding
        assert_allclose(s, p, rtol=1e-11)


def test_hysteretic_is_marked_non_causal() -> None:
    assert not Hysteretic.causal
    assert all(law.causal for law in (Exponential, Fractional, Viscous))
    md = DampedSystem(M3, K3, Hysteretic.loss_factor(K3, 0.02)).modes()
    assert md.partner == "negative"
    # constant loss factor: every mode has zeta = Im sqrt(1 + i eta) / |sqrt(1 + i eta)|
    z = -(1j * np.sqrt(1 + 0.02j)).real / abs(np.sqrt(1 + 0.02j))
    assert_allclose(md.damping_ratio, z, rtol=1e-10)  # proportional: exact, to rounding


def test_bad_input() -> None:
    with pytest.raises(InputError, match="alpha"):
        Fractional(C3, 2.5)
    with pytest.raises(PhysicsError, match="mu"):
        Exponential(C3, [-1.0])
    with pytest.raises(ShapeError, match="n_k"):
        Exponential(C3, [1.0, 2.0])
    with pytest.raises(ShapeError, match="law"):
        DampedSystem(M3, K3, Viscous(np.eye(2)))
