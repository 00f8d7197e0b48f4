"""Bad-input cases of issue 15 inside the modal identification (the ``modal`` branch's part).

Same promises as ``tests/test_badinput.py``: scale-free identification,
``--modes`` bounded by the data, a non-uniform axis refused, a one-line FRF
named as such.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.io import write_frf

from .badinput import check_one_error_line, run_main, snapshot
from .helpers import chain_system

TRUE_HZ = np.array([7.0833362, 19.84809268, 28.67502205])  # chain_system(3) complex modes


def _frf(freq: np.ndarray, scale: float | None = None) -> FRF:
    frf = chain_system(3, c_local=(5.0, 0.0, 2.0)).frf(freq, outputs=[0, 1, 2], inputs=[0])
    if scale is None:
        return frf
    h = frf.H * (scale / np.abs(frf.H).max())
    return FRF(freq, h, outputs=frf.outputs, inputs=frf.inputs)


@pytest.fixture
def here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("scale", [1e300, 1e-300], ids=["1e300", "1e-300"])
def test_scale_free_identification(
    here: Path, capsys: pytest.CaptureFixture[str], scale: float
) -> None:
    """FRF values of 1e300 (or 1e-300) are the same modes in other units."""
    write_frf(_frf(np.linspace(0.5, 40.0, 300), scale), here / "x.npz")
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    assert code == 0, err
    doc = json.loads((here / "m.json").read_text())
    f = sorted(m["frequency_hz"] for m in doc["models"]["complex"]["modes"])
    np.testing.assert_allclose(f, TRUE_HZ, rtol=1e-3)  # noise-free data: 0.1 % is loose


def test_overflowing_csv_value(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """1.8e308 does not fit a float: the reader refuses the infinite value it becomes."""
    write_frf(_frf(np.linspace(0.5, 40.0, 50)), here / "x.csv")
    lines = (here / "x.csv").read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln and ln[0].isdigit())
    cells = lines[k + 3].split(",")
    cells[1] = "1.8e308"
    lines[k + 3] = ",".join(cells)
    (here / "x.csv").write_text("\n".join(lines) + "\n")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.csv", "-o", "m.json"], capsys)
    check_one_error_line(err, code, 2, "finite")
    assert snapshot(here) == before


def test_modes_bounded_by_the_data(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--modes 1000 on 3 outputs x 300 lines: refused before fitting, naming --modes."""
    write_frf(_frf(np.linspace(0.5, 40.0, 300)), here / "x.npz")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json", "--modes", "1000"], capsys)
    check_one_error_line(err, code, 2, "--modes")
    assert snapshot(here) == before


def test_non_uniform_axis_refused(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """pLSCF assumes equally spaced lines; a non-uniform axis is refused, not mis-fitted."""
    f = np.sort(np.concatenate([np.linspace(0.5, 20.0, 200), np.linspace(20.1, 40.0, 60)]))
    write_frf(_frf(f), here / "x.npz")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    check_one_error_line(err, code, 2, "uniform")
    assert snapshot(here) == before


def test_one_line_is_not_a_band_error(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_frf(_frf(np.array([10.0])), here / "x.npz")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    line = check_one_error_line(err, code, 2, "line")
    assert "band:" not in line
    assert snapshot(here) == before


def test_lines_without_data_at_the_end_are_left_out(
    here: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An analyser's export zeroes the lines beyond its cut-off: they leave the band.

    Every FRF exactly zero from 30 Hz on (the third mode, 28.7 Hz, stays inside):
    the modes are those of the same data cut at 30 Hz, and the warning says so.
    """
    freq = np.linspace(0.5, 40.0, 300)
    frf = _frf(freq)
    h = frf.H.copy()
    h[:, :, freq > 30.0] = 0.0
    write_frf(FRF(freq, h, outputs=frf.outputs, inputs=frf.inputs), here / "x.npz")
    code, out, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    assert code == 0, err
    doc = json.loads((here / "m.json").read_text())
    f = sorted(m["frequency_hz"] for m in doc["models"]["complex"]["modes"])
    np.testing.assert_allclose(f, TRUE_HZ, rtol=1e-3)  # noise-free data: 0.1 % is loose
    assert doc["band_hz"][1] == pytest.approx(freq[freq <= 30.0][-1])
    assert "exactly zero were left out of the band" in out + err


def test_lines_without_data_inside_the_band_are_refused(
    here: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    freq = np.linspace(0.5, 40.0, 300)
    frf = _frf(freq)
    h = frf.H.copy()
    h[:, :, 100:104] = 0.0
    write_frf(FRF(freq, h, outputs=frf.outputs, inputs=frf.inputs), here / "x.npz")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    line = check_one_error_line(err, code, 2, "exactly zero at 4 line(s)")
    assert "--band" in line
    assert snapshot(here) == before
    # the same file with a band that leaves them out is identified
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json", "--band", "15", "40"], capsys)
    assert code == 0, err


def test_a_dead_output_is_named(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An output whose FRF is zero at every line (an unplugged channel) made the
    goodness of fit NaN; it is refused, named."""
    freq = np.linspace(0.5, 40.0, 300)
    frf = _frf(freq)
    h = frf.H.copy()
    h[1] = 0.0
    write_frf(FRF(freq, h, outputs=frf.outputs, inputs=frf.inputs), here / "x.npz")
    before = snapshot(here)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    line = check_one_error_line(err, code, 2, "dead or unplugged")
    assert f"output {frf.outputs[1].label} " in line
    assert snapshot(here) == before
