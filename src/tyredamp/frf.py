"""The frequency response function (FRF) data object.

An :class:`FRF` holds a matrix of complex frequency responses on one
frequency axis, always as a 3-D array ``H[out, in, line]`` (the convention of
python-control's ``FrequencyResponseData``), with labelled output and input
channels. It is immutable: conversions, slicing and band selection return new
objects.

Conventions (spec ``radial-damping.md``): time dependence ``e^{i omega t}``;
receptance ``H = X/F`` in m/N, mobility ``V/F = i omega H`` in m/(s N),
accelerance ``A/F = -omega^2 H`` in m/(s^2 N).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_band, as_finite, as_frequency
from .exceptions import InputError, ShapeError

__all__ = ["FRF", "KINDS", "UNITS", "Channel", "FRFKind", "drive_pairs"]

FRFKind = Literal["receptance", "mobility", "accelerance"]
KINDS: tuple[FRFKind, ...] = ("receptance", "mobility", "accelerance")
#: SI unit of each FRF kind (response per unit force).
UNITS: dict[str, str] = {
    "receptance": "m/N",
    "mobility": "m/(s N)",
    "accelerance": "m/(s^2 N)",
}
#: Power ``k`` of ``(i omega)^k`` that turns a receptance into each kind (the one table).
KIND_POWER: dict[str, int] = {"receptance": 0, "mobility": 1, "accelerance": 2}

_DIRECTIONS = {
    1: "+X",
    2: "+Y",
    3: "+Z",
    -1: "-X",
    -2: "-Y",
    -3: "-Z",
    4: "+RX",
    5: "+RY",
    6: "+RZ",
    -4: "-RX",
    -5: "-RY",
    -6: "-RZ",
    0: "scalar",
}


@dataclass(frozen=True)
class Channel:
    """One measured point and direction.

    Parameters
    ----------
    node : int
        Node (point) number, as in UFF files.
    direction : int
        UFF direction code: 1, 2, 3 for +X, +Y, +Z (negative for the opposite
        sense), 4-6 for rotations, 0 for scalar. Tyre radial points use 3
        (local radial axis).
    angle_deg : float or None
        Circumferential angle of the point on the tyre in degrees, if known.
    name : str
        Free label (for example ``"acc07"``).
    """

    node: int
    direction: int = 3
    angle_deg: float | None = None
    name: str = ""

    def __post_init__(self) -> None:
        if int(self.node) != self.node:
            raise InputError(f"Channel.node: expected an integer, got {self.node!r}")
        if self.direction not in _DIRECTIONS:
            raise InputError(
                f"Channel.direction: expected a UFF direction code in -6..6, got {self.direction!r}"
            )
        if self.angle_deg is not None and not np.isfinite(self.angle_deg):
            raise InputError(f"Channel.angle_deg: expected a finite angle, got {self.angle_deg}")

    @property
    def label(self) -> str:
        """Short text label such as ``"5+Z"`` (or the name when given)."""
        return self.name or f"{self.node}{_DIRECTIONS[self.direction]}"


def drive_pairs(outputs: Sequence[Channel], inputs: Sequence[Channel]) -> list[tuple[int, int]]:
    """Pairs ``(i_out, i_in)`` of an output at the node and direction (either sense)
    of an input, in the order of the inputs: the drive points."""
    return [
        (i, j)
        for j, ci in enumerate(inputs)
        for i, co in enumerate(outputs)
        if co.node == ci.node and abs(co.direction) == abs(ci.direction)
    ]


def _channels(ch: Sequence[Channel | int] | None, n: int, name: str) -> tuple[Channel, ...]:
    if ch is None:
        return tuple(Channel(node=i + 1) for i in range(n))
    out = tuple(c if isinstance(c, Channel) else Channel(node=int(c)) for c in ch)
    if len(out) != n:
        raise ShapeError(f"{name}: expected {n} channels to match H, got {len(out)}")
    return out


@dataclass(frozen=True, eq=False)
class FRF:
    """A matrix of frequency response functions on one frequency axis.

    Parameters
    ----------
    frequency : array_like, shape (n_freq,)
        Frequency in Hz, non-negative and strictly increasing.
    H : array_like, complex, shape (n_out, n_in, n_freq)
        The responses. A 1-D array is taken as one output and one input; a 2-D
        array as ``(n_out, n_freq)`` with one input.
    kind : {"receptance", "mobility", "accelerance"}
        Which response per unit force ``H`` holds (SI units, see :data:`UNITS`).
    outputs, inputs : sequence of Channel or int, optional
        Channel labels; integers are taken as node numbers. Default nodes
        1..n.
    coherence : array_like, shape (n_out, n_freq), optional
        Multiple coherence of each output with all inputs (the ordinary
        coherence when there is one input), in [0, 1].
    meta : dict, optional
        Free metadata (test description, estimator, number of averages ...).
    variance : array_like, shape (n_out, n_in, n_freq), optional
        Variance ``E|H_est - H|^2`` of each estimate of ``H`` (real, >= 0, in
        the unit of ``H`` squared), as estimated from the measurement noise
        by the FRF estimator; the weights of a maximum-likelihood fit.
    input_noise : array_like, shape (n_in, n_freq), optional
        Relative variance ``r`` of the error the input (force) noise makes,
        common to all outputs (dimensionless, >= 0): the error of column ``k``
        at a line holds ``-H[:, k] n`` with one complex noise ``n`` of variance
        ``r[k]`` for every output (errors in variables: Pintelon & Schoukens,
        *System Identification*, 2nd ed. 2012, sec. 2.5), which ``variance``
        counts as ``r |H|^2`` on the diagonal only. Given by the cyclic
        one-input estimate (:mod:`tyredamp.signal.cyclic_variance`); the
        final modal fit then takes the outputs' correlation into its standard
        errors (:mod:`tyredamp.modal.sandwich`). Kept in NPZ, CSV and UFF
        files written by tyredamp.

    Examples
    --------
    The receptance of a mass of 1 kg on a spring of 1000 N/m with 1 % damping:

    >>> import numpy as np
    >>> from tyredamp import FRF
    >>> f = np.linspace(0.0, 20.0, 401)  # Hz
    >>> w = 2 * np.pi * f
    >>> frf = FRF(f, 1 / (1000 - w**2 + 2j * 0.01 * np.sqrt(1000) * w), kind="receptance")
    >>> frf.H.shape  # always (outputs, inputs, lines)
    (1, 1, 401)
    >>> frf.band(4.0, 6.0).n_freq  # a new FRF of the lines from 4 to 6 Hz
    41
    >>> acc = frf.accelerance()  # -omega^2 H, in (m/s^2)/N
    >>> acc.kind
    'accelerance'
    """

    frequency: NDArray[np.float64]
    H: NDArray[np.complex128]
    kind: FRFKind = "receptance"
    outputs: tuple[Channel, ...] = ()
    inputs: tuple[Channel, ...] = ()
    coherence: NDArray[np.float64] | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    variance: NDArray[np.float64] | None = None
    input_noise: NDArray[np.float64] | None = None

    def __init__(
        self,
        frequency: ArrayLike,
        H: ArrayLike,
        kind: FRFKind = "receptance",
        outputs: Sequence[Channel | int] | None = None,
        inputs: Sequence[Channel | int] | None = None,
        coherence: ArrayLike | None = None,
        meta: dict[str, Any] | None = None,
        variance: ArrayLike | None = None,
        input_noise: ArrayLike | None = None,
    ) -> None:
        f = as_frequency(frequency, "frequency")
        h = as_finite(H, "H", dtype=complex)
        if h.ndim == 1:
            h = h[None, None, :]
        elif h.ndim == 2:
            h = h[:, None, :]
        if h.ndim != 3:
            raise ShapeError(f"H: expected shape (n_out, n_in, n_freq), got {h.shape}")
        if h.shape[2] != f.size:
            raise ShapeError(
                f"H: expected {f.size} frequency lines (last axis) to match frequency, "
                f"got shape {h.shape}"
            )
        if kind not in KINDS:
            raise InputError(f"kind: expected one of {KINDS}, got {kind!r}")
        coh = None
        if coherence is not None:
            coh = as_finite(coherence, "coherence")
            if coh.ndim == 1 and h.shape[0] == 1:
                coh = coh[None, :]
            if coh.shape != (h.shape[0], f.size):
                raise ShapeError(
                    f"coherence: expected shape {(h.shape[0], f.size)}, got {coh.shape}"
                )
            if np.any(coh < -1e-9) or np.any(coh > 1 + 1e-9):
                raise InputError("coherence: expected values in [0, 1]")
            coh = np.clip(coh, 0.0, 1.0)
            coh.setflags(write=False)
        var = None
        if variance is not None:
            var = as_finite(variance, "variance")
            if var.shape != h.shape:
                if var.size == h.size:
                    var = var.reshape(h.shape)
                else:
                    raise ShapeError(f"variance: expected shape {h.shape} like H, got {var.shape}")
            if np.any(var < 0):
                raise InputError("variance: expected values >= 0")
            var = var.copy()
            var.setflags(write=False)
        rin = None if input_noise is None else _input_noise(input_noise, h.shape)
        f = f.copy()
        h = h.copy()
        f.setflags(write=False)
        h.setflags(write=False)
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "H", h)
        object.__setattr__(self, "kind", kind)
        object.__setattr__(self, "outputs", _channels(outputs, h.shape[0], "outputs"))
        object.__setattr__(self, "inputs", _channels(inputs, h.shape[1], "inputs"))
        object.__setattr__(self, "coherence", coh)
        object.__setattr__(self, "meta", dict(meta or {}))
        object.__setattr__(self, "variance", var)
        object.__setattr__(self, "input_noise", rin)

    # ------------------------------------------------------------------ views
    @property
    def n_out(self) -> int:
        """Number of output (response) channels."""
        return int(self.H.shape[0])

    @property
    def n_in(self) -> int:
        """Number of input (force) channels."""
        return int(self.H.shape[1])

    @property
    def n_freq(self) -> int:
        """Number of frequency lines."""
        return int(self.H.shape[2])

    @property
    def omega(self) -> NDArray[np.float64]:
        """Angular frequency ``2 pi f`` in rad/s, shape (n_freq,)."""
        return 2.0 * np.pi * self.frequency

    @property
    def unit(self) -> str:
        """SI unit of ``H``."""
        return UNITS[self.kind]

    def __repr__(self) -> str:
        return (
            f"FRF(kind={self.kind!r}, n_out={self.n_out}, n_in={self.n_in}, "
            f"n_freq={self.n_freq}, band=[{self.frequency[0]:g}, {self.frequency[-1]:g}] Hz)"
        )

    def _new(self, **changes: Any) -> FRF:
        base: dict[str, Any] = {
            "frequency": self.frequency,
            "H": self.H,
            "kind": self.kind,
            "outputs": self.outputs,
            "inputs": self.inputs,
            "coherence": self.coherence,
            "meta": self.meta,
            "variance": self.variance,
            "input_noise": self.input_noise,
        }
        base.update(changes)
        return FRF(**base)

    # ------------------------------------------------------------ conversions
    def to(self, kind: FRFKind, *, at_zero: Literal["drop", "raise"] = "drop") -> FRF:
        """Return the same responses as another kind.

        Multiplies by ``(i omega)^k`` with ``k`` the difference of the kinds'
        powers (receptance 0, mobility 1, accelerance 2).

        At 0 Hz a conversion that divides by ``omega`` (mobility or accelerance
        to receptance, accelerance to mobility) is undefined. With
        ``at_zero="drop"`` (default) the 0 Hz line is removed from the result;
        with ``"raise"`` an :class:`InputError` is raised. Conversions that
        multiply by ``omega`` give exactly 0 there.
        """
        if kind not in KINDS:
            raise InputError(f"kind: expected one of {KINDS}, got {kind!r}")
        k = KIND_POWER[kind] - KIND_POWER[self.kind]
        if k == 0:
            return self
        frf = self
        if k < 0 and self.frequency[0] == 0.0:
            if at_zero == "raise":
                raise InputError(
                    f"to: converting {self.kind} to {kind} divides by omega, undefined at 0 Hz"
                )
            if at_zero != "drop":
                raise InputError(f"at_zero: expected 'drop' or 'raise', got {at_zero!r}")
            if self.n_freq == 1:
                raise InputError(
                    "the FRF's only frequency line is 0 Hz: nothing left to convert to another kind"
                )
            frf = self.select_lines(slice(1, None))
        factor = (1j * frf.omega) ** k
        var = None if frf.variance is None else frf.variance * np.abs(factor) ** 2
        return frf._new(H=frf.H * factor, kind=kind, variance=var)

    def receptance(self) -> FRF:
        """Shorthand for ``to("receptance")``."""
        return self.to("receptance")

    def mobility(self) -> FRF:
        """Shorthand for ``to("mobility")``."""
        return self.to("mobility")

    def accelerance(self) -> FRF:
        """Shorthand for ``to("accelerance")``."""
        return self.to("accelerance")

    # --------------------------------------------------------------- slicing
    def select_lines(self, index: slice | NDArray[Any] | Sequence[int]) -> FRF:
        """Return the FRF on a subset of frequency lines (kept in order).

        A slice is taken as such (the memory of the lines it holds, not of every
        line); other indices as an integer array.
        """
        idx: Any = np.arange(self.n_freq)[index] if not isinstance(index, slice) else index
        if isinstance(idx, slice) and len(range(self.n_freq)[idx]) == 0:
            raise InputError("select_lines: the selection holds no frequency line")
        if not isinstance(idx, slice) and idx.size == 0:
            raise InputError("select_lines: the selection holds no frequency line")
        coh = None if self.coherence is None else self.coherence[:, idx]
        var = None if self.variance is None else self.variance[:, :, idx]
        rin = None if self.input_noise is None else self.input_noise[:, idx]
        return self._new(
            frequency=self.frequency[idx],
            H=self.H[:, :, idx],
            coherence=coh,
            variance=var,
            input_noise=rin,
        )

    def band(self, f_lo: float, f_hi: float) -> FRF:
        """Return the lines with ``f_lo <= f <= f_hi`` (Hz)."""
        f_lo, f_hi = as_band((f_lo, f_hi))
        mask = (self.frequency >= f_lo) & (self.frequency <= f_hi)
        if not np.any(mask):
            raise InputError(
                f"band: no line in [{f_lo:g}, {f_hi:g}] Hz; data cover "
                f"[{self.frequency[0]:g}, {self.frequency[-1]:g}] Hz"
            )
        return self.select_lines(np.flatnonzero(mask))

    def select(
        self,
        outputs: Sequence[int] | slice | None = None,
        inputs: Sequence[int] | slice | None = None,
    ) -> FRF:
        """Return a sub-matrix by output and input positions (not node numbers)."""
        oi = np.arange(self.n_out)[outputs if outputs is not None else slice(None)]
        ii = np.arange(self.n_in)[inputs if inputs is not None else slice(None)]
        oi, ii = np.atleast_1d(oi), np.atleast_1d(ii)
        if oi.size == 0 or ii.size == 0:
            raise InputError("select: the selection holds no channel")
        coh = None if self.coherence is None else self.coherence[oi]
        if coh is not None and ii.size != self.n_in:
            coh = None  # multiple coherence refers to all inputs
        return self._new(
            H=self.H[np.ix_(oi, ii)],
            outputs=[self.outputs[i] for i in oi],
            inputs=[self.inputs[i] for i in ii],
            coherence=coh,
            variance=None if self.variance is None else self.variance[np.ix_(oi, ii)],
            input_noise=None if self.input_noise is None else self.input_noise[ii],
        )

    def output_index(self, node: int, direction: int | None = None) -> int:
        """Position of the output channel with this node (and direction)."""
        return _find(self.outputs, node, direction, "outputs")

    def input_index(self, node: int, direction: int | None = None) -> int:
        """Position of the input channel with this node (and direction)."""
        return _find(self.inputs, node, direction, "inputs")

    def drive_points(self) -> list[tuple[int, int]]:
        """Pairs ``(i_out, i_in)`` where output and input are the same node and direction."""
        return drive_pairs(self.outputs, self.inputs)

    def with_H(self, H: ArrayLike, kind: FRFKind | None = None) -> FRF:
        """A copy with new responses on the same axis and channels (no coherence or variance)."""
        return self._new(
            H=H, kind=kind or self.kind, coherence=None, variance=None, input_noise=None
        )

    # ---------------------------------------------------------------- xarray
    def to_xarray(self) -> Any:
        """The FRF as an :class:`xarray.Dataset` with named dimensions (imports xarray).

        Dimensions ``output``, ``input``, ``frequency`` (coordinate in Hz);
        variables ``H`` (complex, the unit of :attr:`kind`), optional
        ``coherence`` (output, frequency) and ``variance`` (output, input,
        frequency); channel coordinates ``output_node``,
        ``output_direction``, ``output_angle_deg`` (NaN when unknown),
        ``output_name`` (and the same for ``input``), the labels as the
        ``output``/``input`` coordinates; attributes ``kind``, ``unit``,
        ``tyredamp`` (``"frf 1"``) and ``meta`` (JSON text).
        """
        import json

        import xarray as xr

        def chan(prefix: str, chs: tuple[Channel, ...]) -> dict[str, Any]:
            return {
                prefix: (prefix, [c.label for c in chs]),
                f"{prefix}_node": (prefix, np.array([c.node for c in chs], dtype=np.int32)),
                f"{prefix}_direction": (
                    prefix,
                    np.array([c.direction for c in chs], dtype=np.int32),
                ),
                f"{prefix}_angle_deg": (
                    prefix,
                    np.array([np.nan if c.angle_deg is None else c.angle_deg for c in chs]),
                ),
                f"{prefix}_name": (prefix, [c.name for c in chs]),
            }

        data: dict[str, Any] = {"H": (("output", "input", "frequency"), self.H)}
        if self.coherence is not None:
            data["coherence"] = (("output", "frequency"), self.coherence)
        if self.variance is not None:
            data["variance"] = (("output", "input", "frequency"), self.variance)
        coords = {
            "frequency": ("frequency", self.frequency, {"units": "Hz"}),
            **chan("output", self.outputs),
            **chan("input", self.inputs),
        }
        ds = xr.Dataset(data, coords=coords)
        ds["H"].attrs["units"] = self.unit
        ds.attrs.update(
            tyredamp="frf 1",
            kind=self.kind,
            unit=self.unit,
            meta=json.dumps(self.meta, default=str),
        )
        return ds

    @classmethod
    def from_xarray(cls, ds: Any) -> FRF:
        """Inverse of :meth:`to_xarray` (also from ``H_real``/``H_imag`` as stored in files).

        Raises
        ------
        InputError
            Missing ``H`` or dimensions, or invalid values (checked as in the
            constructor).
        """
        import json

        names = set(getattr(ds, "data_vars", {}))
        if "H" in names:
            h = np.asarray(ds["H"].transpose("output", "input", "frequency").values)
        elif {"H_real", "H_imag"} <= names:
            order = ("output", "input", "frequency")
            h = np.asarray(ds["H_real"].transpose(*order).values) + 1j * np.asarray(
                ds["H_imag"].transpose(*order).values
            )
        else:
            raise InputError("ds: expected a variable 'H' (or 'H_real' and 'H_imag')")

        def chans(prefix: str) -> list[Channel]:
            try:
                node = np.asarray(ds[f"{prefix}_node"].values)
                direc = np.asarray(ds[f"{prefix}_direction"].values)
                ang = np.asarray(ds[f"{prefix}_angle_deg"].values, dtype=float)
                name = [str(v) for v in np.asarray(ds[f"{prefix}_name"].values)]
            except KeyError as exc:
                raise InputError(f"ds: missing channel coordinate {exc.args[0]!r}") from None
            return [
                Channel(
                    int(node[i]),
                    int(direc[i]),
                    None if np.isnan(ang[i]) else float(ang[i]),
                    name[i],
                )
                for i in range(node.size)
            ]

        try:
            meta = json.loads(str(ds.attrs.get("meta", "{}")))
        except json.JSONDecodeError:
            raise InputError("ds.attrs['meta']: not JSON text") from None
        coh = (
            ds["coherence"].transpose("output", "frequency").values
            if "coherence" in names
            else None
        )
        var = (
            ds["variance"].transpose("output", "input", "frequency").values
            if "variance" in names
            else None
        )
        return cls(
            np.asarray(ds["frequency"].values),
            h,
            kind=str(ds.attrs.get("kind", "")),  # type: ignore[arg-type]
            outputs=chans("output"),
            inputs=chans("input"),
            coherence=coh,
            meta=meta if isinstance(meta, dict) else {},
            variance=var,
        )

    def plot(self, **kwargs: Any) -> Any:
        """Bode plot of the FRF; see :func:`tyredamp.plot.plot_frf` (imports matplotlib)."""
        from .plot import plot_frf  # type: ignore[attr-defined,unused-ignore]

        return plot_frf(self, **kwargs)


def _input_noise(values: ArrayLike, shape: tuple[int, ...]) -> NDArray[np.float64]:
    """The checked, read-only ``input_noise`` (n_in, n_freq) of an FRF of ``H.shape``
    ``shape`` (:class:`FRF`)."""
    r = as_finite(values, "input_noise")
    want = (shape[1], shape[2])
    if r.shape != want:
        if r.size != shape[1] * shape[2]:
            raise ShapeError(
                f"input_noise: expected shape {want} (inputs, frequency lines), got {r.shape}"
            )
        r = r.reshape(want)
    if np.any(r < 0):
        raise InputError("input_noise: expected relative variances >= 0")
    r = r.copy()
    r.setflags(write=False)
    return r


def _find(chs: tuple[Channel, ...], node: int, direction: int | None, name: str) -> int:
    for i, c in enumerate(chs):
        if c.node == node and (direction is None or c.direction == direction):
            return i
    raise InputError(
        f"{name}: no channel with node {node}"
        + (f" and direction {direction}" if direction is not None else "")
    )
