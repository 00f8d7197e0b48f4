"""The result-document registry: one reader and writer, one JSON policy, every kind."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.damping import identify_damping
from tyredamp.documents import DOCUMENTS, kind_of, read_document, write_document
from tyredamp.documents.jsonfile import finite, json_text, read_json
from tyredamp.documents.lateral import read_lateral_fit, write_lateral_fit
from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.lateral import rank_models
from tyredamp.studies.lateral import lateral_data
from tyredamp.virtual import VirtualLateralRig

from .helpers import chain_system
from .test_modal_io_cli import _model


def test_registry_holds_every_kind() -> None:
    assert set(DOCUMENTS) == {"modes", "damping", "lateral-fit", "tyredamp-demo-results"}
    assert all(d.version == 1 for d in DOCUMENTS.values())


def test_json_policy_nan_null_complex_pair() -> None:
    doc = {"a": float("nan"), "b": complex(1.5, -2.0), "c": np.array([1 + 1j, np.inf])}
    # a complex array entry stays complex: each part under the NaN rule
    assert finite(doc) == {"a": None, "b": [1.5, -2.0], "c": [[1.0, 1.0], [None, 0.0]]}
    assert json.loads(json_text(doc)) == finite(doc)


def test_reader_refuses_non_strict_json(tmp_path: Path) -> None:
    p = tmp_path / "x.json"
    p.write_text('{"kind": "modes", "x": NaN}')
    with pytest.raises(FileFormatError, match="not strict JSON"):
        read_json(p)
    p.write_text("[1, 2]")
    with pytest.raises(FileFormatError, match="JSON object"):
        read_json(p)
    p.write_text("")
    with pytest.raises(FileFormatError, match="empty"):
        read_json(p)


def test_modes_and_damping_through_the_registry(tmp_path: Path) -> None:
    models = {"complex": _model("complex")}
    path = write_document(tmp_path / "m.json", "modes", models, source="x.uff")
    kind, back, doc = read_document(path)
    assert (kind, doc["version"], sorted(back)) == ("modes", 1, ["complex"])
    assert_allclose(back["complex"].poles, models["complex"].poles, rtol=1e-15)

    cm = chain_system().complex_modes()
    from tyredamp.modal import ModalModel

    dm = identify_damping(ModalModel(cm.poles, cm.psi, cm.psi[:1]), n_samples=0)
    path = write_document(tmp_path / "d.json", "damping", dm)
    kind, back, _ = read_document(path)
    assert kind == "damping"
    assert_allclose(back.modal, dm.modal, rtol=1e-15)


def test_lateral_fit_written_by_the_library(tmp_path: Path) -> None:
    frf = VirtualLateralRig().measure(5.0, 1.7, "ground", 0).frf
    data = lateral_data(frf)
    ranking = rank_models(data, ["maxwell", "hysteretic"])
    path = write_lateral_fit(tmp_path / "l.json", ranking, data, source="rig.npz")
    doc = read_lateral_fit(path)
    assert doc["kind"] == doc["tyredamp"] == "lateral-fit"
    assert doc["order"][0] == ranking.best.name
    assert doc["input"]["file"] == "rig.npz"
    kind, obj, _ = read_document(path)
    assert kind == "lateral-fit"
    assert obj["table"] == doc["table"]


def test_kind_and_version_errors(tmp_path: Path) -> None:
    assert kind_of({"tyredamp": "lateral-fit"}) == "lateral-fit"  # files before "kind"
    with pytest.raises(FileFormatError, match="not a tyredamp result document"):
        kind_of({"kind": "weather"})
    with pytest.raises(FileFormatError, match="newer than this tyredamp"):
        kind_of({"kind": "modes", "version": 2})
    p = tmp_path / "new.json"
    p.write_text('{"kind": "damping", "version": 9}')
    with pytest.raises(FileFormatError, match=r"new\.json: damping: version 9"):
        read_document(p)
    with pytest.raises(InputError, match="kind"):
        write_document(tmp_path / "x.json", "weather", {})
    assert not (tmp_path / "x.json").exists()
