"""Sampled time data of a test: forces and responses on one clock."""

from __future__ import annotations

import difflib
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_finite, check_positive
from .exceptions import InputError, ShapeError
from .frf import Channel

__all__ = [
    "ACQUISITION_KEYS",
    "MOTION_QUANTITIES",
    "QUANTITY_UNITS",
    "Acquisition",
    "Quantity",
    "TimeData",
]

Quantity = Literal["force", "displacement", "velocity", "acceleration", "pressure", "voltage"]
#: SI unit of each measured quantity.
QUANTITY_UNITS: dict[str, str] = {
    "force": "N",
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "pressure": "Pa",
    "voltage": "V",
}
#: The quantities of structural responses (what an FRF relates to a force).
MOTION_QUANTITIES: tuple[str, ...] = ("displacement", "velocity", "acceleration")


def _count(v: Any, name: str, minimum: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int | np.integer):
        if isinstance(v, float) and v.is_integer():
            v = int(v)
        else:
            raise InputError(f"{name}: expected an integer >= {minimum}, got {v!r}")
    if v < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {v!r}")
    return int(v)


@dataclass(frozen=True)
class Acquisition:
    """How a test was acquired: what the FRF estimators need to choose their method.

    Written by the virtual rigs and by the file readers, read by
    :func:`tyredamp.signal.estimate_frf`. Every field is optional: ``None``
    means "not stated" (then the estimator uses its defaults or detects the
    property from the data).

    Parameters
    ----------
    period_samples : int or None
        Samples per period of a periodic excitation (>= 2); selects cyclic
        averaging over whole periods.
    run_starts : tuple of int
        First sample of each separately driven run, increasing from 0
        (default ``(0,)``: one run). Segments never straddle runs.
    settle_samples : int
        Samples to drop at the start of every run (transient), default 0.
    record_samples : int or None
        Record length of burst or impact excitation (transient method).
    band_hz : (float, float) or None
        Excited band in Hz (``f_lo < f_hi``); the estimators keep only its lines.
    n_averages : int or None
        Periods (periodic) or records (burst) per run, as acquired.
    excitation : str
        Name of the excitation signal (``"periodic_chirp"``, ...; "" unknown).
    """

    period_samples: int | None = None
    run_starts: tuple[int, ...] = (0,)
    settle_samples: int = 0
    record_samples: int | None = None
    band_hz: tuple[float, float] | None = None
    n_averages: int | None = None
    excitation: str = ""

    def __post_init__(self) -> None:
        if self.period_samples is not None:
            object.__setattr__(
                self, "period_samples", _count(self.period_samples, "period_samples", 2)
            )
        if self.record_samples is not None:
            object.__setattr__(
                self, "record_samples", _count(self.record_samples, "record_samples", 2)
            )
        if self.n_averages is not None:
            object.__setattr__(self, "n_averages", _count(self.n_averages, "n_averages", 1))
        object.__setattr__(self, "settle_samples", _count(self.settle_samples, "settle_samples", 0))
        if isinstance(self.run_starts, str | bytes) or not isinstance(
            self.run_starts, Sequence | np.ndarray
        ):
            raise InputError(
                f"run_starts: expected a sequence of sample indices, got {self.run_starts!r}"
            )
        runs = tuple(_count(r, "run_starts", 0) for r in self.run_starts)
        if not runs or runs[0] != 0 or any(b <= a for a, b in itertools.pairwise(runs)):
            raise InputError(
                "run_starts: expected increasing sample indices starting at 0, got "
                f"{self.run_starts!r}"
            )
        object.__setattr__(self, "run_starts", runs)
        if self.band_hz is not None:
            try:
                lo, hi = (float(b) for b in self.band_hz)
            except (TypeError, ValueError):
                raise InputError(
                    f"band_hz: expected (f_lo, f_hi) in Hz, got {self.band_hz!r}"
                ) from None
            if not (math.isfinite(lo) and math.isfinite(hi)) or lo < 0 or hi <= lo:
                raise InputError(f"band_hz: expected 0 <= f_lo < f_hi in Hz, got {self.band_hz!r}")
            object.__setattr__(self, "band_hz", (lo, hi))
        if not isinstance(self.excitation, str):
            raise InputError(f"excitation: expected a name, got {self.excitation!r}")

    def check_length(self, n_samples: int) -> None:
        """Raise :class:`InputError` when the fields do not fit a record of ``n_samples``."""
        if self.run_starts[-1] >= n_samples:
            raise InputError(
                f"acquisition.run_starts: last run starts at sample {self.run_starts[-1]}, "
                f"the record has {n_samples} samples"
            )
        for name in ("period_samples", "record_samples"):
            v = getattr(self, name)
            if v is not None and v > n_samples:
                raise InputError(
                    f"acquisition.{name}: {v} samples is longer than the record ({n_samples})"
                )

    def to_dict(self) -> dict[str, Any]:
        """The stated fields as a JSON-ready dict (the keys of :data:`ACQUISITION_KEYS`)."""
        out: dict[str, Any] = {}
        if self.period_samples is not None:
            out["period_samples"] = self.period_samples
        if self.settle_samples:
            out["settle_samples"] = self.settle_samples
        if self.record_samples is not None:
            out["record_samples"] = self.record_samples
        if self.run_starts != (0,):
            out["run_starts"] = list(self.run_starts)
        if self.band_hz is not None:
            out["band_hz"] = list(self.band_hz)
        if self.n_averages is not None:
            out["n_averages"] = self.n_averages
        if self.excitation:
            out["excitation"] = self.excitation
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Acquisition:
        """Inverse of :meth:`to_dict`; an unknown (misspelt) key is an error, never ignored."""
        unknown = [k for k in d if k not in ACQUISITION_KEYS]
        if unknown:
            raise InputError(
                f"acquisition: unknown field(s) {unknown}; expected {sorted(ACQUISITION_KEYS)}"
            )
        kw: dict[str, Any] = dict(d)
        if "run_starts" in kw and kw["run_starts"] is not None:
            rs = kw["run_starts"]
            kw["run_starts"] = (
                tuple(rs)
                if isinstance(rs, Sequence | np.ndarray) and not isinstance(rs, str)
                else rs
            )
        if kw.get("band_hz") is not None:
            b = kw["band_hz"]
            kw["band_hz"] = (
                tuple(b) if isinstance(b, Sequence | np.ndarray) and not isinstance(b, str) else b
            )
        if kw.get("run_starts") is None:
            kw.pop("run_starts", None)
        if kw.get("settle_samples") is None:
            kw.pop("settle_samples", None)
        if kw.get("excitation") is None:
            kw.pop("excitation", None)
        return cls(**kw)

    @classmethod
    def split_meta(cls, meta: Mapping[str, Any]) -> tuple[Acquisition, dict[str, Any]]:
        """Split a legacy metadata dict into the acquisition fields and the free notes.

        Files and code written before :class:`Acquisition` existed kept these
        fields as ``meta`` keys (``period_samples``, ``run_starts``,
        ``settle_samples``, ``record_samples``, ``band_hz``, ``n_periods``,
        ``excitation``); they are taken out of ``meta`` here. A key that
        looks like a misspelling of one of them raises :class:`InputError`
        instead of being kept as a note.
        """
        acq: dict[str, Any] = {}
        notes: dict[str, Any] = {}
        for k, v in meta.items():
            key = _LEGACY.get(k, k)
            if key in ACQUISITION_KEYS:
                acq[key] = v
                continue
            close = difflib.get_close_matches(str(k), list(_LEGACY), n=1, cutoff=0.9)
            if close and str(k) != close[0]:
                raise InputError(
                    f"meta: key {k!r} looks like the acquisition field {close[0]!r}; "
                    "state acquisition fields with TimeData(acquisition=Acquisition(...))"
                )
            notes[k] = v
        return cls.from_dict(acq), notes


#: Field names of :class:`Acquisition` (also its keys in files).
ACQUISITION_KEYS: frozenset[str] = frozenset(f.name for f in fields(Acquisition))
#: Legacy ``meta`` keys and the field each one fills.
_LEGACY: dict[str, str] = {
    "period_samples": "period_samples",
    "run_starts": "run_starts",
    "settle_samples": "settle_samples",
    "record_samples": "record_samples",
    "band_hz": "band_hz",
    "n_periods": "n_averages",
    "n_averages": "n_averages",
    "excitation": "excitation",
}


@dataclass(frozen=True, eq=False)
class TimeData:
    """Simultaneously sampled channels (forces and responses).

    Parameters
    ----------
    data : array_like, shape (n_channels, n_samples)
        Samples in SI units (N, m, m/s, m/s^2, Pa, V by quantity).
    sample_rate : float
        Samples per second (Hz).
    channels : sequence of Channel
        Point and direction of each channel.
    quantities : sequence of str
        ``"force"``, ``"displacement"``, ``"velocity"``, ``"acceleration"``,
        ``"pressure"`` (a microphone, Pa) or ``"voltage"`` (a sensor whose
        sensitivity was not given, V) per channel. Pressure and voltage
        channels are kept and shown but are neither forces nor structural
        responses: FRF estimation leaves them out.
    meta : dict, optional
        Free notes (test description, operator ...); never read by the
        estimators. Legacy acquisition keys (``"period_samples"``,
        ``"run_starts"``, ``"settle_samples"``, ``"record_samples"``,
        ``"band_hz"``, ``"n_periods"``, ``"excitation"``) are moved into
        ``acquisition`` (see :meth:`Acquisition.split_meta`), so files and
        code from before keep working.
    acquisition : Acquisition, optional
        How the test was acquired (period, runs, settle and record lengths,
        band); default from the legacy ``meta`` keys, else nothing stated.
    """

    data: NDArray[np.float64]
    sample_rate: float
    channels: tuple[Channel, ...]
    quantities: tuple[str, ...]
    meta: dict[str, Any] = field(default_factory=dict)
    acquisition: Acquisition = field(default_factory=Acquisition)

    def __init__(
        self,
        data: ArrayLike,
        sample_rate: float,
        channels: Sequence[Channel | int],
        quantities: Sequence[str],
        meta: dict[str, Any] | None = None,
        acquisition: Acquisition | None = None,
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
                raise InputError(
                    f"channel quantity {qi!r}: expected one of {', '.join(QUANTITY_UNITS)} "
                    "(a channel's role on the command line: --channel NAME=ROLE)"
                )
        d = d.copy()
        d.setflags(write=False)
        object.__setattr__(self, "data", d)
        object.__setattr__(self, "sample_rate", fs)
        object.__setattr__(self, "channels", ch)
        object.__setattr__(self, "quantities", q)
        legacy, notes = Acquisition.split_meta(meta or {})
        if acquisition is None:
            acquisition = legacy
        elif not isinstance(acquisition, Acquisition):
            raise InputError(
                f"acquisition: expected an Acquisition, got {type(acquisition).__name__}"
            )
        elif legacy != Acquisition():
            raise InputError(
                "meta: holds acquisition keys "
                f"{sorted(legacy.to_dict())} as well as acquisition=; give them once"
            )
        acquisition.check_length(d.shape[1])
        object.__setattr__(self, "meta", notes)
        object.__setattr__(self, "acquisition", acquisition)

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
        """Positions of the structural response channels (displacement, velocity, acceleration)."""
        return [i for i, q in enumerate(self.quantities) if q in MOTION_QUANTITIES]

    @property
    def other_indices(self) -> list[int]:
        """Positions of the channels that are neither force nor motion (pressure, voltage)."""
        return [i for i, q in enumerate(self.quantities) if q not in (*MOTION_QUANTITIES, "force")]

    @property
    def output_only(self) -> bool:
        """True when no channel is a force: an operational (output-only) recording."""
        return not self.force_indices

    def require_force(self, what: str = "an FRF", where: object = None) -> None:
        """Raise :class:`InputError` in one line when there is no force channel.

        The message says that this is output-only data, names the channels and
        says what to do: name a force channel (``--channel NAME=force:N``) or
        use output-only identification, which tyredamp does not offer yet.

        Parameters
        ----------
        what : str
            What needs the force (``"an FRF"``), for the message.
        where : path-like, optional
            The file the data came from, named first in the message.
        """
        if self.force_indices:
            return
        names = ", ".join(
            f"{c.name or c.label} ({q})"
            for c, q in zip(self.channels, self.quantities, strict=True)
        )
        raise InputError(
            ("" if where is None else f"{where}: ")
            + f"output-only data (no force channel): channels {names}; {what} needs a "
            "measured force: name the force channel with --channel NAME=force:N (a "
            "campaign's channel_map, Python's ChannelMap), or identify its modes output-only "
            "with tyredamp oma (operational modal analysis)"
        )

    def require_response(self, what: str = "an FRF", where: object = None) -> None:
        """Raise :class:`InputError` in one line when no channel is a structural response.

        Pressure and voltage channels are named with what to supply (a
        sensitivity that makes a voltage an acceleration, a velocity ...).
        """
        if self.response_indices:
            return
        others = [
            f"{self.channels[i].name or self.channels[i].label} "
            f"({self.quantities[i]}, {QUANTITY_UNITS[self.quantities[i]]})"
            for i in self.other_indices
        ]
        hint = ""
        volts = [i for i in self.other_indices if self.quantities[i] == "voltage"]
        if volts:
            c = self.channels[volts[0]]
            hint = (
                f"; give a voltage channel's sensitivity, for example --sensitivity "
                f"'{c.name or c.label}=100 mV/g'"
            )
        raise InputError(
            ("" if where is None else f"{where}: ")
            + f"no response channel (displacement, velocity or acceleration): {what} needs "
            + "one"
            + (f"; the other channels are {', '.join(others)}" if others else "")
            + hint
        )

    def __repr__(self) -> str:
        return (
            f"TimeData(n_channels={self.n_channels}, n_samples={self.n_samples}, "
            f"sample_rate={self.sample_rate:g} Hz, forces={len(self.force_indices)})"
        )
