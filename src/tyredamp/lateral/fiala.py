"""Steady-state lateral force of the Fiala beam / Fromm brush model and its damper form.

Spec ``lateral-models.md``, "Steady-state models the paper reviews" (paper
eq. 3-6):

* Fiala (parabolic contact pressure, approximated) and Fromm's brush model
  give the same lateral force
  ``Fy = mu W (psi - psi|psi|/3 + psi^3/27)`` with
  ``psi = K_alpha tan(alpha)/(mu W)`` for ``|psi| <= 3`` and
  ``Fy = mu W sign(alpha)`` beyond (full sliding). The spec writes
  ``psi^2/3`` for ``alpha >= 0``; ``psi|psi|`` is the odd extension.
* With small slip, ``tan(alpha) ~ y'/V`` (eq. 4), the model is a non-linear
  viscous damper ``Fy = c(y') y'`` with
  ``c(y') = K_alpha/V - K_alpha^2 |y'|/(3 mu W V^2) + K_alpha^3 y'^2/(27 mu^2 W^2 V^3)``
  (eq. 5-6), and ``c = mu W/|y'|`` once the whole contact slides.

For small amplitudes ``c -> K_alpha/V``: the tyre-road damper ``C_r`` of the
linear models (eq. 19, 33).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import InputError

__all__ = ["FialaTyre"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class FialaTyre:
    """Fiala / brush steady-state lateral force model.

    Parameters
    ----------
    K_alpha : float
        Cornering stiffness (slope of ``Fy`` against ``alpha`` at 0), N/rad (> 0).
    mu : float
        Friction coefficient (> 0).
    load : float
        Vertical load ``W``, N (> 0).
    """

    K_alpha: float
    mu: float
    load: float

    def __post_init__(self) -> None:
        for n in ("K_alpha", "mu", "load"):
            object.__setattr__(self, n, check_positive(getattr(self, n), f"FialaTyre.{n}"))

    @property
    def max_force(self) -> float:
        """Sliding force ``mu W`` in N."""
        return self.mu * self.load

    @property
    def sliding_slip_angle(self) -> float:
        """Slip angle at which the whole contact slides, ``atan(3 mu W / K_alpha)``, rad."""
        return float(np.arctan(3.0 * self.max_force / self.K_alpha))

    def _force_from_tan(self, t: FloatArray) -> FloatArray:
        fmax = self.max_force
        psi = self.K_alpha * t / fmax
        inside = np.abs(psi) <= 3.0
        out = np.where(
            inside,
            fmax * (psi - psi * np.abs(psi) / 3.0 + psi**3 / 27.0),
            fmax * np.sign(psi),
        )
        return np.asarray(out, dtype=float)

    def lateral_force(self, alpha: ArrayLike) -> FloatArray:
        """Steady-state lateral force ``Fy(alpha)`` (paper eq. 3), N.

        Parameters
        ----------
        alpha : array_like
            Slip angle in rad, ``|alpha| < pi/2``.

        Returns
        -------
        ndarray, same shape
            Lateral force in N (odd in ``alpha``, ``|Fy| <= mu W``).
        """
        a = as_finite(alpha, "alpha", dtype=float)
        if np.any(np.abs(a) >= np.pi / 2):
            raise InputError("alpha: expected |alpha| < pi/2 rad")
        return self._force_from_tan(np.tan(a))

    def damper_force(self, velocity: ArrayLike, speed: float) -> FloatArray:
        """Non-linear damper force ``c(y') y'`` with ``tan(alpha) = y'/V`` (eq. 4-6), N.

        Parameters
        ----------
        velocity : array_like
            Lateral velocity ``y'`` of the wheel, m/s.
        speed : float
            Travel speed ``V``, m/s (> 0).
        """
        v = as_finite(velocity, "velocity", dtype=float)
        vv = check_positive(speed, "speed")
        return self._force_from_tan(v / vv)

    def damper_coefficient(self, velocity: ArrayLike, speed: float) -> FloatArray:
        """Velocity-dependent damping coefficient ``c(y')`` of eq. 5-6, N s/m.

        ``c(y') = K/V - K^2 |y'|/(3 mu W V^2) + K^3 y'^2/(27 mu^2 W^2 V^3)``
        while ``|psi| <= 3``; ``mu W / |y'|`` in full sliding. At ``y' = 0`` it
        is ``K_alpha / V``.
        """
        v = as_finite(velocity, "velocity", dtype=float)
        vv = check_positive(speed, "speed")
        k, fmax = self.K_alpha, self.max_force
        av = np.abs(v)
        poly = k / vv - k**2 * av / (3.0 * fmax * vv**2) + k**3 * v**2 / (27.0 * fmax**2 * vv**3)
        sliding = k * av / (fmax * vv) > 3.0
        safe = np.where(sliding, av, 1.0)
        return np.asarray(np.where(sliding, fmax / safe, poly), dtype=float)

    def equivalent_damping(
        self, velocity_amplitude: ArrayLike, speed: float, n_points: int = 4096
    ) -> FloatArray:
        """Describing-function (first-harmonic) damping for ``y' = U cos(omega t)``, N s/m.

        ``c_eq(U) = (1/(pi U)) int_0^{2 pi} Fy(U cos th) cos th d th``: the
        viscous damper dissipating the same energy per cycle. Tends to
        ``K_alpha/V`` as ``U -> 0``.

        Parameters
        ----------
        velocity_amplitude : array_like
            ``U`` in m/s (> 0).
        speed : float
            Travel speed, m/s (> 0).
        n_points : int
            Points of the periodic trapezoid rule (>= 64).

        Returns
        -------
        ndarray, same shape as ``velocity_amplitude``
        """
        u = as_finite(velocity_amplitude, "velocity_amplitude", dtype=float)
        if np.any(u <= 0):
            raise InputError("velocity_amplitude: expected values > 0 m/s")
        if int(n_points) < 64:
            raise InputError(f"n_points: expected >= 64, got {n_points}")
        th = 2.0 * np.pi * np.arange(int(n_points)) / int(n_points)
        c = np.cos(th)
        flat = u.reshape(-1)
        force = self.damper_force(flat[:, None] * c[None, :], speed)
        ceq = 2.0 * np.mean(force * c[None, :], axis=1) / flat
        return np.asarray(ceq.reshape(u.shape), dtype=float)
