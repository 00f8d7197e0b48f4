"""Each kept mode carries the threshold its statistic was tested against (issue 16):
the base threshold raised where the residual's noise lies along the response
(search.local_thresholds), through the quality record, the modes JSON and the
``tyredamp modal`` table."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.cli import main
from tyredamp.cli.modal import modes_table
from tyredamp.documents.modes import read_modes_json, write_modes_json
from tyredamp.exceptions import InputError
from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal.identify import identify_modes
from tyredamp.modal.model import ModalModel
from tyredamp.modal.statistics.quality import FitQuality

from .test_modal_span_noise import INPUTS, F, _data

#: H1 input-noise error common to the outputs (test_modal_span_noise: it raises the
#: threshold at the resonances), and none (white noise only)
RAISED, WHITE = 3e-3, 0.0


def _frf(common: float) -> FRF:
    _, h, sys_ = _data(common, 3)
    return sys_.frf(F, kind="accelerance", inputs=INPUTS).with_H(h)


@pytest.fixture(scope="module")
def models() -> dict[float, ModalModel]:
    return {c: identify_modes(_frf(c), model="complex").models["complex"] for c in (RAISED, WHITE)}


def _quality(m: ModalModel) -> FitQuality:
    assert m.quality is not None
    return m.quality


def test_noise_along_the_response_raises_each_kept_modes_threshold(
    models: dict[float, ModalModel],
) -> None:
    q = _quality(models[RAISED])
    assert models[RAISED].n_modes == 6  # the chain's six modes
    assert q.thresholds.shape == (6,)
    # the in-span noise is many times the off-span noise at every resonance
    # (test_modal_span_noise): each threshold well above the base one
    assert np.all(q.thresholds > 1.5 * q.threshold)
    assert np.all(q.statistic > q.thresholds)  # and every kept mode passes its own
    for n, why in enumerate(q.kept):
        assert f"> {q.thresholds[n]:.3g} (raised from {q.threshold:.3g}" in why
    with pytest.raises(ValueError, match="read-only"):
        q.thresholds[0] = 0.0


def test_white_noise_keeps_the_base_threshold(models: dict[float, ModalModel]) -> None:
    q = _quality(models[WHITE])
    assert models[WHITE].n_modes == 6
    assert_array_equal(q.thresholds, np.full(6, q.threshold))  # not raised, not lowered
    assert not any("raised" in why for why in q.kept)


@pytest.mark.parametrize("common", [RAISED, WHITE])
def test_per_mode_thresholds_survive_the_modes_json(
    models: dict[float, ModalModel], common: float, tmp_path: Path
) -> None:
    mdl = models[common]
    q = _quality(mdl)
    path = write_modes_json(tmp_path / "modes.json", {"complex": mdl})
    back = _quality(read_modes_json(path)["complex"])
    assert_allclose(back.thresholds, q.thresholds, rtol=1e-15)  # JSON floats round-trip
    assert back.threshold == q.threshold
    assert back.kept == q.kept
    doc = json.loads(path.read_text())
    for n, mode in enumerate(doc["models"]["complex"]["modes"]):
        assert mode["test"]["threshold"] == q.thresholds[n]
        assert mode["test"]["base_threshold"] == q.threshold
        assert mode["test"]["kept"] == q.kept[n]


def _strip(d: Any) -> Any:
    """A modes JSON as written before the per-mode thresholds existed."""
    if isinstance(d, dict):
        return {k: _strip(v) for k, v in d.items() if k not in ("thresholds", "base_threshold")}
    if isinstance(d, list):
        return [_strip(v) for v in d]
    return d


def test_older_files_without_per_mode_thresholds_read_as_the_base(
    models: dict[float, ModalModel], tmp_path: Path
) -> None:
    mdl = models[RAISED]
    q = _quality(mdl)
    path = write_modes_json(tmp_path / "modes.json", {"complex": mdl})
    old = _strip(json.loads(path.read_text()))
    assert "thresholds" not in old["models"]["complex"]["quality"]
    (tmp_path / "old.json").write_text(json.dumps(old))
    back = _quality(read_modes_json(tmp_path / "old.json")["complex"])
    assert_array_equal(back.thresholds, np.full(6, q.threshold))
    assert_allclose(back.statistic, q.statistic)


def test_quality_record_checks_and_reorders_the_thresholds(
    models: dict[float, ModalModel],
) -> None:
    q = _quality(models[RAISED])
    order = np.arange(6)[::-1]
    r = q.reordered(order)
    assert_array_equal(r.thresholds, q.thresholds[::-1])
    assert_array_equal(r.statistic, q.statistic[::-1])
    d = q.to_dict()
    d["thresholds"] = d["thresholds"][:5]
    with pytest.raises(InputError, match="thresholds: expected one per mode"):
        FitQuality.from_dict(d)


def _run(args: list[str]) -> int:
    try:
        main(args)
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


@pytest.mark.parametrize("common", [RAISED, WHITE])
def test_cli_table_shows_each_modes_threshold(
    common: float, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = write_frf(_frf(common), tmp_path / "frf.npz")
    out = tmp_path / "modes.json"
    assert _run(["modal", str(src), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    mdl = read_modes_json(out)["complex"]
    q = _quality(mdl)
    table = modes_table("complex", mdl)
    assert "\n".join(table) in text  # the command prints this table
    assert table[1].endswith(f"thr (base threshold {q.threshold:.3g}, false-alarm rate 0.01)")
    for n in range(mdl.n_modes):
        cells = table[2 + n].split()
        assert cells[-2:] == [f"{q.statistic[n]:.3g}", f"{q.thresholds[n]:.3g}"]
    raised = f"thr raised from {q.threshold:.3g} (noise along the response) for mode(s)"
    if common == RAISED:
        assert np.all(q.thresholds > 1.5 * q.threshold)
        assert f"{raised} 1, 2, 3, 4, 5, 6" in text
    else:
        assert_array_equal(q.thresholds, np.full(mdl.n_modes, q.threshold))
        assert "thr raised" not in text
