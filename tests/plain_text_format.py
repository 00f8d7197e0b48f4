"""A toy measurement format for tests/test_io_registry.py: one FRF as text lines.

Each line holds ``frequency_hz re(H) im(H)`` of a 1 x 1 receptance.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from tyredamp.frf import FRF, Channel
from tyredamp.timedata import TimeData


def read_text(path: str | os.PathLike[str]) -> FRF:
    rows = np.loadtxt(Path(path), ndmin=2)
    h = (rows[:, 1] + 1j * rows[:, 2]).reshape(1, 1, -1)
    return FRF(rows[:, 0], h, outputs=[Channel(1)], inputs=[Channel(1)])


def write_text(obj: FRF | TimeData, path: str | os.PathLike[str]) -> None:
    assert isinstance(obj, FRF)
    h = obj.H[0, 0]
    np.savetxt(Path(path), np.column_stack([obj.frequency, h.real, h.imag]))
