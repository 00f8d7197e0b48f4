"""results.json against its schema (``tyredamp/schemas/results.schema.json``) and its docs page."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from tyredamp.documents.demo import load_schema, validate_results
from tyredamp.documents.jsonfile import finite
from tyredamp.exceptions import InputError
from tyredamp.studies.document import build_results

from .test_studies_demo import quick_demo

# the session's one quick demo (quick_demo) serves the modules of this group: one
# pytest-xdist worker runs them all (pyproject: --dist loadgroup), so it runs once
pytestmark = pytest.mark.xdist_group("demo")

REFERENCE = Path(__file__).resolve().parents[1] / "docs" / "reference" / "results-json.md"


@pytest.fixture(scope="module")
def doc() -> dict[str, Any]:
    _, out = quick_demo()
    text = (out / "results.json").read_text(encoding="utf-8")

    def no_constant(name: str) -> None:
        raise AssertionError(f"results.json holds the non-JSON constant {name}")

    d = json.loads(text, parse_constant=no_constant)  # strict JSON: no NaN or Infinity
    assert isinstance(d, dict)
    return d


def test_schema_is_valid_draft_2020_12() -> None:
    schema = load_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


def test_demo_results_validate(doc: dict[str, Any]) -> None:
    validate_results(doc)
    jsonschema.Draft202012Validator(load_schema()).validate(doc)


def test_required_keys_of_the_issue(doc: dict[str, Any]) -> None:
    rad, lat = doc["radial"], doc["lateral"]
    assert rad["rmsd_real"] > 0
    assert rad["rmsd_complex"] > 0
    assert all({"true", "complex", "real"} <= set(m) for m in rad["modes"])
    assert any(m["true"] and m["complex"] for m in rad["modes"])
    assert rad["damping"]["modal_error"] >= 0
    assert [r["rank"] for r in lat["ranking"]] == list(range(1, len(lat["ranking"]) + 1))
    conds = {(c["pressure_bar"], c["speed_kmh"]) for c in lat["conditions"]}
    assert {(c["pressure_bar"], c["speed_kmh"]) for c in lat["corner_frequency_hz"]} == conds


@pytest.mark.parametrize(
    ("path", "value", "where"),
    [
        (("radial", "rmsd_real"), None, "radial/rmsd_real"),
        (("radial", "rmsd_complex"), -1.0, "radial/rmsd_complex"),
        (("radial", "damping", "modal_error"), "small", "radial/damping/modal_error"),
        (("lateral", "ranking"), [], "lateral/ranking"),
        (("kind",), "modes", "kind"),
    ],
)
def test_schema_rejects_broken_documents(
    doc: dict[str, Any], path: tuple[str, ...], value: Any, where: str
) -> None:
    bad = copy.deepcopy(doc)
    node = bad
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(InputError, match=re.escape(where)):
        validate_results(bad)
    missing = copy.deepcopy(doc)
    del missing["lateral"]["corner_frequency_hz"]
    with pytest.raises(InputError, match="corner_frequency_hz"):
        validate_results(missing)


def test_build_results_is_the_written_document(doc: dict[str, Any]) -> None:
    result, _ = quick_demo()
    again = build_results(result, files=doc["files"])
    assert json.loads(json.dumps(again)) == doc


def test_finite_replaces_non_finite_numbers() -> None:
    import numpy as np

    out = finite({"a": float("nan"), "b": [np.float64(1.5), np.inf], "c": np.array([1, 2])})
    assert out == {"a": None, "b": [1.5, None], "c": [1, 2]}


def _schema_keys(node: Any, out: set[str]) -> None:
    if isinstance(node, dict):
        for k, v in node.get("properties", {}).items():
            out.add(k)
            _schema_keys(v, out)
        for v in node.get("$defs", {}).values():
            _schema_keys(v, out)
        for key in ("items", "additionalProperties"):
            if isinstance(node.get(key), dict):
                _schema_keys(node[key], out)


def test_reference_documents_every_key() -> None:
    """Every property name of the schema appears in a code span of the results.json section
    of docs/reference/results-json.md (as ``radial.rmsd_real`` or in a list such as
    ``{"passed", ...}``)."""
    text = REFERENCE.read_text(encoding="utf-8")
    start = text.index("# results.json")
    end = text.find("\n## ", start + 5)
    section = text[start : end if end > 0 else None]
    keys: set[str] = set()
    _schema_keys(load_schema(), keys)
    words: set[str] = set()
    for span in re.findall(r"`([^`]+)`", section):
        words |= set(re.findall(r"\w+", span))
    missing = sorted(keys - words)
    assert not missing, f"the results.json reference does not mention {missing}"
