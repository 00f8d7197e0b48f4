"""The MAT 5 structure check that runs before scipy.io.loadmat trusts a file's sizes."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
import scipy.io as sio
import scipy.sparse as sp

from tyredamp import FileFormatError
from tyredamp.io import read_timedata
from tyredamp.io._mat5 import check_mat5

CONTENT = {
    "t": np.arange(64) / 64.0,
    "x": np.arange(192.0).reshape(64, 3),
    "c": np.arange(5) + 1j,
    "s": {"a": np.arange(3), "b": "héllo ✓", "n": {"q": np.eye(2)}},
    "cell": np.array([np.arange(2), "txt", np.zeros((0, 3))], dtype=object),
    "i8": np.arange(5, dtype=np.int8),
    "u64": np.arange(3, dtype=np.uint64),
    "flags": np.array([True, False]),
    "sparse": sp.csc_matrix(np.eye(3)),
    "empty": np.zeros((0,)),
    "text": "plain",
}


@pytest.mark.parametrize("compressed", [False, True])
def test_files_scipy_writes_pass(tmp_path: Path, compressed: bool) -> None:
    p = tmp_path / "a.mat"
    sio.savemat(p, CONTENT, do_compression=compressed)
    check_mat5(p.read_bytes(), str(p))  # no error
    assert sio.loadmat(p)["x"].shape == (64, 3)


def _real_part_count(raw: bytes, name: bytes) -> int:
    """Offset of the byte count of variable ``name``'s real part in an uncompressed file."""
    at = raw.index(name + b"\x00" * (8 - len(name)))  # the name, padded to 8 bytes
    return at + 8 + 4  # the next tag: type (4 bytes), then the byte count


def test_a_byte_count_that_does_not_match_the_dimensions_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "a.mat"
    sio.savemat(p, {"signal": np.arange(10.0), "fs": 100.0})
    raw = bytearray(p.read_bytes())
    at = _real_part_count(bytes(raw), b"signal")
    assert struct.unpack_from("<I", raw, at)[0] == 80  # 10 doubles
    struct.pack_into("<I", raw, at, 72)  # 9 doubles for 10 values: what loadmat would trust
    p.write_bytes(bytes(raw))
    with pytest.raises(FileFormatError, match=r"a\.mat: damaged MATLAB file .*10 values has 72"):
        read_timedata(p)


def test_sizes_past_the_end_and_bad_compression_are_refused(tmp_path: Path) -> None:
    p = tmp_path / "a.mat"
    sio.savemat(p, {"signal": np.arange(100.0)}, do_compression=True)
    raw = p.read_bytes()
    with pytest.raises(FileFormatError, match="claims"):
        check_mat5(raw[:-20], "cut.mat")  # the compressed element's count runs past the end
    body = bytearray(raw)
    body[150] ^= 0xFF  # inside the deflate stream
    with pytest.raises(FileFormatError, match="damaged MATLAB file"):
        check_mat5(bytes(body), "flipped.mat")


def test_nesting_is_bounded() -> None:
    """A cell holding a cell ... 40 deep: refused without recursing without end."""

    def cell(inner: bytes) -> bytes:
        flags = struct.pack("<IIII", 6, 8, 1, 0)  # mxCELL
        dims = struct.pack("<II", 5, 8) + struct.pack("<ii", 1, 1)
        name = struct.pack("<I", (1 << 16) | 1) + b"c\x00\x00\x00"  # small element
        body = flags + dims + name + inner
        return struct.pack("<II", 14, len(body)) + body

    leaf = struct.pack("<II", 14, 0)
    element = leaf
    for _ in range(40):
        element = cell(element)
    header = b"MATLAB 5.0 MAT-file".ljust(116) + b"\x00" * 8 + b"\x00\x01IM"
    with pytest.raises(FileFormatError, match="deeper than 32"):
        check_mat5(header + element, "deep.mat")


def test_sparse_indices_outside_the_array_are_refused(tmp_path: Path) -> None:
    """A column pointer changed in a sparse array (SciPy's reader crashed on it)."""
    p = tmp_path / "s.mat"
    sio.savemat(p, {"sp": sp.csc_matrix(np.eye(3))})
    raw = bytearray(p.read_bytes())
    jc = struct.pack("<4i", 0, 1, 2, 3)  # the column pointers of eye(3)
    at = raw.index(jc)
    struct.pack_into("<i", raw, at + 4, 7)  # column 0 ends past the 3 values
    with pytest.raises(FileFormatError, match="column pointers do not fit"):
        check_mat5(bytes(raw), "s.mat")
    struct.pack_into("<i", raw, at + 4, 1)
    struct.pack_into("<i", raw, at - 8 - 12, 5)  # a row index 5 in a 3 x 3 array
    with pytest.raises(FileFormatError, match="row indices do not fit 3 rows"):
        check_mat5(bytes(raw), "s.mat")
