"""Settings of the demo: what both studies run on the virtual tyres."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypedDict

import numpy as np

from ..exceptions import InputError
from ..lateral import DEFAULT_MODELS

if TYPE_CHECKING:
    from .steps import (
        DampingSettings,
        FrfSettings,
        LateralFitSettings,
        ModalSettings,
        QualitySettings,
    )
    from .steps.rolling import RollingSettings

__all__ = ["BAR", "LATERAL_MODELS", "DemoSettings", "DemoSteps"]

#: One bar in Pa.
BAR = 1.0e5
#: The six lateral models fitted by the demo: the paper's four, then the
#: relaxation-length and stretched-string models.
LATERAL_MODELS: tuple[str, ...] = (*DEFAULT_MODELS, "relaxation", "string")


class DemoSteps(TypedDict):
    """The settings of each registered step the demo runs, by step name."""

    frf: FrfSettings
    checks: QualitySettings
    modal: ModalSettings
    damping: DampingSettings
    fit: LateralFitSettings
    rolling: RollingSettings


@dataclass(frozen=True)
class DemoSettings:
    """What the demo runs. :meth:`full` and :meth:`quick` give the two presets.

    Parameters
    ----------
    quick : bool
        Label of the preset (reported; the numbers below decide the work).
    seed : int
        Base seed of every noise generator (same seed, same results).
    radial_pressures_bar : tuple of float
        Inflation pressures of the radial modal test, bar; the first is the
        main one (checks, damping, figures).
    radial_periods : int
        Chirp periods (averages) of the main test.
    radial_side_periods : int
        Periods at the other pressures.
    check_periods : int
        Periods of the extra tests for the linearity and reciprocity checks.
    force_levels_n : (float, float)
        RMS shaker forces of the linearity check, N; the first is the main
        test's force.
    reciprocity_points : (int, int)
        Drive points (1-based point numbers) of the reciprocity test.
    snr_db : float
        Signal-to-noise ratio of every channel of the modal tests, dB.
    check_band_hz : (float, float)
        Band of the linearity, reciprocity and data-quality checks, Hz (below
        it the accelerance of a free tread band is tiny and noise dominates).
    damping_method : {"first", "improved", "refined"}
        Estimator of ``C'`` (eq. [16], [18] or bias-corrected).
    damping_samples : int
        Monte Carlo samples for the damping standard errors.
    lateral_speeds_kmh, lateral_pressures_bar : tuple of float
        Conditions of the rolling-tyre rig.
    lateral_models : tuple of str
        Models fitted at each condition (registry names).
    reference_condition : (float, float)
        ``(pressure_bar, speed_kmh)`` of the vehicle model and time test.
    time_test_frequency_hz : float
        Frequency of the sinusoidal time test, Hz (paper: 2.73).
    """

    quick: bool = False
    seed: int = 0
    radial_pressures_bar: tuple[float, ...] = (7.5, 6.0, 9.0)
    radial_periods: int = 8
    radial_side_periods: int = 8
    check_periods: int = 8
    force_levels_n: tuple[float, float] = (10.0, 40.0)
    reciprocity_points: tuple[int, int] = (1, 5)
    snr_db: float = 40.0
    check_band_hz: tuple[float, float] = (30.0, 200.0)
    damping_method: str = "improved"
    damping_samples: int = 200
    lateral_speeds_kmh: tuple[float, ...] = (5.0, 10.0)
    lateral_pressures_bar: tuple[float, ...] = (1.28, 1.7, 2.4)
    lateral_models: tuple[str, ...] = LATERAL_MODELS
    reference_condition: tuple[float, float] = (1.7, 5.0)
    time_test_frequency_hz: float = 2.73

    def __post_init__(self) -> None:
        if not self.radial_pressures_bar:
            raise InputError("radial_pressures_bar: expected at least one pressure")
        for p in self.radial_pressures_bar:
            if not (np.isfinite(p) and p >= 0):
                raise InputError(f"radial_pressures_bar: expected pressures >= 0 bar, got {p}")
        for name in ("radial_periods", "radial_side_periods", "check_periods"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1:
                raise InputError(f"{name}: expected an integer >= 1, got {v!r}")
        if not isinstance(self.seed, int) or self.seed < 0:
            raise InputError(f"seed: expected an integer >= 0, got {self.seed!r}")
        ref_p, ref_v = self.reference_condition
        if ref_p not in self.lateral_pressures_bar or ref_v not in self.lateral_speeds_kmh:
            raise InputError(
                f"reference_condition: expected a pressure in {self.lateral_pressures_bar} and "
                f"a speed in {self.lateral_speeds_kmh}, got {self.reference_condition}"
            )
        if "hysteretic" not in self.lateral_models:
            raise InputError("lateral_models: the proposed 'hysteretic' model must be included")

    @classmethod
    def full(cls, seed: int = 0) -> DemoSettings:
        """The full demo: 3 radial pressures with 8 averages each, 6 lateral conditions."""
        return cls(quick=False, seed=seed)

    @classmethod
    def quick_preset(cls, seed: int = 0) -> DemoSettings:
        """Reduced setting (tests, a first look): 2 pressures, fewer averages, 2 conditions."""
        return cls(
            quick=True,
            seed=seed,
            radial_pressures_bar=(7.5, 9.0),
            radial_periods=4,
            radial_side_periods=2,
            check_periods=2,
            damping_samples=50,
            lateral_pressures_bar=(1.7,),
        )

    def step_settings(self) -> DemoSteps:
        """The settings of each registered step the demo runs, by step name.

        The demo runs the steps of :data:`tyredamp.studies.registry.STEPS` (the
        recipe of the command line and of a campaign); this is the one place
        where its own knobs become theirs: ``checks`` over ``check_band_hz``,
        ``damping`` with ``damping_method``, ``damping_samples`` and ``seed``,
        ``fit`` with ``lateral_models``, ``rolling`` without the jackknife
        standard errors; ``frf`` (H1, averaging method from the data) and
        ``modal`` (both models) take the steps' defaults.
        """
        from .steps import (
            DampingSettings,
            FrfSettings,
            LateralFitSettings,
            ModalSettings,
            QualitySettings,
        )
        from .steps.rolling import RollingSettings

        return {
            "frf": FrfSettings(),
            "checks": QualitySettings(band=self.check_band_hz),
            "modal": ModalSettings(),
            "damping": DampingSettings(
                method=self.damping_method, samples=self.damping_samples, seed=self.seed
            ),
            "fit": LateralFitSettings(models=self.lateral_models),
            "rolling": RollingSettings(uncertainty=False),
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready copy of the settings."""
        out: dict[str, Any] = {}
        for k, v in self.__dict__.items():
            out[k] = list(v) if isinstance(v, tuple) else v
        return out
