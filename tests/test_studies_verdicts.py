"""Fit verdicts against the noise (tyredamp.studies.verdicts) on FRFs with a known truth."""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp import Channel
from tyredamp.frf import FRF
from tyredamp.modal.model import ModalModel
from tyredamp.studies.lateral_verdicts import lateral_family_verdicts, lateral_fit_verdict
from tyredamp.studies.verdicts import (
    CAUSE_MODEL_FORM,
    CAUSE_NON_PROPORTIONAL,
    CAUSE_OUTSIDE_FAMILY,
    frf_noise_variance,
    modal_fit_verdict,
    noise_test,
)

F = np.linspace(5.0, 100.0, 400)


def two_modes(f2: float = 80.0) -> ModalModel:
    """A 2-mode model, 1 output x 1 input, real modes at 30 Hz and ``f2``."""
    wn = 2 * np.pi * np.array([30.0, f2])
    z = np.array([0.02, 0.02])
    poles = -z * wn + 1j * wn * np.sqrt(1 - z**2)
    psi = (1.0 / np.sqrt(2j * poles.imag))[None, :]
    return ModalModel(poles, psi, psi.copy(), mode_kind="complex", meta={"band_hz": [5.0, 100.0]})


def measured(
    model: ModalModel, n_avg: int, snr: float, seed: int, random_force: bool = False
) -> FRF:
    """H1 from ``n_avg`` averages, noise on the response.

    A fixed periodic force repeated in every average (cyclic), or a new random
    force in every average (Welch-like). The coherence is estimated from the
    averages, as an analyser does.
    """
    rng = np.random.default_rng(seed)
    h = model.frf(F, "receptance").H[0, 0]
    sd = np.abs(h).max() / snr
    if random_force:
        force = (
            rng.standard_normal((n_avg, F.size)) + 1j * rng.standard_normal((n_avg, F.size))
        ) / np.sqrt(2)
    else:  # unit-amplitude periodic force
        force = np.tile(np.exp(1j * rng.uniform(0, 2 * np.pi, F.size)), (n_avg, 1))
    x = h * force + sd * (
        rng.standard_normal((n_avg, F.size)) + 1j * rng.standard_normal((n_avg, F.size))
    ) / np.sqrt(2)
    gff = np.sum(np.abs(force) ** 2, axis=0)
    gxf = np.sum(x * np.conj(force), axis=0)
    gxx = np.sum(np.abs(x) ** 2, axis=0)
    h1 = gxf / gff
    coh = np.abs(gxf) ** 2 / (gff * gxx)
    ch = [Channel(1, 3)]
    meta = {"n_averages": n_avg, "method": "welch" if random_force else "cyclic"}
    return FRF(F, h1[None, None, :], "receptance", ch, ch, coh[None, :], meta)


@pytest.mark.parametrize(
    ("n_avg", "random_force"), [(2, False), (4, False), (16, False), (4, True), (16, True)]
)
def test_the_true_model_is_within_the_noise(n_avg: int, random_force: bool) -> None:
    model = two_modes()
    ratios = []
    for seed in range(5):
        meas = measured(model, n_avg, 300.0, seed, random_force)
        v = modal_fit_verdict(model, meas, subject="true model")
        assert v.status == "ok", v.summary()
        assert v.test is not None
        ratios.append(v.test.ratio)
    # the coherence gives the noise to within a few per cent on average
    assert 0.85 < np.mean(ratios) < 1.15


def test_a_wrong_model_fails_and_names_the_missing_edge_mode() -> None:
    true = two_modes(f2=99.0)  # second mode at the upper band edge
    meas = measured(true, 8, 300.0, 1)
    one = ModalModel(
        true.poles[:1], true.psi_out[:, :1], true.psi_in[:, :1], meta={"band_hz": [5.0, 100.0]}
    )
    v = modal_fit_verdict(one, meas, subject="one mode", expected_hz=[30.0, 99.0])
    assert v.status == "failed"
    text = " ".join(v.reasons)
    assert "upper band edge" in text
    assert "expected mode at 99 Hz not identified" in text
    assert "FAILED" in v.summary()
    d = v.to_dict()
    assert d["passed"] is False
    assert d["residual_to_noise"] > d["threshold"]
    # a model 1 % off in frequency fails, the same data judged
    shifted = two_modes(f2=99.0 * 1.01)
    assert modal_fit_verdict(shifted, meas).status == "failed"


def test_a_model_form_misfit_at_the_edge_is_not_a_missing_mode() -> None:
    """A model off at the upper edge, beside a model of the same band within the noise
    (the complex-mode fit beside a real-mode one): the better model refutes a mode
    missing at the edge; the reason is the model form, the misfit's region is given."""
    true = two_modes(f2=99.0)
    meas = measured(true, 8, 300.0, 1)
    good = modal_fit_verdict(true, meas, subject="complex-mode fit")
    assert good.passed
    shifted = two_modes(f2=99.0 * 1.01)
    alone = modal_fit_verdict(shifted, meas)
    assert "upper band edge" in " ".join(alone.reasons)
    v = modal_fit_verdict(shifted, meas, subject="real-mode fit", better=good)
    text = " ".join(v.reasons)
    assert v.status == "failed"
    assert "band edge" not in text
    assert "the complex-mode fit is within the noise: the model form misses" in text
    assert v.test is not None
    assert v.test.misfit_hz is not None
    assert f"the misfit lies at {v.test.misfit_hz[0]:.4g}" in text
    # its outcome: a miss the data explain (the better model holds them), not a failure
    assert v.outcome == "expected"
    assert v.expected_cause == CAUSE_MODEL_FORM
    assert "FAILED" not in v.summary() + v.brief()
    assert v.to_dict()["outcome"] == "expected"
    assert v.to_dict()["passed"] is False  # the test against the noise is unchanged
    # the same miss of a real-mode model: the data are non-proportionally damped
    real = ModalModel(shifted.poles, shifted.psi_out, shifted.psi_in, "real", meta=shifted.meta)
    vr = modal_fit_verdict(real, meas, subject="real-mode fit", better=good)
    assert (vr.status, vr.outcome) == ("failed", "expected")
    assert vr.expected_cause == CAUSE_NON_PROPORTIONAL
    assert vr.brief().startswith("expected (residual ")
    # alone, or beside a better model that also misses, the same miss is a failure
    assert alone.outcome == "failed"
    assert "FAILED" in alone.summary()
    bad = modal_fit_verdict(shifted, meas, subject="complex-mode fit")
    assert modal_fit_verdict(real, meas, better=bad).outcome == "failed"


def test_a_lost_mode_is_a_failure_even_beside_a_better_model() -> None:
    """A model that misses an expected mode fails, whatever another model does."""
    true = two_modes(f2=99.0)
    meas = measured(true, 8, 300.0, 1)
    good = modal_fit_verdict(true, meas, subject="complex-mode fit")
    assert good.outcome == "ok"
    one = ModalModel(
        true.poles[:1],
        true.psi_out[:, :1],
        true.psi_in[:, :1],
        "real",
        meta={"band_hz": [5.0, 100.0]},
    )
    v = modal_fit_verdict(one, meas, expected_hz=[30.0, 99.0], better=good)
    assert v.status == "failed"
    assert v.outcome == "failed"
    assert v.expected_cause == ""
    assert "expected mode at 99 Hz not identified" in v.outcome_reason


def test_band_edge_and_complex_shape_cautions() -> None:
    m = two_modes(f2=99.5)
    meas = measured(m, 8, 300.0, 2)
    v = modal_fit_verdict(m, meas)
    assert v.status == "ok"
    assert any("crosses the band edge" in c for c in v.cautions)
    psi = m.psi_out.copy()
    bad = ModalModel(
        m.poles,
        psi,
        m.psi_in,
        meta={"band_hz": [5.0, 100.0], "mpc": np.array([0.3, 0.99])},
    )
    assert any("MPC 0.30" in c for c in modal_fit_verdict(bad, meas).cautions)


def bare_frf(model: ModalModel, snr: float, seed: int, f: np.ndarray = F) -> FRF:
    """The model's FRF with white complex noise on the response and no coherence."""
    rng = np.random.default_rng(seed)
    h = model.frf(f, "receptance").H
    sd = np.abs(h).max() / snr
    noise = sd * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape)) / np.sqrt(2)
    return FRF(f, h + noise, "receptance", [Channel(1, 3)], [Channel(1, 3)])


def test_without_coherence_judged_from_the_data() -> None:
    """No coherence: the fit is judged against the noise floor of adjacent lines."""
    m = two_modes()
    ratios = []
    for seed in range(5):
        bare = bare_frf(m, 300.0, seed)
        assert frf_noise_variance(bare) is None
        v = modal_fit_verdict(m, bare)
        assert v.status == "ok", v.summary()
        assert v.test is not None
        assert v.test.noise_from == "adjacent lines"
        assert "noise floor of adjacent lines" in v.summary()
        assert "differences of adjacent lines" in v.cautions[0]
        ratios.append(v.test.ratio)
    # the floor from the data is the noise: the residual of the true model is about it
    # (1 +- 0.3: five runs of 400 lines, a median-based floor)
    assert 0.7 < float(np.mean(ratios)) < 1.3


def test_without_coherence_a_missed_mode_fails() -> None:
    """A model without the 80 Hz mode misses the bare FRF: FAILED, structured, where."""
    m = two_modes()
    one = ModalModel(m.poles[:1], m.psi_out[:, :1], m.psi_in[:, :1], meta={"band_hz": [5.0, 100.0]})
    v = modal_fit_verdict(one, bare_frf(m, 300.0, 0))
    assert v.status == "failed"
    assert v.outcome == "failed"
    assert v.test is not None
    assert v.test.structured
    assert "from the noise floor of adjacent lines (no coherence)" in v.reasons[0]
    assert "structured across lines" in v.reasons[0]
    assert v.test.misfit_hz is not None
    assert v.test.misfit_hz[0] <= 80.0 <= v.test.misfit_hz[1]


def test_without_coherence_a_sharp_missed_mode_fails() -> None:
    """A mode sharper than the line spacing leaves a spike, not a correlation: FAILED."""
    f = np.arange(5.0, 100.0, 1.0)
    m = two_modes(f2=80.3)
    sharp = ModalModel(
        np.array([m.poles[0], -0.0002 * 2 * np.pi * 80.3 + 2j * np.pi * 80.3]),
        m.psi_out,
        m.psi_in,
        meta={"band_hz": [5.0, 100.0]},
    )
    one = ModalModel(m.poles[:1], m.psi_out[:, :1], m.psi_in[:, :1], meta={"band_hz": [5.0, 100.0]})
    v = modal_fit_verdict(one, bare_frf(sharp, 1000.0, 0, f))
    assert v.status == "failed", v.summary()
    assert v.test is not None
    assert v.test.misfit_hz is not None
    assert v.test.misfit_hz[0] <= 80.3 <= v.test.misfit_hz[1] + 1.0


def test_without_coherence_too_few_lines_not_judged() -> None:
    m = two_modes()
    f = np.linspace(20.0, 40.0, 5)
    bare = bare_frf(m, 300.0, 0, f)
    v = modal_fit_verdict(m, bare)
    assert v.status == "not judged"
    assert v.outcome == "not judged"
    assert "too few to judge" in v.cautions[0]
    assert v.brief().startswith("not judged")
    meas = measured(m, 4, 300.0, 0)
    one_avg = FRF(
        meas.frequency,
        meas.H,
        meas.kind,
        meas.outputs,
        meas.inputs,
        np.ones((1, F.size)),
        {"n_averages": 1},
    )
    assert frf_noise_variance(one_avg) is None


def test_model_error_is_said() -> None:
    """A fit outside the floor whose identification widened its noise says so."""
    m = two_modes()
    one = ModalModel(m.poles[:1], m.psi_out[:, :1], m.psi_in[:, :1], meta={"band_hz": [5.0, 100.0]})
    v = modal_fit_verdict(one, bare_frf(m, 300.0, 0), model_error=0.05)
    assert v.status == "failed"
    assert any("model error of 5 % of the response" in r for r in v.reasons)
    assert "within the noise" not in v.summary()


def test_noise_test_chi_square_level() -> None:
    """Known variance: the false-alarm rate of the test is about alpha."""
    rng = np.random.default_rng(0)
    n, trials, fails = 200, 400, 0
    var = rng.uniform(0.5, 2.0, n)
    h = np.ones(n, dtype=complex)
    for _ in range(trials):
        e = np.sqrt(var / 2) * (rng.standard_normal(n) + 1j * rng.standard_normal(n))
        t = noise_test(np.arange(n, dtype=float) + 1, h + e, h, var, alpha=0.05)
        fails += not t.passed
    assert 0.02 < fails / trials < 0.09


def test_lateral_verdict_on_the_rig() -> None:
    from tyredamp.lateral import fit_model
    from tyredamp.virtual import VirtualLateralRig

    rig = VirtualLateralRig()
    data = rig.measure(5.0, 1.7, "ground", 0)
    fit = fit_model(data, "hysteretic")
    v = lateral_fit_verdict(fit, data.frf)
    assert v.test is not None
    # the rig's tyre is a string with contact length, not the hysteretic model: the fit
    # misses by more than the 3 % noise, and the verdict says where
    assert v.status == "failed"
    assert "model form" in " ".join(v.reasons)
    assert v.outcome == "failed"  # one model alone: nothing tells form from a bad fit


def test_lateral_family_outcomes_on_the_rig() -> None:
    """The rig's tyre (a string with contact length) is none of the models: every
    converged fit misses, and each miss is the family's, not the fit's."""
    from dataclasses import replace

    from tyredamp.lateral import fit_model
    from tyredamp.virtual import VirtualLateralRig

    rig = VirtualLateralRig()
    data = rig.measure(5.0, 1.7, "ground", 0)
    fits = [fit_model(data, m) for m in ("hysteretic", "maxwell", "classic")]
    vs = lateral_family_verdicts(fits, data.frf, label="1.7 bar, 5 km/h")
    assert list(vs) == ["hysteretic", "maxwell", "classic"]
    for name, v in vs.items():
        assert v.subject == f"{name} fit at 1.7 bar, 5 km/h"
        assert v.test is not None
        assert v.test.ratio > v.test.threshold  # each misses the noise, judged alone
        assert v.status == "failed"
        assert v.outcome == "expected"
        assert v.expected_cause == CAUSE_OUTSIDE_FAMILY
        assert "FAILED" not in v.summary() + v.brief()
        # the same numbers as the verdict of the fit alone
        alone = lateral_fit_verdict(fits[list(vs).index(name)], data.frf)
        assert alone.test is not None
        assert v.test.ratio == alone.test.ratio
    # a model that holds the data (its fitted FRF the measured one) makes the others'
    # misses their form
    exact = replace(fits[0], fitted=fits[0].measured.copy())
    vs = lateral_family_verdicts([exact, *fits[1:]], data.frf)
    assert vs["hysteretic"].outcome == "ok"
    assert {vs[n].outcome for n in ("maxwell", "classic")} == {"expected"}
    assert vs["maxwell"].expected_cause == CAUSE_MODEL_FORM
    assert "hysteretic fit of the same FRF is within the noise" in vs["maxwell"].expected_why
    # a fit whose optimiser stopped on its limit may be what misses: a failure, and the
    # family can no longer be said to miss
    stuck = replace(fits[1], message="The maximum number of function evaluations is exceeded.")
    vs = lateral_family_verdicts([fits[0], stuck, fits[2]], data.frf)
    assert {v.outcome for v in vs.values()} == {"failed"}
    # a single model: nothing to compare with
    vs = lateral_family_verdicts(fits[:1], data.frf)
    assert vs["hysteretic"].outcome == "failed"


def test_mimo_noise_from_the_multiple_coherence() -> None:
    """Two uncorrelated forces of equal power: the true 2-input model is within the noise."""
    m1 = two_modes()
    wn = m1.poles
    psi_in = np.vstack([m1.psi_in, 0.7 * m1.psi_in * np.array([1.0, -1.0])])  # 2 inputs
    model = ModalModel(wn, m1.psi_out, psi_in, meta={"band_hz": [5.0, 100.0]})
    h = model.frf(F, "receptance").H[0]  # (2, n_freq)
    ratios = []
    for seed, n_avg in enumerate((8, 8, 32, 32)):
        rng = np.random.default_rng(seed)
        f_in = (
            rng.standard_normal((n_avg, 2, F.size)) + 1j * rng.standard_normal((n_avg, 2, F.size))
        ) / np.sqrt(2)
        sd = np.abs(h).max() / 300.0
        x = np.einsum("jf,ajf->af", h, f_in) + sd * (
            rng.standard_normal((n_avg, F.size)) + 1j * rng.standard_normal((n_avg, F.size))
        ) / np.sqrt(2)
        gff = np.einsum("aif,ajf->fij", f_in, np.conj(f_in))
        gxf = np.einsum("af,ajf->fj", x, np.conj(f_in))
        gxx = np.sum(np.abs(x) ** 2, axis=0)
        h1 = np.linalg.solve(np.transpose(gff, (0, 2, 1)), gxf[:, :, None])[:, :, 0]  # (f, 2)
        coh = np.real(np.einsum("fj,fj->f", h1, np.conj(gxf))) / gxx
        ch = [Channel(1, 3)]
        meas = FRF(
            F,
            h1.T[None, :, :],
            "receptance",
            ch,
            [Channel(1, 3), Channel(2, 3)],
            coh[None, :],
            {"n_averages": n_avg, "method": "welch"},  # random forces
        )
        v = modal_fit_verdict(model, meas)
        assert v.status == "ok", v.summary()
        assert v.test is not None
        ratios.append(v.test.ratio)
    assert 0.75 < np.mean(ratios) < 1.05  # approximate, on the side of more noise


def test_a_fallback_of_the_refinement_is_named() -> None:
    true = two_modes(f2=99.0)
    meas = measured(true, 8, 300.0, 3)
    one = ModalModel(
        true.poles[:1],
        true.psi_out[:, :1],
        true.psi_in[:, :1],
        meta={
            "band_hz": [5.0, 100.0],
            "warnings": ["real-mode refinement not acceptable (a pole crossed the band edge)"],
        },
    )
    v = modal_fit_verdict(one, meas)
    assert v.status == "failed"
    assert any("fell back to the complex-mode poles" in r for r in v.reasons)


def test_a_resonance_held_by_residual_terms_is_said() -> None:
    """A mode held as a residual mode inside the band: the fit may be within the noise,
    but the verdict says that resonance is not identified as a mode."""
    m = two_modes()
    held = ModalModel(m.poles[1:], m.psi_out[:, 1:], m.psi_in[:, 1:])
    one = ModalModel(
        m.poles[:1],
        m.psi_out[:, :1],
        m.psi_in[:, :1],
        residual_modes=held,
        meta={"band_hz": [5.0, 100.0]},
    )
    v = modal_fit_verdict(one, measured(m, 8, 300.0, 0))
    assert v.status == "ok", v.summary()
    assert any("resonance(s) inside the band at 80 Hz" in c for c in v.cautions)


def test_lateral_verdict_without_coherence_is_judged() -> None:
    """The rig's FRF without its coherence: the lateral fit is judged against the noise
    floor of adjacent lines, which is the noise the coherence gives."""
    from tyredamp.lateral import fit_model
    from tyredamp.virtual import VirtualLateralRig

    rig = VirtualLateralRig()
    data = rig.measure(5.0, 1.7, "ground", 0)
    fit = fit_model(data, "hysteretic")
    frf = data.frf
    bare = FRF(frf.frequency, frf.H, frf.kind, frf.outputs, frf.inputs)
    v = lateral_fit_verdict(fit, bare)
    assert v.test is not None
    assert v.test.noise_from == "adjacent lines"
    assert v.status in ("ok", "failed")
    assert v.cautions[0].startswith("no coherence: judged against the noise floor")
    with_coherence = lateral_fit_verdict(fit, frf)
    assert with_coherence.test is not None
    # the floor of 176 lines is the coherence's noise to within 20 % in variance (a
    # median over 21 lines, about 5 degrees of freedom each: the ratio of the two
    # statistics is 0.82-1.23 over seeds 0-5, 0.94 for this seed)
    assert v.test.ratio == pytest.approx(with_coherence.test.ratio, rel=0.2)
