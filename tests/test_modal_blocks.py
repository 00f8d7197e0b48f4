"""Per-line work of the identification in bounded blocks of lines.

* the weighted residual ``H - H^`` of :func:`~tyredamp.modal.fit._basis.residual_lines`,
  formed block by block (also on strided lines, as the coherent scan asks),
  equals the modal sum written out term by term;
* the residual peaks' matched-window score, block by block, gives the peaks of
  one block holding every line, and the local maxima are those of the
  neighbour comparison written out;
* the out-of-band scan's start, block by block, is the one of a single block.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from numpy.typing import NDArray

import tyredamp.modal.fit._basis as basis_mod
import tyredamp.modal.search.residual_peaks as peaks_mod
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.search.out_of_band import _scan_starts

F = np.linspace(5.0, 60.0, 700)


def _data(
    seed: int = 3,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    rng = np.random.default_rng(seed)
    fn = np.array([14.0, 31.0, 47.0])
    z = np.array([0.02, 0.015, 0.01])
    w = 2 * np.pi * fn
    poles = -z * w + 1j * w * np.sqrt(1 - z * z)
    res = rng.normal(size=(2, 2, 3)) + 1j * rng.normal(size=(2, 2, 3))
    s = 2j * np.pi * F
    h = np.einsum("jkn,nf->jkf", res, 1 / (s - poles[:, None]))
    h += np.einsum("jkn,nf->jkf", res.conj(), 1 / (s - poles.conj()[:, None]))
    h += 1e-2 * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    return poles, res, h


@pytest.mark.parametrize("lines", [slice(0, 700), slice(30, 650, 3)])
def test_residual_lines_in_small_blocks_is_the_modal_sum(
    lines: slice, monkeypatch: pytest.MonkeyPatch
) -> None:
    poles, res, h = _data()
    lw = 1.0 + 0.3 * np.cos(F / 3.0)
    fit = ModalFitter(F, h, 0, "complex", [], line_weights=lw)
    upper = np.array([[0.3, -0.1], [0.2, 0.05]])
    lower = np.array([[-40.0, 10.0], [5.0, 7.0]])
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 1)
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 29)  # many blocks, the last short
    got = basis_mod.residual_lines(fit, poles, res * 0.9, (upper, lower), lines)
    # the receptance model written out (power 0): sum_n R / (s - p) + conj(R) / (s - conj p)
    # + upper + lower / s^2, weighted per line as the fit weights the data
    f = F[lines]
    s = 2j * np.pi * f
    model = np.zeros((2, 2, f.size), complex)
    for n in range(3):
        model += 0.9 * res[:, :, n, None] / (s - poles[n])
        model += 0.9 * np.conj(res[:, :, n, None]) / (s - np.conj(poles[n]))
    model += upper[:, :, None] + lower[:, :, None] / s**2
    want = (h[:, :, lines] - model) * lw[lines]
    # the same sums in another order: round-off of the largest term only
    assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(h).max())


def _peaks_written_out(score: NDArray[np.float64]) -> list[int]:
    sc = np.where(np.isfinite(score), score, -1e300)
    out = []
    for i in range(sc.size):
        left = sc[i - 1] if i > 0 else -np.inf
        right = sc[i + 1] if i + 1 < sc.size else -np.inf
        if np.isfinite(score[i]) and sc[i] > left and sc[i] >= right:
            out.append(i)
    return sorted(out, key=lambda i: -sc[i])


def test_local_maxima_are_those_of_the_neighbour_comparison() -> None:
    rng = np.random.default_rng(5)
    score = np.round(rng.normal(size=400), 1)  # ties between neighbours
    score[rng.random(400) < 0.3] = -np.inf
    score[[0, -1]] = [5.0, 6.0]  # maxima at the ends
    got = peaks_mod._peaks(score)
    want = _peaks_written_out(score)
    assert sorted(got.tolist()) == sorted(want)
    assert_allclose(score[got], score[want])  # best first (ties in either order)


def test_residual_peaks_in_small_blocks_are_those_of_one_block(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    rng = np.random.default_rng(11)
    f = np.geomspace(10.0, 200.0, 5000)  # not uniform: the spacing per line counts
    k = 4
    pw = rng.chisquare(2 * k, size=f.size) / 2
    for fc in (40.0, 90.0, 150.0):
        pw += 3.0 / (1.0 + ((f - fc) / (0.02 * fc)) ** 2)
    whole = peaks_mod.residual_peaks(f, pw, k, 0.02, 20.0, 12)
    monkeypatch.setattr(peaks_mod, "PEAK_BLOCK", 37)
    blocks = peaks_mod.residual_peaks(f, pw, k, 0.02, 20.0, 12)
    assert whole.freq.size > 0
    # each line's score is the same arithmetic in either case: equal, not close
    assert np.array_equal(blocks.freq, whole.freq)
    assert np.array_equal(blocks.excess, whole.excess)


def test_out_of_band_scan_in_small_blocks_is_that_of_one_block(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    poles, _, h = _data(8)
    # the lowest mode is outside the band: its tail is in the residual of a fit
    # of the other two
    band = F >= 20.0
    fr = F[band]
    fit = ModalFitter(fr, h[:, :, band], 0, "complex", [])
    r = fit.fit(poles[1:], np.ones((2, 2)))
    one = _scan_starts(fit, r, (5.0, 20.0), -1.0, 0.02, 20.0)
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 1)
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 23)
    assert len(basis_mod.blocks(fit, 64)) > 10
    fit2 = ModalFitter(fr, h[:, :, band], 0, "complex", [])
    many = _scan_starts(fit2, r, (5.0, 20.0), -1.0, 0.02, 20.0)
    assert one
    assert many == one  # the grid points of the same statistic, summed in other blocks
    assert all(5.0 <= abs(p.imag) / (2 * np.pi) <= 20.0 for p in one)  # in the range asked


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_ml_refine_in_small_blocks_is_that_of_one_block(
    kind: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the maximum-likelihood stage sums its Gram matrices and residuals over blocks
    # of lines when the basis of every line is more than one block: blocks of a few
    # lines must give the fit of one block (the basis whole) to round-off
    from tyredamp.modal.fit.ml import ml_refine

    poles, _, h = _data(4)
    rng = np.random.default_rng(2)
    v = (1e-4 + 1e-2 * np.abs(h) ** 2) * rng.uniform(0.5, 2.0, size=h.shape)
    v[0, 1, 5] = 0.0  # an exact entry: the output's smallest variance stands for it
    part = np.ones((3, 2), complex)
    fit = ModalFitter(F, h, 0, kind, [(0, 0)])
    wls = fit.fit(poles, part)
    one = ml_refine(fit, wls, v, tol=1e-10)
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 1)
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 41)  # 18 blocks, the last short
    many = ml_refine(ModalFitter(F, h, 0, kind, [(0, 0)]), wls, v, tol=1e-10)
    assert one.status == many.status
    # the same optimum; the sums in another order: round-off, amplified by the
    # iteration's stopping point (measured below 1e-12)
    assert_allclose(many.poles, one.poles, rtol=1e-10)
    assert_allclose(many.cost, one.cost, rtol=1e-10)
    assert_allclose(many.model, one.model, rtol=0, atol=1e-9 * np.abs(one.model).max())
    assert_allclose(many.psi_out, one.psi_out, rtol=0, atol=1e-9 * np.abs(one.psi_out).max())
    assert_allclose(many.std_frequency_hz, one.std_frequency_hz, rtol=1e-8)


def test_model_receptance_in_small_blocks_is_the_modal_sum(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # ModalModel.receptance synthesises in blocks of lines: with blocks of 7 lines
    # it is eq. [10] plus the residual modes and terms, written out term by term
    import tyredamp.modal.model as model_mod
    from tyredamp.modal import ModalModel

    poles, _, _ = _data(6)
    rng = np.random.default_rng(6)
    po = rng.normal(size=(2, 3)) + 1j * rng.normal(size=(2, 3))
    pi = rng.normal(size=(2, 3)) + 1j * rng.normal(size=(2, 3))
    extra = ModalModel(np.array([-30.0 + 600.0j]), np.ones((2, 1)) + 0.5j, np.ones((2, 1)))
    upper = rng.normal(size=(2, 2))
    lower = rng.normal(size=(2, 2))
    m = ModalModel(poles, po, pi, upper_residual=upper, lower_residual=lower, residual_modes=extra)
    monkeypatch.setattr(model_mod, "SYNTH_BLOCK", 7)
    got = m.receptance(F)
    s = 2j * np.pi * F
    want = upper[:, :, None] + lower[:, :, None] / s**2
    for p, a, b in zip(
        np.r_[poles, extra.poles],
        np.c_[po, extra.psi_out].T,
        np.c_[pi, extra.psi_in].T,
        strict=True,
    ):
        r = np.outer(a, b)[:, :, None]
        want = want + r / (s - p) + np.conj(r) / (s - np.conj(p))
    # the same sums in another order: round-off of the largest term
    assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    with pytest.raises(ValueError, match="0 Hz"):
        m.receptance(np.r_[0.0, F])
