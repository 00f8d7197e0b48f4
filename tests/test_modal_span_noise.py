"""Noise along the response (modal.search.span_noise) and the mode threshold it raises
(stats.span_threshold, search.local_thresholds)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import stats as sps

from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.search.search import ModeTest, local_thresholds
from tyredamp.modal.search.span_noise import WINDOW, span_noise
from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold, span_threshold

from .helpers import chain_system

F = np.linspace(0.5, 40.0, 1200)
INPUTS = [0, 5]


def _data(common: float, seed: int, white: float = 1e-3) -> tuple[np.ndarray, np.ndarray, Any]:
    """Accelerances of the chain with white noise of RMS ``white`` times the mean |H|
    per entry, plus ``common`` times an H1 input-noise error ``H(f) M(f)`` (``M``
    complex Gaussian n_in x n_in per line, common to all outputs)."""
    sys_ = chain_system()
    rng = np.random.default_rng(seed)
    h0 = sys_.frf(F, kind="accelerance", inputs=INPUTS).H
    sd = white * np.abs(h0).mean()
    e = sd * (rng.normal(size=h0.shape) + 1j * rng.normal(size=h0.shape)) / np.sqrt(2)
    m = (rng.normal(size=(2, 2, F.size)) + 1j * rng.normal(size=(2, 2, F.size))) / np.sqrt(2)
    e = e + common * np.einsum("jif,ikf->jkf", h0, m)
    return h0, h0 + e, sys_


def _fit(h: np.ndarray, sys_: Any) -> tuple[ModalFitter, Any]:
    cm = sys_.complex_modes()
    fit = ModalFitter(F, h, 2, "complex", [])
    return fit, fit.fit(cm.poles, cm.psi[INPUTS].T, refine=False)


def _span(fit: ModalFitter, res: Any) -> Any:
    r = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    s2 = res.sigma_out**2
    return span_noise(fit, res.poles, r, (res.upper, res.lower), s2)


def test_white_noise_lies_evenly_in_and_off_the_span_of_the_response() -> None:
    # independent noise of the fit's variance: 1 per complex direction in and off the
    # span (a statistical check: the lines' sums have 2 n n_in^2 dof in the span)
    _, h, sys_ = _data(0.0, 1)
    fit, res = _fit(h, sys_)
    sp = _span(fit, res)
    n = F.size
    lam_in = float(sp.cin[-1] / n)
    lam_out = float(sp.cout[-1] / n)
    assert abs(lam_in - 1.0) < 4.0 * np.sqrt(1.0 / (n * 4)) + 0.05
    assert abs(lam_out - 1.0) < 0.05
    # and the threshold is not raised anywhere (nor lowered)
    n_out = h.shape[0]
    k = mode_parameters(n_out, 2, "complex")
    thr = mode_threshold(k, F.size)
    poles = res.poles
    got = local_thresholds(fit, sp, poles, thr, ModeTest(k, F.size))
    assert_allclose(got, thr)


def test_white_noise_as_large_as_the_response_is_not_taken_for_noise_along_it() -> None:
    # at lines where the noise is as large as the response (weak modes at 20 dB,
    # antiresonances) the span of the noisy data's own columns holds much of the
    # noise itself: projected on it, white noise looks concentrated along the
    # response (lambda_in well above 1) and raised the thresholds of weak true modes.
    # The span is taken from the fitted model, not from the noisy data: 1 within
    # its scatter, and no threshold raised
    _, h, sys_ = _data(0.0, 4, white=0.3)
    fit, res = _fit(h, sys_)
    sp = _span(fit, res)
    n = F.size
    lam_in = float(sp.cin[-1] / n)
    assert abs(lam_in - 1.0) < 4.0 * np.sqrt(1.0 / (n * 4)) + 0.05
    # the same residual projected on the noisy data's columns: biased (the old rule)
    isd = 1.0 / res.sigma_out
    u = h * isd[:, None, None]
    r = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    e = _residual(fit, res, r)
    q = np.linalg.qr(u.transpose(2, 0, 1))[0]
    p = np.conj(q).transpose(0, 2, 1) @ (e * isd[:, None, None]).transpose(2, 0, 1)
    lam_data = float(np.sum(np.abs(p) ** 2) / (2 * 4 * n))
    assert lam_data > 1.3
    k = mode_parameters(h.shape[0], 2, "complex")
    thr = mode_threshold(k, F.size)
    got = local_thresholds(fit, sp, res.poles, thr, ModeTest(k, F.size))
    assert np.count_nonzero(got > thr) <= 1  # 5 % one-sided per pole, 6 poles


def _residual(fit: ModalFitter, res: Any, r: np.ndarray) -> np.ndarray:
    from tyredamp.modal.fit import _basis

    blocks = _basis.residual_blocks(fit, res.poles, r, (res.upper, res.lower))
    return np.concatenate([blk for _, blk in blocks], axis=2)


def test_span_noise_against_the_projector_of_the_modal_sum() -> None:
    # independent computation: the residual from the modal sum, the projector
    # U (U^H U)^-1 U^H of the whitened model's columns per line, windows by hand
    _, h, sys_ = _data(3e-3, 2)
    fit, res = _fit(h, sys_)
    sp = _span(fit, res)
    R = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    s = 2j * np.pi * F
    model = res.upper[:, :, None] * s**2 + res.lower[:, :, None]
    for n, p in enumerate(res.poles):
        r = R[:, :, n, None]
        model = model + r * s**2 / (s - p) + np.conj(r) * s**2 / (s - np.conj(p))
    isd = 1.0 / res.sigma_out
    e = (h - model) * isd[:, None, None]
    u = model * isd[:, None, None]
    n_out = h.shape[0]
    a = np.empty(F.size)
    b = np.empty(F.size)
    for i in range(F.size):
        ui = u[:, :, i]
        proj = ui @ np.linalg.solve(ui.conj().T @ ui, ui.conj().T)
        ein = np.sum(np.abs(proj @ e[:, :, i]) ** 2)
        a[i] = ein / (2 * 4)
        b[i] = (np.sum(np.abs(e[:, :, i]) ** 2) - ein) / (2 * (n_out - 2) * 2)
    df = F[1] - F[0]
    for fc in (5.0, 12.3, 20.0):
        p = complex(-0.001 * 2 * np.pi * fc, 2 * np.pi * fc)  # narrow: the window rules
        sel = np.abs(F - fc) <= WINDOW * df + 0.5 * df
        got = sp.at(p)
        assert got[2] == np.count_nonzero(sel)
        assert_allclose(got[:2], (a[sel].mean(), b[sel].mean()), rtol=1e-8)


def test_noise_common_to_the_outputs_raises_the_threshold_at_the_resonances() -> None:
    # an H1 error H M from input noise lies in the span of H(f): many noise units per
    # direction there near the resonances, and the threshold rises
    _, h, sys_ = _data(3e-3, 3)
    fit, res = _fit(h, sys_)
    sp = _span(fit, res)
    poles = res.poles
    lam = np.array([sp.at(complex(p))[:2] for p in poles])
    in_band = (poles.imag / (2 * np.pi) > F[0]) & (poles.imag / (2 * np.pi) < F[-1])
    assert np.all(lam[in_band, 0] > 3.0 * lam[in_band, 1])
    k = mode_parameters(h.shape[0], 2, "complex")
    thr = mode_threshold(k, F.size)
    got = local_thresholds(fit, sp, poles[in_band], thr, ModeTest(k, F.size))
    assert np.all(got > 1.5 * thr)


def test_span_threshold_is_exact_when_every_parameter_lies_in_the_span() -> None:
    # a = min(4 n_in, k) = k: the statistic is lambda_in chi2_k, the Satterthwaite
    # form is exact (c = lambda_in, d = k): the threshold scales by lambda_in
    thr = mode_threshold(4, 300)
    assert_allclose(span_threshold(thr, 4, 1, 300, (5.0, 0.4, 100)), 5.0 * thr, rtol=1e-12)
    # no excess beyond the scatter of the in-span variance: unchanged
    assert span_threshold(thr, 4, 1, 300, (1.2, 1.0, 5)) == thr
    assert span_threshold(thr, 36, 2, 300, (0.9, 1.0, 100)) == thr


@pytest.mark.parametrize("lam", [(6.0, 0.5), (3.0, 0.8)])
def test_span_threshold_quantile_against_monte_carlo(lam: tuple[float, float]) -> None:
    # the Satterthwaite quantile of lambda_in chi2_8 + lambda_out chi2_28 at 1 %
    # against the sampled distribution (one line: level alpha)
    k, n_in, alpha = 36, 2, 0.01
    rng = np.random.default_rng(0)
    t = lam[0] * rng.chisquare(8, 400_000) + lam[1] * rng.chisquare(28, 400_000)
    base = float(sps.chi2.isf(alpha, k))
    got = span_threshold(base, k, n_in, 1, (*lam, 1000), alpha)
    assert_allclose(got, np.quantile(t, 1 - alpha), rtol=0.04)


def test_one_input_split_equals_the_qr_projection() -> None:
    # with one input the in-span power is |u^H e|^2 / ||u||^2 (no QR): the same as
    # the projection on the QR basis of the column, to round-off; a line where the
    # data vanish takes the QR route (its basis is some unit vector)
    from tyredamp.modal.search.span_noise import _split

    rng = np.random.default_rng(11)
    n_out, n_f = 7, 50
    u = rng.normal(size=(n_out, 1, n_f)) + 1j * rng.normal(size=(n_out, 1, n_f))
    e = rng.normal(size=(n_out, 1, n_f)) + 1j * rng.normal(size=(n_out, 1, n_f))
    e_in, e_all = _split(u, e)
    q = np.linalg.qr(u.transpose(2, 0, 1))[0]
    p = np.conj(q).transpose(0, 2, 1) @ e.transpose(2, 0, 1)
    assert_allclose(e_in, np.sum(np.abs(p) ** 2, axis=(1, 2)), rtol=1e-12)
    assert_allclose(e_all, np.sum(np.abs(e) ** 2, axis=(0, 1)), rtol=1e-12)
    assert np.all(e_in <= e_all * (1 + 1e-12))
    u[:, :, 3] = 0.0
    e_in0, _ = _split(u, e)
    q0 = np.linalg.qr(u[:, :, 3])[0]
    assert_allclose(e_in0[3], np.abs(np.conj(q0[:, 0]) @ e[:, 0, 3]) ** 2, rtol=1e-12)
