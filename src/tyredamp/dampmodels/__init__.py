"""Which damping model does the structure have? Damping laws, exact modes, identification, choice.

Damping laws (:mod:`.laws`): viscous, hysteretic (complex stiffness), exponential
relaxation kernels and fractional derivative, each the damping part ``Z(s)``
of the dynamic stiffness ``D(s) = s^2 M + K + Z(s)`` (Adhikari & Woodhouse,
J. Sound Vib. 243(1) (2001) 63-88). :class:`DampedSystem` gives their exact
FRFs and exact modes. Identification: from complex modes
(:func:`exponential_from_modes`, A-W part 2, with its viscous-consistency
test) and from FRFs (:func:`fit_model`); :func:`compare_models` ranks the
models by likelihood under the measured noise and gives a verdict.
"""

from __future__ import annotations

from .choice import LikelihoodRatio, ModelComparison, compare_models, likelihood_ratio
from .frffit import MODELS, ModalStart, ModelFit, fit_model, start_from_modes
from .fromodes import RelaxationEstimate, exponential_from_modes
from .laws import LAWS, DampingLaw, Exponential, Fractional, Hysteretic, Viscous
from .system import DampedSystem, ExactModes, newton_mode

__all__ = [
    "LAWS",
    "MODELS",
    "DampedSystem",
    "DampingLaw",
    "ExactModes",
    "Exponential",
    "Fractional",
    "Hysteretic",
    "LikelihoodRatio",
    "ModalStart",
    "ModelComparison",
    "ModelFit",
    "RelaxationEstimate",
    "Viscous",
    "compare_models",
    "exponential_from_modes",
    "fit_model",
    "likelihood_ratio",
    "newton_mode",
    "start_from_modes",
]
