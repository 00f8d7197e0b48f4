"""``tyredamp frf --each-record``: one FRF file per averaged record, all or none."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.testing import assert_allclose

from tyredamp.io import read_frf, write_timedata
from tyredamp.timedata import TimeData

from .excitation_records import respond
from .test_cli_frf import assert_input_error, run


def _impact_file(tmp_path: Path, forces: int = 1) -> Path:
    rng = np.random.default_rng(2)
    n = 9000
    x = np.zeros(n)
    for t0, h in ((200, 1.0), (3100, 1.6), (6900, 0.7)):
        x[t0 : t0 + 8] += h * np.sin(np.pi * np.arange(8) / 8)
    y = respond(x) + 1e-4 * rng.standard_normal(n)
    x = x + 1e-4 * rng.standard_normal(n)
    rows, nodes, q = [x, y], [1, 2], ["force", "acceleration"]
    if forces == 2:
        rows, nodes, q = [x, 0.3 * x + y, y], [1, 3, 2], ["force", "force", "acceleration"]
    return write_timedata(TimeData(np.vstack(rows), 1000.0, nodes, q), tmp_path / "hits.uff")


def test_each_record_writes_one_frf_per_hit(capsys, tmp_path: Path) -> None:
    src = _impact_file(tmp_path)
    out = tmp_path / "h.uff"
    code, stdout, _ = run(capsys, "frf", str(src), "-o", str(out), "--each-record")
    assert code == 0
    joint = read_frf(out)
    recs = [read_frf(tmp_path / f"h.record{k}.uff") for k in (1, 2, 3)]
    assert not (tmp_path / "h.record4.uff").exists()
    assert "3 records" in stdout
    for r in recs:
        assert_allclose(r.frequency, joint.frequency, rtol=1e-12)  # the same lines
    # the records differ from each other (independent hits, their own noise) ...
    assert not np.allclose(recs[0].H, recs[1].H, rtol=1e-6)
    # ... and agree with the averaged FRF where the response is strong, to the few per
    # cent by which each record's cut of the ringing (its own leakage) differs
    strong = np.abs(joint.H[0, 0]) > 0.3 * np.abs(joint.H[0, 0]).max()
    for r in recs:
        assert_allclose(r.H[0, 0, strong], joint.H[0, 0, strong], rtol=0.05)


def test_each_record_refused_with_two_forces_leaves_no_file(capsys, tmp_path: Path) -> None:
    src = _impact_file(tmp_path, forces=2)
    out = tmp_path / "h.uff"
    code, _, err = run(
        capsys, "frf", str(src), "-o", str(out), "--each-record", "--reference", "1+Z"
    )
    assert code == 0 or "force" in err
    code, _, err = run(capsys, "frf", str(src), "-o", str(tmp_path / "g.uff"), "--each-record")
    assert_input_error(code, err, tmp_path / "g.uff")
    assert not list(tmp_path.glob("g.record*"))
