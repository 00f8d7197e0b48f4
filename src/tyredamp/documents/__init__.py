"""Result documents: one home for every JSON file tyredamp writes as a result.

Each kind has a version, a writer (object -> JSON-ready document) and a
reader (parsed document -> object), in one registry, :data:`DOCUMENTS`:

=================  =======  ==========================================  ==========================
kind               version  object                                      module
=================  =======  ==========================================  ==========================
``modes``          1        ``dict`` of :class:`~tyredamp.modal.ModalModel`   :mod:`.modes`
``damping``        1        :class:`~tyredamp.damping.DampingModel`     :mod:`.damping`
``lateral-fit``    1        the checked document (``dict``)             :mod:`.lateral`
demo results       1        the checked document (``dict``)             :mod:`.demo`
=================  =======  ==========================================  ==========================

All of them are read and written by :mod:`.jsonfile` under one policy:
strict JSON, non-finite numbers as ``null``, complex numbers as ``[re, im]``,
atomic writes (no partial file on error). The method packages keep pure
``to_dict``/``from_dict``; the documents add the kind and version around
them. :func:`read_document` recognises any of them by its ``"kind"``.

Example
-------
>>> from tyredamp.documents import read_document     # doctest: +SKIP
>>> kind, obj, doc = read_document("modes.json")      # doctest: +SKIP
>>> kind, sorted(obj)                                  # doctest: +SKIP
('modes', ['complex', 'real'])
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError, InputError, TyredampError
from .jsonfile import read_json, write_json

__all__ = [
    "DOCUMENTS",
    "DocumentKind",
    "kind_of",
    "read_document",
    "write_document",
]


@dataclass(frozen=True)
class DocumentKind:
    """One kind of result document.

    Attributes
    ----------
    kind : str
        Value of the document's ``"kind"`` key.
    version : int
        Newest layout version this tyredamp writes and reads.
    to_document : callable
        ``to_document(obj, **options) -> dict``: the JSON-ready document.
    from_document : callable
        ``from_document(doc) -> obj``; raises :class:`FileFormatError`.
    """

    kind: str
    version: int
    to_document: Callable[..., dict[str, Any]]
    from_document: Callable[[dict[str, Any]], Any]


@functools.cache
def _registry() -> dict[str, DocumentKind]:
    """:data:`DOCUMENTS`, built on first use (the kinds' modules import the method packages,
    which a command that only reads options or writes JSON does not need)."""
    from .damping import DAMPING_KIND, DAMPING_VERSION, damping_document, damping_from_document
    from .demo import RESULTS_KIND, RESULTS_VERSION, results_from_document
    from .lateral import (
        LATERAL_FIT_KIND,
        LATERAL_FIT_VERSION,
        lateral_fit_document,
        lateral_fit_from_document,
    )
    from .modes import MODES_KIND, MODES_VERSION, models_from_document, modes_document

    def results_document(doc: dict[str, Any]) -> dict[str, Any]:
        return results_from_document(doc)

    return {
        d.kind: d
        for d in (
            DocumentKind(MODES_KIND, MODES_VERSION, modes_document, models_from_document),
            DocumentKind(DAMPING_KIND, DAMPING_VERSION, damping_document, damping_from_document),
            DocumentKind(
                LATERAL_FIT_KIND,
                LATERAL_FIT_VERSION,
                lateral_fit_document,
                lateral_fit_from_document,
            ),
            DocumentKind(RESULTS_KIND, RESULTS_VERSION, results_document, results_from_document),
        )
    }


def __getattr__(name: str) -> Any:
    #: Every result document by kind (:class:`DocumentKind`); a new kind is one module
    #: and one line in :func:`_registry`.
    if name == "DOCUMENTS":
        return _registry()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def kind_of(doc: dict[str, Any]) -> str:
    """The registered kind of a parsed document.

    Raises
    ------
    FileFormatError
        No known kind, or a version newer than this tyredamp reads.
    """
    kind = doc.get("kind", doc.get("tyredamp"))
    documents = _registry()
    if not isinstance(kind, str) or kind not in documents:
        raise FileFormatError(
            f"not a tyredamp result document (kind {kind!r}; expected one of {sorted(documents)})"
        )
    version = doc.get("version", 1)
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise FileFormatError(f"{kind}: version: expected an integer >= 1, got {version!r}")
    if version > documents[kind].version:
        raise FileFormatError(
            f"{kind}: version {version} is newer than this tyredamp reads "
            f"({documents[kind].version}); update tyredamp"
        )
    return kind


def read_document(path: str | os.PathLike[str]) -> tuple[str, Any, dict[str, Any]]:
    """Read any result document: ``(kind, object, parsed document)``.

    Raises
    ------
    FileFormatError
        Not strict JSON, no known kind or version, or a malformed document,
        including fields of the wrong type (the message starts with the path).
    """
    p = Path(path)
    try:
        doc = read_json(p)
        kind = kind_of(doc)
        return kind, _registry()[kind].from_document(doc), doc
    except FileFormatError as exc:
        msg = str(exc)
        raise FileFormatError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
    except TyredampError as exc:
        raise FileFormatError(f"{p}: {exc}") from None
    except KeyError as exc:
        raise FileFormatError(f"{p}: missing key {exc.args[0]!r}") from None
    except (TypeError, ValueError, AttributeError, IndexError) as exc:
        # a field of the wrong type (a string for a number, a number for a list ...)
        name = type(exc).__name__
        raise FileFormatError(f"{p}: a field has the wrong type ({name}: {exc})") from None


def write_document(path: str | os.PathLike[str], kind: str, obj: Any, **options: Any) -> Path:
    """Write ``obj`` as a document of ``kind`` (strict JSON, atomically); returns the path.

    ``options`` go to the kind's ``to_document`` (for example ``source=`` of
    the modes document).
    """
    documents = _registry()
    if kind not in documents:
        raise InputError(f"kind: expected one of {sorted(documents)}, got {kind!r}")
    return write_json(documents[kind].to_document(obj, **options), path)
