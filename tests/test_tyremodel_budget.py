"""Uncertainty budgets, model-error verdicts and the input checks of the tyre model."""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.modal.model import ModalModel
from tyredamp.tyremodel import (
    LateralCarcass,
    RingObservation,
    fit_ring,
    rigid_ring_from_modes,
    ring_amplitude,
    wave_number_analysis,
)
from tyredamp.tyremodel.budget import Assumptions, UncertaintyBudget, rigid_ring_budget
from tyredamp.tyremodel.checks import check_lateral, check_modes, check_ring
from tyredamp.tyremodel.rigid import RigidRingParameters
from tyredamp.tyremodel.ring.identifiability import MODEL_LIMITED, admit_model_error
from tyredamp.virtual import RingTyre, RingTyreParameters, analytic_ring_frequencies

BAR = 1e5


@cache
def modes() -> ModalModel:
    # the virtual tyre's n = 1 and n = 2 modes at 7.5 bar (0-60 Hz keeps it fast)
    return (
        RingTyre(RingTyreParameters(pressure=7.5 * BAR)).truth((0.0, 60.0)).modal_model("visible")
    )


def budget_of(
    m_a: float, c_a: float, a: Assumptions
) -> tuple[RigidRingParameters, UncertaintyBudget]:
    wa = wave_number_analysis(modes())
    rr = rigid_ring_from_modes(modes(), analysis=wa, attachment_mass=m_a, attachment_damping=c_a)
    b = rigid_ring_budget(
        modes(), rr, analysis=wa, attachment_mass=m_a, attachment_damping=c_a, assumptions=a
    )
    return rr, b


def test_calibration_term_closed_form() -> None:
    # without an attachment mass BELT_MASS = 1 / (s A^2) scales as 1/s: the half difference
    # at s = 1 -+ u is m u / (1 - u^2); FREQ_LONG and DAMP_LONG do not depend on s
    a = Assumptions(force_sensitivity=0.012, acceleration_sensitivity=0.016)
    u = math.hypot(0.012, 0.016)  # 0.02
    rr, b = budget_of(0.0, 0.0, a)
    # rtol 1e-12: the same arithmetic in another order
    assert_allclose(b.terms["BELT_MASS"]["calibration"], rr.belt_mass * u / (1 - u**2), rtol=1e-12)
    assert b.terms["FREQ_LONG"]["calibration"] == 0.0
    assert b.terms["DAMP_LONG"]["calibration"] == 0.0
    assert b.terms["DAMP_LONG"]["attachment damping"] == 0.0
    assert "no attachment damper removed" in b.assumptions["DAMP_LONG"]


def test_attachment_terms_and_total() -> None:
    a = Assumptions(attachment_damping=0.4)
    rr, b = budget_of(0.1, 350.0, a)
    # DAMP_LONG is linear in the removed damper: the half difference at c_a (1 -+ 0.4) is
    # 0.4 times the whole effect of the damper (the value without it, computed separately)
    assert b.without_attachment_damping is not None
    assert b.without_attachment_damping > rr.damp_long
    # rtol 1e-9: linear in c_a up to rounding
    assert_allclose(
        b.terms["DAMP_LONG"]["attachment damping"],
        0.4 * (b.without_attachment_damping - rr.damp_long),
        rtol=1e-9,
    )
    assert f"{b.without_attachment_damping:.4g} without removing it" in b.assumptions["DAMP_LONG"]
    for key, terms in b.terms.items():
        # rtol 1e-12: the root sum of squares
        assert_allclose(b.total[key], math.sqrt(sum(v**2 for v in terms.values())), rtol=1e-12)
    assert b.terms["BELT_MASS"]["attachment mass"] > 0
    # with the default 1 % + 1 % calibration BELT_MASS is known to about 1.4 %, far above its
    # statistical error (none here: exact modes)
    assert 0.013 < b.total["BELT_MASS"] / rr.belt_mass < 0.02
    assert "+- " in b.comment("BELT_MASS")
    assert "assumes" in b.comment("BELT_MASS")


@pytest.mark.parametrize(
    "kw",
    [{"force_sensitivity": 0.6}, {"acceleration_sensitivity": math.nan}, {"attachment_damping": 2}],
)
def test_assumptions_bounded(kw: dict[str, float]) -> None:
    with pytest.raises(InputError, match="uncertainty"):
        Assumptions(**kw)


# ------------------------------------------------------------------ model error in the ring
def test_admit_model_error_rules() -> None:
    base = {
        "a": {"verdict": "identified", "relative_se": 0.01, "correlated_with": []},
        "b": {"verdict": "identified", "relative_se": 0.01, "correlated_with": []},
        "c": {
            "verdict": "not identifiable from these modes",
            "relative_se": 2,
            "correlated_with": [],
        },
    }
    theta, se = np.array([1.0, 0.01, 5.0]), np.array([0.01, 0.01, 10.0])
    ok = admit_model_error(base, theta, se, 1.2)
    assert ok["a"]["verdict"] == "identified"
    assert not ok["a"]["model_limited"]
    assert ok["b"]["verdict"] == "consistent with zero"  # 0.01 +- 0.01
    assert ok["c"]["consistent_with_zero"]
    assert ok["c"]["verdict"].startswith("not identifiable")
    # the discrepancy bound se sqrt(dof), against the verdict scale: 0.01 sqrt(400) = 0.2
    bad = admit_model_error(base, theta, se, 140.0, dof=400)
    assert bad["a"]["model_limited"]
    assert bad["a"]["verdict"].startswith("model-limited")
    assert bad["a"]["model_error_bound"] == pytest.approx(0.2, rel=1e-12)  # closed form
    assert not bad["c"]["model_limited"]  # already not identifiable
    # ... 0.01 sqrt(16) = 0.04 < 0.1: still identified, its bound reported
    # c: 5 +- 10 was consistent with zero already; b (0.01 +- 0.01) stays so with the bound
    assert bad["b"]["consistent_with_zero"]
    # a value 3 se from zero is not consistent with zero by noise, but is with the bound
    far = admit_model_error(base, np.array([1.0, 0.03, 5.0]), se, 1.2)
    assert not far["b"]["consistent_with_zero"]
    near = admit_model_error(base, np.array([1.0, 0.03, 5.0]), se, 140.0, dof=16)
    assert near["b"]["consistent_with_zero"]  # 2 se sqrt(17) = 0.082 > 0.03
    small = admit_model_error(base, theta, se, 140.0, dof=16)
    assert small["a"]["verdict"] == "identified"
    assert small["a"]["model_error_bound"] == pytest.approx(0.04, rel=1e-12)
    assert ok["a"]["model_error_bound"] == 0.0  # chi2/dof 1.2: no model-error term
    assert admit_model_error(base, theta, se, None)["a"]["verdict"] == "identified"


def analytic_observations(rng: np.random.Generator, bias: float) -> list[RingObservation]:
    """Analytic-ring modes (n = 1..6 at 5 and 9 bar) with noise, times (1 + bias (-1)^n)."""
    true = RingTyreParameters()
    out = []
    for p in (5.0, 9.0):
        tp = true.with_pressure(p * BAR)
        for n in range(1, 7):
            a = ring_amplitude([n], radius=tp.radius, mass_per_length=tp.mass_per_length)[0]
            f = analytic_ring_frequencies(tp, [n])[0] * (1 + bias * (-1) ** n)
            z = 0.03
            e = rng.standard_normal(3)
            out.append(
                RingObservation(
                    pressure=p * BAR,
                    n=n,
                    member="cos",
                    frequency_hz=float(f * (1 + 1e-3 * e[0])),
                    frequency_std=float(1e-3 * f),
                    damping_ratio=float(z * (1 + 0.02 * e[1])),
                    damping_std=float(0.02 * z),
                    amplitude=float(a * (1 + 0.01 * e[2])),
                    amplitude_std=float(0.01 * a),
                    use_amplitude=True,
                    drive_phi2=float(a * a),
                    mode_index=n - 1,
                )
            )
    return out


def test_ring_fit_admits_model_error() -> None:
    rng = np.random.default_rng(5)
    good = fit_ring(analytic_observations(rng, 0.0), radius=0.5, attachment_damping=0.0)
    disc = good.model_discrepancy()
    assert disc["chi2_per_dof"] < MODEL_LIMITED
    assert not disc["model_limited"]
    assert good.verdicts["EI"]["verdict"] == "identified"
    # a 2 % alternating misfit against 0.1 % noise: chi2/dof in the hundreds
    bad = fit_ring(analytic_observations(rng, 0.02), radius=0.5, attachment_damping=0.0)
    disc = bad.model_discrepancy()
    assert disc["model_limited"]
    assert disc["chi2_per_dof"] > 50
    assert 0.005 < disc["frequency_rms_relative"] < 0.03  # the misfit's size, about 2 %
    assert not [k for k, v in bad.verdicts.items() if v["verdict"] == "identified"]
    assert bad.to_dict()["model_discrepancy"]["model_limited"]


# ---------------------------------------------------------------------------- input checks
def test_check_modes_and_ring() -> None:
    m = modes()
    with pytest.raises(InputError, match="same modes"):
        check_modes([(5e5, m, "a.json"), (7e5, m, "b.json")])
    other = ModalModel(
        m.poles * 1.01, m.psi_out, m.psi_in, outputs=m.outputs, inputs=m.inputs, meta=m.meta
    )
    with pytest.raises(InputError, match="same pressure"):
        check_modes([(5e5, m, "a.json"), (5e5, other, "b.json")])
    unstable = ModalModel(
        np.conj(-m.poles), m.psi_out, m.psi_in, outputs=m.outputs, inputs=m.inputs, meta=m.meta
    )
    with pytest.raises(InputError, match="unstable"):
        check_modes([(5e5, unstable, "u.json")])
    # the same frequencies labelled with two pressures: the tension cannot follow p R b
    obs = analytic_observations(np.random.default_rng(1), 0.0)
    same = [replace(o, pressure=(5 if i % 2 else 9) * BAR) for i, o in enumerate(obs[:6] * 2)]
    with pytest.raises(InputError, match="do not change with the pressure"):
        check_ring(fit_ring(same, radius=0.5, attachment_damping=0.0))


def carcass(p_bar: float | None, err: float | None = None) -> LateralCarcass:
    return LateralCarcass(
        "hysteretic", 10.0, p_bar, 1e5, 1e3, 0.6, 0.01, 6e4, 1e3, False, "lat.json", err
    )


def test_check_lateral_pressure() -> None:
    with pytest.raises(InputError, match="--force"):
        check_lateral([carcass(1.7)], [7.5 * BAR], force=False)
    (w,) = check_lateral([carcass(1.7)], [7.5 * BAR], force=True)
    assert "kept" in w
    assert check_lateral([carcass(7.2)], [7.5 * BAR], force=False) == []  # within 10 %
    (w,) = check_lateral([carcass(None)], [7.5 * BAR], force=False)
    assert "not recorded" in w
    assert carcass(7.5, 0.2).model_limited
    assert "MODEL-LIMITED" in carcass(7.5, 0.2).comment()
    assert not carcass(7.5, 0.01).model_limited
