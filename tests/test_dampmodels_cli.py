"""``tyredamp damping --models``: the damping-model comparison in the damping JSON."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tyredamp.cli import main
from tyredamp.dampmodels import DampedSystem, Exponential
from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal import ModalModel

from .test_damping_cli import modes_file

M3 = np.diag([1.0, 2.0, 1.5])
K3 = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) * 1e4
C3 = np.array([[1.5, -0.6, 0.4], [-0.6, 1.2, 0.3], [0.4, 0.3, 0.9]])


def _files(tmp_path: Path) -> tuple[Path, Path]:
    sys = DampedSystem(M3, K3, Exponential(2 * C3, np.array([60.0])))
    md = sys.modes()
    mm = ModalModel(md.poles, md.shapes, md.shapes[:1], outputs=[0, 1, 2], inputs=[0])
    src = modes_file(tmp_path / "modes.json", {"complex": mm})
    f = np.linspace(2.0, 40.0, 120)
    H = sys.receptance(f)[:, :1, :]
    var = (0.01 * np.abs(H)) ** 2  # 40 dB
    rng = np.random.default_rng(4)
    Hn = H + np.sqrt(var / 2) * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))
    frf = write_frf(FRF(f, Hn, outputs=[0, 1, 2], inputs=[0], variance=var), tmp_path / "frf.npz")
    return src, frf


def test_models_option_ranks_and_writes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src, frf = _files(tmp_path)
    out = tmp_path / "damp.json"
    main(
        [
            "damping", str(src), "--out", str(out), "--samples", "0",
            "--models", "viscous,hysteretic,exponential,fractional", "--frf", str(frf),
        ]
    )  # fmt: skip
    text = capsys.readouterr().out
    assert "damping models:" in text
    assert "not consistent with viscous damping" in text
    assert "the data support the exponential model" in text
    doc = json.loads(out.read_text())["meta"]["damping_models"]
    assert doc["ranking"]["best"] == "exponential"
    assert doc["aw_part2"]["viscous_consistent"] is False


def test_models_option_without_frf_and_bad_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, _ = _files(tmp_path)
    out = tmp_path / "damp.json"
    main(["damping", str(src), "-o", str(out), "--samples", "0", "--models", "viscous"])
    assert "no FRF file given" in capsys.readouterr().out
    bad = tmp_path / "bad.json"
    with pytest.raises(SystemExit) as exc:
        main(["damping", str(src), "-o", str(bad), "--samples", "0", "--models", "maxwell"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("tyredamp: error: --models")
    assert not bad.exists()
