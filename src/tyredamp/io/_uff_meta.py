r"""The UFF metadata record: a whole ``meta`` dict in data sets 151 (header).

When ``meta`` does not fit the ID lines whole, the file also holds the whole
``meta`` as JSON in a chain of data sets 151 (header) placed before the data
sets 58, so nothing is truncated (the conditions of a lateral rig FRF, the
truth of a virtual test, a long description). Each 151 set carries
``tyredamp1 meta K N`` (part K of N, from 1) in its model-name field and up to
240 characters of the JSON in its description, application and program
fields (80 each). The JSON is ASCII with every space written as the JSON
escape ``\u0020`` (so no field begins or ends with a blank that a reader
would strip); it decodes to the same ``meta``. Other programs see ordinary
header sets; the ID lines still carry what fits, as before.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError
from ._common import meta_from_json, meta_to_json

__all__ = ["META_FIELDS", "META_MARK", "meta_record", "read_meta_record"]

#: Model-name mark of a metadata data set 151, followed by ``K N`` (part K of N).
META_MARK = "tyredamp1 meta"
#: Text fields of data set 151 (80 characters each) that carry the JSON.
META_FIELDS = ("description", "db_app", "program")


def meta_record(meta: dict[str, Any]) -> list[dict[str, Any]]:
    """Data sets 151 holding the whole ``meta`` as JSON (module docs, "Metadata record")."""
    text = meta_to_json(meta).replace(" ", "\\u0020")
    per_set = 80 * len(META_FIELDS)
    chunks = [text[k : k + per_set] for k in range(0, len(text), per_set)] or ["{}"]
    out = []
    for k, chunk in enumerate(chunks):
        d: dict[str, Any] = {
            "type": 151,
            "model_name": f"{META_MARK} {k + 1} {len(chunks)}",
            # fixed dates: the same data give the same file
            "date_db_created": "",
            "time_db_created": "",
            "date_db_saved": "",
            "time_db_saved": "",
            "date_file_written": "",
            "time_file_written": "",
        }
        for j, name in enumerate(META_FIELDS):
            d[name] = chunk[80 * j : 80 * (j + 1)] or "NONE"
        out.append(d)
    return out


def read_meta_record(p: Path, uff: Any, types: list[int]) -> dict[str, Any] | None:
    """The ``meta`` of the data sets 151 written by :func:`meta_record`, None without them.

    ``uff`` is the open :class:`pyuff.UFF` of ``p`` and ``types`` its data-set types.
    """
    idx = [k for k, t in enumerate(types) if t == 151]
    read = uff.read_sets(idx) if idx else []
    headers: list[dict[str, Any]] = [read] if isinstance(read, dict) else list(read)
    parts: dict[int, str] = {}
    total = None
    for h in headers:
        tokens = str(h.get("model_name", "")).split()
        if len(tokens) != 4 or " ".join(tokens[:2]) != META_MARK:
            continue
        try:
            k, n = int(tokens[2]), int(tokens[3])
        except ValueError:
            raise FileFormatError(f"{p}: corrupt tyredamp metadata record {tokens!r}") from None
        if (total is not None and n != total) or k in parts or not 1 <= k <= n:
            raise FileFormatError(f"{p}: corrupt tyredamp metadata record (part {k} of {n})")
        total = n
        parts[k] = "".join(
            "" if str(h.get(name, "")).strip() == "NONE" else str(h.get(name, "")).strip()
            for name in META_FIELDS
        )
    if total is None:
        return None
    if len(parts) != total:
        raise FileFormatError(
            f"{p}: incomplete tyredamp metadata record: {len(parts)} of {total} parts"
        )
    return meta_from_json("".join(parts[k] for k in range(1, total + 1)), f"{p}: metadata record")
