"""Standard errors of frequency and damping ratio under noise correlated across outputs
(modal.sandwich): the closed form without common noise, the rank-two bookkeeping
against a dense covariance, and the scatter over Monte Carlo draws with noise on
force and responses."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel
from tyredamp.modal.fit._scaling import pole_std
from tyredamp.modal.fit.fit import FitResult, ModalFitter
from tyredamp.modal.fit.ml import line_weights_full, ml_refine
from tyredamp.modal.problem.problem import build_problem
from tyredamp.modal.sandwich import _jacobians, _row_weights, sandwich_covariance

F = np.linspace(8.0, 16.0, 161)
FN = np.array([10.0, 13.0])
ZETA = np.array([0.01, 0.015])
W = 2 * np.pi * FN
POLES = -ZETA * W + 1j * W * np.sqrt(1 - ZETA**2)
PI = np.array([[1.0, 0.8]], complex)
_rng = np.random.default_rng(5)
PO = _rng.normal(size=(4, 2)) + 0.2j * _rng.normal(size=(4, 2))
H0 = ModalModel(POLES, PO, PI).frf(F, "receptance").H
#: the responses' own noise (flat, 0.3 % of the RMS response) and the force's relative
#: noise (2 %): the force's part of the variance dominates near the resonances
D = (0.003 * np.sqrt(np.mean(np.abs(H0) ** 2))) ** 2 * np.ones(H0.shape)
R = np.full((1, F.size), 0.02**2)
V = D + R[None] * np.abs(H0) ** 2


def _draw(rng: np.random.Generator) -> np.ndarray:
    """H1-like data: the responses' noise plus the force's, ``H0 n`` with one ``n`` per line."""
    e = np.sqrt(D / 2) * (rng.normal(size=H0.shape) + 1j * rng.normal(size=H0.shape))
    n = np.sqrt(R / 2) * (rng.normal(size=R.shape) + 1j * rng.normal(size=R.shape))
    return H0 + e + H0 * n[None]


def _ml(
    h: np.ndarray, kind: Literal["complex", "real"] = "complex"
) -> tuple[ModalFitter, FitResult]:
    fit = ModalFitter(F, h, 0, kind, [], upper=True, lower=True)
    return fit, ml_refine(fit, fit.fit(POLES, PI.T.copy()), V)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_without_common_noise_the_sandwich_is_the_information(
    kind: Literal["complex", "real"],
) -> None:
    """``r = 0`` and the weights ``1 / sqrt(V / 2)``: ``B = A`` (module docstring, eq. 3),
    so the sandwich is ``A^-1`` (rounding: rtol 1e-8), and ``A^-1`` gives the ML
    stage's own Fisher errors (known variance; the same J^T J: rtol 1e-6)."""
    fit, ml = _ml(_draw(np.random.default_rng(1)), kind)
    ainv, cov, th = sandwich_covariance(fit, ml, None, V, np.zeros_like(R))
    f0, z0, _ = pole_std(fit.w_ref, th, 2, ainv)
    f1, z1, _ = pole_std(fit.w_ref, th, 2, cov)
    assert_allclose(f1, f0, rtol=1e-8)
    assert_allclose(z1, z0, rtol=1e-8)
    assert_allclose(f0, ml.std_frequency_hz, rtol=1e-6)
    assert_allclose(z0, ml.std_damping_ratio, rtol=1e-6)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_rank_two_updates_equal_the_dense_covariance(kind: Literal["complex", "real"]) -> None:
    """``B`` of eq. (3) equals ``J^T W Sigma W J`` with ``Sigma_f = D_f + r_f h_f h_f^H``
    (``D_f = diag(V_f - min(r_f |h_f|^2, V_f))``) assembled as a dense real
    covariance of the (Re, Im) rows of every output at each line (``Cov(Re, Re) =
    Cov(Im, Im) = Re Sigma / 2``, ``Cov(Im, Re) = Im Sigma / 2``). Rounding of sums
    of 161 lines: rtol 1e-8."""
    fit, ml = _ml(_draw(np.random.default_rng(2)), kind)
    ainv, cov, _ = sandwich_covariance(fit, ml, None, V, R)
    th, blocks = _jacobians(fit, ml, lambda sl: _row_weights(V, sl))
    jac = np.stack(list(next(blocks)[1]))  # (n_out, rows, n_par): one block here
    om = line_weights_full(V)[0::2].T  # (n_out, n_f): the weight of each entry
    h = ml.model[:, 0, :]
    b = np.zeros((th.size, th.size))
    for f in range(F.size):
        common = R[0, f] * np.abs(h[:, f]) ** 2
        sig = np.diag(V[:, 0, f] - np.minimum(common, V[:, 0, f]))  # D_f >= 0
        sig = sig + R[0, f] * np.outer(h[:, f], h[:, f].conj())
        sw = om[:, f, None] * sig * om[None, :, f]
        real = np.block([[sw.real, -sw.imag], [sw.imag, sw.real]]) / 2  # (Re, Im) rows
        g = np.concatenate([jac[:, 2 * f, :], jac[:, 2 * f + 1, :]])  # (2 n_out, n_par)
        b += g.T @ real @ g
    assert_allclose(cov, ainv @ b @ ainv, rtol=1e-8, atol=1e-12 * np.abs(cov).max())


def test_sandwich_errors_match_the_scatter_with_noise_on_force_and_responses() -> None:
    """Over 200 draws, the standard deviation of f and zeta of both modes, of the
    maximum-likelihood fit and of the weighted least-squares fit with the separable
    weights of the pipeline, is the sandwich's standard error to 10 % (the standard
    deviation of 200 draws scatters by 5 %; measured 1-5 %, and 1-4 % over 1000
    draws), while the plain Fisher error is about half of it (the test can fail)."""
    fs, ws = [], []
    for seed in range(200):
        h = _draw(np.random.default_rng(100 + seed))
        fit, ml = _ml(h)
        pr = build_problem(FRF(F, h, variance=V), (8.0, 16.0))
        wf = ModalFitter(pr.frequency, pr.H, 0, "complex", [], line_weights=pr.line_weights)
        wls = wf.fit(POLES, PI.T.copy(), sigma=pr.sigma_out, passes=1)
        fs.append(np.concatenate([np.abs(ml.poles), -ml.poles.real / np.abs(ml.poles)]))
        ws.append(np.concatenate([np.abs(wls.poles), -wls.poles.real / np.abs(wls.poles)]))
        if seed == 0:
            _, cov, th = sandwich_covariance(fit, ml, None, V, R)
            f_ml, z_ml, _ = pole_std(fit.w_ref, th, 2, cov)
            fisher = np.concatenate([ml.std_frequency_hz, ml.std_damping_ratio])
            _, cw, tw = sandwich_covariance(wf, wls, wf.weights(pr.sigma_out), pr.variance, R)
            f_w, z_w, _ = pole_std(wf.w_ref, tw, 2, cw)
    scatter_ml = np.std(fs, axis=0) * np.array([1 / (2 * np.pi)] * 2 + [1.0] * 2)
    scatter_w = np.std(ws, axis=0) * np.array([1 / (2 * np.pi)] * 2 + [1.0] * 2)
    assert_allclose(np.concatenate([f_ml, z_ml]), scatter_ml, rtol=0.10)
    assert_allclose(np.concatenate([f_w, z_w]), scatter_w, rtol=0.10)
    assert np.all(fisher < 0.7 * scatter_ml)


@pytest.mark.parametrize("seed", [3])
def test_pipeline_scales_the_pole_errors_by_the_sandwich(seed: int) -> None:
    """``identify_modes`` on an FRF that carries its input noise reports the sandwich's
    factors (``meta["pole_variance_ratio"]``, about 4 here: the Fisher errors are half
    the scatter) and its standard errors of f and zeta are the fit's times their
    square roots; without ``input_noise`` the factors are those of the noise along
    the response, the same for both."""
    from tyredamp.modal import identify_modes

    h = _draw(np.random.default_rng(seed))
    with_r = identify_modes(FRF(F, h, variance=V, input_noise=R), model="complex", n_modes=2)
    plain = identify_modes(FRF(F, h, variance=V), model="complex", n_modes=2)
    m1, m0 = with_r.models["complex"], plain.models["complex"]
    ratio = np.asarray(m1.meta["pole_variance_ratio"])
    assert ratio.shape == (2, 2)
    assert np.all((ratio > 2.0) & (ratio < 8.0))
    assert_allclose(m1.frequency_hz, m0.frequency_hz, rtol=1e-12)  # the estimate is the same
    along = np.asarray(m0.meta["noise_along_response"])
    assert_allclose(np.asarray(m0.meta["pole_variance_ratio"]), np.stack([along, along], 1))


def test_blocks_of_lines_give_the_same_covariance(monkeypatch: pytest.MonkeyPatch) -> None:
    """The Gram matrices and the updates summed block by block (lines of large
    problems) give the covariance of one block: rounding, rtol 1e-9."""
    from tyredamp.modal.fit import _basis

    fit, ml = _ml(_draw(np.random.default_rng(4)))
    one = sandwich_covariance(fit, ml, None, V, R)[1]
    monkeypatch.setattr(_basis, "BLOCK_BYTES", 1)
    monkeypatch.setattr(_basis, "MIN_BLOCK_LINES", 40)
    assert len(_basis.blocks(fit, 10)) == 5
    assert_allclose(sandwich_covariance(fit, ml, None, V, R)[1], one, rtol=1e-9)
