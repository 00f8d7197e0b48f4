"""Output half-spectra and the poly-reference LSCF estimator on them.

The positive power spectrum (half-spectrum) is the Fourier transform of the
positive-lag correlations,

    S+(omega) = w_0 R_0 / 2 + sum_{i>=1} w_i R_i e^{-i omega i dt},

with an exponential window ``w_i = exp(-beta i)`` (Peeters & Van der
Auweraer, "PolyMAX: a revision of operational modal analysis", IOMAC 2005,
eq. 3-4; Cauberghe, PhD thesis VUB 2004, sec. 3.4). It has the modal form
``sum_k phi_k g_k^T / (i omega - lambda_k) + c.c.`` of an FRF, so the pLSCF
pole estimator of :mod:`tyredamp.modal.poles.lscf` applies unchanged; the window adds
``beta f_s`` to every decay rate, which is subtracted from the poles
(``lambda = lambda_w + beta f_s``). The shapes follow from a linear
least-squares fit of the residues at the selected poles (the LSFD step).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..modal.poles.lscf import plscf
from .ssi import OrderPoles, _normalised

__all__ = ["half_spectra", "plscf_poles", "residue_shapes"]


def half_spectra(
    R: NDArray[np.float64], sample_rate: float, window_end: float = 0.01
) -> tuple[NDArray[np.float64], NDArray[np.complex128], float]:
    """Half-spectra of the correlations.

    Parameters
    ----------
    R : ndarray, shape (n_lags, n_out, n_ref)
    sample_rate : float
        Hz.
    window_end : float
        Value of the exponential window at the last lag.

    Returns
    -------
    frequency : ndarray, shape (n_lags + 1,)
        0 .. f_s / 2 in Hz.
    S : ndarray, complex, shape (n_out, n_ref, n_freq)
    beta : float
        Window decay per lag (the added decay rate is ``beta f_s`` in 1/s).
    """
    L = R.shape[0]
    beta = -np.log(window_end) / (L - 1)
    w = np.exp(-beta * np.arange(L))
    r = R * w[:, None, None]
    r[0] *= 0.5
    n = 2 * L
    S = np.fft.rfft(r, n, axis=0)  # e^{-i omega i dt} convention of numpy
    f = np.asarray(np.fft.rfftfreq(n, 1 / sample_rate), dtype=np.float64)
    return f, np.ascontiguousarray(S.transpose(1, 2, 0)), float(beta)


def plscf_poles(
    R: NDArray[np.float64],
    sample_rate: float,
    band: tuple[float, float],
    max_order: int,
) -> tuple[OrderPoles, tuple[NDArray[np.float64], NDArray[np.complex128]]]:
    """pLSCF poles of every order ``1..max_order`` from the half-spectra.

    Returns the poles (window decay removed) with the participation vectors as
    the "shapes" the stabilisation compares, and ``(frequency, S)`` in the band.
    """
    f, S, beta = half_spectra(R, sample_rate)
    sel = (f >= band[0]) & (f <= band[1])
    ps = plscf(f[sel], S[:, :, sel], max_order)
    poles = ps.poles + beta * sample_rate
    part = ps.participation
    op = OrderPoles(ps.order, poles, _normalised(part.T).T, ps.orders)
    return op, (f[sel], S[:, :, sel])


def residue_shapes(
    frequency: NDArray[np.float64],
    S: NDArray[np.complex128],
    poles: NDArray[np.complex128],
    beta_rate: float,
) -> NDArray[np.complex128]:
    """Mode shapes (m, n_out) from the residues of the half-spectra at ``poles``.

    ``S_jr(omega) = sum_k [A_jrk / (i omega - mu_k) + B_jrk / (i omega - mu_k^*)] + U_jr``
    with ``mu_k = lambda_k - beta_rate`` the windowed poles, solved by linear least
    squares per (j, r); each mode's shape is the residue column of the reference
    where it is largest (a rank-one residue ``phi_k g_k^T``).
    """
    mu = poles - beta_rate
    s = 2j * np.pi * frequency
    basis = np.concatenate(
        [
            1 / (s[:, None] - mu[None, :]),
            1 / (s[:, None] - np.conj(mu)[None, :]),
            np.ones((s.size, 1)),
        ],
        axis=1,
    )
    n_out, n_ref, _ = S.shape
    rhs = S.reshape(n_out * n_ref, -1).T
    coef, *_ = np.linalg.lstsq(basis, rhs, rcond=None)
    A = coef[: mu.size].T.reshape(n_out, n_ref, mu.size)
    r = np.argmax(np.sum(np.abs(A) ** 2, axis=0), axis=0)
    shapes = np.asarray(A[:, r, np.arange(mu.size)], dtype=np.complex128)
    return _normalised(shapes).T
