"""Spatial harmonics sampled at the measured angles: resolution, aliasing, single-harmonic fit.

On ``J`` equally spaced points, ``cos(n theta)`` and ``sin(n theta)`` sample
to the same vectors (up to the sign of the sine) as those of ``|k J +- n|``:
the points resolve both members of every ``n < J/2`` (16 points: ``n <= 7``);
at ``n = J/2`` only the cosine member is seen. For arbitrary angles the same
is decided numerically: wave numbers ``m`` whose sampled two-dimensional
subspace equals that of ``n`` (projector difference below ``1e-8``) are its
aliases (:func:`alias_candidates`), and the resolved range is the set of
``n`` whose columns are linearly independent of all lower ones
(:func:`resolved_wave_numbers`). :func:`harmonic_fit` fits one harmonic
``a cos n theta + b sin n theta`` to a shape by weighted least squares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError

__all__ = [
    "HarmonicFit",
    "alias_candidates",
    "as_angles",
    "harmonic_fit",
    "resolved_wave_numbers",
]

_ALIAS_TOL = 1e-8


def _columns(theta: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """Sampled ``[cos n theta, sin n theta]`` (only the non-vanishing ones)."""
    if n == 0:
        return np.ones((theta.size, 1))
    c = np.cos(n * theta)
    s = np.sin(n * theta)
    cols = [c]
    if np.linalg.norm(s) > 1e-9 * math.sqrt(theta.size):
        cols.append(s)
    return np.column_stack(cols)


def _projector(a: NDArray[np.float64]) -> NDArray[np.float64]:
    q, r = np.linalg.qr(a)
    keep = np.abs(np.diag(r)) > 1e-9 * max(1.0, float(np.abs(r).max()))
    q = q[:, keep]
    return np.asarray(q @ q.T, dtype=np.float64)


def as_angles(angles_deg: ArrayLike) -> NDArray[np.float64]:
    a = as_finite(angles_deg, "angles_deg", ndim=1)
    if a.size < 3:
        raise InputError(
            f"the points' angles around the tyre: expected at least 3 measured points, got {a.size}"
        )
    wrapped = np.mod(a, 360.0)
    d = np.abs(wrapped[:, None] - wrapped[None, :])
    d = np.minimum(d, 360.0 - d)
    np.fill_diagonal(d, np.inf)
    if np.any(d < 1e-9):
        raise InputError(
            "the points' angles around the tyre: two response points are at the same angle; "
            "expected distinct points"
        )
    return np.deg2rad(a)


def resolved_wave_numbers(angles_deg: ArrayLike) -> tuple[int, bool]:
    """Largest wave number whose cos and sin members the angles resolve.

    ``n`` is resolved when the sampled columns ``1, cos theta, sin theta, ...,
    cos n theta, sin n theta`` are linearly independent (full column rank).

    Parameters
    ----------
    angles_deg : array_like, shape (J,)
        Measured angles in deg.

    Returns
    -------
    n_max : int
        Largest fully resolved wave number (``J`` equal points: ``ceil(J/2) - 1``;
        16 points: 7).
    cos_only_next : bool
        Whether the cosine member of ``n_max + 1`` is still independent (the
        Nyquist wave number ``J/2`` of an even number of equal points).
    """
    th = as_angles(angles_deg)
    cols = [np.ones(th.size)]
    n = 0
    while True:
        m = n + 1
        trial = np.column_stack([*cols, np.cos(m * th), np.sin(m * th)])
        if trial.shape[1] > th.size or np.linalg.matrix_rank(trial, tol=1e-8) < trial.shape[1]:
            cos_only = np.column_stack([*cols, np.cos(m * th)])
            ok = cos_only.shape[1] <= th.size and (
                np.linalg.matrix_rank(cos_only, tol=1e-8) == cos_only.shape[1]
            )
            return n, bool(ok)
        cols += [np.cos(m * th), np.sin(m * th)]
        n = m


def alias_candidates(angles_deg: ArrayLike, n: int, n_limit: int) -> list[int]:
    """Wave numbers ``m <= n_limit`` (``m != n``) that the angles cannot tell from ``n``.

    ``m`` aliases ``n`` when its sampled cos/sin columns span the same space
    as those of ``n`` (equal orthogonal projectors, tolerance 1e-8); on ``J``
    equal points these are ``|k J +- n|``.

    Parameters
    ----------
    angles_deg : array_like, shape (J,)
    n : int
        Wave number (>= 0).
    n_limit : int
        Largest wave number considered.

    Returns
    -------
    list of int
        Ascending.
    """
    if n < 0 or n_limit < 0:
        raise InputError(f"n, n_limit: expected integers >= 0, got {n}, {n_limit}")
    th = as_angles(angles_deg)
    p_n = _projector(_columns(th, n))
    out = []
    for m in range(n_limit + 1):
        if m == n:
            continue
        if np.linalg.norm(_projector(_columns(th, m)) - p_n) < _ALIAS_TOL * th.size:
            out.append(m)
    return out


@dataclass(frozen=True)
class HarmonicFit:
    """Single-harmonic fit of one shape (see :func:`harmonic_fit`).

    Attributes
    ----------
    n : int
        Wave number fitted.
    coefficients : ndarray, complex, shape (2,)
        ``a``, ``b`` of ``a cos n theta + b sin n theta`` (``b = 0`` for ``n = 0``).
    fraction : float
        Energy fraction explained, ``1 - ||r||_W^2 / ||x||_W^2`` in [0, 1].
    chi2 : float or None
        ``2 sum |r_j|^2 / sigma_j^2`` (with standard errors).
    dof : int
        ``2 (J - k)``.
    covariance : ndarray, shape (k, k)
        ``(A^T W A)^-1`` of the coefficients (complex variance; units of x^2
        when unweighted with unit weights).
    """

    n: int
    coefficients: NDArray[np.complex128]
    fraction: float
    chi2: float | None
    dof: int
    covariance: NDArray[np.float64]


def harmonic_fit(
    theta: NDArray[np.float64],
    x: NDArray[np.complex128],
    n: int,
    sigma: NDArray[np.float64] | None = None,
) -> HarmonicFit:
    """Weighted least-squares fit of ``a cos n theta + b sin n theta`` to ``x``.

    Parameters
    ----------
    theta : ndarray, shape (J,)
        Angles in rad.
    x : ndarray, complex, shape (J,)
        Shape values.
    n : int
        Wave number.
    sigma : ndarray, shape (J,), optional
        Standard errors ``sqrt(E|dx|^2)``; unit weights when absent.
    """
    a = _columns(theta, n)
    w = np.ones(theta.size) if sigma is None else 1.0 / np.asarray(sigma, float)
    aw = a * w[:, None]
    xw = x * w
    coef, *_ = np.linalg.lstsq(aw, xw, rcond=None)
    r = xw - aw @ coef
    tot = float(np.vdot(xw, xw).real)
    res = float(np.vdot(r, r).real)
    frac = 1.0 - res / tot if tot > 0 else 0.0
    cov = np.linalg.pinv(aw.T @ aw)
    full = np.zeros(2, dtype=complex)
    full[: coef.size] = coef
    if a.shape[1] == 1 and n > 0:
        cov = np.diag([cov[0, 0], 0.0])
    return HarmonicFit(
        n=n,
        coefficients=full,
        fraction=float(np.clip(frac, 0.0, 1.0)),
        chi2=None if sigma is None else 2.0 * res,
        dof=2 * (theta.size - a.shape[1]),
        covariance=np.asarray(cov, dtype=float),
    )
