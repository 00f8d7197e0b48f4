"""tyredamp: measuring, identifying and modelling vibration damping in pneumatic tyres."""

from __future__ import annotations

from .exceptions import (
    ConvergenceError,
    FileFormatError,
    InputError,
    PhysicsError,
    ShapeError,
    TyredampError,
)
from .frf import FRF, Channel

__version__ = "0.1.0"

__all__ = [
    "FRF",
    "Channel",
    "ConvergenceError",
    "FileFormatError",
    "InputError",
    "PhysicsError",
    "ShapeError",
    "TyredampError",
    "__version__",
]
