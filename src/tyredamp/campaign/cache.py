"""Content-addressed cache of step results: a rerun recomputes only what changed.

Each step result of each test is stored as one JSON file
``DIR/cache/<key>.json``, written atomically
(:func:`tyredamp.io._safety.atomic_path`), where ``key`` is the SHA-256 of

* the SHA-256 of the test file's bytes,
* the step (study and name), the settings it depends on and the test
  conditions it reads,
* the key of the step before it (so a changed modal result renews the damping),
* the tyredamp version.

A finished step is on disk as soon as the campaign receives it, so a crash,
a kill or Ctrl-C loses nothing that finished, and a changed setting renews
only the steps that depend on it. Entries that cannot be read (for example a
disk that filled up) count as missing and are computed again.

Each entry carries the SHA-256 of its document's exact JSON text
(``"sha256"``, written before the document). An entry whose text no longer
matches it (edited, truncated, damaged on disk), or that is not an entry of
its key, is not trusted: it is computed again and named in
:attr:`ResultCache.damaged` (the campaign reports it as a warning).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

from .. import __version__
from ..documents.jsonfile import json_text
from ..io._safety import atomic_path

__all__ = ["CACHE_FORMAT", "ResultCache", "file_digest", "step_key"]

#: Version of the cache entry layout (part of every key).
CACHE_FORMAT = 2


def file_digest(path: str | os.PathLike[str]) -> str:
    """SHA-256 (hex) of a file's bytes (the file is only read)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def step_key(
    study: str,
    step: str,
    input_digest: str,
    settings: Any,
    conditions: Any,
    upstream_key: str | None,
    version: str = __version__,
) -> str:
    """The cache key (SHA-256 hex) of one step of one test (see the module docstring)."""
    ident = {
        "format": CACHE_FORMAT,
        "tyredamp": version,
        "study": study,
        "step": step,
        "input_sha256": input_digest,
        "settings": settings,
        "conditions": conditions,
        "upstream": upstream_key,
    }
    text = json.dumps(ident, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


_KIND = "tyredamp-campaign-cache"
_DOC = b',"document":'


class ResultCache:
    """Step documents on disk under ``root`` (``DIR/cache``), one JSON file per key.

    Attributes
    ----------
    damaged : list of str
        One line for each entry found damaged by :meth:`get` (then recomputed).
    """

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        self.damaged: list[str] = []

    def path(self, key: str) -> Path:
        """The file of ``key``."""
        return self.root / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The stored document of ``key``; None when absent, unreadable or damaged."""
        p = self.path(key)
        try:
            raw = p.read_bytes()
        except FileNotFoundError:
            return None
        except OSError as exc:
            self._bad(key, f"cannot be read ({exc.strerror})")
            return None
        try:
            entry = json.loads(raw)
        except (UnicodeDecodeError, ValueError, RecursionError):
            self._bad(key, "is not valid JSON")
            return None
        if not isinstance(entry, dict) or entry.get("kind") != _KIND or entry.get("key") != key:
            self._bad(key, "is not the cache entry of its name")
            return None
        doc, start = entry.get("document"), raw.find(_DOC)
        text = raw[start + len(_DOC) : raw.rstrip().rfind(b"}")] if start > 0 else b""
        if not isinstance(doc, dict) or hashlib.sha256(text).hexdigest() != entry.get("sha256"):
            self._bad(key, "does not match its checksum")
            return None
        return doc

    def _bad(self, key: str, why: str) -> None:
        self.damaged.append(f"{self.path(key)}: the cache entry {why}; not trusted, computed again")

    def put(self, key: str, document: dict[str, Any], about: dict[str, Any]) -> Path:
        """Store ``document`` under ``key`` atomically, with ``about`` (test, step) and checksum."""
        text = json_text(document, indent=0).encode("utf-8")
        head = json.dumps(
            {"kind": _KIND, "key": key, **about, "sha256": hashlib.sha256(text).hexdigest()},
            allow_nan=False,
        ).encode("utf-8")
        with atomic_path(self.path(key)) as tmp:
            tmp.write_bytes(head[:-1] + _DOC + text + b"}\n")
        return self.path(key)
