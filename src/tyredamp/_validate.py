"""Argument checks shared across the package.

Each function raises a :class:`~tyredamp.exceptions.TyredampError` subclass
whose message names the argument, what was expected and what came.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .exceptions import InputError, PhysicsError, ShapeError

__all__ = [
    "as_band",
    "as_count",
    "as_finite",
    "as_frequency",
    "as_square_symmetric",
    "check_positive",
    "check_positive_definite",
    "check_positive_semidefinite",
]


def as_finite(
    x: ArrayLike,
    name: str,
    *,
    ndim: int | None = None,
    dtype: Any = float,
    allow_empty: bool = False,
) -> NDArray[Any]:
    """Return ``x`` as an array of ``dtype``; reject NaN, inf and wrong ``ndim``."""
    try:
        raw = np.asarray(x)
        if np.iscomplexobj(raw) and not np.issubdtype(np.dtype(dtype), np.complexfloating):
            if np.any(raw.imag != 0):
                raise InputError(
                    f"{name}: expected real values, got complex numbers "
                    f"({int(np.count_nonzero(raw.imag))} with a non-zero imaginary part)"
                )
            raw = raw.real
        arr = np.asarray(raw, dtype=dtype)
    except InputError:
        raise
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{name}: expected numbers, got {type(x).__name__} ({exc})") from None
    if ndim is not None and arr.ndim != ndim:
        raise ShapeError(f"{name}: expected a {ndim}-D array, got shape {arr.shape}")
    if not allow_empty and arr.size == 0:
        raise ShapeError(f"{name}: expected a non-empty array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise InputError(f"{name}: expected finite values, got {bad} NaN or infinite entries")
    return arr


def as_band(band: Any, name: str = "band", *, positive: bool = False) -> tuple[float, float]:
    """A frequency band ``(f_lo, f_hi)`` in Hz: two finite numbers, ``0 <= f_lo < f_hi``.

    One rule for every band of the package: frequencies are not negative and
    a band has width. ``positive=True`` also demands ``f_lo > 0``, for the
    uses that space frequencies logarithmically or divide by them.

    Raises
    ------
    InputError
        Not two numbers, not finite, ``f_lo < 0`` (``<= 0`` with
        ``positive``) or ``f_hi <= f_lo``; the message names ``name``.
    """
    rule = "0 < f_lo < f_hi" if positive else "0 <= f_lo < f_hi"
    # the command-line option of the same name, for a message a CLI user reads
    name = "band (--band)" if name == "band" else name
    try:
        if isinstance(band, str) or len(band) != 2:
            raise TypeError
        lo, hi = float(band[0]), float(band[1])
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected (f_lo, f_hi) in Hz with {rule}, got {band!r}") from None
    ok = np.isfinite(lo) and np.isfinite(hi) and (lo > 0 if positive else lo >= 0) and hi > lo
    if not ok:
        raise InputError(f"{name}: expected (f_lo, f_hi) in Hz with {rule}, got {band!r}")
    return lo, hi


def as_frequency(f: ArrayLike, name: str = "frequency") -> NDArray[np.float64]:
    """Return a 1-D, finite, non-negative, strictly increasing frequency axis in Hz."""
    arr = as_finite(f, name, ndim=1)
    if np.any(arr < 0):
        raise InputError(f"{name}: expected non-negative values in Hz, got minimum {arr.min():g}")
    if arr.size > 1 and np.any(np.diff(arr) <= 0):
        i = int(np.argmax(np.diff(arr) <= 0))
        raise InputError(
            f"{name}: expected strictly increasing values, "
            f"got {arr[i]:g} followed by {arr[i + 1]:g} at index {i + 1}"
        )
    return arr


def as_square_symmetric(
    a: ArrayLike, name: str, *, n: int | None = None, rtol: float = 1e-8
) -> NDArray[np.float64]:
    """Return a real, finite, square, symmetric matrix (symmetrised exactly)."""
    arr = as_finite(a, name, ndim=2)
    if arr.shape[0] != arr.shape[1]:
        raise ShapeError(f"{name}: expected a square matrix, got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ShapeError(f"{name}: expected shape ({n}, {n}), got {arr.shape}")
    scale = float(np.max(np.abs(arr))) if arr.size else 0.0
    asym = float(np.max(np.abs(arr - arr.T))) if arr.size else 0.0
    if asym > rtol * max(scale, np.finfo(float).tiny):
        raise PhysicsError(
            f"{name}: expected a symmetric matrix, got max |A - A^T| = {asym:.3g} "
            f"(max |A| = {scale:.3g})"
        )
    return 0.5 * (arr + arr.T)


def _min_eig(a: NDArray[np.float64]) -> tuple[float, float]:
    w = np.linalg.eigvalsh(a)
    return float(w[0]), float(np.max(np.abs(w))) if w.size else 0.0


def check_positive_definite(a: NDArray[np.float64], name: str) -> None:
    """Raise :class:`PhysicsError` unless symmetric ``a`` is positive definite."""
    try:
        np.linalg.cholesky(a)
    except np.linalg.LinAlgError:
        lo, _ = _min_eig(a)
        raise PhysicsError(
            f"{name}: expected a positive definite matrix, got smallest eigenvalue {lo:.3g}"
        ) from None


def check_positive_semidefinite(a: NDArray[np.float64], name: str, *, rtol: float = 1e-10) -> None:
    """Raise :class:`PhysicsError` unless symmetric ``a`` is positive semi-definite."""
    lo, hi = _min_eig(a)
    if lo < -rtol * max(hi, np.finfo(float).tiny):
        raise PhysicsError(
            f"{name}: expected a positive semi-definite matrix, got smallest eigenvalue {lo:.3g}"
        )


def check_positive(value: float, name: str, *, allow_zero: bool = False) -> float:
    """Return ``float(value)`` if finite and > 0 (or >= 0); else raise :class:`PhysicsError`."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number, got {value!r}") from None
    if not np.isfinite(v):
        raise InputError(f"{name}: expected a finite number, got {v}")
    if v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise PhysicsError(f"{name}: expected a value {bound}, got {v:g}")
    return v


def as_count(value: Any, name: str, minimum: int = 0) -> int:
    """``int(value)`` for an integer (not a bool) ``>= minimum``; else :class:`InputError`."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return int(value)
