"""Sampled time data of a test: forces and responses on one clock."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_finite, check_positive
from .exceptions import InputError, ShapeError
from .frf import Channel

__all__ = ["QUANTITY_UNITS", "Quantity", "TimeData"]

Quantity = Literal["force", "displacement", "velocity", "acceleration"]
#: SI unit of each measured quantity.
QUANTITY_UNITS: dict[str, str] = {
    "force": "N",
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
}


@dataclass(frozen=True, eq=False)
class TimeData:
    """Simultaneously sampled channels (forces and responses).

    Parameters
    ----------
    data : array_like, shape (n_channels, n_samples)
        Samples in SI units (N, m, m/s, m/s^2 by quantity).
    sample_rate : float
        Samples per second (Hz).
    channels : sequence of Channel
        Point and direction of each channel.
    quantities : sequence of str
        ``"force"``, ``"displacement"``, ``"velocity"`` or ``"acceleration"``
        per channel.
    meta : dict, optional
        Free metadata. Keys used by the estimators: ``"period_samples"``
        (int, length of one period of a periodic excitation),
        ``"settle_samples"`` (int, samples to drop at the start).
    """

    data: NDArray[np.float64]
    sample_rate: float
    channels: tuple[Channel, ...]
    quantities: tuple[str, ...]
    meta: dict[str, Any] = field(default_factory=dict)

    def __init__(
        self,
        data: ArrayLike,
        sample_rate: float,
        channels: Sequence[Channel | int],
        quantities: Sequence[str],
        meta: dict[str, Any] | None = None,
    ) -> None:
        d = as_finite(data, "data")
        if d.ndim == 1:
            d = d[None, :]
        if d.ndim != 2:
            raise ShapeError(f"data: expected shape (n_channels, n_samples), got {d.shape}")
        if d.shape[1] < 2:
            raise ShapeError(f"data: expected at least 2 samples per channel, got {d.shape[1]}")
        fs = check_positive(sample_rate, "sample_rate")
        ch = tuple(c if isinstance(c, Channel) else Channel(node=int(c)) for c in channels)
        if len(ch) != d.shape[0]:
            raise ShapeError(f"channels: expected {d.shape[0]} channels, got {len(ch)}")
        q = tuple(quantities)
        if len(q) != d.shape[0]:
            raise ShapeError(f"quantities: expected {d.shape[0]} entries, got {len(q)}")
        for qi in q:
            if qi not in QUANTITY_UNITS:
                raise InputError(f"quantities: expected one of {tuple(QUANTITY_UNITS)}, got {qi!r}")
        d = d.copy()
        d.setflags(write=False)
        object.__setattr__(self, "data", d)
        object.__setattr__(self, "sample_rate", fs)
        object.__setattr__(self, "channels", ch)
        object.__setattr__(self, "quantities", q)
        object.__setattr__(self, "meta", dict(meta or {}))

    @property
    def n_channels(self) -> int:
        """Number of channels."""
        return int(self.data.shape[0])

    @property
    def n_samples(self) -> int:
        """Number of samples per channel."""
        return int(self.data.shape[1])

    @property
    def time(self) -> NDArray[np.float64]:
        """Sample times in s, starting at 0."""
        return np.arange(self.n_samples) / self.sample_rate

    @property
    def units(self) -> tuple[str, ...]:
        """SI unit of each channel."""
        return tuple(QUANTITY_UNITS[q] for q in self.quantities)

    @property
    def force_indices(self) -> list[int]:
        """Positions of the force channels."""
        return [i for i, q in enumerate(self.quantities) if q == "force"]

    @property
    def response_indices(self) -> list[int]:
        """Positions of the response (non-force) channels."""
        return [i for i, q in enumerate(self.quantities) if q != "force"]

    def __repr__(self) -> str:
        return (
            f"TimeData(n_channels={self.n_channels}, n_samples={self.n_samples}, "
            f"sample_rate={self.sample_rate:g} Hz, forces={len(self.force_indices)})"
        )
