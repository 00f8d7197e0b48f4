"""The demo's own files read back whole, and ``lateral fit`` on them reproduces the demo's fits.

Uses the one quick demo of the test session (:func:`tests.test_demo.quick_demo`).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.cli import main
from tyredamp.demo import DemoResult
from tyredamp.io import read_frf, read_timedata
from tyredamp.lateral import DEFAULT_MODELS, LateralData, rank_models

from .test_demo import quick_demo


@pytest.fixture(scope="module")
def demo() -> tuple[DemoResult, Path]:
    return quick_demo()


def test_every_data_file_reads_back_whole(demo: tuple[DemoResult, Path]) -> None:
    from tyredamp.demo import _data_files

    result, out = demo
    files = _data_files(result)
    assert files  # every file the demo writes as data
    for rel, obj in files.items():
        back = read_timedata(out / rel) if rel.endswith("time.uff") or "_time_" in rel else None
        if back is None:
            frf = read_frf(out / rel)
            assert_array_equal(frf.H, obj.H)  # type: ignore[union-attr]
            assert_array_equal(frf.frequency, obj.frequency)  # type: ignore[union-attr]
            assert frf.meta == json.loads(json.dumps(obj.meta)), rel
        else:
            assert_array_equal(back.data, obj.data)  # type: ignore[union-attr]
            assert back.meta == json.loads(json.dumps(obj.meta)), rel


def test_json_documents_read_back(demo: tuple[DemoResult, Path]) -> None:
    from tyredamp.damping import DampingModel
    from tyredamp.modal.io import read_modes_json

    result, out = demo
    p0 = f"{result.radial.main.pressure_bar:g}bar"
    models = read_modes_json(out / f"modes_{p0}.json")
    for name, mdl in result.radial.main.models.items():
        assert_allclose(models[name].poles, mdl.poles, rtol=1e-15)
    dm = DampingModel.from_dict(json.loads((out / f"damping_{p0}.json").read_text()))
    assert_allclose(dm.modal, result.radial.damping.modal, rtol=1e-15)


@pytest.mark.parametrize("force", ["ground", "axle"])
def test_lateral_fit_on_demo_files_reproduces_the_demo(
    demo: tuple[DemoResult, Path], force: str, tmp_path: Path
) -> None:
    """``tyredamp lateral fit FILE`` (no options) gives the demo's parameters to 1e-9."""
    result, out = demo
    for c in result.lateral.conditions:
        tag = f"{c.pressure_bar:g}bar_{c.speed_kmh:g}kmh"
        path = out / "data" / f"lateral_{tag}_{force}_frf.uff"
        js = tmp_path / f"{tag}_{force}.json"
        try:
            main(["lateral", "fit", str(path), "--out", str(js)])
        except SystemExit as exc:
            raise AssertionError(f"lateral fit exited with {exc.code}") from None
        doc = json.loads(js.read_text())
        cond = doc["conditions"]
        assert cond["force"] == force
        assert_allclose(cond["speed_kmh"], c.speed_kmh, rtol=1e-15)
        data: LateralData = c.ground if force == "ground" else c.axle
        assert cond["wheel_mass_kg"] == data.wheel_mass
        if force == "ground":  # the demo's own ranking of the ground-force FRF
            fits = {f.name: f for f in c.ranking.fits}
        else:  # the demo predicts the axle FRF; the same fit of its in-memory data
            fits = {f.name: f for f in rank_models(data, DEFAULT_MODELS).fits}
        assert {f["model"] for f in doc["fits"]} == set(DEFAULT_MODELS)
        for f in doc["fits"]:
            want = fits[f["model"]].params
            assert set(f["params"]) == set(want)
            for k, v in want.items():
                assert_allclose(f["params"][k], v, rtol=1e-9, err_msg=f"{tag} {f['model']} {k}")
