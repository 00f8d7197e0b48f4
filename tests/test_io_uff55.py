"""Modes exchanged as UFF data set 55: tyredamp <-> pyuff, scaling, the damping CLI."""

from __future__ import annotations

import gc
import warnings
from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose

from tyredamp import Channel, FileFormatError
from tyredamp.cli import main
from tyredamp.io.uff55 import read_uff55, write_uff55
from tyredamp.modal import ModalModel

from .helpers import chain_system

DRIVE = 1


def complex_model() -> ModalModel:
    cm = chain_system().complex_modes()
    outs = [Channel(node=i + 1, direction=3) for i in range(cm.psi.shape[0])]
    return ModalModel(
        cm.poles, cm.psi, cm.psi[[DRIVE - 1]], "complex", outs, [Channel(node=DRIVE, direction=3)]
    )


def residues(m: ModalModel) -> np.ndarray:
    """psi_out psi_in^T per mode, invariant to the sign of the square roots."""
    return np.einsum("om,im->moi", m.psi_out, m.psi_in)


def pyuff_write(path: Path, sets: list[dict]) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
        gc.collect()


def pyuff_read(path: Path) -> list[dict]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)
        sets = pyuff.UFF(str(path)).read_sets()
        gc.collect()
    return [sets] if isinstance(sets, dict) else sets


# E13.6 fields: 7 significant digits, relative rounding <= 5e-7 per value
RT = 2e-6


def test_complex_modes_round_trip_and_pyuff_reads_them(tmp_path: Path) -> None:
    model = complex_model()
    path = write_uff55(model, tmp_path / "modes.unv")
    sets = pyuff_read(path)
    assert len(sets) == model.n_modes
    for n, s in enumerate(sets):
        assert s["analysis_type"] == 3
        assert_allclose(s["eig"], model.poles[n], rtol=RT)
        assert s["modal_a"] == 1.0
        assert_allclose(s["modal_b"], -model.poles[n], rtol=RT)
        assert_allclose(
            s["r3"], model.psi_out[:, n], rtol=RT, atol=RT * np.abs(model.psi_out).max()
        )
        assert_allclose(s["r1"], 0.0)
    back = read_uff55(path)
    assert back.mode_kind == "complex"
    assert back.outputs == model.outputs
    assert back.inputs == model.inputs  # from tyredamp's ID line 2
    assert_allclose(back.poles, model.poles, rtol=RT)
    assert_allclose(
        residues(back), residues(model), rtol=RT, atol=RT * np.abs(residues(model)).max()
    )


def test_real_modes_round_trip(tmp_path: Path) -> None:
    sysm = chain_system()
    um = sysm.undamped_modes()
    fn = um.omega / (2 * np.pi)
    zeta = np.linspace(0.01, 0.03, fn.size)
    outs = [Channel(node=i + 1, direction=-2 if i == 2 else 3) for i in range(um.phi.shape[0])]
    model = ModalModel.from_real_modes(
        fn, zeta, um.phi, um.phi[[0]], outputs=outs, inputs=[Channel(node=1, direction=3)]
    )
    path = write_uff55(model, tmp_path / "real.uff")
    sets = pyuff_read(path)
    assert [s["analysis_type"] for s in sets] == [2] * fn.size
    assert_allclose([s["freq"] for s in sets], fn, rtol=RT)
    assert_allclose([s["modal_damp_vis"] for s in sets], zeta, rtol=RT)
    # node 3 was measured in -Y: its value sits in r2 with the sign flipped
    assert_allclose(sets[0]["r2"][2], -um.phi[2, 0], rtol=RT)
    back = read_uff55(path)
    assert back.mode_kind == "real"
    assert_allclose(back.frequency_hz, fn, rtol=RT)
    assert_allclose(back.damping_ratio, zeta, rtol=RT)
    assert_allclose(back.poles, model.poles, rtol=RT)
    # the -Y point is read back as +Y: its residues change sign
    sign = np.array([-1.0 if c.direction == -2 else 1.0 for c in outs])
    r0 = residues(model)
    assert_allclose(residues(back) * sign[None, :, None], r0, rtol=RT, atol=RT * np.abs(r0).max())


def test_pyuff_written_modes_with_modal_a_and_mass(tmp_path: Path) -> None:
    """Files as another program writes them: shapes scaled by modal A / modal mass."""
    sysm = chain_system()
    cm = sysm.complex_modes()
    nodes = np.arange(1, cm.Psi.shape[0] + 1)
    sets = [
        pyuff.prepare_55(
            id1="complex modes from a lab program",
            model_type=1,
            analysis_type=3,
            data_ch=2,
            spec_data_type=8,
            load_case=1,
            mode_n=n + 1,
            eig=cm.poles[n],
            modal_a=cm.a[n],
            modal_b=cm.b[n],
            node_nums=nodes,
            r1=np.zeros(nodes.size, complex),
            r2=np.zeros(nodes.size, complex),
            r3=cm.Psi[:, n],
        )
        for n in range(cm.poles.size)
    ]
    path = tmp_path / "lab.unv"
    pyuff_write(path, sets)
    m = read_uff55(path, inputs=[Channel(node=1, direction=3)])
    want = cm.psi[:, None, :] * cm.psi[None, [0], :]  # (o, i, m)
    got = np.einsum("om,im->oim", m.psi_out, m.psi_in)
    # pyuff writes E13.5: 6 significant digits
    assert_allclose(got, want, rtol=2e-5, atol=2e-5 * np.abs(want).max())
    assert "assumptions" in m.meta
    assert not m.meta["assumptions"]  # modal A was given: nothing assumed but the drive point

    um = sysm.undamped_modes()
    real_sets = [
        pyuff.prepare_55(
            id1="normal modes",
            model_type=1,
            analysis_type=2,
            data_ch=2,
            spec_data_type=8,
            load_case=1,
            mode_n=n + 1,
            freq=um.omega[n] / (2 * np.pi),
            modal_m=4.0,
            modal_damp_vis=0.02,
            modal_damp_his=0.0,
            node_nums=nodes,
            r1=np.zeros(nodes.size),
            r2=np.zeros(nodes.size),
            r3=2.0 * um.phi[:, n],  # modal mass 4 for shapes twice the mass-normalised ones
        )
        for n in range(um.omega.size)
    ]
    rpath = tmp_path / "lab_real.unv"
    pyuff_write(rpath, real_sets)
    mr = read_uff55(rpath)
    assert mr.psi_in.shape == mr.psi_out.shape  # no drive points stated: every DOF an input
    assert any("every measured DOF" in a for a in mr.meta["assumptions"])
    ref = ModalModel.from_real_modes(
        um.omega / (2 * np.pi), np.full(um.omega.size, 0.02), um.phi, um.phi
    )
    assert_allclose(residues(mr), residues(ref), rtol=2e-5, atol=2e-5 * np.abs(residues(ref)).max())


def test_damping_cli_on_pyuff_modes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sysm = chain_system()
    cm = sysm.complex_modes()
    nodes = np.arange(1, cm.Psi.shape[0] + 1)
    sets = [
        pyuff.prepare_55(
            model_type=1,
            analysis_type=3,
            data_ch=2,
            spec_data_type=8,
            load_case=1,
            mode_n=n + 1,
            eig=cm.poles[n],
            modal_a=cm.a[n],
            modal_b=cm.b[n],
            node_nums=nodes,
            r1=np.zeros(nodes.size, complex),
            r2=np.zeros(nodes.size, complex),
            r3=cm.Psi[:, n],
        )
        for n in range(cm.poles.size)
    ]
    path = tmp_path / "lab.unv"
    pyuff_write(path, sets)
    out = tmp_path / "damping.json"
    try:
        main(["damping", str(path), "--out", str(out), "--samples", "0"])
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert f"{cm.poles.size} modes at {nodes.size} points" in captured.out
    import json

    doc = json.loads(out.read_text())
    # all modes of the chain at all its points: C is the chain's damping matrix
    html = tmp_path / "report.html"
    main_ok = True
    try:
        main(["report", str(path), "--out", str(html)])
    except SystemExit as exc:
        main_ok = not exc.code
    assert main_ok, capsys.readouterr().err
    assert "Modes: lab.unv" in html.read_text()
    # pyuff writes 6 significant digits; C is a difference of large terms: 1 % of max
    assert_allclose(np.array(doc["physical"]), sysm.C, atol=1e-2 * np.abs(sysm.C).max())


@pytest.mark.parametrize(
    ("content", "word"),
    [
        (None, "no data set 55"),
        ("garbage\n", "data set"),
    ],
)
def test_bad_uff55_files(tmp_path: Path, content: str | None, word: str) -> None:
    path = tmp_path / "bad.unv"
    if content is None:
        from tyredamp.frf import FRF
        from tyredamp.io import write_frf

        write_frf(FRF([1.0, 2.0], [1.0, 2.0]), path)
    else:
        path.write_text(content)
    with pytest.raises(FileFormatError, match=word):
        read_uff55(path)
