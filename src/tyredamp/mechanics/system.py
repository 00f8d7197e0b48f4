"""Linear MCK systems: undamped and complex modes, FRFs (spec eq. [1]-[10], [14]).

``M x'' + C x' + K x = f`` with symmetric ``M`` (positive definite), ``C``
and ``K`` (positive semi-definite), eq. [1].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .._validate import (
    as_frequency,
    as_square_symmetric,
    check_positive_definite,
    check_positive_semidefinite,
)
from ..exceptions import InputError, PhysicsError
from ..frf import FRF, Channel, FRFKind
from .modal_sum import kind_factor, modal_sum_receptance, pole_quantities

__all__ = ["ComplexModes", "MCKSystem", "UndampedModes"]

#: Memory budget (bytes) for one batch of dynamic-stiffness matrices.
_BATCH_BYTES = 64 * 2**20


@dataclass(frozen=True)
class UndampedModes:
    """Mass-normalised real modes of ``(K - omega^2 M) phi = 0``.

    Attributes
    ----------
    omega : ndarray, shape (n,)
        Undamped natural frequencies in rad/s, ascending.
    phi : ndarray, shape (n_dof, n)
        Mode shapes with ``phi^T M phi = I`` (units 1/sqrt(kg)).
    """

    omega: NDArray[np.float64]
    phi: NDArray[np.float64]

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Natural frequencies in Hz."""
        return self.omega / (2 * np.pi)


@dataclass(frozen=True)
class ComplexModes:
    """Complex modes of a viscously damped system (spec eq. [5]-[10]).

    One member of each conjugate pair is kept (``Im p_n > 0``), sorted by
    ``Im p_n``.

    Attributes
    ----------
    poles : ndarray, complex, shape (m,)
        ``p_n = -sigma_n + i Omega_n`` in rad/s.
    Psi : ndarray, complex, shape (n_dof, m)
        Displacement eigenvectors (eq. [6]) with the complex mass
        normalisation ``Psi_n^T M Psi_n = 1`` (plain transpose), largest real
        entry positive. For proportional damping ``Psi_n = phi_n`` and
        ``a_n = 2 i Omega_n``.
    a, b : ndarray, complex, shape (m,)
        Normalisation constants of eq. [8] for ``Psi``.
    psi : ndarray, complex, shape (n_dof, m)
        ``psi_n = Psi_n / sqrt(a_n)`` (eq. [10]), in 1/sqrt(kg s^-1).
    """

    poles: NDArray[np.complex128]
    Psi: NDArray[np.complex128]
    a: NDArray[np.complex128]
    b: NDArray[np.complex128]
    psi: NDArray[np.complex128]

    @property
    def omega_n(self) -> NDArray[np.float64]:
        """Undamped natural frequency ``|p_n|`` in rad/s."""
        return np.abs(self.poles)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Natural frequency ``|p_n| / 2 pi`` in Hz."""
        return pole_quantities(self.poles)[0]

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta_n = -Re p_n / |p_n|``."""
        return pole_quantities(self.poles)[1]

    def frf(
        self,
        frequency: ArrayLike,
        kind: FRFKind = "receptance",
        outputs: Sequence[int] | NDArray[np.integer[Any]] | None = None,
        inputs: Sequence[int] | NDArray[np.integer[Any]] | None = None,
    ) -> NDArray[np.complex128]:
        """FRF matrix by the modal sum [10], shape (n_out, n_in, n_freq)."""
        f = as_frequency(frequency)
        oi = _dofs(outputs, self.psi.shape[0], "outputs")
        ii = _dofs(inputs, self.psi.shape[0], "inputs")
        h = modal_sum_receptance(f, self.poles, self.psi[oi], self.psi[ii])
        return h * kind_factor(2 * np.pi * f, kind)


def _dofs(
    idx: Sequence[int] | NDArray[np.integer[Any]] | None, n: int, name: str
) -> NDArray[np.intp]:
    if idx is None:
        return np.arange(n)
    arr = np.atleast_1d(np.asarray(idx))
    if arr.size == 0 or arr.dtype.kind not in "iu":
        raise InputError(f"{name}: expected a non-empty list of DOF indices, got {idx!r}")
    if np.any(arr < 0) or np.any(arr >= n):
        raise InputError(f"{name}: DOF indices must lie in 0..{n - 1}, got {arr.tolist()}")
    return arr.astype(np.intp)


class MCKSystem:
    """A linear viscously damped system ``M x'' + C x' + K x = f`` (eq. [1]).

    Parameters
    ----------
    M : array_like, shape (n, n)
        Mass matrix in kg, symmetric positive definite.
    C : array_like, shape (n, n)
        Viscous damping matrix in N s/m, symmetric positive semi-definite.
    K : array_like, shape (n, n)
        Stiffness matrix in N/m, symmetric positive semi-definite.
    """

    def __init__(self, M: ArrayLike, C: ArrayLike, K: ArrayLike) -> None:
        m = as_square_symmetric(M, "M")
        n = m.shape[0]
        c = as_square_symmetric(C, "C", n=n)
        k = as_square_symmetric(K, "K", n=n)
        check_positive_definite(m, "M")
        check_positive_semidefinite(k, "K")
        check_positive_semidefinite(c, "C")
        for arr in (m, c, k):
            arr.setflags(write=False)
        self.M, self.C, self.K = m, c, k
        self._undamped: UndampedModes | None = None
        self._complex: ComplexModes | None = None

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom."""
        return int(self.M.shape[0])

    def __repr__(self) -> str:
        return f"MCKSystem(n_dof={self.n_dof})"

    def with_damping(self, C: ArrayLike) -> MCKSystem:
        """Same mass and stiffness, another damping matrix."""
        return MCKSystem(self.M, C, self.K)

    # ------------------------------------------------------------------ modes
    def undamped_modes(self) -> UndampedModes:
        """Mass-normalised real modes (``phi^T M phi = I``), ascending frequency."""
        if self._undamped is None:
            lam, phi = sla.eigh(self.K, self.M)
            lam = np.clip(lam, 0.0, None)
            # fix the sign: largest-magnitude entry positive (reproducible shapes)
            idx = np.argmax(np.abs(phi), axis=0)
            sign = np.sign(phi[idx, np.arange(phi.shape[1])])
            sign[sign == 0] = 1.0
            self._undamped = UndampedModes(omega=np.sqrt(lam), phi=phi * sign)
        return self._undamped

    def modal_damping(self) -> NDArray[np.float64]:
        """Damping in undamped modal coordinates ``C' = Phi^T C Phi`` (eq. [14])."""
        phi = self.undamped_modes().phi
        return phi.T @ self.C @ phi

    def is_proportional(self, rtol: float = 1e-9) -> bool:
        """True when ``C'`` is diagonal (Caughey condition ``C M^-1 K`` symmetric)."""
        cp = self.modal_damping()
        off = cp - np.diag(np.diag(cp))
        return bool(np.max(np.abs(off)) <= rtol * max(np.max(np.abs(cp)), 1e-300))

    def complex_modes(self) -> ComplexModes:
        """State-space complex modes of eq. [4]-[9], normalised for eq. [10].

        Solves the first-order eigenproblem of eq. [4]-[5] through the state
        matrix ``[[-M^-1 C, -M^-1 K], [I, 0]]``, keeps the eigenvalue with
        ``Im p > 0`` of each pair and the displacement part ``Psi_n`` of
        ``Theta_n = [p_n Psi_n; Psi_n]`` (eq. [6]), and computes ``a_n``,
        ``b_n`` (eq. [8]) and ``psi_n = Psi_n / sqrt(a_n)``.

        Raises
        ------
        PhysicsError
            If a mode is overdamped or a rigid-body mode exists (real poles),
            where the conjugate-pair form [10] does not apply.
        """
        if self._complex is not None:
            return self._complex
        n = self.n_dof
        lu = sla.cho_factor(self.M)
        minv_c = sla.cho_solve(lu, self.C)
        minv_k = sla.cho_solve(lu, self.K)
        a_state = np.block([[-minv_c, -minv_k], [np.eye(n), np.zeros((n, n))]])
        lam, vec = sla.eig(a_state)
        scale = np.max(np.abs(lam)) if lam.size else 1.0
        upper = lam.imag > 1e-10 * scale
        n_upper = int(np.count_nonzero(upper))
        if n_upper != n:
            raise PhysicsError(
                f"complex_modes: {n - n_upper} of {n} modes have real poles (overdamped or "
                "rigid-body); the conjugate-pair modal form of eq. [10] needs underdamped modes"
            )
        p = lam[upper]
        Psi = vec[n:, upper]
        order = np.argsort(p.imag)
        p, Psi = p[order], Psi[:, order]
        # complex mass normalisation Psi^T M Psi = 1 (plain transpose): Psi reduces
        # to the mass-normalised phi_n for proportional damping, where a_n = 2 i Omega_n
        Psi = Psi / np.sqrt(np.einsum("in,ij,jn->n", Psi, self.M, Psi))
        idx = np.argmax(np.abs(Psi.real), axis=0)
        sign = np.sign(Psi.real[idx, np.arange(n)])
        sign[sign == 0] = 1.0
        Psi = Psi * sign
        a, b = normalisation_constants(self.M, self.C, self.K, p, Psi)
        psi = Psi / np.sqrt(a)
        self._complex = ComplexModes(poles=p, Psi=Psi, a=a, b=b, psi=psi)
        return self._complex

    # ------------------------------------------------------------------- FRFs
    def frf(
        self,
        frequency: ArrayLike,
        kind: FRFKind = "receptance",
        outputs: Sequence[int] | None = None,
        inputs: Sequence[int] | None = None,
        method: str = "direct",
        output_channels: Sequence[Channel] | None = None,
        input_channels: Sequence[Channel] | None = None,
    ) -> FRF:
        """FRF matrix at the chosen DOFs.

        Parameters
        ----------
        frequency : array_like, shape (n_freq,)
            Frequency in Hz.
        kind : {"receptance", "mobility", "accelerance"}
            Which FRF to return.
        outputs, inputs : sequence of int, optional
            DOF indices (0-based) of responses and forces; default all DOFs.
        method : {"direct", "modal"}
            ``"direct"`` solves ``(K - omega^2 M + i omega C) X = F`` at each
            line; ``"modal"`` sums the complex modes (eq. [10]).
        output_channels, input_channels : sequence of Channel, optional
            Labels for the result; default nodes numbered by DOF index + 1.

        Returns
        -------
        FRF
            Shape (n_out, n_in, n_freq).
        """
        f = as_frequency(frequency)
        oi = _dofs(outputs, self.n_dof, "outputs")
        ii = _dofs(inputs, self.n_dof, "inputs")
        if method == "direct":
            h = self.receptance_direct(f, oi, ii)
        elif method == "modal":
            h = self.complex_modes().frf(f, "receptance", oi, ii)
        else:
            raise InputError(f"method: expected 'direct' or 'modal', got {method!r}")
        h = h * kind_factor(2 * np.pi * f, kind)
        oc = output_channels or [Channel(node=int(i) + 1) for i in oi]
        ic = input_channels or [Channel(node=int(i) + 1) for i in ii]
        return FRF(f, h, kind=kind, outputs=oc, inputs=ic)

    def receptance_direct(
        self,
        frequency: ArrayLike,
        outputs: Sequence[int] | NDArray[np.integer[Any]] | None = None,
        inputs: Sequence[int] | NDArray[np.integer[Any]] | None = None,
    ) -> NDArray[np.complex128]:
        """Receptance ``(K - w^2 M + i w C)^-1`` at the DOFs, shape (n_out, n_in, n_freq)."""
        f = as_frequency(frequency)
        oi = _dofs(outputs, self.n_dof, "outputs")
        ii = _dofs(inputs, self.n_dof, "inputs")
        n = self.n_dof
        w = 2 * np.pi * f
        rhs = np.zeros((n, ii.size), dtype=complex)
        rhs[ii, np.arange(ii.size)] = 1.0
        out = np.empty((oi.size, ii.size, f.size), dtype=complex)
        batch = max(1, int(_BATCH_BYTES // (16 * n * n)))
        for start in range(0, f.size, batch):
            ww = w[start : start + batch]
            d = (
                self.K[None, :, :]
                - (ww**2)[:, None, None] * self.M[None, :, :]
                + 1j * ww[:, None, None] * self.C[None, :, :]
            )
            try:
                x = np.linalg.solve(d, np.broadcast_to(rhs, (ww.size, n, ii.size)))
            except np.linalg.LinAlgError:
                raise PhysicsError(
                    "frf: the dynamic stiffness is singular at a line (undamped resonance "
                    "or rigid-body mode at 0 Hz); add damping or move the line"
                ) from None
            out[:, :, start : start + batch] = np.moveaxis(x[:, oi, :], 0, -1)
        return out


def normalisation_constants(
    M: NDArray[np.float64],
    C: NDArray[np.float64],
    K: NDArray[np.float64],
    poles: NDArray[np.complex128],
    Psi: NDArray[np.complex128],
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """``a_n`` and ``b_n`` of eq. [8] for displacement eigenvectors ``Psi`` (columns).

    ``a_n = Psi_n^T C Psi_n + 2 p_n Psi_n^T M Psi_n``,
    ``b_n = Psi_n^T K Psi_n - p_n^2 Psi_n^T M Psi_n`` (plain transpose, not
    Hermitian); for an exact eigenpair ``p_n = -b_n / a_n`` (eq. [9]).
    """
    mm = np.einsum("in,ij,jn->n", Psi, M, Psi)
    cc = np.einsum("in,ij,jn->n", Psi, C, Psi)
    kk = np.einsum("in,ij,jn->n", Psi, K, Psi)
    return cc + 2 * poles * mm, kk - poles**2 * mm
