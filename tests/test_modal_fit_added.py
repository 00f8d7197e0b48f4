"""One added mode refined with the others held fixed (ModalFitter.fit_added), and
the per-mode contributions of ModalFitter.fit (spec eq. [10])."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.modal.fit.fit import ModalFitter

from .helpers import chain_system

F = np.linspace(0.5, 40.0, 400)


def test_fit_added_recovers_the_missing_mode_exactly() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H
    fit = ModalFitter(F, h, 2, "complex", [(0, 0), (5, 1)], upper=False, lower=False)
    part = cm.psi[[0, 5]].T  # true participation (m, n_in)
    k = int(np.argsort(cm.poles.imag)[2])  # leave one mode out, give the others exactly
    keep = np.delete(np.arange(cm.poles.size), k)
    start = cm.poles[k] * (1.02 + 0.01j)
    l0 = part[k] / part[k][np.argmax(np.abs(part[k]))] * 1.1
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    p, lk, sig = fit.fit_added(cm.poles[keep], part[keep], start, l0, omega_bounds=(lo, hi))
    # noise-free data, the full modal set at the optimum: exact to solver tolerance
    assert_allclose(p, cm.poles[k], rtol=1e-8)
    ratio = lk / part[k]
    assert_allclose(ratio, ratio[0], rtol=1e-7)  # participation up to one complex scale
    # the residual of the full model is round-off only
    assert np.all(sig <= 1e-8 * np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2))))


def test_contributions_match_the_synthesised_mode_frfs() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(3)
    h = sys_.frf(F, kind="mobility", inputs=[2]).H
    h = h + 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2)) * (
        rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    )
    fit = ModalFitter(F, h, 1, "complex", [(2, 0)])
    res = fit.fit(cm.poles, cm.psi[[2]].T, refine=False)
    # independent reference: each mode's FRF from its scaled shape (eq. [10])
    s = 2j * np.pi * F
    data_ss = np.sum(np.abs(h) ** 2)
    for n, p in enumerate(res.poles):
        r = res.psi_out[:, n, None] * res.psi_in[None, :, n]  # (n_out, n_in)
        g = s / (s - p)
        gb = s / (s - np.conj(p))
        hn = r[:, :, None] * g + np.conj(r)[:, :, None] * gb
        # same quantity by two routes: round-off only
        assert_allclose(res.contribution[n], np.sqrt(np.sum(np.abs(hn) ** 2) / data_ss), rtol=1e-9)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_blocks_of_lines_give_the_same_fits(kind: str, monkeypatch: pytest.MonkeyPatch) -> None:
    # the Gram blocks, the QR route and the fitted FRFs are summed over blocks of
    # lines (no per-line array of the fits): blocks of a few lines must give the
    # fits of one block (every line at once) to round-off
    import tyredamp.modal.fit._basis as basis_mod

    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(9)
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H
    h = h + 1e-3 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    lw = 1.0 + 0.5 * np.cos(F)  # line weights
    fit = ModalFitter(F, h, 2, kind, [(0, 0), (5, 1)], line_weights=lw)
    part = cm.psi[[0, 5]].T
    k = int(np.argsort(cm.poles.imag)[-1])
    keep = np.delete(np.arange(cm.poles.size), k)
    p0 = cm.poles[keep] * 1.001
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    one = fit.fit(p0, part[keep])
    one_added = fit.fit_added(
        one.poles, one.participation, cm.poles[k] * 1.01, np.ones(2), omega_bounds=(lo, hi)
    )
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 1)
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 37)  # 11 blocks, the last short
    assert len(basis_mod.blocks(fit, 10)) == 11
    many = ModalFitter(F, h, 2, kind, [(0, 0), (5, 1)], line_weights=lw).fit(p0, part[keep])
    assert_allclose(many.poles, one.poles, rtol=1e-10)
    assert_allclose(many.psi_out, one.psi_out, rtol=1e-8, atol=1e-10 * np.abs(one.psi_out).max())
    assert_allclose(many.model, one.model, rtol=0, atol=1e-10 * np.abs(one.model).max())
    assert_allclose(many.std_frequency_hz, one.std_frequency_hz, rtol=1e-6)
    assert_allclose(many.significance, one.significance, rtol=1e-6)
    # a new fitter on blocks of a few lines
    many_added = ModalFitter(F, h, 2, kind, [(0, 0), (5, 1)], line_weights=lw).fit_added(
        one.poles, one.participation, cm.poles[k] * 1.01, np.ones(2), omega_bounds=(lo, hi)
    )
    assert_allclose(many_added[0], one_added[0], rtol=1e-10)
    assert_allclose(many_added[2], one_added[2], rtol=1e-8)


@pytest.mark.parametrize("noise", [1e-2, 1e-3])
def test_fit_added_gram_blocks_match_the_explicit_projection(
    noise: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    # fit_added evaluates from Gram blocks of the fixed and the added basis unless a
    # subtraction would lose accuracy; forcing the QR route everywhere must give the
    # same refinement, and its residual is that of a linear fit with all modes at the
    # refined pole
    import tyredamp.modal.fit._added as added_mod
    import tyredamp.modal.fit._linalg as lin_mod

    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(4)
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H
    h = h + noise * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    fit = ModalFitter(F, h, 2, "complex", [(0, 0), (5, 1)])
    part = cm.psi[[0, 5]].T
    k = int(np.argsort(cm.poles.imag)[3])
    keep = np.delete(np.arange(cm.poles.size), k)
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    args = (cm.poles[keep], part[keep], cm.poles[k] * (1.01 + 0.01j), np.ones(2))
    a = fit.fit_added(*args, omega_bounds=(lo, hi))
    res = fit.fit(
        np.append(cm.poles[keep], a[0]), np.concatenate([part[keep], a[1][None]]), refine=False
    )
    assert_allclose(a[2], res.sigma_out, rtol=1e-9)
    monkeypatch.setattr(added_mod, "_PROJ_TOL", np.inf)
    monkeypatch.setattr(lin_mod, "_CANCEL_TOL", np.inf)
    # the QR route everywhere
    b = ModalFitter(F, h, 2, "complex", [(0, 0), (5, 1)]).fit_added(*args, omega_bounds=(lo, hi))
    assert_allclose(b[0], a[0], rtol=1e-10)
    assert_allclose(b[1], a[1], rtol=1e-8)
    assert_allclose(b[2], a[2], rtol=1e-9)


@pytest.mark.parametrize("n_in", [1, 2])
def test_blocks_with_many_outputs_give_the_same_added_mode(
    n_in: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # with several blocks and a fixed basis no larger than the data (more outputs
    # than its columns), the fixed part keeps Q_r of every line and an evaluation
    # forms the added columns of every line at once: the refinement of one block
    # (every line at once) to round-off, with line weights and one or two inputs
    import tyredamp.modal.fit._basis as basis_mod

    sys_ = chain_system(n=12)
    cm = sys_.complex_modes()
    rng = np.random.default_rng(21)
    inputs = [0, 5][:n_in]
    h = sys_.frf(F, kind="accelerance", inputs=inputs).H  # (12, n_in, 400)
    h = h + 1e-3 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    lw = 1.0 + 0.5 * np.cos(F)
    drive = [(j, i) for i, j in enumerate(inputs)]
    part = cm.psi[inputs].T
    order = np.argsort(cm.poles.imag)
    k = int(order[3])
    keep = order[:3]  # few fixed modes: n_cols(3) <= 12 outputs
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    args = (cm.poles[keep], part[keep], cm.poles[k] * 1.01, np.ones(n_in))
    one = ModalFitter(F, h, 2, "complex", drive, line_weights=lw)
    assert one.n_cols(3) <= one.n_out
    ref = one.fit_added(*args, omega_bounds=(lo, hi))
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 1)
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 37)  # 11 blocks, the last short
    many = ModalFitter(F, h, 2, "complex", drive, line_weights=lw)
    fx = many.fixed_part(cm.poles[keep], part[keep])
    assert len(fx.parts) == 11
    assert fx.qr is not None
    assert fx.qy is None
    got = many.fit_added(*args, omega_bounds=(lo, hi), fixed=fx)
    assert_allclose(got[0], ref[0], rtol=1e-10)
    assert_allclose(got[1], ref[1], rtol=1e-8)
    assert_allclose(got[2], ref[2], rtol=1e-8)


def test_fixed_basis_of_one_block_kept_with_more_columns_than_outputs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # several blocks, the fixed basis larger than the data (more columns than the
    # two outputs) but no larger than one block of the fits: Q_r of every line is
    # kept and the added columns formed at once; the refinement of one block to
    # round-off, and the fixed basis is not formed again per evaluation
    import tyredamp.modal.fit._basis as basis_mod

    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(8)
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H[:2]  # 2 outputs, 2 inputs
    h = h + 1e-3 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    part = cm.psi[[0, 5]].T
    order = np.argsort(cm.poles.imag)
    k, keep = int(order[2]), np.delete(order, 2)
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    args = (cm.poles[keep], part[keep], cm.poles[k] * 1.01, np.ones(2))
    drive = [(0, 0)]
    ref = ModalFitter(F, h, 2, "complex", drive).fit_added(*args, omega_bounds=(lo, hi))
    many = ModalFitter(F, h, 2, "complex", drive)
    qf = many.n_cols(keep.size)
    assert qf > many.n_out
    monkeypatch.setattr(basis_mod, "BLOCK_BYTES", 8 * many.n_rows * qf)  # Q_r fits one block
    monkeypatch.setattr(basis_mod, "MIN_BLOCK_LINES", 37)
    fx = many.fixed_part(cm.poles[keep], part[keep])
    assert len(fx.parts) > 1
    assert fx.qr is not None
    calls = []
    real = many._basis_ek

    def counted(th: np.ndarray, m: int, *a: object, **kw: object) -> object:
        calls.append(m)
        return real(th, m, *a, **kw)

    monkeypatch.setattr(many, "_basis_ek", counted)
    got = many.fit_added(*args, omega_bounds=(lo, hi), fixed=fx)
    assert calls == []  # the fixed basis (m > 1 modes) not formed again
    # the same refinement by other sums: round-off times the conditioning
    assert_allclose(got[0], ref[0], rtol=1e-10)
    assert_allclose(got[1], ref[1], rtol=1e-8)
    assert_allclose(got[2], ref[2], rtol=1e-8)


def test_residual_blocks_against_the_modal_sum() -> None:
    # the residual H - H^ of residual_blocks (one real product of [Re R, Im R, upper,
    # lower] and the columns a + b, i (a - b), kappa, kappa_low) against the modal sum
    # sum_n R_n kappa / (s - p_n) + conj(R_n) kappa / (s - conj p_n) + upper kappa +
    # lower kappa / (i w)^2 written out, line weights applied
    import tyredamp.modal.fit._basis as basis_mod

    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(5)
    h = sys_.frf(F, kind="mobility", inputs=[0, 5]).H
    lw = 1.0 + 0.5 * np.cos(F)
    fit = ModalFitter(F, h, 1, "complex", [(0, 0), (5, 1)], line_weights=lw)
    r = rng.normal(size=(6, 2, 4)) + 1j * rng.normal(size=(6, 2, 4))
    p = cm.poles[:4]
    up, low = rng.normal(size=(6, 2)), rng.normal(size=(6, 2))
    s = 2j * np.pi * F
    kap = s**1  # mobility: (i w)^1
    modes = np.einsum("jkn,nf->jkf", r, kap / (s - p[:, None]))
    modes += np.einsum("jkn,nf->jkf", np.conj(r), kap / (s - np.conj(p)[:, None]))
    extra = up[:, :, None] * kap + low[:, :, None] * kap / s**2
    for terms, model in (((up, low), modes + extra), ((None, None), modes)):
        got = np.concatenate([e for _, e in basis_mod.residual_blocks(fit, p, r, terms)], axis=2)
        # the same sum in another order: round-off of the largest term
        tol = 1e-12 * np.abs(modes + extra).max() * lw.max()
        assert_allclose(got, (h - model) * lw, rtol=0, atol=tol)
