"""Structure check of a MATLAB 5 (v5-v7) MAT file before SciPy reads it.

:func:`scipy.io.loadmat` trusts the sizes written in a file's data elements:
a damaged element (a dimension, a byte count or a class byte changed) can
make its compiled reader touch memory outside the file and end the process
with a segmentation fault, so the one-line error never comes. This module
walks the element tree of the MAT-file format (MathWorks, "MAT-File Format",
R2019b, chapter 1: a 128-byte header; tagged data elements of type, byte
count and data padded to 8 bytes, or *small* elements of at most 4 bytes
packed into the tag; ``miMATRIX`` elements made of array flags, dimensions,
name and the real and imaginary parts, with cells and structures holding
``miMATRIX`` elements of their own; ``miCOMPRESSED`` elements holding one
zlib-compressed element) and checks that every size fits inside its parent
and that a numeric array's data hold exactly ``prod(dims)`` values, and a
sparse array's row indices and column pointers index inside it. It reads
nothing into arrays but a sparse array's indices; what it cannot check
(object, function-handle and opaque classes) is only bounded by its parent
element.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..exceptions import FileFormatError

__all__ = ["check_mat5"]

#: Bytes per value of the data types (MAT-File Format, table 1-1).
_SIZE = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 9: 8, 12: 8, 13: 8, 16: 1, 17: 2, 18: 4}
_MATRIX, _COMPRESSED = 14, 15
#: Array classes whose data are checked value by value: char (4) and numeric (6-15).
_CHECKED = {4, *range(6, 16)}
_CELL, _STRUCT, _SPARSE = 1, 2, 5
_MAX_DEPTH = 32
#: Largest inflated size of one compressed element, a multiple of the file's size.
_INFLATE_RATIO = 1000


class _Damaged(Exception):
    """A structural error, with what was found where."""


def check_mat5(data: bytes, where: str) -> None:
    """Refuse a MAT 5 file whose element sizes do not fit together.

    Parameters
    ----------
    data : bytes
        The whole file.
    where : str
        The file's name for messages.

    Raises
    ------
    FileFormatError
        An element's size runs past its parent, a numeric array's data do not
        hold ``prod(dims)`` values, a compressed element does not inflate, or
        elements nest deeper than 32 levels.
    """
    if len(data) < 128 or data[126:128] not in (b"IM", b"MI"):
        return  # not a MAT 5 file: v4 and HDF5 files are left to their readers
    order = "<" if data[126:128] == b"IM" else ">"
    try:
        _elements(memoryview(data)[128:], order, 0, len(data))
    except _Damaged as exc:
        raise FileFormatError(f"{where}: damaged MATLAB file ({exc})") from None


def _tag(buf: memoryview, pos: int, order: str) -> tuple[int, int, int, int]:
    """``(type, nbytes, data start, next element)`` of the element at ``pos``."""
    if pos + 8 > len(buf):
        raise _Damaged(f"an element's tag at byte {pos} runs past its end")
    word, nbytes = struct.unpack_from(order + "II", buf, pos)
    if word >> 16:  # small element: byte count in the upper half, data in the tag
        small = word >> 16
        if small > 4:
            raise _Damaged(f"a small element at byte {pos} claims {small} bytes")
        return word & 0xFFFF, small, pos + 4, pos + 8
    start = pos + 8
    end = start + nbytes
    if end > len(buf):
        raise _Damaged(f"an element at byte {pos} claims {nbytes} bytes, {len(buf) - start} left")
    step = nbytes if word == _COMPRESSED else nbytes + (-nbytes) % 8
    return word, nbytes, start, min(start + step, len(buf))


def _elements(buf: memoryview, order: str, depth: int, file_size: int) -> None:
    """Check each top-level element of ``buf``."""
    pos = 0
    while pos < len(buf):
        kind, nbytes, start, pos = _tag(buf, pos, order)
        _element(kind, buf[start : start + nbytes], order, depth, file_size)


def _element(kind: int, body: memoryview, order: str, depth: int, file_size: int) -> None:
    if depth > _MAX_DEPTH:
        raise _Damaged(f"elements nest deeper than {_MAX_DEPTH} levels")
    if kind == _COMPRESSED:
        inflater = zlib.decompressobj()
        try:
            raw = inflater.decompress(body, _INFLATE_RATIO * file_size + 1)
        except zlib.error as exc:
            raise _Damaged(f"a compressed element does not inflate ({exc})") from None
        if len(raw) > _INFLATE_RATIO * file_size:
            raise _Damaged("a compressed element inflates beyond any plausible size")
        _elements(memoryview(raw), order, depth + 1, file_size)
    elif kind == _MATRIX:
        if len(body):  # an empty miMATRIX is an empty array
            _matrix(body, order, depth, file_size)
    elif kind not in _SIZE:
        raise _Damaged(f"unknown data type {kind}")


def _matrix(body: memoryview, order: str, depth: int, file_size: int) -> None:
    """Array flags, dimensions, name and data of one ``miMATRIX`` element."""
    kind, n, start, pos = _tag(body, 0, order)
    if kind != 6 or n != 8:
        raise _Damaged("an array's flags are not two 32-bit words")
    flags = struct.unpack_from(order + "I", body, start)[0]
    cls, is_complex = flags & 0xFF, bool(flags & 0x0800)
    kind, n, start, pos = _tag(body, pos, order)
    if kind != 5 or n < 8 or n % 4:
        raise _Damaged("an array's dimensions are not two or more 32-bit integers")
    dims = struct.unpack_from(f"{order}{n // 4}i", body, start)
    if min(dims) < 0:
        raise _Damaged(f"an array has a negative dimension {dims}")
    count = 1
    for d in dims:
        count *= d
    kind, n, start, pos = _tag(body, pos, order)  # the name: miINT8 text
    if kind not in (1, 2):
        raise _Damaged("an array's name is not text")
    if cls in _CHECKED:
        for part in ("real", "imaginary")[: 1 + is_complex]:
            if count == 0 and pos >= len(body):
                break
            kind, n, start, pos = _tag(body, pos, order)
            if kind == 16 and count <= n <= 4 * count:
                continue  # UTF-8 text: one to four bytes per character
            if kind not in _SIZE or n != count * _SIZE[kind]:
                raise _Damaged(
                    f"an array of {count} values has {n} bytes of data type {kind} in its "
                    f"{part} part"
                )
    elif cls == _SPARSE:
        _sparse(body, pos, order, dims, is_complex)
    elif cls == _CELL:
        for _ in range(count):
            kind, n, start, pos = _tag(body, pos, order)
            if kind != _MATRIX:
                raise _Damaged("a cell of a cell array is not an array")
            _element(kind, body[start : start + n], order, depth + 1, file_size)
    elif cls == _STRUCT:
        kind, n, start, pos = _tag(body, pos, order)
        if kind != 5 or n != 4:
            raise _Damaged("a structure's field-name length is not one 32-bit integer")
        width = struct.unpack_from(order + "i", body, start)[0]
        kind, n, start, pos = _tag(body, pos, order)
        if width <= 0 or kind not in (1, 2) or n % width:
            raise _Damaged("a structure's field names do not fit their length")
        for _ in range(count * (n // width)):
            kind, n, start, pos = _tag(body, pos, order)
            if kind != _MATRIX:
                raise _Damaged("a structure's field is not an array")
            _element(kind, body[start : start + n], order, depth + 1, file_size)


def _sparse(
    body: memoryview, pos: int, order: str, dims: tuple[int, ...], is_complex: bool
) -> None:
    """Row indices ``ir``, column pointers ``jc`` and values of a sparse array
    (MAT-File Format, "Sparse array"): ``jc`` has ``n + 1`` nondecreasing
    entries from 0, every row index lies in ``0 .. m - 1`` and the values hold
    at least ``jc[n]`` entries."""
    if len(dims) != 2:
        raise _Damaged(f"a sparse array has {len(dims)} dimensions")
    index = []
    for what in ("row indices", "column pointers"):
        kind, n, start, pos = _tag(body, pos, order)
        if kind not in (5, 6) or n % 4:
            raise _Damaged(f"a sparse array's {what} are not 32-bit integers")
        index.append(
            np.frombuffer(body[start : start + n], dtype=order + ("i4" if kind == 5 else "u4"))
        )
    ir, jc = index
    rows, cols = dims
    if jc.size != cols + 1 or jc[0] != 0 or np.any(np.diff(jc.astype(np.int64)) < 0):
        raise _Damaged(f"a sparse array's {jc.size} column pointers do not fit {cols} columns")
    nnz = int(jc[-1])
    if nnz > ir.size or (nnz and (ir[:nnz].min() < 0 or ir[:nnz].max() >= rows)):
        raise _Damaged(f"a sparse array's row indices do not fit {rows} rows and {nnz} values")
    for part in ("real", "imaginary")[: 1 + is_complex]:
        kind, n, start, pos = _tag(body, pos, order)
        if kind not in _SIZE or n < nnz * _SIZE[kind]:
            raise _Damaged(f"a sparse array's {part} part holds fewer than its {nnz} values")
