"""The interface every linear lateral tyre model implements, and the models' registry.

:class:`LateralModel` derives every FRF kind, at the ground or the axle force,
from a model's mobility (the conventions are in :mod:`tyredamp.lateral.models`),
holds its parameters and operating conditions (vector and dict forms) and
declares the starting values of a fit. :data:`MODELS` maps a registry name to
its class (filled by :mod:`tyredamp.lateral.models`, which defines the
models); :func:`get_model_class` also accepts the aliases.
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
)

__all__ = ["MODELS", "LateralModel", "get_model_class"]


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


#: Registry of the fittable linear models by name.
MODELS: dict[str, type[LateralModel]] = {}  # filled by tyredamp.lateral.models

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
