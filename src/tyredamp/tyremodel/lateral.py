"""Lateral bridge: the lateral carcass quantities a ``.tir`` file holds, from the lateral fits.

The lateral models of paper 001 (spec ``lateral-models.md``) fitted to a
rolling tyre's lateral FRF (:mod:`tyredamp.lateral.fit`) contain a carcass
spring ``K`` (``k`` in the Maxwell and visco-plastic models) in series with
the tyre-road damper ``C_r = C_alpha / V`` (``c``, ``c2``; eq. 19, 33). In
the first-order relaxation model (eq. 13, 21) the same series pair is
``k = C_alpha / sigma``, ``c = C_alpha / V``, hence the relaxation length

``sigma = C_r V / K``

and the cornering stiffness ``C_alpha = C_r V``. The lateral stiffness is
``K``. For the relaxation and stretched-string models the fitted values are
used directly (for the string ``C_r V / K = sigma + a``, its standing-tyre
value). The classic (Kelvin-Voigt) model has no tyre-road damper, so it
gives no relaxation length.

Standard errors: from the fit's correlation of the log-parameters when a
:class:`~tyredamp.lateral.fit.LateralFit` is given; from a lateral-fit JSON
(which stores standard errors but no correlations) the two parameters are
taken as uncorrelated and the result says so.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError, InputError
from ..lateral.fit import LateralFit

__all__ = ["LateralCarcass", "lateral_carcass", "read_lateral_carcass"]

# model name -> (stiffness parameter, road damper parameter)
#: Mean relative amplitude misfit above which the lateral quantities are model-limited.
MODEL_LIMITED = 0.05

_PAIRS = {
    "hysteretic": ("K", "C_r"),
    "maxwell": ("k", "c"),
    "viscoplastic": ("k", "c2"),
}


@dataclass(frozen=True)
class LateralCarcass:
    """Lateral carcass quantities of one lateral fit (SI).

    Attributes
    ----------
    model : str
        Lateral model name.
    speed : float
        Test speed ``V`` in m/s.
    pressure_bar : float or None
        Inflation pressure, when known.
    lateral_stiffness, lateral_stiffness_std : float
        ``K`` in N/m.
    relaxation_length, relaxation_length_std : float
        ``sigma = C_r V / K`` in m.
    cornering_stiffness, cornering_stiffness_std : float
        ``C_alpha = C_r V`` in N/rad.
    correlation_used : bool
        Whether the standard errors include the fit's correlation.
    source : str
    model_error : float or None
        The fit's mean absolute relative amplitude error (a fraction; the
        misfit of the model to the measured FRF, paper 001 Table 1), when known.
        Above :data:`MODEL_LIMITED` the quantities are flagged model-limited:
        their standard errors describe the noise, not the model's misfit.
    """

    model: str
    speed: float
    pressure_bar: float | None
    lateral_stiffness: float
    lateral_stiffness_std: float
    relaxation_length: float
    relaxation_length_std: float
    cornering_stiffness: float
    cornering_stiffness_std: float
    correlation_used: bool
    source: str = ""
    model_error: float | None = None

    @property
    def model_limited(self) -> bool:
        """Whether the model misses the measured FRF by more than :data:`MODEL_LIMITED`."""
        return self.model_error is not None and self.model_error > MODEL_LIMITED

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary with units."""
        return {
            "model": self.model,
            "speed_m_s": self.speed,
            "speed_kmh": self.speed * 3.6,
            "pressure_bar": self.pressure_bar,
            "lateral_stiffness": {
                "value": self.lateral_stiffness,
                "stderr": self.lateral_stiffness_std,
                "unit": "N/m",
            },
            "relaxation_length": {
                "value": self.relaxation_length,
                "stderr": self.relaxation_length_std,
                "unit": "m",
            },
            "cornering_stiffness": {
                "value": self.cornering_stiffness,
                "stderr": self.cornering_stiffness_std,
                "unit": "N/rad",
            },
            "stderr_note": "with the fit's correlation"
            if self.correlation_used
            else "parameters taken as uncorrelated (the lateral-fit JSON has no correlations)",
            "source": self.source,
            "model_error": self.model_error,
            "model_limited": self.model_limited,
        }

    def comment(self) -> str:
        """One line for a ``.tir`` comment."""
        p = "?" if self.pressure_bar is None else f"{self.pressure_bar:g} bar"
        return (
            f"lateral carcass ({self.model} fit, {self.speed * 3.6:g} km/h, {p}): "
            f"K = {self.lateral_stiffness:.5g} +- {self.lateral_stiffness_std:.2g} N/m, "
            f"relaxation length C_r V / K = {self.relaxation_length:.4g} +- "
            f"{self.relaxation_length_std:.2g} m"
            + (
                f"; MODEL-LIMITED: the fit misses the FRF by {100 * self.model_error:.2g} % on "
                "average, more than its standard errors say"
                if self.model_limited and self.model_error is not None
                else ""
            )
        )


def _from_parts(
    model: str,
    params: Mapping[str, float],
    stderr: Mapping[str, float],
    derived: Mapping[str, float],
    speed: float | None,
    corr: Any,
    names: tuple[str, ...] | None,
    pressure_bar: float | None,
    source: str,
) -> LateralCarcass:
    if speed is None or not (math.isfinite(speed) and speed > 0):
        raise InputError(
            f"lateral fit ({model}): the test speed is unknown; the relaxation length needs it"
        )
    v = float(speed)
    rho = 0.0
    if model in _PAIRS:
        kn, cn = _PAIRS[model]
        k, c = float(params[kn]), float(params[cn])
        rk, rc = float(stderr[kn]) / k, float(stderr[cn]) / c
        if corr is not None and names is not None:
            rho = float(corr[names.index(kn), names.index(cn)])
        ca, rca = c * v, rc
        sigma = c * v / k
        rs = math.sqrt(max(rk**2 + rc**2 - 2 * rho * rk * rc, 0.0))
    elif model == "relaxation":
        ca, sigma = float(params["C_alpha"]), float(params["sigma"])
        rca, rs = float(stderr["C_alpha"]) / ca, float(stderr["sigma"]) / sigma
        if corr is not None and names is not None:
            rho = float(corr[names.index("C_alpha"), names.index("sigma")])
        k = ca / sigma
        rk = math.sqrt(max(rca**2 + rs**2 - 2 * rho * rca * rs, 0.0))
    elif model == "string":
        ca = float(params["C_alpha"])
        sigma = float(params["sigma"]) + float(params["a"])
        rca = float(stderr["C_alpha"]) / ca
        rs = math.hypot(float(stderr["sigma"]), float(stderr["a"])) / sigma
        k = float(derived.get("lateral_stiffness", ca / sigma))
        rk = math.hypot(rca, rs)
    else:
        raise InputError(
            f"lateral fit ({model}): the model has no tyre-road damper, so no relaxation length "
            "(use the proposed hysteretic, Maxwell, visco-plastic, relaxation or string fit)"
        )
    return LateralCarcass(
        model=model,
        speed=v,
        pressure_bar=pressure_bar,
        lateral_stiffness=k,
        lateral_stiffness_std=k * rk,
        relaxation_length=sigma,
        relaxation_length_std=sigma * rs,
        cornering_stiffness=ca,
        cornering_stiffness_std=ca * rca,
        correlation_used=corr is not None or model == "string",
        source=source,
    )


def _with_error(err: Any, c: LateralCarcass) -> LateralCarcass:
    """``c`` with the fit's relative amplitude misfit, when it is a finite number."""
    from dataclasses import replace

    if isinstance(err, (int, float)) and not isinstance(err, bool) and math.isfinite(err):
        return replace(c, model_error=float(err))
    return c


def lateral_carcass(
    fit: LateralFit | Mapping[str, Any],
    *,
    pressure_bar: float | None = None,
    speed: float | None = None,
    source: str = "",
) -> LateralCarcass:
    """Lateral stiffness and relaxation length ``C_r V / K`` of one lateral fit.

    Parameters
    ----------
    fit : LateralFit or mapping
        A fit object, or one entry of ``"fits"`` of the lateral-fit JSON
        (``tyredamp lateral fit``).
    pressure_bar : float, optional
        Inflation pressure (reported only).
    speed : float, optional
        Test speed in m/s when the fit does not carry it.
    source : str
    """
    if isinstance(fit, LateralFit):
        names = fit.model.param_names
        return _with_error(
            fit.amplitude_error,
            _from_parts(
                fit.model.name,
                fit.params,
                fit.stderr,
                fit.model.derived(),
                fit.speed if fit.speed is not None else speed,
                fit.correlation,
                names,
                pressure_bar,
                source,
            ),
        )
    try:
        sp = fit.get("speed_m_s")
        return _with_error(
            fit.get("amplitude_error"),
            _from_parts(
                str(fit["model"]),
                fit["params"],
                fit["stderr"],
                fit.get("derived", {}),
                float(sp) if sp is not None else speed,
                None,
                None,
                pressure_bar,
                source,
            ),
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"lateral fit: malformed entry ({exc!r})") from None


def read_lateral_carcass(
    path: str | os.PathLike[str],
    *,
    pressure_bar: float | None = None,
    all_models: bool = False,
) -> list[LateralCarcass]:
    """Lateral carcass quantities from a lateral-fit JSON (``tyredamp lateral fit``).

    Uses the best-ranked model that has a tyre-road damper (or every such
    model with ``all_models``). The pressure comes from ``pressure_bar`` or
    the file's ``conditions.pressure_bar``.

    Raises
    ------
    FileFormatError
        Not a lateral-fit JSON.
    InputError
        No fit with a tyre-road damper, unknown speed.
    """
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FileFormatError(f"{p}: not a lateral-fit JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("tyredamp") != "lateral-fit":
        raise FileFormatError(f'{p}: expected a lateral-fit document ("tyredamp": "lateral-fit")')
    fits = doc.get("fits")
    if not isinstance(fits, list) or not fits:
        raise FileFormatError(f"{p}: no fits in the document")
    cond = doc.get("conditions") or {}
    pb = pressure_bar if pressure_bar is not None else cond.get("pressure_bar")
    by_name = {f.get("model"): f for f in fits if isinstance(f, dict)}
    order = [m for m in doc.get("order", list(by_name)) if m in by_name]
    usable = [m for m in order if m in (*_PAIRS, "relaxation", "string")]
    if not usable:
        raise InputError(f"{p}: no fitted model with a tyre-road damper ({order})")
    chosen = usable if all_models else usable[:1]
    return [
        lateral_carcass(
            by_name[m],
            pressure_bar=None if pb is None else float(pb),
            speed=cond.get("speed_m_s"),
            source=p.name,
        )
        for m in chosen
    ]
