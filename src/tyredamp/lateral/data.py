"""A measured lateral FRF with its operating conditions, prepared for the fits.

:class:`LateralData` holds the FRF with the travel speed, the force (ground or
axle) and the wheel mass; :func:`_prepare` turns it into the lines the fits of
:mod:`tyredamp.lateral.fit` use: the accelerance on the band without the 0 Hz
line, and the weights of each line (the choices are in :mod:`.fit`'s
docstring, "Method").
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_band, as_finite, check_positive
from ..exceptions import InputError, ShapeError
from ..frf import FRF, KIND_POWER
from ._lsq import Lines, Segment
from .models import LateralModel
from .response import (
    ComplexArray,
    FloatArray,
    ForceKind,
    _check_force,
    ground_from_axle_accelerance,
)

__all__ = ["LateralData", "Weights"]

Weights = Literal["auto", "relative", "coherence", "uniform"]


@dataclass(frozen=True)
class LateralData:
    """A measured lateral FRF with its operating conditions.

    Parameters
    ----------
    frf : FRF
        1x1 FRF of lateral acceleration (or displacement/velocity) per
        lateral force, any kind.
    speed : float, optional
        Travel speed ``V`` in m/s (> 0); needed by the relaxation-length and
        string models and by :func:`fit_joint`.
    force : {"ground", "axle"}
        Whether the force is the ground (contact-patch) force or the force
        at the wheel axle.
    wheel_mass : float
        Wheel mass between axle force transducer and tyre, kg (>= 0); used
        when ``force="axle"``.
    label : str
        Free label (for example ``"1.7 bar, 5 km/h"``).
    """

    frf: FRF
    speed: float | None = None
    force: ForceKind = "ground"
    wheel_mass: float = 0.0
    label: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.frf, FRF):
            raise InputError(f"frf: expected an FRF, got {type(self.frf).__name__}")
        if self.speed is not None:
            object.__setattr__(self, "speed", check_positive(self.speed, "speed"))
        _check_force(self.force)
        object.__setattr__(
            self, "wheel_mass", check_positive(self.wheel_mass, "wheel_mass", allow_zero=True)
        )

    @classmethod
    def from_frf(
        cls,
        frf: FRF,
        *,
        speed: float | None = None,
        force: ForceKind | None = None,
        wheel_mass: float | None = None,
        label: str | None = None,
    ) -> LateralData:
        """Build from an FRF, taking missing conditions from ``frf.meta``.

        Meta keys read: ``"speed_m_s"``, ``"force"``, ``"wheel_mass_kg"``,
        ``"label"`` (as written by :mod:`tyredamp.virtual.lateral_rig`).
        """
        meta = frf.meta
        sp = speed if speed is not None else _meta_number(meta, "speed_m_s", "m/s", None)
        fo = force if force is not None else meta.get("force", "ground")
        if not isinstance(fo, str):
            raise InputError(f"FRF meta 'force': expected 'ground' or 'axle', got {fo!r}")
        wm = (
            wheel_mass if wheel_mass is not None else _meta_number(meta, "wheel_mass_kg", "kg", 0.0)
        )
        lb = label if label is not None else str(meta.get("label", ""))
        return cls(
            frf=frf,
            speed=None if sp is None else float(sp),
            force=fo,  # type: ignore[arg-type]
            wheel_mass=float(0.0 if wm is None else wm),
            label=lb,
        )


def _meta_number(meta: dict[str, Any], key: str, unit: str, default: float | None) -> float | None:
    """A number from FRF meta (absent: ``default``); anything else is an InputError naming it."""
    if key not in meta:
        return default
    v = meta[key]
    if isinstance(v, bool) or not isinstance(v, int | float) or not np.isfinite(v):
        raise InputError(f"FRF meta {key!r}: expected a finite number in {unit}, got {v!r}")
    return float(v)


@dataclass(frozen=True, eq=False)
class _Prepared:
    """The lines to fit, shared by every model fitted to the same data and options."""

    data: LateralData
    frequency: FloatArray
    measured: ComplexArray  # accelerance at the data's force
    weights: FloatArray
    weights_name: str

    @property
    def omega(self) -> FloatArray:
        """Angular frequency, rad/s."""
        return 2.0 * np.pi * self.frequency

    def ground_receptance(self) -> ComplexArray:
        """Ground-force receptance of the data, m/N (for the starting values)."""
        d = self.data
        acc = self.measured
        a_g = ground_from_axle_accelerance(acc, d.wheel_mass) if d.force == "axle" else acc
        return np.asarray(a_g / (-(self.omega**2)), dtype=complex)

    def segment(
        self,
        cls: type[LateralModel],
        cond: dict[str, float],
        tmap: FloatArray | None = None,
        offset: FloatArray | None = None,
    ) -> Segment:
        """The residual of ``cls`` on these lines (:mod:`._lsq`; ``tmap``, ``offset`` there)."""
        d = self.data
        return Segment(cls, cond, self.lines, d.force, d.wheel_mass, tmap, offset)

    @cached_property
    def lines(self) -> Lines:
        """The lines with their per-line factors (:mod:`._lsq`), built once per preparation."""
        return Lines(self.frequency, self.measured, self.weights)


def _lines(frf: FRF, band: tuple[float, float] | None) -> slice:
    """The lines above 0 Hz within ``band``: a slice, as the axis increases strictly."""
    f = frf.frequency
    lo = int(np.searchsorted(f, 0.0, side="right"))
    hi = f.size
    if band is not None:
        b_lo, b_hi = as_band(band)
        lo = max(lo, int(np.searchsorted(f, b_lo, side="left")))
        hi = int(np.searchsorted(f, b_hi, side="right"))
    return slice(lo, max(lo, hi))


def _channel(frf: FRF, channel: tuple[int, int] | None) -> tuple[int, int]:
    if channel is None:
        if frf.n_out * frf.n_in != 1:
            raise ShapeError(
                f"channel: the FRF holds {frf.n_out}x{frf.n_in} FRFs, a lateral fit takes one; "
                "choose it with channel=(out, in), counted from 0 (command line: --channel OUT IN, "
                "counted from 1)"
            )
        return (0, 0)
    i, j = channel
    if not (0 <= i < frf.n_out and 0 <= j < frf.n_in):
        raise ShapeError(
            f"channel: expected (out, in) within {frf.n_out}x{frf.n_in}, got {channel}"
        )
    return i, j


def _weights(
    weights: Weights | ArrayLike, mag: FloatArray, coherence: FloatArray | None
) -> tuple[FloatArray, str]:
    mode = weights
    if mode == "auto":
        mode = "coherence" if coherence is not None else "relative"
    if mode == "relative":
        return 1.0 / mag, "relative"
    if mode == "uniform":
        return np.full(mag.size, 1.0 / float(np.sqrt(np.mean(mag**2)))), "uniform"
    if mode == "coherence":
        if coherence is None:
            raise InputError("weights: 'coherence' needs an FRF with coherence")
        g2 = np.clip(coherence, 1e-6, 1.0 - 1e-9)
        return 1.0 / (mag * np.sqrt((1.0 - g2) / g2)), "coherence"
    raise InputError(
        f"weights: expected 'auto', 'relative', 'coherence', 'uniform' or an array, got {weights!r}"
    )


def _prepare(
    data: LateralData | FRF,
    band: tuple[float, float] | None,
    weights: Weights | ArrayLike,
    channel: tuple[int, int] | None = None,
) -> _Prepared:
    """The fitted lines as views of the FRF (copies only where a conversion needs one)."""
    d = data if isinstance(data, LateralData) else LateralData.from_frf(data)
    frf = d.frf
    i, j = _channel(frf, channel)
    user_w: FloatArray | None = None
    if not isinstance(weights, str):
        user_w = as_finite(weights, "weights", ndim=1)
        if user_w.size != frf.n_freq:
            raise ShapeError(
                f"weights: expected {frf.n_freq} values (one per line), got {user_w.size}"
            )
        if np.any(user_w < 0):
            raise InputError("weights: expected values >= 0")
    sl = _lines(frf, band)
    n = sl.stop - sl.start
    if n < 4:
        raise InputError(
            f"the FRF has {n} line(s) above 0 Hz in the band; the lateral fit needs at least 4"
        )
    f = frf.frequency[sl]
    acc = frf.H[i, j, sl]
    k = KIND_POWER["accelerance"] - KIND_POWER[frf.kind]
    if k:  # as FRF.to: H (i omega)^k
        acc = acc * (1j * (2.0 * np.pi * f)) ** k
    mag = np.abs(acc)
    if np.any(mag == 0):
        raise InputError(
            "the FRF is exactly 0 at some lines; drop them (relative weights undefined)"
        )
    coh = None  # multiple coherence refers to all inputs (FRF.select)
    if frf.coherence is not None and frf.n_in == 1:
        coh = frf.coherence[i, sl]
    if user_w is not None:
        wts, wname = user_w[sl], "user"
    else:
        wts, wname = _weights(weights, mag, coh)
    del mag
    if np.count_nonzero(wts) < 4:
        raise InputError("weights: expected at least 4 lines with non-zero weight")
    if d.force == "axle" and np.any(1.0 - d.wheel_mass * acc == 0):  # A_g infinite
        raise InputError("accelerance: 1 - wheel_mass * A_axle is 0 at some line (A_g infinite)")
    return _Prepared(d, f, acc, np.asarray(wts, dtype=float), wname)
