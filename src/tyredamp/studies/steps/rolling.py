"""The ``rolling`` step: travelling waves of a rolling tyre from output-only data.

The recipe is :func:`tyredamp.oma.rolling.rolling_modes` (fixed sensors:
SSI-cov and the spatial split into forward and backward waves; the in-tyre
sensor: pLSCF resolved through ``f_fixed = f_rot + s n f_w``), the same call
as ``tyredamp rolling``. A campaign runs it on each test of the ``rolling``
study; the fixed-frame modes, with their shapes at the sensor angles, are
what the campaign tracks against speed (families ``n=3 forward`` ...).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ...exceptions import InputError
from ...timedata import TimeData
from ._settings import Band, Boolean, StepSettings, knob

__all__ = ["RollingSettings", "RollingStep"]


@dataclass(frozen=True)
class RollingSettings(StepSettings):
    """How a rolling tyre is identified output-only (``tyredamp rolling``; a campaign's
    ``[settings.rolling.rolling]``)."""

    section: ClassVar[str] = "rolling"

    band: tuple[float, float] | None = knob(
        None,
        "Band of the identification (Hz); default the recording's band.",
        Band(),
        "--band",
        unit="Hz",
        metavar="F_LO F_HI",
    )
    uncertainty: bool = knob(
        True,
        "Skip the jackknife standard errors of the modes (faster).",
        Boolean(),
        "--no-uncertainty",
    )
    spatial: bool = knob(
        False,
        "Identify each wave number and direction apart (fixed sensors equally spaced "
        "around the tyre; the default for such sensors and a long enough record).",
        Boolean(),
        "--spatial",
    )
    general: bool = knob(
        False,
        "Identify all fixed sensors together and split each mode into waves afterwards "
        "(the default for sensors not equally spaced).",
        Boolean(),
        "--general",
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.spatial and self.general:
            raise InputError("spatial, general: expected one route for the fixed sensors, got both")

    @property
    def route(self) -> bool | None:
        """``spatial`` of :func:`~tyredamp.oma.rolling.rolling_modes`: ``True``,
        ``False`` or ``None`` (its default: by the sensors' layout)."""
        return True if self.spatial else (False if self.general else None)


class RollingStep:
    """Rolling-tyre waves from one output-only recording (module docstring)."""

    name: ClassVar[str] = "rolling"
    Settings: ClassVar[type[RollingSettings]] = RollingSettings
    conditions: ClassVar[tuple[str, ...]] = ()

    @staticmethod
    def run(
        data: TimeData, settings: RollingSettings, wheel_speed_hz: float | None = None
    ) -> tuple[Any, list[Any]]:
        """The waves (:class:`~tyredamp.oma.rolling.RollingModes`) and no verdicts."""
        from ...oma.rolling import rolling_modes

        res = rolling_modes(
            data,
            wheel_speed_hz,
            band=settings.band,
            uncertainty=settings.uncertainty,
            spatial=settings.route,
        )
        return res, []

    @staticmethod
    def document(result: Any, source: str = "") -> dict[str, Any]:
        """JSON document: the waves and the fixed-frame modes with their shapes.

        ``modes``: one per fixed-frame mode: ``frequency_hz``, ``damping_ratio``,
        their standard errors, ``shape`` as ``[re, im]`` rows at ``angles_deg``.
        """
        r = result.fixed_result
        modes = []
        if r is None:  # the wave-number route: each wave is a mode of one wave number
            from ...oma.spatial import wave_shape

            for w in result.fixed:
                n, d = int(w.wave_number or 0), w.fixed_direction or "standing"
                psi = wave_shape(n, d, result.angles_deg)
                sf, sz = w.std_frequency_hz, w.std_damping_ratio
                modes.append(
                    {
                        "frequency_hz": w.fixed_hz,
                        "damping_ratio": w.damping_ratio,
                        "std_frequency_hz": sf if np.isfinite(sf) else None,
                        "std_damping_ratio": sz if np.isfinite(sz) else None,
                        "shape": np.column_stack([psi.real, psi.imag]).tolist(),
                    }
                )
        else:
            # the modes that gave a wave (not those the band edge cut off)
            waved = {w.fixed_hz for w in result.fixed}
            for j in (j for j in range(r.n_modes) if float(r.frequency_hz[j]) in waved):
                sf, sz = float(r.std_frequency_hz[j]), float(r.std_damping_ratio[j])
                modes.append(
                    {
                        "frequency_hz": float(r.frequency_hz[j]),
                        "damping_ratio": float(r.damping_ratio[j]),
                        "std_frequency_hz": sf if np.isfinite(sf) else None,
                        "std_damping_ratio": sz if np.isfinite(sz) else None,
                        "shape": np.column_stack([r.shapes[:, j].real, r.shapes[:, j].imag])
                        .astype(float)
                        .tolist(),
                    }
                )
        return {
            "kind": "rolling_waves",
            "source": source,
            "wheel_speed_hz": result.wheel_speed_hz,
            "angles_deg": list(result.angles_deg),
            "points": list(result.points),
            "waves": result.table(),
            "modes": modes,
            "notes": list(result.notes),
        }

    @staticmethod
    def run_file(
        path: Path,
        upstream: Mapping[str, Any],
        settings: Mapping[str, Any],
        conditions: Mapping[str, Any] | None,
    ) -> dict[str, Any]:
        """The step on one test file of a campaign."""
        from ...io import ChannelMap, read_timedata

        cmap = ChannelMap.from_dict((conditions or {}).get("channel_map") or {})
        data = read_timedata(path, channel_map=cmap)
        s = RollingSettings.from_mapping(settings["rolling"])
        res, _ = RollingStep.run(data, s)
        return RollingStep.document(res, source=Path(path).name)
