"""Rigid ring, .tir subset, lateral bridge and ``tyredamp tyre-model`` (issue 18, items 3-5)."""

from __future__ import annotations

import json
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.axes import Axes
from numpy.testing import assert_allclose

from tyredamp.cli import cli
from tyredamp.cli.tyremodel import write_all_or_none
from tyredamp.documents.modes import write_modes_json
from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.lateral import HystereticModel, LateralData, fit_model
from tyredamp.plot import plot_ring_frequencies
from tyredamp.tyremodel import (
    fit_ring,
    lateral_carcass,
    parse_tir,
    read_lateral_carcass,
    rigid_ring_from_modes,
    tir_text,
)
from tyredamp.virtual import (
    Imperfection,
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    TyreTruth,
)

BAR = 1e5


@cache
def truth(p_bar: float, imperfect: bool = False) -> TyreTruth:
    imps = (Imperfection(60.0, mass=0.5, stiffness=2e4),) if imperfect else ()
    return RingTyre(RingTyreParameters(pressure=p_bar * BAR), imperfections=imps).truth(
        (0.0, 200.0)
    )


# ----------------------------------------------------------------------- rigid ring
@pytest.mark.parametrize("imperfect", [False, True])
def test_rigid_ring_equals_exact_modes(imperfect: bool) -> None:
    tr = truth(7.5, imperfect)
    tyre_mass = 0.5 if imperfect else 0.0
    prm = RingTyreParameters(pressure=7.5 * BAR)
    rr = rigid_ring_from_modes(
        tr.modal_model("visible"), pressure=7.5 * BAR, attachment_mass=0.1, radius=0.5
    )
    # the exact n = 1 modes of the tyre: those the test sees (visible), attachment included
    one = np.flatnonzero((tr.wave_number == 1) & tr.visible)
    f_exact = np.mean(tr.frequency_hz[one])
    z_exact = np.mean(tr.damping_ratio[one])
    # must-show: within 2 % of the values computed from the exact modes
    assert_allclose(rr.freq_long, f_exact, rtol=0.02)
    assert_allclose(rr.damp_long, z_exact, rtol=0.02)
    m_exact = prm.band_mass + tyre_mass  # band 2 pi R rho A plus the imperfection's mass
    assert_allclose(rr.belt_mass, m_exact, rtol=0.02)
    w = 2 * np.pi * f_exact
    assert_allclose(rr.k_long, m_exact * w**2, rtol=0.02)
    assert_allclose(rr.c_long, 2 * z_exact * m_exact * w, rtol=0.02)
    # and the ring's closed form: k = pi R (k_r + k_t)
    assert_allclose(
        rr.k_long, np.pi * 0.5 * (prm.radial_stiffness + prm.tangential_stiffness), rtol=0.03
    )
    # what a radial test cannot give is listed, not invented
    assert "FREQ_WINDUP" in rr.not_given
    assert "tangential" in rr.not_given["FREQ_WINDUP"]
    vis = tr.select("visible")
    assert rr.members
    assert all(vis[m["index"]] in one for m in rr.members)
    if imperfect:
        assert rr.splitting_hz is not None
        assert rr.splitting_hz > 0


def test_rigid_ring_known_attachment_damper() -> None:
    tr = truth(7.5)
    rr = rigid_ring_from_modes(
        tr.modal_model("visible"),
        attachment_mass=MeasurementLayout().attachment_mass,
        attachment_damping=MeasurementLayout().attachment_damping,
    )
    # without the shaker's damper, the member with a node at the drive point (not excited,
    # not attached) has the bare belt's damping
    one = np.flatnonzero((tr.wave_number == 1) & ~tr.visible)
    assert_allclose(rr.damp_long, tr.damping_ratio[one[0]], rtol=0.02)


def test_rigid_ring_standard_errors_propagate() -> None:
    tr = truth(7.5)
    mdl = tr.modal_model("visible")
    std = {
        "frequency_hz": 1e-3 * mdl.frequency_hz,
        "damping_ratio": 1e-3 * np.ones(mdl.n_modes),
        "psi_out": 1e-3 * np.abs(mdl.psi_out).max(axis=0)[None, :] * np.ones(mdl.psi_out.shape),
    }
    from tyredamp.modal.model import ModalModel

    noisy = ModalModel(
        mdl.poles, mdl.psi_out, mdl.psi_in, "complex", mdl.outputs, mdl.inputs, std=std
    )
    rr = rigid_ring_from_modes(noisy, attachment_mass=0.1)
    assert rr.freq_long_std > 0
    assert rr.belt_mass_std > 0
    rel = np.sqrt(
        (rr.belt_mass_std / rr.belt_mass) ** 2 + (2 * rr.freq_long_std / rr.freq_long) ** 2
    )
    assert_allclose(rr.k_long_std / rr.k_long, rel, rtol=1e-12)


def test_rigid_ring_needs_n1() -> None:
    tr = truth(7.5)
    mdl = tr.modal_model("visible")
    from tyredamp.modal.model import ModalModel

    keep = [k for k in range(mdl.n_modes) if k > 0]  # drop the n = 1 mode (the lowest)
    sub = ModalModel(
        mdl.poles[keep],
        mdl.psi_out[:, keep],
        mdl.psi_in[:, keep],
        "complex",
        mdl.outputs,
        mdl.inputs,
    )
    with pytest.raises(InputError, match="n = 1"):
        rigid_ring_from_modes(sub)


# --------------------------------------------------------------------------------- .tir
def test_tir_round_trip() -> None:
    rr = rigid_ring_from_modes(
        truth(7.5).modal_model("visible"), pressure=7.5 * BAR, attachment_mass=0.1, radius=0.5
    )
    text = tir_text(rr, source="m.json", extra_comments=["lateral: K = 1 N/m"])
    doc = parse_tir(text)
    assert_allclose(doc["INERTIA"]["BELT_MASS"], rr.belt_mass, rtol=1e-9)
    assert_allclose(doc["STRUCTURAL"]["FREQ_LONG"], rr.freq_long, rtol=1e-9)
    assert_allclose(doc["STRUCTURAL"]["DAMP_LONG"], rr.damp_long, rtol=1e-9)
    assert doc["OPERATING_CONDITIONS"]["INFLPRES"] == 7.5e5
    assert doc["UNITS"]["MASS"] == "kg"
    # nothing the test cannot give is set
    for key in ("FREQ_WINDUP", "DAMP_WINDUP", "BELT_IYY", "LATERAL_STIFFNESS"):
        assert all(key not in sec for sec in doc.values())
        assert f"$ {key}: not given" in text


def test_tir_parser_reads_comments_and_refuses_bad_lines() -> None:
    doc = parse_tir(
        "!:FILE_TYPE tir\n$ header comment\n[MODEL]\nPROPERTY_FILE_FORMAT = 'MF_62' $ c\n"
        "FITTYP = 62  $ fit type\n[STRUCTURAL]\nFREQ_LONG=77.17\n"
    )
    assert doc == {
        "MODEL": {"PROPERTY_FILE_FORMAT": "MF_62", "FITTYP": 62.0},
        "STRUCTURAL": {"FREQ_LONG": 77.17},
    }
    with pytest.raises(FileFormatError, match="before any"):
        parse_tir("FREQ_LONG = 1\n")
    with pytest.raises(FileFormatError, match="line 2"):
        parse_tir("[A]\nnot a key value line\n")
    with pytest.raises(FileFormatError, match="repeated"):
        parse_tir("[A]\nX = 1\nX = 2\n")
    with pytest.raises(FileFormatError, match="no \\[SECTION\\]"):
        parse_tir("$ only a comment\n")


def test_tir_parser_reads_table_sections() -> None:
    # a [SHAPE] section as ADAMS/MF-Tyre files write it: column names, then rows of numbers
    doc = parse_tir(
        "[DIMENSION]\nWIDTH = 0.335\n[SHAPE]\n{radial width}\n 1.00  0.00\n 0.90  1.00 $ c\n"
        "[VERTICAL]\nFNOMIN = 16929\n"
    )
    assert doc["SHAPE"] == {"_columns": ["radial", "width"], "_rows": [[1.0, 0.0], [0.9, 1.0]]}
    assert doc["VERTICAL"] == {"FNOMIN": 16929.0}
    with pytest.raises(FileFormatError, match="line 2"):
        parse_tir("[SHAPE]\n1.0 abc\n")  # a row that is not numbers is still refused


# ------------------------------------------------------------------------ lateral bridge
def test_lateral_carcass_from_fit_and_dict() -> None:
    true = HystereticModel(K=1.2e5, h=1.5e4, C_r=8.0e3)
    f = np.geomspace(0.3, 9.0, 80)
    speed = 5.0 / 3.6
    data = LateralData(true.frf(f), speed=speed)
    fit = fit_model(data, "hysteretic")
    lc = lateral_carcass(fit, pressure_bar=2.4)
    # relaxation length sigma = C_r V / K (noise-free data: the true values)
    assert_allclose(lc.relaxation_length, true.C_r * speed / true.K, rtol=1e-6)
    assert_allclose(lc.lateral_stiffness, true.K, rtol=1e-6)
    assert_allclose(lc.cornering_stiffness, true.C_r * speed, rtol=1e-6)
    assert lc.correlation_used
    d = {
        "model": "maxwell",
        "params": {"k": 1e5, "c": 2e4},
        "stderr": {"k": 1e3, "c": 4e2},
        "speed_m_s": 2.0,
    }
    lm = lateral_carcass(d)
    assert_allclose(lm.relaxation_length, 2e4 * 2.0 / 1e5, rtol=1e-14)
    # uncorrelated: relative errors add in quadrature
    assert_allclose(lm.relaxation_length_std / lm.relaxation_length, np.hypot(0.01, 0.02))
    assert not lm.correlation_used
    with pytest.raises(InputError, match="no tyre-road damper"):
        lateral_carcass({"model": "classic", "params": {}, "stderr": {}, "speed_m_s": 1.0})
    with pytest.raises(InputError, match="speed"):
        lateral_carcass({**d, "speed_m_s": None})


def test_read_lateral_json(tmp_path: Path) -> None:
    doc = {
        "tyredamp": "lateral-fit",
        "conditions": {"speed_m_s": 2.0, "pressure_bar": 1.7},
        "order": ["classic", "hysteretic"],
        "fits": [
            {"model": "classic", "params": {"k": 1.0, "c": 1.0}, "stderr": {"k": 0, "c": 0}},
            {
                "model": "hysteretic",
                "params": {"K": 1e5, "h": 1e4, "C_r": 5e3},
                "stderr": {"K": 1e3, "h": 1e3, "C_r": 50.0},
                "speed_m_s": 2.0,
            },
        ],
    }
    p = tmp_path / "lat.json"
    p.write_text(json.dumps(doc), encoding="utf-8")
    (lc,) = read_lateral_carcass(p)
    assert lc.model == "hysteretic"
    assert lc.pressure_bar == 1.7
    assert_allclose(lc.relaxation_length, 5e3 * 2.0 / 1e5)
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "modes"}', encoding="utf-8")
    with pytest.raises(FileFormatError, match="lateral-fit"):
        read_lateral_carcass(bad)


# ------------------------------------------------------------------------------- plot
def test_plot_ring_frequencies() -> None:
    fit = fit_ring(
        [(p * BAR, truth(p).modal_model("visible")) for p in (6.0, 9.0)],
        radius=0.5,
        attachment_mass=0.1,
    )
    ax = plot_ring_frequencies(fit)
    assert isinstance(ax, Axes)
    assert len(ax.get_lines()) >= 2


# -------------------------------------------------------------------------------- CLI
@pytest.fixture(scope="module")
def modes_files(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    d = tmp_path_factory.mktemp("modes")
    out = []
    for p in (6.0, 9.0):
        path = d / f"m{p:g}.json"
        write_modes_json(path, {"complex": truth(p).modal_model("visible")})
        out.append(path)
    return out


def test_cli_tyre_model(tmp_path: Path, modes_files: list[Path]) -> None:
    out = tmp_path / "model"
    before = [p.read_bytes() for p in modes_files]
    res = CliRunner().invoke(
        cli,
        [
            "tyre-model",
            *map(str, modes_files),
            "--pressure",
            "6,9",
            "--radius",
            "0.5",
            "--attachment-mass",
            "0.1",
            "--predict",
            "7.5",
            "--out",
            str(out),
        ],
    )
    assert res.exit_code == 0, res.output
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        [
            "ring.json",
            "rigid_ring.json",
            "tyre_inplane_6bar.tir",
            "tyre_inplane_9bar.tir",
            "ring_frequencies.png",
            ".tyredamp-manifest.json",
        ]
    )
    ring = json.loads((out / "ring.json").read_text())
    assert ring["kind"] == "tyre-ring-model"
    assert [m["n"] for m in ring["inputs"][0]["wave_numbers"]["modes"]][:3] == [1, 2, 3]
    assert ring["predictions"][0]["pressure_bar"] == 7.5
    rig = json.loads((out / "rigid_ring.json").read_text())
    tir = parse_tir((out / "tyre_inplane_6bar.tir").read_text())
    assert_allclose(
        tir["INERTIA"]["BELT_MASS"], rig["rigid_ring"][0]["BELT_MASS"]["value"], rtol=1e-9
    )
    assert "n = 1" in res.output
    assert "not given" in res.output
    assert [p.read_bytes() for p in modes_files] == before  # inputs untouched
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


def test_cli_refuses_without_writing(tmp_path: Path, modes_files: list[Path]) -> None:
    runner = CliRunner()
    out = tmp_path / "model"
    res = runner.invoke(
        cli, ["tyre-model", str(modes_files[0]), "--radius", "0.5", "--out", str(out)]
    )
    assert res.exit_code != 0
    assert "pressure" in str(res.exception) or "pressure" in res.output
    assert not out.exists()
    res = runner.invoke(
        cli,
        [
            "tyre-model",
            *map(str, modes_files),
            "--pressure",
            "6",
            "--radius",
            "0.5",
            "--out",
            str(out),
        ],
    )
    assert res.exit_code != 0
    assert not out.exists()
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    res = runner.invoke(
        cli,
        [
            "tyre-model",
            *map(str, modes_files),
            "--pressure",
            "6,9",
            "--radius",
            "0.5",
            "--out",
            str(out),
        ],
    )
    assert res.exit_code != 0
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]


def test_write_all_or_none(tmp_path: Path) -> None:
    def ok(p: Path) -> None:
        p.write_text("x")

    def boom(p: Path) -> None:
        p.write_text("partial")
        raise RuntimeError("disk full")

    target = tmp_path / "out"
    with pytest.raises(RuntimeError):
        write_all_or_none(target, {"a.txt": ok, "b.txt": boom})
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []
    # an existing empty directory is filled
    target.mkdir()
    files = write_all_or_none(target, {"a.txt": ok})
    assert [f.name for f in files] == ["a.txt"]
    assert (target / "a.txt").read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_modal_command_labels_wave_numbers() -> None:
    from tyredamp.cli.modal import modes_table
    from tyredamp.plot import plot_mode_shapes_ring
    from tyredamp.studies.radial import label_wave_numbers

    mdl = truth(7.0).modal_model("visible")
    label_wave_numbers(mdl)
    assert mdl.meta["wave_number"] == truth(7.0).wave_number[truth(7.0).select("visible")].tolist()
    table = "\n".join(modes_table("complex", mdl))
    assert "n = 1 (cos)" in table
    axes = plot_mode_shapes_ring(mdl, modes=[2])
    assert "n = 3" in axes[0].get_title()


def test_cli_one_line_error_without_angles(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tyredamp.cli import main
    from tyredamp.frf import Channel
    from tyredamp.modal.model import ModalModel

    mdl = truth(7.0).modal_model("visible")
    bare = ModalModel(
        mdl.poles,
        mdl.psi_out,
        mdl.psi_in,
        outputs=[Channel(node=c.node) for c in mdl.outputs],
        inputs=mdl.inputs,
    )
    path = tmp_path / "m.json"
    write_modes_json(path, {"complex": bare})
    out = tmp_path / "model"
    argv = ["tyre-model", str(path), "--pressure", "7", "--radius", "0.5", "--out", str(out)]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("tyredamp: error:")
    assert len(err.strip().splitlines()) == 1
    assert "angle" in err
    assert not out.exists()


@given(
    mass=st.floats(1e-3, 1e4),
    freq=st.floats(1e-2, 1e4),
    damp=st.floats(1e-6, 1.0),
    pressure=st.floats(0.0, 1e7),
)
@settings(max_examples=50, deadline=None)
def test_tir_round_trip_property(mass: float, freq: float, damp: float, pressure: float) -> None:
    from tyredamp.tyremodel import RigidRingParameters

    w = 2 * np.pi * freq
    rr = RigidRingParameters(
        pressure=pressure,
        belt_mass=mass,
        belt_mass_std=0.01 * mass,
        freq_long=freq,
        freq_long_std=0.0,
        damp_long=damp,
        damp_long_std=0.0,
        k_long=mass * w**2,
        k_long_std=0.0,
        c_long=2 * damp * mass * w,
        c_long_std=0.0,
    )
    doc = parse_tir(tir_text(rr))
    # written with 10 significant digits
    assert_allclose(doc["INERTIA"]["BELT_MASS"], mass, rtol=1e-9)
    assert_allclose(doc["STRUCTURAL"]["FREQ_LONG"], freq, rtol=1e-9)
    assert_allclose(doc["STRUCTURAL"]["DAMP_LONG"], damp, rtol=1e-9)
    assert_allclose(doc["OPERATING_CONDITIONS"]["INFLPRES"], pressure, rtol=1e-9)
