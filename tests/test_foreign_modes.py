"""Mode sets from other programs and roving-hammer tests.

A UFF 55 export of a beam (13 modes at 8 points, geometry in the same file,
written with pyuff's own writer as a foreign program would), the real
geometry files of the gallery, and the real roving-hammer FRFs of a beam
(one accelerometer at node 1, the hammer at nodes 1, 2, 3).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.cli import main
from tyredamp.damping import identify_damping
from tyredamp.damping.modeset import (
    at_shape_points,
    parse_mode_numbers,
    scaling_problem,
    select_modes,
    shape_side,
)
from tyredamp.documents.modes import modes_document, read_modes, write_modes_json
from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.frf import FRF, Channel
from tyredamp.geometry import Geometry
from tyredamp.io.uff55 import read_uff55
from tyredamp.io.uff_geometry import read_uff_geometry
from tyredamp.modal.identify import identify_modes
from tyredamp.modal.model import ModalModel
from tyredamp.plot.geometry import geometry_view, mode_displacements, plot_mode_shapes_geometry
from tyredamp.plot.modeshapes import plot_mode_shapes, shape_views
from tyredamp.report.files import build_files_report
from tyredamp.studies.radial import damping_from_modes
from tyredamp.tyremodel.layout import evenly_around, ring_angles
from tyredamp.virtual import RingTyre, RingTyreParameters

pyuff = pytest.importorskip("pyuff")

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data" / "ladisk_pyuff" / "data"
#: The beam's modes, given to the identification (its mode count is not tested here).
BEAM_MODES_HZ = [51.5, 142.2, 278.7, 460.4, 687.2, 958.5]


def real(name: str) -> Path:
    p = REAL / name
    if not p.exists():
        pytest.skip(f"real-data gallery not found ({p})")
    return p


# ------------------------------------------------------------------ a foreign UFF 55
def _pole(f_hz: float, zeta: float) -> complex:
    wn = 2 * np.pi * f_hz
    return complex(-zeta * wn, wn * np.sqrt(1 - zeta**2))


def write_foreign_uff55(
    path: Path,
    poles: np.ndarray,
    xyz_values: np.ndarray,
    coordinates: np.ndarray | None,
    modal_a: float = 0.0,
    trace: list[int] | None = None,
) -> Path:
    """Complex modes (analysis type 3) at nodes 1..n as another program writes them.

    ``xyz_values`` has shape (m, 3, n) (X, Y, Z of every node in every mode);
    ``coordinates`` (n, 3) in m, or None for no geometry in the file.
    """
    n = xyz_values.shape[2]
    nodes = np.arange(1, n + 1)
    sets = []
    if coordinates is not None:
        zeros = np.zeros(n, int)
        sets.append(
            pyuff.prepare_15(
                node_nums=nodes,
                def_cs=zeros,
                disp_cs=zeros,
                color=np.ones(n, int),
                x=coordinates[:, 0],
                y=coordinates[:, 1],
                z=coordinates[:, 2],
            )
        )
        line = nodes if trace is None else np.asarray(trace)
        sets.append(pyuff.prepare_82(trace_num=1, n_nodes=line.size, color=1, id="t", nodes=line))
    for k, p in enumerate(poles):
        r = xyz_values[k]
        sets.append(
            pyuff.prepare_55(
                id1="foreign",
                id2="NONE",
                id3="NONE",
                id4="NONE",
                id5="NONE",
                model_type=1,
                analysis_type=3,
                data_ch=2,
                spec_data_type=8,
                data_type=5,
                n_data_per_node=3,
                r1=r[0],
                r2=r[1],
                r3=r[2],
                load_case=1,
                mode_n=k + 1,
                eig=complex(p),
                modal_a=modal_a,
                modal_b=-complex(p) * modal_a,
                node_nums=nodes,
            )
        )
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    return path


def beam_values(n_nodes: int = 8, n_modes: int = 13) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poles, (m, 3, n) Z-only complex shapes and node coordinates of a free-free-ish beam."""
    x = np.linspace(0.0, 1.0, n_nodes)
    poles = np.array([_pole(20.0 * (k + 1) ** 2, 0.01 + 0.001 * k) for k in range(n_modes)])
    vals = np.zeros((n_modes, 3, n_nodes), complex)
    phase = np.exp(1j * 0.05 * np.arange(n_nodes) / n_nodes)  # slightly complex shapes
    for k in range(n_modes):
        vals[k, 2] = 1e-2 * np.sin((k + 1) * np.pi * (x + 0.05) / 1.1) * phase
    xyz = np.column_stack([x, np.zeros(n_nodes), np.zeros(n_nodes)])
    return poles, vals, xyz


@pytest.fixture
def beam_files(tmp_path: Path) -> dict[str, Path]:
    poles, vals, xyz = beam_values()
    return {
        "unscaled": write_foreign_uff55(tmp_path / "beam.uff", poles, vals, xyz, modal_a=0.0),
        "scaled": write_foreign_uff55(tmp_path / "beam_a.uff", poles, vals, xyz, modal_a=1.0),
    }


Run = Callable[..., tuple[int, str]]


@pytest.fixture
def run(capsys: pytest.CaptureFixture[str]) -> Run:
    """``tyredamp ARGS`` as the console script runs it: (exit code, stdout + stderr)."""

    def _run(*args: str) -> tuple[int, str]:
        code = 0
        try:
            main(list(args))
        except SystemExit as exc:
            code = int(exc.code or 0)
        out = capsys.readouterr()
        return code, out.out + out.err

    return _run


# -------------------------------------------------------------------------- scaling
def test_uff55_modal_a_zero_is_unscaled(beam_files: dict[str, Path]) -> None:
    m0 = read_uff55(beam_files["unscaled"])
    m1 = read_uff55(beam_files["scaled"])
    assert m0.meta["scaled"] is False
    assert "modal A" in m0.meta["scaling_note"]
    assert m1.meta["scaled"] is True
    assert "modal A" in scaling_problem(m0)
    assert scaling_problem(m1) == ""
    assert m0.meta["drive_points_stated"] is False  # the file does not say where it was hit


@pytest.mark.parametrize(("modal_m", "scaled"), [(0.0, False), (2.0, True)])
def test_uff55_real_modes_without_modal_mass_are_unscaled(
    tmp_path: Path, modal_m: float, scaled: bool
) -> None:
    nodes = np.arange(1, 4)
    s = pyuff.prepare_55(
        id1="real", id2="NONE", id3="NONE", id4="NONE", id5="NONE", model_type=1,
        analysis_type=2, data_ch=2, spec_data_type=8, data_type=2, n_data_per_node=3,
        r1=np.zeros(3), r2=np.zeros(3), r3=np.array([1.0, 0.5, -0.5]), load_case=1, mode_n=1,
        freq=12.0, modal_m=modal_m, modal_damp_vis=0.01, modal_damp_his=0.0, node_nums=nodes,
    )  # fmt: skip
    path = tmp_path / "real.uff"
    pyuff.UFF(str(path)).write_sets([s], mode="overwrite")
    m = read_uff55(path)
    assert m.meta["scaled"] is scaled
    assert ("modal mass" in scaling_problem(m)) is not scaled


def test_damping_refuses_unscaled_modes_in_one_line(
    beam_files: dict[str, Path], tmp_path: Path, run: Run
) -> None:
    out = tmp_path / "d.json"
    code, text = run("damping", str(beam_files["unscaled"]), "-o", str(out), "--modes", "1-3")
    assert code == 2
    lines = [s for s in text.splitlines() if s.strip()]
    assert len(lines) == 1
    assert lines[0].startswith("tyredamp: error:")
    assert "unscaled" in text
    assert "modal A" in text
    assert "drive-point FRF" in text
    assert not out.exists()


def test_fit_without_drive_point_is_unscaled() -> None:
    m = ModalModel(
        [_pole(10.0, 0.01)], [[1.0], [0.5]], [[0.3]], outputs=[Channel(1, 3), Channel(2, 3)]
    )
    assert scaling_problem(m) == ""  # input 1+Z is the drive point (default node 1, dir 3)
    m2 = ModalModel(
        [_pole(10.0, 0.01)],
        [[1.0], [0.5]],
        [[0.3]],
        outputs=[Channel(1, 3), Channel(2, 3)],
        inputs=[Channel(9, 3)],
    )
    assert "drive point" in scaling_problem(m2)
    doc = modes_document({"complex": m2})
    assert doc["models"]["complex"]["scaled"] is False
    assert "drive point" in doc["models"]["complex"]["scaling_note"]
    with pytest.raises(InputError, match="unscaled"):
        damping_from_modes({"complex": m2}, n_samples=0)


# ---------------------------------------------------------------------- mode subsets
def test_parse_mode_numbers() -> None:
    assert parse_mode_numbers("1,2,5-7") == [1, 2, 5, 6, 7]
    assert parse_mode_numbers(" 3 ; 1 ") == [3, 1]
    for bad in ("", "a", "3-1", "0,1", "1,1", "2-x"):
        with pytest.raises(InputError):
            parse_mode_numbers(bad)


def test_too_many_modes_for_the_points_says_how_many(
    beam_files: dict[str, Path], tmp_path: Path, run: Run
) -> None:
    code, text = run("damping", str(beam_files["scaled"]), "-o", str(tmp_path / "d.json"))
    assert code == 2
    assert "13 modes at 8 points" in text
    assert "at most 8 modes" in text
    assert "--modes" in text


def test_damping_on_chosen_modes(beam_files: dict[str, Path], tmp_path: Path, run: Run) -> None:
    out = tmp_path / "d.json"
    code, text = run(
        "damping", str(beam_files["scaled"]), "-o", str(out), "--modes", "1,2,5-7", "--samples", "0"
    )
    assert code == 0, text
    doc = json.loads(out.read_text())
    assert doc["meta"]["modes_used"] == [1, 2, 5, 6, 7]
    assert doc["meta"]["n_modes_available"] == 13
    assert doc["meta"]["shape_points"] == "outputs"
    assert doc["meta"]["scaling"] == "mass-normalised"
    full = read_uff55(beam_files["scaled"])
    idx = [0, 1, 4, 5, 6]
    assert_allclose(doc["modes"]["frequency_hz"], full.frequency_hz[idx], rtol=1e-12)  # copied
    # the same C' as identified from a hand-cut model of those modes
    cut = ModalModel(
        full.poles[idx], full.psi_out[:, idx], full.psi_in[:, idx], outputs=full.outputs
    )
    ref = identify_damping(cut, n_samples=0)
    assert_allclose(doc["modal"], ref.modal, rtol=1e-9, atol=1e-12 * np.abs(ref.modal).max())
    assert "modes used: 1-2, 5-7 of 1-13" in text


def test_damping_on_a_band(beam_files: dict[str, Path], tmp_path: Path, run: Run) -> None:
    out = tmp_path / "d.json"
    code, text = run(
        "damping",
        str(beam_files["scaled"]),
        "-o",
        str(out),
        "--band",
        "50",
        "600",
        "--samples",
        "0",
    )
    assert code == 0, text
    f = read_uff55(beam_files["scaled"]).frequency_hz
    want = [k + 1 for k in range(f.size) if 50 <= f[k] <= 600]
    assert json.loads(out.read_text())["meta"]["modes_used"] == want
    code, text = run("damping", str(beam_files["scaled"]), "-o", str(out), "--modes", "1,14")
    assert code == 2
    assert "--modes: mode 14 does not exist" in text


def test_select_modes_keeps_per_mode_records() -> None:
    tr = RingTyre(RingTyreParameters(pressure=7e5)).truth((0.0, 200.0))
    m = tr.modal_model("visible")
    m.meta["mpc"] = list(np.arange(m.n_modes) / 10)
    sub, nums = select_modes(m, [2, 4], band=(0.0, 1e4))
    assert nums == [2, 4]
    assert sub.meta["mpc"] == [m.meta["mpc"][1], m.meta["mpc"][3]]
    assert_allclose(sub.poles, m.poles[[1, 3]], rtol=0)  # copied, not computed
    two = ModalModel(m.poles[:2], m.psi_out[:, :2], m.psi_in[:, :2], meta={"band_hz": [0, 9]})
    assert select_modes(two, [2])[0].meta["band_hz"] == [0, 9]  # not a per-mode list
    with pytest.raises(InputError, match="no mode chosen"):
        select_modes(m, band=(1e5, 2e5))


# --------------------------------------------------------------- layout and drawing
def test_ring_layout_from_data() -> None:
    th = np.radians(np.arange(16) * 22.5)
    ring = Geometry(range(1, 17), np.column_stack([np.cos(th), np.sin(th), np.zeros(16)]))
    chans = [Channel(k, 1) for k in range(1, 17)]
    ang = ring_angles(chans, ring)
    assert ang is not None
    assert_allclose(ang, np.arange(16) * 22.5, atol=1e-9)  # rounding of the circle fit
    half = Geometry(
        range(1, 9), np.column_stack([np.cos(th[:8] / 2), np.sin(th[:8] / 2), np.zeros(8)])
    )
    assert ring_angles(chans[:8], half) is None  # a half circle is not a tread
    line = Geometry(range(1, 9), np.column_stack([np.arange(8.0), np.zeros(8), np.zeros(8)]))
    assert ring_angles(chans[:8], line) is None
    assert evenly_around([0, 90, 180, 270])
    assert not evenly_around([0, 10, 20, 30])


def test_beam_drawn_on_its_geometry_not_as_a_ring(beam_files: dict[str, Path]) -> None:
    m = read_uff55(beam_files["scaled"])
    g = read_uff_geometry(beam_files["scaled"])
    assert shape_views(m, g) == ["geometry"]
    assert shape_views(m) == ["points"]  # no geometry, no angles: shape against point
    dim, basis = geometry_view(g)
    assert dim == 2
    drawn = plot_mode_shapes(m, g, modes=[0, 1])
    assert [v for v, _ in drawn] == ["geometry"]
    # the view shows the beam's axis and its bending (z), not the arbitrary y
    dim, basis = geometry_view(g, np.tile([0.0, 0.0, 1e-3], (1, g.n_nodes, 1)))
    assert dim == 2
    assert_allclose(np.abs(basis[:, 0]), [1, 0, 0], atol=1e-9)  # rounding of the SVD
    assert_allclose(np.abs(basis[:, 1]), [0, 0, 1], atol=1e-9)


def test_tyre_modes_drawn_as_a_ring() -> None:
    m = RingTyre(RingTyreParameters(pressure=7e5)).truth((0.0, 200.0)).modal_model("visible")
    assert shape_views(m) == ["ring"]
    no_angles = ModalModel(m.poles, m.psi_out, m.psi_in)
    assert shape_views(no_angles) == ["points"]
    # the same points given by a geometry: the wireframe and the ring, shapes as measured
    th = np.radians([c.angle_deg for c in m.outputs])
    g = Geometry([c.node for c in m.outputs], np.column_stack([np.cos(th), np.sin(th), 0 * th]))
    assert shape_views(no_angles, g) == ["geometry", "ring"]
    drawn = dict(plot_mode_shapes(no_angles, g, modes=[0]))
    ring_line = drawn["ring"][0].lines[1].get_ydata()
    s = m.second_order_shapes()[:, 0]
    assert_allclose(ring_line[:-1], 1 + 0.3 * (s / np.max(np.abs(s))).real, rtol=1e-12)  # rounding


def test_report_of_a_beam_uff55_with_its_geometry(beam_files: dict[str, Path]) -> None:
    html = build_files_report([beam_files["unscaled"]])
    assert "mode shapes on the test geometry" in html
    assert "around the circumference" not in html
    assert "Unscaled mode shapes" in html


@pytest.mark.parametrize(
    "name",
    [
        "mesh_Oros-modal_uff15_uff2412.uff",
        "Artemis export - Geometry RPBC_setup_05_14102016_105117.uff",
        "TestLab 161 164 18 15 82.uff",
    ],
)
def test_shapes_on_real_geometry_files(name: str) -> None:
    g = read_uff_geometry(real(name))
    nodes = list(g.nodes)[:: max(1, g.n_nodes // 10)][:10]
    outs = [Channel(n, d) for n in nodes for d in (1, 2, 3)]
    rng = np.random.default_rng(1)
    m = ModalModel(
        [_pole(10.0, 0.02), _pole(25.0, 0.02)],
        rng.standard_normal((len(outs), 2)) * 1e-2,
        rng.standard_normal((1, 2)) * 1e-2,
        outputs=outs,
        inputs=[outs[2]],
    )
    assert shape_views(m, g)[0] == "geometry"
    axs = plot_mode_shapes_geometry(m, g)
    dim, _ = geometry_view(g, mode_displacements(m, g))
    assert len(axs) == 2
    assert axs[0].name == ("3d" if dim == 3 else "rectilinear")
    for line in g.trace_lines:
        assert all(n in g.nodes for n in line)


def test_element_outlines_from_2412() -> None:
    p = real("mesh_Oros-modal_uff15_uff2412.uff")
    g = read_uff_geometry(p)
    u = pyuff.UFF(str(p))
    types = list(u.get_set_types())
    elems = u.read_sets(types.index(2412))
    n_el = sum(len(v["nodes_nums"]) for v in elems.values() if isinstance(v, dict))
    closed = [line for line in g.trace_lines if line[0] == line[-1]]
    assert len(closed) == n_el  # every element's outline, closed
    assert {len(line) for line in closed} == {5}  # quadrilaterals


# ------------------------------------------------------------------------ tyre model
def _tyre_uff(tmp_path: Path, p_bar: float, with_geometry: bool = True) -> tuple[Path, Path]:
    """The virtual tyre's exact modes as a modes JSON and as a foreign UFF 55 (X, Y)."""
    m = RingTyre(RingTyreParameters(pressure=p_bar * 1e5)).truth((0.0, 200.0))
    mdl = m.modal_model("visible")
    js = tmp_path / f"t{p_bar:g}.json"
    write_modes_json(js, {"complex": mdl})
    th = np.radians([c.angle_deg for c in mdl.outputs])
    vals = np.zeros((mdl.n_modes, 3, th.size), complex)
    vals[:, 0] = (mdl.psi_out * np.cos(th)[:, None]).T
    vals[:, 1] = (mdl.psi_out * np.sin(th)[:, None]).T
    xyz = np.column_stack([0.5 * np.cos(th), 0.5 * np.sin(th), np.zeros(th.size)])
    uff = write_foreign_uff55(
        tmp_path / f"t{p_bar:g}.uff",
        mdl.poles,
        vals,
        xyz if with_geometry else None,
        modal_a=1.0,
        trace=[*range(1, th.size + 1), 1],
    )
    return js, uff


def test_tyre_model_reads_a_ring_uff55(tmp_path: Path, run: Run) -> None:
    files = [_tyre_uff(tmp_path, p) for p in (6.0, 9.0)]
    common = ["--pressure", "6,9", "--radius", "0.5", "--attachment-damping", "0"]
    code, text = run("tyre-model", *(str(j) for j, _ in files), "-o", str(tmp_path / "a"), *common)
    assert code == 0, text
    code, text = run("tyre-model", *(str(u) for _, u in files), "-o", str(tmp_path / "b"), *common)
    assert code == 0, text
    a = json.loads((tmp_path / "a" / "ring.json").read_text())
    b = json.loads((tmp_path / "b" / "ring.json").read_text())
    wa = [m["n"] for m in a["inputs"][0]["wave_numbers"]["modes"]]
    assert [m["n"] for m in b["inputs"][0]["wave_numbers"]["modes"]] == wa
    pb = {q["name"]: q for q in b["ring"]["parameters"]}
    for q in a["ring"]["parameters"]:
        # the UFF 55 fields hold 7 significant digits: the parameters move by far less
        # than their standard errors (5 % of one), and the mass per length barely at all
        assert abs(pb[q["name"]]["value"] - q["value"]) <= 0.05 * q["stderr"], q["name"]
    pa = {q["name"]: q for q in a["ring"]["parameters"]}
    assert_allclose(pb["rhoA"]["value"], pa["rhoA"]["value"], rtol=1e-5)  # 7-digit fields


def test_tyre_model_refuses_what_is_not_a_ring(
    beam_files: dict[str, Path], tmp_path: Path, run: Run
) -> None:
    code, text = run(
        "tyre-model",
        str(beam_files["scaled"]),
        "--pressure",
        "2",
        "--radius",
        "0.5",
        "-o",
        str(tmp_path / "x"),
    )
    assert code == 2
    assert "not a ring" in text
    assert len(text.strip().splitlines()) == 1
    _, bare = _tyre_uff(tmp_path, 7.0, with_geometry=False)
    code, text = run(
        "tyre-model", str(bare), "--pressure", "7", "--radius", "0.5", "-o", str(tmp_path / "y")
    )
    assert code == 2
    assert "no node coordinates" in text
    assert "--geometry" in text
    assert not (tmp_path / "x").exists()
    assert not (tmp_path / "y").exists()


# ---------------------------------------------------------------- roving hammer (real)
@pytest.fixture(scope="module")
def beam_frf() -> FRF:
    h = np.array(
        [
            np.loadtxt(real(f"meas_point_{k}.txt"), dtype=complex, converters=complex)
            for k in (1, 2, 3)
        ]
    )
    f = np.arange(h.shape[1], dtype=float)  # 0-1000 Hz at 1 Hz
    return FRF(
        f[1:],
        h[None, :, 1:],  # line 0 (DC) is meaningless
        kind="accelerance",
        outputs=[Channel(1, 3)],
        inputs=[Channel(1, 3), Channel(2, 3), Channel(3, 3)],
    )


@pytest.fixture(scope="module")
def beam_models(beam_frf: FRF) -> dict[str, ModalModel]:
    return dict(identify_modes(beam_frf, frequencies=BEAM_MODES_HZ).models)


def test_roving_hammer_shapes_at_the_inputs(beam_models: dict[str, ModalModel]) -> None:
    m = beam_models["complex"]
    assert shape_side(m) == "inputs"
    pts = at_shape_points(m)
    assert [c.node for c in pts.outputs] == [1, 2, 3]
    assert pts.meta["shapes_from"] == "inputs"
    assert at_shape_points(pts) is pts  # a second call changes nothing
    f = np.linspace(40.0, 900.0, 50)
    # reciprocity: the reciprocal model's receptance is the transpose (to rounding)
    assert_allclose(pts.receptance(f), np.swapaxes(m.receptance(f), 0, 1), rtol=1e-12)
    doc = modes_document(beam_models)
    assert doc["models"]["complex"]["shapes_at"] == "inputs"
    assert doc["models"]["complex"]["scaled"] is True  # node 1 is hit and measured
    assert shape_views(m) == ["points"]


def test_roving_hammer_damping_at_the_hammer_points(beam_models: dict[str, ModalModel]) -> None:
    # the beam's response is not at hammer point 1 for every mode: the even modes
    # (and the weak 900.9 Hz one) have a negative modal mass there, so their shapes
    # cannot be mass-normalised; chosen by hand they are refused, by default left out
    refusal = r"1\+Z gives the mode\(s\) at 142\.2.*negative modal mass"
    with pytest.raises(InputError, match=refusal):
        damping_from_modes(beam_models, modes=[1, 2, 3], n_samples=0)
    auto = damping_from_modes(beam_models, n_samples=0)
    assert auto.meta["modes_used"] == [1, 3, 5]
    assert "were left out" in auto.findings[0]
    # modes 1, 3 and 5 are scaled, but their shapes' phases (zeta 0.02 %) are below
    # what the fit resolves: C' indefinite and further from the modes than diag C'
    assert auto.diagnostics.definiteness_modal == "indefinite"
    assert any(f.startswith("C' is not determined by these modes") for f in auto.findings)
    dm = damping_from_modes(beam_models, modes=[1], n_samples=0)
    assert [c.node for c in dm.points] == [1, 2, 3]
    assert dm.meta["shape_points"] == "inputs"
    assert dm.meta["modes_used"] == [1]
    # the fit gives the shapes at the hammer points their standard errors
    with_std = damping_from_modes(beam_models, modes=[1], n_samples=20)
    assert not any("excitation points carry no standard errors" in f for f in with_std.findings)
    assert np.all(np.isfinite(with_std.std["modal"]))
    # eq. [15]: C'_nn = -2 Re p_n, here of mode 1 of the file (not of any other)
    m = beam_models["complex"]
    assert_allclose(np.diag(dm.modal), -2 * m.poles.real[:1], rtol=1e-9)  # rounding


def test_roving_hammer_without_drive_point_is_refused(beam_frf: FRF) -> None:
    sub = FRF(
        beam_frf.frequency,
        beam_frf.H[:, 1:, :],
        kind="accelerance",
        outputs=beam_frf.outputs,
        inputs=beam_frf.inputs[1:],
    )
    models = identify_modes(sub, frequencies=BEAM_MODES_HZ[:3], band=(20.0, 350.0)).models
    assert "drive point" in scaling_problem(at_shape_points(models["complex"]))
    with pytest.raises(InputError, match="unscaled"):
        damping_from_modes(dict(models), n_samples=0)


def test_roving_hammer_report_and_cli(
    beam_models: dict[str, ModalModel], tmp_path: Path, run: Run
) -> None:
    js = tmp_path / "beam_modes.json"
    write_modes_json(js, beam_models, source="beam")
    html = build_files_report([js])
    assert "excitation points" in html
    assert "against the point" in html
    assert "around the circumference" not in html
    out = tmp_path / "d.json"
    code, text = run("damping", str(js), "-o", str(out), "--modes", "1", "--samples", "0")
    assert code == 0, text
    assert "points: the inputs (1+Z, 2+Z, 3+Z)" in text
    doc = json.loads(out.read_text())
    assert [p["node"] for p in doc["points"]] == [1, 2, 3]
    assert read_modes(js)["complex"].n_modes == len(BEAM_MODES_HZ)


def test_a_file_that_is_not_modes_says_what_modes_come_from(tmp_path: Path) -> None:
    tir = tmp_path / "tyre.tir"
    tir.write_text("[VERTICAL]\nFNOMIN = 4000\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"tyre\.tir: not valid JSON.*modes JSON.*'\.tir'"):
        read_modes(tir)
