"""Output correlations of long records by FFT over blocks, streamed.

The covariance-driven SSI (Peeters & De Roeck 1999, eq. 9) needs the output
correlations ``R_i = E[y_{k+i} y_ref,k^T]`` for lags ``i = 0 .. L-1``. They are
estimated here as ``R_i = sum_k y_{k+i} y_ref,k^T / (N - i)`` (the unbiased
estimate) without forming a Hankel matrix of the raw data: the reference
samples are cut into blocks of ``B`` samples, each block is correlated with the
``B + L`` output samples that start with it by one zero-padded FFT (overlap-save
with ``n_fft >= B + L``, so no lag wraps around), and the block sums are
accumulated. Time is ``O(N log B)`` and memory ``O(B n_channels + L n_out
n_ref)`` whatever the record length ``N``; records are fed in chunks of any size
(:class:`CorrelationAccumulator`), so an hour of data never needs to be in memory.

The sums are kept per group of consecutive blocks (between ``n_groups`` and
``2 n_groups`` groups; adjacent groups are merged pairwise as the record grows),
which is what the segment jackknife of :mod:`tyredamp.oma.uncertainty` resamples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_count
from ..exceptions import InputError, ShapeError

__all__ = ["CorrelationAccumulator", "Correlations", "correlations"]


@dataclass(frozen=True)
class Correlations:
    """Output correlations with their per-group sums.

    Attributes
    ----------
    R : ndarray, shape (n_lags, n_out, n_ref)
        Unbiased correlation estimate per lag (units of the data squared),
        with the record mean removed.
    group_sums : ndarray, shape (n_groups, n_lags, n_out, n_ref)
        Raw sums ``sum_k y_{k+i} y_ref,k^T`` of each group of reference samples.
    group_counts : ndarray, shape (n_groups, n_lags)
        Number of products in each group's sum per lag.
    mean_out : ndarray, shape (n_out,)
        Record mean of the outputs.
    mean_ref : ndarray, shape (n_ref,)
        Record mean of the references.
    n_samples : int
        Record length (samples).
    sample_rate : float
        Hz.
    """

    R: NDArray[np.float64]
    group_sums: NDArray[np.float64]
    group_counts: NDArray[np.float64]
    mean_out: NDArray[np.float64]
    mean_ref: NDArray[np.float64]
    n_samples: int
    sample_rate: float

    @property
    def n_groups(self) -> int:
        """Number of groups of consecutive blocks."""
        return int(self.group_sums.shape[0])

    def leave_out(self, g: int) -> NDArray[np.float64]:
        """The correlation estimate without the products of group ``g``, shape like ``R``."""
        s = self.group_sums.sum(axis=0) - self.group_sums[g]
        c = self.group_counts.sum(axis=0) - self.group_counts[g]
        return _centred(s, c, self.mean_out, self.mean_ref)


def _centred(
    sums: NDArray[np.float64],
    counts: NDArray[np.float64],
    mean_out: NDArray[np.float64],
    mean_ref: NDArray[np.float64],
) -> NDArray[np.float64]:
    """``sums / counts - m_out m_ref^T`` per lag (the mean removed after the sums)."""
    c = np.maximum(counts, 1.0)[:, None, None]
    out: NDArray[np.float64] = sums / c - mean_out[None, :, None] * mean_ref[None, None, :]
    return out


class CorrelationAccumulator:
    """Streamed correlations ``R_0 .. R_{L-1}`` of outputs against references.

    Parameters
    ----------
    n_out : int
        Output channels (rows of ``R_i``).
    ref_index : sequence of int
        Indices (into the outputs) of the reference channels.
    n_lags : int
        Number of lags ``L`` (>= 2).
    sample_rate : float
        Hz (kept for the result).
    block : int, optional
        Reference samples per FFT block; default ``max(4 L, 4096)``.
    n_groups : int, optional
        Target number of groups of blocks for the segment jackknife (default 16).

    Examples
    --------
    >>> import numpy as np
    >>> acc = CorrelationAccumulator(2, [0], n_lags=3, sample_rate=100.0)
    >>> y = np.random.default_rng(0).standard_normal((2, 1000))
    >>> acc.add(y[:, :300]); acc.add(y[:, 300:])
    >>> acc.result().R.shape
    (3, 2, 1)
    """

    def __init__(
        self,
        n_out: int,
        ref_index: ArrayLike,
        n_lags: int,
        sample_rate: float,
        *,
        block: int | None = None,
        n_groups: int = 16,
    ) -> None:
        self.n_out = as_count(n_out, "n_out", 1)
        self.ref = np.asarray(ref_index, dtype=int).ravel()
        if self.ref.size == 0 or self.ref.min() < 0 or self.ref.max() >= self.n_out:
            raise InputError(
                f"references: expected channel indices 0..{self.n_out - 1}, got {self.ref.tolist()}"
            )
        self.n_lags = as_count(n_lags, "n_lags", 2)
        self.sample_rate = float(sample_rate)
        self.block = as_count(block, "block", 1) if block is not None else max(4 * n_lags, 4096)
        self.n_fft = 1 << int(np.ceil(np.log2(self.block + self.n_lags)))
        self.n_groups = as_count(n_groups, "n_groups", 2)
        self._buf = np.zeros((self.n_out, 0))
        self._sums: list[NDArray[np.float64]] = []
        self._counts: list[NDArray[np.float64]] = []
        self._total = np.zeros(self.n_out)
        self._n = 0

    def add(self, chunk: ArrayLike) -> None:
        """Feed the next samples, shape (n_out, n_chunk), in time order."""
        y = np.asarray(chunk, dtype=float)
        if y.ndim != 2 or y.shape[0] != self.n_out:
            raise ShapeError(f"chunk: expected shape ({self.n_out}, n), got {y.shape}")
        if not np.all(np.isfinite(y)):
            raise InputError("data: NaN or infinite samples; OMA needs finite samples throughout")
        self._total += y.sum(axis=1)
        self._n += y.shape[1]
        self._buf = np.concatenate([self._buf, y], axis=1) if self._buf.size else y.copy()
        B, L = self.block, self.n_lags
        while self._buf.shape[1] >= B + L:
            self._block(self._buf[:, : B + L], B, np.full(L, float(B)))
            self._buf = self._buf[:, B:]

    def _block(self, seg: NDArray[np.float64], n_ref: int, counts: NDArray[np.float64]) -> None:
        nf = self.n_fft
        Y = np.fft.rfft(seg, nf, axis=1)
        Rr = np.fft.rfft(seg[self.ref, :n_ref], nf, axis=1)
        c = np.fft.irfft(Y[:, None, :] * np.conj(Rr)[None, :, :], nf, axis=2)[:, :, : self.n_lags]
        self._sums.append(np.ascontiguousarray(c.transpose(2, 0, 1)))
        self._counts.append(counts)
        if len(self._sums) >= 2 * self.n_groups:  # merge neighbours pairwise
            self._sums = [a + b for a, b in zip(self._sums[::2], self._sums[1::2], strict=True)]
            self._counts = [
                a + b for a, b in zip(self._counts[::2], self._counts[1::2], strict=True)
            ]

    def result(self) -> Correlations:
        """Flush the last samples and return the :class:`Correlations`.

        Raises
        ------
        InputError
            Fewer samples than ``4 n_lags`` (too short a record for the lags).
        """
        L = self.n_lags
        if self._n < 4 * L:
            raise InputError(
                f"record: {self._n} samples is too short for {L} correlation lags; expected "
                f"at least {4 * L} samples (a longer record, fewer block rows or less decimation)"
            )
        rest = self._buf
        n_rest = rest.shape[1]
        if n_rest:
            lag = np.arange(L)
            counts = np.clip(n_rest - lag, 0, None).astype(float)
            self._block(rest, n_rest, counts)
            self._buf = np.zeros((self.n_out, 0))
        sums = np.stack(self._sums)
        counts_arr = np.stack(self._counts)
        if sums.shape[0] > self.n_groups + 1 and counts_arr[-1, 0] < 0.5 * counts_arr[0, 0]:
            sums[-2] += sums[-1]  # a short tail joins its neighbour
            counts_arr[-2] += counts_arr[-1]
            sums, counts_arr = sums[:-1], counts_arr[:-1]
        m = self._total / self._n
        R = _centred(sums.sum(axis=0), counts_arr.sum(axis=0), m, m[self.ref])
        return Correlations(R, sums, counts_arr, m, m[self.ref], self._n, self.sample_rate)


def correlations(
    data: ArrayLike,
    sample_rate: float,
    n_lags: int,
    references: ArrayLike | None = None,
    *,
    block: int | None = None,
    n_groups: int = 16,
) -> Correlations:
    """Correlations of an in-memory record (see :class:`CorrelationAccumulator`).

    Parameters
    ----------
    data : array_like, shape (n_out, n_samples)
        Output records (any unit).
    sample_rate : float
        Hz.
    n_lags : int
        Lags ``0 .. n_lags - 1``.
    references : sequence of int, optional
        Reference channel indices; default all channels.
    block, n_groups : int, optional
        As in :class:`CorrelationAccumulator`.
    """
    y = np.asarray(data, dtype=float)
    if y.ndim != 2:
        raise ShapeError(f"data: expected shape (n_channels, n_samples), got {y.shape}")
    refs = np.arange(y.shape[0]) if references is None else references
    if block is None:  # at least 2 n_groups blocks, so that every jackknife group is filled
        n_lags_ = max(int(n_lags), 1)
        block = max(2 * n_lags_, min(max(4 * n_lags_, 4096), y.shape[1] // (2 * n_groups)))
    acc = CorrelationAccumulator(
        y.shape[0], refs, n_lags, sample_rate, block=block, n_groups=n_groups
    )
    step = max(acc.block, 1 << 16)
    for s in range(0, y.shape[1], step):
        acc.add(y[:, s : s + step])
    return acc.result()
