"""The law of the mode statistic of a mode that is not there with several inputs
(stats.rank_one_sf, mode_null_sf, mode_null_isf; complex modes: Khatri 1964,
real modes: Chiani 2017) against closed forms (one input: chi-square) and Monte
Carlo samples of the rank-one least-squares fit it describes."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import stats as sps

from tyredamp.modal import identify_modes
from tyredamp.modal.model import ModalModel
from tyredamp.modal.statistics.stats import (
    mode_null_isf,
    mode_null_sf,
    mode_parameters,
    mode_threshold,
    rank_one_available,
    rank_one_sf,
)


def _rank_one_drop(n_out: int, n_in: int, n: int, seed: int, real: bool = False) -> np.ndarray:
    """The drop of the cost (real units: each real part of variance 1) when the best
    rank-one residue ``psi l^T`` is fitted to an ``n_out x n_in`` block of pure
    complex Gaussian noise (``real``: real ``u l^T`` to real unit Gaussian noise,
    the projections of a real mode's column): by least squares over ``psi`` for
    each ``l`` and then over the direction of ``l`` -- computed here by power
    iteration on ``Z^H Z``, not by the singular values."""
    rng = np.random.default_rng(seed)
    z = rng.normal(size=(n, n_out, n_in))
    if not real:
        z = z + 1j * rng.normal(size=(n, n_out, n_in))
    g = np.conj(z).transpose(0, 2, 1) @ z  # (n, n_in, n_in)
    # einsum on vectors of z's own type: a stacked matmul by (n_in, 1) complex columns
    # took ~8x longer for the same products
    v = np.ones((n, n_in), z.dtype)
    for _ in range(80):
        v = np.einsum("nij,nj->ni", g, v)
        v /= np.linalg.norm(v, axis=1, keepdims=True)
    # the drop of ||Z - psi l^T||^2 over psi at the unit direction l = conj(v): ||Z v||^2
    return np.sum(np.abs(np.einsum("nij,nj->ni", z, v)) ** 2, axis=1)


@pytest.mark.parametrize("n_out", [1, 3, 16])
def test_one_input_is_the_chi_square_of_the_parameters(n_out: int) -> None:
    # one input: the residue is a column, 2 n_out real coefficients; with the pole's
    # 2 the chi2_k of mode_parameters, exactly
    k = mode_parameters(n_out, 1, "complex")
    for x in (5.0, 30.0, 80.0):
        assert_allclose(rank_one_sf(x, n_out, 1), sps.chi2.sf(x, 2 * n_out), rtol=1e-9)
        assert_allclose(mode_null_sf(x, n_out, 1), sps.chi2.sf(x, k), rtol=1e-12)
    assert_allclose(mode_null_isf(1e-6, n_out, 1), sps.chi2.isf(1e-6, k), rtol=1e-12)
    assert mode_threshold(k, 800, 0.01, None, (n_out, 1)) == mode_threshold(k, 800, 0.01)


@pytest.mark.parametrize(("n_out", "n_in"), [(4, 3), (2, 2), (8, 4), (3, 5)])
def test_rank_one_law_against_monte_carlo(n_out: int, n_in: int) -> None:
    t = _rank_one_drop(n_out, n_in, 100_000, seed=n_out * 10 + n_in)
    for q in (0.5, 0.9, 0.99, 0.999):
        x = float(np.quantile(t, q))
        p = 1.0 - q
        se = np.sqrt(p * (1 - p) / t.size)
        assert abs(rank_one_sf(x, n_out, n_in) - p) < 4.5 * se
    # symmetric in outputs and inputs (the law of the largest singular value)
    assert_allclose(rank_one_sf(30.0, n_out, n_in), rank_one_sf(30.0, n_in, n_out), rtol=1e-9)


def test_mode_null_adds_the_pole_as_chi_square_two() -> None:
    # T_0 + B, B ~ chi2_2 independent: sampled sum against the quadrature
    n_out, n_in = 4, 3
    t = _rank_one_drop(n_out, n_in, 100_000, seed=7)
    t = t + np.random.default_rng(8).chisquare(2, t.size)
    for q in (0.9, 0.99, 0.999):
        x = float(np.quantile(t, q))
        p = 1.0 - q
        assert abs(mode_null_sf(x, n_out, n_in) - p) < 4.5 * np.sqrt(p * (1 - p) / t.size)


def test_quantile_inverts_the_tail_and_lies_beyond_the_parameter_count() -> None:
    for n_out, n_in in ((4, 3), (8, 4), (2, 2)):
        k = mode_parameters(n_out, n_in, "complex")
        for level in (1e-3, 1e-5, 1e-8):
            x = mode_null_isf(level, n_out, n_in)
            assert_allclose(mode_null_sf(x, n_out, n_in), level, rtol=1e-5)
            # the rank-one residue's law has a heavier tail than chi2_k: the old
            # threshold let noise modes of several inputs through
            assert x > sps.chi2.isf(level, k)
        thr = mode_threshold(k, 1000, 0.01, None, (n_out, n_in))
        assert_allclose(thr, mode_null_isf(1e-5, n_out, n_in), rtol=1e-12)
    # the estimated-weight corrections scale with it
    k = mode_parameters(4, 3, "complex")
    ratio = mode_null_isf(1e-5, 4, 3) / sps.chi2.isf(1e-5, k)
    assert_allclose(
        mode_threshold(k, 1000, 0.01, 12.0, (4, 3)), ratio * mode_threshold(k, 1000, 0.01, 12.0)
    )


def test_rank_one_law_refuses_what_it_cannot_evaluate() -> None:
    with pytest.raises(ValueError, match="min"):
        rank_one_sf(100.0, 20, 17)
    # an empty residue block or a level that is no probability: named, not a number
    with pytest.raises(ValueError, match="n_out, n_in >= 1"):
        rank_one_sf(10.0, 0, 3)
    with pytest.raises(ValueError, match="n_out, n_in >= 1"):
        mode_null_sf(10.0, 4, 0)
    with pytest.raises(ValueError, match="probability"):
        mode_null_isf(0.0, 4, 3)
    with pytest.raises(ValueError, match="probability"):
        mode_null_isf(1.5, 4, 3)
    # mode_threshold keeps the parameter count's quantile there
    k = mode_parameters(20, 17, "complex")
    assert mode_threshold(k, 100, 0.01, None, (20, 17)) == mode_threshold(k, 100, 0.01)


@pytest.mark.parametrize("n_out", [1, 3, 16])
def test_real_one_input_is_the_chi_square_of_the_parameters(n_out: int) -> None:
    # one input: u l^T is a real column of n_out coefficients; with the pole's 2 the
    # chi2_k of a real mode (n_out + 2), exactly
    k = mode_parameters(n_out, 1, "real")
    for x in (5.0, 30.0, 80.0):
        assert_allclose(rank_one_sf(x, n_out, 1, "real"), sps.chi2.sf(x, n_out), rtol=1e-12)
        assert_allclose(mode_null_sf(x, n_out, 1, "real"), sps.chi2.sf(x, k), rtol=1e-12)
    assert_allclose(mode_null_isf(1e-6, n_out, 1, "real"), sps.chi2.isf(1e-6, k), rtol=1e-12)
    assert mode_threshold(k, 800, 0.01, None, (n_out, 1), "real") == mode_threshold(k, 800, 0.01)


@pytest.mark.parametrize(("n_out", "n_in"), [(4, 3), (2, 2), (8, 4), (3, 5), (16, 16)])
def test_real_rank_one_law_against_monte_carlo(n_out: int, n_in: int) -> None:
    t = _rank_one_drop(n_out, n_in, 100_000, seed=n_out * 10 + n_in + 1, real=True)
    for q in (0.5, 0.9, 0.99, 0.999):
        x = float(np.quantile(t, q))
        p = 1.0 - q
        se = np.sqrt(p * (1 - p) / t.size)
        assert abs(rank_one_sf(x, n_out, n_in, "real") - p) < 4.5 * se
    assert_allclose(
        rank_one_sf(30.0, n_out, n_in, "real"), rank_one_sf(30.0, n_in, n_out, "real"), rtol=1e-9
    )


def test_real_law_lies_between_the_chi_square_and_the_complex_law() -> None:
    # the real residue's law: heavier-tailed than chi2 of its n_out + n_in - 1
    # parameters, lighter than the complex law of twice as many; the pole's chi2_2
    # added as sampled
    n_out, n_in = 4, 3
    t = _rank_one_drop(n_out, n_in, 100_000, seed=11, real=True)
    t = t + np.random.default_rng(12).chisquare(2, t.size)
    for q in (0.9, 0.99, 0.999):
        x = float(np.quantile(t, q))
        p = 1.0 - q
        assert abs(mode_null_sf(x, n_out, n_in, "real") - p) < 4.5 * np.sqrt(p * (1 - p) / t.size)
    k = mode_parameters(n_out, n_in, "real")
    for level in (1e-3, 1e-5, 1e-8):
        x = mode_null_isf(level, n_out, n_in, "real")
        assert_allclose(mode_null_sf(x, n_out, n_in, "real"), level, rtol=1e-5)
        assert sps.chi2.isf(level, k) < x < mode_null_isf(level, n_out, n_in)
    assert_allclose(
        mode_threshold(k, 1000, 0.01, None, (n_out, n_in), "real"),
        mode_null_isf(1e-5, n_out, n_in, "real"),
        rtol=1e-12,
    )


def test_real_law_refuses_what_it_cannot_evaluate() -> None:
    # an ill-conditioned law (condition of its matrix ~3e16 at 16 x 40): refused by
    # rank_one_sf, and the threshold keeps the parameter count's quantile
    assert rank_one_available(16, 16, "real")
    assert not rank_one_available(40, 16, "real")
    with pytest.raises(ValueError, match="not evaluated"):
        rank_one_sf(100.0, 40, 16, "real")
    k = mode_parameters(40, 16, "real")
    assert mode_threshold(k, 100, 0.01, None, (40, 16), "real") == mode_threshold(k, 100, 0.01)
    with pytest.raises(ValueError, match="kind"):
        rank_one_sf(10.0, 4, 3, "viscous")
    # a parameter count that is not that of the shape and kind: named
    with pytest.raises(ValueError, match="parameter count"):
        mode_threshold(mode_parameters(4, 3, "complex"), 100, 0.01, None, (4, 3), "real")


def test_identify_reports_the_real_law_for_real_modes_of_several_inputs() -> None:
    # two inputs: the real model's modes are judged against the real rank-one law,
    # the complex model's against the complex one (not the parameter count's chi2)
    f_n = np.array([30.0, 55.0])
    p = -0.02 * 2 * np.pi * f_n + 2j * np.pi * f_n
    rng = np.random.default_rng(3)
    psi = rng.normal(size=(5, 2)) + 0.2j * rng.normal(size=(5, 2))
    lin = rng.normal(size=(2, 2))
    frf = ModalModel(p, psi, lin).frf(np.arange(10.0, 80.0, 0.1), "receptance")
    h = frf.H
    noise = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    res = identify_modes(frf.with_H(h + 1e-3 * np.abs(h).mean() * noise), model="both")
    n_f = res.frequency.size
    for kind in ("complex", "real"):
        k = mode_parameters(5, 2, kind)
        want = mode_threshold(k, n_f, 0.01, None, (5, 2), kind)
        assert want > mode_threshold(k, n_f, 0.01)
        tests = [m["test"] for m in res.models[kind].to_dict()["modes"]]
        assert tests
        assert all(np.isclose(t["base_threshold"], want, rtol=1e-9) for t in tests)
