"""Strict JSON output and atomic-file permissions."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from tyredamp.cli import main
from tyredamp.documents.jsonfile import finite, json_text, write_json
from tyredamp.io._atomic import atomic_path


def test_nan_becomes_null_and_numpy_plain() -> None:
    doc = {"a": np.float64(np.nan), "b": np.arange(3), "c": [1.0, float("inf")], 4: np.int64(2)}
    assert finite(doc) == {"a": None, "b": [0, 1, 2], "c": [1.0, None], "4": 2}
    assert "NaN" not in json_text(doc)
    assert json.loads(json_text(doc))["c"] == [1.0, None]


def test_write_json_mode_and_no_partial(tmp_path: Path) -> None:
    out = write_json({"x": 1.5}, tmp_path / "a.json")
    umask = os.umask(0)
    os.umask(umask)
    assert (out.stat().st_mode & 0o777) == (0o666 & ~umask)

    def fail_midway() -> None:
        with atomic_path(tmp_path / "b.json") as tmp:
            tmp.write_text("half")
            raise RuntimeError("boom")

    with pytest.raises(RuntimeError):
        fail_midway()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


@pytest.mark.parametrize("cmd", [["lateral", "simulate"], ["damping", "x.json"]])
def test_negative_seed_is_usage_error(
    cmd: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main([*cmd, "--out", str(tmp_path / "o.json"), "--seed", "-1"])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "seed" in err[0]
    assert not (tmp_path / "o.json").exists()
