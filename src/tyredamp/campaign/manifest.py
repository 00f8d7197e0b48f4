"""Protection of a campaign's output files, and the skip of outputs that would not change.

After a campaign has written its tables, documents and report, it records
the SHA-256 of each in the folder's manifest
(:data:`tyredamp.io._safety.MANIFEST_NAME`, the layout of the demo's
manifest) together with the *outputs key*: the SHA-256 of everything the
outputs are made from (:func:`outputs_key`: the campaign file's tests,
conditions and tracking settings, the cache key of every step of every
test, the failures, the tyredamp version, whether a report is written).

* A later run refuses to replace a file that is no longer as the campaign
  wrote it (:func:`check_edits`, with :func:`tyredamp.io._safety.changed_since_written`):
  a user's edits to ``report.html`` or ``modes.csv`` are never overwritten.
* A run whose outputs key equals the recorded one, over files that are all
  as written, writes nothing (:func:`reusable_summary`): the tables and
  figures would be the same bytes.

The cache entries are not listed: each carries its own checksum
(:mod:`.cache`).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .. import __version__
from ..exceptions import InputError
from ..io._safety import MANIFEST_NAME, atomic_path, changed_since_written
from .runner import TestRun
from .spec import Campaign

__all__ = ["begin_outputs", "check_edits", "outputs_key", "reusable_summary", "seal_outputs"]

#: Version of what :func:`outputs_key` covers (part of the key).
OUTPUTS_FORMAT = 1
_KIND = "tyredamp-manifest"


def outputs_key(campaign: Campaign, runs: Sequence[TestRun], report: bool) -> str:
    """SHA-256 (hex) of everything a campaign's output files are computed from."""
    ident = {
        "format": OUTPUTS_FORMAT,
        "tyredamp": __version__,
        "campaign": str(campaign.path),
        "name": campaign.name,
        "tracking": campaign.tracking,
        "report": report,
        "tests": [
            {
                "id": r.spec.test_id,
                "file": r.spec.rel,
                "study": r.spec.study,
                "conditions": r.spec.conditions,
                "keys": r.keys,
                "digest": r.digest,
                "failed": [r.failed_step, r.reason],
                "have": sorted([*r.documents, *r.skipped]),
            }
            for r in runs
        ],
    }
    text = json.dumps(ident, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _manifest(root: Path) -> dict[str, Any] | None:
    try:
        doc = json.loads((root / MANIFEST_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(doc, dict) or not isinstance(doc.get("sha256"), dict):
        return None
    return doc


def check_edits(
    root: str | os.PathLike[str], option: str = "--out", shown: str | None = None
) -> None:
    """Refuse to go on when a file the campaign wrote in ``root`` was changed since.

    Raises
    ------
    InputError
        One line naming the folder and the changed files, and what to do.
    """
    real = Path(root)
    doc = _manifest(real)
    if doc is None:
        return
    listed = [f for f in doc["sha256"] if isinstance(f, str) and (real / f).is_file()]
    changed = changed_since_written(real, listed)
    if changed:
        few = ", ".join(changed[:3]) + (f" and {len(changed) - 3} more" if len(changed) > 3 else "")
        raise InputError(
            f"{option}: {shown or os.fspath(root)}: {few} changed since the campaign wrote it; "
            "not replaced: move the changed files elsewhere (or choose another output folder) "
            "and run again"
        )


def reusable_summary(root: str | os.PathLike[str], key: str) -> dict[str, Any] | None:
    """The summary of the outputs in ``root`` when they are exactly those of ``key``, else None."""
    real = Path(root)
    doc = _manifest(real)
    if doc is None or doc.get("outputs_key") != key:
        return None
    files = [f for f in doc["sha256"] if isinstance(f, str)]
    if not files or any(not (real / f).is_file() for f in files):
        return None
    if changed_since_written(real, files):
        return None
    try:
        summary = json.loads((real / "campaign.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    ok = isinstance(summary, dict) and summary.get("complete") is True
    return summary if ok else None


def _write(root: Path, files: dict[str, str], key: str | None) -> None:
    doc = {"kind": _KIND, "version": 1, "outputs_key": key, "sha256": dict(sorted(files.items()))}
    with atomic_path(root / MANIFEST_NAME) as tmp:
        tmp.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def begin_outputs(root: str | os.PathLike[str]) -> None:
    """Check for edits once more (the run took time), then clear the manifest's list.

    From here until :func:`seal_outputs` the files are being replaced; a run
    killed in between leaves them unlisted, and the next run replaces them.
    """
    real = Path(root)
    check_edits(real)
    if real.is_dir():
        _write(real, {}, None)


def seal_outputs(root: str | os.PathLike[str], key: str) -> None:
    """Record the SHA-256 of every output file (cache aside) and the outputs ``key``."""
    real = Path(root)
    try:
        summary = json.loads((real / "campaign.json").read_text(encoding="utf-8"))
        written = [f for f in summary.get("written", []) if isinstance(f, str)]
    except (OSError, ValueError, RecursionError, AttributeError):
        written = []
    files: dict[str, str] = {}
    for f in written:
        p = real / f
        if f.startswith("cache/") or ".." in Path(f).parts or not p.is_file():
            continue
        h = hashlib.sha256()
        with open(p, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        files[f] = h.hexdigest()
    _write(real, files, key)
