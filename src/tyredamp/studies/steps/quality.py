"""The ``checks`` step: data quality of time data or FRFs (``tyredamp check quality``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...frf import FRF
from ...timedata import TimeData
from ._settings import Band, Number, StepSettings, knob

if TYPE_CHECKING:
    from ...signal import CheckResult

__all__ = ["QualitySettings", "QualityStep"]


@dataclass(frozen=True)
class QualitySettings(StepSettings):
    """Thresholds of the data-quality check (clipping, dead channels, low coherence,
    drive-point passivity)."""

    section: ClassVar[str] = "checks"

    coherence_min: float = knob(
        0.9,
        "Lines with multiple coherence below this count as low.",
        Number(0.0, 1.0, optional=False),
        "--coherence-min",
    )
    max_low_fraction: float = knob(
        0.1,
        "Largest accepted fraction of low-coherence lines where the response is strong.",
        Number(0.0, 1.0, optional=False),
        "--max-low-fraction",
    )
    band: tuple[float, float] | None = knob(
        None,
        "Check only lines in this band (Hz).",
        Band(),
        "--band",
        unit="Hz",
        metavar="F_LO F_HI",
    )


class QualityStep:
    """Time data or FRF -> :class:`~tyredamp.signal.CheckResult` (its own verdict).

    In a campaign the switch ``quality`` (default true) turns it off.
    """

    name: ClassVar[str] = "checks"
    Settings: ClassVar[type[QualitySettings]] = QualitySettings
    #: the campaign key that switches the step off (the CLI runs it or not)
    switch: ClassVar[str] = "quality"

    @staticmethod
    def run(data: TimeData | FRF, settings: QualitySettings) -> tuple[CheckResult, dict[str, Any]]:
        """The quality check of ``data``; the verdict is the result's ``passed``."""
        from ...signal import quality_check

        res = quality_check(
            data,
            coherence_min=settings.coherence_min,
            max_low_coherence_fraction=settings.max_low_fraction,
            band=settings.band,
        )
        return res, {"quality": res}
