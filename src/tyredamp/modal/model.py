"""The modal model: poles and mode shapes that synthesise an FRF matrix.

One representation serves both models of the paper: mode shapes ``psi``
scaled as in spec eq. [10], so that the residue of mode ``n`` between output
``j`` and input ``k`` is ``R_jkn = psi_out[j, n] * psi_in[k, n]``. For real
(proportionally damped) modes ``psi = phi / sqrt(2 i Omega_n)`` with
mass-normalised real ``phi`` (spec eq. [3], with the factor 2 the printed
paper drops).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, as_frequency
from ..exceptions import InputError, ShapeError
from ..frf import FRF, Channel, FRFKind
from ..mechanics.modal_sum import kind_factor, modal_sum_receptance, pole_quantities
from .statistics.quality import FitQuality

__all__ = ["ModalModel", "ModeKind"]

#: lines per block of :meth:`ModalModel.receptance` (the modal sum's per-mode
#: columns of a block, not of every line)
SYNTH_BLOCK = 1 << 15

ModeKind = Literal["complex", "real"]


@dataclass(frozen=True, eq=False)
class ModalModel:
    """Identified (or exact) modal model of an FRF matrix.

    Parameters
    ----------
    poles : array_like, complex, shape (m,)
        One pole of each pair, ``p_n = -sigma_n + i Omega_n`` in rad/s,
        ``Im p_n > 0``.
    psi_out : array_like, complex, shape (n_out, m)
        Mode shapes at the outputs in the eq. [10] scaling.
    psi_in : array_like, complex, shape (n_in, m)
        Mode shapes at the inputs (drive points) in the same scaling.
    mode_kind : {"complex", "real"}
        ``"real"`` when the shapes are ``phi / sqrt(2 i Omega_n)`` with real
        ``phi`` (eq. [2]/[3]); ``"complex"`` for general viscous modes (eq. [10]).
    outputs, inputs : sequence of Channel, optional
        Labels of the rows of ``psi_out`` and ``psi_in``.
    lower_residual : array_like, shape (n_out, n_in), optional
        Lower residual ``-L / omega^2`` term coefficient (kg^-1), modes below
        the band: adds ``L / s^2`` to the receptance.
    upper_residual : array_like, shape (n_out, n_in), optional
        Upper residual (m/N), modes above the band: adds a constant receptance.
    std : dict of str to ndarray, optional
        Standard errors: ``"frequency_hz"`` (m,), ``"damping_ratio"`` (m,),
        ``"psi_out"`` (n_out, m) real magnitude of the complex standard error.
    meta : dict, optional
        Fit information (band, model order, rmsd, ...).
    residual_modes : ModalModel, optional
        Modes outside the analysis band that the fit used as residual terms
        (for example the tail of a mode just above the band). They are not
        modes of this model (``n_modes``, ``poles`` and the shapes exclude
        them) but :meth:`receptance` adds their contribution, so the model
        reproduces the fitted FRFs. Same outputs and inputs.
    quality : FitQuality, optional
        Fit quality of an identified model: goodness of fit against the
        noise, each mode's test statistic and why it was kept, the rejected
        candidates (per-mode entries follow the sorted poles).

    The arrays of a model are read-only, as those of :class:`~tyredamp.frf.FRF`.
    """

    poles: NDArray[np.complex128]
    psi_out: NDArray[np.complex128]
    psi_in: NDArray[np.complex128]
    mode_kind: ModeKind = "complex"
    outputs: tuple[Channel, ...] = ()
    inputs: tuple[Channel, ...] = ()
    lower_residual: NDArray[np.complex128] | None = None
    upper_residual: NDArray[np.complex128] | None = None
    std: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    residual_modes: ModalModel | None = None
    quality: FitQuality | None = None

    def __init__(
        self,
        poles: ArrayLike,
        psi_out: ArrayLike,
        psi_in: ArrayLike,
        mode_kind: ModeKind = "complex",
        outputs: Sequence[Channel | int] | None = None,
        inputs: Sequence[Channel | int] | None = None,
        lower_residual: ArrayLike | None = None,
        upper_residual: ArrayLike | None = None,
        std: dict[str, ArrayLike] | None = None,
        meta: dict[str, Any] | None = None,
        residual_modes: ModalModel | None = None,
        quality: FitQuality | None = None,
    ) -> None:
        p = as_finite(poles, "poles", ndim=1, dtype=complex, allow_empty=True)
        po = as_finite(psi_out, "psi_out", ndim=2, dtype=complex, allow_empty=True)
        pi = as_finite(psi_in, "psi_in", ndim=2, dtype=complex, allow_empty=True)
        if po.shape[1] != p.size or pi.shape[1] != p.size:
            raise ShapeError(
                f"psi_out/psi_in: expected {p.size} columns (one per pole), "
                f"got {po.shape} and {pi.shape}"
            )
        if np.any(p.imag <= 0):
            raise InputError("poles: expected Im p > 0 (one member of each conjugate pair)")
        if mode_kind not in ("complex", "real"):
            raise InputError(f"mode_kind: expected 'complex' or 'real', got {mode_kind!r}")
        order = np.argsort(p.imag)
        p, po, pi = p[order], po[:, order], pi[:, order]
        oc = tuple(
            c if isinstance(c, Channel) else Channel(node=int(c))
            for c in (outputs if outputs is not None else range(1, po.shape[0] + 1))
        )
        ic = tuple(
            c if isinstance(c, Channel) else Channel(node=int(c))
            for c in (inputs if inputs is not None else range(1, pi.shape[0] + 1))
        )
        if len(oc) != po.shape[0] or len(ic) != pi.shape[0]:
            raise ShapeError("outputs/inputs: expected one channel per row of psi_out/psi_in")
        res: list[NDArray[np.complex128] | None] = []
        for r, name in ((lower_residual, "lower_residual"), (upper_residual, "upper_residual")):
            if r is None:
                res.append(None)
                continue
            ra = as_finite(r, name, dtype=complex)
            if ra.shape != (po.shape[0], pi.shape[0]):
                raise ShapeError(
                    f"{name}: expected shape {(po.shape[0], pi.shape[0])}, got {ra.shape}"
                )
            res.append(ra.copy())
        stds: dict[str, NDArray[np.float64]] = {}
        for key, val in (std or {}).items():
            arr = np.array(val, dtype=float)
            if key in ("frequency_hz", "damping_ratio") and arr.shape != (p.size,):
                raise ShapeError(f"std[{key!r}]: expected shape ({p.size},), got {arr.shape}")
            stds[key] = arr[..., order] if arr.ndim and arr.shape[-1] == p.size else arr
        object.__setattr__(self, "poles", p)
        object.__setattr__(self, "psi_out", po)
        object.__setattr__(self, "psi_in", pi)
        object.__setattr__(self, "mode_kind", mode_kind)
        object.__setattr__(self, "outputs", oc)
        object.__setattr__(self, "inputs", ic)
        object.__setattr__(self, "lower_residual", res[0])
        object.__setattr__(self, "upper_residual", res[1])
        object.__setattr__(self, "std", stds)
        object.__setattr__(self, "meta", dict(meta or {}))
        if residual_modes is not None:
            if not isinstance(residual_modes, ModalModel):
                raise InputError(
                    f"residual_modes: expected a ModalModel, got {type(residual_modes).__name__}"
                )
            if residual_modes.psi_out.shape[0] != po.shape[0] or (
                residual_modes.psi_in.shape[0] != pi.shape[0]
            ):
                raise ShapeError(
                    "residual_modes: expected the same outputs and inputs as the model, got "
                    f"{residual_modes.psi_out.shape[0]} and {residual_modes.psi_in.shape[0]}"
                )
        object.__setattr__(self, "residual_modes", residual_modes)
        if quality is not None:
            if not isinstance(quality, FitQuality):
                raise InputError(f"quality: expected a FitQuality, got {type(quality).__name__}")
            if quality.statistic.size != p.size:
                raise ShapeError(
                    f"quality: expected {p.size} per-mode entries, got {quality.statistic.size}"
                )
            quality = quality.reordered(order)
        object.__setattr__(self, "quality", quality)
        for arr in (p, po, pi, *(r for r in res if r is not None), *stds.values()):
            arr.setflags(write=False)

    @classmethod
    def from_real_modes(
        cls,
        frequency_hz: ArrayLike,
        damping_ratio: ArrayLike,
        phi_out: ArrayLike,
        phi_in: ArrayLike,
        **kwargs: Any,
    ) -> ModalModel:
        """Build a real-mode model from ``f_n``, ``zeta_n`` and mass-normalised ``phi`` (eq. [2]).

        ``phi_out`` has shape (n_out, m), ``phi_in`` (n_in, m), real, in 1/sqrt(kg).
        """
        from ..mechanics.modal_sum import pole_from_frequency_damping

        p = pole_from_frequency_damping(frequency_hz, damping_ratio)
        po = as_finite(phi_out, "phi_out", ndim=2)
        pi = as_finite(phi_in, "phi_in", ndim=2)
        scale = 1.0 / np.sqrt(2j * p.imag)
        return cls(p, po * scale, pi * scale, mode_kind="real", **kwargs)

    # ----------------------------------------------------------- derived
    @property
    def n_modes(self) -> int:
        """Number of modes (conjugate pairs)."""
        return int(self.poles.size)

    @property
    def omega_n(self) -> NDArray[np.float64]:
        """Undamped natural frequency ``|p_n|`` in rad/s."""
        return np.abs(self.poles)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """Natural frequency ``|p_n| / 2 pi`` in Hz."""
        return pole_quantities(self.poles)[0]

    @property
    def damped_frequency_hz(self) -> NDArray[np.float64]:
        """Damped natural frequency ``Omega_n / 2 pi`` in Hz."""
        return self.poles.imag / (2 * np.pi)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta_n = -Re p_n / |p_n|``."""
        return pole_quantities(self.poles)[1]

    @property
    def residues(self) -> NDArray[np.complex128]:
        """``R[j, k, n] = psi_out[j, n] psi_in[k, n]`` (eq. [3]/[10]), shape (n_out, n_in, m)."""
        return np.einsum("jn,kn->jkn", self.psi_out, self.psi_in)

    @property
    def phi_out(self) -> NDArray[np.float64]:
        """Real shapes ``phi = Re(psi sqrt(2 i Omega))`` at the outputs (eq. [3]), 1/sqrt(kg)."""
        return np.real(self.psi_out * np.sqrt(2j * self.poles.imag))

    def second_order_shapes(self) -> NDArray[np.complex128]:
        """``Psi^_n = psi_n sqrt(2 i Omega_n)`` at the outputs (spec step 7).

        ``Re Psi^_n`` is close to the mass-normalised real mode ``phi_n``;
        ``Im Psi^_n`` comes from non-proportional damping. The branch of the
        square root is fixed so that ``Re Psi^`` has its largest entry positive.
        """
        shp = self.psi_out * np.sqrt(2j * self.poles.imag)
        idx = np.argmax(np.abs(shp.real), axis=0)
        sign = np.sign(shp.real[idx, np.arange(self.n_modes)])
        sign[sign == 0] = 1
        return shp * sign

    # ---------------------------------------------------------- synthesis
    def receptance(self, frequency: ArrayLike) -> NDArray[np.complex128]:
        """Receptance matrix (eq. [10] plus residuals), shape (n_out, n_in, n_freq).

        Synthesised in blocks of :data:`SYNTH_BLOCK` lines: besides the result,
        the memory does not grow with the lines (the modal sum forms a column
        per mode and line).
        """
        f = as_frequency(frequency)
        if self.lower_residual is not None and np.any(f == 0):
            raise InputError("frequency: the lower residual L/s^2 is undefined at 0 Hz")
        if f.size <= SYNTH_BLOCK:
            return self._receptance_block(f)
        h = np.empty((self.psi_out.shape[0], self.psi_in.shape[0], f.size), np.complex128)
        for a in range(0, f.size, SYNTH_BLOCK):
            h[:, :, a : a + SYNTH_BLOCK] = self._receptance_block(f[a : a + SYNTH_BLOCK])
        return h

    def _receptance_block(self, f: NDArray[np.float64]) -> NDArray[np.complex128]:
        """:meth:`receptance` of the lines ``f`` (Hz) at once."""
        h = modal_sum_receptance(f, self.poles, self.psi_out, self.psi_in)
        if self.residual_modes is not None:
            h += self.residual_modes.receptance(f)
        if self.upper_residual is not None:
            h += self.upper_residual[:, :, None]
        if self.lower_residual is not None:
            h += self.lower_residual[:, :, None] / (2j * np.pi * f) ** 2
        return h

    def frf(self, frequency: ArrayLike, kind: FRFKind = "receptance") -> FRF:
        """Synthesised :class:`FRF` of this model at ``frequency`` (Hz)."""
        f = as_frequency(frequency)
        h = self.receptance(f)
        h *= kind_factor(2 * np.pi * f, kind)
        return FRF(
            f,
            h,
            kind=kind,
            outputs=self.outputs,
            inputs=self.inputs,
            meta={"source": f"{self.mode_kind}-mode model"},
        )

    # ------------------------------------------------------- serialisation
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (complex numbers as ``[re, im]``); see :meth:`from_dict`.

        Layout::

            {"mode_kind": "complex" | "real",
             "outputs": [{"node", "direction", "angle_deg", "name"}, ...],
             "inputs": [...],
             "modes": [{"frequency_hz", "damping_ratio", "pole": [re, im],
                        "shape": [[re, im] per output]  (eq. [10] scaling),
                        "participation": [[re, im] per input],
                        "std": {"frequency_hz", "damping_ratio",
                                "shape": [per output] (optional),
                                "participation": [per input] (optional)}}, ...],
             "lower_residual": [[[re, im] per input] per output] | null,
             "upper_residual": ... | null,
             "meta": {...},
             "residual_modes": {same layout, without residuals} | null}

        ``residual_modes`` (out-of-band modes used as residual terms) is
        optional: readers that ignore it still get every in-band mode.
        """

        def c2(z: Any) -> Any:
            z = np.asarray(z)
            return np.stack([z.real, z.imag], axis=-1).tolist()

        modes = []
        for n in range(self.n_modes):
            std: dict[str, Any] = {}
            for key in ("frequency_hz", "damping_ratio"):
                if key in self.std:
                    std[key] = float(self.std[key][n])
            if "psi_out" in self.std:
                std["shape"] = np.asarray(self.std["psi_out"])[:, n].tolist()
            if "psi_in" in self.std:
                std["participation"] = np.asarray(self.std["psi_in"])[:, n].tolist()
            modes.append(
                {
                    "frequency_hz": float(self.frequency_hz[n]),
                    "damping_ratio": float(self.damping_ratio[n]),
                    "pole": c2(self.poles[n]),
                    "shape": c2(self.psi_out[:, n]),
                    "participation": c2(self.psi_in[:, n]),
                    "std": std,
                }
            )
            if self.quality is not None:
                t = float(self.quality.statistic[n])
                h = float(self.quality.thresholds[n])
                modes[-1]["test"] = {
                    "statistic": t if np.isfinite(t) else None,
                    # the threshold applied to this mode; the base one beside it
                    "threshold": h if np.isfinite(h) else None,
                    "base_threshold": self.quality.threshold,
                    "kept": self.quality.kept[n],
                }
        return {
            "mode_kind": self.mode_kind,
            "outputs": [_channel_dict(c) for c in self.outputs],
            "inputs": [_channel_dict(c) for c in self.inputs],
            "modes": modes,
            "lower_residual": None if self.lower_residual is None else c2(self.lower_residual),
            "upper_residual": None if self.upper_residual is None else c2(self.upper_residual),
            "meta": _jsonable(self.meta),
            "residual_modes": None
            if self.residual_modes is None
            else self.residual_modes.to_dict(),
            "quality": None if self.quality is None else self.quality.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ModalModel:
        """Inverse of :meth:`to_dict`; raises :class:`InputError` naming a missing key."""
        try:
            modes = d["modes"]
            outputs = [Channel(**c) for c in d["outputs"]]
            inputs = [Channel(**c) for c in d["inputs"]]

            def cz(x: Any) -> NDArray[np.complex128]:
                a = np.asarray(x, dtype=float)
                if a.size == 0:  # no entries (a model without inputs: output-only modes)
                    return np.zeros(0, complex)
                if a.shape[-1:] != (2,):
                    raise InputError(f"expected [re, im] pairs, got shape {a.shape}")
                return a[..., 0] + 1j * a[..., 1]

            m = len(modes)
            poles = np.array([cz(md["pole"]) for md in modes], dtype=complex).reshape(m)
            po = np.array([cz(md["shape"]) for md in modes], dtype=complex).reshape(m, -1).T
            pi = np.array([cz(md["participation"]) for md in modes], dtype=complex)
            pi = pi.reshape(m, -1).T
            if m == 0:
                po = np.zeros((len(outputs), 0), complex)
                pi = np.zeros((len(inputs), 0), complex)
            std: dict[str, Any] = {}
            for key in ("frequency_hz", "damping_ratio"):
                if m and all(key in md.get("std", {}) for md in modes):
                    std[key] = [md["std"][key] for md in modes]
            if m and all("shape" in md.get("std", {}) for md in modes):
                std["psi_out"] = np.array([md["std"]["shape"] for md in modes], float).T
            if m and all("participation" in md.get("std", {}) for md in modes):
                std["psi_in"] = np.array([md["std"]["participation"] for md in modes], float).T
            lr = d.get("lower_residual")
            ur = d.get("upper_residual")
            rm = d.get("residual_modes")
            qd = d.get("quality")
            return cls(
                poles,
                po,
                pi,
                mode_kind=d.get("mode_kind", "complex"),
                outputs=outputs,
                inputs=inputs,
                lower_residual=None if lr is None else cz(lr),
                upper_residual=None if ur is None else cz(ur),
                std=std,
                meta=d.get("meta", {}),
                residual_modes=None if rm is None else cls.from_dict(rm),
                quality=None if qd is None else FitQuality.from_dict(qd),
            )
        except KeyError as exc:
            raise InputError(f"modal model: missing key {exc.args[0]!r}") from None
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"modal model: malformed entry ({exc})") from None

    def __repr__(self) -> str:
        fr = ", ".join(f"{x:.2f}" for x in self.frequency_hz)
        return f"ModalModel({self.mode_kind}, {self.n_modes} modes at [{fr}] Hz)"


def _channel_dict(c: Channel) -> dict[str, Any]:
    return {"node": c.node, "direction": c.direction, "angle_deg": c.angle_deg, "name": c.name}


def _jsonable(x: Any) -> Any:
    """Convert NumPy scalars/arrays (complex as [re, im]) inside ``x`` to JSON types."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        if np.iscomplexobj(x):
            return np.stack([x.real, x.imag], axis=-1).tolist()
        return x.tolist()
    if isinstance(x, np.generic):
        return _jsonable(x.item())
    if isinstance(x, complex):
        return [x.real, x.imag]
    return x
