"""Operational modal analysis end to end: preprocessing, poles, selection, errors, harmonics."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.signal as ss
from numpy.typing import ArrayLike, NDArray

from .._blas import blas_threads as blas_limit
from .._validate import as_band, check_positive
from ..exceptions import InputError, ShapeError
from .correlation import Correlations, correlations
from .harmonics import HarmonicTest, detect_wheel_speed, harmonic_tests
from .selection import Stabilisation, select_modes, stabilisation
from .spectra import half_spectra, plscf_poles, residue_shapes
from .ssi import OrderPoles, ssi_cov
from .uncertainty import jackknife_std

__all__ = ["DeferredErrors", "OMAResult", "choose_references", "oma", "oma_deferred", "preprocess"]

Method = Literal["ssi", "plscf"]


@dataclass(frozen=True)
class OMAResult:
    """Modes identified from output-only data.

    Attributes
    ----------
    frequency_hz, damping_ratio : ndarray, shape (m,)
        Natural frequency (Hz) and damping ratio of each structural mode.
    std_frequency_hz, std_damping_ratio : ndarray, shape (m,)
        Jackknife standard errors (:mod:`tyredamp.oma.uncertainty`).
    poles : ndarray of complex, shape (m,)
        rad/s, ``Im > 0``.
    shapes : ndarray of complex, shape (n_out, m)
        Unscaled mode shapes (unit norm; output-only data cannot scale them).
    order : ndarray of int, shape (m,)
        Model order each mode was taken at; ``n_orders`` how many orders held it.
    n_orders : ndarray of int, shape (m,)
    harmonics : list of dict
        Peaks told apart as harmonics (frequency, kurtosis, z, wheel order), kept out.
    wheel_speed_hz : float or None
        Given, or detected from the harmonics.
    method : str
        ``"ssi"`` or ``"plscf"``.
    band_hz : (float, float)
    sample_rate : float
        After decimation (Hz).
    references : tuple of int
        Reference channel indices.
    poleset : OrderPoles
        Every pole of every order (stabilisation diagram).
    stab : Stabilisation
    cut : float
        The data-driven distance cut of the selection.
    notes : list of str
    """

    frequency_hz: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    std_frequency_hz: NDArray[np.float64]
    std_damping_ratio: NDArray[np.float64]
    poles: NDArray[np.complex128]
    shapes: NDArray[np.complex128]
    order: NDArray[np.int64]
    n_orders: NDArray[np.int64]
    harmonics: list[dict[str, Any]]
    wheel_speed_hz: float | None
    method: str
    band_hz: tuple[float, float]
    sample_rate: float
    references: tuple[int, ...]
    poleset: OrderPoles
    stab: Stabilisation
    cut: float
    notes: list[str] = field(default_factory=list)

    @property
    def n_modes(self) -> int:
        """Number of structural modes."""
        return int(self.frequency_hz.size)


@dataclass(frozen=True)
class DeferredErrors:
    """What the jackknife of :func:`oma` needs, kept to run it later on some modes only.

    Attributes
    ----------
    corr : Correlations
        With its group sums.
    block_rows : int
    orders, poles : list of ndarray
        Per mode of the result (in its order), the model orders and poles its
        estimate averages over.
    shapes : ndarray of complex, shape (m, n_out)
    """

    corr: Correlations
    block_rows: int
    orders: list[NDArray[np.int64]]
    poles: list[NDArray[np.complex128]]
    shapes: NDArray[np.complex128]

    def std(self, modes: list[int]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Jackknife standard errors (Hz, -) of the given modes of the result
        (:func:`~.uncertainty.jackknife_std`); empty arrays for none."""
        if not modes:
            return np.zeros(0), np.zeros(0)
        return jackknife_std(self.corr, self.block_rows, [self.orders[j] for j in modes],
                             [self.poles[j] for j in modes], self.shapes[modes])  # fmt: skip


def preprocess(
    data: ArrayLike, sample_rate: float, decimate: int = 1
) -> tuple[NDArray[np.float64], float]:
    """Mean-removed records decimated by ``decimate`` (FIR anti-alias, zero phase).

    Decimation is done in stages of at most 10 (:func:`scipy.signal.decimate`
    with ``ftype="fir"``: a linear-phase filter adds no poles to the data).
    """
    y = np.asarray(data, dtype=float)
    y = y - y.mean(axis=1, keepdims=True)
    fs = float(sample_rate)
    q = int(decimate)
    while q > 1:
        step = next((k for k in range(min(q, 10), 1, -1) if q % k == 0), q)
        y = ss.decimate(y, step, ftype="fir", axis=1, zero_phase=True)
        fs /= step
        q //= step
    return np.ascontiguousarray(y), fs


def choose_references(y: NDArray[np.float64], n_max: int = 8) -> list[int]:
    """Up to ``n_max`` channels that are the least linearly dependent.

    A pivoted QR of the standardised records' zero-lag correlation matrix (the
    channels a pivoted Cholesky factorisation takes first): the set spans most of
    the measured motion with the smallest redundancy.
    """
    if y.shape[0] <= n_max:
        return list(range(y.shape[0]))
    sub = y[:, :: max(1, y.shape[1] // 20000)]
    sd = np.maximum(sub.std(axis=1), 1e-300)
    c = np.corrcoef(sub / sd[:, None])
    import scipy.linalg as sla

    _, _, piv = sla.qr(c, pivoting=True)
    return sorted(int(p) for p in piv[:n_max])


def _check(y: NDArray[np.float64], method: str) -> None:
    if y.ndim != 2 or y.shape[1] == 0 or y.shape[0] == 0:
        raise ShapeError(f"data: expected channels x samples with samples, got shape {y.shape}")
    if not np.all(np.isfinite(y)):
        bad = sorted({int(i) for i in np.argwhere(~np.isfinite(y))[:, 0]})
        raise InputError(
            f"data: channel(s) {', '.join(str(b + 1) for b in bad[:5])} hold NaN or infinite "
            "samples; OMA needs finite samples throughout (cut the record or drop the channel)"
        )
    if method == "ssi" and y.shape[0] < 2:
        raise InputError(
            "data: SSI needs at least 2 response channels, got 1 (use the pLSCF method "
            "for a single channel)"
        )
    flat = np.flatnonzero(np.ptp(y, axis=1) == 0)
    if flat.size:
        raise InputError(f"data: channel {flat[0] + 1} is constant; it holds no response")


def _defaults(
    y: NDArray[np.float64],
    fs: float,
    refs: list[int],
    band: tuple[float, float],
    block_rows: int | None,
    max_order: int | None,
) -> tuple[int, int]:
    """Block rows ``i`` and the largest order: the ``2 i`` lags cover two periods of
    the lowest frequency of the band (or 1/50 of the sampling rate) as far as
    ``i n_ref <= 240`` allows, and the order goes to 120 (``i n_ref`` bounds it)."""
    r = len(refs)
    if block_rows is None:
        f_lo = band[0] if band[0] > 0 else fs / 100
        # at most 240 columns of the Toeplitz matrix (its SVD is repeated per segment)
        block_rows = int(np.clip(np.ceil(fs / f_lo), 20, max(20, 240 // r)))
        block_rows = max(block_rows, int(np.ceil(80 / r)) + 1)
    n_hi = min(block_rows * r, (block_rows - 1) * y.shape[0])
    order_hi = min(n_hi, 120) if max_order is None else int(max_order)
    if order_hi > n_hi or order_hi < 2:
        raise InputError(
            f"max order: expected 2..{n_hi} for {block_rows} block rows and {r} reference(s), "
            f"got {order_hi}"
        )
    return block_rows, order_hi


def oma(
    data: ArrayLike,
    sample_rate: float,
    *,
    method: Method = "ssi",
    references: ArrayLike | None = None,
    band: tuple[float, float] | None = None,
    decimate: int | None = None,
    block_rows: int | None = None,
    max_order: int | None = None,
    n_groups: int = 16,
    wheel_speed_hz: float | None = None,
    uncertainty: bool = True,
    blas_threads: int | None = 1,
) -> OMAResult:
    """Identify modes from output-only records.

    Parameters
    ----------
    data : array_like, shape (n_out, n_samples)
        Response records (any motion unit; one unit per channel).
    sample_rate : float
        Hz.
    method : {"ssi", "plscf"}
        Covariance-driven SSI (:mod:`.ssi`) or pLSCF on half-spectra (:mod:`.spectra`).
    references : sequence of int, optional
        Reference channels (0-based); default up to 8 least-dependent channels.
    band : (float, float), optional
        Hz; default 0 .. 0.45 of the (decimated) sampling rate.
    decimate : int, optional
        Decimation factor; default the largest that keeps ``band[1]`` below 0.4
        of the new sampling rate (1 without a band).
    block_rows, max_order : int, optional
        SSI block rows ``i`` (lags ``2 i``) and the largest model order.
    n_groups : int
        Segments of the jackknife (>= 2).
    wheel_speed_hz : float, optional
        Rotation frequency of a rolling tyre; harmonics at its multiples are kept
        out of the modes. Without it the speed is detected from the harmonics.
    uncertainty : bool
        Compute the jackknife standard errors (SSI; ``n_groups`` more SVDs). Without
        them (NaN) no mode is left out for its scatter.
    blas_threads : int or None
        BLAS threads while it runs (default 1: the SSI works on many small
        matrices, on which more threads cost far more than they gain; ``None``
        leaves the caller's setting).

    Returns
    -------
    OMAResult
    """
    with blas_limit(blas_threads):
        return _oma(data, sample_rate, method, references, band, decimate, block_rows,
                    max_order, n_groups, wheel_speed_hz, uncertainty)[0]  # fmt: skip


def oma_deferred(
    data: ArrayLike,
    sample_rate: float,
    *,
    method: Method = "ssi",
    references: ArrayLike | None = None,
    band: tuple[float, float] | None = None,
    decimate: int | None = None,
    block_rows: int | None = None,
    max_order: int | None = None,
    n_groups: int = 16,
    wheel_speed_hz: float | None = None,
    blas_threads: int | None = 1,
) -> tuple[OMAResult, DeferredErrors]:
    """:func:`oma` without standard errors, and what computes them later.

    For callers that keep only some of the modes (the wave-number route of
    :mod:`.spatial_poles`): the jackknife, most of the cost, then runs on
    those alone. The parameters are those of :func:`oma`. The modes returned
    do not depend on the errors: the rule of :func:`oma` that drops a mode
    whose jackknife scatter is too large is left to the caller.

    Returns
    -------
    result : OMAResult
        With NaN standard errors.
    errors : DeferredErrors
    """
    with blas_limit(blas_threads):
        return _oma(data, sample_rate, method, references, band, decimate, block_rows,
                    max_order, n_groups, wheel_speed_hz, False)  # fmt: skip


def _oma(
    data: ArrayLike,
    sample_rate: float,
    method: Method,
    references: ArrayLike | None,
    band: tuple[float, float] | None,
    decimate: int | None,
    block_rows: int | None,
    max_order: int | None,
    n_groups: int,
    wheel_speed_hz: float | None,
    uncertainty: bool,
) -> tuple[OMAResult, DeferredErrors]:
    """The body of :func:`oma` (same parameters) and its deferred errors."""
    y0 = np.asarray(data, dtype=float)
    if y0.ndim == 1:
        y0 = y0[None, :]
    _check(y0, method)
    fs0 = check_positive(sample_rate, "sample rate")
    if band is not None:
        band = as_band(band, "band")
        if band[1] > fs0 / 2:
            raise InputError(f"band: upper edge {band[1]:g} Hz is above the Nyquist {fs0 / 2:g} Hz")
    q = decimate if decimate is not None else (max(1, int(fs0 * 0.4 // band[1])) if band else 1)
    y, fs = preprocess(y0, fs0, q)
    bnd = band if band is not None else (0.0, 0.45 * fs)
    refs = choose_references(y) if references is None else [int(r) for r in np.ravel(references)]
    i, n_hi = _defaults(y, fs, refs, bnd, block_rows, max_order)
    if y.shape[1] < 8 * i:
        raise InputError(
            f"record: {y.shape[1]} samples (after decimation by {q}) is too short for {2 * i} "
            f"correlation lags; expected at least {8 * i} samples"
        )
    corr = correlations(y, fs, 2 * i + (1 if method == "ssi" else 0), refs, n_groups=n_groups)
    if method == "ssi":
        op, _ = ssi_cov(corr.R, fs, i, np.arange(2, n_hi + 1, 2))
    elif method == "plscf":
        op, _ = plscf_poles(corr.R, fs, bnd, max(2, n_hi // (2 * len(refs))))
    else:
        raise InputError(f"method: expected 'ssi' or 'plscf', got {method!r}")
    st = stabilisation(op, bnd)
    clusters, cut = select_modes(op, st)
    rep = np.array([c.representative for c in clusters], dtype=np.intp)
    return _finish(
        y, fs, corr, op, st, clusters, rep, cut, method, bnd, i, refs, wheel_speed_hz, uncertainty
    )


def _near_orders(op: OrderPoles, c: Any) -> NDArray[np.intp]:
    """Up to 5 members of cluster ``c`` at its lowest model orders.

    Every member already recurred from the previous order (the distance cut of
    :func:`~.selection.select_modes`), so the lowest orders hold the mode once it
    is stable. Higher orders fit more of the correlation estimate's own error:
    on the rolling virtual tyre the damping ratios drifted down with the order
    (by 20-40 % at orders 100-120 against 0-10 % at 20-50, 16 fixed sensors,
    ``benchmarks/rolling_oma.py``), the known over-fitting of SSI at orders far
    above the number of modes (Reynders, Houbrechts & De Roeck 2012, sec. 3).
    """
    mem = np.asarray(c.members)
    return np.asarray(mem[np.argsort(op.order[mem], kind="stable")[:5]], dtype=np.intp)


def _finish(
    y: NDArray[np.float64],
    fs: float,
    corr: Correlations,
    op: OrderPoles,
    st: Stabilisation,
    clusters: list[Any],
    rep: NDArray[np.intp],
    cut: float,
    method: str,
    band: tuple[float, float],
    i: int,
    refs: list[int],
    wheel: float | None,
    uncertainty: bool = True,
) -> tuple[OMAResult, DeferredErrors]:
    """Standard errors, shapes (pLSCF), the harmonic tests and the result."""
    notes: list[str] = []
    # each mode's estimate: the mean over (up to) 5 of its cluster's lowest orders, a
    # smooth statistic the jackknife replicates as it is
    sub = [_near_orders(op, c) for c in clusters]
    fm = np.array([np.mean(op.frequency_hz[ix]) for ix in sub]) if sub else np.zeros(0)
    zm = np.array([np.mean(op.damping_ratio[ix]) for ix in sub]) if sub else np.zeros(0)
    wm = 2 * np.pi * fm
    poles = -zm * wm + 1j * wm * np.sqrt(np.clip(1 - zm**2, 0.0, None))
    if method == "ssi":
        shapes = op.shapes[rep]
        if uncertainty and rep.size:
            sf, sz = jackknife_std(
                corr, i, [op.order[ix] for ix in sub], [op.poles[ix] for ix in sub], shapes
            )
        else:
            sf = sz = np.full(rep.size, np.nan)
    else:
        f, S, beta = half_spectra(corr.R, fs)
        sel = (f >= band[0]) & (f <= band[1])
        shapes = (
            residue_shapes(f[sel], S[:, :, sel], poles, beta * fs)
            if rep.size
            else (np.zeros((0, y.shape[0]), complex))
        )
        sf = sz = np.full(rep.size, np.nan)
        notes.append("pLSCF: standard errors are given by the SSI method only")
    fn = np.abs(poles) / (2 * np.pi)
    zeta = -poles.real / np.maximum(np.abs(poles), 1e-300)
    tests: list[HarmonicTest] = (
        harmonic_tests(y, fs, fn, zeta, shapes, wheel, sf) if rep.size else []
    )
    harm = np.array([t.harmonic for t in tests], bool)
    detected = None
    if wheel is None and harm.sum() >= 2:
        detected = detect_wheel_speed(fn[harm])
        if detected is not None:
            notes.append(f"wheel speed {detected:.4g} Hz detected from {int(harm.sum())} harmonics")
    hlist = [
        {
            "frequency_hz": float(fn[j]),
            "damping_ratio": float(zeta[j]),
            "kurtosis": tests[j].kurtosis,
            "z": tests[j].z,
            "wheel_order": tests[j].wheel_order,
        }
        for j in np.flatnonzero(harm)
    ]
    keep = ~harm if harm.size else np.zeros(0, bool)
    # a resonance of half-power half-bandwidth B = zeta f seen for T seconds has its
    # frequency fixed to about B / sqrt(B T) = sqrt(B / T) (Bendat & Piersol, Random
    # Data, 4th ed. 2010, sec. 8.5.4: the random error of a peak of bandwidth B is that of
    # B T averages); a pole whose segment scatter is ten times that is not a resonance
    # the record determines: left out, and said so
    T = y.shape[1] / fs
    scale = np.sqrt(np.maximum(zeta, 1e-12) * fn / T)
    loose = keep & np.isfinite(sf) & (sf > 10 * scale)
    for j in np.flatnonzero(loose):
        notes.append(
            f"{fn[j]:.4g} Hz left out: its frequency scatters by {sf[j]:.2g} Hz over the "
            f"segments, {sf[j] / scale[j]:.0f} times what a mode of its damping shows in "
            "this record"
        )
    keep &= ~loose
    for j in np.flatnonzero(keep & (zeta <= 0)):
        notes.append(f"{fn[j]:.4g} Hz left out: no positive damping (a harmonic the test missed?)")
    keep &= zeta > 0
    # a mode whose damping is not told from zero by its own standard error (t < 2):
    # kept, and said so
    for j in np.flatnonzero(keep & np.isfinite(sz) & (zeta < 2 * sz)):
        notes.append(
            f"{fn[j]:.4g} Hz: damping {100 * zeta[j]:.3g} % +- {100 * sz[j]:.2g} % "
            "is not told from zero by this record"
        )
    if not keep.any():
        notes.append("no structural mode found: no cluster of poles persisted over the orders")
    kj = np.flatnonzero(keep)
    sh_k = shapes[kj] if method == "ssi" else np.zeros((0, y.shape[0]), complex)
    later = DeferredErrors(
        corr, i, [op.order[sub[j]] for j in kj], [op.poles[sub[j]] for j in kj], sh_k
    )
    return OMAResult(
        fn[keep],
        zeta[keep],
        sf[keep],
        sz[keep],
        poles[keep],
        shapes[keep].T,
        op.order[rep][keep],
        np.array([c.n_orders for c in clusters], np.int64)[keep]
        if clusters
        else np.zeros(0, np.int64),
        hlist,
        wheel if wheel is not None else detected,
        method,
        band,
        fs,
        tuple(refs),
        op,
        st,
        cut,
        notes,
    ), later
