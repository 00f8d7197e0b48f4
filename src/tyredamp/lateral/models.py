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
string impedance) is :mod:`.response`; the interface they implement
(:class:`LateralModel`) and the registry by name (:data:`MODELS`,
:func:`get_model_class`) are :mod:`.base`.

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
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .._validate import check_positive
from ..exceptions import InputError
from .base import MODELS, LateralModel, get_model_class
from .response import (
    ComplexArray,
    FloatArray,
    as_freq,
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


# registered here, where the models are defined (:data:`.base.MODELS`)
MODELS.update(
    {
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
)
