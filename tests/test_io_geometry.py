"""Test geometry from UFF 15/2411/82/18/2420/164 written by pyuff; ring angles on channels."""

from __future__ import annotations

import gc
import warnings
from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose

from tyredamp import Channel, FileFormatError, InputError
from tyredamp.geometry import Geometry
from tyredamp.io.uff_geometry import read_uff_geometry

N = 16
R = 0.5  # m


def write(path: Path, sets: list[dict]) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
        gc.collect()


def ring_sets(mm: bool = True, cylindrical: bool = False) -> list[dict]:
    """16 points on a ring of radius 0.5 m in the global x-z plane, closed trace line."""
    ang = np.arange(N) * 360.0 / N
    k = 1000.0 if mm else 1.0
    if cylindrical:  # system 5: cylinder axis along global -y, origin (1, 2, 3) m
        rot = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])  # local x, y, z axes in global
        mat = np.vstack([rot, np.array([1.0, 2.0, 3.0]) * k])
        cs = [
            pyuff.prepare_2420(
                Part_UID=1,
                Part_Name="tyre",
                CS_sys_labels=[5],
                CS_types=[1],
                CS_colors=[8],
                CS_names=["cyl"],
                CS_matrices=[mat],
            )
        ]
        nodes = pyuff.prepare_15(
            node_nums=list(range(1, N + 1)),
            def_cs=[5] * N,
            disp_cs=[5] * N,
            color=[1] * N,
            x=np.full(N, R * k),
            y=ang,
            z=np.zeros(N),
        )
    else:
        cs = []
        t = np.radians(ang)
        nodes = pyuff.prepare_15(
            node_nums=list(range(1, N + 1)),
            def_cs=[0] * N,
            disp_cs=[0] * N,
            color=[1] * N,
            x=R * np.cos(t) * k,
            y=np.zeros(N),
            z=R * np.sin(t) * k,
        )
    units = [
        pyuff.prepare_164(
            units_code=5 if mm else 1,
            units_description="mm" if mm else "SI",
            temp_mode=1,
            length=k,
            force=1.0,
            temp=1.0,
            temp_offset=273.15,
        )
    ]
    trace = pyuff.prepare_82(
        trace_num=1, n_nodes=N + 1, color=1, id="ring", nodes=np.r_[np.arange(1, N + 1), 1]
    )
    return units + cs + [nodes, trace]


def test_ring_geometry_from_pyuff(tmp_path: Path) -> None:
    path = tmp_path / "geo.unv"
    write(path, ring_sets(mm=True))
    g = read_uff_geometry(path)
    assert g.nodes == tuple(range(1, N + 1))
    t = np.radians(np.arange(N) * 360.0 / N)
    assert_allclose(
        g.coordinates, np.column_stack([R * np.cos(t), 0 * t, R * np.sin(t)]), atol=1e-6
    )  # pyuff writes data set 15 as E13.5: 6 digits of 500 mm
    assert g.trace_lines == ((*range(1, N + 1), 1),)
    chans = [Channel(n, 3) for n in (1, 3, 5, 9)]
    ang = g.ring_angles(chans)
    assert ang is not None
    assert_allclose(ang, [0.0, 45.0, 90.0, 180.0], atol=1e-3)
    got = [c.angle_deg for c in g.with_angles(chans)]
    assert got == pytest.approx([0.0, 45.0, 90.0, 180.0], abs=1e-3)


def test_cylindrical_system_2420_and_radial_directions(tmp_path: Path) -> None:
    path = tmp_path / "cyl.unv"
    write(path, ring_sets(mm=False, cylindrical=True))
    g = read_uff_geometry(path)
    th = np.radians(np.arange(N) * 360.0 / N)
    # local (r cos th, r sin th, 0) with local x -> global x, local y -> global z
    want = np.column_stack([1 + R * np.cos(th), np.full(N, 2.0), 3 + R * np.sin(th)])
    assert_allclose(g.coordinates, want, atol=1e-12)
    # direction 1 of a cylindrical displacement system is radial at the node
    radial = g.direction_vectors([Channel(n, 1) for n in range(1, N + 1)])
    assert_allclose(radial, (want - [1.0, 2.0, 3.0]) / R, atol=1e-12)
    assert g.ring_angles([Channel(n, 1) for n in range(1, N + 1)]) is not None


def test_coordinate_system_18(tmp_path: Path) -> None:
    cs = pyuff.prepare_18(
        cs_num=[7],
        cs_type=[0],
        ref_cs_num=[0],
        color=[1],
        method=[1],
        cs_name=["shifted"],
        ref_o=np.array([[1.0, 0.0, 0.0]]),
        x_point=np.array([[1.0, 1.0, 0.0]]),  # local x = global y
        xz_point=np.array([[1.0, 1.0, 1.0]]),  # local z = global z
    )
    nodes = pyuff.prepare_15(
        node_nums=[1, 2],
        def_cs=[7, 0],
        disp_cs=[0, 0],
        color=[1, 1],
        x=[2.0, 2.0],
        y=[0.0, 0.0],
        z=[0.0, 1.0],
    )
    path = tmp_path / "cs18.unv"
    write(path, [cs, nodes])
    g = read_uff_geometry(path)
    assert_allclose(g.coordinates, [[1.0, 2.0, 0.0], [2.0, 0.0, 1.0]], atol=1e-12)
    assert g.ring_angles([Channel(1), Channel(2)]) is None  # two points: no ring


def test_geometry_object_and_bad_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="unique"):
        Geometry([1, 1], np.zeros((2, 3)))
    with pytest.raises(InputError, match="trace_lines"):
        Geometry([1, 2], np.zeros((2, 3)), [[1, 3]])
    with pytest.raises(InputError, match="node 4"):
        Geometry([1, 2], np.zeros((2, 3))).positions([Channel(4)])
    line = Geometry([1, 2, 3], [[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
    assert line.ring_angles([Channel(1), Channel(2), Channel(3)]) is None  # collinear
    garbage = tmp_path / "g.unv"
    garbage.write_text("    -1\n    15\nnot numbers at all\n    -1\n")
    with pytest.raises(FileFormatError):
        read_uff_geometry(garbage)
    frf_only = tmp_path / "frf.uff"
    from tyredamp.frf import FRF
    from tyredamp.io import write_frf

    write_frf(FRF([1.0, 2.0], [1.0, 2.0]), frf_only)
    with pytest.raises(FileFormatError, match="no node data set"):
        read_uff_geometry(frf_only)
    bad_cs = tmp_path / "badcs.unv"
    write(
        bad_cs,
        [
            pyuff.prepare_15(
                node_nums=[1], def_cs=[9], disp_cs=[0], color=[1], x=[0.0], y=[0.0], z=[0.0]
            )
        ],
    )
    with pytest.raises(FileFormatError, match="coordinate system 9"):
        read_uff_geometry(bad_cs)


def test_report_draws_modes_on_pyuff_geometry(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Modes (UFF 55) of the virtual tyre with a UFF 15 + 82 geometry from pyuff's writer."""
    from tyredamp.cli import main
    from tyredamp.io.uff55 import write_uff55
    from tyredamp.plot import plot_mode_shapes_geometry
    from tyredamp.plot.geometry import mode_displacements
    from tyredamp.virtual import RingTyre, TyreTruth

    truth = TyreTruth.from_tyre(RingTyre(), band=(0.0, 120.0))
    model = truth.modal_model()
    assert [c.node for c in model.outputs] == list(range(1, N + 1))
    modes = write_uff55(model, tmp_path / "modes.unv")
    geo = tmp_path / "geometry.unv"
    write(geo, ring_sets(mm=True))
    g = read_uff_geometry(geo)
    # displacement of node 5 in mode 0 = its shape entry along global z (direction 3)
    d = mode_displacements(model, g)
    shapes = model.second_order_shapes()
    assert_allclose(d[0, 4], [0.0, 0.0, shapes[4, 0]])
    axs = plot_mode_shapes_geometry(model, g, modes=[0, 1])
    assert len(axs) == 2
    html = tmp_path / "report.html"
    try:
        main(["report", str(modes), str(geo), "--out", str(html)])
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    assert code == 0, capsys.readouterr().err
    text = html.read_text()
    assert "mode shapes on the test geometry" in text
    assert "test geometry (nodes, trace lines)" in text


def test_modal_geometry_option_sets_ring_angles(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tyredamp.cli import main
    from tyredamp.cli.modal import _with_geometry
    from tyredamp.frf import FRF
    from tyredamp.io import write_frf

    geo = tmp_path / "geometry.unv"
    write(geo, ring_sets(mm=True))
    f = np.linspace(10.0, 100.0, 50)
    outs = [Channel(n, 3) for n in range(1, N + 1)]
    frf = FRF(f, np.ones((N, 1, f.size)) * (1 + 1j), "accelerance", outs, [Channel(1, 3)])
    placed = _with_geometry(frf, geo)
    assert [c.angle_deg for c in placed.outputs] == pytest.approx(
        list(np.arange(N) * 22.5), abs=1e-3
    )
    assert placed.inputs[0].angle_deg == pytest.approx(0.0, abs=1e-3)
    # a channel whose node the geometry lacks: one-line error, nothing written
    path = write_frf(FRF(f, np.ones((1, 1, f.size)), "accelerance", [99], [1]), tmp_path / "x.npz")
    out = tmp_path / "modes.json"
    with pytest.raises(SystemExit) as info:
        main(["modal", str(path), "--out", str(out), "--geometry", str(geo)])
    assert info.value.code == 2
    assert "has no node 99" in capsys.readouterr().err
    assert not out.exists()
