"""One rule for every reader and parser: hostile or damaged input ends in one line.

Every file tyredamp reads goes through :func:`guarded_read` (the registry's
``FileFormat.read``, the UFF 55 and geometry readers, channel-map and campaign
files). Inside it:

* library loggers (asammdf, npTDMS, matplotlib, scipy, xarray, pyuff) are
  silenced, and what a library's destructor prints about a half-opened file
  (``Exception ignored in ... __del__``) is dropped: the one error line is the
  only thing the user sees;
* every numeric or library exception that content can cause
  (``OverflowError``, ``ZeroDivisionError``, ``FloatingPointError``,
  ``MemoryError`` from a declared size, ``RecursionError``, ``ValueError``,
  ``EOFError``, ``struct.error``, ``zlib.error``, ``UnicodeError``) becomes a
  :class:`~tyredamp.exceptions.FileFormatError` naming the file;
* an ``OSError`` without a file name (``No space left on device``) gets it.

Also here, shared by the readers: the axis units (:func:`axis_scale`: a
frequency axis in Hz, kHz, rad/s, cpm or rpm, a time axis in s, ms, us or
min, anything else refused), the bounded TOML reader (:func:`load_toml`) and
the archive check (:func:`check_archive`) that reads every member's declared
size and compression ratio before anything is inflated.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import math
import os
import struct
import sys
import tomllib
import zipfile
import zlib
from collections.abc import Iterator
from typing import Any, Literal

from ..exceptions import FileFormatError, TyredampError

__all__ = [
    "FREQUENCY_UNITS",
    "MAX_ARCHIVE_RATIO",
    "MAX_TOML_BYTES",
    "MAX_TOML_DEPTH",
    "TIME_UNITS",
    "axis_scale",
    "check_archive",
    "guarded_read",
    "library_messages",
    "load_toml",
    "quiet_libraries",
    "toml_depth",
]

#: Loggers of the libraries behind the readers (silenced while a file is read).
LIBRARY_LOGGERS = (
    "asammdf",
    "nptdms",
    "matplotlib",
    "scipy",
    "xarray",
    "pyuff",
    "h5py",
    "canmatrix",
)

#: Frequency-axis units: factor to Hz (rad/s: 1/(2 pi); cycles or revolutions per minute: 1/60).
FREQUENCY_UNITS: dict[str, float] = {
    "hz": 1.0,
    "1/s": 1.0,
    "cps": 1.0,
    "khz": 1e3,
    "rad/s": 1.0 / (2.0 * math.pi),
    "rad/sec": 1.0 / (2.0 * math.pi),
    "cpm": 1.0 / 60.0,
    "rpm": 1.0 / 60.0,
    "1/min": 1.0 / 60.0,
}
#: Time-axis units: factor to seconds.
TIME_UNITS: dict[str, float] = {
    "s": 1.0,
    "sec": 1.0,
    "secs": 1.0,
    "second": 1.0,
    "seconds": 1.0,
    "ms": 1e-3,
    "msec": 1e-3,
    "us": 1e-6,
    "µs": 1e-6,
    "μs": 1e-6,
    "usec": 1e-6,
    "min": 60.0,
}
_SI = {"frequency": ("Hz", FREQUENCY_UNITS), "time": ("s", TIME_UNITS)}


def _norm(label: str) -> str:
    t = "".join(str(label).split()).lower().strip("[]()")
    return t.replace("rad.s^-1", "rad/s").replace("rad/s^1", "rad/s").replace("s^-1", "1/s")


def axis_scale(
    label: object, axis: Literal["frequency", "time"], where: str
) -> tuple[float, str | None]:
    """``(factor to Hz or s, note)`` of an axis unit; blank or ``NONE`` means Hz or s.

    Parameters
    ----------
    label : str or None
        The unit as the file writes it (``"rad/s"``, ``"kHz"``, ``"ms"``).
    axis : {"frequency", "time"}
    where : str
        The file (and field) for the message.

    Returns
    -------
    factor : float
        Multiply the axis values by it to get Hz (frequency) or s (time);
        rad/s is divided by 2 pi, cpm and rpm by 60, minutes multiplied by 60.
    note : str or None
        ``"frequency axis in rad/s converted to Hz"`` when converted.

    Raises
    ------
    FileFormatError
        Any other unit (a frequency axis in s, a time axis in Hz, ``degC``).
    """
    si, table = _SI[axis]
    text = "" if label is None else str(label).strip()
    if text.upper() in ("", "NONE", "-"):
        return 1.0, None
    factor = table.get(_norm(text))
    if factor is None:
        known = ", ".join(dict.fromkeys(k for k in table if k.isascii() and "/sec" not in k))
        raise FileFormatError(
            f"{where}: {axis} axis unit {text[:40]!r} is not one of {known}; "
            f"tyredamp reads a {axis} axis in these units only"
        )
    note = None if factor == 1.0 else f"{axis} axis in {text} converted to {si}"
    return factor, note


# ----------------------------------------------------------------------------- quiet
def _drop_unraisable(_unraisable: Any) -> None:
    """Drop what a destructor raises while a file is read (a half-opened file's cleanup)."""


#: Log records of the libraries, one list per read under way (innermost last).
_RECORDS: list[list[logging.LogRecord]] = []


class _Capture(logging.Handler):
    def __init__(self, sink: list[logging.LogRecord]) -> None:
        super().__init__(logging.DEBUG)
        self.sink = sink

    def emit(self, record: logging.LogRecord) -> None:
        self.sink.append(record)


def library_messages() -> list[str]:
    """What the libraries logged during the read under way (for a reader that checks, e.g.
    npTDMS's ``less data than expected`` of a truncated file)."""
    return [r.getMessage() for r in _RECORDS[-1]] if _RECORDS else []


def _library_loggers() -> list[logging.Logger]:
    names = set(LIBRARY_LOGGERS)
    for name in list(logging.root.manager.loggerDict):
        if name.split(".")[0] in LIBRARY_LOGGERS:
            names.add(name)
    return [logging.getLogger(n) for n in sorted(names)]


@contextlib.contextmanager
def quiet_libraries() -> Iterator[list[logging.LogRecord]]:
    """Keep the readers' libraries off stderr: their loggers and their destructors.

    The loggers of :data:`LIBRARY_LOGGERS` and their children (npTDMS gives
    each module its own console handler) send their records to a list instead
    of stderr (yielded; :func:`library_messages` reads it), and are restored
    afterwards; ``sys.unraisablehook`` drops what a destructor raises
    (asammdf's ``__del__`` of a file it failed to open), and a garbage
    collection before leaving runs those destructors while the hook is in place.
    """
    records: list[logging.LogRecord] = []
    capture = _Capture(records)
    saved = []
    for log in _library_loggers():
        saved.append((log, list(log.handlers), log.propagate, log.disabled))
        log.handlers = [capture]
        log.propagate = False
        log.disabled = False
    hook = sys.unraisablehook
    sys.unraisablehook = _drop_unraisable
    _RECORDS.append(records)
    try:
        yield records
    finally:
        gc.collect()
        _RECORDS.pop()
        sys.unraisablehook = hook
        for log, handlers, propagate, disabled in saved:
            log.handlers = handlers
            log.propagate = propagate
            log.disabled = disabled


_NUMERIC = (OverflowError, ZeroDivisionError, FloatingPointError)
_CONTENT = (ValueError, EOFError, struct.error, zlib.error, UnicodeError, zipfile.BadZipFile)


def _short(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def _forget_hidden_context(exc: BaseException) -> None:
    """Drop contexts that are never shown (``raise ... from None``): their frames hold
    half-built library objects whose destructors would print after the error line."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        if e.__suppress_context__ and e.__cause__ is None:
            e.__context__ = None
        e = e.__cause__ or e.__context__


@contextlib.contextmanager
def guarded_read(path: str | os.PathLike[str]) -> Iterator[None]:
    """Read ``path`` under the one rule of this module (module docstring).

    Raises
    ------
    FileFormatError
        For every numeric or library error the content caused, naming ``path``.
    OSError
        Operating-system errors, with ``path`` as their file name when they had none.
    """
    name = os.fspath(path)
    with quiet_libraries():
        try:
            try:
                yield
            except TyredampError:
                raise
            except OSError as exc:
                if exc.filename is None and exc.errno is not None:
                    raise OSError(exc.errno, exc.strerror or _short(exc), name) from None
                raise
            except MemoryError:
                raise FileFormatError(
                    f"{name}: declares more data than fits in memory; the file is corrupt "
                    "or not a measurement"
                ) from None
            except RecursionError:
                raise FileFormatError(f"{name}: content nested too deeply to read") from None
            except _NUMERIC as exc:
                raise FileFormatError(
                    f"{name}: numbers out of range ({type(exc).__name__}: {_short(exc)})"
                ) from None
            except _CONTENT as exc:
                raise FileFormatError(
                    f"{name}: not readable ({type(exc).__name__}: {_short(exc)})"
                ) from None
        except BaseException as exc:
            # inside quiet_libraries: the destructors this frees run under its hook
            _forget_hidden_context(exc)
            raise


# ----------------------------------------------------------------------------- TOML
#: Largest TOML file read (bytes): channel maps and campaign files are a few kB.
MAX_TOML_BYTES = 4 << 20
#: Deepest nesting of tables and arrays accepted in a TOML file.
MAX_TOML_DEPTH = 32


def toml_depth(text: str) -> int:
    """The deepest nesting of ``[``/``{`` (and of dotted table headers) in TOML ``text``.

    A linear scan that skips strings and comments; an upper bound of what
    :mod:`tomllib` would recurse into (arrays, inline tables, dotted keys).
    """
    depth = best = 0
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if c in "\"'":
            q3 = text[i : i + 3]
            if q3 in ('"""', "'''"):
                j = text.find(q3, i + 3)
                i = n if j < 0 else j + 3
                at_line_start = False
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if (c == '"' and text[j] == "\\") else 1
            i = j + 1
            at_line_start = False
            continue
        if c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if c == "\n":
            at_line_start = True
            i += 1
            continue
        if at_line_start and c == "[" and depth == 0:
            j = text.find("\n", i)
            header = text[i : n if j < 0 else j]
            best = max(best, header.count(".") + 1)
            i = n if j < 0 else j
            continue
        if not c.isspace():
            at_line_start = False
        if c == "=" and depth == 0:
            k = text.rfind("\n", 0, i) + 1
            best = max(best, text[k:i].count(".") + 1)
        if c in "[{":
            depth += 1
            best = max(best, depth)
        elif c in "]}":
            depth = max(0, depth - 1)
        i += 1
    return best


def load_toml(
    text: str, where: str, what: str = "valid TOML", max_depth: int = MAX_TOML_DEPTH
) -> dict[str, Any]:
    """Parse TOML ``text`` after checking its size and nesting depth.

    Raises
    ------
    FileFormatError
        Larger than :data:`MAX_TOML_BYTES`, nested deeper than ``max_depth``,
        or not valid TOML; the message names ``where`` and says it is not ``what``.
    """
    if len(text) > MAX_TOML_BYTES:
        raise FileFormatError(
            f"{where}: {len(text)} characters; a TOML file of tyredamp is at most "
            f"{MAX_TOML_BYTES >> 20} MiB"
        )
    depth = toml_depth(text)
    if depth > max_depth:
        raise FileFormatError(
            f"{where}: tables or arrays nested {depth} deep; at most {max_depth} are read"
        )
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(f"{where}: not {what} ({_short(exc)})") from None
    except RecursionError:
        raise FileFormatError(f"{where}: tables or arrays nested too deeply") from None


# ----------------------------------------------------------------------------- archives
#: Largest compression ratio accepted for an archive member above 1 MiB (deflate reaches
#: about 1000:1 on constant data; measured data rarely beats 10:1).
MAX_ARCHIVE_RATIO = 200.0


def check_archive(
    zf: zipfile.ZipFile,
    where: str,
    max_bytes: int,
    max_ratio: float = MAX_ARCHIVE_RATIO,
    limit_text: str | None = None,
) -> int:
    """Check every member of a ZIP archive from its declared sizes, before inflating any.

    Parameters
    ----------
    zf : zipfile.ZipFile
        The open archive (only its central directory is read).
    where : str
        The file, for the message.
    max_bytes : int
        Most bytes all members may take once inflated.
    max_ratio : float
        Largest inflated-to-stored ratio of a member larger than 1 MiB.
    limit_text : str, optional
        What ``max_bytes`` is, for the message (default ``"the N bytes allowed"``).

    Returns
    -------
    int
        The declared inflated size of all members (bytes).

    Raises
    ------
    FileFormatError
        A member whose ratio is above ``max_ratio`` (a "zip bomb"), or
        members that together exceed ``max_bytes``.
    """
    total = 0
    for info in zf.infolist():
        stored = max(int(info.compress_size), 1)
        size = int(info.file_size)
        if size > (1 << 20) and size / stored > max_ratio:
            raise FileFormatError(
                f"{where}: member {info.filename[:60]!r} inflates {size / stored:.0f}-fold "
                f"(to {size} bytes); refused before inflating (a compression bomb?)"
            )
        total += size
        if total > max_bytes:
            raise FileFormatError(
                f"{where}: its members take {total} bytes or more inflated, more than "
                f"{limit_text or f'the {max_bytes} bytes allowed'}; refused before inflating"
            )
    return total
