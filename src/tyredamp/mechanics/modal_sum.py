"""FRF synthesis from poles and mode shapes (spec eq. [2], [3], [10]).

These functions are shared by the mechanics core (exact modes of an MCK
system) and the modal identification (fitted modes).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, as_frequency
from ..exceptions import InputError, ShapeError
from ..frf import KIND_POWER, KINDS, FRFKind

__all__ = ["kind_factor", "modal_sum_receptance", "pole_from_frequency_damping", "pole_quantities"]


def kind_factor(omega: NDArray[np.float64], kind: FRFKind) -> NDArray[np.complex128]:
    """``(i omega)^k`` that turns a receptance into ``kind`` (k = 0, 1, 2)."""
    if kind not in KINDS:
        raise InputError(f"kind: expected one of {KINDS}, got {kind!r}")
    return (1j * np.asarray(omega, dtype=float)) ** KIND_POWER[kind]


def pole_quantities(poles: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Natural frequency and damping ratio of poles; inverse of :func:`pole_from_frequency_damping`.

    ``f_n = |p_n| / 2 pi`` (Hz) and ``zeta_n = -Re p_n / |p_n|`` (spec eq. [3]/[5]).

    Parameters
    ----------
    poles : array_like, complex, any shape
        Poles in rad/s (one per conjugate pair), ``p != 0``.

    Returns
    -------
    frequency_hz, damping_ratio : ndarray, the shape of ``poles``
    """
    p = np.asarray(poles, dtype=complex)
    mag = np.abs(p)
    return mag / (2 * np.pi), -p.real / mag


def pole_from_frequency_damping(f_n: ArrayLike, zeta: ArrayLike) -> NDArray[np.complex128]:
    """Poles ``p_n = -zeta_n omega_n + i omega_n sqrt(1 - zeta_n^2)`` (spec eq. [3]).

    Parameters
    ----------
    f_n : array_like
        Undamped natural frequencies in Hz (``omega_n = 2 pi f_n``).
    zeta : array_like
        Damping ratios, in [0, 1).
    """
    f = as_finite(f_n, "f_n")
    z = as_finite(zeta, "zeta")
    if np.any(f <= 0):
        raise InputError("f_n: expected natural frequencies > 0 Hz")
    if np.any(z < 0) or np.any(z >= 1):
        raise InputError("zeta: expected damping ratios in [0, 1) (underdamped modes)")
    w = 2 * np.pi * f
    return -z * w + 1j * w * np.sqrt(1 - z**2)


def modal_sum_receptance(
    frequency: ArrayLike,
    poles: ArrayLike,
    psi_out: ArrayLike,
    psi_in: ArrayLike,
) -> NDArray[np.complex128]:
    """Receptance by the complex modal sum of spec eq. [10].

    ``H_jk(s) = sum_n psi_jn psi_kn / (s - p_n) + conj(psi_jn psi_kn) / (s - conj(p_n))``
    with ``s = i omega``.

    Parameters
    ----------
    frequency : array_like, shape (n_freq,)
        Frequency in Hz.
    poles : array_like, complex, shape (n_modes,)
        One pole of each conjugate pair (rad/s), usually with Im > 0.
    psi_out : array_like, complex, shape (n_out, n_modes)
        Mode shapes at the outputs, scaled as in [10] (``psi = Psi / sqrt(a)``).
    psi_in : array_like, complex, shape (n_in, n_modes)
        Mode shapes at the inputs, same scaling.

    Returns
    -------
    ndarray, complex, shape (n_out, n_in, n_freq)
        Receptance in the units implied by the mode shapes (m/N for SI
        systems).
    """
    f = as_frequency(frequency)
    p = as_finite(poles, "poles", ndim=1, dtype=complex)
    po = as_finite(psi_out, "psi_out", ndim=2, dtype=complex)
    pi = as_finite(psi_in, "psi_in", ndim=2, dtype=complex)
    if po.shape[1] != p.size or pi.shape[1] != p.size:
        raise ShapeError(
            f"psi_out/psi_in: expected {p.size} mode columns to match poles, "
            f"got {po.shape} and {pi.shape}"
        )
    s = 2j * np.pi * f
    g = 1.0 / (s[None, :] - p[:, None])  # (n_modes, n_freq)
    gc = 1.0 / (s[None, :] - np.conj(p)[:, None])
    # residues R[j, k, n] = psi_jn psi_kn, summed over modes with the pole terms
    h = np.einsum("jn,kn,nf->jkf", po, pi, g, optimize=True)
    h += np.einsum("jn,kn,nf->jkf", np.conj(po), np.conj(pi), gc, optimize=True)
    return h
