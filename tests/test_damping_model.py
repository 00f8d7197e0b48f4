"""identify_damping: DampingModel, diagnostics, findings, proportional fits, Monte Carlo."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import InputError, PhysicsError, ShapeError
from tyredamp.damping import (
    DampingModel,
    fit_rayleigh,
    identify_damping,
    reduced_receptance,
)
from tyredamp.damping.diagnostics import SYMMETRY_BAD
from tyredamp.mechanics import MCKSystem, rayleigh_damping
from tyredamp.modal import ModalModel

from .helpers import chain_system
from .test_damping_identify import exact_model, mck


def with_std(model: ModalModel, rel: float) -> ModalModel:
    """Same model with relative standard errors ``rel`` on f, zeta and |psi|."""
    return ModalModel(
        model.poles,
        model.psi_out,
        model.psi_in,
        std={
            "frequency_hz": rel * model.frequency_hz,
            "damping_ratio": rel * model.damping_ratio,
            "psi_out": rel * np.abs(model.psi_out),
        },
    )


# -------------------------------------------------------- symmetry, definiteness
@pytest.mark.parametrize("method", ["first", "improved", "refined"])
def test_spd_truth_gives_spd_c_without_forcing_symmetry(method: str) -> None:
    """Full-rank PSD C (zeta < 1 %), full set: C' symmetric and positive definite."""
    s = mck(11, n=6, zeta_max=0.008, rank=6)
    dm = identify_damping(exact_model(s), method, n_samples=0)  # type: ignore[arg-type]
    d = dm.diagnostics
    # no symmetrisation anywhere: asymmetry is the O(zeta^2) theory error (or rounding)
    assert d.symmetry_modal < 1e-3
    assert d.definiteness_modal == "positive definite"
    assert np.all(d.eigenvalues_modal > 0)
    assert any("positive definite" in f for f in dm.findings)
    assert any("symmetric to" in f for f in dm.findings)


def test_real_modes_flagged() -> None:
    """Real modes: zero imaginary parts give a diagonal C' and the finding says why."""
    s = mck(2, zeta_max=0.01)
    cm = s.complex_modes()
    um = s.undamped_modes()
    real = ModalModel.from_real_modes(cm.frequency_hz, cm.damping_ratio, um.phi, um.phi)
    dm = identify_damping(real, n_samples=0)
    off = dm.modal - np.diag(np.diag(dm.modal))
    # Im Psi^ = Im(phi / sqrt(2i Omega) * sqrt(2i Omega)) is rounding only
    assert np.max(np.abs(off)) < 1e-12 * np.max(np.abs(dm.modal))
    assert dm.diagnostics.imaginary_ratio < 1e-12
    assert any("cannot be identified from real modes" in f for f in dm.findings)
    # diagonal from the poles, eq. [15]: C'_nn = -2 Re p_n
    assert_allclose(np.diag(dm.modal), -2 * real.poles.real, rtol=1e-12)


@pytest.mark.parametrize("perm", [[5, 4, 3, 2, 1, 0], [2, 0, 1, 5, 3, 4]])
def test_shuffled_modes_flagged(perm: list[int]) -> None:
    """Shapes paired with the wrong poles: strong asymmetry or indefiniteness is flagged."""
    s = mck(11, n=6, zeta_max=0.008, rank=6)
    cm = s.complex_modes()
    bad = ModalModel(cm.poles, cm.psi[:, perm], cm.psi[:, perm])
    dm = identify_damping(bad, n_samples=0)
    d = dm.diagnostics
    assert d.symmetry_modal > SYMMETRY_BAD or d.definiteness_modal == "indefinite"
    text = " ".join(dm.findings)
    assert "strongly asymmetric" in text or "indefinite" in text


def test_truncation_leakage_findings() -> None:
    """4 of 8 modes at 8 points: rank-4 C, same inertia as C', leakage explained."""
    s = mck(4, n=8, zeta_max=0.01, rank=8)
    dm = identify_damping(exact_model(s, slice(0, 4)), "improved", n_samples=0)
    d = dm.diagnostics
    assert dm.physical.shape == (8, 8)
    assert np.linalg.matrix_rank(dm.physical, tol=1e-9 * np.abs(dm.physical).max()) == 4
    # Sylvester: C = P^T C' P has the inertia of C' plus N - m zeros
    n_pos_modal = int(np.sum(d.eigenvalues_modal > 0))
    tol = 1e-9 * np.abs(d.eigenvalues_physical).max()
    assert int(np.sum(d.eigenvalues_physical > tol)) == n_pos_modal
    assert any("power leakage" in f for f in dm.findings)
    assert dm.lancaster_physical is None
    with pytest.raises(PhysicsError, match="singular mass matrix"):
        dm.mck()


# ------------------------------------------------------------ complete set
def test_complete_set_lancaster_and_mck(chain: MCKSystem) -> None:
    dm = identify_damping(exact_model(chain), "refined", n_samples=0)
    assert dm.lancaster_physical is not None
    # both exact for complete exact modes
    assert_allclose(dm.lancaster_physical, chain.C, atol=1e-9 * np.abs(chain.C).max())
    assert dm.diagnostics.lancaster_difference is not None
    assert dm.diagnostics.lancaster_difference < 1e-9
    sysm = dm.mck()
    # refined reduced model = the chain (identities, rounding)
    assert_allclose(sysm.M, chain.M, atol=1e-9)
    assert_allclose(sysm.K, chain.K, atol=1e-9 * np.abs(chain.K).max())
    # the chain's C has rank 2 (two dampers): positive semi-definite, said so
    assert dm.diagnostics.definiteness_modal == "positive semi-definite"
    assert any("4 zero eigenvalue" in f for f in dm.findings)


# --------------------------------------------------------------- proportional
def test_rayleigh_truth_recovered() -> None:
    """Rayleigh-damped system: diagonal C', alpha/beta recovered, all FRF errors ~0."""
    s0 = mck(3, zeta_max=0.01)
    um = s0.undamped_modes()
    c = rayleigh_damping(s0.M, s0.K, 0.5, 2e-4)
    s = s0.with_damping(c)
    dm = identify_damping(exact_model(s), "first", n_samples=0)
    pr = dm.proportional
    # real modes exactly for proportional damping: C' diagonal to rounding
    assert dm.diagnostics.non_proportionality < 1e-9
    # zeta from the poles equals alpha/(2w) + beta w/2 exactly -> exact fit
    assert_allclose([pr.rayleigh_alpha, pr.rayleigh_beta], [0.5, 2e-4], rtol=1e-8)
    assert pr.zeta_fit_error < 1e-8
    assert max(pr.frf_error_full, pr.frf_error_modal, pr.frf_error_rayleigh) < 1e-8
    assert_allclose(dm.frequency_hz, um.frequency_hz, rtol=1e-6)  # |p| = omega exactly
    assert_allclose(dm.rayleigh_physical(), c, atol=1e-8 * np.abs(c).max())


def test_nonproportional_proportional_models_worse(chain: MCKSystem) -> None:
    dm = identify_damping(exact_model(chain), "refined", n_samples=0)
    pr = dm.proportional
    # full C' reproduces the exact modes (rounding); diagonal and Rayleigh do not
    assert pr.frf_error_full < 1e-9
    assert pr.frf_error_modal > 1e-3
    assert pr.frf_error_rayleigh > pr.frf_error_modal
    assert any("clearly better than any proportional model" in f for f in dm.findings)


def test_fit_rayleigh_nonnegative() -> None:
    """Damping ratios falling faster than 1/omega: alpha >= 0 and beta clipped at 0."""
    w = np.array([10.0, 20.0, 40.0])
    alpha, beta, fit = fit_rayleigh(w, 0.2 / w**2)
    assert alpha > 0
    assert beta == 0.0
    assert_allclose(fit, alpha / (2 * w))


def test_reduced_receptance_matches_direct_solve() -> None:
    """Phi (W^2 - w^2 + i w C')^-1 Phi^T equals (K - w^2 M + i w C)^-1 for the full set."""
    s = mck(6, zeta_max=0.02)
    um = s.undamped_modes()
    f = np.linspace(1.0, 40.0, 31)
    h = reduced_receptance(f, um.phi, s.modal_damping(), um.omega)
    # same linear system written in modal coordinates: rounding
    assert_allclose(h, s.receptance_direct(f), rtol=1e-9, atol=1e-12 * np.abs(h).max())


# ---------------------------------------------------------------- Monte Carlo
def test_monte_carlo_reproducible_and_linear() -> None:
    """Fixed seed reproduces; for small errors the std scales linearly with the input std."""
    s = mck(8, zeta_max=0.01, rank=6)
    base = exact_model(s)
    d1 = identify_damping(with_std(base, 1e-4), "improved", n_samples=60, seed=3)
    d2 = identify_damping(with_std(base, 1e-4), "improved", n_samples=60, seed=3)
    d3 = identify_damping(with_std(base, 2e-4), "improved", n_samples=60, seed=3)
    assert_allclose(d1.std["modal"], d2.std["modal"], rtol=0)
    # same random draws, doubled scale, linear regime: ratio 2 within 2 %
    ratio = np.linalg.norm(d3.std["modal"]) / np.linalg.norm(d1.std["modal"])
    assert_allclose(ratio, 2.0, rtol=0.02)
    assert d1.uncertainty == {"method": "monte_carlo", "n_samples": 60, "n_failed": 0, "seed": 3}
    assert d1.std["physical"].shape == (6, 6)
    assert any("Monte Carlo standard errors" in f for f in d1.findings)


def test_monte_carlo_diagonal_std_from_damping_ratio() -> None:
    """Only zeta uncertain: std of C'_nn = 2 omega_n std(zeta_n) (eq. [15], linear)."""
    s = mck(8, zeta_max=0.01, rank=6)
    base = exact_model(s)
    sz = 1e-5 * np.ones(6)
    model = ModalModel(base.poles, base.psi_out, base.psi_in, std={"damping_ratio": sz})
    dm = identify_damping(model, "first", n_samples=400, seed=0)
    # C'_nn = 2 zeta_n omega_n; 400 samples: std estimate within ~3.5/sqrt(800) ~ 12 %
    assert_allclose(np.diag(dm.std["modal"]), 2 * base.omega_n * sz, rtol=0.15)


def test_no_std_no_monte_carlo(chain: MCKSystem) -> None:
    dm = identify_damping(exact_model(chain), n_samples=50)
    assert dm.std == {}
    assert dm.uncertainty == {}
    assert any("No standard errors" in f for f in dm.findings)


# -------------------------------------------------------------- serialisation
def test_to_dict_round_trip() -> None:
    s = chain_system()
    dm = identify_damping(with_std(exact_model(s), 1e-3), "improved", n_samples=20)
    text = json.dumps(dm.to_dict())
    back = DampingModel.from_dict(json.loads(text))
    assert_allclose(back.modal, dm.modal, rtol=0)
    assert_allclose(back.physical, dm.physical, rtol=0)
    assert_allclose(back.poles, dm.poles, rtol=0)
    assert_allclose(back.std["modal"], dm.std["modal"], rtol=0)
    assert back.points == dm.points
    assert back.findings == dm.findings
    assert back.diagnostics.definiteness_modal == dm.diagnostics.definiteness_modal
    assert_allclose(back.diagnostics.eigenvalues_modal, dm.diagnostics.eigenvalues_modal)
    assert back.proportional.frf_error_modal == dm.proportional.frf_error_modal
    assert back.to_dict() == json.loads(text)


def test_from_dict_errors() -> None:
    with pytest.raises(InputError, match="kind 'damping'"):
        DampingModel.from_dict({"kind": "modes"})
    dm = identify_damping(exact_model(chain_system()), n_samples=0).to_dict()
    del dm["modal"]
    with pytest.raises(InputError, match="missing key 'modal'"):
        DampingModel.from_dict(dm)


def test_identify_validation() -> None:
    s = mck(0)
    with pytest.raises(InputError, match="ModalModel"):
        identify_damping(s)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="method"):
        identify_damping(exact_model(s), "exact")  # type: ignore[arg-type]
    cm = s.complex_modes()
    few_points = ModalModel(cm.poles, cm.psi[:3], cm.psi[:1])
    with pytest.raises(ShapeError, match="at least as many measured points as modes"):
        identify_damping(few_points)
    with pytest.raises(InputError, match="n_samples"):
        identify_damping(exact_model(s), n_samples=-1)
