"""The registry of steps: every path (CLI, campaign, demo, Python) finds a step here.

:data:`STEPS` maps a step's name to its class; a step class has

* ``name``: its name (the key here, the section of a campaign's settings);
* ``Settings``: a frozen :class:`~tyredamp.studies.steps.StepSettings`
  dataclass, every knob declared once (default, unit, check, text, option);
* ``run(inputs, settings) -> (result, verdicts)``: the whole recipe;
* optionally ``document(result, ...)`` (its JSON document), ``switch`` (the
  campaign key that turns it off), and for a step a campaign runs on a test
  file: ``sections`` (the settings sections its result depends on, default
  its own), ``conditions`` (the test conditions it uses) and
  ``run_file(path, upstream, settings, conditions) -> document``.

:data:`STUDIES` gives the chain of steps a campaign runs on each test of a
study. A new step is one module and one line of :data:`STEPS` (and one entry
in a chain of :data:`STUDIES` when a campaign should run it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .steps import DampingStep, FrfStep, LateralFitStep, ModalStep, QualityStep, StepSettings
from .steps.rolling import RollingStep

__all__ = ["STEPS", "STUDIES", "Study", "settings_class", "step_sections"]

#: Every step by name.
STEPS: dict[str, Any] = {
    "frf": FrfStep,
    "checks": QualityStep,
    "modal": ModalStep,
    "damping": DampingStep,
    "fit": LateralFitStep,
    "rolling": RollingStep,
}


@dataclass(frozen=True)
class Study:
    """The chain of steps a campaign runs on a test of one study.

    Attributes
    ----------
    name : str
        ``"radial"`` or ``"lateral"``.
    steps : tuple of str
        Step names (keys of :data:`STEPS`) in order; a step's cache key includes
        the keys of the steps before it.
    """

    name: str
    steps: tuple[str, ...]

    @property
    def settings_of(self) -> dict[str, tuple[str, ...]]:
        """For each step, the settings sections its result depends on."""
        return {s: step_sections(s) for s in self.steps}

    @property
    def sections(self) -> tuple[str, ...]:
        """Every settings section of the study, in the order of its steps."""
        return tuple(dict.fromkeys(x for s in self.steps for x in step_sections(s)))

    @property
    def optional(self) -> frozenset[str]:
        """Steps a campaign can switch off (those with a ``switch``)."""
        return frozenset(s for s in self.steps if getattr(STEPS[s], "switch", None))

    @property
    def conditions_of(self) -> dict[str, tuple[str, ...]]:
        """For each step, the test conditions its result depends on."""
        return {s: tuple(getattr(STEPS[s], "conditions", ())) for s in self.steps}


#: The studies of a campaign and their chains of steps.
STUDIES: dict[str, Study] = {
    "radial": Study("radial", ("modal", "damping")),
    "lateral": Study("lateral", ("fit",)),
    "rolling": Study("rolling", ("rolling",)),
}


def step_sections(step: str) -> tuple[str, ...]:
    """The settings sections the result of ``step`` depends on (its own by default)."""
    return tuple(getattr(STEPS[step], "sections", (step,)))


def settings_class(section: str) -> type[StepSettings]:
    """The settings class of a section (a step's name)."""
    cls: type[StepSettings] = STEPS[section].Settings
    return cls
