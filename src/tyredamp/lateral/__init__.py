"""Lateral tyre dynamics of paper 001 (spec ``lateral-models.md``).

* :mod:`.models` -- the linear models (classic, Maxwell, visco-plastic,
  proposed hysteretic, relaxation length, stretched string) with receptance,
  mobility and accelerance at the ground or axle force; :mod:`.base` -- the
  interface they implement and their registry; :mod:`.response` -- the
  algebra they share (wheel mass, axle/ground force, string impedance).
* :mod:`.fiala` -- steady-state Fiala/brush force and its non-linear damper form.
* :mod:`.characteristics` -- corner frequency and the dB differences of
  eq. 38-40, Figure 7 data.
* :mod:`.fit` -- weighted complex least-squares fits, standard errors, Table 1
  figure; :mod:`.ranking` -- AIC/BIC ranking; :mod:`.joint` -- joint fits
  across speeds.
* :mod:`.vehicle` -- the single-degree-of-freedom vehicle (eq. 41-44).
* :mod:`.timedomain` -- exact harmonic/periodic steady states, impulse
  response and non-causal precursor, and exact state-space transients;
  :mod:`.prony` -- the causal generalised-Maxwell approximation of the
  hysteretic tyre; :mod:`.causality` -- its error against the ideal model.

The virtual rolling-tyre rig is :mod:`tyredamp.virtual.lateral_rig`.
"""

from __future__ import annotations

from .causality import CausalError, causal_error
from .characteristics import (
    CornerDifferences,
    Figure7Curves,
    corner_differences,
    corner_frequency,
    delta_ar_asymptote,
    delta_ar_maxwell,
    figure7_curves,
)
from .fiala import FialaTyre
from .fit import DEFAULT_MODELS, LateralData, LateralFit, fit_model
from .joint import JointFit, fit_by_pressure, fit_joint
from .models import (
    MODELS,
    ClassicModel,
    HystereticModel,
    LateralModel,
    MaxwellModel,
    RelaxationLengthModel,
    StretchedStringModel,
    ViscoPlasticModel,
    get_model_class,
)
from .prony import GeneralizedMaxwellTyre, fit_generalized_maxwell
from .ranking import Ranking, rank_models
from .response import attach_mass, axle_from_ground_accelerance, ground_from_axle_accelerance
from .timedomain import (
    harmonic_response,
    impulse_response,
    periodic_response,
    precursor,
    state_space,
    transient_response,
)
from .vehicle import LateralVehicle, Resonance

__all__ = [
    "DEFAULT_MODELS",
    "MODELS",
    "CausalError",
    "ClassicModel",
    "CornerDifferences",
    "FialaTyre",
    "Figure7Curves",
    "GeneralizedMaxwellTyre",
    "HystereticModel",
    "JointFit",
    "LateralData",
    "LateralFit",
    "LateralModel",
    "LateralVehicle",
    "MaxwellModel",
    "Ranking",
    "RelaxationLengthModel",
    "Resonance",
    "StretchedStringModel",
    "ViscoPlasticModel",
    "attach_mass",
    "axle_from_ground_accelerance",
    "causal_error",
    "corner_differences",
    "corner_frequency",
    "delta_ar_asymptote",
    "delta_ar_maxwell",
    "figure7_curves",
    "fit_by_pressure",
    "fit_generalized_maxwell",
    "fit_joint",
    "fit_model",
    "get_model_class",
    "ground_from_axle_accelerance",
    "harmonic_response",
    "impulse_response",
    "periodic_response",
    "precursor",
    "rank_models",
    "state_space",
    "transient_response",
]
