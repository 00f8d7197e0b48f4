"""The commands on UFF 58 files written by pyuff directly (as another program would).

The files carry no tyredamp metadata: ASCII data set 58, accelerance in g/N
(converted by the reader), time histories in N and m/s^2. The system is a
6-DOF spring-mass chain with local dampers (``tests/helpers.chain_system``),
so the exact modes and FRFs are known.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose
from threadpoolctl import threadpool_limits

from tyredamp.cli import main
from tyredamp.documents.modes import read_modes_json
from tyredamp.io import read_frf, write_timedata
from tyredamp.mechanics import time_response
from tyredamp.timedata import TimeData

from .helpers import chain_system

G = 9.80665


@pytest.fixture(scope="module", autouse=True)
def _one_blas_thread() -> Iterator[None]:
    with threadpool_limits(limits=1, user_api="blas"):
        yield


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def write_frf_with_pyuff(path: Path, f: np.ndarray, h: np.ndarray, nodes_in: list[int]) -> None:
    """Accelerance ``h`` (m/(s^2 N), shape (n_out, n_in, n_f)) as ASCII UFF 58 in g/N."""
    sets = []
    for o in range(h.shape[0]):
        for i, ref in enumerate(nodes_in):
            sets.append(
                pyuff.prepare_58(
                    binary=0,
                    id1="FRF exported by another program",
                    func_type=4,
                    rsp_node=o + 1,
                    rsp_dir=3,
                    ref_node=ref,
                    ref_dir=3,
                    data=h[o, i] / G,
                    x=f,
                    abscissa_spacing=1,
                    abscissa_min=float(f[0]),
                    abscissa_inc=float(f[1] - f[0]),
                    abscissa_spec_data_type=18,
                    ordinate_spec_data_type=12,
                    ordinate_axis_units_lab="g",
                    orddenom_spec_data_type=13,
                    orddenom_axis_units_lab="N",
                )
            )
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")


def write_time_with_pyuff(path: Path, td: TimeData) -> None:
    """Time data as ASCII UFF 58 function type 1 (forces in N, accelerations in m/s^2)."""
    sets = []
    for k, (c, q) in enumerate(zip(td.channels, td.quantities, strict=True)):
        sets.append(
            pyuff.prepare_58(
                binary=0,
                id1=f"channel {k + 1}",
                func_type=1,
                rsp_node=c.node,
                rsp_dir=c.direction,
                ref_node=0,
                ref_dir=0,
                data=td.data[k],
                x=td.time,
                abscissa_spacing=1,
                abscissa_min=0.0,
                abscissa_inc=1.0 / td.sample_rate,
                abscissa_spec_data_type=17,
                ordinate_spec_data_type=13 if q == "force" else 12,
                ordinate_axis_units_lab="N" if q == "force" else "m/s^2",
                orddenom_spec_data_type=0,
            )
        )
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")


@pytest.fixture(scope="module")
def chain_frf_file(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray]:
    """MIMO accelerance of the chain (inputs at masses 1 and 3), 0.1 % noise; exact f_n."""
    sysm = chain_system()
    f = np.arange(1, 801) * 0.05  # 0.05-40 Hz, every mode of the chain (< 33 Hz)
    h = sysm.frf(f, "accelerance", inputs=[0, 2]).H
    rng = np.random.default_rng(0)
    noise = rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape)
    h = h + 1e-3 * np.abs(h).mean() * noise
    path = tmp_path_factory.mktemp("pyuff") / "chain_frf.unv"
    write_frf_with_pyuff(path, f, h, [1, 3])
    fn = sysm.complex_modes().frequency_hz
    return path, fn


def test_modal_on_pyuff_frf(
    capsys: pytest.CaptureFixture[str], chain_frf_file: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    path, fn = chain_frf_file
    frf = read_frf(path)
    assert frf.kind == "accelerance"
    assert frf.H.shape == (6, 2, 800)
    modes = tmp_path / "modes.json"
    code, _, err = run(capsys, "modal", str(path), "--out", str(modes), "--model", "complex")
    assert code == 0, err
    m = read_modes_json(modes)["complex"]
    # six modes of a 6-DOF chain from 0.1 % noise: frequencies within 0.1 %
    assert m.n_modes == fn.size
    assert_allclose(m.frequency_hz, fn, rtol=1e-3)
    # every order of the diagram (--order-step 1): the same modes, recorded in meta
    modes1 = tmp_path / "modes1.json"
    code, _, err = run(
        capsys, "modal", str(path), "-o", str(modes1), "--model", "complex", "--order-step", "1"
    )
    assert code == 0, err
    m1 = read_modes_json(modes1)["complex"]
    assert m1.meta["order_step"] == 1
    assert m.meta["order_step"] == 2
    assert_allclose(m1.frequency_hz, m.frequency_hz, rtol=1e-6)
    code, _, err = run(capsys, "modal", str(path), "-o", str(modes1), "--order-step", "0")
    assert code != 0
    report = tmp_path / "r.html"
    code, _out, err = run(capsys, "report", str(modes), str(path), "--out", str(report))
    assert code == 0, err
    assert "chain_frf.unv" in report.read_text()


def test_checks_on_pyuff_frf(
    capsys: pytest.CaptureFixture[str], chain_frf_file: tuple[Path, np.ndarray]
) -> None:
    path, _ = chain_frf_file
    code, out, err = run(capsys, "check", "reciprocity", str(path))
    assert code == 0, err
    # H_13 against H_31 of a symmetric system with 0.1 % noise
    assert out.startswith("reciprocity: PASS")
    fig = float(out.split("differ by up to ")[1].split(" %")[0])
    assert fig < 1.0
    code, out, err = run(capsys, "check", "quality", str(path))
    assert code == 0, err
    assert out.startswith("quality: ")


def test_frf_on_pyuff_time_data(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A random test of the chain written by pyuff gives the same FRF as tyredamp's own file."""
    sysm = chain_system()
    fs, n = 200.0, 2**15
    rng = np.random.default_rng(1)
    force = rng.standard_normal((1, n)) * 5.0
    resp = time_response(sysm, force, fs, [0], [0, 2, 5])
    td = TimeData(
        np.vstack([force, resp.acceleration]),
        fs,
        [1, 1, 3, 6],
        ["force", "acceleration", "acceleration", "acceleration"],
    )
    theirs, ours = tmp_path / "daq.uff", tmp_path / "own.uff"
    write_time_with_pyuff(theirs, td)
    write_timedata(td, ours)
    outs = []
    for src in (theirs, ours):
        dst = tmp_path / f"frf_{src.stem}.npz"
        code, out, err = run(
            capsys, "frf", str(src), "--out", str(dst), "--method", "welch", "--segment", "2048"
        )
        assert code == 0, err
        assert "1 input(s)" in out
        outs.append(read_frf(dst))
    # ASCII UFF keeps 12 significant digits (io docstring): the FRFs agree to ~1e-10
    assert_allclose(outs[0].H, outs[1].H, rtol=1e-8, atol=1e-12 * np.abs(outs[1].H).max())
    # and the first resonance is where the chain has it (Welch/Hann bias aside)
    frf = outs[0].to("receptance")
    fn = sysm.complex_modes().frequency_hz[0]
    near = (frf.frequency > 0.5 * fn) & (frf.frequency < 1.5 * fn)
    peak = frf.frequency[near][np.argmax(np.abs(frf.H[0, 0][near]))]
    assert abs(peak - fn) < 2 * (frf.frequency[1] - frf.frequency[0])
    code, out, err = run(capsys, "check", "quality", str(theirs))
    assert code == 0
    assert "quality:" in out


def test_bad_pyuff_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    bad = tmp_path / "broken.uff"
    bad.write_text("    -1\n    58\nthis is not a data set\n")
    for argv in (
        ["modal", str(bad), "--out", str(tmp_path / "m.json")],
        ["frf", str(bad), "--out", str(tmp_path / "f.uff")],
        ["check", "quality", str(bad)],
    ):
        code, _out, err = run(capsys, *argv)
        assert code == 2
        assert len(err.strip().splitlines()) == 1
        assert "broken.uff" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.uff"]
