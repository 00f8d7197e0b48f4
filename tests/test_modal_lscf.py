"""pLSCF poles and the automatic selection rules."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.exceptions import InputError, ShapeError
from tyredamp.modal.poles.lscf import PoleSet, plscf
from tyredamp.modal.poles.selection import StabilityFlags, cluster_poles, stability_flags
from tyredamp.modal.statistics.indicators import mac

from .helpers import chain_system

F = np.linspace(0.1, 40.0, 800)


def _nearest(found: np.ndarray, true: np.ndarray) -> np.ndarray:
    return np.array([found[np.argmin(np.abs(found - t))] for t in true])


def test_plscf_high_order_recovers_exact_poles() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, inputs=[0]).H
    ps = plscf(F, h, 24)
    idx = ps.at_order(24)
    got = _nearest(ps.poles[idx], cm.poles)
    # noise-free data; the z-domain model needs over-modelling, at order 24 the
    # poles agree to ~1e-7 relative
    assert_allclose(got, cm.poles, rtol=1e-6)
    assert set(np.unique(ps.order)) <= set(range(1, 25))


def test_plscf_band_not_starting_at_zero_and_two_inputs() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, inputs=[0, 3]).H
    ps = plscf(F, h, 14, band=(8.0, 40.0))  # normalised band: only modes 2..6 inside
    idx = ps.at_order(14)
    sel = cm.frequency_hz > 9.0
    got = _nearest(ps.poles[idx], cm.poles[sel])
    assert_allclose(got, cm.poles[sel], rtol=1e-4)  # over-modelled, noise-free
    # participation vectors are the mode shapes at the inputs (up to scale)
    j = [int(idx[np.argmin(np.abs(ps.poles[idx] - p))]) for p in cm.poles[sel]]
    m = mac(ps.participation[j].T, cm.psi[[0, 3]][:, sel])
    assert np.all(np.diag(m) > 0.999)


def test_selection_finds_each_mode_once_with_noise() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(5)
    h = sys_.frf(F, inputs=[0]).H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    h = h + 0.01 * rms * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    ps = plscf(F, h, 40)
    flags = stability_flags(ps)
    kept, rejected = cluster_poles(ps, flags)
    f_kept = np.array([c.frequency_hz for c in kept])
    assert f_kept.size == cm.poles.size
    assert_allclose(f_kept, cm.frequency_hz, rtol=1e-3)  # pLSCF medians, 40 dB noise
    assert all(c.fraction >= 0.3 for c in kept)
    assert all(c.fraction < 0.3 for c in rejected)
    # stable implies admissible: positive damping below 20 %
    st = flags.stable
    assert np.all((ps.damping_ratio[st] > 0) & (ps.damping_ratio[st] <= 0.2))


def test_plscf_input_checks() -> None:
    h = np.ones((2, 1, 10), complex)
    f = np.arange(1.0, 11.0)
    with pytest.raises(InputError, match="max_order"):
        plscf(f, h, 20)
    with pytest.raises(ShapeError, match="H"):
        plscf(f, h[:, :, :5], 2)
    with pytest.raises(InputError, match="band"):
        plscf(f, h, 2, band=(5.0, 2.0))
    with pytest.raises(InputError, match="min_fraction"):
        cluster_poles(
            plscf(F, chain_system().frf(F).H, 4),
            stability_flags(plscf(F, chain_system().frf(F).H, 4)),
            min_fraction=0.0,
        )


def _direct_lscf_poles(f: np.ndarray, h: np.ndarray, p: int) -> np.ndarray:
    """Poles of order ``p`` from the stacked linear least-squares problem (one input).

    Unknowns: real ``beta_o0..beta_op`` per output and ``alpha_0..alpha_{p-1}``
    (``alpha_p = 1``); equation error ``B_o(z) - H_o(f) A(z)`` on every line,
    real and imaginary parts stacked. Independent of the normal-equation code.
    """
    n_out = h.shape[0]
    lo, hi = f[0], f[-1]
    dt = 0.5 / (hi - lo)
    z = np.exp(1j * 2 * np.pi * (f - lo) * dt)
    zp = z[:, None] ** np.arange(p + 1)[None, :]
    n_f = f.size
    rows = []
    rhs = []
    for o in range(n_out):
        blk = np.zeros((n_f, n_out * (p + 1) + p), complex)
        blk[:, o * (p + 1) : (o + 1) * (p + 1)] = zp
        blk[:, n_out * (p + 1) :] = -h[o, 0][:, None] * zp[:, :p]
        rows.append(blk)
        rhs.append(h[o, 0] * zp[:, p])
    a = np.concatenate(rows)
    b = np.concatenate(rhs)
    ab = np.vstack([a.real, a.imag])
    x = np.linalg.lstsq(ab, np.concatenate([b.real, b.imag]), rcond=None)[0]
    alpha = np.concatenate([x[n_out * (p + 1) :], [1.0]])
    zr = np.roots(alpha[::-1])
    zr = zr[zr.imag > 0]
    return 1j * 2 * np.pi * lo + np.log(zr) / dt


def test_plscf_equals_the_stacked_least_squares_problem_with_many_outputs() -> None:
    # 40 outputs > 2 * 6 + 1 lag sums: the Gram-reduced normal equations are used
    rng = np.random.default_rng(2)
    f = np.linspace(2.0, 38.0, 300)
    sys_ = chain_system()
    h = sys_.frf(f, inputs=[0]).H
    h = np.concatenate([h * rng.normal(size=(1, 1, 1)) for _ in range(7)])[:40]
    h = h + 1e-3 * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    ps = plscf(f, h, 6, min_order=2, output_weights=np.ones(h.shape[0]))
    for p in (2, 4, 6):
        got = np.sort_complex(ps.poles[ps.at_order(p)])
        ref = np.sort_complex(_direct_lscf_poles(f, h, p))
        assert_allclose(got, ref, rtol=1e-8)


def test_plscf_order_step_counts_down_from_the_highest_order() -> None:
    h = chain_system().frf(F, inputs=[0]).H
    ps = plscf(F, h, 24, min_order=5, order_step=3)
    assert ps.orders.tolist() == [6, 9, 12, 15, 18, 21, 24]
    assert set(np.unique(ps.order)) <= set(ps.orders.tolist())
    full = plscf(F, h, 24, min_order=5)
    for p in (6, 15, 24):  # the same orders give the same poles
        assert_allclose(
            np.sort_complex(ps.poles[ps.at_order(p)]),
            np.sort_complex(full.poles[full.at_order(p)]),
            rtol=1e-9,
        )
    # stability is judged against the previous computed order
    flags = stability_flags(ps)
    kept, _ = cluster_poles(ps, flags)
    assert len(kept) == chain_system().complex_modes().poles.size
    for bad in (0, -2, 1.5, "2", True):
        with pytest.raises(InputError, match="order_step"):
            plscf(F, h, 24, order_step=bad)  # type: ignore[arg-type]


def _span_share(v: np.ndarray, vecs: np.ndarray) -> float:
    """Share of |v|^2 in the span of the rows of ``vecs`` (singular values >= 0.1 max)."""
    u, sv, _ = np.linalg.svd(vecs.T, full_matrices=False)
    q = u[:, sv >= 0.1 * sv[0]]
    return float(np.linalg.norm(q.conj().T @ v) ** 2 / np.linalg.norm(v) ** 2)


def _rule3_distance(
    p: np.ndarray, lv: np.ndarray, od: np.ndarray, cut: float = 0.01, repeated: bool = False
) -> np.ndarray:
    """Dense rule-3 distance matrix (1e6 for two poles of the same order); with
    ``repeated``, the participation term of a repeated root: a pole's twins are the
    poles of its order within the cut and half a half-width of it, and an edge's MAC
    is the larger share of either pole's vector in the span of its partner and the
    partner's twins."""
    d = np.abs(p[:, None] - p[None, :]) / np.maximum(np.abs(p)[:, None], np.abs(p)[None, :])
    if lv.shape[1] > 1 and not repeated:
        d = d + 1 - mac(lv.T, lv.T)
    elif lv.shape[1] > 1:
        m = mac(lv.T, lv.T)
        half = np.minimum(np.abs(p.real)[:, None], np.abs(p.real)[None, :])
        twin = (
            (od[:, None] == od[None, :])
            & (d <= cut)
            & (np.abs(p[:, None] - p[None, :]) <= 0.5 * half)
        )
        np.fill_diagonal(twin, False)
        for i in np.flatnonzero(twin.any(axis=1)):
            span = lv[np.append(i, np.flatnonzero(twin[i]))]
            for j in np.flatnonzero((od != od[i]) & (d[i] <= cut)):
                share = _span_share(lv[j], span)
                m[i, j] = m[j, i] = max(m[i, j], share)
        d = d + 1 - m
    d = np.where(od[:, None] == od[None, :], 1e6, d)
    np.fill_diagonal(d, 0.0)
    return np.clip(0.5 * (d + d.T), 0, 1e6)


def _one_linkage(ps: PoleSet, flags: StabilityFlags, cut: float = 0.01) -> list[tuple[int, ...]]:
    """Reference clusters: one complete linkage over all stable poles, cut at ``cut``
    (then, with several inputs, the poles of a repeated root split linkage into more
    clusters than its multiplicity regrouped by ``_repeated_slots``, tested apart)."""
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    from tyredamp.modal.poles.selection import _repeated_slots

    idx = np.flatnonzero(flags.stable)
    p, lv, od = ps.poles[idx], ps.participation[idx], ps.order[idx]

    def link(sel: np.ndarray, repeated: bool) -> np.ndarray:
        d = _rule3_distance(p[sel], lv[sel], od[sel], cut, repeated)
        return fcluster(
            linkage(squareform(d, checks=False), "complete"), t=cut, criterion="distance"
        )

    lab = link(np.arange(idx.size), False)
    if lv.shape[1] > 1:  # the poles of clusters spanning < 30 % of the orders, again
        n_ord = np.array([np.unique(od[lab == k]).size for k in range(lab.max() + 1)])
        rest = np.flatnonzero(n_ord[lab] < 0.3 * ps.orders.size)
        if rest.size > 1:
            sub = _repeated_slots(p[rest], od[rest], link(rest, True) - 1)
            lab[rest] = lab.max() + 1 + sub
    return sorted(tuple(idx[lab == k].tolist()) for k in np.unique(lab))


def test_clusters_equal_one_complete_linkage() -> None:
    sys_ = chain_system()
    rng = np.random.default_rng(8)
    h = sys_.frf(F, inputs=[0, 3]).H
    h = h + 0.02 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    ps = plscf(F, h, 30)
    flags = stability_flags(ps, max_damping=0.5)
    kept, rej = cluster_poles(ps, flags)
    ref = _one_linkage(ps, flags)
    got = sorted(tuple(c.members.tolist()) for c in kept + rej)
    assert len(ref) > 5
    assert got == ref
    for c in kept + rej:  # representative: median frequency and damping of the members
        fn = np.abs(ps.poles[c.members]) / (2 * np.pi)
        assert c.frequency_hz == pytest.approx(np.median(fn), rel=1e-12)
        assert c.fraction == np.unique(ps.order[c.members]).size / ps.orders.size


@pytest.mark.parametrize("n_in", [1, 2])
def test_clusters_of_a_dense_pole_cloud_equal_one_complete_linkage(n_in: int) -> None:
    # 12 orders of 25 jittered modes (each present at 80 % of the orders) and 30
    # spurious poles, all in 40-60 Hz: ~550 poles, almost no gap of |p| above the cut
    rng = np.random.default_rng(30 + n_in)
    orders = np.arange(20, 44, 2)
    f0, z0 = rng.uniform(40, 60, 25), rng.uniform(0.01, 0.05, 25)
    l0 = rng.normal(size=(25, n_in)) + 1j * rng.normal(size=(25, n_in))
    od, f, z, lv = [], [], [], []
    for o in orders:
        m = rng.random(25) < 0.8
        f += [f0[m] * (1 + 0.002 * rng.normal(size=m.sum())), rng.uniform(40, 60, 30)]
        z += [z0[m] + 0.001 * rng.normal(size=m.sum()), rng.uniform(0.005, 0.15, 30)]
        noise = rng.normal(size=(m.sum() + 30, n_in)) + 1j * rng.normal(size=(m.sum() + 30, n_in))
        lv.append(np.concatenate([l0[m], np.zeros((30, n_in))]) + 0.03 * noise)
        lv[-1][m.sum() :] = noise[m.sum() :]
        od.append(np.full(m.sum() + 30, o))
    w, zz = 2 * np.pi * np.concatenate(f), np.abs(np.concatenate(z))
    ps = PoleSet(
        order=np.concatenate(od),
        poles=-zz * w + 1j * w * np.sqrt(1 - zz**2),
        participation=np.concatenate(lv) / np.linalg.norm(np.concatenate(lv), axis=1)[:, None],
        orders=orders,
        band_hz=(40.0, 60.0),
    )
    n = ps.poles.size
    stable = rng.random(n) < 0.95
    flags = StabilityFlags(*(4 * [stable]))
    mag = np.sort(np.abs(ps.poles[stable]))
    assert n > 500
    assert np.count_nonzero(mag[1:] / mag[:-1] - 1 > 0.01) <= 2  # few gaps to split at
    kept, rej = cluster_poles(ps, flags)
    got = sorted(tuple(c.members.tolist()) for c in kept + rej)
    ref = _one_linkage(ps, flags)
    assert got == ref
    assert sum(len(c) >= 5 for c in ref) >= 15  # the modes
    assert len(kept) >= 15


def test_threshold_edges_hold_every_pair_within_the_cut() -> None:
    from tyredamp.modal.poles.selection import _threshold_edges

    # clumps of poles all around the circle (arg p wraps at -pi/pi) over a decade of |p|
    rng = np.random.default_rng(4)
    centre = np.exp(rng.uniform(0, np.log(10), 80) + 1j * rng.uniform(-np.pi, np.pi, 80))
    centre[:4] = [-1 + 1e-3j, -1 - 1e-3j, -3 + 0j, -3 - 2e-3j]  # on either side of the wrap
    p = np.repeat(centre, 5) * (1 + 0.004 * (rng.normal(size=400) + 1j * rng.normal(size=400)))
    od = rng.integers(0, 8, 400)
    for n_in in (1, 2):
        lv = rng.normal(size=(400, n_in)) + 1j * rng.normal(size=(400, n_in))
        lv[1::2] = lv[::2] + 0.05 * rng.normal(size=(200, n_in))  # MAC near 1 for half the pairs
        for cut, repeated in [(c, r) for c in (0.01, 0.05, 0.5, 1.5) for r in (False, True)]:
            d_ref = _rule3_distance(p, lv, od, cut, repeated)
            i, j, d = _threshold_edges(p, lv, od, cut, repeated)
            ri, rj = np.nonzero(np.triu(d_ref <= cut, 1))
            assert ri.size > 50
            o = np.lexsort((j, i))
            assert_array_equal(i[o], ri)
            assert_array_equal(j[o], rj)
            assert_allclose(d[o], d_ref[ri, rj], rtol=1e-12, atol=1e-14)


def test_aberth_roots_equal_companion_eigenvalues() -> None:
    from tyredamp.modal.poles.lscf import _aberth

    rng = np.random.default_rng(4)
    # roots near the unit circle (poles), a few far inside and outside, real pairs
    r = np.concatenate(
        [
            rng.uniform(0.9, 0.99, 12) * np.exp(1j * np.linspace(0.2, 2.9, 12)),
            [0.2 + 0.1j, 3.0 + 1.0j, 40.0 + 5.0j],
        ]
    )
    roots = np.concatenate([r, r.conj(), [0.5, -2.0]])
    c = np.real(np.poly(roots))[::-1]  # ascending, leading coefficient 1
    # starting values: the roots of a nearby polynomial of lower degree
    guess = np.sort_complex(roots)[2:] * (1 + 1e-3 * rng.normal(size=roots.size - 2))
    got = _aberth(c, guess)
    assert got is not None
    ref = np.roots(c[::-1])
    d = np.abs(np.sort_complex(got)[:, None] - ref[None, :]).min(axis=1)
    assert np.all(d <= 1e-9 * np.maximum(np.abs(np.sort_complex(got)), 1.0))
    # no convergence -> None (the caller falls back to the eigenvalues)
    assert _aberth(c, guess, max_iter=1) is None
    assert _aberth(c, np.zeros(roots.size + 1, complex)) is None  # more guesses than roots


def test_plscf_aberth_orders_equal_eigenvalue_orders(monkeypatch: pytest.MonkeyPatch) -> None:
    import tyredamp.modal.poles.lscf as lscf_mod

    rng = np.random.default_rng(6)
    h = chain_system().frf(F, inputs=[0]).H
    h = h + 0.01 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    monkeypatch.setattr(lscf_mod, "_ABERTH_MIN_ORDER", 10**9)
    ref = plscf(F, h, 60, min_order=15, order_step=2)
    monkeypatch.setattr(lscf_mod, "_ABERTH_MIN_ORDER", 16)
    got = plscf(F, h, 60, min_order=15, order_step=2)
    assert got.poles.size == ref.poles.size
    for p in ref.orders:
        a = np.sort_complex(ref.poles[ref.at_order(p)])
        b = np.sort_complex(got.poles[got.at_order(p)])
        assert_allclose(b, a, rtol=1e-9)


def test_companion_eigvals_equal_numpy_eigvals_of_the_companion() -> None:
    from tyredamp.modal.poles.lscf import _companion, _companion_eigvals

    rng = np.random.default_rng(11)
    # one input: the roots of a polynomial built from known roots (closed form)
    r = rng.uniform(0.5, 0.99, 9) * np.exp(1j * rng.uniform(0.1, 3.0, 9))
    roots = np.concatenate([r, r.conj(), [0.3, -0.7]])
    alpha = np.real(np.poly(roots))[::-1][:-1, None]  # alpha_0..alpha_{p-1}, alpha_p = 1
    got = np.sort_complex(_companion_eigvals(alpha, 1))
    assert_allclose(got, np.sort_complex(roots), rtol=1e-10)
    # any number of inputs: the eigenvalues of the block companion matrix
    for n_in, p in ((1, 3), (1, 40), (2, 7), (3, 5)):
        alpha = rng.normal(size=(p * n_in, n_in))
        ref = np.linalg.eigvals(_companion(alpha, n_in))
        got = _companion_eigvals(alpha, n_in)
        assert got.shape == ref.shape
        d = np.abs(got[:, None] - ref[None, :]).min(axis=1)
        assert np.all(d <= 1e-10 * np.maximum(np.abs(got), 1.0))
    with pytest.raises(np.linalg.LinAlgError):  # as np.linalg.eigvals
        _companion_eigvals(np.array([[np.nan], [1.0]]), 1)


def test_aberth_any_degree_equals_companion_eigenvalues() -> None:
    from tyredamp.modal.poles.lscf import _aberth, _companion

    rng = np.random.default_rng(12)
    # degrees at and around the block lengths of the evaluation (b = isqrt(n) + 1).
    # Random coefficients: roots around the unit circle, about half outside it
    # (reversed evaluation), well conditioned as in the stabilisation diagrams
    for n in (1, 2, 3, 4, 8, 15, 16, 24, 63, 80, 121):
        c = np.append(rng.normal(size=n), 1.0)
        ref = np.linalg.eigvals(_companion(c[:-1, None], 1))
        # starting values: the roots of a nearby polynomial of degree n - 2
        keep = max(n - 2, 0)
        guess = ref[:keep] * (1 + 1e-3 * rng.normal(size=keep))
        got = _aberth(c, guess)
        assert got is not None
        assert got.size == n
        d = np.abs(got[:, None] - ref[None, :]).min(axis=1)
        assert np.all(d <= 1e-11 * np.maximum(np.abs(got), 1.0)), n
        d = np.abs(ref[:, None] - got[None, :]).min(axis=1)  # every root found
        assert np.all(d <= 1e-11 * np.maximum(np.abs(ref), 1.0)), n


def test_unit_powers_equal_cosine_and_sine() -> None:
    from tyredamp.modal.poles.lscf import _unit_powers

    theta = np.linspace(0.0, np.pi, 333)
    eps = np.finfo(float).eps
    for p in (0, 1, 2, 5, 8, 61, 120):
        zc, zs = _unit_powers(theta, p)
        d = np.arange(p + 1)
        ph = np.outer(d, theta)
        assert zc.shape == zs.shape == (p + 1, theta.size)
        # the reference cos(d theta) carries the rounding of d * theta itself
        tol = ((d * np.pi + 8) * eps)[:, None]
        assert np.all(np.abs(zc - np.cos(ph)) <= tol)
        assert np.all(np.abs(zs - np.sin(ph)) <= tol)
    zc, zs = _unit_powers(theta, 1)
    assert np.array_equal(zc, np.vstack([np.ones_like(theta), np.cos(theta)]))
    assert np.array_equal(zs, np.vstack([np.zeros_like(theta), np.sin(theta)]))


def test_plscf_cholesky_fallback_gives_the_same_poles(monkeypatch: pytest.MonkeyPatch) -> None:
    import tyredamp.modal.poles.lscf as lscf_mod

    rng = np.random.default_rng(13)
    h = chain_system().frf(F, inputs=[0, 3]).H
    h = h + 0.01 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    ref = plscf(F, h, 20, min_order=4)

    def failing_dposv(a: np.ndarray, b: np.ndarray, **kw: object) -> tuple:
        return a, b, 1  # "not positive definite": the LU solve takes over

    monkeypatch.setattr(lscf_mod.sla.lapack, "dposv", failing_dposv)
    got = plscf(F, h, 20, min_order=4)
    assert got.poles.size == ref.poles.size
    for p in ref.orders:
        a = np.sort_complex(ref.poles[ref.at_order(p)])
        b = np.sort_complex(got.poles[got.at_order(p)])
        assert_allclose(b, a, rtol=1e-9)
    # singular normal equations (no signal): least squares, then no pole at all
    with pytest.raises(InputError, match="no pole"):
        plscf(F, np.zeros((2, 1, F.size), complex), 4)


def test_det_coefficients_equal_the_two_by_two_determinant() -> None:
    """``det A(z) = a11 a22 - a12 a21`` of a 2 x 2 matrix polynomial, the products of
    polynomials by ``np.convolve`` (an independent route)."""
    from tyredamp.modal.poles.lscf import _det_coefficients

    rng = np.random.default_rng(4)
    p = 7
    alpha = rng.normal(size=(p * 2, 2))
    a = np.concatenate([alpha.reshape(p, 2, 2), np.eye(2)[None]])  # a[r] = alpha_r
    exact = np.convolve(a[:, 0, 0], a[:, 1, 1]) - np.convolve(a[:, 0, 1], a[:, 1, 0])
    # FFT interpolation: round-off of the largest value on the unit circle
    assert_allclose(_det_coefficients(alpha, 2), exact, rtol=0, atol=1e-12 * np.abs(exact).max())


@pytest.mark.parametrize("n_in", [2, 3])
def test_plscf_aberth_orders_equal_eigenvalue_orders_several_inputs(
    monkeypatch: pytest.MonkeyPatch, n_in: int
) -> None:
    """With several inputs the sweeps on ``det A(z)`` find the block companion's
    eigenvalues: every pole of every order the same to round-off."""
    import tyredamp.modal.poles.lscf as lscf_mod

    rng = np.random.default_rng(8)
    h = chain_system().frf(F, inputs=list(range(n_in))).H
    h = h + 0.01 * np.abs(h).mean() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    monkeypatch.setattr(lscf_mod, "_ABERTH_MIN_ORDER", 10**9)
    ref = plscf(F, h, 40, min_order=10, order_step=2)
    monkeypatch.setattr(lscf_mod, "_ABERTH_MIN_ORDER", 16)
    calls = []
    aberth = lscf_mod._aberth
    monkeypatch.setattr(lscf_mod, "_aberth", lambda c, g: calls.append(1) or aberth(c, g))
    got = plscf(F, h, 40, min_order=10, order_step=2)
    assert len(calls) > 5  # the sweeps ran (not the eigenvalue fallback alone)
    assert got.poles.size == ref.poles.size
    for p in ref.orders:
        ia, ib = ref.at_order(p), got.at_order(p)
        oa, ob = np.argsort(ref.poles[ia]), np.argsort(got.poles[ib])  # same order
        a, b = ref.poles[ia][oa], got.poles[ib][ob]
        # roots to ~1e-13 relative; poles (log of z) as those of one input's test
        assert_allclose(b, a, rtol=1e-9)
        # participation from the same A(z) at roots equal to ~1e-13: its null
        # vector moves by that over the gap of the two singular values
        pa, pb = ref.participation[ia][oa], got.participation[ib][ob]
        assert_allclose(pb, pa, atol=1e-6)
