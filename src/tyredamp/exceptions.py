"""Exceptions raised by tyredamp.

Every error the package raises on purpose is a :class:`TyredampError`. The
subclasses also inherit the matching built-in exception, so callers that
catch ``ValueError`` or ``RuntimeError`` keep working (the pattern of
python-control's ``control.exception``).
"""

from __future__ import annotations

__all__ = [
    "ConvergenceError",
    "FileFormatError",
    "InputError",
    "PhysicsError",
    "ShapeError",
    "TyredampError",
]


class TyredampError(Exception):
    """Base class of every error raised on purpose by tyredamp."""


class InputError(TyredampError, ValueError):
    """An argument has an invalid value (NaN, out of range, wrong option)."""


class ShapeError(InputError):
    """An array argument has the wrong shape or size."""


class PhysicsError(InputError):
    """Parameters that cannot describe a physical system.

    Examples: a mass matrix that is not positive definite, a negative
    inflation pressure, a non-symmetric stiffness matrix.
    """


class FileFormatError(TyredampError, ValueError):
    """A file is empty, truncated, corrupt or not of the expected layout."""


class ConvergenceError(TyredampError, RuntimeError):
    """An iterative numerical method did not reach its tolerance."""
