"""The steps of the studies, one module each: typed settings, the recipe, the document.

Each step module holds a frozen settings dataclass (every knob declared
once with :func:`knob`: default, unit, check, text and command-line option;
unknown keys refused) and a step class whose ``run(inputs, settings)``
returns ``(result, verdicts)``. :mod:`tyredamp.studies.registry` lists them;
the command line builds its options from the settings classes, a campaign
file is validated against them, and the demo and Python call the same
``run``.
"""

from ._settings import (
    Band,
    Boolean,
    Check,
    Choice,
    Integer,
    Knob,
    Length,
    Names,
    Number,
    Pair,
    Positives,
    Registered,
    StepSettings,
    knob,
    knobs,
    samples,
)
from .damping import DampingSettings, DampingStep
from .frf import FrfSettings, FrfStep
from .lateral_fit import LateralFitSettings, LateralFitStep
from .modal import ModalSettings, ModalStep
from .quality import QualitySettings, QualityStep

__all__ = [
    "Band",
    "Boolean",
    "Check",
    "Choice",
    "DampingSettings",
    "DampingStep",
    "FrfSettings",
    "FrfStep",
    "Integer",
    "Knob",
    "LateralFitSettings",
    "LateralFitStep",
    "Length",
    "ModalSettings",
    "ModalStep",
    "Names",
    "Number",
    "Pair",
    "Positives",
    "QualitySettings",
    "QualityStep",
    "Registered",
    "StepSettings",
    "knob",
    "knobs",
    "samples",
]
