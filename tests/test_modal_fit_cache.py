"""What one ModalFitter call reuses from another is passed explicitly (issue 14: a
stateless fitter): the fixed part of fit_added (``fixed_part``), an intermediate
fit at rest (``fit(..., start=res)``); the data rows of one block. Each gives the
results of computing everything again, and a fitter holds no state between calls."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.exceptions import InputError
from tyredamp.modal.fit import _basis
from tyredamp.modal.fit._linalg import _levenberg_marquardt, at_rest
from tyredamp.modal.fit.fit import ModalFitter

from .helpers import chain_system

F = np.linspace(0.5, 40.0, 400)


def _noisy(noise: float, seed: int) -> tuple[Any, np.ndarray]:
    sys_ = chain_system()
    rng = np.random.default_rng(seed)
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H
    h = h + noise * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    return sys_, h


def _fitter(h: np.ndarray, kind: str = "complex") -> ModalFitter:
    return ModalFitter(F, h, 2, kind, [(0, 0), (5, 1)])


def _state(fit: ModalFitter) -> dict[str, Any]:
    """A fitter's attributes, arrays copied (to compare before and after calls)."""
    return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in vars(fit).items()}


def _same_state(before: dict[str, Any], fit: ModalFitter) -> None:
    after = vars(fit)
    assert set(after) == set(before)
    for k, v in before.items():
        if isinstance(v, np.ndarray):
            assert_array_equal(after[k], v, err_msg=k)
        elif isinstance(v, tuple):
            assert len(after[k]) == len(v)
            for x, y in zip(after[k], v, strict=True):
                assert_array_equal(x, y, err_msg=k)
        else:
            assert after[k] == v, k


def _case(kind: str) -> tuple[Any, np.ndarray, tuple[Any, Any], Any, tuple[float, float]]:
    sys_, h = _noisy(1e-3, 5)
    cm = sys_.complex_modes()
    part = cm.psi[[0, 5]].T
    k = int(np.argsort(cm.poles.imag)[3])
    keep = np.delete(np.arange(cm.poles.size), k)
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    return cm, h, (cm.poles[keep] * 1.001, part[keep]), cm.poles[k], (lo, hi)


@pytest.mark.parametrize("kind", ["complex", "real"])
@pytest.mark.parametrize("many_blocks", [False, True])
def test_fit_added_with_a_given_fixed_part_gives_the_result_of_forming_it(
    kind: str, many_blocks: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    if many_blocks:
        monkeypatch.setattr(_basis, "BLOCK_BYTES", 1)
        monkeypatch.setattr(_basis, "MIN_BLOCK_LINES", 37)
    _, h, fixed, pk, bounds = _case(kind)
    fit = _fitter(h, kind)
    assert (len(_basis.blocks(fit, 20)) > 1) == many_blocks
    fx = fit.fixed_part(*fixed)
    # an immutable value: frozen, read-only arrays, the one block's basis only
    with pytest.raises(dataclasses.FrozenInstanceError):
        fx.m = 0  # type: ignore[misc]
    assert not fx.tmap.flags.writeable
    assert not fx.th.flags.writeable
    assert (fx.phi0 is None) == many_blocks
    for start in (pk * 1.03, pk * 1.01, pk * (0.99 + 0.01j)):
        given = fit.fit_added(*fixed, start, np.ones(2), omega_bounds=bounds, fixed=fx)
        formed = fit.fit_added(*fixed, start, np.ones(2), omega_bounds=bounds)
        new = _fitter(h, kind).fit_added(*fixed, start, np.ones(2), omega_bounds=bounds)
        # the same arithmetic on the same arrays: identical
        for a, b, c in zip(given, formed, new, strict=True):
            assert_array_equal(a, b)
            assert_array_equal(a, c)
    # the fixed part of other modes is refused, not used
    other = (fixed[0] * 1.002, fixed[1])
    with pytest.raises(InputError, match="fixed"):
        fit.fit_added(*other, pk, np.ones(2), omega_bounds=bounds, fixed=fx)
    # another fitter's fixed part of the same modes on the same data: the same value
    fx2 = _fitter(h, kind).fixed_part(*fixed)
    for f in dataclasses.fields(fx):
        x, y = getattr(fx, f.name), getattr(fx2, f.name)
        if isinstance(x, np.ndarray):
            assert_array_equal(x, y, err_msg=f.name)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_a_fitter_holds_no_state_between_calls(kind: str) -> None:
    cm, h, fixed, pk, bounds = _case(kind)
    part = cm.psi[[0, 5]].T
    opts = {"passes": 1, "tol": 10.0, "uncertainty": False}
    a, b = _fitter(h, kind), _fitter(h, kind)
    before = _state(a)
    # a: fit_added, fit, fit_added again, a fit started at its own result
    a1 = a.fit_added(*fixed, pk * 1.01, np.ones(2), omega_bounds=bounds)
    a2 = a.fit(cm.poles * 1.002, part, **opts)
    a3 = a.fit_added(*fixed, pk * 1.02, np.ones(2), omega_bounds=bounds)
    a4 = a.fit(a2.poles, a2.participation, start=a2, **opts)
    _same_state(before, a)  # attributes unchanged by the calls
    # b: the same calls in another order, each on its own
    b4_start = b.fit(cm.poles * 1.002, part, **opts)
    b3 = b.fit_added(*fixed, pk * 1.02, np.ones(2), omega_bounds=bounds)
    b1 = b.fit_added(*fixed, pk * 1.01, np.ones(2), omega_bounds=bounds)
    b4 = b.fit(b4_start.poles, b4_start.participation, start=b4_start, **opts)
    for x, y in ((a1, b1), (a3, b3)):
        for u, v in zip(x, y, strict=True):
            assert_array_equal(u, v)
    for x, y in ((a2, b4_start), (a4, b4)):
        assert_array_equal(x.poles, y.poles)
        assert_array_equal(x.sigma_out, y.sigma_out)
        assert_array_equal(x.significance, y.significance)
        assert x.n_iter == y.n_iter


def test_a_fit_started_at_a_fit_at_rest_returns_it_with_one_evaluation() -> None:
    sys_, h = _noisy(1e-2, 6)
    cm = sys_.complex_modes()
    part = cm.psi[[0, 5]].T
    fit = _fitter(h)
    opts = {"passes": 1, "tol": 10.0, "uncertainty": False}
    first = fit.fit(cm.poles * 1.002, part, **opts)
    assert first.status == "converged"
    assert first.n_iter > 1
    assert first.rest is not None
    again = fit.fit(first.poles, first.participation, start=first, **opts)
    # without ``start`` the refinement runs from there: it stops after one
    # evaluation at the same point (the start re-packed from the poles, round-off apart)
    new = _fitter(h).fit(first.poles, first.participation, **opts)
    assert again.n_iter == new.n_iter == 1
    assert again.status == new.status == "converged"
    assert_allclose(again.poles, new.poles, rtol=1e-13)
    assert_allclose(again.sigma_out, new.sigma_out, rtol=1e-10)
    assert_allclose(again.significance, new.significance, rtol=1e-8)
    assert_array_equal(again.poles, first.poles)
    assert again is not first
    # another tolerance is not served from it: the refinement goes on
    other = fit.fit(
        first.poles, first.participation, start=first, passes=1, tol=1e-6, uncertainty=False
    )
    assert other.n_iter > 1
    # a start that is not the given poles is not used: the fit of no start
    moved = fit.fit(first.poles * 1.001, first.participation, start=first, **opts)
    plain = fit.fit(first.poles * 1.001, first.participation, **opts)
    assert_array_equal(moved.poles, plain.poles)
    assert moved.n_iter == plain.n_iter > 1
    # a final fit (standard errors) is computed, whatever the start
    full = fit.fit(first.poles, first.participation, start=first, passes=1, tol=10.0)
    assert np.all(np.isfinite(full.std_frequency_hz))
    # a fit stopped at its evaluation limit is not at rest
    short = fit.fit(cm.poles * 1.01, part, max_nfev=2, **opts)
    assert short.status == "maxfev"
    assert short.rest is None


def test_at_rest_is_the_first_stop_of_levenberg_marquardt() -> None:
    # cost (x - a)^T M (x - a) + c: J^T J = M, J^T r = M (x - a) (gradient / 2)
    rng = np.random.default_rng(1)
    a_mat = rng.normal(size=(4, 4))
    M = a_mat @ a_mat.T + 4 * np.eye(4)
    a = rng.normal(size=4)
    lb, ub = np.full(4, -10.0), np.full(4, 10.0)

    def evaluate(x: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, None]:
        d = x - a
        return float(d @ M @ d) + 1.0, M, M @ d, None

    for shift, rest in ((1e-6, True), (1e-1, False)):
        x = a + shift
        c, A, g, _ = evaluate(x)
        assert at_rest(x, c, A, g, (lb, ub), 1.0, 10) == rest
        nfev = _levenberg_marquardt(evaluate, x, lb, ub, 50, dof=10, tol=1.0)[1]
        assert (nfev == 1) == rest


def test_one_block_data_rows_are_kept_read_only_and_equal_the_blocked_rows(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _, h = _noisy(1e-3, 7)
    fit = _fitter(h)
    assert _basis.one_block(fit)
    y = fit.Y
    assert not y.flags.writeable
    monkeypatch.setattr(_basis, "BLOCK_BYTES", 1)
    blocked = _fitter(h)
    assert not _basis.one_block(blocked)
    # several blocks: no per-line array is kept (issue 15: the data plus a constant)
    assert blocked._y is None
    assert blocked._factors is None
    assert_array_equal(blocked.Y, y)
    # the rows of some lines from the data, all lines from what the fitter keeps
    sl = slice(3, 40)
    assert_array_equal(_basis.ydata(fit, sl), _basis.ydata(blocked, sl))
    assert _basis.ydata(fit, slice(0, F.size)) is y


@pytest.mark.parametrize(
    ("spacing", "blocked"), [(3e-5, False), (3e-6, False), (3e-6, True), (3e-8, True)]
)
def test_ill_conditioned_basis_by_cholesky_qr(
    spacing: float, blocked: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a pole pair this close makes the Gram matrix too ill-conditioned for the Gram
    # route (cond > _MAX_GRAM_COND): below _MAX_CQR2_COND by CholeskyQR2, beyond it
    # (spacing 3e-8, cond ~1e12) by shifted CholeskyQR3, in one block of rows or
    # several; the projection must match an independent least-squares solution and
    # the Kaufman normal equations from the explicit derivative matrix, and no
    # Householder QR is taken
    from scipy.linalg import lapack

    import tyredamp.modal.fit._linalg as lin

    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(12)
    h = sys_.frf(F, inputs=[0]).H * (2j * np.pi * F) ** 2
    h = h + 1e-2 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    fit = ModalFitter(F, h, 2, "complex", [])
    poles = np.append(cm.poles, cm.poles[2] * (1 + spacing))  # cond 1.3e6, 1.3e8
    m = poles.size
    ref = np.zeros(m, np.intp)
    th = fit.pack(poles, np.ones((m, 1), complex), ref)
    phi, D, dpar, dcol = fit.basis(th, m, ref)
    g = phi.T @ phi
    d = np.sqrt(g.diagonal())
    gs = g / np.outer(d, d)
    r1 = lapack.dpotrf(gs)[0]
    cond = 1.0 / lapack.dpocon(r1, float(abs(gs).sum(axis=0).max()))[0]
    assert cond > lin._MAX_GRAM_COND
    assert (cond > lin._MAX_CQR2_COND) == (spacing < 1e-7)

    def no_householder(*args: Any, **kw: Any) -> Any:
        raise AssertionError("the Householder route was taken")

    monkeypatch.setattr(lin, "_qr_blocks", no_householder)
    if blocked:
        monkeypatch.setattr(_basis, "BLOCK_BYTES", 1)  # blocks of MIN_BLOCK_LINES lines
        fit = ModalFitter(F, h, 2, "complex", [])
        assert len(_basis.blocks(fit, fit.n_cols(m))) > 1
    w = np.ones(fit.n_out)
    sol = fit._solve(th, m, ref, w, residual=False)
    assert sol["qr"]
    # references: least squares by numpy's SVD solver, Q from numpy's Householder QR
    yw = fit.Y * w
    C = np.linalg.lstsq(phi, yw, rcond=None)[0]
    r = yw - phi @ C
    Q = np.linalg.qr(phi)[0]
    qtd = Q.T @ D
    A = np.zeros((D.shape[1], th.size))
    A[np.arange(D.shape[1]), dpar] = 1.0
    jtj_ref = A.T @ ((D.T @ D - qtd.T @ qtd) * (C @ C.T)[dcol[:, None], dcol[None, :]]) @ A
    jtr_ref = -(A.T @ np.einsum("id,id->d", D, (r @ C.T)[:, dcol]))
    jtj, jtr = fit._normal(sol, th.size)
    # tolerances: round-off times cond(Phi) ~ sqrt(cond) for the cost and the fit,
    # the coefficients of the close pair are as ill-determined as cond(Phi) says;
    # at cond 1e12 numpy's lstsq reference itself differs from a Householder QR of
    # Phi by 1.5e-8 of the largest gradient entry (measured), hence 1e-7 there
    gtol = 1e-8 if cond < lin._MAX_CQR2_COND else 1e-7
    assert_allclose(sol["cost"], np.sum(r**2), rtol=1e-9)
    assert_allclose(phi @ sol["C"], phi @ C, rtol=0, atol=1e-9 * np.abs(yw).max())
    assert_allclose(np.abs(sol["R"].T @ sol["R"]), np.abs(g), rtol=0, atol=1e-12 * np.abs(g).max())
    assert_allclose(jtj, jtj_ref, rtol=0, atol=gtol * np.max(np.abs(jtj_ref)))
    assert_allclose(jtr, jtr_ref, rtol=0, atol=gtol * np.max(np.abs(jtr_ref)))


@pytest.mark.parametrize("n_in", [1, 2])
def test_residual_power_is_the_weighted_residual_of_the_modal_sum(n_in: int) -> None:
    # _basis.residual_power forms the modes' terms as one matrix product; reference:
    # the modal sum R / (s - p) + conj(R) / (s - conj p) mode by mode, plus the
    # residual terms, weighted per line and per output
    sys_ = chain_system()
    cm = sys_.complex_modes()
    inputs = [0, 5][:n_in]
    rng = np.random.default_rng(8)
    h = sys_.frf(F, kind="accelerance", inputs=inputs).H
    h = h + 1e-2 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    lw = 1.0 + 0.3 * np.sin(F)
    fit = ModalFitter(F, h, 2, "complex", [], line_weights=lw)
    res = fit.fit(cm.poles, cm.psi[inputs].T, refine=False)
    R = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    s2 = res.sigma_out**2
    got = _basis.residual_power(fit, res.poles, R, (res.upper, res.lower), s2)
    s = 2j * np.pi * F
    model = np.zeros_like(h)
    for n, p in enumerate(res.poles):
        r = R[:, :, n, None]
        model += r * s**2 / (s - p) + np.conj(r) * s**2 / (s - np.conj(p))
    model += res.upper[:, :, None] * s**2 + res.lower[:, :, None]
    ref = np.einsum("jkf,j->f", np.abs(h - model) ** 2 * lw**2, 1.0 / s2)
    assert_allclose(got, ref, rtol=1e-9)  # two routes to the same sums: round-off


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_basis_times_data_from_the_complex_data(kind: str) -> None:
    # _basis.rows_t_data: B^T Y as Re(conj(B_c)^T H_c), without forming the data rows;
    # reference: the real rows of the data (ydata) and a real product
    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(2)
    h = sys_.frf(F, kind="accelerance", inputs=[0, 5]).H
    h = h + 1e-2 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    fit = ModalFitter(F, h, 2, kind, [], line_weights=1.0 + 0.4 * np.cos(F))
    part = cm.psi[[0, 5]].T
    if kind == "real":
        part = np.abs(part) + 0j
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    th = fit.pack(cm.poles, part, ref)
    sl = slice(37, 290)
    B = fit._basis_ek(th, cm.poles.size, ref, True, sl)[0]
    want = B.T @ _basis.ydata(fit, sl)
    assert_allclose(_basis.rows_t_data(fit, sl, B), want, rtol=0, atol=1e-12 * np.abs(want).max())
    # rows in another layout: the real product itself
    Bc = np.ascontiguousarray(B)
    assert_allclose(_basis.rows_t_data(fit, sl, Bc), want, rtol=0, atol=0)


def test_the_search_forms_one_fixed_part_per_mode_set() -> None:
    # FixedParts (owned by the caller of the search stages): the same mode set gives
    # the same value, another mode set a new one, equal to the fitter's fixed_part
    from tyredamp.modal.search.search import FixedParts

    _, h, fixed, _, _ = _case("complex")
    fit = _fitter(h)
    held = FixedParts(fit)
    a = held.of(*fixed)
    assert a is not None
    assert held.of(fixed[0].copy(), fixed[1].copy()) is a
    other = (fixed[0] * 1.002, fixed[1])
    b = held.of(*other)
    assert b is not None
    assert b is not a
    assert_array_equal(b.tmap, fit.fixed_part(*other).tmap)
    assert held.of(*fixed) is not a  # only the latest mode set is held


@pytest.mark.parametrize("smallest", [1e-4, 1e-6])
def test_fixed_range_of_an_ill_conditioned_basis_in_blocks(
    smallest: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Phi with singular values from 1 to `smallest` (Gram condition 1e8 and 1e12:
    # CholeskyQR2, then its shifted start) held in three row blocks; reference: the
    # projector from numpy's SVD of Phi. Q_r^T X = T^T Phi^T X must be orthonormal
    # coordinates of the range, ||P Y||^2 the residual power, and no Householder QR
    import tyredamp.modal.fit._linalg as lin

    rng = np.random.default_rng(3)
    n, q = 600, 12
    u = np.linalg.qr(rng.normal(size=(n, q)))[0]
    v = np.linalg.qr(rng.normal(size=(q, q)))[0]
    phi = (u * np.geomspace(1.0, smallest, q)) @ v.T * rng.uniform(0.5, 2.0, q)
    y = phi @ rng.normal(size=(q, 2)) + 1e-3 * rng.normal(size=(n, 2))
    parts = [slice(0, 200), slice(200, 450), slice(450, n)]

    def no_householder(*args: Any, **kw: Any) -> Any:
        raise AssertionError("the Householder route was taken")

    monkeypatch.setattr(lin, "_qr_blocks", no_householder)
    shifted = []
    start = lin._shifted_start

    def spy(*args: Any) -> Any:
        shifted.append(True)
        return start(*args)

    monkeypatch.setattr(lin, "_shifted_start", spy)
    tmap, qty, yyp = lin._fixed_range(
        lambda: ((phi[s], y[s]) for s in parts), q, (y * y).sum(axis=0), None, n
    )
    qr = phi @ tmap  # Q_r
    uu = np.linalg.svd(phi, full_matrices=False)[0]
    res = y - uu @ (uu.T @ y)
    # tolerances: orthonormality and the projection to round-off times cond(Phi)
    assert_allclose(qr.T @ qr, np.eye(q), rtol=0, atol=1e-9)
    assert_allclose(qr @ qty, uu @ (uu.T @ y), rtol=0, atol=1e-9 * np.abs(y).max())
    assert_allclose(yyp, (res * res).sum(axis=0), rtol=1e-6)
    assert bool(shifted) == (smallest < 1e-5)
