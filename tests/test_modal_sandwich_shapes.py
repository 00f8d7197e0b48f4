"""Standard errors of the mode shapes under noise correlated across outputs
(modal.sandwich.sandwich_shapes): the closed form without common noise (the delta
method of modal.fit._scaling), the second moments against a dense covariance, and the
scatter over Monte Carlo draws with noise on force and responses."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.frf import FRF
from tyredamp.modal.fit import _scaling
from tyredamp.modal.fit.fit import FitResult, ModalFitter
from tyredamp.modal.fit.ml import line_weights_full, ml_refine
from tyredamp.modal.sandwich import (
    _outputs,
    _project,
    _row_weights,
    sandwich_covariance,
    sandwich_shapes,
)

from .test_modal_sandwich_std import H0, PI, POLES, D, F, R, V, _draw

DRIVE = [(0, 0)]


def _wls(
    kind: Literal["complex", "real"], drive: list[tuple[int, int]]
) -> tuple[ModalFitter, FitResult, np.ndarray]:
    fit = ModalFitter(F, _draw(np.random.default_rng(1)), 0, kind, drive, upper=True, lower=True)
    res = fit.fit(POLES, PI.T.copy())
    return fit, res, fit.weights(res.sigma_out)


@pytest.mark.parametrize("drive", [[], DRIVE])
@pytest.mark.parametrize("kind", ["complex", "real"])
def test_without_common_noise_the_shapes_errors_are_the_delta_method(
    kind: Literal["complex", "real"], drive: list[tuple[int, int]]
) -> None:
    """``r = 0`` and a variance the weights whiten (``V = 2 / w^2``: ``W Sigma W = I``):
    the sandwich's errors of ``psi_out`` and ``psi_in`` are the delta method of
    ``_scaling.shape_std`` / ``input_shape_std`` with ``Cov(theta) = A^-1`` and ``s^2 =
    1`` (the same quantities summed another way: rounding, rtol 1e-9)."""
    fit, res, w = _wls(kind, drive)
    vs = np.broadcast_to((2.0 / w**2)[:, None, None], V.shape).copy()
    ainv, _, th = sandwich_covariance(fit, res, w, vs, np.zeros_like(R))
    m = POLES.size
    ref = np.argmax(np.abs(res.participation), axis=1).astype(np.intp)
    sol = fit._solve(th, m, ref, w)
    didx = np.array([j for j, _ in drive], dtype=np.intp)
    b = _scaling.scale(fit, th, m, ref, sol["C"][:, didx].T, w[didx])[0]
    c = sol["C"] / w[None, :]
    u = c[0 : 2 * m : 2].T + 1j * c[1 : 2 * m : 2].T if kind == "complex" else c[:m].T + 0j
    out0 = _scaling.shape_std(fit, th, m, ref, w, sol, ainv, 1.0, b, u, didx)
    in0 = _scaling.input_shape_std(fit, th, m, ref, w, sol, ainv, 1.0, b, didx)
    cov, out1, in1, _ = sandwich_shapes(fit, res, w, vs, np.zeros_like(R))
    assert_allclose(cov, ainv, rtol=1e-9, atol=1e-12 * np.abs(ainv).max())
    assert_allclose(out1, out0, rtol=1e-9)
    assert_allclose(in1, in0, rtol=1e-9, atol=1e-12 * in0.max())


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_shape_errors_equal_the_dense_covariance(kind: Literal["complex", "real"]) -> None:
    """Each ``psi_out`` entry's error as a linear map of all outputs' whitened noise,
    formed densely (``d theta = A^-1 J^T W e``, ``d C_j = K_j W_j e_j + M_j d theta``,
    ``d b = beta^T [d theta, d C_D]``, ``d psi = b d u + u d b``), against the dense
    covariance ``Sigma_f = D_f + r_f h_f h_f^H`` of the (Re, Im) rows of every output
    at each line: the second moments of ``sandwich_shapes`` summed by rows, eq. (2)
    and (3) (rounding of sums of 161 lines: rtol 1e-8)."""
    fit = ModalFitter(F, _draw(np.random.default_rng(2)), 0, kind, DRIVE, upper=True, lower=True)
    ml = ml_refine(fit, fit.fit(POLES, PI.T.copy()), V)
    _, std, _, _ = sandwich_shapes(fit, ml, None, V, R)

    def rows(sl: slice) -> np.ndarray:
        return _row_weights(V, sl)

    pr = _project(fit, ml, rows)
    m, q, n_out = POLES.size, pr.q, fit.n_out
    outs = list(_outputs(fit, pr, rows, pr.parts[0], True))  # one block here
    n_rows = outs[0][0].shape[0]
    jac = np.concatenate([o[0] for o in outs])  # (n_out rows, n_par)
    lth = np.linalg.pinv(jac.T @ jac) @ jac.T  # d theta per unit of W e
    dc = []
    for j, (_, x) in enumerate(outs):
        own = np.zeros((q, n_out * n_rows))
        own[:, j * n_rows : (j + 1) * n_rows] = x.T
        dc.append(own - pr.sol[j][:, 1:] @ pr.s[j].T @ lth)  # K_j + M_j d theta
    c = np.column_stack([s[:, 0] for s in pr.sol])
    b = fit._scale(pr.th, m, pr.ref, c[:, [0]].T, np.ones(1))[0]
    beta = fit._scale_jacobian(pr.th, m, pr.ref, c[:, [0]].T, np.ones(1))
    db = beta.T @ np.concatenate([lth, dc[0]])  # (m, N)
    om = line_weights_full(V)[0::2].T
    h = ml.model[:, 0, :]
    for j in range(n_out):
        for n in range(m):
            if kind == "complex":
                du = dc[j][2 * n] + 1j * dc[j][2 * n + 1]
                u = c[2 * n, j] + 1j * c[2 * n + 1, j]
            else:
                du, u = dc[j][n] + 0j, c[n, j] + 0j
            lin = (b[n] * du + u * db[n]).reshape(n_out, n_rows)
            var = 0.0
            for f in range(F.size):
                common = R[0, f] * np.abs(h[:, f]) ** 2
                sig = np.diag(V[:, 0, f] - np.minimum(common, V[:, 0, f]))
                sig = sig + R[0, f] * np.outer(h[:, f], h[:, f].conj())
                sw = om[:, f, None] * sig * om[None, :, f]
                real = np.block([[sw.real, -sw.imag], [sw.imag, sw.real]]) / 2
                g = np.concatenate([lin[:, 2 * f], lin[:, 2 * f + 1]])
                var += float(g.real @ real @ g.real + g.imag @ real @ g.imag)
            assert_allclose(std[j, n], np.sqrt(var), rtol=1e-8)


def test_shape_errors_match_the_scatter_with_noise_on_force_and_responses() -> None:
    """Over 200 draws (noise on force and responses, a drive point), the rms scatter of
    every ``psi_out`` and ``psi_in`` entry of the maximum-likelihood fit is the
    sandwich's standard error (at the fit of the exact FRF) to 10 % (the rms of 200
    draws scatters by 5 %; measured 2-10 %, 1-4 % over 1000 draws), while the errors
    without the common part miss it by more than 20 % for some entry (the test can
    fail). The shape's amplitude along itself (eq. (S3)) scatters ``kappa`` times its
    variance with the entries taken independent: to 25 % (a variance of 200 draws
    scatters by 10 %; measured 4-12 % over 400), ``kappa`` about 2 here. The pipeline
    (``identify_modes`` on an FRF carrying its input noise) reports the sandwich's
    errors times ``sqrt(kappa)``: within 15 % of the scatter so scaled (its own fit
    and residual terms, the local dispersion)."""
    from tyredamp.modal import identify_modes

    po, pi = [], []
    for seed in range(200):
        h = _draw(np.random.default_rng(100 + seed))
        fit = ModalFitter(F, h, 0, "complex", DRIVE, upper=True, lower=True)
        ml = ml_refine(fit, fit.fit(POLES, PI.T.copy()), V)
        po.append(ml.psi_out)
        pi.append(ml.psi_in)
    fit = ModalFitter(F, H0, 0, "complex", DRIVE, upper=True, lower=True)
    ml = ml_refine(fit, fit.fit(POLES, PI.T.copy()), V)
    _, s_out, s_in, kappa = sandwich_shapes(fit, ml, None, V, R)
    _, s0_out, _, _ = sandwich_shapes(fit, ml, None, V, np.zeros_like(R))
    err = np.asarray(po) - np.mean(po, axis=0)
    sc_out = np.sqrt(np.mean(np.abs(err) ** 2, axis=0))
    sc_in = np.sqrt(np.mean(np.abs(pi - np.mean(pi, axis=0)) ** 2, axis=0))
    assert_allclose(s_out, sc_out, rtol=0.10)
    assert_allclose(s_in, sc_in, rtol=0.10)
    assert np.max(np.abs(s0_out / sc_out - 1.0)) > 0.2
    info = np.sum(np.abs(ml.psi_out) ** 2 / s_out**2, axis=0)  # 1 / Var_ind(a_n)
    amp = np.einsum("jn,sjn->sn", np.conj(ml.psi_out) / s_out**2 / info, err)
    assert_allclose(kappa, np.mean(np.abs(amp) ** 2, axis=0) * info, rtol=0.25)
    assert np.all(kappa > 1.3)
    h = _draw(np.random.default_rng(100))
    frf = FRF(F, h, variance=V, input_noise=R, outputs=[1, 2, 3, 4], inputs=[1])
    mdl = identify_modes(frf, model="complex", n_modes=2).models["complex"]
    assert mdl.meta["pole_variance_ratio"] is not None
    assert_allclose(np.asarray(mdl.std["psi_out"]), sc_out * np.sqrt(kappa), rtol=0.15)


def test_without_input_noise_the_shapes_keep_the_noise_along_the_response() -> None:
    """An FRF without ``input_noise``: no sandwich (``pole_variance_ratio`` is the noise
    along the response, which then inflates the shapes' errors too); with it the
    estimate is the same and only the shapes' errors move."""
    from tyredamp.modal import identify_modes

    h = _draw(np.random.default_rng(3))
    frf = FRF(F, h, variance=D + R[None] * np.abs(H0) ** 2, outputs=[1, 2, 3, 4], inputs=[1])
    with_r = FRF(F, h, variance=frf.variance, input_noise=R, outputs=[1, 2, 3, 4], inputs=[1])
    m0 = identify_modes(frf, model="complex", n_modes=2).models["complex"]
    m1 = identify_modes(with_r, model="complex", n_modes=2).models["complex"]
    along = np.asarray(m0.meta["noise_along_response"])
    assert_allclose(np.asarray(m0.meta["pole_variance_ratio"]), np.stack([along, along], 1))
    assert_allclose(m1.psi_out, m0.psi_out, rtol=1e-12)  # the estimate is the same
    s0, s1 = np.asarray(m0.std["psi_out"]), np.asarray(m1.std["psi_out"])
    assert not np.allclose(s0, s1, rtol=0.05)  # only the errors moved
