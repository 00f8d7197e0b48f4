"""Modes JSON round trip and the ``tyredamp modal`` command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.cli import main
from tyredamp.documents.modes import modes_document, read_modes_json, write_modes_json
from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.io import write_frf
from tyredamp.modal.model import ModalModel
from tyredamp.modal.statistics.quality import short_reason, strongest_rejected

from .helpers import chain_system


def _run(args: list[str]) -> int:
    """Run the CLI; return its exit code (0 when it returns normally)."""
    try:
        main(args)
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def _model(kind: str) -> ModalModel:
    cm = chain_system().complex_modes()
    resid = ModalModel(cm.poles[-1:], cm.psi[:, -1:], cm.psi[:1, -1:], mode_kind="complex")
    return ModalModel(
        cm.poles[:-1],
        cm.psi[:, :-1],
        cm.psi[:1, :-1],
        mode_kind=kind,  # type: ignore[arg-type]
        std={
            "frequency_hz": np.full(5, 0.01),
            "damping_ratio": np.full(5, 1e-4),
            "psi_out": np.full((6, 5), 1e-5),
        },
        meta={
            "rmsd": 1e-3,
            "relative_error": 0.02,
            "band_hz": [0.0, 40.0],
            "frf_kind": "receptance",
            "mpc": np.ones(5),
        },
        residual_modes=resid,
    )


def test_modes_json_round_trip(tmp_path: Path) -> None:
    models = {"complex": _model("complex"), "real": _model("real")}
    path = write_modes_json(tmp_path / "m.json", models, source="x.uff")
    doc = json.loads(path.read_text())
    assert doc["kind"] == "modes"
    assert doc["source"] == "x.uff"
    assert doc["band_hz"] == [0.0, 40.0]
    assert doc["frf_kind"] == "receptance"
    assert doc["models"]["complex"]["rmsd"] == 1e-3
    back = read_modes_json(path)
    for key, m in models.items():
        b = back[key]
        assert b.mode_kind == m.mode_kind
        assert_allclose(b.poles, m.poles, rtol=1e-15)  # JSON keeps doubles exactly
        assert_allclose(b.psi_out, m.psi_out, rtol=1e-15)
        assert_allclose(b.std["frequency_hz"], m.std["frequency_hz"])
        assert b.residual_modes is not None
        f = np.linspace(1.0, 30.0, 5)
        assert_allclose(b.receptance(f), m.receptance(f), rtol=1e-12)


def test_read_modes_json_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("")
    with pytest.raises(FileFormatError, match="empty"):
        read_modes_json(bad)
    bad.write_text("{not json")
    with pytest.raises(FileFormatError, match="JSON"):
        read_modes_json(bad)
    bad.write_text(json.dumps({"kind": "damping"}))
    with pytest.raises(FileFormatError, match="modes"):
        read_modes_json(bad)
    bad.write_text(json.dumps({"kind": "modes", "models": {"complex": {"modes": []}}}))
    with pytest.raises(FileFormatError, match="missing key"):
        read_modes_json(bad)
    with pytest.raises(InputError, match="models"):
        modes_document({})


def test_cli_modal_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sys_ = chain_system()
    f = np.linspace(0.5, 40.0, 400)
    frf = sys_.frf(f, kind="accelerance", inputs=[0])
    rng = np.random.default_rng(0)
    rms = np.sqrt(np.mean(np.abs(frf.H) ** 2, axis=2, keepdims=True))
    frf = frf.with_H(frf.H + 1e-3 * rms * rng.normal(size=frf.H.shape))
    src = write_frf(frf, tmp_path / "frf.npz")
    before = Path(src).read_bytes()
    out = tmp_path / "modes.json"
    assert _run(["modal", str(src), "--out", str(out), "--band", "0", "40"]) == 0
    text = capsys.readouterr().out
    assert "complex modes (6)" in text
    assert "real modes (6)" in text
    assert "RMSD real / complex" in text
    assert "threshold" in text  # the mode test's column and threshold
    assert "goodness of fit (ML): the model explains the data to the noise" in text
    assert "noise model: residual" in text
    models = read_modes_json(out)
    assert_allclose(models["complex"].frequency_hz, sys_.complex_modes().frequency_hz, rtol=1e-4)
    q = models["complex"].quality
    assert q is not None
    assert np.all(q.statistic > q.threshold)
    # the rejected candidates in one line: their number, the strongest first, each with
    # its own short reason, and where every reason is
    assert q.rejected
    assert f"{len(q.rejected)} candidate(s) rejected" in text
    assert "closest to the threshold" not in text
    assert "(every reason in the modes JSON)" in text
    top = strongest_rejected(q.rejected)[0]
    assert f": {top.frequency_hz:.2f} Hz: {short_reason(top)}" in text
    doc = json.loads(out.read_text())
    mode0 = doc["models"]["complex"]["modes"][0]
    assert mode0["test"]["statistic"] > mode0["test"]["threshold"]
    assert Path(src).read_bytes() == before  # input untouched
    # a non-uniform axis is refused with one line
    g = np.concatenate([np.linspace(0.5, 20.0, 100), np.linspace(20.2, 40.0, 300)])
    src2 = write_frf(sys_.frf(g, kind="accelerance", inputs=[0]), tmp_path / "g.npz")
    assert _run(["modal", str(src2), "--out", str(tmp_path / "g.json")]) == 2
    assert "uniformly spaced" in capsys.readouterr().err
    # more modes than the data can hold: refused before any fit
    assert _run(["modal", str(src), "--out", str(tmp_path / "h.json"), "--modes", "1000"]) == 2
    assert "at most" in capsys.readouterr().err


def test_cli_modal_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "m.json"
    assert _run(["modal", str(tmp_path / "missing.npz"), "--out", str(out)]) == 2
    sys_ = chain_system()
    src = write_frf(sys_.frf(np.linspace(0.5, 40.0, 200), inputs=[0]), tmp_path / "f.npz")
    assert _run(["modal", str(src), "--out", str(out), "--frequencies", "3,abc"]) == 2
    assert "frequencies" in capsys.readouterr().err
    assert not out.exists()  # nothing written on error


def test_cli_modal_help_has_example(capsys: pytest.CaptureFixture[str]) -> None:
    assert _run(["modal", "--help"]) == 0
    assert "Example:" in capsys.readouterr().out
