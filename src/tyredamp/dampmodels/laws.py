"""Damping laws: the damping part ``Z(s)`` of the dynamic stiffness.

Every law here is linear and written in the Laplace variable ``s`` (rad/s,
time dependence ``e^{st}``) as the damping part of the dynamic stiffness

``D(s) = s^2 M + K + Z(s)``,  ``H(s) = D(s)^-1``  (receptance),

after Adhikari & Woodhouse, "Identification of damping: part 2, non-viscous
damping", J. Sound Vib. 243(1) (2001) 63-88, eq. (1)-(3), where
``Z(s) = s G(s)`` and ``G(s)`` is the Laplace transform of the matrix of
kernel functions. The laws:

``viscous``
    ``Z(s) = s C`` (A-W part 1, eq. (1)).
``hysteretic``
    ``Z(s) = i D sign(Im s)``: a complex stiffness ``K + i D`` with a
    frequency-independent loss (``D = eta K`` for one loss factor ``eta``;
    Woodhouse, J. Sound Vib. 215(3) (1998) 547-569, sec. 2). Not causal:
    its impulse response starts before the impulse, so it is a
    frequency-domain model only.
``exponential``
    ``Z(s) = s sum_k C_k mu_k / (s + mu_k)`` (A-W part 2, eq. (4)): relaxation
    kernels ``C_k mu_k e^{-mu_k t}``; ``mu -> infinity`` is viscous ``sum C_k``.
``fractional``
    ``Z(s) = C s^alpha`` on the principal branch, ``0 < alpha < 2``
    (Bagley & Torvik, AIAA J. 21(5) (1983) 741-748, eq. (1)); ``alpha = 1`` is
    viscous, ``alpha -> 0`` a stiffness.

Each law also gives ``dZ/ds``, which the exact modes need (residue
normalisation ``x^T D'(p) x = 1``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError, PhysicsError, ShapeError

__all__ = [
    "LAWS",
    "DampingLaw",
    "Exponential",
    "Fractional",
    "Hysteretic",
    "Viscous",
]


def _square(a: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.array(as_finite(a, name, dtype=float), dtype=float)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        raise ShapeError(f"{name}: expected a square matrix, got shape {arr.shape}")
    arr.setflags(write=False)
    return arr


class DampingLaw(ABC):
    """A linear damping law: ``Z(s)`` and ``dZ/ds`` (module docstring)."""

    name: ClassVar[str]
    #: True when the law has a time-domain (causal, finite-state) realisation.
    causal: ClassVar[bool] = True

    @property
    @abstractmethod
    def n_dof(self) -> int:
        """Size of the matrices."""

    @abstractmethod
    def term(self, s: complex) -> NDArray[np.complex128]:
        """``Z(s)``, shape (n, n), in N/m."""

    @abstractmethod
    def dterm(self, s: complex) -> NDArray[np.complex128]:
        """``dZ/ds``, shape (n, n), in N s/m."""

    @abstractmethod
    def parameters(self) -> dict[str, object]:
        """Plain parameters (for documents)."""

    def loss_matrix(self, omega: float) -> NDArray[np.float64]:
        """``Im Z(i omega)``, the dissipative part at ``omega > 0`` rad/s, in N/m."""
        return np.asarray(self.term(1j * omega).imag, dtype=float)


@dataclass(frozen=True)
class Viscous(DampingLaw):
    """``Z(s) = s C`` (A-W part 1, eq. (1)).

    Parameters
    ----------
    C : array_like, shape (n, n)
        Damping matrix in N s/m.
    """

    C: NDArray[np.float64]
    name: ClassVar[str] = "viscous"

    def __post_init__(self) -> None:
        object.__setattr__(self, "C", _square(self.C, "C"))

    @property
    def n_dof(self) -> int:
        return int(self.C.shape[0])

    def term(self, s: complex) -> NDArray[np.complex128]:
        return s * self.C.astype(complex)

    def dterm(self, s: complex) -> NDArray[np.complex128]:
        return self.C.astype(complex)

    def parameters(self) -> dict[str, object]:
        return {"C": self.C.tolist()}


@dataclass(frozen=True)
class Hysteretic(DampingLaw):
    """``Z(s) = i D sign(Im s)``: complex stiffness ``K + i D`` (Woodhouse 1998, sec. 2).

    Parameters
    ----------
    D : array_like, shape (n, n)
        Loss stiffness in N/m (``eta K`` for a constant loss factor ``eta``).

    Notes
    -----
    Non-causal: ``(K + i D - omega^2 M)^-1`` for ``omega > 0`` continued to
    negative frequencies by conjugation has poles at ``p`` and ``-p``, one
    of each pair in the right half plane, so there is no time-domain
    simulation of it; it defines frequency-domain data only.
    """

    D: NDArray[np.float64]
    name: ClassVar[str] = "hysteretic"
    causal: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "D", _square(self.D, "D"))

    @classmethod
    def loss_factor(cls, K: ArrayLike, eta: float) -> Hysteretic:
        """The constant-loss-factor law ``D = eta K``."""
        if not eta >= 0:
            raise PhysicsError(f"eta: expected a loss factor >= 0, got {eta}")
        return cls(eta * _square(K, "K"))

    @property
    def n_dof(self) -> int:
        return int(self.D.shape[0])

    def term(self, s: complex) -> NDArray[np.complex128]:
        sign = 1.0 if complex(s).imag >= 0 else -1.0
        return 1j * sign * self.D.astype(complex)

    def dterm(self, s: complex) -> NDArray[np.complex128]:
        return np.zeros(self.D.shape, dtype=complex)

    def parameters(self) -> dict[str, object]:
        return {"D": self.D.tolist()}


@dataclass(frozen=True)
class Exponential(DampingLaw):
    """``Z(s) = s sum_k C_k mu_k/(s + mu_k)`` (A-W part 2, eq. (4)).

    Parameters
    ----------
    C : array_like, shape (n_k, n, n) or (n, n)
        Damping coefficient matrices ``C_k`` in N s/m (the viscous limit is
        ``sum_k C_k``).
    mu : array_like, shape (n_k,)
        Relaxation parameters ``mu_k > 0`` in 1/s (time constants ``1/mu_k``).
    """

    C: NDArray[np.float64]
    mu: NDArray[np.float64]
    name: ClassVar[str] = "exponential"

    def __post_init__(self) -> None:
        c = np.array(as_finite(self.C, "C", dtype=float), dtype=float)
        if c.ndim == 2:
            c = c[None]
        mu = np.atleast_1d(np.array(as_finite(self.mu, "mu", dtype=float), dtype=float))
        if c.ndim != 3 or c.shape[1] != c.shape[2] or c.shape[0] != mu.size:
            raise ShapeError(
                f"C: expected shape (n_k, n, n) with n_k = {mu.size} (one per mu), got {c.shape}"
            )
        if np.any(mu <= 0):
            raise PhysicsError(f"mu: expected relaxation parameters > 0 (1/s), got {mu}")
        c.setflags(write=False)
        mu.setflags(write=False)
        object.__setattr__(self, "C", c)
        object.__setattr__(self, "mu", mu)

    @property
    def n_dof(self) -> int:
        return int(self.C.shape[1])

    def term(self, s: complex) -> NDArray[np.complex128]:
        w = s * self.mu / (s + self.mu)
        return np.asarray(np.tensordot(w, self.C, axes=1), dtype=complex)

    def dterm(self, s: complex) -> NDArray[np.complex128]:
        w = self.mu**2 / (s + self.mu) ** 2
        return np.asarray(np.tensordot(w, self.C, axes=1), dtype=complex)

    def parameters(self) -> dict[str, object]:
        return {"C": self.C.tolist(), "mu": self.mu.tolist()}


@dataclass(frozen=True)
class Fractional(DampingLaw):
    """``Z(s) = C s^alpha`` on the principal branch (Bagley & Torvik 1983, eq. (1)).

    Parameters
    ----------
    C : array_like, shape (n, n)
        Coefficient matrix in N s^alpha/m.
    alpha : float
        Order of the derivative, ``0 < alpha < 2``; 1 is viscous.
    """

    C: NDArray[np.float64]
    alpha: float
    name: ClassVar[str] = "fractional"

    def __post_init__(self) -> None:
        object.__setattr__(self, "C", _square(self.C, "C"))
        a = float(self.alpha)
        if not 0 < a < 2:
            raise InputError(f"alpha: expected a derivative order in (0, 2), got {self.alpha}")
        object.__setattr__(self, "alpha", a)

    @property
    def n_dof(self) -> int:
        return int(self.C.shape[0])

    def term(self, s: complex) -> NDArray[np.complex128]:
        return complex(s) ** self.alpha * self.C.astype(complex)

    def dterm(self, s: complex) -> NDArray[np.complex128]:
        return self.alpha * complex(s) ** (self.alpha - 1) * self.C.astype(complex)

    def parameters(self) -> dict[str, object]:
        return {"C": self.C.tolist(), "alpha": self.alpha}


#: The laws by name.
LAWS: dict[str, type[DampingLaw]] = {
    cls.name: cls for cls in (Viscous, Hysteretic, Exponential, Fractional)
}
