"""``tyredamp simulate rolling``: the recording and its truth on disk, one-line refusals."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tyredamp.cli import main
from tyredamp.io import read_timedata


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run the console entry point; (exit code, stdout, stderr)."""
    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_rolling_writes_recording_and_truth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, truth = tmp_path / "rolling.npz", tmp_path / "waves.json"
    code, stdout, _ = run(
        capsys, "simulate", "rolling", "--out", str(out), "--speed", "30", "--duration", "1",
        "--sensors", "4", "--tyre-sensors", "2", "--excitation", "impulse", "--truth", str(truth),
    )  # fmt: skip
    assert code == 0
    assert "rolling at 30 km/h" in stdout
    data = read_timedata(out)
    assert [c.name for c in data.channels] == ["F1", "A1", "A2", "A3", "A4", "T1", "T2"]
    assert data.n_samples == 1024
    doc = json.loads(truth.read_text(encoding="utf-8"))
    assert doc["kind"] == "rolling_truth"
    assert doc["speed_kmh"] == 30.0
    n3 = [w for w in doc["waves"] if w["wave_number"] == 3]
    assert {w["direction"] for w in n3} == {"forward", "backward"}
    f_rot = doc["rotation_hz"]
    for w in n3:
        k = 3 if w["direction"] == "backward" else -3
        # 1e-9: the fixed frame is the Doppler shift of the rotating frame
        assert np.isclose(w["fixed_hz"], abs(w["rotating_hz"] - k * f_rot), rtol=1e-9)


@pytest.mark.parametrize(
    ("speed", "message"),
    [
        ("nan", "--speed: expected a finite speed >= 0 km/h, got nan"),
        ("-3", "--speed: expected a finite speed >= 0 km/h, got -3"),
        (
            "400",
            "--speed: expected a speed below the critical (standing-wave) speed of the tyre "
            "at 7.5 bar, 356 km/h; got 400 km/h",
        ),
    ],
)
def test_simulate_rolling_refuses_bad_speeds(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], speed: str, message: str
) -> None:
    out = tmp_path / "r.npz"
    code, _, err = run(capsys, "simulate", "rolling", "--out", str(out), "--speed", speed)
    assert code == 2
    assert err.strip() == f"tyredamp: error: {message}"
    assert err.count("\n") == 1
    assert not out.exists()
