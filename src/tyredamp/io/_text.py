"""Text of files written by other programs: UTF-8, else the legacy Windows encoding.

Lab software on Windows still writes header text (units labels such as
``m/s²``, ``g²/Hz``, channel names such as ``Beschleunigung Ü``) in cp1252
or Latin-1. :func:`decode_text` tries, in order, UTF-16 (only with its byte
order mark), UTF-8 (with or without a byte order mark), cp1252, then
Latin-1 (which decodes any byte), and says which one it used, so a reader can
record it in the object's ``meta`` (``"text_encoding"``).
"""

from __future__ import annotations

import codecs
from typing import Any

__all__ = ["decode_bytes", "decode_text"]


def decode_text(raw: bytes, where: Any = None) -> tuple[str, str]:
    """``(text, encoding)`` of a file's bytes; the encoding is ``"utf-8"``,
    ``"utf-16"``, ``"cp1252"`` or ``"latin-1"``.

    Parameters
    ----------
    raw : bytes
        The file content.
    where : any, optional
        Unused; kept for symmetry with the readers' messages.
    """
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:
            return raw.decode("utf-16"), "utf-16"
        except UnicodeDecodeError:
            pass
    if raw.startswith(codecs.BOM_UTF8):
        raw = raw[len(codecs.BOM_UTF8) :]
    try:
        return raw.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        pass
    try:
        return raw.decode("cp1252"), "cp1252"
    except UnicodeDecodeError:  # 0x81, 0x8D, 0x8F, 0x90, 0x9D are not cp1252
        return raw.decode("latin-1"), "latin-1"


def decode_bytes(raw: bytes) -> tuple[str, str]:
    """Like :func:`decode_text` for a short string (a header field)."""
    return decode_text(raw)
