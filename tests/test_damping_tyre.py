"""Damping identification on the virtual truck tyre (spec step 7 on the ring model).

Truth: :class:`tyredamp.virtual.TyreTruth` (exact modes of the 128-DOF ring,
``C'`` of eq. [14] on the undamped modes, the damping reduced to the 16
points by the same modal projection). Only the cos-type member of each
double mode (antinode at the drive point) is visible from one radial shaker,
so 6 modes (n = 1..6) at 16 points are identified.

What the comparison shows (numbers from this file and
``benchmarks/damping_tyre.py``):

* with the exact visible modes, ``C'`` is 9.0 % (Frobenius) from the truth and
  18 % asymmetric; its symmetric part is within 1.5 %. The error is leakage:
  the local dampers couple the visible modes to modes outside the set
  (above all the kHz extensional modes of the same wave numbers, which look
  identical at the 16 points), and that contribution enters ``C'`` mostly
  antisymmetrically;
* the physical matrix reproduces the truth reduced to the points (rank 6,
  with the negative "leakage" entries) within 2 % (symmetric part), while
  both differ completely from the true ``C`` at the point DOFs (nearly
  diagonal dashpots), because 6 shapes cannot represent a local distribution.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.cli import main
from tyredamp.damping import DampingModel, identify_damping
from tyredamp.damping.diagnostics import SYMMETRY_OK
from tyredamp.documents.modes import write_modes_json
from tyredamp.modal import ModalModel
from tyredamp.modal.identify import identify_modes
from tyredamp.signal.estimators import estimate_frf
from tyredamp.virtual import (
    MeasurementLayout,
    RingTyre,
    TyreTruth,
    VirtualModalTest,
    run_modal_test,
)


@pytest.fixture(scope="module")
def truth() -> TyreTruth:
    # a 30 N s/m damper at the drive point (a tip held by the shaker, 0.1 kg): a local
    # loss large enough to show the leakage the module docstring describes (the
    # default tip, 2 N s/m in series with 10 g, leaves the bare ring nearly proportional)
    return RingTyre(layout=MeasurementLayout(attachment_mass=0.1, attachment_damping=30.0)).truth()


def truth_modal(truth: TyreTruth, dm: DampingModel) -> np.ndarray:
    """True C' of the visible modes, with the signs of the identified basis."""
    idx = truth.select("visible")
    ct = truth.modal_damping[np.ix_(idx, idx)]
    sign = np.sign(np.sum(dm.basis * truth.phi_points[:, idx], axis=0))
    return ct * np.outer(sign, sign)


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.mark.parametrize("method", ["first", "improved", "refined"])
def test_exact_tyre_modes(truth: TyreTruth, method: str) -> None:
    dm = identify_damping(truth.modal_model("visible"), method, n_samples=0)  # type: ignore[arg-type]
    ct = truth_modal(truth, dm)
    # leakage from out-of-set modes (module docstring): 9.0 % raw, 1.5 % symmetric
    assert rel(dm.modal, ct) < 0.10
    assert rel(dm.modal_symmetric, ct) < 0.02
    # the same projection as TyreTruth.reduced_damping, with identified shapes
    assert rel(dm.physical_symmetric, truth.reduced_damping()) < 0.025
    # truth is symmetric positive definite; so is the identification, unforced
    assert dm.diagnostics.definiteness_modal == "positive definite"
    # out-of-set modes leave an antisymmetric part of about 5 % (0.0497 with the first-order
    # method on the sixth-order ring): well above rounding, and named in the findings when
    # it is above the 5 % at which the report stops calling C' symmetric
    asym = dm.diagnostics.symmetry_modal
    assert 0.03 < asym < 0.25
    word = "leakage" if asym > SYMMETRY_OK else "symmetric to"
    assert any(word in f for f in dm.findings)


def test_reduced_is_not_the_point_damping(truth: TyreTruth) -> None:
    """The rank-6 physical matrix is a projection, not the dashpots at the points."""
    dm = identify_damping(truth.modal_model("visible"), n_samples=0)
    pts = truth.point_dofs
    c_pts = truth.system.C[np.ix_(pts, pts)]
    # true C at the points: diagonal-dominant, all diagonal entries large and positive
    assert np.all(np.diag(c_pts) > 100)
    # the projection keeps only 6 of 16 spatial patterns: most of it is lost
    assert rel(dm.physical_symmetric, c_pts) > 0.7
    assert dm.diagnostics.negative_offdiagonal_fraction > 0.3
    assert np.linalg.matrix_rank(dm.physical, tol=1e-8 * np.abs(dm.physical).max()) == 6
    # yet it reproduces what the modes see: U^T C U = C' (pinv(U) U = I)
    assert_allclose(dm.basis.T @ dm.physical @ dm.basis, dm.modal, atol=1e-9 * dm.modal.max())


def test_noisy_tyre_modes(truth: TyreTruth) -> None:
    """Exact modes plus noise: 0.3 % on each shape entry (RMS of the shape), 0.3 % on zeta.

    Median over 10 draws: raw C' within 10 %, symmetric part within 4 %; the
    Monte Carlo standard errors from the stated std cover the actual scatter.
    """
    base = truth.modal_model("visible")
    rng = np.random.default_rng(7)
    scale = 0.003 * np.sqrt(np.mean(np.abs(base.psi_out) ** 2, axis=0))
    raw, sym, draws = [], [], []
    for _ in range(10):
        noise = rng.standard_normal(base.psi_out.shape) + 1j * rng.standard_normal(
            base.psi_out.shape
        )
        psi = base.psi_out + scale * noise / np.sqrt(2)
        z = base.damping_ratio * (1 + 0.003 * rng.standard_normal(base.n_modes))
        w = base.omega_n
        p = -z * w + 1j * w * np.sqrt(1 - z**2)
        model = ModalModel(p, psi, psi[:1], outputs=base.outputs, inputs=base.inputs)
        dm = identify_damping(model, "improved", n_samples=0)
        ct = truth_modal(truth, dm)
        raw.append(rel(dm.modal, ct))
        sym.append(rel(dm.modal_symmetric, ct))
        # C'_kn carries the signs of basis columns k and n: compare in the truth's signs
        sign = np.sign(np.sum(dm.basis * truth.phi_points[:, truth.select("visible")], axis=0))
        draws.append(dm.modal * np.outer(sign, sign))
    # 10 draws: median robust to one bad draw
    assert np.median(raw) < 0.10
    assert np.median(sym) < 0.04
    std_model = ModalModel(
        base.poles,
        base.psi_out,
        base.psi_in,
        outputs=base.outputs,
        inputs=base.inputs,
        std={
            "damping_ratio": 0.003 * base.damping_ratio,
            "psi_out": np.broadcast_to(scale, base.psi_out.shape),
        },
    )
    mc = identify_damping(std_model, "improved", n_samples=100, seed=1)
    scatter = np.std(np.array(draws), axis=0, ddof=1)
    # 10 draws vs 100 MC samples: the Frobenius norms agree within a factor 1.6
    ratio = np.linalg.norm(scatter) / np.linalg.norm(mc.std["modal"])
    assert 1 / 1.6 < ratio < 1.6


# ------------------------------------------------------------- whole chain
@pytest.fixture(scope="module")
def chain_result() -> tuple[VirtualModalTest, ModalModel, DampingModel]:
    """Virtual modal test at 40 dB SNR -> H1 FRFs -> complex-mode fit -> damping."""
    # 2 s chirp period (0.5 Hz lines, >= 4 lines per half-power band), 4 averages
    # a strongly non-proportional tyre (350 N s/m at the drive point, half its C'_off), so
    # that the truncation bias the findings must name is there
    tyre = RingTyre(layout=MeasurementLayout(attachment_damping=350.0), nonproportionality=0.5)
    vt = run_modal_test(tyre, seed=0, snr_db=40.0, period=2.0, n_periods=4)
    frf = estimate_frf(vt.data, "H1")
    model = identify_modes(frf, band=(20.0, 200.0), model="complex").models["complex"]
    dm = identify_damping(model, "improved", n_samples=100, seed=0)
    return vt, model, dm


@pytest.mark.slow
def test_whole_chain_modal_matrix(
    chain_result: tuple[VirtualModalTest, ModalModel, DampingModel],
) -> None:
    """40 dB SNR: C' within 10 % of the truth on the identified modes, unforced SPD."""
    vt, model, dm = chain_result
    truth = vt.truth
    idx = truth.select("visible")
    assert model.n_modes == idx.size == 6
    # natural frequencies of the fit: measured 4e-5 relative; 1e-3 leaves room for noise
    assert_allclose(dm.frequency_hz, truth.frequency_hz[idx], rtol=1e-3)
    ct = truth_modal(truth, dm)
    # measured: 8.7 % raw (leakage, as with exact modes), 1.9 % symmetric part
    assert rel(dm.modal, ct) < 0.10
    assert rel(dm.modal_symmetric, ct) < 0.03
    assert dm.diagnostics.definiteness_modal == "positive definite"
    # std covers the noise, not the leakage bias: the finding says so
    assert dm.std["modal"].shape == (6, 6)
    assert any("systematic error" in f for f in dm.findings)


@pytest.mark.slow
def test_whole_chain_physical_matrix(
    chain_result: tuple[VirtualModalTest, ModalModel, DampingModel],
) -> None:
    """Physical C against the true damping reduced to the 16 points (module docstring).

    The reduction TyreTruth.reduced_damping is the same modal projection with
    the true shapes and C': the identification reproduces it within 3 %
    (measured 2.3 %), negative "leakage" entries included. Both are far from
    the true C at the point DOFs, which 6 shapes cannot represent.
    """
    vt, _, dm = chain_result
    truth = vt.truth
    red = truth.reduced_damping()
    assert rel(dm.physical_symmetric, red) < 0.03
    assert [c.node for c in dm.points] == [c.node for c in truth.outputs]
    # negative entries in both, in the same places (sign agreement on the big ones)
    big = np.abs(red) > 0.1 * np.abs(red).max()
    assert np.all(np.sign(dm.physical_symmetric[big]) == np.sign(red[big]))
    assert np.any(red[big] < 0)
    pts = truth.point_dofs
    assert rel(dm.physical_symmetric, truth.system.C[np.ix_(pts, pts)]) > 0.7


@pytest.mark.slow
def test_whole_chain_cli(
    chain_result: tuple[VirtualModalTest, ModalModel, DampingModel],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The same modes through ``tyredamp damping`` give the same file content."""
    _, model, dm = chain_result
    src = write_modes_json(tmp_path / "modes.json", {"complex": model})
    out = tmp_path / "damping.json"
    main(["damping", str(src), "--out", str(out), "--samples", "100"])
    back = DampingModel.from_dict(json.loads(out.read_text()))
    # JSON round trip of the modal model: 1e-12 (float text is exact; re-sorting of poles)
    assert_allclose(back.modal, dm.modal, rtol=1e-9, atol=1e-9 * np.abs(dm.modal).max())
    assert "6 modes at 16 points" in capsys.readouterr().out
