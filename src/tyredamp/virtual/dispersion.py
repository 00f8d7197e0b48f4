"""The continuous ring tyre and the staggered difference: dispersion relations.

The natural frequencies of each circumferential wave number ``n`` of the
inflated ring on an elastic foundation: the inextensible formula of the spec
(:func:`analytic_ring_frequencies`) and the 2x2 eigenproblem of the extensible
ring (:func:`ring_dispersion`), continuous or with ``n`` replaced by the symbol
of the staggered difference on ``n_ring`` nodes (:func:`staggered_weights`,
:func:`difference_symbol`), which the discrete ring
(:class:`~tyredamp.virtual.ring.RingTyre`) reproduces exactly for its
axisymmetric modes. The energy they come from, its derivation and the
discretisation are stated in the module docstring of :mod:`tyredamp.virtual.ring`.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError
from .parameters import RingTyreParameters

__all__ = [
    "analytic_ring_frequencies",
    "difference_symbol",
    "ring_dispersion",
    "staggered_weights",
]

FDOrder = Literal[2, 4, 6]
_ORDERS = (2, 4, 6)


# ----------------------------------------------------------------- analytic
def analytic_ring_frequencies(params: RingTyreParameters, n: ArrayLike) -> NDArray[np.float64]:
    """Natural frequencies of the inextensible inflated ring on an elastic foundation.

    ``omega_n^2 = [EI n^2 (n^2-1)^2/R^4 + T0 n^2 (n^2-1)/R^2 + k_r n^2 + k_t]
    / [rho A (1 + n^2)]`` (spec ``virtual-tyre.md``; derivation in the module
    docstring of :mod:`tyredamp.virtual.ring`). ``n = 0`` is the rigid rotation
    of the band on the sidewalls (``k_t / rho A``); ``n = 1`` is the translation
    ``(k_r + k_t)/(2 rho A)``. Each ``n >= 1`` is a double mode (cos and sin).

    Parameters
    ----------
    params : RingTyreParameters
    n : array_like of int, shape (k,)
        Circumferential wave numbers, >= 0.

    Returns
    -------
    ndarray, shape (k,)
        Natural frequencies in Hz.
    """
    nn = _wave_number_array(n)
    return _inextensible_hz(params, nn)


def _inextensible_hz(params: RingTyreParameters, s: NDArray[np.float64]) -> NDArray[np.float64]:
    r = params.radius
    s2 = s**2
    num = (
        params.bending_stiffness * s2 * (s2 - 1) ** 2 / r**4
        + params.hoop_tension * s2 * (s2 - 1) / r**2
        + params.radial_stiffness * s2
        + params.tangential_stiffness
    )
    w2 = num / (params.mass_per_length * (1 + s2))
    return np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)


def _wave_number_array(n: ArrayLike) -> NDArray[np.float64]:
    arr = as_finite(n, "n", dtype=float)
    arr = np.atleast_1d(arr)
    if np.any(arr < 0) or np.any(arr != np.round(arr)):
        raise InputError(f"n: expected integer wave numbers >= 0, got {arr.tolist()}")
    return arr


def staggered_weights(order: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Offsets and weights of the central staggered first difference of ``order``.

    ``f'(x) ~ (1/h) sum_k a_k [f(x + o_k h) - f(x - o_k h)]`` with
    ``o_k = k - 1/2``; order 2: ``a = [1]``, order 4: ``[9/8, -1/24]``,
    order 6: ``[75/64, -25/384, 3/640]``.

    Parameters
    ----------
    order : {2, 4, 6}

    Returns
    -------
    offsets, weights : ndarray, shape (order/2,)
    """
    if order not in _ORDERS:
        raise InputError(f"fd_order: expected one of {_ORDERS}, got {order!r}")
    m = order // 2
    off = np.arange(1, m + 1) - 0.5
    # Taylor matching: sum_k 2 a_k o_k^(2l+1) = delta_l0, l = 0..m-1
    a = np.array([[2 * o ** (2 * ell + 1) for o in off] for ell in range(m)])
    rhs = np.zeros(m)
    rhs[0] = 1.0
    return off.astype(np.float64), np.linalg.solve(a, rhs).astype(np.float64)


def difference_symbol(n: ArrayLike, n_ring: int | None, order: int = 4) -> NDArray[np.float64]:
    """Effective wave number ``s(n)`` of the staggered difference on ``n_ring`` nodes.

    ``s(n) = (2/h) sum_k a_k sin(o_k n h)``, ``h = 2 pi / n_ring``; the discrete
    derivative of ``sin(n theta)`` is ``s(n) cos(n theta)``. ``n_ring=None``
    returns ``n`` itself (the continuous ring).

    Parameters
    ----------
    n : array_like, shape (k,)
        Wave numbers.
    n_ring : int or None
        Number of ring nodes.
    order : {2, 4, 6}
        Order of the difference.

    Returns
    -------
    ndarray, shape (k,)
    """
    nn = np.atleast_1d(np.asarray(n, dtype=float))
    if n_ring is None:
        return nn
    off, a = staggered_weights(order)
    h = 2 * np.pi / n_ring
    return (2.0 / h) * np.sum(a[:, None] * np.sin(off[:, None] * nn[None, :] * h), axis=0)


def ring_dispersion(
    params: RingTyreParameters,
    n: ArrayLike,
    *,
    n_ring: int | None = None,
    fd_order: int = 6,
    extensible: bool = True,
    branch: Literal["flexural", "extensional"] = "flexural",
) -> NDArray[np.float64]:
    """Frequencies of wave number ``n`` of the extensible ring, continuous or discretised.

    Solves the 2x2 eigenproblem of the energy in the module docstring of
    :mod:`tyredamp.virtual.ring` for
    ``w = a cos n theta``, ``v = c sin n theta``:

    ``q_aa = (EA + T0)/R^2 + EI s^4/R^4 + T0 (s^2 - 1)/R^2 + k_r``,
    ``q_ac = (EA + T0) s/R^2 + EI s^3/R^4``,
    ``q_cc = (EA + T0) s^2/R^2 + EI s^2/R^4 + k_t``,
    ``omega^2 = eig(Q) / rho A``,

    with ``s = n`` for the continuous ring and ``s = s(n)``
    (:func:`difference_symbol`) for the staggered discretisation on
    ``n_ring`` nodes, whose axisymmetric modes it reproduces exactly. With
    ``extensible=False`` the inextensible formula is evaluated at ``s``.

    Parameters
    ----------
    params : RingTyreParameters
    n : array_like of int, shape (k,)
        Wave numbers >= 0 (for a discrete ring below ``n_ring / 2``).
    n_ring : int, optional
        Number of ring nodes; ``None`` for the continuous ring.
    fd_order : {2, 4, 6}
        Order of the staggered differences.
    extensible : bool
        Finite ``EA`` (True) or the inextensible limit.
    branch : {"flexural", "extensional"}
        Lower (bending) or upper (membrane) root; for ``n = 0`` the lower is
        the rotation and the upper the breathing mode.

    Returns
    -------
    ndarray, shape (k,)
        Frequencies in Hz.
    """
    nn = _wave_number_array(n)
    if n_ring is not None and np.any(nn >= n_ring / 2):
        raise InputError(f"n: expected wave numbers below n_ring/2 = {n_ring / 2:g}")
    s = difference_symbol(nn, n_ring, fd_order)
    if not extensible:
        if branch != "flexural":
            raise InputError("branch: the inextensible ring has only the flexural branch")
        return _inextensible_hz(params, s)
    r = params.radius
    ea, ei, t0 = params.membrane_stiffness, params.bending_stiffness, params.hoop_tension
    qaa = (ea + t0) / r**2 + ei * s**4 / r**4 + t0 * (s**2 - 1) / r**2 + params.radial_stiffness
    qac = (ea + t0) * s / r**2 + ei * s**3 / r**4
    qcc = (ea + t0) * s**2 / r**2 + ei * s**2 / r**4 + params.tangential_stiffness
    tr = qaa + qcc
    det = qaa * qcc - qac**2
    disc = np.sqrt(np.clip((qaa - qcc) ** 2 + 4 * qac**2, 0.0, None))
    hi = 0.5 * (tr + disc)
    if branch == "flexural":
        lo = det / hi  # stable smaller root
        w2 = lo
    elif branch == "extensional":
        w2 = hi
    else:
        raise InputError(f"branch: expected 'flexural' or 'extensional', got {branch!r}")
    return np.sqrt(np.clip(w2, 0.0, None) / params.mass_per_length) / (2 * np.pi)
