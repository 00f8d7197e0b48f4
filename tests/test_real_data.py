"""The real-data gallery as a test: every public measured file through the user's commands.

The rows (file, commands, reference, tolerance) are defined once, in
``benchmarks/gallery.py``, which also writes the table of docs/gallery.md.
Each row runs the real command line (in this process for speed; the rows
marked ``subprocess`` through a separate ``tyredamp`` process instead, at
least one per command, so that every command is tested the way a user runs
it) and asserts that the
outcome agrees with a reference tyredamp did not compute: the source's
published values, sdypy-EMA results stored with the command that made them
(``benchmarks/results/gallery_references.json``), an independent reading of
the file, or the physics. A row the current code does not meet is an
``xfail(strict=True)`` with the reason: the day it passes, the test says so.
The gallery sits beside the repository (``../shared/real-data``); without
it the module is skipped.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
if not REAL.is_dir():  # pragma: no cover - the gallery is beside the repository in CI
    pytest.skip(f"real-data gallery not found at {REAL}", allow_module_level=True)


def _load_gallery() -> Any:
    spec = importlib.util.spec_from_file_location(
        "tyredamp_gallery", ROOT / "benchmarks" / "gallery.py"
    )
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses resolve their module by name
    spec.loader.exec_module(mod)
    return mod


gallery = _load_gallery()
REFERENCES = gallery.load_references()


def _params(use_subprocess: bool) -> list[Any]:
    out = []
    for row in gallery.ROWS:
        if row.subprocess != use_subprocess:  # each row runs once, one way or the other
            continue
        marks = [pytest.mark.xfail(strict=True, reason=row.xfail)] if row.xfail else []
        if row.long:  # a modal identification of half a minute or more: `pytest -m long`
            marks.append(pytest.mark.long)
        out.append(pytest.param(row, id=row.id, marks=marks))
    return out


def _assert_row(row: Any, use_subprocess: bool) -> None:
    if row.needs_references and not REFERENCES:
        pytest.fail("benchmarks/results/gallery_references.json is missing")
    check, commands, _ = gallery.run_row(row, REAL, REFERENCES, use_subprocess=use_subprocess)
    assert commands, "the row ran no command"
    assert check.ok, f"{row.id}: {check.outcome} -- {check.agreement}"


@pytest.mark.parametrize("row", _params(False))
def test_gallery_row(row: Any) -> None:
    _assert_row(row, use_subprocess=False)


@pytest.mark.parametrize("row", _params(True))
def test_gallery_row_through_a_subprocess(row: Any) -> None:
    _assert_row(row, use_subprocess=True)


#: One row per user command that also runs as a separate process.
THROUGH_A_PROCESS = {
    "check": "impact-lvm-quality",
    "frf": "impact-lvm-no-map",
    "modal": "case1-frf-modal",
    "damping": "uff55-anonymised",
    "campaign": "beam-campaign",
    "report": "beam-report",
    "tyre-model": "tir-fed-40psi",
}


def test_every_command_runs_through_a_subprocess() -> None:
    rows = {row.id: row for row in gallery.ROWS}
    for command, row_id in THROUGH_A_PROCESS.items():
        assert rows[row_id].subprocess, command


def test_every_catalogue_file_has_a_row() -> None:
    """Each measured file of the gallery folder is in the table (the .pkl cache and notes aside)."""
    files = {
        p.relative_to(REAL).as_posix()
        for p in REAL.rglob("*")
        if p.is_file() and p.suffix not in (".md", ".pkl")
    }
    covered = set()
    for row in gallery.ROWS:
        for k in ("1", "2", "3"):
            covered.add(row.file.replace("1..3", k))
    skipped = {
        f for f in files if f.startswith("pyOMA-dev_pyOMA/tests/files/") and f.endswith(".txt")
    }
    assert files - covered - skipped == set()


def test_kept_hz_leaves_out_a_mode_that_fails_its_test(tmp_path: Path) -> None:
    """A hit's confirmation counts only modes that pass their test: a model keeps one
    mode when none passes ("the only mode left, not significant"), which confirms nothing."""
    doc = {
        "models": {
            "complex": {
                "modes": [
                    {"frequency_hz": 114.2, "test": {"statistic": 181.0, "threshold": 27.6}},
                    {"frequency_hz": 112.9, "test": {"statistic": 15.6, "threshold": 27.6}},
                    {"frequency_hz": 50.0},  # asked for: no test
                ]
            }
        }
    }
    path = tmp_path / "m.json"
    path.write_text(gallery.json.dumps(doc), encoding="utf-8")
    assert gallery.kept_hz(path) == [50.0, 114.2]
