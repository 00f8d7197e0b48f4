"""``tyredamp oma``: the command on synthetic and real files, the document, one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.documents.modes import read_modes_json
from tyredamp.frf import Channel
from tyredamp.io import write_timedata
from tyredamp.mechanics import time_response
from tyredamp.oma import oma
from tyredamp.timedata import TimeData

from .test_cli_frf import assert_input_error, run
from .test_oma import _chain

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
TOWER = REAL / "pyOMA-dev_pyOMA" / "tests" / "files" / "measurement_1" / "measurement_1.npy"

#: pyOMA2 1.4.3 (pip install pyOMA_2) on the same tower file, channels 1-5, decimated
#: by 6, SSI(method="cov", br=40, ordmax=80, ref_ind=[3, 4]), mpe(order_in="find_min"):
#: its natural frequencies in Hz (benchmarks/oma_compare.py prints them beside tyredamp's)
PYOMA2_TOWER_HZ = [
    1.4344,
    2.0999,
    4.0165,
    4.7731,
    6.6795,
    7.6180,
    9.6653,
    12.1632,
    12.5977,
    13.8749,
]


@pytest.fixture(scope="module")
def record() -> tuple[np.ndarray, float]:
    s = _chain()
    fs = 200.0
    rng = np.random.default_rng(11)
    y = time_response(s, rng.standard_normal((3, int(400 * fs))), fs, inputs=[0, 1, 2])
    return y.acceleration, fs


def test_oma_command_writes_an_output_only_modes_document(capsys, tmp_path: Path, record) -> None:
    y, fs = record
    td = TimeData(y, fs, [Channel(i + 1) for i in range(3)], ["acceleration"] * 3)
    src = write_timedata(td, tmp_path / "ambient.npz")
    out = tmp_path / "modes.json"
    png = tmp_path / "stab.png"
    code, stdout, err = run(
        capsys, "oma", str(src), "--out", str(out), "--stabilisation-plot", str(png)
    )
    assert code == 0, err
    assert "modes (3, output-only, shapes not scaled)" in stdout
    doc = json.loads(out.read_text())
    assert doc["output_only"] is True
    assert doc["kind"] == "modes"
    assert doc["models"]["complex"]["scaled"] is False
    assert doc["oma"]["method"] == "ssi"
    models = read_modes_json(out)  # readable by every reader of modes files
    truth = np.abs(_chain().complex_modes().poles) / (2 * np.pi)
    assert_allclose(models["complex"].frequency_hz, truth, rtol=0.005)  # f 0.5 %
    assert png.stat().st_size > 1000


def test_oma_command_wave_numbers_from_angles(capsys, tmp_path: Path) -> None:
    from .test_oma import _travelling_field

    angles = np.arange(8) * 45.0
    w, _ = _travelling_field(angles, 100.0, 30000, np.random.default_rng(4))
    src = tmp_path / "ring.npy"
    np.save(src, w.T)
    out = tmp_path / "m.json"
    code, _, err = run(
        capsys, "oma", str(src), "--sample-rate", "100", "--angles",
        ",".join(f"{a:g}" for a in angles), "--max-order", "60", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    waves = json.loads(out.read_text())["oma"]["waves"]
    assert [(w["wave_number"], w["direction"]) for w in waves] == [
        (2, "forward"),
        (3, "backward"),
        (1, "forward"),
    ]
    page = tmp_path / "report.html"
    code, _, err = run(capsys, "report", str(out), "--out", str(page))
    assert code == 0, err
    text = page.read_text()
    assert "Output-only data (operational modal analysis, ssi)" in text
    assert "Travelling waves of each mode" in text


@pytest.mark.parametrize(
    ("array", "args", "message"),
    [
        (np.full((5000, 3), np.nan), [], "NaN"),
        (np.random.default_rng(0).standard_normal((5000, 1)), [], "at least 2"),
        (np.random.default_rng(0).standard_normal((60, 3)), [], "too short"),
        (np.zeros((0, 3)), [], "samples"),
        (np.random.default_rng(0).standard_normal((5000, 3)), ["--references", "7"], "1..3"),
    ],
)
def test_oma_bad_input_one_line(capsys, tmp_path: Path, array, args, message) -> None:
    src = tmp_path / "bad.npy"
    np.save(src, array)
    out = tmp_path / "m.json"
    code, _, err = run(capsys, "oma", str(src), "--sample-rate", "100", *args, "--out", str(out))
    assert_input_error(code, err, out)
    assert message in err


def test_oma_npy_needs_a_sample_rate(capsys, tmp_path: Path) -> None:
    src = tmp_path / "a.npy"
    np.save(src, np.ones((100, 2)))
    out = tmp_path / "m.json"
    code, _, err = run(capsys, "oma", str(src), "--out", str(out))
    assert_input_error(code, err, out)
    assert "--sample-rate" in err


@pytest.mark.skipif(not TOWER.is_file(), reason="real-data gallery absent")
def test_tower_reproduces_pyoma2_modes() -> None:
    y = np.load(TOWER).T[:5]  # channel 6 excluded, as the test's setup_info.txt says
    res = oma(y, 256.0, band=(0.5, 15.0), decimate=6, references=[3, 4])
    for f in PYOMA2_TOWER_HZ:
        k = int(np.argmin(np.abs(res.frequency_hz - f)))
        # the same mode within 0.5 % (two SSI implementations, orders and lags differ)
        assert abs(res.frequency_hz[k] - f) < 0.005 * f, (f, res.frequency_hz)
    assert res.n_modes <= len(PYOMA2_TOWER_HZ) + 2  # no crowd of spurious modes
