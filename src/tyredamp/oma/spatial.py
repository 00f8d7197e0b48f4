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
    "nyquist_wave_number",
    "peak_contrast",
    "peak_test_has_power",
    "power_threshold",
    "spatial_channels",
    "spatial_spectra",
    "travelling_channels",
    "wave_shape",
    "welch_dof",
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
    S : ndarray, shape (2, K // 2 + 1, m)
        ``S[0, n]`` the two-sided PSD of ``q_n`` at ``+f`` (backward waves),
        ``S[1, n]`` at ``-f`` (forward waves), unit of ``y`` squared per Hz.
        For ``n = 0`` and, with ``K`` even, the Nyquist wave number ``K / 2``
        (:func:`nyquist_wave_number`) ``q_n`` is a real record times a
        constant phase, so both rows hold the same spectrum.
    """
    from scipy.signal import welch

    Y = np.asarray(y, float)
    K = Y.shape[0]
    n_hi = K // 2
    q = np.stack([re + 1j * im for re, im in
                  (spatial_channels(Y, angles_deg, n) for n in range(n_hi + 1))])  # fmt: skip
    seg = min(nperseg, Y.shape[1])
    f2, P = welch(q, fs=sample_rate, nperseg=seg, return_onesided=False, axis=-1)
    m = seg // 2 + 1
    f = np.abs(f2[:m])
    pos = P[:, :m]
    neg = P[:, (-np.arange(m)) % seg]
    return f, np.stack([pos, neg]).real


def nyquist_wave_number(n_sensors: int) -> int | None:
    """The wave number whose two directions equally spaced sensors cannot tell apart.

    At ``theta_k = theta_0 + 2 pi k / K`` the two travelling waves
    ``e^{+-i n theta_k}`` of ``n = K / 2`` (``K`` even) are both
    ``e^{+-i n theta_0} (-1)^k``: one real pattern, the spatial Nyquist
    frequency of the sampling of the circumference (the spatial form of the
    sampling theorem; Kindt, Sas & Desmet, J. Sound Vib. 320 (2009)
    1049-1068, sec. 3, on the wave numbers a ring of sensors resolves). Its
    channel ``sum_k (-1)^k y_k`` holds both waves of ``n = K / 2`` (and the
    aliases ``K / 2 + m K``) at their fixed-frame frequencies, without their
    direction.

    Parameters
    ----------
    n_sensors : int
        ``K``.

    Returns
    -------
    int or None
        ``K // 2`` for even ``K >= 2``, ``None`` for odd ``K`` (every wave
        number up to ``(K - 1) / 2`` keeps its direction, and ``K / 2`` is
        not an integer).
    """
    K = int(n_sensors)
    return K // 2 if K >= 2 and K % 2 == 0 else None


def welch_dof(n_samples: int, nperseg: int) -> float:
    """Equivalent degrees of freedom of a Welch PSD with a Hann window and 50 % overlap.

    ``nu = 2 M / (1 + 2 rho^2)`` for ``M`` segments whose neighbours overlap
    by half: Welch's variance of averaged overlapping periodograms (Welch, IEEE
    Trans. Audio Electroacoust. 15(2) (1967) 70-73), ``var = S^2 / M (1 + 2
    (1 - 1/M) c^2)``, with ``c = 0.167`` the overlap correlation of the Hann
    window at 50 % (Harris, Proc. IEEE 66(1) (1978) 51-83, table I); segments
    further apart do not overlap, and ``nu = 2 S^2 / var``. For ``M = 1``:
    ``nu = 2``. The tests check it against the scatter of simulated white noise.

    Parameters
    ----------
    n_samples : int
        Record length (samples).
    nperseg : int
        Segment length (samples).

    Returns
    -------
    float
    """
    seg = min(int(nperseg), int(n_samples))
    M = max(1, (int(n_samples) - seg) // (seg // 2) + 1)
    return 2.0 * M / (1.0 + 2.0 * (1.0 - 1.0 / M) * 0.167**2)


def power_threshold(dof: float, alpha: float = 1e-3) -> float:
    """The ratio two PSD estimates of one level exceed with probability ``alpha``.

    Each Welch estimate is ``S chi2_nu / nu`` (Bendat & Piersol, Random Data,
    4th ed. 2010, sec. 8.5: the chi-square law of smoothed spectral estimates),
    so the ratio of two independent ones is ``F(nu, nu)``; this is its
    ``1 - alpha`` quantile.

    Parameters
    ----------
    dof : float
        ``nu`` of both estimates (:func:`welch_dof`).
    alpha : float
        Probability that noise alone passes.

    Returns
    -------
    float
    """
    from scipy.stats import f as f_dist

    return float(f_dist.ppf(1.0 - alpha, dof, dof))


def peak_test_has_power(dof: float, alpha: float = 1e-3, miss: float = 0.01) -> bool:
    """Whether an isolated resonance passes the flank test of the channel spectra.

    A resonance alone rises five times above its flanks at ``f -+ 2 zeta f``
    (:func:`peak_contrast`); two Welch estimates with ``nu`` degrees of
    freedom each scatter by ``chi2_nu / nu`` (Bendat & Piersol 2010, sec.
    8.5), so its estimated contrast is about ``5 F`` with ``F ~ F(nu, nu)``.
    The test keeps a pole whose contrast exceeds the ``1 - alpha`` quantile of
    ``F(nu, nu)`` (:func:`power_threshold`, what noise alone passes with
    probability ``alpha``); this says whether a resonance passes it with
    probability at least ``1 - miss``: ``5 F_miss(nu, nu) >= F_{1-alpha}(nu, nu)``.
    Short records (few averages) fail it: their spectra cannot tell a
    resonance from noise at that confidence.

    Parameters
    ----------
    dof : float
        ``nu`` (:func:`welch_dof`).
    alpha, miss : float
        False-pass probability for noise and miss probability for a resonance.

    Returns
    -------
    bool
    """
    from scipy.stats import f as f_dist

    return bool(5.0 * f_dist.ppf(miss, dof, dof) >= power_threshold(dof, alpha))


def peak_contrast(s: ArrayLike, f_axis: ArrayLike, f: float, zeta: float) -> float:
    """How far a spectrum rises at a pole above its flanks.

    The largest value of ``s`` within the half-power band ``f -+ zeta f`` (at
    least the nearest bin and one either side) over the larger of the two
    values at ``f -+ 2 zeta f`` (at least 3 bins away: beyond the Hann main
    lobe). A resonance of damping ``zeta`` alone gives about 5 there: the
    single-mode response ``1 / ((1 - r^2)^2 + (2 zeta r)^2)`` of a white
    excitation is ``1 / (4 zeta^2)`` at ``r = 1`` and ``1 / (20 zeta^2)`` at
    ``r = 1 -+ 2 zeta`` to first order in ``zeta`` (the frequency response of
    one mode, Ewins, Modal Testing, 2nd ed. 2000, sec. 2.2); the skirt of a
    stronger neighbour rises towards one flank and gives less than 1.

    Parameters
    ----------
    s : array_like, shape (m,)
        PSD on ``f_axis``.
    f_axis : array_like, shape (m,)
        Hz, equally spaced.
    f, zeta : float
        The pole's natural frequency (Hz) and damping ratio.

    Returns
    -------
    float
        ``0`` when a flank falls outside ``f_axis``.
    """
    S = np.asarray(s, float)
    fa = np.asarray(f_axis, float)
    df = fa[1] - fa[0]
    k = round((f - fa[0]) / df)
    half = max(1, round(abs(zeta) * f / df))
    off = max(3, round(2 * abs(zeta) * f / df))
    if k - off < 0 or k + off >= S.size:
        return 0.0
    top = float(np.max(S[k - half : k + half + 1]))
    flank = float(max(S[k - off], S[k + off]))
    return top / flank if flank > 0 else float("inf")


def wave_shape(wave_number: int, direction: str, angles_deg: ArrayLike) -> NDArray[np.complex128]:
    """Unit shape at the sensor angles of one travelling wave of a wave-number channel.

    In ``psi(theta) = a e^{i n theta} + b e^{-i n theta}`` (module docstring,
    Huang & Soedel 1987, eq. 21) the backward wave is ``a`` and the forward wave
    ``b``, so a backward wave has the shape ``e^{i n theta_k}``, a forward one
    ``e^{-i n theta_k}`` and ``n = 0`` ones.

    Parameters
    ----------
    wave_number : int
    direction : {"backward", "forward", "standing"}
        As a fixed observer sees it.
    angles_deg : array_like, shape (K,)

    Returns
    -------
    ndarray of complex, shape (K,)
    """
    th = np.deg2rad(np.asarray(angles_deg, float).ravel())
    s = -1.0 if direction == "forward" else 1.0
    return np.exp(1j * s * wave_number * th)
