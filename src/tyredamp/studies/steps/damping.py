"""The ``damping`` step: the damping matrix from identified modes (``tyredamp damping``)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...exceptions import InputError
from ._settings import Band, Boolean, Check, Choice, Integer, StepSettings, knob

if TYPE_CHECKING:
    from ...damping import DampingModel
    from ...modal.model import ModalModel

#: The estimators of :data:`tyredamp.damping.METHODS` (named here so that the settings
#: load without the numerical packages; a test keeps the two equal).
DAMPING_METHODS: tuple[str, ...] = ("first", "improved", "refined")

__all__ = ["DampingSettings", "DampingStep", "ModeNumbers"]


#: Most Monte Carlo samples of the damping step (standard errors to about 0.7 %).
MAX_SAMPLES = 10_000
#: Highest mode number a selection may name (no fit holds more modes).
MAX_MODE_NUMBER = 1000


@dataclass(frozen=True)
class ModeNumbers(Check):
    """Mode numbers counted from 1: text such as ``"1,2,5-7"`` or a list of integers."""

    def __call__(self, value: Any, where: str) -> Any:
        from ...damping.modeset import parse_mode_numbers

        if value is None:
            return None
        if isinstance(value, list | tuple) and all(
            isinstance(v, int) and not isinstance(v, bool) for v in value
        ):
            value = ",".join(str(v) for v in value)
        if not isinstance(value, str):
            raise InputError(f"{where}: expected mode numbers such as 1,2,5-7, got {value!r}")
        if any(int(n) > MAX_MODE_NUMBER for n in re.findall(r"\d+", value[:10000])) or (
            len(value) > 10000
        ):
            raise InputError(
                f"{where}: expected mode numbers from 1 to {MAX_MODE_NUMBER}, got {value[:80]!r}"
            )
        try:
            return tuple(parse_mode_numbers(value))
        except InputError as exc:
            raise InputError(f"{where}:{str(exc).split(':', 1)[1]}") from None

    def schema(self) -> dict[str, Any]:
        return {
            "type": ["array", "string"],
            "items": {"type": "integer", "minimum": 1},
            "minItems": 1,
            "description": "mode numbers counted from 1, or text such as '1,2,5-7'",
        }


@dataclass(frozen=True)
class DampingSettings(StepSettings):
    """How the damping matrix is identified (``tyredamp damping``; a campaign's
    ``[settings.radial.damping]``)."""

    section: ClassVar[str] = "damping"

    method: str = knob(
        "improved",
        "first: eq. [16]; improved: eq. [18]; refined: bias-corrected (exact for "
        "consistent modes).",
        Choice(DAMPING_METHODS),
        "--method",
    )
    model: str = knob(
        "complex",
        "Which model of the modes file to use (complex modes carry the coupling).",
        Choice(("complex", "real")),
        "--model",
    )
    samples: int = knob(
        200,
        "Monte Carlo samples for the standard errors (0 to skip; at most 10000: the "
        "standard error of a standard error from N samples is about 1/sqrt(2N), 0.7 % at "
        "10000).",
        Integer(0, optional=False, maximum=MAX_SAMPLES),
        "--samples",
    )
    seed: int = knob(0, "Monte Carlo seed.", Integer(0, optional=False), "--seed")
    modes: tuple[int, ...] | None = knob(
        None,
        "Modes to use, numbered from 1 in order of frequency: e.g. 1,2,5-7 (default all).",
        ModeNumbers(),
        "--modes",
        metavar="LIST",
    )
    band: tuple[float, float] | None = knob(
        None,
        "Use only the modes with natural frequency in F1..F2 Hz.",
        Band(),
        "--band",
        unit="Hz",
        metavar="F1 F2",
    )
    normalise: bool = knob(
        True,
        "Skip the alpha_n^(n) = 1 phase normalisation of the complex shapes.",
        Boolean(),
        "--no-normalise",
    )


class DampingStep:
    """Identified modes -> :class:`~tyredamp.damping.DampingModel` (findings inside)."""

    name: ClassVar[str] = "damping"
    Settings: ClassVar[type[DampingSettings]] = DampingSettings
    #: the campaign key that switches the step off (the CLI runs it or not)
    switch: ClassVar[str] = "enabled"

    @staticmethod
    def run(
        models: dict[str, ModalModel],
        settings: DampingSettings,
        meta: dict[str, Any] | None = None,
    ) -> tuple[DampingModel, dict[str, Any]]:
        """The damping matrix of ``models[settings.model]``; no verdicts of its own
        (its findings are in the result)."""
        from ..radial import damping_from_modes

        s = settings
        dm = damping_from_modes(
            models,
            model=s.model,
            method=s.method,  # type: ignore[arg-type]
            normalise=s.normalise,
            n_samples=s.samples,
            seed=s.seed,
            meta=meta,
            modes=None if s.modes is None else list(s.modes),
            band=s.band,
        )
        return dm, {}

    @staticmethod
    def document(result: DampingModel) -> dict[str, Any]:
        """The damping document (``docs/damping-json.md``)."""
        from ...documents.damping import damping_document

        return damping_document(result)
