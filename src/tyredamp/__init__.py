"""tyredamp: measuring, identifying and modelling vibration damping in pneumatic tyres.

The package namespace is light: :class:`FRF` and :class:`Channel` (which
need NumPy) are imported on first access, so that ``tyredamp --version`` and
``--help`` start without NumPy (``benchmarks/startup.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .exceptions import (
    ConvergenceError,
    FileFormatError,
    InputError,
    PhysicsError,
    ShapeError,
    TyredampError,
)

if TYPE_CHECKING:
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


def __getattr__(name: str) -> Any:
    """``FRF`` and ``Channel`` on first access (PEP 562)."""
    if name in ("FRF", "Channel"):
        from . import frf

        return getattr(frf, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
