"""Identification and model choice (tyredamp.dampmodels.frffit, .choice, .fromodes)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import chi2

from tyredamp.dampmodels import (
    MODELS,
    DampedSystem,
    Exponential,
    Fractional,
    Hysteretic,
    ModelFit,
    Viscous,
    compare_models,
    exponential_from_modes,
    likelihood_ratio,
    start_from_modes,
)
from tyredamp.dampmodels.frffit import _jacobian, _names, _receptance, _unpack
from tyredamp.exceptions import InputError

M3 = np.diag([1.0, 2.0, 1.5])
K3 = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) * 1e4
C3 = np.array([[1.5, -0.6, 0.4], [-0.6, 1.2, 0.3], [0.4, 0.3, 0.9]])

TRUTHS = {
    "proportional": Viscous(M3 @ np.diag([0.0, 0.0, 0.0]) + 2e-4 * K3),
    "viscous": Viscous(C3),
    "hysteretic": Hysteretic.loss_factor(K3, 0.04),
    "exponential": Exponential(2 * C3, [60.0]),
    "fractional": Fractional(8 * C3, 0.5),
}


def _data(law, rng, n_f=200):
    f = np.linspace(2.0, 40.0, n_f)
    sys = DampedSystem(M3, K3, law)
    md = sys.modes()
    H = sys.receptance(f)[:, [0], :]
    sig = 0.01 * np.abs(H) / np.sqrt(2)  # 40 dB: noise 1 % of |H| per line
    Hn = H + sig * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))
    start = start_from_modes(md.poles, md.shapes * np.sqrt(2j * md.poles.imag))
    return f, Hn, sig, start


@pytest.mark.parametrize("model", MODELS)
def test_jacobian_matches_finite_differences(model: str) -> None:
    rng = np.random.default_rng(3)
    n, m, rows = 4, 3, np.array([0, 2])
    f = np.linspace(1.0, 30.0, 7)
    x = rng.standard_normal(len(_names(model, m, n)))
    x[:m] = [20.0, 60.0, 120.0]
    if model == "exponential":
        x[-1] = np.log(80.0)
    J = _jacobian(model, 2 * np.pi * f, x, n, m, rows)
    h = 1e-6
    cols = []
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        hp = _receptance(model, f, *_unpack(model, x + e, m, n), rows)
        hm = _receptance(model, f, *_unpack(model, x - e, m, n), rows)
        cols.append((hp - hm) / (2 * h))
    # central differences: truncation h^2 and rounding eps/h, about 1e-9 relative
    assert_allclose(J, np.stack(cols, -1), rtol=0, atol=1e-7 * np.abs(J).max())


@pytest.mark.parametrize("truth", ["viscous", "exponential", "hysteretic", "fractional"])
def test_true_model_chosen_at_40_db(truth: str) -> None:
    rng = np.random.default_rng(11)
    f, H, sig, start = _data(TRUTHS[truth], rng)
    cmp = compare_models(f, H, sig, [0], start)
    assert cmp.best == truth, cmp.summary()
    fit = cmp.fits[truth]
    # chi2 of the true model is chi2_{n-k} distributed: inside its central 99.9 %
    dof = fit.n_data - fit.n_params
    assert chi2.ppf(5e-4, dof) < fit.chi2 < chi2.ppf(1 - 5e-4, dof)
    if truth in ("exponential", "fractional"):
        true = 60.0 if truth == "exponential" else 0.5
        est, std = (
            (fit.extra["mu"], fit.std[-1] * fit.extra["mu"])
            if truth == "exponential"
            else (
                fit.extra["alpha"],
                fit.std[-1],
            )
        )
        # within 4 standard errors (a 1-in-15000 event for a correct error)
        assert abs(est - true) < 4 * std


def test_proportional_truth_kept_simple() -> None:
    rng = np.random.default_rng(5)
    f, H, sig, start = _data(TRUTHS["proportional"], rng)
    cmp = compare_models(f, H, sig, [0], start, models=("proportional", "viscous"))
    assert cmp.best == "proportional"
    (test,) = cmp.tests
    assert not test.rejected
    assert "proportional" in cmp.verdict


def _fit(model: str, chi: float, k: int) -> ModelFit:
    z = np.zeros(k)
    return ModelFit(model, z[:0], z[:0].reshape(0, 0), z[:0].reshape(0, 0), {}, z, z, (), chi, 100)


def test_likelihood_ratio_closed_form() -> None:
    simple, rich = _fit("viscous", 120.0, 3), _fit("exponential", 110.0, 4)
    lr = likelihood_ratio(simple, rich)
    assert_allclose(lr.p_value, chi2.sf(10.0, 1), rtol=1e-12)  # Wilks: chi^2_1 tail
    lr_b = likelihood_ratio(simple, rich, boundary=True)
    assert_allclose(lr_b.p_value, 0.5 * chi2.sf(10.0, 1), rtol=1e-12)  # Self & Liang mixture
    assert lr.rejected
    assert "rejected" in lr.format()


def test_unknown_model_refused() -> None:
    rng = np.random.default_rng(0)
    f, H, sig, start = _data(TRUTHS["viscous"], rng, n_f=20)
    with pytest.raises(InputError, match="models"):
        compare_models(f, H, sig, [0], start, models=("viscous", "maxwell"))


def _chain(n: int = 30) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A-W part 2, sec. 4: 30 unit masses, springs k_u, dashpots between masses 8 and 17."""
    k_u, c_u = 4e5, 40.0
    K = 2 * k_u * np.eye(n) - k_u * (np.eye(n, k=1) + np.eye(n, k=-1))
    C = np.zeros((n, n))
    for i in range(7, 16):
        C[i : i + 2, i : i + 2] += c_u * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return np.eye(n), K, C


@pytest.mark.parametrize("gamma", [0.02, 0.5])
def test_aw_part2_relaxation_recovered(gamma: float) -> None:
    M, K, C = _chain()
    t_min = 2 * np.pi / np.sqrt(np.linalg.eigvalsh(K).max())
    theta = gamma * t_min
    md = DampedSystem(M, K, Exponential(C, [1 / theta])).modes()
    est = exponential_from_modes(md.poles, md.shapes * np.sqrt(2j * md.poles.imag))
    # first-order theory (A-W part 2, eq. (13)-(14)): bias of a few % on exact modes
    assert_allclose(est.theta, theta, rtol=0.05)
    assert not est.viscous_consistent
    assert est.asymmetry_after < 0.2 * est.asymmetry


def test_aw_part2_viscous_modes_consistent() -> None:
    M, K, C = _chain()
    md = DampedSystem(M, K, Viscous(C)).modes()
    est = exponential_from_modes(md.poles, md.shapes * np.sqrt(2j * md.poles.imag))
    assert est.viscous_consistent
    assert "consistent with viscous" in est.format()


def test_demo_tyre_supports_the_fractional_model() -> None:
    from tyredamp.report.dampmodels import DAMPMODELS_HEADING, dampmodels_report
    from tyredamp.report.html import HtmlReport
    from tyredamp.studies.dampmodels import TRUE_MODEL, dampmodels_section, run_dampmodels

    study = run_dampmodels(seed=3)
    assert study.comparison.best == TRUE_MODEL
    sec = dampmodels_section(study)
    fit, truth = sec["fitted"], sec["truth"]
    # the fits start from the modes identified in the noisy FRFs: all three found
    assert len(fit["frequency_hz"]) == len(truth["frequency_hz"]) == 3
    # the truth is fractional to first order in (s tau)^alpha (< 1 %): alpha within
    # 4 standard errors (a correct fit misses that with probability < 1e-4)
    assert abs(fit["alpha"] - truth["alpha"]) < 4 * fit["alpha_std"]
    assert all(t["rejected"] for t in sec["tests"] if t["simple"] == "viscous")
    rep = HtmlReport("t")
    dampmodels_report(rep, {"damping_models": sec})
    assert DAMPMODELS_HEADING in rep.render()
