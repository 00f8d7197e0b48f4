"""Single-degree-of-freedom lateral vehicle model (spec eq. 41-44).

A rigid body of mass ``M`` rests on a lateral tyre element; a lateral force
``Fy`` acts on the body. With any tyre model of ground-force mobility
``V_t`` (dynamic stiffness ``Z = i omega / V_t``) the body responds as

    Y/Fy = 1 / (Z(omega) - M omega^2)                        (eq. 42)

computed stably through the mobility ``V = V_t / (1 + i omega M V_t)``
(:func:`tyredamp.lateral.models.attach_mass`), which stays finite at 0 Hz
for tyres with a series damper. For the proposed tyre,
``Z = 1/(1/(K + i h) + 1/(i omega C))`` and eq. 42 expands to

    Y/Fy = (1 + i (h + C omega)/K) /
           ((-M omega^2 - h C omega/K) + i [C omega - M omega^2 (h + C omega)/K])

with the limits ``C -> inf`` (eq. 43) ``Y/Fy = 1/(K + i h - M omega^2)`` and
``h/K -> 0`` (eq. 44) ``Y/Fy = (1 + i C omega/K) / (i C omega - M omega^2 (1 + i C omega/K))``.
The system is third order (eq. 41): the damper in series adds a state.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize_scalar

from .._validate import as_band, check_positive
from ..exceptions import InputError, PhysicsError
from ..frf import FRF, Channel, FRFKind
from .models import LateralModel
from .response import _receptance_from_mobility, as_freq, attach_mass

__all__ = [
    "LateralVehicle",
    "Resonance",
    "eq42_receptance",
    "eq43_receptance",
    "eq44_receptance",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def _omega_pos(freq_hz: ArrayLike) -> FloatArray:
    f = as_freq(freq_hz)
    if np.any(f == 0):
        raise InputError("freq_hz: expected frequencies > 0 Hz (receptance infinite at 0 Hz)")
    return np.asarray(2.0 * np.pi * f, dtype=float)


def eq42_receptance(K: float, h: float, C: float, M: float, freq_hz: ArrayLike) -> ComplexArray:
    """Closed form of spec eq. 42 for the proposed tyre under a body of mass ``M``.

    Parameters
    ----------
    K, h : float
        Carcass stiffness and hysteretic damping, N/m.
    C : float
        Tyre-road damping ``C_r``, N s/m.
    M : float
        Body mass, kg.
    freq_hz : array_like
        Frequencies in Hz (> 0).

    Returns
    -------
    ndarray, complex
        ``Y/Fy`` in m/N.
    """
    w = _omega_pos(freq_hz)
    num = 1.0 + 1j * (h + C * w) / K
    den = (-M * w**2 - h * C * w / K) + 1j * (C * w - M * w**2 * (h + C * w) / K)
    return np.asarray(num / den, dtype=complex)


def eq43_receptance(K: float, h: float, M: float, freq_hz: ArrayLike) -> ComplexArray:
    """Spec eq. 43 (``C -> inf``): ``1/(K + i h - M omega^2)`` in m/N; f > 0."""
    w = _omega_pos(freq_hz)
    return np.asarray(1.0 / (K + 1j * h - M * w**2), dtype=complex)


def eq44_receptance(K: float, C: float, M: float, freq_hz: ArrayLike) -> ComplexArray:
    """Spec eq. 44 (``h/K -> 0``): ``(1 + i C w/K)/(i C w - M w^2 (1 + i C w/K))`` in m/N."""
    w = _omega_pos(freq_hz)
    q = 1.0 + 1j * C * w / K
    return np.asarray(q / (1j * C * w - M * w**2 * q), dtype=complex)


@dataclass(frozen=True)
class Resonance:
    """A resonance peak of the vehicle model.

    Attributes
    ----------
    frequency : float
        Frequency of the peak, Hz.
    peak : float
        ``|H|`` at the peak, in the unit of ``quantity``.
    quantity : str
        ``"receptance"`` (m/N) or ``"accelerance"`` (m/(s^2 N)).
    """

    frequency: float
    peak: float
    quantity: str


@dataclass(frozen=True)
class LateralVehicle:
    """Body of mass ``M`` on a lateral tyre (spec eq. 41-42), any tyre model.

    Parameters
    ----------
    tyre : LateralModel
        Tyre model (ground-force description).
    mass : float
        Body mass ``M`` in kg (> 0).
    """

    tyre: LateralModel
    mass: float

    def __post_init__(self) -> None:
        if not isinstance(self.tyre, LateralModel):
            raise InputError(f"tyre: expected a LateralModel, got {type(self.tyre).__name__}")
        object.__setattr__(self, "mass", check_positive(self.mass, "mass"))

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        return attach_mass(self.tyre._mobility(omega), omega, self.mass)

    def mobility(self, freq_hz: ArrayLike) -> ComplexArray:
        """Body velocity per force, m/(s N) (finite at 0 Hz)."""
        f = as_freq(freq_hz)
        return self._mobility(2.0 * np.pi * f)

    def receptance(self, freq_hz: ArrayLike) -> ComplexArray:
        """Body displacement per force ``Y/Fy`` (eq. 42), m/N."""
        f = as_freq(freq_hz)
        return _receptance_from_mobility(self._mobility, self.tyre._static_compliance(), f)

    def accelerance(self, freq_hz: ArrayLike) -> ComplexArray:
        """Body acceleration per force, m/(s^2 N)."""
        f = as_freq(freq_hz)
        w = 2.0 * np.pi * f
        return np.asarray(1j * w * self._mobility(w), dtype=complex)

    def response(self, freq_hz: ArrayLike, kind: FRFKind = "accelerance") -> ComplexArray:
        """Any kind: ``"receptance"``, ``"mobility"`` or ``"accelerance"``."""
        if kind == "receptance":
            return self.receptance(freq_hz)
        if kind == "mobility":
            return self.mobility(freq_hz)
        if kind == "accelerance":
            return self.accelerance(freq_hz)
        raise InputError(f"kind: expected 'receptance', 'mobility' or 'accelerance', got {kind!r}")

    def frf(self, freq_hz: ArrayLike, kind: FRFKind = "accelerance") -> FRF:
        """The body response as a 1x1 :class:`~tyredamp.frf.FRF` (1-D increasing ``freq_hz``)."""
        return FRF(
            freq_hz,
            self.response(freq_hz, kind),
            kind=kind,
            outputs=[Channel(node=1, direction=2, name="body lateral")],
            inputs=[Channel(node=1, direction=2, name="body force")],
            meta={"tyre": self.tyre.to_dict(), "mass_kg": self.mass},
        )

    def resonance(
        self,
        f_range: tuple[float, float] = (0.05, 50.0),
        quantity: Literal["receptance", "accelerance"] = "receptance",
        n_grid: int = 4000,
    ) -> Resonance:
        """The highest interior peak of ``|H|`` in a band.

        A log-spaced scan finds interior local maxima (the band edges do not
        count, so the ``1/omega`` rise of a series damper at low frequency is
        not taken for a resonance); the highest is refined by a bounded
        scalar search.

        Parameters
        ----------
        f_range : (float, float)
            Search band in Hz, ``0 < lo < hi``.
        quantity : {"receptance", "accelerance"}
            Which magnitude to maximise.
        n_grid : int
            Scan points (>= 100).

        Returns
        -------
        Resonance

        Raises
        ------
        PhysicsError
            No interior peak: the system is over-damped in the band.
        """
        lo, hi = as_band(f_range, "f_range", positive=True)  # log-spaced scan
        if quantity not in ("receptance", "accelerance"):
            raise InputError(f"quantity: expected 'receptance' or 'accelerance', got {quantity!r}")
        if int(n_grid) < 100:
            raise InputError(f"n_grid: expected >= 100, got {n_grid}")
        f = np.logspace(np.log10(lo), np.log10(hi), int(n_grid))

        def mag(x: ArrayLike) -> FloatArray:
            return np.abs(self.response(x, quantity))

        a = mag(f)
        interior = np.flatnonzero((a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:])) + 1
        if interior.size == 0:
            raise PhysicsError(
                f"resonance: |{quantity}| has no interior peak in [{lo:g}, {hi:g}] Hz "
                "(over-damped in this band)"
            )
        i = int(interior[np.argmax(a[interior])])
        res = minimize_scalar(
            lambda lf: -float(mag(np.array([10.0**lf]))[0]),
            bounds=(np.log10(f[i - 1]), np.log10(f[i + 1])),
            method="bounded",
            options={"xatol": 1e-10},
        )
        fr = float(10.0**res.x)
        return Resonance(frequency=fr, peak=float(mag(np.array([fr]))[0]), quantity=quantity)
