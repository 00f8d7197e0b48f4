"""The demo's ``results.json``: kind, version, schema, reader and writer.

The document is assembled from a demo run by
:func:`tyredamp.studies.document.build_results`; its layout is described key
by key in ``docs/reference/results-json.md`` and formally in
``tyredamp/schemas/results.schema.json`` (JSON Schema draft 2020-12), which
:func:`validate_results` applies. jsonschema is needed only for validation (a
test dependency), never to write the file.
"""

from __future__ import annotations

import json
import os
from importlib import resources
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError, InputError
from .jsonfile import read_json, write_json

__all__ = [
    "RESULTS_KIND",
    "RESULTS_VERSION",
    "load_schema",
    "read_results",
    "results_from_document",
    "validate_results",
    "write_results",
]

#: ``"kind"`` of the demo's results.json (also how a directory is recognised
#: as an earlier demo output that may be replaced).
RESULTS_KIND = "tyredamp-demo-results"
RESULTS_VERSION = 1


def results_from_document(doc: dict[str, Any]) -> dict[str, Any]:
    """Check the kind of a parsed results document and return it."""
    if doc.get("kind") != RESULTS_KIND:
        raise FileFormatError(f'expected a demo results document with "kind": "{RESULTS_KIND}"')
    return doc


def write_results(path: str | os.PathLike[str], doc: dict[str, Any]) -> Path:
    """Write a results document (strict JSON, atomically); returns the path."""
    return write_json(results_from_document(doc), path)


def read_results(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a demo results.json (kind checked; :func:`validate_results` checks the layout)."""
    p = Path(path)
    try:
        return results_from_document(read_json(p))
    except FileFormatError as exc:
        msg = str(exc)
        raise FileFormatError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None


def load_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of results.json, from the package data."""
    text = resources.files("tyredamp").joinpath("schemas/results.schema.json").read_text("utf-8")
    schema = json.loads(text)
    assert isinstance(schema, dict)
    return schema


def validate_results(doc: Any) -> None:
    """Validate a results document against :func:`load_schema`.

    Needs the optional ``jsonschema`` package (a test dependency).

    Raises
    ------
    InputError
        The document does not follow the schema (the message names the first
        offending key), or jsonschema is not installed.
    """
    try:
        import jsonschema
    except ImportError:  # pragma: no cover - jsonschema is a test dependency
        raise InputError(
            "validate_results: needs the jsonschema package (pip install jsonschema)"
        ) from None
    schema = load_schema()
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    errors = sorted(cls(schema).iter_errors(doc), key=lambda e: list(e.absolute_path))
    if errors:
        e = errors[0]
        where = "/".join(str(p) for p in e.absolute_path) or "(top level)"
        raise InputError(f"results: {where}: {e.message} ({len(errors)} problem(s) in all)")
