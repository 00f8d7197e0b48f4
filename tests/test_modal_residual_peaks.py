"""Where the residual search looks for missed modes (issue 16):
``modal.search.residual_peaks``.

* the residual power's noise mean from its median (chi-square scaling);
* broad structure that no 5-line window shows is found by the matched windows;
* the coherent scan's statistic equals the least-squares extra sum of squares
  of a pole's column added to the fitted modes' columns within its window,
  computed independently per FRF; its best candidate lies at a weak mode that
  the fit left out;
* with several inputs the fitted modes keep their rank-one residues (their
  participation held): the statistic equals the extra sum of squares of a
  rank-one trial residue over inputs x lines, computed with explicit
  Kronecker columns and a generalised eigenproblem; with one input it is the
  per-FRF statistic;
* a weak mode between two strong ones, with several inputs, is found by the
  identification (the scan froze every input's coefficient of the fitted modes
  and took up the weak mode's share).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats as sps

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel
from tyredamp.modal.fit._basis import factors
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.problem.problem import build_problem
from tyredamp.modal.search.residual_peaks import (
    SCAN_HALF,
    _off_fitted,
    _rank_one_off_fitted,
    _scan_statistic,
    noise_mean,
    residual_peaks,
    scan_of,
)


@pytest.mark.parametrize("k", [1, 4, 32])
def test_noise_mean_from_the_median_of_chi_square_lines(k: int) -> None:
    rng = np.random.default_rng(k)
    pw = 3.7 * sps.chi2.rvs(2 * k, size=200_000, random_state=rng) / 2
    assert noise_mean(pw, k) == pytest.approx(3.7 * k, rel=0.01)


def test_broad_structure_is_found_by_the_matched_windows() -> None:
    rng = np.random.default_rng(1)
    k = 8
    f = np.arange(10.0, 200.0, 0.05)
    pw = sps.chi2.rvs(2 * k, size=f.size, random_state=rng) / 2
    # a resonance's excess (Lorentzian, half-width 1.5 Hz) at 100 Hz: 120 noise
    # units in all, under 2 per line, so no 5-line window stands out of the noise
    bump = 1.0 / (1.0 + ((f - 100.0) / 1.5) ** 2)
    pw = pw + 120.0 * bump / bump.sum()
    threshold = 60.0
    five = np.convolve(pw, np.ones(5) / 5, mode="same")
    assert 5 * np.max(five[np.abs(f - 100) < 3] - np.median(five)) < 0.25 * threshold * 4
    got = residual_peaks(f, pw, k, 0.015, threshold, 12)
    assert np.any(np.abs(got.freq - 100.0) < 1.5)
    # pure noise: what the matched windows return stands within their noise
    clean = residual_peaks(f, pw - 120.0 * bump / bump.sum(), k, 0.015, threshold, 12)
    assert not np.any(np.abs(clean.freq - 100.0) < 1.5)


def _four_modes() -> tuple[FRF, ModalModel]:
    f = np.array([20.0, 41.0, 43.0, 80.0])
    z = np.array([0.01, 0.01, 0.03, 0.01])
    w = 2 * np.pi * f
    p = -z * w + 1j * w * np.sqrt(1 - z * z)
    rng = np.random.default_rng(7)
    psi = rng.normal(size=(5, 4)) + 0.3j * rng.normal(size=(5, 4))
    psi[:, 2] *= 0.08  # weak, broad, beside a strong mode
    true = ModalModel(p, psi, np.ones((1, 4)))
    fr = np.arange(10.0, 100.0, 0.05)
    h = true.frf(fr, "receptance").H
    sd = 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(fr, h + sd * e, kind="receptance"), true


def test_the_scan_is_the_extra_sum_of_squares_of_a_pole_beside_the_fitted_modes() -> None:
    frf, true = _four_modes()
    pr = build_problem(frf, (12.0, 95.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    keep = np.array([0, 1, 3])
    res = fit.fit(true.poles[keep], np.ones((3, 1), complex), refine=True)
    grid = scan_of(fit, res, 0.01)
    best = grid.candidates(0.0, 1)[0]
    p_g, t_g = best
    assert abs(abs(p_g) / (2 * np.pi) - 43.0) < 0.6  # the left-out mode
    # independently: per FRF, least squares of the residual on the fitted modes'
    # columns within the window, with and without the pole's column
    f = fit.f
    zg = -p_g.real / abs(p_g)
    fg = abs(p_g) / (2 * np.pi)
    win = (f >= fg - SCAN_HALF * zg * fg) & (f <= fg + SCAN_HALF * zg * fg)
    s, kap, _ = factors(fit, slice(None))
    s, kap = s[win], kap[win]
    wn = np.abs(res.poles.imag)
    near = res.poles[(wn >= 2 * np.pi * f[win][0]) & (wn <= 2 * np.pi * f[win][-1])]
    cols = [kap / (s - q) for q in near]
    b = np.stack(cols, axis=1) if cols else np.zeros((s.size, 0), complex)
    a = (kap / (s - p_g))[:, None]
    # the fit's residual written out: modal sum with conjugates, residual terms
    r = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    model = np.einsum("jkn,nl->jkl", r, kap[None, :] / (s[None, :] - res.poles[:, None]))
    model += np.einsum(
        "jkn,nl->jkl", np.conj(r), kap[None, :] / (s[None, :] - np.conj(res.poles)[:, None])
    )
    _, _, kap_low = factors(fit, slice(None))
    if res.upper is not None:
        model += res.upper[:, :, None] * kap[None, None, :]
    if res.lower is not None:
        model += res.lower[:, :, None] * kap_low[win][None, None, :]
    e = pr.H[:, 0, win] - model[:, 0, :]
    s2 = np.maximum(res.sigma_out**2, 1e-300)
    extra = 0.0
    for j in range(e.shape[0]):
        ss = []
        for basis in (b, np.hstack([b, a])):
            c, *_ = np.linalg.lstsq(basis, e[j], rcond=None)
            ss.append(float(np.sum(np.abs(e[j] - basis @ c) ** 2)))
        extra += (ss[0] - ss[1]) / s2[j]
    assert t_g == pytest.approx(extra, rel=1e-6)
    # and it clears the mode test's scale: a mode there lowers the cost by far more
    # than the noise of one pole's column
    assert t_g > 10 * 2 * 5


def _scan_case(n_out: int, n_in: int, seed: int) -> tuple[object, ...]:
    """Random residual, two fitted poles inside the windows and three trial columns."""
    rng = np.random.default_rng(seed)
    n_l = 120
    w = 2 * np.pi * np.linspace(40.0, 60.0, n_l)
    s = 1j * w
    kap = np.ones(n_l, complex)
    near = np.array([-2.0 + 2j * np.pi * 47.0, -3.0 + 2j * np.pi * 53.0])
    l_near = rng.normal(size=(2, n_in)) + 1j * rng.normal(size=(2, n_in))
    e = rng.normal(size=(n_out, n_in, n_l)) + 1j * rng.normal(size=(n_out, n_in, n_l))
    trial = 2j * np.pi * np.array([48.5, 50.0, 52.0]) - 1.5
    inside = np.zeros((3, n_l), bool)
    inside[0, 10:110] = True
    inside[1, 5:115] = True
    inside[2, 20:100] = True
    a = np.where(inside, kap[None, :] / (s[None, :] - trial[:, None]), 0.0)
    return e, a, inside, s, kap, near, l_near


@pytest.mark.parametrize(("n_out", "n_in"), [(3, 2), (5, 4), (2, 3)])
def test_the_scan_keeps_the_fitted_modes_rank_one_with_several_inputs(
    n_out: int, n_in: int
) -> None:
    from scipy import linalg as sla

    e, a, inside, s, kap, near, l_near = _scan_case(n_out, n_in, n_out * 10 + n_in)
    got = _rank_one_off_fitted(e, a, inside, s, kap, near, l_near)
    for g in range(a.shape[0]):
        win = inside[g]
        # per output the data over inputs x lines; the fitted modes' columns
        # l_n (x) b_n, the trial's l (x) a for each unit l
        v = np.stack([np.kron(l_near[n], kap[win] / (s[win] - near[n])) for n in range(2)], 1)
        u = np.stack([np.kron(np.eye(n_in)[k], a[g, win]) for k in range(n_in)], 1)
        u_off = u - v @ np.linalg.lstsq(v, u, rcond=None)[0]
        d = e[:, :, win].reshape(n_out, -1)  # (n_out, n_in * lines), input-major
        wd = u_off.conj().T @ d.T  # (n_in, n_out)
        want = sla.eigh(wd @ wd.conj().T, u_off.conj().T @ u_off, eigvals_only=True)[-1]
        assert got[g] == pytest.approx(want, rel=1e-8)


def test_the_rank_one_scan_of_one_input_is_the_per_frf_statistic() -> None:
    e, a, inside, s, kap, near, l_near = _scan_case(4, 1, 7)
    got = _rank_one_off_fitted(e, a, inside, s, kap, near, l_near)
    want = _scan_statistic(e, _off_fitted(a, inside, s, kap, near), 1)
    np.testing.assert_allclose(got, want, rtol=1e-9)
    # no fitted mode in the window: the plain rank-one statistic
    none = np.zeros(0, complex)
    np.testing.assert_allclose(
        _rank_one_off_fitted(e, a, inside, s, kap, none, l_near[:0]),
        _scan_statistic(e, a, 1),
        rtol=1e-9,
    )


def test_the_scan_sees_a_weak_mode_between_strong_ones_with_several_inputs() -> None:
    # a mode 13 times weaker between two strong ones, 4 inputs, 20 dB: the scan
    # of the fit without it reaches its held-pole statistic (the cost drop of a
    # mode at its true pole with every residue refitted); freeing every input's
    # coefficient of the fitted modes took up 60 % of it, below the scan's share
    # of the threshold for modes 2 times above it
    rng = np.random.default_rng(0)
    f = np.array([62.0, 72.53, 73.50, 74.83, 86.0])
    z = np.array([0.01, 0.0126, 0.0061, 0.0149, 0.01])
    amp = np.array([0.6, 0.53, 0.008, 1.1, 0.5])
    w = 2 * np.pi * f
    p = -z * w + 1j * w * np.sqrt(1 - z * z)
    n_out, n_in = 6, 4
    psi_out = (rng.normal(size=(n_out, 5)) + 1j * rng.normal(size=(n_out, 5))) * amp
    psi_in = rng.normal(size=(n_in, 5)) + 0.3j * rng.normal(size=(n_in, 5))
    frf = ModalModel(p, psi_out, psi_in).frf(np.arange(50.0, 100.0, 0.08), "mobility")
    rms = np.sqrt(np.mean(np.abs(frf.H) ** 2, axis=(1, 2), keepdims=True))
    e = (rng.normal(size=frf.H.shape) + 1j * rng.normal(size=frf.H.shape)) / np.sqrt(2)
    pr = build_problem(frf.with_H(frf.H + 0.1 * rms * e), (55.0, 95.0))
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    keep = np.array([0, 1, 3, 4])
    res = fit.fit(p[keep], psi_in.T[keep], refine=True)
    held = fit.fit(
        np.append(res.poles, p[2]),
        np.concatenate([res.participation, psi_in.T[2:3]]),
        refine=False,
    ).significance[-1]
    assert 150 < held < 500  # a few times the mode test's threshold
    grid = scan_of(fit, res, 0.01)
    near = np.abs(np.abs(grid.poles) / (2 * np.pi) - 73.5) < z[2] * 73.5
    assert np.max(grid.stat[near]) > 0.8 * held
