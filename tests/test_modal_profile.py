"""Likelihood intervals of f and zeta (modal.fit.profile): the linearised interval in
the linear limit, the likelihood-ratio cut at their ends (checked against an
independent profile of a hand-written model), the rule of which modes are
profiled, and the intervals in the identified model and its JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import least_squares

from tyredamp.cli.modal import modes_table
from tyredamp.frf import FRF
from tyredamp.modal import identify_modes
from tyredamp.modal.fit import profile as prof
from tyredamp.modal.fit.fit import ModalFitter, pole_bounds
from tyredamp.modal.model import ModalModel

F = np.arange(40.0, 60.0, 0.075)
W1 = 2 * np.pi * 50.0
ZETA = 0.01
POLES = np.array([complex(-ZETA * W1, W1), complex(-ZETA * W1, W1) * (1 + ZETA)])


def _data(weak: float, sd: float, seed: int, kind: str = "complex") -> tuple[np.ndarray, float]:
    """Two modes one half-power half-width apart, the second ``weak`` times the first
    (complex modes, or real ones: residues ``phi phi / (2 i Omega)``, real ``phi``, here
    scaled by ``2 Omega``)."""
    rng = np.random.default_rng(1)
    if kind == "complex":
        psi = (rng.normal(size=(4, 2)) + 1j * rng.normal(size=(4, 2))) * np.array([1.0, weak])
        part = np.ones((1, 2)) + 0j
    else:
        unit = np.abs(np.sqrt(2j * POLES.imag)) / np.sqrt(2j * POLES.imag)
        psi = rng.normal(size=(4, 2)) * np.array([1.0, weak]) * unit  # R = -i phi (scaled)
        part = np.ones((1, 2)) * unit
    h = ModalModel(POLES, psi, part).frf(F, "receptance").H
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return h + sd * e, sd


def _fit(h: np.ndarray, sd: float, kind: str = "complex") -> tuple[ModalFitter, object]:
    fit = ModalFitter(F, h, 0, kind, [], upper=False, lower=False)
    res = fit.fit(POLES, np.ones((2, 1)), passes=1, sigma=np.full(4, sd), tol=1e-10)
    return fit, res


def _intervals(h: np.ndarray, sd: float, kind: str = "complex") -> tuple[object, prof.Intervals]:
    """The likelihood intervals of the whole fit (its own cost profiled)."""
    fit, res = _fit(h, sd, kind)
    ref = np.zeros(2, np.intp)
    th = fit.pack(res.poles, res.participation, ref)
    s2 = res.cost / (res.n_obs - res.n_par)
    std = (res.std_frequency_hz, res.std_damping_ratio, res.std_pole)
    ev = prof.fitter_cost(fit, 2, ref, fit.weights(np.full(4, sd)))
    iv = prof.likelihood_intervals(
        ev, th, res.poles, std, 2, fit.w_ref, (res.cost, s2), pole_bounds(2, th.size)
    )
    return res, iv


def _local(h: np.ndarray, sd: float, kind: str = "complex") -> tuple[object, prof.Intervals]:
    """The intervals of the final stage (each mode profiled on its own lines)."""
    fit, res = _fit(h, sd, kind)
    iv = prof.fit_intervals(fit, res, 2, np.full(4, sd))
    assert iv is not None
    return res, iv


def _pole(wn: float, z: float) -> complex:
    return complex(-z * wn, wn * np.sqrt(1 - z * z))


def _profile_rise(
    h: np.ndarray, sd: float, k: int, which: str, value: float, kind: str = "complex"
) -> float:
    """The rise of the weighted cost, in units of the residual variance, when mode
    ``k``'s natural frequency (Hz) or damping ratio is held at ``value`` and every
    other pole parameter refitted, the residues solved by least squares: written
    here from the model ``sum_n R_n / (s - p_n) + conj(R_n) / (s - conj p_n)``
    (``R_n = a + i b`` per output: real columns ``1/(s-p) + 1/(s-conj p)`` and
    ``i (1/(s-p) - 1/(s-conj p))``; for real modes ``R_n = -i a / (2 Omega_n)``
    with real ``a``: the one column ``i (1/(s-p) - 1/(s-conj p))``) with scipy's
    least squares, without the package's fitter."""
    s = 2j * np.pi * F
    y = (h[:, 0, :] / sd).T  # (n_f, n_out), units of the noise
    yr = np.vstack([y.real, y.imag])

    def cost(x: np.ndarray) -> float:  # x = (wn_0, z_0, wn_1, z_1)
        cols = []
        for n in range(2):
            p = _pole(x[2 * n], x[2 * n + 1])
            u, v = 1 / (s - p), 1 / (s - np.conj(p))
            cols += [u + v, 1j * (u - v)] if kind == "complex" else [1j * (u - v)]
        a = np.stack(cols, axis=1)
        ar = np.vstack([a.real, a.imag])
        c, *_ = np.linalg.lstsq(ar, yr, rcond=None)
        r = yr - ar @ c
        return float(np.sum(r * r))

    _, res = _fit(h, sd, kind)
    x_hat = np.ravel(np.column_stack([np.abs(res.poles), -res.poles.real / np.abs(res.poles)]))
    scale = np.array([1.0, 1e-3, 1.0, 1e-3])
    opt = {"x_scale": scale, "xtol": 1e-15, "ftol": 1e-15, "gtol": 1e-15}
    c0 = float(least_squares(lambda x: [np.sqrt(cost(x))], x_hat, **opt).fun[0] ** 2)
    j = 2 * k + (0 if which == "f" else 1)
    held = 2 * np.pi * value if which == "f" else value
    free = np.arange(4) != j

    def full(z: np.ndarray) -> np.ndarray:
        x = np.empty(4)
        x[free], x[j] = z, held
        return x

    opt["x_scale"] = scale[free]
    c1 = least_squares(lambda z: [np.sqrt(cost(full(z)))], x_hat[free], **opt).fun[0] ** 2
    # 4 (complex) or 2 (real modes) real residue coefficients per output, 4 pole parameters
    dof = 2 * F.size * 4 - (4 if kind == "complex" else 2) * 4 - 4
    return (float(c1) - c0) / (c0 / dof)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_the_ends_are_the_likelihood_ratio_cut_of_an_independent_profile(kind: str) -> None:
    # a weak mode (statistic about 100) one half-width above a strong one at a
    # noise of 5 % of the strong mode's peak response: both modes are profiled
    h, sd = _data(0.3, 0.05, seed=5, kind=kind)
    _, iv = _intervals(h, sd, kind)
    assert iv.likelihood.all()
    assert not iv.open.any()
    lo, hi = (prof.Z95 - prof.R_TOL) ** 2 - 0.01, (prof.Z95 + prof.R_TOL) ** 2 + 0.01
    for k in (0, 1):
        for which, ends in (("f", iv.frequency_hz[k]), ("z", iv.damping_ratio[k])):
            for v in ends:
                rise = _profile_rise(h, sd, k, which, float(v), kind)
                # signed root within R_TOL of 1.96 (1.94^2 = 3.76 .. 1.98^2 = 3.92), and
                # the independent profile's own convergence (1e-3 of the cut)
                assert lo <= rise <= hi


def test_in_the_linear_limit_the_likelihood_interval_is_the_linearised_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a tiny noise: the pole's standard error is 1e-4 half-widths, where the model is
    # linear in it; profiled anyway (KAPPA 0), the ends are the linearised ones
    monkeypatch.setattr(prof, "KAPPA", 0.0)
    h, sd = _data(0.3, 1e-5, seed=6)
    res, iv = _intervals(h, sd)
    assert iv.likelihood.all()
    f_hat = np.abs(res.poles) / (2 * np.pi)
    z_hat = -res.poles.real / np.abs(res.poles)
    for ends, hat, s in (
        (iv.frequency_hz, f_hat, res.std_frequency_hz),
        (iv.damping_ratio, z_hat, res.std_damping_ratio),
    ):
        # each end within 2 % of the half-width (R_TOL / 1.96 = 1 % plus the curvature)
        assert_half = np.abs(ends - (hat[:, None] + np.array([-1, 1]) * prof.Z95 * s[:, None]))
        assert np.all(assert_half <= 0.02 * prof.Z95 * s[:, None])


def test_which_modes_are_profiled() -> None:
    p = np.array([complex(-2.0, 300.0), complex(-2.0, 320.0), complex(-2.0, 340.0)])
    # standard errors of 0.5 %, 2 % (imaginary part) and NaN of the half-width 2 rad/s
    sd = np.array([0.01 + 0.01j, 0.01 + 0.04j, complex(np.nan, np.nan)])
    assert list(prof.needs_profile(p, sd)) == [False, True, False]


def test_a_failed_profile_leaves_the_linearised_interval(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(prof, "_profile_cost", lambda *a, **k: None)
    h, sd = _data(0.3, 0.05, seed=5)
    res, iv = _intervals(h, sd)
    assert not iv.likelihood.any()
    f_hat = np.abs(res.poles[:2]) / (2 * np.pi)
    np.testing.assert_allclose(iv.frequency_hz[:, 1], f_hat + prof.Z95 * res.std_frequency_hz)


@pytest.mark.parametrize("given_variance", [False, True])
def test_identified_model_reports_the_intervals(given_variance: bool) -> None:
    h, sd = _data(0.3, 0.05, seed=7)
    frf = FRF(F, h, kind="receptance")
    var = np.full(h.shape, sd**2) if given_variance else None
    m = identify_modes(frf, model="complex", variance=var).models["complex"]
    assert m.n_modes == 2
    fi = np.asarray(m.meta["interval_frequency_hz"])
    zi = np.asarray(m.meta["interval_damping_ratio"])
    assert m.meta["interval_method"] == ["likelihood", "likelihood"]
    if given_variance:  # the maximum-likelihood fit's own cost was profiled
        assert m.meta["refinement"].startswith("maximum likelihood")
    assert np.all(fi[:, 0] < m.frequency_hz)
    assert np.all(m.frequency_hz < fi[:, 1])
    assert np.all(zi[:, 0] < m.damping_ratio)
    assert np.all(m.damping_ratio < zi[:, 1])
    # the standard error is the half-width of the symmetric interval that holds it
    half = np.max(np.abs(fi - m.frequency_hz[:, None]), axis=1)
    np.testing.assert_allclose(m.std["frequency_hz"], half / prof.Z95, rtol=1e-12)
    half_z = np.max(np.abs(zi - m.damping_ratio[:, None]), axis=1)
    np.testing.assert_allclose(m.std["damping_ratio"], half_z / prof.Z95, rtol=1e-12)
    # the command line's table gives them
    table = "\n".join(modes_table("complex", m))
    assert "mode 2: 95 % likelihood interval f [" in table
    # strict JSON, and read back
    d = json.loads(json.dumps(m.to_dict(), allow_nan=False))
    back = ModalModel.from_dict(d)
    np.testing.assert_allclose(back.meta["interval_frequency_hz"], fi)
    assert back.meta["interval_method"] == ["likelihood", "likelihood"]


@pytest.mark.parametrize("seed", [5, 6, 10])
def test_the_profile_on_a_modes_own_lines_gives_the_whole_profiles_ends(seed: int) -> None:
    # fit_intervals profiles each mode on its own lines (the modes beyond them
    # subtracted) and carries the factor onto the whole fit's standard errors; its
    # ends lie within 0.2 half-widths of the whole profile's, closer than the
    # linearised ends (0.04-0.46 half-widths off on these data) in sum
    h, sd = _data(0.3 if seed != 10 else 0.25, 0.05, seed=seed)
    res, whole = _intervals(h, sd)
    _, local = _local(h, sd)
    assert whole.likelihood.all()
    assert local.likelihood.all()
    gap_local = gap_lin = 0.0
    lin_f, lin_z = prof._linearised(res.poles, res.std_frequency_hz, res.std_damping_ratio)
    for got, ref, lin in (
        (local.frequency_hz, whole.frequency_hz, lin_f),
        (local.damping_ratio, whole.damping_ratio, lin_z),
    ):
        half = 0.5 * (ref[:, 1] - ref[:, 0])[:, None]
        assert np.all(np.abs(got - ref) <= 0.2 * half)
        gap_local += float(np.sum(np.abs(got - ref) / half))
        gap_lin += float(np.sum(np.abs(lin - ref) / half))
    assert gap_local < gap_lin


def test_modes_not_told_apart_have_intervals_that_hold_each_other() -> None:
    # two modes of equal strength one half-width apart at a noise where each one's
    # frequency error is a tenth of the half-width: pushed toward the other, a
    # mode's profile dips where the two trade places, and its interval holds the
    # other's frequency (the linearised intervals do not)
    h, sd = _data(0.5, 0.05, seed=8)
    res, iv = _intervals(h, sd)
    assert iv.likelihood.all()
    f_hat = np.abs(res.poles) / (2 * np.pi)
    assert iv.frequency_hz[0, 1] > f_hat[1]
    assert iv.frequency_hz[1, 0] < f_hat[0]
    lin_f, _ = prof._linearised(res.poles, res.std_frequency_hz, res.std_damping_ratio)
    assert lin_f[0, 1] < f_hat[1]
    assert lin_f[1, 0] > f_hat[0]
    # the identified model says so
    m = identify_modes(FRF(F, h, kind="receptance"), model="complex").models["complex"]
    assert m.n_modes == 2
    assert m.meta["interval_method"] == ["likelihood, not told from a neighbour"] * 2


def test_real_modes_get_likelihood_intervals_too() -> None:
    # the real-mode model (proportional damping, spec eq. [2]/[3]) of the same weak
    # mode beside a strong one: profiled on the mode's own lines with the real-mode
    # fitter, within 0.2 half-widths of the whole fit's profile, and reported by the
    # identified real model (it kept the linearised intervals before)
    h, sd = _data(0.3, 0.05, seed=5, kind="real")
    _, whole = _intervals(h, sd, "real")
    _, local = _local(h, sd, "real")
    assert whole.likelihood.all()
    assert local.likelihood.all()
    for got, ref in (
        (local.frequency_hz, whole.frequency_hz),
        (local.damping_ratio, whole.damping_ratio),
    ):
        half = 0.5 * (ref[:, 1] - ref[:, 0])[:, None]
        assert np.all(np.abs(got - ref) <= 0.2 * half)
    m = identify_modes(FRF(F, h, kind="receptance"), model="both").models["real"]
    assert m.n_modes == 2
    assert m.meta["interval_method"] == ["likelihood", "likelihood"]
    fi = np.asarray(m.meta["interval_frequency_hz"])
    zi = np.asarray(m.meta["interval_damping_ratio"])
    assert np.all((fi[:, 0] < m.frequency_hz) & (m.frequency_hz < fi[:, 1]))
    assert np.all((zi[:, 0] < m.damping_ratio) & (m.damping_ratio < zi[:, 1]))
    half = np.max(np.abs(fi - m.frequency_hz[:, None]), axis=1)
    np.testing.assert_allclose(m.std["frequency_hz"], half / prof.Z95, rtol=1e-12)
