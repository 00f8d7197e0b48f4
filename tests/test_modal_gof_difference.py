"""Goodness of fit against the noise from second differences: the inflation of eq. (GoF-1)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import integrate, special

from tyredamp.frf import FRF
from tyredamp.modal.assemble import goodness
from tyredamp.modal.problem.problem import build_problem
from tyredamp.modal.statistics.stats import (
    DIFFERENCE_INFLATION,
    chi2_sf,
    difference_noise,
    goodness_of_fit,
)

M = math.log(2.0)


def _both_below(r: float, a: float = M) -> float:
    """``P(X <= a, Y <= a)`` of two unit exponentials ``|z_1|^2, |z_2|^2`` of complex
    Gaussians with ``|rho|^2 = r``: Kibble's bivariate exponential density
    ``exp(-(x + y) / (1 - r)) I_0(2 sqrt(r x y) / (1 - r)) / (1 - r)`` integrated
    over the square (numerically, independent of the series of the module docstring)."""

    def dens(y: float, x: float) -> float:
        return float(
            np.exp(-(x + y) / (1 - r)) / (1 - r) * special.i0(2 * np.sqrt(r * x * y) / (1 - r))
        )

    return float(integrate.dblquad(dens, 0.0, a, 0.0, a, epsabs=1e-13, epsrel=1e-12)[0])


def test_inflation_equals_its_closed_form() -> None:
    """eq. (GoF-1): 1 - 2 + 4 (g_0 + 2 g_1 + 2 g_2) / ln(2)^2 with the lag correlations
    of second differences |rho|^2 = 4/9 (lag 1) and 1/36 (lag 2)."""
    g = [0.25, _both_below(4.0 / 9.0) - 0.25, _both_below(1.0 / 36.0) - 0.25]
    kappa = 1.0 - 2.0 + 4.0 * (g[0] + 2 * g[1] + 2 * g[2]) / M**2
    # the quadrature converges to ~1e-12; the constant is stated to 16 digits
    assert_allclose(DIFFERENCE_INFLATION, kappa, rtol=1e-9)


def test_inflation_against_monte_carlo() -> None:
    """The cost of pure noise against each FRF's difference noise has mean ``dof`` and
    variance ``2 kappa dof`` (the chi-square's would be ``2 dof``)."""
    rng = np.random.default_rng(7)
    n_rep, shape = 2500, (2, 2, 300)
    e = (rng.normal(size=(n_rep, *shape)) + 1j * rng.normal(size=(n_rep, *shape))) / np.sqrt(2)
    dof = 2 * int(np.prod(shape))
    v = difference_noise(e, per_input=True)  # (n_rep, 2, 2): every FRF of every draw
    cost = 2 * np.sum(np.sum(e.real**2 + e.imag**2, axis=-1) / v, axis=(1, 2))
    # mean: E[1 / v^] - 1 is O(kappa / n) = 0.7 %; 3 standard errors of the mean 0.5 %
    assert_allclose(np.mean(cost) / dof, 1.0, atol=0.012)
    ratio = np.var(cost) / (2 * dof)
    # the sample variance of 2500 draws has a relative standard error of about
    # sqrt(2 / 2500) = 2.8 % (the cost is near Gaussian); 4 of them, plus O(1/n)
    assert_allclose(ratio, DIFFERENCE_INFLATION, rtol=0.12)
    assert ratio > 1.5  # the chi-square's variance alone (1) would fail


def test_goodness_of_fit_with_inflation_is_the_scaled_chi_square() -> None:
    dof, kappa, x = 20000, DIFFERENCE_INFLATION, 20500.0
    g = goodness_of_fit(x, dof, "test", inflation=kappa)
    # the same special function on the scaled arguments: round-off only
    assert_allclose(g.p_value, chi2_sf(x / kappa, dof / kappa), rtol=1e-12)
    assert g.expected == dof
    plain = goodness_of_fit(x, dof, "test")
    assert plain.p_value < g.p_value  # the wider law: a larger tail probability
    assert_allclose(plain.p_value, chi2_sf(x, dof), rtol=1e-12)  # round-off only
    with pytest.raises(ValueError, match="inflation"):
        goodness_of_fit(x, dof, "test", inflation=0.5)
    with pytest.raises(ValueError, match="inflation"):
        goodness_of_fit(x, dof, "test", noise_dof=10.0, inflation=kappa)


def test_pure_noise_false_fail_rate_near_its_level() -> None:
    """A correct model (here: no mode, zero model, of data that are noise alone) fails
    the test at 10 % about 10 % of the time; tested as if the noise were known it
    would fail far more often (the difference noise's own scatter)."""
    rng = np.random.default_rng(3)
    f = np.arange(1.0, 301.0)
    fails, fails_known = 0, 0
    n_rep = 300
    for _ in range(n_rep):
        h = (rng.normal(size=(3, 1, f.size)) + 1j * rng.normal(size=(3, 1, f.size))) * 1e-3
        pr = build_problem(FRF(f, h, kind="receptance"), None)
        sq = np.abs(pr.H) ** 2  # the zero model's residual, normalised units
        g = goodness(pr, sq, 0, 0, 0.1)
        fails += not g.passed
        var = difference_noise(pr.H, per_input=True)
        chi2 = 2.0 * float(np.einsum("okf,ok->", sq, 1.0 / var))
        fails_known += chi2_sf(chi2, 2 * sq.size) < 0.1
    # binomial standard deviation of the rate at 10 % over 300 draws: 1.7 %
    assert abs(fails / n_rep - 0.1) < 0.06
    assert fails_known / n_rep > fails / n_rep + 0.05
