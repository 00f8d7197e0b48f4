"""Maximum-likelihood refinement with the per-line variance (modal.fit.ml) against an
independent full least-squares fit, its Fisher standard errors, and the choice
of weights (modal.final.full_weights)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import least_squares

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.final import full_weights
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.fit.ml import fisher_scale, line_weights_full, ml_refine
from tyredamp.modal.problem.problem import build_problem, line_factor_dof

F = np.linspace(5.0, 50.0, 400)
FN = np.array([15.0, 16.0, 30.0])
ZETA = np.array([0.02, 0.015, 0.01])
W = 2 * np.pi * FN
POLES = -ZETA * W + 1j * W * np.sqrt(1 - ZETA**2)
N_OUT, N_IN = 3, 2


def _data(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Two-input data with a strongly non-separable variance (noise that grows with |H|)."""
    rng = np.random.default_rng(seed)
    po = rng.normal(size=(N_OUT, 3)) + 1j * rng.normal(size=(N_OUT, 3))
    pi = rng.normal(size=(N_IN, 3)) + 0.3j * rng.normal(size=(N_IN, 3))
    h0 = ModalModel(POLES, po, pi).frf(F, "receptance").H
    sd = 0.02 * np.sqrt(np.mean(np.abs(h0) ** 2)) * (0.2 + np.abs(h0) / np.abs(h0).max())
    h = h0 + sd * (rng.normal(size=h0.shape) + 1j * rng.normal(size=h0.shape)) / np.sqrt(2)
    return h, sd**2, pi, h0


def _independent_fit(h: np.ndarray, v: np.ndarray, start: object) -> least_squares:
    """All parameters (poles, rank-one residues u l^T with l_ref = 1, residual terms)
    by scipy's least_squares on the full residual (H - model) / sqrt(V / 2)."""
    s = 2j * np.pi * F
    ref = np.argmax(np.abs(start.psi_in.T), axis=1)  # type: ignore[attr-defined]
    other = 1 - ref

    def model(x: np.ndarray) -> np.ndarray:
        p = -np.exp(x[0:3]) + 1j * x[3:6]
        u = (x[6:15] + 1j * x[15:24]).reshape(3, N_OUT)
        lv = np.ones((3, N_IN), complex)
        lv[np.arange(3), other] = x[24:27] + 1j * x[27:30]
        r = u[:, :, None] * lv[:, None, :]
        hm = np.zeros_like(h)
        for n in range(3):
            hm += r[n][:, :, None] / (s - p[n]) + np.conj(r[n])[:, :, None] / (s - np.conj(p[n]))
        return (
            hm
            + x[30:36].reshape(N_OUT, N_IN)[:, :, None]
            + x[36:42].reshape(N_OUT, N_IN)[:, :, None] / s**2
        )

    def resid(x: np.ndarray) -> np.ndarray:
        e = (h - model(x)) / np.sqrt(v / 2)
        return np.concatenate([e.real.ravel(), e.imag.ravel()])

    pin = start.psi_in.T  # type: ignore[attr-defined]
    lref = pin[np.arange(3), ref]
    u0 = (start.psi_out * lref[None, :]).T  # type: ignore[attr-defined]
    l0 = (pin / lref[:, None])[np.arange(3), other]
    p0 = start.poles  # type: ignore[attr-defined]
    x0 = np.concatenate(
        [
            np.log(-p0.real),
            p0.imag,
            u0.real.ravel(),
            u0.imag.ravel(),
            l0.real,
            l0.imag,
            start.upper.ravel(),  # type: ignore[attr-defined]
            start.lower.ravel(),  # type: ignore[attr-defined]
        ]
    )
    return least_squares(resid, x0, xtol=1e-14, ftol=1e-14, gtol=1e-14, x_scale="jac")


def test_ml_refine_matches_a_full_least_squares_fit_and_its_fisher_errors() -> None:
    h, v, pi, _ = _data(0)
    fit = ModalFitter(F, h, 0, "complex", [], upper=True, lower=True)
    wls = fit.fit(POLES, pi.T.copy())
    ml = ml_refine(fit, wls, v, tol=1e-10)
    ls = _independent_fit(h, v, wls)
    # the same optimum: cost to 1e-8 relative, poles to 1e-6 (measured 1e-9, 1e-8)
    assert ml.cost == pytest.approx(float(np.sum(ls.fun**2)), rel=1e-8)
    p_ls = -np.exp(ls.x[0:3]) + 1j * ls.x[3:6]
    assert_allclose(ml.poles, p_ls, rtol=1e-6)
    # the WLS start is measurably elsewhere (it ignores the variance)
    assert np.max(np.abs(wls.poles - p_ls) / np.abs(p_ls)) > 1e-6
    # Fisher standard errors of f and zeta: the inverse of the full J^T J (all
    # parameters) gives the same marginal variances (Schur complement), measured 1e-7
    cov = np.linalg.inv(ls.jac.T @ ls.jac)
    sig, om = np.exp(ls.x[0:3]), ls.x[3:6]
    mag = np.hypot(sig, om)
    for n in range(3):
        gf = np.zeros(ls.x.size)
        gf[n], gf[3 + n] = sig[n] ** 2 / mag[n] / (2 * np.pi), om[n] / mag[n] / (2 * np.pi)
        gz = np.zeros(ls.x.size)
        gz[n], gz[3 + n] = om[n] ** 2 * sig[n] / mag[n] ** 3, -sig[n] * om[n] / mag[n] ** 3
        assert ml.std_frequency_hz[n] == pytest.approx(np.sqrt(gf @ cov @ gf), rel=1e-4)
        assert ml.std_damping_ratio[n] == pytest.approx(np.sqrt(gz @ cov @ gz), rel=1e-4)
    # the model it returns is that of the optimum (unweighted, the data's kind)
    e_ls = ls.fun[: h.size].reshape(h.shape) + 1j * ls.fun[h.size :].reshape(h.shape)
    e_ml = (h - ml.model) / np.sqrt(v / 2)
    assert np.max(np.abs(e_ml - e_ls)) < 1e-4 * np.max(np.abs(e_ls))
    assert ml.status == "maximum likelihood"


def test_ml_errors_cover_the_scatter() -> None:
    """Over 60 noise draws the ML frequencies scatter as their Fisher errors say
    (z-scores of RMS 1; 60 draws x 3 modes: standard error of the RMS ~ 0.05)."""
    z = []
    for seed in range(60):
        h, v, pi, _ = _data(100 + seed)
        fit = ModalFitter(F, h, 0, "complex", [], upper=True, lower=True)
        ml = ml_refine(fit, fit.fit(POLES, pi.T.copy()), v)
        z.append((np.abs(ml.poles) - np.abs(POLES)) / (2 * np.pi) / ml.std_frequency_hz)
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.85 < rms < 1.15


def test_identify_uses_the_full_variance_when_known() -> None:
    h, v, _, _ = _data(1)
    frf = FRF(F, h, kind="receptance")
    res = identify_modes(frf, model="complex", variance=v)
    m = res.models["complex"]
    assert m.meta["refinement"] == "maximum likelihood"
    assert_allclose(m.frequency_hz, FN, rtol=1e-3)
    assert m.quality.passed  # chi-square of the ML cost against its dof
    # the same data without their variance: the noise estimated from the residual is
    # one level per output, below the noise of the strong lines (it varies 35-fold
    # along the axis), so the fit leaves structure, and the identification is
    # repeated against that level plus a noise proportional to the response
    # (modal.problem.model_error): a per-line variance, so the ML stage runs on it, and the
    # verdict names it; the modes stay those of the known variance
    r0 = identify_modes(frf, model="complex")
    m0 = r0.models["complex"]
    assert r0.model_error > 0
    assert m0.meta["refinement"] == "maximum likelihood"
    assert "model error" in m0.quality.verdict
    assert_allclose(m0.frequency_hz, FN, rtol=1e-3)


def test_full_weights_choice_and_helpers() -> None:
    h, v, _, _ = _data(2)
    frf = FRF(F, h, kind="receptance")
    assert full_weights(build_problem(frf, variance=v))  # known variance: always
    assert fisher_scale(None, 10.0, 5) == 1.0
    assert fisher_scale(10.0, 10.0, 5) == pytest.approx(10.0 / 6.0)
    assert fisher_scale(4.0, 10.0, 5) == pytest.approx(2.0)
    om = line_weights_full(np.ones((2, 1, 3)))
    assert om is not None
    assert om.shape == (6, 2)
    assert_allclose(om, np.sqrt(2.0))
    assert line_weights_full(np.zeros((2, 1, 3))) is None
    # the adjacent-line count of a factor estimated with nu dof (4000 lines: ~3 %)
    rng = np.random.default_rng(0)
    g = rng.chisquare(24, 4000) / 24
    assert line_factor_dof(1 / np.sqrt(g)) == pytest.approx(24.0, rel=0.15)


@pytest.mark.parametrize("scale", [1.0, 1e-9])
def test_projection_matches_least_squares(scale: float) -> None:
    # _projection on a well-conditioned basis (the Gram route) and on one whose last
    # column nearly repeats the first (condition ~1e9, beyond the Gram limit: the QR
    # route): fitted values as lstsq's, and Q^T of an orthonormal basis Q of the
    # range: R = Q^T pw has R^T R = pw^T pw and R^T Q^T X = pw^T X
    from tyredamp.modal.fit.ml import _projection

    rng = np.random.default_rng(3)
    pw = rng.normal(size=(400, 6))
    if scale < 1:
        pw[:, 5] = pw[:, 0] + scale * pw[:, 5]
    yw = rng.normal(size=400)
    X = rng.normal(size=(400, 3))
    c, qt = _projection(pw, yw)
    ref = np.linalg.lstsq(pw, yw, rcond=None)[0]
    # fitted values: the least-squares error of either route is ~eps times the
    # condition (1e-9 relative of the data's norm is far above it for both)
    assert_allclose(pw @ c, pw @ ref, atol=1e-9 * np.linalg.norm(yw))
    R = qt(pw)
    g = pw.T @ pw
    # identities of an orthonormal Q: relative to the largest Gram entry, eps-sized
    assert_allclose(R.T @ R, g, atol=1e-12 * np.abs(g).max())
    assert_allclose(R.T @ qt(X), pw.T @ X, atol=1e-12 * np.abs(pw.T @ X).max() * 10)


def test_evaluate_gram_route_matches_the_qr_route(monkeypatch: pytest.MonkeyPatch) -> None:
    # _evaluate's J^T J, J^T r, cost and coefficients from the Gram matrix of each
    # output's weighted [Phi | E] (Schur complement) against the Householder-QR route
    # (taken when the Gram route is refused) and against J formed explicitly by
    # central differences of the projected residual
    from tyredamp.modal.fit import ml

    h, v, pi, _ = _data(2)
    fit = ModalFitter(F, h, 0, "complex", [], upper=True, lower=True)
    wls = fit.fit(POLES, pi.T.copy())
    om = line_weights_full(v)
    assert om is not None
    part = np.asarray(wls.participation, complex)
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    th = fit.pack(wls.poles, part, ref)
    cost, jtj, jtr, sol = ml._evaluate(fit, th, 3, ref, om)
    monkeypatch.setattr(ml, "_gram_chol", lambda g: None)
    cost_q, jtj_q, jtr_q, sol_q = ml._evaluate(fit, th, 3, ref, om)
    monkeypatch.undo()
    # the two routes: eps times the basis condition (~1e4 here) relative to the largest entry
    assert cost == pytest.approx(cost_q, rel=1e-10)
    assert_allclose(jtj, jtj_q, rtol=0, atol=1e-9 * np.abs(jtj).max())
    assert_allclose(jtr, jtr_q, rtol=0, atol=1e-9 * np.abs(jtr).max())
    assert_allclose(sol["C"], sol_q["C"], rtol=0, atol=1e-9 * np.abs(sol["C"]).max())

    def proj_res(x: np.ndarray) -> np.ndarray:
        # the variable-projection residual of every output at x (unit-free, weighted)
        B, _ = fit._basis_ek(x, 3, ref, False)
        out = []
        for j in range(N_OUT):
            pw, yw = B * om[:, j : j + 1], fit.Y[:, j] * om[:, j]
            out.append(yw - pw @ np.linalg.lstsq(pw, yw, rcond=None)[0])
        return np.concatenate(out)

    r0 = proj_res(th)
    J = np.empty((r0.size, th.size))
    for i in range(th.size):
        dx = np.zeros(th.size)
        dx[i] = 1e-6 * max(1.0, abs(th[i]))
        J[:, i] = (proj_res(th + dx) - proj_res(th - dx)) / (2 * dx[i])
    assert cost == pytest.approx(float(r0 @ r0), rel=1e-10)  # the same residual
    # J^T r (J = d r / d theta) is exact for the projected residual (Kaufman's J
    # differs from the exact Jacobian by a term orthogonal to r); central
    # differences ~1e-7 relative
    assert_allclose(jtr, J.T @ r0, rtol=0, atol=1e-5 * np.abs(jtr).max())
