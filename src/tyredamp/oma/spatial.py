"""Wave-number channels of equally spaced fixed sensors around a rolling tyre.

With ``K`` sensors at ``theta_k = theta_0 + 2 pi k / K`` the spatial DFT
``q_n(t) = sum_k y_k(t) e^{-i n theta_k}`` keeps, of a shape
``psi(theta) = a e^{i n theta} + b e^{-i n theta}`` (the spatial Fourier
series of a ring mode, Huang & Soedel, J. Sound Vib. 118(2) (1987) 253-270,
eq. 21), only the wave number ``n`` (and its aliases ``K -+ n``). For a pole
``lambda`` of the real records ``y = psi e^{lambda t} + c.c.``,
``q_n = K (a e^{lambda t} + conj(b) e^{conj(lambda) t})``, so the real pair
``(Re q_n, Im q_n)`` is a 2-channel output-only problem whose mode shape
``(u, v)`` gives back ``a = (u + i v) / K`` and ``b = (u - i v) / K`` (the
travelling-wave split of rolling-tyre measurements in Kindt, Sas & Desmet,
J. Sound Vib. 320 (2009) 1049-1068, sec. 3). Identifying each ``n`` apart
keeps waves of other wave numbers out of its poles.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "equally_spaced",
    "spatial_channels",
    "spatial_spectra",
    "travelling_channels",
]


def equally_spaced(angles_deg: ArrayLike, tol_deg: float = 0.5) -> bool:
    """Whether ``K >= 3`` angles (deg) sit every ``360 / K`` degrees, within ``tol_deg``."""
    th = np.sort(np.mod(np.asarray(angles_deg, float).ravel(), 360.0))
    if th.size < 3:
        return False
    gaps = np.diff(np.append(th, th[0] + 360.0))
    return bool(np.all(np.abs(gaps - 360.0 / th.size) <= tol_deg))


def spatial_channels(y: ArrayLike, angles_deg: ArrayLike, wave_number: int) -> NDArray[np.float64]:
    """The real pair ``(Re q_n, Im q_n)`` of ``q_n = sum_k y_k e^{-i n theta_k}``.

    Parameters
    ----------
    y : array_like, shape (K, n_samples)
        Records of the fixed sensors (one motion unit).
    angles_deg : array_like, shape (K,)
        Sensor angles in degrees (direction of ``+theta``).
    wave_number : int
        ``n >= 1``.

    Returns
    -------
    ndarray, shape (2, n_samples)
        Same unit as ``y``.
    """
    Y = np.asarray(y, float)
    th = np.deg2rad(np.asarray(angles_deg, float).ravel())
    q = np.exp(-1j * wave_number * th) @ Y
    return np.stack([q.real, q.imag])


def travelling_channels(
    y: ArrayLike, angles_deg: ArrayLike, wave_number: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The backward and the forward wave of wave number ``n``, each as a real pair.

    In ``q_n = K (a e^{lambda t} + conj(b) e^{conj(lambda') t})`` the backward
    wave ``a`` has only positive and the forward wave ``b`` only negative
    frequencies (Kindt, Sas & Desmet 2009, sec. 3: the sign of the spatial
    order tells the direction). Masking the spectrum of ``q_n`` to ``f > 0``
    gives ``p = K a e^{lambda t}``, to ``f < 0`` gives ``m``, and ``conj(m) =
    K b e^{lambda' t}``; each is returned as ``(Re, Im)``, a 2-channel record
    holding one wave even when both share one frequency. The DC and Nyquist
    bins are shared half and half.

    Parameters
    ----------
    y : array_like, shape (K, n_samples)
    angles_deg : array_like, shape (K,)
    wave_number : int

    Returns
    -------
    backward, forward : ndarray, shape (2, n_samples)
    """
    re, im = spatial_channels(y, angles_deg, wave_number)
    Q = np.fft.fft(re + 1j * im)
    N = Q.size
    w = np.zeros(N)
    w[1 : (N + 1) // 2] = 1.0
    w[0] = 0.5
    if N % 2 == 0:
        w[N // 2] = 0.5
    p = np.fft.ifft(Q * w)
    m = np.conj(np.fft.ifft(Q * w[(-np.arange(N)) % N]))
    return np.stack([p.real, p.imag]), np.stack([m.real, m.imag])


def spatial_spectra(
    y: ArrayLike, sample_rate: float, angles_deg: ArrayLike, nperseg: int = 1024
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Power spectra of every wave-number channel, backward (``f > 0``) and forward.

    Parameters
    ----------
    y : array_like, shape (K, n_samples)
    sample_rate : float
        Hz.
    angles_deg : array_like, shape (K,)
    nperseg : int
        Welch segment length (samples).

    Returns
    -------
    f : ndarray, shape (m,)
        Hz, ``0 .. sample_rate / 2``.
    S : ndarray, shape (2, n_hi + 1, m)
        ``S[0, n]`` the two-sided PSD of ``q_n`` at ``+f`` (backward waves),
        ``S[1, n]`` at ``-f`` (forward waves), unit of ``y`` squared per Hz.
    """
    from scipy.signal import welch

    Y = np.asarray(y, float)
    K = Y.shape[0]
    n_hi = (K - 1) // 2
    q = np.stack([re + 1j * im for re, im in
                  (spatial_channels(Y, angles_deg, n) for n in range(n_hi + 1))])  # fmt: skip
    seg = min(nperseg, Y.shape[1])
    f2, P = welch(q, fs=sample_rate, nperseg=seg, return_onesided=False, axis=-1)
    m = seg // 2 + 1
    f = np.abs(f2[:m])
    pos = P[:, :m]
    neg = P[:, (-np.arange(m)) % seg]
    return f, np.stack([pos, neg]).real
