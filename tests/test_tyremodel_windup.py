"""The tangential test and the belt's wind-up: FREQ_WINDUP, DAMP_WINDUP, BELT_IYY."""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from numpy.testing import assert_allclose

from tyredamp.cli import cli
from tyredamp.documents.modes import write_modes_json
from tyredamp.exceptions import InputError
from tyredamp.frf import Channel
from tyredamp.modal.model import ModalModel
from tyredamp.tyremodel import parse_tir, windup_budget, windup_from_modes
from tyredamp.tyremodel.budget import Assumptions
from tyredamp.tyremodel.wavenumber import wave_number_analysis
from tyredamp.virtual import (
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    TyreTruth,
    bare_ring_windup,
    run_modal_test,
    tangential_tyre,
    windup_truth,
)

BAR = 1e5
R = RingTyreParameters().radius


@cache
def tyre() -> RingTyre:
    return RingTyre()


@cache
def tangential_truth() -> TyreTruth:
    return tangential_tyre(tyre()).truth((0.0, 200.0))


# ------------------------------------------------------------------ the virtual truth
def test_bare_ring_windup_is_the_closed_form() -> None:
    prm = RingTyreParameters()
    bare = RingTyre(prm, MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0))
    f0, z0, i0 = bare_ring_windup(prm)
    # independent: omega_0^2 = k_t / (rho A), I = rho A 2 pi R^3 from the parameters
    assert_allclose(f0, math.sqrt(prm.tangential_stiffness / prm.mass_per_length) / (2 * np.pi))
    assert_allclose(i0, prm.band_mass * prm.radius**2)
    w = windup_truth(bare)
    # the staggered differences of a constant vanish: the discrete rotation mode is the
    # continuous one to the eigensolver's round-off
    assert_allclose(w.bare_frequency_hz, f0, rtol=1e-9)
    assert_allclose(w.bare_damping_ratio, z0, rtol=1e-9)
    assert_allclose(w.inertia, i0, rtol=1e-12)
    assert_allclose(w.modal_inertia, i0, rtol=1e-9)
    assert w.purity > 1 - 1e-9
    # the drive-rod tip (10 g, 2 N s/m) lowers the tested frequency and adds damping
    wt = windup_truth(tyre())
    assert wt.frequency_hz < wt.bare_frequency_hz
    assert wt.damping_ratio > wt.bare_damping_ratio
    assert_allclose(wt.bare_frequency_hz, f0, rtol=1e-9)


def test_tangential_rig_channels_and_radial_default() -> None:
    kw = {"period": 1.0, "n_periods": 1, "oversample": 2, "seed": 3, "band": (0.0, 100.0)}
    tan = run_modal_test(tyre(), direction="tangential", **kw)  # type: ignore[arg-type]
    rad = run_modal_test(tyre(), **kw)  # type: ignore[arg-type]
    assert {c.direction for c in tan.data.channels} == {1}
    assert {c.direction for c in rad.data.channels} == {3}
    assert tan.data.meta["measured_direction"] == "tangential"
    assert "measured_direction" not in rad.data.meta
    # tangential points sit half a node spacing (360/64/2 deg) ahead of the radial ones
    ang_t = [c.angle_deg for c in tan.data.channels[1:]]
    ang_r = [c.angle_deg for c in rad.data.channels[1:]]
    assert_allclose(np.subtract(ang_t, ang_r), 360 / 64 / 2)
    # at the rotation's frequency the tangential drive-point FRF is resonant; the radial one
    # has only the tails of the flexural modes (30 times lower)
    f = np.array([windup_truth(tyre()).frequency_hz])
    h_t = np.abs(tan.true_frf(f).H[0, 0, 0])
    h_r = np.abs(rad.true_frf(f).H[0, 0, 0])
    assert h_t > 10 * h_r


# ------------------------------------------------------------ identification from shapes
def synthetic(
    shapes: list[np.ndarray], freqs: list[float], direction: int = 1, zeta: float = 0.01
) -> ModalModel:
    """Complex modes whose second-order shapes are the given real shapes (1/sqrt(kg))."""
    theta = np.arange(16) * 22.5
    om = 2 * np.pi * np.asarray(freqs)
    poles = -zeta * om + 1j * om * math.sqrt(1 - zeta**2)
    big = np.column_stack(shapes).astype(complex)
    psi = big / np.sqrt(2j * poles.imag)
    outs = tuple(
        Channel(k + 1, direction=direction, angle_deg=float(a), name=f"A{k + 1}")
        for k, a in enumerate(theta)
    )
    ins = (Channel(1, direction=direction, angle_deg=0.0, name="F1"),)
    return ModalModel(poles, psi, psi[:1], mode_kind="complex", outputs=outs, inputs=ins)


def test_rotation_found_by_shape_with_closed_form_inertia() -> None:
    th = np.radians(np.arange(16) * 22.5)
    a_t, i_true = 0.3, None
    i_true = R**2 / a_t**2
    n1 = 0.2 * np.cos(th)
    rot = a_t * np.ones(16) + 0.01 * np.cos(2 * th)  # a rotation with a little n = 2
    mdl = synthetic([n1, rot, 0.2 * np.cos(3 * th)], [25.0, 40.0, 60.0])
    w = windup_from_modes(mdl, radius=R)
    assert w.index == 1  # not the lowest mode: the one whose shape is n = 0
    # the least-squares n = 0 fit of a uniform shape is its mean; the n = 2 part is orthogonal
    assert_allclose(w.belt_iyy, i_true, rtol=1e-12)
    assert_allclose(w.freq_windup, 40.0, rtol=1e-12)
    assert_allclose(w.damp_windup, 0.01, rtol=1e-12)
    assert_allclose(w.k_windup, i_true * (2 * np.pi * 40.0) ** 2, rtol=1e-12)
    # attachment mass at the drive point: I = (1 - m_a phi_d^2) R^2 / A_t^2 with phi_d = the
    # drive-point shape, f_0 = f / sqrt(1 - m_a phi_d^2) (closed forms of the module docstring)
    m_a = 0.5
    phi_d2 = float(rot[0]) ** 2
    wa = windup_from_modes(mdl, radius=R, attachment_mass=m_a)
    assert_allclose(wa.belt_iyy, (1 - m_a * phi_d2) * i_true, rtol=1e-12)
    assert_allclose(wa.freq_windup, 40.0 / math.sqrt(1 - m_a * phi_d2), rtol=1e-12)


def test_no_rotation_mode_or_radial_channels_refused() -> None:
    th = np.radians(np.arange(16) * 22.5)
    mdl = synthetic([0.2 * np.cos(th), 0.2 * np.cos(2 * th)], [25.0, 40.0])
    with pytest.raises(InputError, match=r"no n = 0.*found: n = 1 .* at 25 Hz, n = 2"):
        windup_from_modes(mdl, radius=R, source="t.json")
    radial = synthetic([np.ones(16)], [40.0], direction=3)
    with pytest.raises(InputError, match="radial"):
        windup_from_modes(radial, radius=R)


def test_windup_from_exact_modes_equals_truth() -> None:
    tr = tangential_truth()
    lay = tyre().layout
    w = windup_from_modes(
        tr.modal_model("all"),
        radius=R,
        attachment_mass=lay.attachment_mass,
        attachment_damping=lay.attachment_damping,
    )
    wt = windup_truth(tyre())
    # exact complex modes: the second-order shape of the nearly proportional rotation mode is
    # its mass-normalised real mode to O(zeta^2) (1e-5 here)
    assert_allclose(w.freq_windup, wt.bare_frequency_hz, rtol=1e-5)
    assert_allclose(w.damp_windup, wt.bare_damping_ratio, rtol=1e-4)
    assert_allclose(w.belt_iyy, wt.inertia, rtol=1e-4)
    # Zegelaar / Pacejka: k_theta = I omega^2 = 2 pi R^3 k_t for the ring
    prm = RingTyreParameters()
    assert_allclose(w.k_windup, 2 * np.pi * R**3 * prm.tangential_stiffness, rtol=1e-4)


def test_windup_budget_calibration_closed_form() -> None:
    tr = tangential_truth()
    mdl = tr.modal_model("all")
    w = windup_from_modes(mdl, radius=R)
    a = Assumptions(force_sensitivity=0.03, acceleration_sensitivity=0.04)
    b = windup_budget(
        mdl,
        w,
        analysis=wave_number_analysis(mdl),
        attachment_mass=0,
        attachment_damping=0,
        assumptions=a,
    )
    u = 0.05  # hypot(0.03, 0.04)
    # BELT_IYY ~ 1 / s: half of I / (1 - u) - I / (1 + u) = I u / (1 - u^2)
    assert_allclose(b.terms["BELT_IYY"]["calibration"], w.belt_iyy * u / (1 - u**2), rtol=1e-9)
    # without an attachment the frequency does not depend on the scale
    assert b.terms["FREQ_WINDUP"]["calibration"] == pytest.approx(0.0, abs=1e-12)
    assert f"rigid rotation of the belt seen at radius {R:.4g} m" in b.comment("BELT_IYY")


def test_windup_identified_from_the_noisy_virtual_test() -> None:
    from tyredamp.studies.radial import frf_from_time, modes_from_frf

    t = run_modal_test(
        tyre(), direction="tangential", seed=5, n_periods=2, band=(0.0, 100.0), oversample=4
    )
    frf = frf_from_time(t.data, "H1")
    mdl = modes_from_frf(frf, band=(5.0, 100.0), model="complex").models["complex"]
    lay = tyre().layout
    w = windup_from_modes(
        mdl,
        radius=R,
        attachment_mass=lay.attachment_mass,
        attachment_damping=lay.attachment_damping,
    )
    wt = windup_truth(tyre())
    # 40 dB SNR on every channel, 2 averages: over seeds 1-20 (benchmarks/windup.py) the
    # errors stay below 2e-4 (frequency), 2.7 % (damping) and 0.15 % (inertia), also when
    # the fit splits the resonance into two poles (4 seeds in 20)
    assert_allclose(w.freq_windup, wt.bare_frequency_hz, rtol=4e-4)
    assert_allclose(w.damp_windup, wt.bare_damping_ratio, rtol=0.05)
    assert_allclose(w.belt_iyy, wt.inertia, rtol=0.005)


def test_split_rotation_poles_are_combined_and_said() -> None:
    th = np.radians(np.arange(16) * 22.5)
    one = np.ones(16)
    # a resonance split into two in-phase poles 0.2 Hz apart (bandwidth 0.68 Hz), a third
    # uniform mode far away, and an n = 1 mode
    mdl = synthetic([0.05 * one, 0.3 * one, 0.2 * np.cos(th), 0.04 * one], [33.8, 34.0, 48.0, 90.0])
    w = windup_from_modes(mdl, radius=R)
    assert w.index == 1  # the pole of largest amplitude leads
    # closed form: the residues add, A_t^2 = 0.05^2 + 0.3^2; frequency weighted by them
    assert_allclose(w.belt_iyy, R**2 / (0.05**2 + 0.3**2), rtol=1e-12)
    f_mean = (0.05**2 * 33.8 + 0.3**2 * 34.0) / (0.05**2 + 0.3**2)
    assert_allclose(w.freq_windup, f_mean, rtol=1e-12)
    assert any("split the rotation into 2 poles" in n for n in w.notes)
    assert any("90 Hz are not used" in n for n in w.notes)


# ----------------------------------------------------------------------------- CLI
@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    d = tmp_path_factory.mktemp("windup")
    rad = write_modes_json(d / "rad.json", {"complex": tyre().truth((0.0, 200.0)).modal_model()})
    tan_model = tangential_truth().modal_model("all")
    tan = write_modes_json(d / "tan.json", {"complex": tan_model})
    keep = [k for k in range(tan_model.n_modes) if k != 0]  # without the rotation mode
    no_rot = ModalModel(
        tan_model.poles[keep],
        tan_model.psi_out[:, keep],
        tan_model.psi_in[:, keep],
        mode_kind="complex",
        outputs=tan_model.outputs,
        inputs=tan_model.inputs,
    )
    nr = write_modes_json(d / "no_rotation.json", {"complex": no_rot})
    return rad, tan, nr


def run(args: list[str]) -> tuple[int, str]:
    res = CliRunner().invoke(cli, ["tyre-model", *args])
    return res.exit_code, res.output


def test_cli_round_trip(tmp_path: Path, files: tuple[Path, Path, Path]) -> None:
    rad, tan, _ = files
    out = tmp_path / "out"
    code, text = run(
        [
            str(rad),
            "--tangential",
            str(tan),
            "--pressure",
            "7.5",
            "--radius",
            str(R),
            "--attachment-mass",
            "0.01",
            "--attachment-damping",
            "2",
            "--out",
            str(out),
        ]
    )
    assert code == 0, text
    assert "FREQ_WINDUP" in text
    doc = parse_tir((out / "tyre_inplane_7.5bar.tir").read_text())
    wt = windup_truth(tyre())
    # exact modes in: the truth out, to O(zeta^2) (see test_windup_from_exact_modes_equals_truth)
    assert_allclose(doc["INERTIA"]["BELT_IYY"], wt.inertia, rtol=1e-4)
    assert_allclose(doc["STRUCTURAL"]["FREQ_WINDUP"], wt.bare_frequency_hz, rtol=1e-5)
    assert_allclose(doc["STRUCTURAL"]["DAMP_WINDUP"], wt.bare_damping_ratio, rtol=1e-4)
    assert "BELT_MASS" in doc["INERTIA"]


@pytest.mark.parametrize(
    ("which", "message"),
    [
        ("radial", "response channels are radial"),
        ("no_rotation", "no n = 0 (uniform rotation) mode"),
        ("swapped", "the response channels are tangential (UFF direction 1"),
    ],
)
def test_cli_bad_tangential_input(
    tmp_path: Path,
    files: tuple[Path, Path, Path],
    which: str,
    message: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    from tyredamp.cli import main

    rad, tan, nr = files
    first, second = {"radial": (rad, rad), "no_rotation": (rad, nr), "swapped": (tan, tan)}[which]
    out = tmp_path / "out"
    argv = ["tyre-model", str(first), "--tangential", str(second), "--pressure", "7.5"]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--radius", str(R), "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("tyredamp: error: ")
    assert len(err.strip().splitlines()) == 1
    assert message in err
    assert not out.exists()


def test_merge_writes_the_windup_keys() -> None:
    from tyredamp.tyremodel import build_tyre_model

    rad = tyre().truth((0.0, 200.0)).modal_model()
    tan = tangential_truth().modal_model("all")
    res = build_tyre_model(
        [(7.5 * BAR, rad, "rad.json")], radius=R, tangential=[(7.5 * BAR, tan, "tan.json")]
    )
    base = "\n".join(
        [
            "[MDI_HEADER]",
            "FILE_TYPE = 'tir'",
            "[UNITS]",
            "LENGTH = 'meter'",
            "FORCE = 'newton'",
            "MASS = 'kg'",
            "TIME = 'second'",
            "[OPERATING_CONDITIONS]",
            "INFLPRES = 750000",
            "[INERTIA]",
            "BELT_IYY = 1.0  $ the supplier's",
        ]
    )
    merged = parse_tir(res.merged_tir(base, "base.tir"))
    w = res.windups[0]
    assert w is not None
    assert_allclose(merged["INERTIA"]["BELT_IYY"], w.belt_iyy, rtol=1e-6)  # 7 digits written
    assert_allclose(merged["STRUCTURAL"]["FREQ_WINDUP"], w.freq_windup, rtol=1e-6)
    assert_allclose(merged["STRUCTURAL"]["DAMP_WINDUP"], w.damp_windup, rtol=1e-6)
    doc = res.rigid_document()["rigid_ring"][0]
    assert "FREQ_WINDUP" not in doc["not_given"]
    assert doc["windup"]["BELT_IYY"]["value"] == w.belt_iyy
    # a tangential test at a pressure without a radial test is refused
    with pytest.raises(InputError, match=r"radial tests are at 7\.5 bar"):
        build_tyre_model(
            [(7.5 * BAR, rad, "rad.json")], radius=R, tangential=[(9 * BAR, tan, "tan.json")]
        )
    # and a second one at the same pressure
    with pytest.raises(InputError, match="a second tangential test"):
        build_tyre_model(
            [(7.5 * BAR, rad, "rad.json")],
            radius=R,
            tangential=[(None, tan, "tan.json"), (7.5 * BAR, tan, "tan2.json")],
        )


def test_simulate_tangential_test(tmp_path: Path) -> None:
    from tyredamp.documents.modes import read_modes
    from tyredamp.io import read_frf

    out, truth_file = tmp_path / "tan.npz", tmp_path / "truth.json"
    res = CliRunner().invoke(
        cli,
        [
            "simulate",
            "radial",
            "--direction",
            "tangential",
            "--frf",
            "--periods",
            "1",
            "--no-cavity",
            "--out",
            str(out),
            "--truth",
            str(truth_file),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "true wind-up (n = 0 rotation)" in res.output
    frf = read_frf(out)
    assert {c.direction for c in frf.outputs} == {1}
    mdl = read_modes(truth_file)["complex"]
    w = windup_from_modes(mdl, radius=R, attachment_mass=0.01, attachment_damping=2.0)
    # the exact modes written: the truth to O(zeta^2) (test_windup_from_exact_modes_equals_truth)
    assert_allclose(w.freq_windup, windup_truth(tyre()).bare_frequency_hz, rtol=1e-5)
