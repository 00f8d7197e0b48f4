"""``tyredamp simulate`` and the whole command chain on its files.

simulate radial (time data, UFF type 1) -> frf -> check -> modal -> damping ->
report, with the exact modes of the virtual tyre (--truth) as the reference;
simulate lateral -> lateral fit -> report.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose
from threadpoolctl import threadpool_limits

from tyredamp.cli import main
from tyredamp.documents.modes import read_modes_json
from tyredamp.io import read_frf, read_timedata
from tyredamp.studies.radial import virtual_tyre


@pytest.fixture(scope="module", autouse=True)
def _one_blas_thread() -> Iterator[None]:
    """Small matrices: one BLAS thread is as fast alone and far faster on busy cores."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run the console entry point; (exit code, stdout, stderr)."""
    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def radial_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Time data, FRFs and truth of the virtual tyre at 7.5 bar (4 periods, seed 1)."""
    d = tmp_path_factory.mktemp("radial")
    files = {
        "time": d / "tyre_test.uff",
        "frf": d / "tyre_frf.uff",
        "truth": d / "truth.json",
    }
    for argv in (
        ["simulate", "radial", "--out", str(files["time"]), "--periods", "4", "--seed", "1"],
        [
            "simulate",
            "radial",
            "--out",
            str(files["frf"]),
            "--frf",
            "--periods",
            "4",
            "--seed",
            "1",
            "--truth",
            str(files["truth"]),
        ],
    ):
        try:
            main(argv)
        except SystemExit as exc:
            raise AssertionError(f"{argv}: exit {exc.code}") from None
    return files


def test_simulate_radial_writes_uff58(radial_files: dict[str, Path]) -> None:
    sets = pyuff.UFF(str(radial_files["time"])).read_sets()
    # time histories; the whole meta in data sets 151 (io.uff "Metadata record")
    assert {s["func_type"] for s in sets if s["type"] == 58} == {1}
    assert sum(s["type"] == 58 for s in sets) == 17  # 1 force + 16 accelerations
    td = read_timedata(radial_files["time"])
    assert td.quantities.count("force") == 1
    assert td.sample_rate == 1024.0
    sets = pyuff.UFF(str(radial_files["frf"])).read_sets()
    # FRFs, their coherence and (type 0, "tyredamp FRF variance") their variance; the
    # metadata record (data sets 151) before them
    data = [s for s in sets if s["type"] == 58]
    assert {s["func_type"] for s in data} == {0, 4, 6}
    # the variance per pair and the force noise's relative variance per input
    assert {s["id1"].strip() for s in data if s["func_type"] == 0} == {
        "tyredamp FRF variance",
        "tyredamp FRF input noise",
    }
    frf = read_frf(radial_files["frf"])
    assert frf.H.shape[:2] == (16, 1)
    assert frf.kind == "accelerance"
    truth = read_modes_json(radial_files["truth"])["complex"]
    exact = virtual_tyre(7.5).truth()  # the free tyre with cavity and splice
    vis = exact.select("visible")
    # splice-split pairs and the cavity pair are all driven: more than one per n
    assert truth.n_modes == vis.size > 6
    assert_allclose(truth.frequency_hz, exact.frequency_hz[vis], rtol=1e-9)  # JSON round trip


def test_chain_on_simulated_files(
    capsys: pytest.CaptureFixture[str], radial_files: dict[str, Path], tmp_path: Path
) -> None:
    frf2 = tmp_path / "frf_from_time.uff"
    code, out, err = run(capsys, "frf", str(radial_files["time"]), "--out", str(frf2))
    assert code == 0, err
    # the same estimator on the same time data as 'simulate --frf' (same seed): same FRF
    a, b = read_frf(frf2), read_frf(radial_files["frf"])
    assert_allclose(a.H, b.H, rtol=1e-12, atol=0)

    code, out, err = run(capsys, "check", "quality", str(radial_files["time"]))
    assert code == 0
    assert out.startswith("quality: ")
    code, out, err = run(
        capsys, "check", "linearity", str(radial_files["frf"]), str(frf2), "--band", "30", "200"
    )
    assert code == 0
    assert "linearity: PASS" in out

    modes = tmp_path / "modes.json"
    code, out, err = run(capsys, "modal", str(radial_files["frf"]), "--out", str(modes))
    assert code == 0, err
    assert "RMSD real / complex" in out
    models = read_modes_json(modes)
    truth = read_modes_json(radial_files["truth"])["complex"]
    # all six visible modes, natural frequencies within 0.05 % of the exact ones (40 dB SNR)
    assert_allclose(models["complex"].frequency_hz, truth.frequency_hz, rtol=5e-4)

    damping = tmp_path / "damping.json"
    code, out, err = run(capsys, "damping", str(modes), "--out", str(damping), "--samples", "20")
    assert code == 0, err
    assert json.loads(damping.read_text())["kind"] == "damping"

    report = tmp_path / "report.html"
    code, out, err = run(
        capsys,
        "report",
        str(modes),
        str(damping),
        str(radial_files["frf"]),
        str(radial_files["truth"]),
        "--out",
        str(report),
    )
    assert code == 0, err
    html = report.read_text()
    for text in ("Modal analysis", "Damping identification", "Measured data", "f true (Hz)"):
        assert text in html
    # Figs. 2, 3, 4 against the FRF named in the modes file, shapes, Fig. 5, the FRF itself
    assert html.count("data:image/png;base64,") >= 7


def test_reciprocity_with_two_drive_points(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "mimo.uff"
    code, stdout, err = run(
        capsys,
        "simulate",
        "radial",
        "--out",
        str(out),
        "--frf",
        "--drive-points",
        "1,5",
        "--periods",
        "2",
        "--seed",
        "3",
    )
    assert code == 0, err
    assert "drive point(s) 1, 5" in stdout
    assert read_frf(out).n_in == 2
    code, stdout, _ = run(capsys, "check", "reciprocity", str(out), "--band", "30", "200")
    assert code == 0
    assert "reciprocity: PASS" in stdout


def test_simulate_lateral_is_lateral_simulate(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    args = ["--speed", "10", "--pressure", "2.4", "--seed", "4"]
    assert run(capsys, "simulate", "lateral", "--out", str(a), *args)[0] == 0
    assert run(capsys, "lateral", "simulate", "--out", str(b), *args)[0] == 0
    fa, fb = read_frf(a), read_frf(b)
    assert_allclose(fa.H, fb.H, rtol=0, atol=0)
    lat = tmp_path / "lateral.json"
    code, _, err = run(capsys, "lateral", "fit", str(a), "--out", str(lat))
    assert code == 0, err
    report = tmp_path / "lateral.html"
    code, _out, err = run(capsys, "report", str(lat), str(a), "--out", str(report))
    assert code == 0, err
    html = report.read_text()
    assert "Lateral tyre models" in html
    assert "virtual rig whose exact tyre" in html  # the truth from the NPZ metadata
    assert "hysteretic" in html
    assert html.count("data:image/png;base64,") == 2  # the FRF and the fitted models


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--drive-points", "1,17"], "drive_points"),
        (["--drive-points", "a"], "--drive-points"),
        (["--pressure", "-1"], "--pressure"),
        (["--periods", "0"], "--periods"),
        (["--format", "xls"], "--format"),
        (["--snr", "nan"], "snr"),
    ],
)
def test_simulate_bad_input(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, argv: list[str], message: str
) -> None:
    out = tmp_path / "x.uff"
    code, _, err = run(capsys, "simulate", "radial", "--out", str(out), *argv)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert message in err
    assert not any(tmp_path.iterdir())  # nothing written, no temporary file left


def test_truth_and_out_must_differ(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "x.uff"
    code, _, err = run(
        capsys, "simulate", "radial", "--out", str(out), "--truth", str(out), "--periods", "1"
    )
    assert code == 2
    assert "--truth" in err
    assert not out.exists()


def test_simulated_noise_follows_snr(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """--snr inf gives noise-free data: the cyclic H1 FRF is then exact to ~1e-3."""
    out = tmp_path / "clean.npz"
    code, _, err = run(
        capsys, "simulate", "radial", "--out", str(out), "--frf", "--snr", "inf", "--periods", "1"
    )
    assert code == 0, err
    frf = read_frf(out)
    exact = virtual_tyre(7.5).truth().frf(frf.frequency)  # the tyre the command simulates
    # the first-order hold of the simulation: relative error ~ (pi f / fs_sim)^2 / 3 < 1e-3
    err_rel = np.abs(frf.H - exact.H) / np.abs(exact.H).max()
    assert err_rel.max() < 2e-3
