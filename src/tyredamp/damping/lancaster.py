"""Lancaster's exact M, C, K from a complete set of complex modes.

With the eq. [10] scaling the receptance is
``H(s) = sum_n R_n / (s - p_n) + conj(R_n) / (s - conj(p_n))``, ``R_n = psi_n psi_n^T``.
Expanding ``H(s) = (M s^2 + C s + K)^-1`` for large ``|s|``,
``H = M^-1 / s^2 - M^-1 C M^-1 / s^3 + O(s^-4)``, and comparing with the
expansion of the modal sum, ``sum_n p_n^k R_n / s^(k+1) + c.c.``, gives

* ``sum_n R_n + c.c. = 0``,
* ``sum_n p_n R_n + c.c. = M^-1``,
* ``sum_n p_n^2 R_n + c.c. = -M^-1 C M^-1``, so ``C = -M (sum p^2 R + c.c.) M``,

and at ``s = 0``, ``H(0) = K^-1 = -sum_n R_n / p_n + c.c.``. These hold only
when all ``N`` mode pairs of the ``N``-DOF system are present (the modal sums
of a truncated set have rank ``2m < 2N``), so this is a cross-check for complete
modal data, not a replacement for the truncated-mode methods.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError, PhysicsError, ShapeError

__all__ = ["LancasterMatrices", "lancaster_matrices"]


@dataclass(frozen=True)
class LancasterMatrices:
    """Exact ``M``, ``C``, ``K`` from complete complex modes, and the identity check.

    Attributes
    ----------
    M, C, K : ndarray, shape (N, N)
        kg, N s/m, N/m (for shapes in 1/sqrt(kg s^-1)).
    zero_sum : float
        ``||sum R + c.c.|| / ||sum p R + c.c.|| * max|p|``: zero for an exact,
        complete set (the identity ``sum R + c.c. = 0``), dimensionless.
    """

    M: NDArray[np.float64]
    C: NDArray[np.float64]
    K: NDArray[np.float64]
    zero_sum: float


def lancaster_matrices(poles: ArrayLike, psi: ArrayLike) -> LancasterMatrices:
    """``M``, ``C``, ``K`` of an ``N``-DOF system from all its ``N`` complex modes.

    Parameters
    ----------
    poles : array_like, complex, shape (N,)
        One pole of each pair, rad/s.
    psi : array_like, complex, shape (N, N)
        Mode shapes at all ``N`` DOFs in the eq. [10] scaling
        (``psi_n = Psi_n / sqrt(a_n)``), 1/sqrt(kg s^-1).

    Returns
    -------
    LancasterMatrices

    Raises
    ------
    ShapeError
        If the modal set is not complete (``psi`` not square).
    PhysicsError
        If ``sum p R + c.c.`` (``M^-1``) or ``-sum R / p + c.c.`` (``K^-1``) is
        singular.
    """
    p = as_finite(poles, "poles", ndim=1, dtype=complex)
    s = as_finite(psi, "psi", ndim=2, dtype=complex)
    if s.shape != (p.size, p.size):
        raise ShapeError(
            "psi: Lancaster's formulas need the complete modal set (as many modes as "
            f"points, shape ({p.size}, {p.size})), got {s.shape}"
        )
    if np.any(p == 0):
        raise InputError("poles: expected non-zero poles")

    def msum(weight: NDArray[Any]) -> NDArray[np.complex128]:
        r = (s * weight) @ s.T
        return r + np.conj(r)

    s0 = msum(np.ones(p.shape, dtype=complex))
    s1 = msum(p)
    s2 = msum(p**2)
    sk = -msum(1.0 / p)
    scale = max(float(np.linalg.norm(s1)), 1e-300)
    try:
        m_mat = np.asarray(np.linalg.inv(s1.real), dtype=float)
        k_mat = np.asarray(np.linalg.inv(sk.real), dtype=float)
    except np.linalg.LinAlgError:
        raise PhysicsError(
            "lancaster_matrices: sum p R (M^-1) or sum R/p (K^-1) is singular; the modes are "
            "not a complete independent set"
        ) from None
    c_mat = -m_mat @ s2.real @ m_mat
    return LancasterMatrices(
        M=m_mat,
        C=c_mat,
        K=k_mat,
        zero_sum=float(np.linalg.norm(s0) * np.max(np.abs(p)) / scale),
    )
