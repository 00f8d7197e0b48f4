"""Fitting lateral models: self-recovery, standard errors, criteria, ranking, joint fits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.frf import FRF
from tyredamp.lateral import (
    ClassicModel,
    HystereticModel,
    LateralData,
    LateralModel,
    MaxwellModel,
    RelaxationLengthModel,
    StretchedStringModel,
    ViscoPlasticModel,
    fit_joint,
    fit_model,
    rank_models,
)

SPEED = 5 / 3.6
WHEEL = 100.0
F = np.linspace(0.25, 9.0, 71)

TRUTHS: list[LateralModel] = [
    ClassicModel(k=1.3e5, c=2e3),
    MaxwellModel(k=1.3e5, c=5e4),
    ViscoPlasticModel(k=1.3e5, c1=1.5e3, c2=5e4),
    HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4),
    RelaxationLengthModel(C_alpha=8e4, sigma=0.4, speed=SPEED),
    StretchedStringModel(C_alpha=8e4, sigma=0.4, a=0.2, speed=SPEED),
]


def _data(model: LateralModel, force: str, noise: float = 0.0, seed: int = 0) -> LateralData:
    a = model.response(F, "accelerance", force, WHEEL)  # type: ignore[arg-type]
    if noise:
        rng = np.random.default_rng(seed)
        eps = (rng.standard_normal(F.size) + 1j * rng.standard_normal(F.size)) / math.sqrt(2)
        a = a * (1 + noise * eps)
    return LateralData(
        FRF(F, a, kind="accelerance"),
        speed=SPEED,
        force=force,  # type: ignore[arg-type]
        wheel_mass=WHEEL,
    )


@pytest.mark.parametrize("force", ["ground", "axle"])
@pytest.mark.parametrize("truth", TRUTHS, ids=lambda m: m.name)
def test_noise_free_self_recovery(truth: LateralModel, force: str) -> None:
    fit = fit_model(_data(truth, force), truth.name)
    # Required: within 0.1 %; the fit reaches rounding level, so check far tighter (1e-6).
    assert_allclose(fit.model.vector(), truth.vector(), rtol=1e-6)
    assert fit.amplitude_error < 1e-8
    assert fit.model.conditions == truth.conditions


@pytest.mark.parametrize("truth", TRUTHS, ids=lambda m: m.name)
def test_standard_errors_cover_truth_at_40_db(truth: LateralModel) -> None:
    # 40 dB SNR: complex relative noise of rms 1 % per line; relative weights make the
    # weighted residuals i.i.d., so s^2 (J^T J)^-1 is the right covariance. Required: in
    # >= 80 % of 20 seeds each parameter lies within 2 standard errors (expected ~95 %).
    noise = 10 ** (-40 / 20)
    inside = np.zeros(len(truth.param_names))
    n_seeds = 20
    for seed in range(n_seeds):
        fit = fit_model(_data(truth, "ground", noise, seed), truth.name, weights="relative")
        z = [(fit.params[k] - v) / fit.stderr[k] for k, v in truth.params.items()]
        inside += np.abs(z) < 2
    assert np.all(inside / n_seeds >= 0.8), dict(zip(truth.param_names, inside, strict=True))


def test_criteria_and_table1_figure_definitions() -> None:
    truth = HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4)
    d = _data(truth, "ground", noise=0.02, seed=3)
    fit = fit_model(d, "maxwell", weights="relative")
    meas = d.frf.H[0, 0]
    model = fit.model.accelerance(F)
    rel = (np.abs(model) - np.abs(meas)) / np.abs(meas)
    # Table 1 figure and its signed version, recomputed by hand (rounding).
    assert_allclose(fit.amplitude_error, np.mean(np.abs(rel)), rtol=1e-12)
    assert_allclose(fit.amplitude_bias, np.mean(rel), rtol=1e-12)
    r = (model - meas) / np.abs(meas)
    rss = float(np.sum(r.real**2 + r.imag**2))
    assert_allclose(fit.rss, rss, rtol=1e-12)
    n = 2 * F.size
    assert_allclose(fit.aic, n * np.log(rss / n) + 2 * 3, rtol=1e-12)
    assert_allclose(fit.bic, n * np.log(rss / n) + 3 * np.log(n), rtol=1e-12)


def test_ranking_prefers_the_true_model() -> None:
    truth = HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4)
    ranking = rank_models(_data(truth, "axle", noise=0.01, seed=1))
    assert ranking.order[0] == "hysteretic"
    assert ranking.delta[0] == 0
    assert all(d >= 0 for d in ranking.delta)
    assert_allclose(sum(ranking.weight), 1.0, rtol=1e-12)  # normalised weights
    assert len(ranking.reasons) == 4
    assert ranking.reasons[0].startswith("1. hysteretic: lowest BIC")
    table = ranking.format_table()
    assert "hysteretic" in table
    assert "amp.err" in table
    d = ranking.to_dict()
    assert d["order"] == list(ranking.order)
    assert len(d["fits"]) == 4


def test_aic_ranking_and_errors() -> None:
    truth = MaxwellModel(k=1.3e5, c=5e4)
    data = _data(truth, "ground", noise=0.01, seed=2)
    r = rank_models(data, ["maxwell", "classic"], criterion="aic")
    assert r.order[0] == "maxwell"
    with pytest.raises(InputError, match="duplicated"):
        rank_models(data, ["maxwell", "Maxwell"])
    with pytest.raises(InputError, match="criterion"):
        rank_models(data, ["maxwell"], criterion="dic")  # type: ignore[arg-type]


def test_joint_fit_shares_cornering_stiffness() -> None:
    ca, k, h = 8e4, 1.3e5, 1.5e4
    data = []
    for v_kmh in (5.0, 10.0):
        v = v_kmh / 3.6
        m = HystereticModel(K=k, h=h, C_r=ca / v)
        a = m.axle_accelerance(F, WHEEL)
        data.append(
            LateralData(
                FRF(F, a, kind="accelerance"),
                speed=v,
                force="axle",
                wheel_mass=WHEEL,
                label=f"{v_kmh:g} km/h",
            )
        )
    j = fit_joint(data, "proposed")
    assert j.names == ("K", "h", "C_alpha")
    # Noise-free joint fit: recovers the shared parameters to rounding (checked at 1e-6).
    assert_allclose([j.params["K"], j.params["h"], j.params["C_alpha"]], [k, h, ca], rtol=1e-6)
    assert_allclose(j.fits[1].params["C_r"], ca / (10 / 3.6), rtol=1e-6)
    none = fit_joint(data, "proposed", share="none")
    assert len(none.names) == 6
    # The shared model has fewer parameters for the same (zero) misfit: lower BIC.
    assert j.bic < none.bic
    assert j.to_dict()["model"] == "hysteretic"


def test_joint_fit_needs_speeds() -> None:
    d = _data(TRUTHS[1], "ground")
    no_speed = LateralData(d.frf)
    with pytest.raises(InputError, match="speed"):
        fit_joint([no_speed, no_speed], "maxwell")
    with pytest.raises(InputError, match="at least 2"):
        fit_joint([d], "maxwell")


def test_input_errors() -> None:
    d = _data(TRUTHS[3], "ground")
    with pytest.raises(InputError, match="speed"):
        fit_model(LateralData(d.frf), "relaxation")
    with pytest.raises(InputError, match="the lateral fit needs at least 4"):
        fit_model(d, "maxwell", band=(1.0, 1.1))
    with pytest.raises(InputError, match="coherence"):
        fit_model(d, "maxwell", weights="coherence")
    with pytest.raises(InputError, match="weights"):
        fit_model(d, "maxwell", weights=np.ones(3))
    with pytest.raises(InputError, match="start"):
        fit_model(d, "maxwell", start=[1.0, -1.0])
    with pytest.raises(InputError, match="force"):
        LateralData(d.frf, force="hub")  # type: ignore[arg-type]


def test_from_frf_reads_meta_and_other_kinds() -> None:
    truth = HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4)
    frf = FRF(
        F,
        truth.axle_accelerance(F, WHEEL),
        kind="accelerance",
        meta={"speed_m_s": SPEED, "force": "axle", "wheel_mass_kg": WHEEL},
    )
    d = LateralData.from_frf(frf)
    assert (d.speed, d.force, d.wheel_mass) == (SPEED, "axle", WHEEL)
    # The same data as a receptance FRF fits to the same parameters (conversion is exact).
    rec = frf.to("receptance")
    fit = fit_model(rec, "proposed", weights="relative", start=truth.params)
    assert_allclose(fit.model.vector(), truth.vector(), rtol=1e-6)
    assert fit.to_dict()["force"] == "axle"
