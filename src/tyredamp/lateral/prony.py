"""Causal stand-in for the hysteretic tyre: a generalised Maxwell (Prony) carcass.

The hysteretic carcass ``K + i h`` of :class:`~tyredamp.lateral.models.HystereticModel`
is not causal, so transients need an approximation:
:func:`fit_generalized_maxwell` fits a generalised Maxwell (Prony) series
``Z_c(omega) = k0 + sum_j k_j i omega tau_j / (1 + i omega tau_j)`` (all
``k >= 0``, so passive and causal) to ``K + i h`` over a band, and
:class:`GeneralizedMaxwellTyre` puts it in series with the road damper
``C_r``. The simulation is :mod:`tyredamp.lateral.timedomain`; how far the
approximation is from the ideal model, :mod:`tyredamp.lateral.causality`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import nnls

from .._validate import as_band, check_positive
from ..exceptions import InputError, PhysicsError
from .models import HystereticModel, LateralModel
from .response import ComplexArray, FloatArray, as_freq

__all__ = ["GeneralizedMaxwellTyre", "fit_generalized_maxwell"]


@dataclass(frozen=True)
class GeneralizedMaxwellTyre(LateralModel):
    """Causal tyre: damper ``C_r`` in series with a generalised Maxwell carcass.

    Carcass dynamic stiffness
    ``Z_c = k0 + sum_j k_j i omega tau_j / (1 + i omega tau_j)`` (N/m): a spring
    ``k0`` parallel to Maxwell arms (spring ``k_j``, damper ``k_j tau_j``).
    Mobility ``i omega / Z_c + 1/C_r``. Built by
    :func:`fit_generalized_maxwell` as the causal stand-in for
    :class:`~tyredamp.lateral.models.HystereticModel`; not a fitting model.

    Parameters
    ----------
    k0 : float
        Equilibrium (static) stiffness, N/m (> 0).
    stiffness : tuple of float
        Arm stiffnesses ``k_j``, N/m (>= 0).
    tau : tuple of float
        Arm relaxation times ``tau_j``, s (> 0).
    C_r : float
        Road damper, N s/m (> 0, ``inf`` for none).
    """

    k0: float
    stiffness: tuple[float, ...]
    tau: tuple[float, ...]
    C_r: float

    name: ClassVar[str] = "generalized_maxwell"
    label: ClassVar[str] = "causal generalised Maxwell carcass + road damper"

    def __post_init__(self) -> None:
        object.__setattr__(self, "k0", check_positive(self.k0, "k0"))
        ks = tuple(check_positive(k, "stiffness", allow_zero=True) for k in self.stiffness)
        ts = tuple(check_positive(t, "tau") for t in self.tau)
        if len(ks) != len(ts):
            raise InputError(f"stiffness, tau: expected equal lengths, got {len(ks)} and {len(ts)}")
        object.__setattr__(self, "stiffness", ks)
        object.__setattr__(self, "tau", ts)
        c = float(self.C_r)
        if math.isnan(c) or c <= 0:
            raise InputError(f"C_r: expected a value > 0 (or inf), got {c:g}")
        object.__setattr__(self, "C_r", c)

    def carcass_stiffness(self, freq_hz: ArrayLike) -> ComplexArray:
        """``Z_c`` in N/m at ``freq_hz`` (Hz, >= 0)."""
        w = 2.0 * np.pi * as_freq(freq_hz)
        return self._zc(w)

    def _zc(self, w: FloatArray) -> ComplexArray:
        z = np.full(np.shape(w), self.k0, dtype=complex)
        for k, t in zip(self.stiffness, self.tau, strict=True):
            z = z + k * (1j * w * t) / (1.0 + 1j * w * t)
        return z

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        road = 0.0 if math.isinf(self.C_r) else 1.0 / self.C_r
        return np.asarray(1j * omega / self._zc(omega) + road, dtype=complex)

    def _static_compliance(self) -> float:
        return 1.0 / self.k0 if math.isinf(self.C_r) else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": self.name,
            "params": {
                "k0": self.k0,
                "stiffness": list(self.stiffness),
                "tau": list(self.tau),
                "C_r": self.C_r,
            },
            "units": {"k0": "N/m", "stiffness": "N/m", "tau": "s", "C_r": "N s/m"},
            "conditions": {},
        }


def fit_generalized_maxwell(
    model: HystereticModel,
    band: tuple[float, float],
    per_decade: int = 3,
    f_ref: float | None = None,
    n_points: int = 400,
) -> GeneralizedMaxwellTyre:
    """Causal generalised-Maxwell approximation of the hysteretic carcass ``K + i h``.

    A constant loss ``h`` over a band forces the storage stiffness of any
    causal model to rise with frequency (Kramers-Kronig: about
    ``(2 h/pi) ln(f2/f1)`` between ``f1`` and ``f2``), so ``K + i h`` cannot be
    matched everywhere. This approximation keeps what governs a resonance:

    * the loss ``Im Z_c = sum_j k_j omega tau_j / (1 + (omega tau_j)^2)`` matches
      ``h`` on ``n_points`` log-spaced frequencies of ``band`` (non-negative
      least squares, :func:`scipy.optimize.nnls`; relaxation times
      ``tau_j = 1/(2 pi f_j)`` log-spaced with ``per_decade`` per decade from
      half a decade below to half a decade above the band);
    * the storage equals ``K`` at ``f_ref``: ``k0 = K - sum_j k_j (w tau_j)^2/(1 + (w tau_j)^2)``.

    All ``k_j >= 0`` and ``k0 > 0``, so the model is passive and causal.

    Parameters
    ----------
    model : HystereticModel
        The ideal model (its ``C_r`` is kept).
    band : (float, float)
        Frequency band in Hz, ``0 < lo < hi``.
    per_decade : int
        Maxwell arms per decade (>= 1).
    f_ref : float, optional
        Frequency where the storage stiffness equals ``K``, Hz (default the
        geometric centre of ``band``; use the resonance of the system).
    n_points : int
        Fit frequencies (>= 10).

    Returns
    -------
    GeneralizedMaxwellTyre

    Raises
    ------
    PhysicsError
        The band is so wide that ``k0`` would not be positive.
    """
    if not isinstance(model, HystereticModel):
        raise InputError(f"model: expected a HystereticModel, got {type(model).__name__}")
    lo, hi = as_band(band, positive=True)  # log-spaced arms
    if int(per_decade) < 1 or int(n_points) < 10:
        raise InputError(
            f"per_decade >= 1 and n_points >= 10 expected, got {per_decade}, {n_points}"
        )
    fr = math.sqrt(lo * hi) if f_ref is None else check_positive(f_ref, "f_ref")
    if model.h == 0:
        return GeneralizedMaxwellTyre(k0=model.K, stiffness=(), tau=(), C_r=model.C_r)
    dec = math.log10(hi / lo)
    n_arms = math.ceil((dec + 1.0) * int(per_decade)) + 1
    f_arm = np.logspace(math.log10(lo) - 0.5, math.log10(hi) + 0.5, n_arms)
    tau = 1.0 / (2.0 * np.pi * f_arm)
    w = 2.0 * np.pi * np.logspace(math.log10(lo), math.log10(hi), int(n_points))
    wt = w[:, None] * tau[None, :]
    loss = wt / (1.0 + wt**2)
    coef, _ = nnls(loss / model.h, np.ones(w.size), maxiter=50 * tau.size)
    wr = 2.0 * np.pi * fr * tau
    k0 = model.K - float(np.sum(coef * wr**2 / (1.0 + wr**2)))
    if k0 <= 0:
        raise PhysicsError(
            f"band: [{lo:g}, {hi:g}] Hz is too wide for h/K = {model.loss_factor:.3g}; the "
            f"static stiffness k0 = {k0:.3g} N/m would not be positive"
        )
    keep = coef > 0
    return GeneralizedMaxwellTyre(
        k0=k0,
        stiffness=tuple(float(x) for x in coef[keep]),
        tau=tuple(float(x) for x in tau[keep]),
        C_r=model.C_r,
    )
