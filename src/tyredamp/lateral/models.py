"""Linear lateral tyre models of paper 001 (spec ``lateral-models.md``).

Every model describes the lateral response of a rolling tyre: ``y`` is the
lateral displacement of the wheel centre and ``Fy`` the lateral force at the
contact patch (the *ground force*), positive in the same direction as ``y``.
Time dependence is ``e^{i omega t}``, so

* receptance  ``Y/Fy``           in m/N,
* mobility    ``i omega Y/Fy``   in m/(s N),
* accelerance ``-omega^2 Y/Fy``  in m/(s^2 N).

Models with a viscous damper in series (all but the classic one) drift
without bound under a static force, so their receptance is infinite at
0 Hz. Each model therefore implements its *mobility*, which is finite at every
frequency, and the other kinds are derived from it exactly (the accelerance is
exactly 0 at 0 Hz; asking for a receptance at 0 Hz raises
:class:`~tyredamp.exceptions.InputError` for those models).

The response algebra they share (wheel mass, axle and ground force, the
string impedance) is :mod:`.response`.

Models (receptance ``Y/Fy``):

============================  ==========================================  ==========
class                         ``Y/Fy``                                    spec/paper
============================  ==========================================  ==========
:class:`ClassicModel`          ``1/(k + i omega c)``                       Kelvin-Voigt
:class:`MaxwellModel`          ``1/k + 1/(i omega c)``                     Crolla et al.
:class:`ViscoPlasticModel`     ``1/(k + i omega c1) + 1/(i omega c2)``     Lines (eq. 20)
:class:`HystereticModel`       ``1/(K + i h) + 1/(i omega C_r)``           Peng (eq. 26-36)
:class:`RelaxationLengthModel` Maxwell with ``k = C_a/sigma, c = C_a/V``   eq. 13, 21
:class:`StretchedStringModel`  string with contact half-length ``a``       eq. 10 (Pacejka)
============================  ==========================================  ==========
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .._validate import check_positive
from ..exceptions import InputError
from ..frf import FRF, Channel, FRFKind
from .response import (
    ComplexArray,
    FloatArray,
    ForceKind,
    _check_force,
    _receptance_from_mobility,
    as_freq,
    attach_mass,
    string_impedance,
)

__all__ = [
    "MODELS",
    "ClassicModel",
    "HystereticModel",
    "LateralModel",
    "MaxwellModel",
    "RelaxationLengthModel",
    "StretchedStringModel",
    "ViscoPlasticModel",
    "get_model_class",
]


@dataclass(frozen=True)
class LateralModel(ABC):
    """Interface of every linear lateral tyre model.

    Subclasses are frozen dataclasses whose fields are the parameters (SI
    units, listed in :attr:`param_names` with :attr:`param_units`) followed by
    the operating conditions that are known rather than fitted (for example
    the travel speed, :attr:`condition_names`).
    """

    #: Registry key of the model.
    name: ClassVar[str] = ""
    #: Human-readable name.
    label: ClassVar[str] = ""
    #: Fitted parameters, in order.
    param_names: ClassVar[tuple[str, ...]] = ()
    #: SI unit of each parameter.
    param_units: ClassVar[tuple[str, ...]] = ()
    #: Known operating conditions (fields that are not fitted).
    condition_names: ClassVar[tuple[str, ...]] = ()
    #: Parameter that represents the tyre-road damper ``C_alpha / V`` (eq. 19,
    #: 33), or ``None``. Used to share ``C_alpha`` across travel speeds.
    road_damper: ClassVar[str | None] = None

    # ------------------------------------------------------------ to implement
    @abstractmethod
    def _mobility(self, omega: FloatArray) -> ComplexArray:
        """Ground-force mobility ``i omega Y/Fy`` at ``omega`` (rad/s, >= 0)."""

    def _static_compliance(self) -> float:
        """Receptance at 0 Hz in m/N (``inf`` when a damper is in series)."""
        return math.inf

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray] | None:
        """The mobility and its derivatives ``d V / d ln p_k`` (shape ``(P, n)``) at ``omega``.

        Used by the fits for an analytic Jacobian; None (the default): central
        differences instead.
        """
        return None

    # ----------------------------------------------------------------- kinds
    def mobility(self, freq_hz: ArrayLike) -> ComplexArray:
        """Ground-force mobility ``i omega Y/Fy``.

        Parameters
        ----------
        freq_hz : array_like
            Frequencies in Hz (>= 0), any shape.

        Returns
        -------
        ndarray, complex, same shape
            Mobility in m/(s N).
        """
        f = as_freq(freq_hz)
        return np.asarray(self._mobility(2.0 * np.pi * f), dtype=complex)

    def receptance(self, freq_hz: ArrayLike) -> ComplexArray:
        """Ground-force receptance ``Y/Fy`` in m/N (see :meth:`mobility`).

        Raises
        ------
        InputError
            At 0 Hz for a model whose static compliance is infinite.
        """
        f = as_freq(freq_hz)
        return _receptance_from_mobility(self._mobility, self._static_compliance(), f)

    def accelerance(self, freq_hz: ArrayLike) -> ComplexArray:
        """Ground-force accelerance ``-omega^2 Y/Fy`` in m/(s^2 N) (see :meth:`mobility`)."""
        f = as_freq(freq_hz)
        w = 2.0 * np.pi * f
        return np.asarray(1j * w * self._mobility(w), dtype=complex)

    def dynamic_stiffness(self, freq_hz: ArrayLike) -> ComplexArray:
        """Dynamic stiffness ``Fy/Y = 1/receptance`` in N/m (0 at 0 Hz for series models)."""
        f = as_freq(freq_hz)
        w = 2.0 * np.pi * f
        v = self._mobility(w)
        out = np.empty(np.shape(f), dtype=complex)
        zero = w == 0
        out[~zero] = 1j * w[~zero] / v[~zero]
        s0 = self._static_compliance()
        out[zero] = 0.0 if math.isinf(s0) else 1.0 / s0
        return out

    def response(
        self,
        freq_hz: ArrayLike,
        kind: FRFKind = "accelerance",
        force: ForceKind = "ground",
        wheel_mass: float = 0.0,
    ) -> ComplexArray:
        """Any FRF kind at the ground force or at the axle force.

        Parameters
        ----------
        freq_hz : array_like
            Frequencies in Hz (>= 0).
        kind : {"receptance", "mobility", "accelerance"}
            Response quantity per unit force.
        force : {"ground", "axle"}
            ``"ground"``: per unit contact-patch force; ``"axle"``: per unit
            force at the wheel axle, which also accelerates ``wheel_mass``
            (:func:`attach_mass`).
        wheel_mass : float
            Wheel mass in kg (used when ``force="axle"``).

        Returns
        -------
        ndarray, complex, same shape as ``freq_hz``
        """
        _check_force(force)
        f = as_freq(freq_hz)
        w = 2.0 * np.pi * f
        m = check_positive(wheel_mass, "wheel_mass", allow_zero=True)

        def mob(wv: FloatArray) -> ComplexArray:
            v = self._mobility(wv)
            return attach_mass(v, wv, m) if force == "axle" else v

        if kind == "mobility":
            return np.asarray(mob(w), dtype=complex)
        if kind == "accelerance":
            return np.asarray(1j * w * mob(w), dtype=complex)
        if kind == "receptance":
            # A rigid mass does not change the static compliance.
            return _receptance_from_mobility(mob, self._static_compliance(), f)
        raise InputError(f"kind: expected 'receptance', 'mobility' or 'accelerance', got {kind!r}")

    def axle_accelerance(self, freq_hz: ArrayLike, wheel_mass: float) -> ComplexArray:
        """Accelerance per unit axle force, ``A_g/(1 + M_w A_g)`` in m/(s^2 N).

        Parameters
        ----------
        freq_hz : array_like
            Frequencies in Hz (>= 0).
        wheel_mass : float
            Wheel mass ``M_w`` in kg (>= 0).
        """
        return self.response(freq_hz, "accelerance", "axle", wheel_mass)

    def frf(
        self,
        freq_hz: ArrayLike,
        kind: FRFKind = "accelerance",
        force: ForceKind = "ground",
        wheel_mass: float = 0.0,
    ) -> FRF:
        """The model response as a 1x1 :class:`~tyredamp.frf.FRF`.

        Parameters are those of :meth:`response`; ``freq_hz`` must be 1-D and
        strictly increasing. ``meta`` records the model, force and wheel mass.
        """
        h = self.response(freq_hz, kind, force, wheel_mass)
        return FRF(
            freq_hz,
            h,
            kind=kind,
            outputs=[Channel(node=1, direction=2, name="lateral acceleration")],
            inputs=[Channel(node=1, direction=2, name=f"{force} force")],
            meta={"model": self.to_dict(), "force": force, "wheel_mass_kg": float(wheel_mass)},
        )

    # ------------------------------------------------------------ parameters
    @property
    def params(self) -> dict[str, float]:
        """Fitted parameters by name (SI units, see :attr:`param_units`)."""
        return {n: float(getattr(self, n)) for n in self.param_names}

    @property
    def conditions(self) -> dict[str, float]:
        """Known operating conditions by name (SI units)."""
        return {n: float(getattr(self, n)) for n in self.condition_names}

    def vector(self) -> FloatArray:
        """Parameters as an array in :attr:`param_names` order."""
        return np.array([getattr(self, n) for n in self.param_names], dtype=float)

    @classmethod
    def from_vector(cls, values: ArrayLike, **conditions: float) -> LateralModel:
        """Build the model from parameters in :attr:`param_names` order."""
        v = np.asarray(values, dtype=float).ravel()
        if v.size != len(cls.param_names):
            raise InputError(
                f"values: expected {len(cls.param_names)} parameters {cls.param_names}, "
                f"got {v.size}"
            )
        missing = [n for n in cls.condition_names if n not in conditions]
        if missing:
            raise InputError(f"{cls.__name__}: missing operating condition(s) {missing}")
        kw: dict[str, float] = dict(zip(cls.param_names, (float(x) for x in v), strict=True))
        kw.update({n: float(conditions[n]) for n in cls.condition_names})
        return cls(**kw)

    def derived(self) -> dict[str, float]:
        """Derived quantities (corner frequency, relaxation length ...), SI units."""
        return {}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description: ``{"model", "params", "units", "conditions"}``."""
        return {
            "model": self.name,
            "params": self.params,
            "units": dict(zip(self.param_names, self.param_units, strict=True)),
            "conditions": self.conditions,
        }

    @staticmethod
    def from_dict(d: dict[str, Any]) -> LateralModel:
        """Inverse of :meth:`to_dict`."""
        try:
            cls = get_model_class(str(d["model"]))
            kw = dict(d["params"])
            kw.update(d.get("conditions", {}))
        except (KeyError, TypeError) as exc:
            raise InputError(f"d: expected keys 'model' and 'params', got {d!r} ({exc})") from None
        names = {f.name for f in fields(cls)}
        unknown = set(kw) - names
        if unknown:
            raise InputError(f"d: unknown parameter(s) {sorted(unknown)} for {cls.__name__}")
        return cls(**kw)

    # -------------------------------------------------------------- fitting
    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        """Starting parameter vectors for a fit to a ground-force receptance.

        Parameters
        ----------
        omega : ndarray, shape (n,)
            Angular frequencies (> 0) in rad/s.
        receptance : ndarray, complex, shape (n,)
            Measured ``Y/Fy_ground`` in m/N.
        **conditions : float
            Operating conditions (:attr:`condition_names`).

        Returns
        -------
        list of ndarray
            Candidate parameter vectors (all entries finite and > 0).
        """
        raise NotImplementedError(f"{cls.__name__} has no automatic starting values")


def _positive_fields(obj: Any, names: tuple[str, ...], allow_zero: tuple[str, ...] = ()) -> None:
    for n in names:
        v = check_positive(getattr(obj, n), f"{type(obj).__name__}.{n}", allow_zero=n in allow_zero)
        object.__setattr__(obj, n, v)


def _median_pos(x: ArrayLike, fallback: float) -> float:
    a = np.asarray(x, dtype=float)
    a = a[np.isfinite(a) & (a > 0)]
    return float(np.median(a)) if a.size else fallback


def _maxwell_guess(omega: FloatArray, rec: ComplexArray) -> tuple[float, float, float]:
    """(k, c, eta) from ``Y = 1/(k(1 + i eta)) + 1/(i omega c)``: linear in (a, b, 1/c).

    ``Re Y = a``, ``Im Y = -b - (1/c)/omega`` with ``a - i b = 1/(k + i h)``.
    """
    a = float(np.median(rec.real))
    design = np.column_stack([np.ones_like(omega), 1.0 / omega])
    sol, *_ = np.linalg.lstsq(design, -rec.imag, rcond=None)
    b, inv_c = float(sol[0]), float(sol[1])
    scale = float(np.median(np.abs(rec)))
    if not a > 0:
        a = scale
    if not inv_c > 0:
        inv_c = _median_pos(-rec.imag * omega, scale * float(np.median(omega)))
    z = 1.0 / complex(a, -max(b, 0.0))
    k = max(z.real, 1e-12 / max(scale, 1e-300))
    eta = min(max(z.imag / k, 1e-3), 2.0)
    return k, 1.0 / inv_c, eta


# ----------------------------------------------------------------------------------- models
@dataclass(frozen=True)
class ClassicModel(LateralModel):
    """Classic (Kelvin-Voigt) model: spring ``k`` parallel to damper ``c``.

    ``Y/Fy = 1/(k + i omega c)`` (spec table; paper "classic model").

    Parameters
    ----------
    k : float
        Lateral stiffness, N/m (> 0).
    c : float
        Viscous damping coefficient, N s/m (> 0).
    """

    k: float
    c: float

    name: ClassVar[str] = "classic"
    label: ClassVar[str] = "classic (Kelvin-Voigt)"
    param_names: ClassVar[tuple[str, ...]] = ("k", "c")
    param_units: ClassVar[tuple[str, ...]] = ("N/m", "N s/m")

    def __post_init__(self) -> None:
        _positive_fields(self, ("k", "c"))

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        return np.asarray(1j * omega / (self.k + 1j * omega * self.c), dtype=complex)

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray]:
        # V = i w / Z, Z = k + i w c: dV/dln k = -V k / Z, dV/dln c = -V (i w c) / Z.
        iwc = 1j * omega * self.c
        z = self.k + iwc
        v = 1j * omega / z
        vz = v / z
        return v, np.array([-self.k * vz, -iwc * vz])

    def _static_compliance(self) -> float:
        return 1.0 / self.k

    def derived(self) -> dict[str, float]:
        return {"tau": self.c / self.k}

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        z = 1.0 / receptance
        k = _median_pos(z.real, 1.0 / float(np.median(np.abs(receptance))))
        c = _median_pos(z.imag / omega, k / float(np.median(omega)))
        return [np.array([k, c])]


@dataclass(frozen=True)
class MaxwellModel(LateralModel):
    """Maxwell model (Crolla et al.): spring ``k`` in series with damper ``c``.

    ``Y/Fy = 1/k + 1/(i omega c)`` (spec table). Equal to the first-order
    relaxation model (eq. 13, 21) with ``k = C_alpha/sigma``, ``c = C_alpha/V``.

    Parameters
    ----------
    k : float
        Spring stiffness, N/m (> 0).
    c : float
        Series (tyre-road) damping coefficient, N s/m (> 0).
    """

    k: float
    c: float

    name: ClassVar[str] = "maxwell"
    label: ClassVar[str] = "Maxwell"
    param_names: ClassVar[tuple[str, ...]] = ("k", "c")
    param_units: ClassVar[tuple[str, ...]] = ("N/m", "N s/m")
    road_damper: ClassVar[str | None] = "c"

    def __post_init__(self) -> None:
        _positive_fields(self, ("k", "c"))

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        return np.asarray(1j * omega / self.k + 1.0 / self.c, dtype=complex)

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray]:
        # V = i w / k + 1/c.
        g = np.empty((2, omega.size), dtype=complex)
        g[0] = -1j * omega / self.k
        g[1] = -1.0 / self.c
        return 1.0 / self.c - g[0], g

    def corner_frequency(self) -> float:
        """``k / (2 pi c)`` in Hz (where the two compliances are equal in size)."""
        return self.k / (2.0 * np.pi * self.c)

    def derived(self) -> dict[str, float]:
        return {"f0": self.corner_frequency(), "tau": self.c / self.k}

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        k, c, _ = _maxwell_guess(omega, receptance)
        return [np.array([k, c])]


@dataclass(frozen=True)
class ViscoPlasticModel(LateralModel):
    """Visco-plastic model (Lines): damper ``c2`` in series with a Kelvin unit (``k``, ``c1``).

    ``Y/Fy = 1/(k + i omega c1) + 1/(i omega c2)`` (paper eq. 20).

    Parameters
    ----------
    k : float
        Carcass stiffness, N/m (> 0).
    c1 : float
        Carcass viscous damping, N s/m (> 0).
    c2 : float
        Tyre-road damping ``C_alpha / V`` (paper eq. 19), N s/m (> 0).
    """

    k: float
    c1: float
    c2: float

    name: ClassVar[str] = "viscoplastic"
    label: ClassVar[str] = "visco-plastic (Lines)"
    param_names: ClassVar[tuple[str, ...]] = ("k", "c1", "c2")
    param_units: ClassVar[tuple[str, ...]] = ("N/m", "N s/m", "N s/m")
    road_damper: ClassVar[str | None] = "c2"

    def __post_init__(self) -> None:
        _positive_fields(self, ("k", "c1", "c2"))

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        return np.asarray(
            1j * omega / (self.k + 1j * omega * self.c1) + 1.0 / self.c2, dtype=complex
        )

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray]:
        # V = i w / Z + 1/c2, Z = k + i w c1 (as the classic model, plus the series damper).
        iwc = 1j * omega * self.c1
        z = self.k + iwc
        vt = 1j * omega / z
        vz = vt / z
        g = np.empty((3, omega.size), dtype=complex)
        np.multiply(vz, -self.k, out=g[0])
        np.multiply(vz, -iwc, out=g[1])
        g[2] = -1.0 / self.c2
        vt += 1.0 / self.c2
        return vt, g

    def derived(self) -> dict[str, float]:
        return {"f0": self.k / (2.0 * np.pi * self.c2)}

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        k, c, eta = _maxwell_guess(omega, receptance)
        w_mid = float(np.sqrt(omega.min() * omega.max()))
        return [np.array([k, eta * k / w_mid, c]), np.array([k, 0.05 * k / w_mid, c])]


@dataclass(frozen=True)
class HystereticModel(LateralModel):
    """Proposed model (Peng): damper ``C_r`` in series with ``K`` parallel to hysteretic ``h``.

    ``Y/Fy = 1/(K + i h) + 1/(i omega C_r)`` (paper eq. 26, 33, 36): carcass
    ``Y_t/Fy = 1/(K + i h)`` plus tyre-road interaction
    ``Y_r/Fy = 1/(i omega C_r)`` with ``C_r = C_alpha / V``.

    The hysteretic term is evaluated for ``omega >= 0`` as written; its
    negative-frequency extension ``K - i h`` is implied wherever a real time
    signal is built (Hermitian symmetry). At exactly 0 Hz the static
    compliance is taken as ``1/K`` (``h sign(0) = 0``). The model is not causal
    (see :mod:`tyredamp.lateral.timedomain`).

    Parameters
    ----------
    K : float
        Carcass lateral stiffness, N/m (> 0).
    h : float
        Hysteretic damping (loss stiffness), N/m (>= 0); ``h/K`` is the loss
        factor, typically 0.1-0.2 for tread rubber (Gehman, spec).
    C_r : float
        Tyre-road damping ``C_alpha / V``, N s/m (> 0; ``inf`` for a tyre that
        cannot roll sideways, the limit of spec eq. 43).
    """

    K: float
    h: float
    C_r: float

    name: ClassVar[str] = "hysteretic"
    label: ClassVar[str] = "proposed hysteretic (Peng)"
    param_names: ClassVar[tuple[str, ...]] = ("K", "h", "C_r")
    param_units: ClassVar[tuple[str, ...]] = ("N/m", "N/m", "N s/m")
    road_damper: ClassVar[str | None] = "C_r"

    def __post_init__(self) -> None:
        _positive_fields(self, ("K", "h"), allow_zero=("h",))
        try:
            c = float(self.C_r)
        except (TypeError, ValueError):
            raise InputError(f"HystereticModel.C_r: expected a number, got {self.C_r!r}") from None
        if math.isnan(c) or c <= 0:
            raise InputError(f"HystereticModel.C_r: expected a value > 0 (or inf), got {c:g}")
        object.__setattr__(self, "C_r", c)

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        road = 0.0 if math.isinf(self.C_r) else 1.0 / self.C_r
        return np.asarray(1j * omega / (self.K + 1j * self.h) + road, dtype=complex)

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray]:
        # V = i w / Z + 1/C_r, Z = K + i h (constant): dV/dln K = -V_t K/Z, dV/dln h = -V_t i h/Z.
        z = self.K + 1j * self.h
        road = 0.0 if math.isinf(self.C_r) else 1.0 / self.C_r
        g = np.empty((3, omega.size), dtype=complex)
        np.multiply(omega, 1j / z, out=g[0])  # V_t
        np.multiply(g[0], -1j * self.h / z, out=g[1])
        v = g[0] + road
        g[0] *= -self.K / z
        g[2] = -road
        return v, g

    def _static_compliance(self) -> float:
        return 1.0 / self.K if math.isinf(self.C_r) else math.inf

    @property
    def loss_factor(self) -> float:
        """``h / K`` (dimensionless)."""
        return self.h / self.K

    def corner_frequency(self) -> float:
        """Corner frequency ``f0 = K / (2 pi C_r)`` in Hz (spec eq. 38)."""
        return self.K / (2.0 * np.pi * self.C_r)

    def low_frequency_asymptote(self, freq_hz: ArrayLike) -> ComplexArray:
        """Low-frequency asymptote ``1/(i omega C_r)`` (viscous damper), m/N; f > 0."""
        f = as_freq(freq_hz)
        if np.any(f == 0):
            raise InputError("freq_hz: the low-frequency asymptote is infinite at 0 Hz")
        return np.asarray(1.0 / (1j * 2.0 * np.pi * f * self.C_r), dtype=complex)

    def high_frequency_asymptote(self, freq_hz: ArrayLike) -> ComplexArray:
        """High-frequency asymptote ``1/(K + i h)`` (constant), m/N."""
        f = as_freq(freq_hz)
        return np.full(np.shape(f), 1.0 / (self.K + 1j * self.h), dtype=complex)

    def maxwell(self) -> MaxwellModel:
        """The Maxwell model with ``k = K``, ``c = C_r`` (the comparison of spec eq. 40)."""
        return MaxwellModel(k=self.K, c=self.C_r)

    def derived(self) -> dict[str, float]:
        return {"f0": self.corner_frequency(), "loss_factor": self.loss_factor}

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        k, c, eta = _maxwell_guess(omega, receptance)
        return [np.array([k, eta * k, c]), np.array([k, 0.15 * k, c])]


@dataclass(frozen=True)
class RelaxationLengthModel(LateralModel):
    """First-order relaxation-length model (stretched string without contact length).

    ``(sigma/V) dFy/dt + Fy = C_alpha alpha`` with ``alpha = y'/V`` for pure
    lateral motion (paper eq. 13, 21), hence
    ``Y/Fy = sigma/C_alpha + V/(i omega C_alpha)``: a Maxwell model with
    ``k = C_alpha/sigma`` and ``c = C_alpha/V``.

    Parameters
    ----------
    C_alpha : float
        Cornering stiffness, N/rad (> 0).
    sigma : float
        Relaxation length, m (> 0).
    speed : float
        Travel speed ``V``, m/s (> 0); an operating condition, not fitted.
    """

    C_alpha: float
    sigma: float
    speed: float

    name: ClassVar[str] = "relaxation"
    label: ClassVar[str] = "relaxation length (first order)"
    param_names: ClassVar[tuple[str, ...]] = ("C_alpha", "sigma")
    param_units: ClassVar[tuple[str, ...]] = ("N/rad", "m")
    condition_names: ClassVar[tuple[str, ...]] = ("speed",)

    def __post_init__(self) -> None:
        _positive_fields(self, ("C_alpha", "sigma", "speed"))

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        return np.asarray((1j * omega * self.sigma + self.speed) / self.C_alpha, dtype=complex)

    def _mobility_gradient(self, omega: FloatArray) -> tuple[ComplexArray, ComplexArray]:
        # V = (i w sigma + V_s) / C_alpha.
        g = np.empty((2, omega.size), dtype=complex)
        np.multiply(omega, 1j * self.sigma / self.C_alpha, out=g[1])
        v = g[1] + self.speed / self.C_alpha
        np.negative(v, out=g[0])
        return v, g

    def maxwell(self) -> MaxwellModel:
        """Equivalent :class:`MaxwellModel` (``k = C_alpha/sigma``, ``c = C_alpha/V``)."""
        return MaxwellModel(k=self.C_alpha / self.sigma, c=self.C_alpha / self.speed)

    def derived(self) -> dict[str, float]:
        return {
            "k": self.C_alpha / self.sigma,
            "c": self.C_alpha / self.speed,
            "f0": self.speed / (2.0 * np.pi * self.sigma),
        }

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        v = check_positive(conditions.get("speed", float("nan")), "speed")
        k, c, _ = _maxwell_guess(omega, receptance)
        ca = c * v
        return [np.array([ca, ca / k])]


@dataclass(frozen=True)
class StretchedStringModel(LateralModel):
    """Pacejka's stretched-string model with finite contact length (paper eq. 10).

    Mobility ``1 / string_impedance(...)`` (see :func:`string_impedance` for
    the derivation). Low-frequency limit: a damper ``C_alpha/V``; high-frequency
    limit: a spring ``C_alpha/(sigma + a)``; ``a = 0`` gives
    :class:`RelaxationLengthModel`.

    Parameters
    ----------
    C_alpha : float
        Cornering stiffness ``2 c_c (sigma + a)^2``, N/rad (> 0).
    sigma : float
        Relaxation length of the free string, m (> 0).
    a : float
        Contact half-length, m (>= 0).
    speed : float
        Travel speed ``V``, m/s (> 0); not fitted.
    """

    C_alpha: float
    sigma: float
    a: float
    speed: float

    name: ClassVar[str] = "string"
    label: ClassVar[str] = "stretched string (Pacejka)"
    param_names: ClassVar[tuple[str, ...]] = ("C_alpha", "sigma", "a")
    param_units: ClassVar[tuple[str, ...]] = ("N/rad", "m", "m")
    condition_names: ClassVar[tuple[str, ...]] = ("speed",)

    def __post_init__(self) -> None:
        _positive_fields(self, ("C_alpha", "sigma", "a", "speed"), allow_zero=("a",))

    @property
    def c_c(self) -> float:
        """Foundation stiffness per unit length ``C_alpha / (2 (sigma + a)^2)``, N/m^2."""
        return self.C_alpha / (2.0 * (self.sigma + self.a) ** 2)

    @property
    def lateral_stiffness(self) -> float:
        """Standing-tyre lateral stiffness ``2 c_c (sigma + a)``, N/m."""
        return self.C_alpha / (self.sigma + self.a)

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        w = np.asarray(omega, dtype=float)
        return 1.0 / string_impedance(w, self.c_c, self.sigma, self.a, self.speed)

    def derived(self) -> dict[str, float]:
        return {"lateral_stiffness": self.lateral_stiffness, "c_c": self.c_c}

    @classmethod
    def initial_guesses(
        cls, omega: FloatArray, receptance: ComplexArray, **conditions: float
    ) -> list[FloatArray]:
        v = check_positive(conditions.get("speed", float("nan")), "speed")
        k, c, _ = _maxwell_guess(omega, receptance)
        ca = c * v
        total = ca / k  # sigma + a
        return [np.array([ca, (1.0 - q) * total, q * total]) for q in (0.2, 0.4, 0.6)]


#: Registry of the fittable linear models by name.
MODELS: dict[str, type[LateralModel]] = {
    cls.name: cls
    for cls in (
        ClassicModel,
        MaxwellModel,
        ViscoPlasticModel,
        HystereticModel,
        RelaxationLengthModel,
        StretchedStringModel,
    )
}

_ALIASES = {
    "kelvin-voigt": "classic",
    "kelvin": "classic",
    "visco-plastic": "viscoplastic",
    "visco_plastic": "viscoplastic",
    "lines": "viscoplastic",
    "proposed": "hysteretic",
    "peng": "hysteretic",
    "relaxation-length": "relaxation",
    "first-order": "relaxation",
    "stretched-string": "string",
    "pacejka": "string",
}


def get_model_class(name: str | type[LateralModel]) -> type[LateralModel]:
    """Model class from a registry name or alias (``"proposed"``, ``"lines"`` ...).

    Parameters
    ----------
    name : str or LateralModel subclass
        One of :data:`MODELS` or an alias; a class is returned unchanged.
    """
    if isinstance(name, type):
        if not issubclass(name, LateralModel):
            raise InputError(f"model: expected a LateralModel subclass, got {name!r}")
        return name
    key = str(name).strip().lower()
    key = _ALIASES.get(key, key)
    if key not in MODELS:
        raise InputError(
            f"model: expected one of {sorted(MODELS)} (or an alias {sorted(_ALIASES)}), "
            f"got {name!r}"
        )
    return MODELS[key]
