"""Verdicts without coherence on a measured free beam, and the rejected-candidate line.

The beam of the real-data folder: impact-test accelerances exported alone (one
complex value per line, 0-1000 Hz at 1 Hz, no coherence), written to UFF and
run through ``tyredamp modal`` as a user would.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tyredamp.cli import main
from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal.statistics.quality import RejectedMode, rejected_summary, short_reason


def real_data() -> Path:
    """The shared real-data folder beside the repository (skip when it is absent)."""
    root = Path(__file__).resolve().parents[2] / "shared" / "real-data"
    if not root.is_dir():
        pytest.skip("the real-data folder ../shared/real-data is absent")
    return root


def beam_uff(tmp_path: Path) -> Path:
    """The three measured beam FRFs (response 1, hammer at 1, 2, 3) as one UFF."""
    folder = real_data() / "ladisk_pyuff" / "data"
    H = np.array([np.genfromtxt(folder / f"meas_point_{i}.txt", dtype=complex) for i in (1, 2, 3)])
    f = np.arange(H.shape[1], dtype=float)
    # line 0 (DC) is meaningless (the catalogue)
    return write_frf(FRF(f[1:], H[None, :, 1:], kind="accelerance"), tmp_path / "beam.uff")


def run_modal(args: list[str], capsys: pytest.CaptureFixture[str]) -> list[str]:
    code = 0
    try:
        main(["modal", *args])
    except SystemExit as exc:
        code = int(exc.code or 0)
    assert code == 0
    return [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("verdict:")]


def test_beam_without_coherence_is_judged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = beam_uff(tmp_path)
    out = tmp_path / "modes.json"
    lines = run_modal([str(src), "--band", "10", "300", "-o", str(out)], capsys)
    assert len(lines) == 2
    for ln in lines:
        assert "NOT JUDGED" not in ln
        assert ("OK:" in ln) or ("FAILED:" in ln) or ("as the data explain" in ln)
    assert "noise floor of adjacent lines" in lines[0]


def test_beam_bad_fit_fails(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two modes and no residual terms in 10-300 Hz: the 278.7 Hz mode is missed."""
    src = beam_uff(tmp_path)
    out = tmp_path / "modes.json"
    args = [str(src), "--band", "10", "300", "--frequencies", "51.5,142.2", "--no-residuals"]
    lines = run_modal([*args, "--model", "complex", "-o", str(out)], capsys)
    assert lines[0].startswith("verdict: complex-mode fit: FAILED: the residual is")
    assert "from the noise floor of adjacent lines (no coherence)" in lines[0]


def test_rejected_summary_gives_each_its_reason() -> None:
    """Each candidate with its own reason, the largest statistic first, the count."""
    line_spacing = "half-power bandwidth 0.109 Hz below the line spacing 1 Hz (not resolved)"
    rej = [
        RejectedMode(31.2, 0.01, "not significant: T = 12 <= 28", 12.0, 28.0),
        RejectedMode(278.67, 2e-4, line_spacing, 8.2e5, 34.4),
        RejectedMode(278.67, 2e-4, line_spacing, 8.1e5, 34.4),
        RejectedMode(50.9, 0.02, "present in 12% of orders < 30%"),
        RejectedMode(
            52.1,
            0.02,
            "present in 12% of orders < 30%; not tried: the mode at 51.5194 Hz stands for it",
        ),
    ]
    text = rejected_summary(rej)
    assert text.startswith("5 candidate(s) rejected, largest mode statistic T first: ")
    assert "closest to the threshold" not in text
    # 278.67 (largest T) first, once, with its reason; then 31.2 with its T and threshold
    assert text.index("278.67 Hz: half-power band below the line spacing") < text.index(
        "31.20 Hz: not significant, T = 12 <= 28"
    )
    assert text.count("278.67 Hz") == 1
    assert text.endswith("; 1 more")
    assert short_reason(rej[4]) == "represented by the mode at 51.52 Hz"
    assert "unstable in the stabilisation diagram" in short_reason(rej[3])
    assert math.isnan(rej[3].statistic)
