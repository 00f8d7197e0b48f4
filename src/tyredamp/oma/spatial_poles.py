"""The wave-number route of rolling OMA: each wave number's channel identified apart.

With fixed sensors equally spaced around the circumference, the spatial DFT
splits their records into one channel per wave number ``n`` and direction of
travel in space (:mod:`.spatial`); :func:`spatial_poles` identifies each channel
on its own (:func:`~tyredamp.oma.identify.oma`) and records, for each pole, the
power of its channel and of the opposite direction over the median of all
channels and how far the channel's spectrum rises at the pole;
:func:`select_spatial_poles` keeps the poles that sensor noise alone would pass
with probability at most ``ALPHA`` per test. The kept poles become waves of the
rolling tyre in :func:`~tyredamp.oma.rolling.rolling_modes`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .identify import DeferredErrors, oma_deferred
from .spatial import (
    nyquist_wave_number,
    peak_contrast,
    power_threshold,
    spatial_spectra,
    travelling_channels,
    welch_dof,
)

__all__ = [
    "ALPHA",
    "CHANNEL_ORDER",
    "SpatialPole",
    "select_spatial_poles",
    "spatial_poles",
    "spatial_route",
]


ALPHA = 1e-3
"""Probability that sensor noise alone passes each test of :func:`select_spatial_poles`."""

SEGMENT = 1024
"""Welch segment (samples) of the channel spectra the selection tests use."""

CHANNEL_ORDER = 40
"""Largest SSI model order of one wave-number channel (unless given).

A channel of one wave number and direction holds, in the band, only the
waves of ``n`` and its aliases ``K -+ n`` travelling that way: a few poles,
where the record of all sensors holds every wave of the band. Forty states
(twenty poles) leave room for the noise poles a stabilisation diagram needs
to tell the physical ones apart; ``benchmarks/README.md`` compares 30, 40,
60 and 80 on the virtual tyre.
"""

CHANNEL_BLOCK_ROWS = CHANNEL_ORDER // 2 + 2
"""SSI block rows of one wave-number channel (unless given): about the fewest
whose Toeplitz matrix holds :data:`CHANNEL_ORDER` (``2 (i - 1) >= 40`` for the
channel's two outputs, Peeters & De Roeck 1999, eq. 16-18). Longer lags add
more of the correlation estimate's noise than information about a channel's
few waves: on the virtual tyre 100 block rows (the default of
:func:`~.identify.oma` for a band from 0 Hz) gave larger frequency errors
and jackknife errors 1.6 times their actual scatter; 22 gave the most waves
within 0.5 % and 10 % and intervals that cover about as they should
(``benchmarks/README.md``: 22, 25, 30, 50, 100).
"""


@dataclass(frozen=True)
class SpatialPole:
    """One pole of one wave-number channel, before the selection.

    Attributes
    ----------
    wave_number : int
    direction : str
        As a fixed observer sees it: ``"backward"``, ``"forward"`` or ``"standing"``.
    frequency_hz, damping_ratio, std_frequency_hz, std_damping_ratio : float
        As identified from the channel's 2-channel record (Hz; NaN without errors).
    ratio, other : float
        Power of this channel and of the opposite direction at the pole's
        frequency over the median of all channels there.
    contrast : float
        How far the channel's spectrum rises at the pole above its flanks
        (:func:`~tyredamp.oma.spatial.peak_contrast`).
    orders : int
        Model orders the pole persisted over in its channel's stabilisation.
    """

    wave_number: int
    direction: str
    frequency_hz: float
    damping_ratio: float
    std_frequency_hz: float
    std_damping_ratio: float
    ratio: float
    other: float
    contrast: float
    orders: int


def _channel_poles(
    y: Any, fs: float, angles: list[float], kw: dict[str, Any]
) -> tuple[list[SpatialPole], dict[int, tuple[DeferredErrors, int]], float, float]:
    """Every pole of every channel without standard errors, with what computes
    them (keyed by ``id`` of the pole), the spectra's bin (Hz) and dof."""
    out: list[SpatialPole] = []
    later: dict[int, tuple[DeferredErrors, int]] = {}
    K = len(angles)
    nperseg = SEGMENT
    fs_, S = spatial_spectra(y, fs, angles, nperseg)
    nyq = nyquist_wave_number(K)
    real = {0} | ({nyq} if nyq is not None else set())
    rows = [S[c, n] for n in range(S.shape[1]) for c in (0, 1) if c == 0 or n not in real]
    floor = np.median(np.stack(rows), axis=0)  # one row per independent channel
    opts = {k: v for k, v in kw.items() if k != "uncertainty"}
    opts.setdefault("max_order", CHANNEL_ORDER)
    if opts["max_order"] is None:
        opts["max_order"] = CHANNEL_ORDER
    if opts.get("block_rows") is None:
        opts["block_rows"] = CHANNEL_BLOCK_ROWS
    for n in range(0, K // 2 + 1):
        if n in real:  # one real channel: the standing pattern at the sensors
            parts = [("standing", oma_deferred(travelling_channels(y, angles, n)[0], fs, **opts))]
        else:
            bwd, fwd = travelling_channels(y, angles, n)
            parts = [("backward", oma_deferred(bwd, fs, **opts)),
                     ("forward", oma_deferred(fwd, fs, **opts))]  # fmt: skip
        for d, (r, err) in parts:
            c = int(d == "forward")
            for j in range(r.n_modes):
                f, z = float(r.frequency_hz[j]), float(r.damping_ratio[j])
                k = int(np.argmin(np.abs(fs_ - f)))
                ratio = float(S[c, n, k] / floor[k])
                other = float(S[1 - c, n, k] / floor[k]) if n not in real else ratio
                p = SpatialPole(n, d, f, z, np.nan, np.nan, ratio, other,
                                peak_contrast(S[c, n], fs_, f, z), int(r.n_orders[j]))  # fmt: skip
                out.append(p)
                later[id(p)] = (err, j)
    return out, later, float(fs_[1] - fs_[0]), welch_dof(np.shape(y)[-1], nperseg)


def _with_errors(
    poles: list[SpatialPole], later: dict[int, tuple[DeferredErrors, int]]
) -> list[SpatialPole]:
    """The poles with their jackknife standard errors, one jackknife per channel."""
    groups: dict[int, tuple[DeferredErrors, list[int], list[int]]] = {}
    for i, p in enumerate(poles):
        err, j = later[id(p)]
        groups.setdefault(id(err), (err, [], []))[1].append(j)
        groups[id(err)][2].append(i)
    out = list(poles)
    for err, modes, where in groups.values():
        sf, sz = err.std(modes)
        for i, a, b in zip(where, sf.tolist(), sz.tolist(), strict=True):
            out[i] = replace(poles[i], std_frequency_hz=a, std_damping_ratio=b)
    return out


def spatial_poles(
    y: Any, fs: float, angles: list[float], kw: dict[str, Any]
) -> tuple[list[SpatialPole], float, float]:
    """Every pole of each wave-number channel ``n = 0 .. K // 2``, the
    backward and forward wave of each ``n >= 1`` identified apart (:mod:`.spatial`),
    except the Nyquist wave number ``K / 2`` of an even ``K``, whose one real
    channel gives ``"standing"`` poles (:func:`.spatial.nyquist_wave_number`;
    :mod:`.nyquist` resolves their direction where it can).

    Parameters
    ----------
    y : array_like, shape (K, n_samples)
        The fixed sensors, equally spaced.
    fs : float
        Hz.
    angles : list of float
        Their angles, deg.
    kw : dict
        Options of :func:`~tyredamp.oma.identify.oma` (``max_order`` defaults
        to :data:`CHANNEL_ORDER`); with ``uncertainty`` every pole gets its
        jackknife errors (:func:`spatial_route` computes them for the kept
        poles only).

    Returns
    -------
    poles : list of SpatialPole
    resolution : float
        Hz, the bin of the channel spectra.
    dof : float
        Degrees of freedom of each bin of those spectra (:func:`.spatial.welch_dof`).
    """
    poles, later, res, dof = _channel_poles(y, fs, angles, kw)
    if kw.get("uncertainty", True):
        poles = _with_errors(poles, later)
    return poles, res, dof


def spatial_route(
    y: Any, fs: float, angles: list[float], kw: dict[str, Any], band: tuple[float, float]
) -> tuple[list[SpatialPole], list[str]]:
    """The waves of the wave-number route: the poles of every channel
    (:func:`spatial_poles`), those taken for waves (:func:`select_spatial_poles`),
    and, with ``kw["uncertainty"]``, their jackknife errors, computed for the
    kept poles only.

    A kept pole whose frequency scatters over the jackknife segments by more
    than ten times ``sqrt(zeta f / T)`` is left out, as :func:`~.identify.oma`
    does: the random error of the frequency of a resonance of half-power
    half-bandwidth ``B = zeta f`` seen for ``T`` seconds is about ``sqrt(B / T)``
    (Bendat & Piersol, Random Data, 4th ed. 2010, sec. 8.5.4).

    Parameters
    ----------
    y, fs, angles, kw
        As in :func:`spatial_poles`.
    band : (float, float)
        Hz, the band of the identification.

    Returns
    -------
    kept : list of SpatialPole
    notes : list of str
        One per pole left out for its scatter.
    """
    poles, later, res, dof = _channel_poles(y, fs, angles, kw)
    kept = select_spatial_poles(poles, band, res, dof)
    if not kw.get("uncertainty", True):
        return kept, []
    kept = _with_errors(kept, later)
    T = np.shape(y)[-1] / fs
    notes: list[str] = []
    out = []
    for p in kept:
        scale = np.sqrt(max(p.damping_ratio, 1e-12) * p.frequency_hz / T)
        if np.isfinite(p.std_frequency_hz) and p.std_frequency_hz > 10 * scale:
            notes.append(f"{p.frequency_hz:.4g} Hz (wave number {p.wave_number}, {p.direction}) "
                         f"left out: its frequency scatters by {p.std_frequency_hz:.2g} Hz over "
                         f"the segments, {p.std_frequency_hz / scale:.0f} times what a mode of "
                         "its damping shows in this record")  # fmt: skip
            continue
        out.append(p)
    return out, notes


def select_spatial_poles(
    poles: list[SpatialPole],
    band: tuple[float, float],
    resolution: float,
    dof: float,
    floor_ratio: float | None = None,
    alpha: float = ALPHA,
) -> list[SpatialPole]:
    """The poles of :func:`spatial_poles` taken for waves.

    With ``q`` the ratio two PSD estimates of one level exceed with
    probability ``alpha`` (:func:`.spatial.power_threshold`), a pole is kept
    when (i) its channel holds ``q`` times (or ``floor_ratio`` times, when
    given) the median power of all channels at its frequency: sensor noise
    spreads evenly over the wave numbers, so the median is the noise level;
    (ii) the channel's spectrum rises at the pole ``q`` times above its flanks
    at ``f -+ max(2 zeta f, 3 bins)`` (:func:`.spatial.peak_contrast`; a
    resonance gives about 5, the skirt of a stronger one less than 1); (iii)
    those flanks lie inside ``band``: a peak the band cuts may be the band's
    edge (the filter's transition), not a mode; and (iv) no pole of the same
    channel that persisted over more model orders (on a tie: with more power)
    lies within the sum
    of their half-power half-bandwidths ``zeta_1 f_1 + zeta_2 f_2`` (one
    channel holds one wave per resonance: two poles closer than that are one
    resonance the fit split, and the one stable over more orders is the
    better fit; the half-power points of a mode lie at ``f (1 -+ zeta)``,
    Ewins, Modal Testing, 2nd ed. 2000, sec. 2.2).

    Parameters
    ----------
    poles : list of SpatialPole
    band : (float, float)
        Hz, the band of the identification.
    resolution : float
        Hz, the bin of the spectra.
    dof : float
        Degrees of freedom of each bin.
    floor_ratio : float, optional
        A fixed threshold for (i) instead of ``q`` (the benchmark compares values).
    alpha : float
        False-pass probability of each test for noise alone.

    Returns
    -------
    list of SpatialPole
        Most stable first.
    """
    lo, hi = band
    q = power_threshold(dof, alpha)
    floor = q if floor_ratio is None else float(floor_ratio)
    keep: list[SpatialPole] = []
    for p in sorted(poles, key=lambda x: (-x.orders, -x.ratio)):
        f, z = p.frequency_hz, p.damping_ratio
        off = max(2 * abs(z) * f, 3 * resolution)
        if p.ratio < floor or p.contrast < q or f + off > hi or (lo > 0 and f - off < lo):
            continue
        if any(x.wave_number == p.wave_number and x.direction == p.direction
               and abs(x.frequency_hz - f) <= x.damping_ratio * x.frequency_hz + z * f
               for x in keep):  # fmt: skip
            continue
        keep.append(p)
    return keep
