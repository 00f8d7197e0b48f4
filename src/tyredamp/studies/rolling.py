"""The rolling tyre in the demo: the virtual tyre at a few speeds, identified output-only.

At each speed :func:`tyredamp.virtual.rolling_test` records the rotating ring
tyre under a random road force (16 fixed sensors, one in the tyre) and
:func:`tyredamp.oma.rolling.rolling_modes` identifies it without the force;
each exact wave (:class:`~tyredamp.virtual.RollingTruth`) is put beside the
identified one of the same wave number and direction
(:func:`tyredamp.oma.rolling.compare_waves`), in the fixed frame (fixed
sensors) and in the tyre (the in-tyre sensor).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .steps.rolling import RollingSettings

__all__ = ["RollingSpeed", "RollingStudy", "rolling_section", "run_rolling"]


@dataclass(frozen=True, eq=False)
class RollingSpeed:
    """One speed: the truth table and the comparison in both frames.

    Attributes
    ----------
    speed_kmh, wheel_speed_hz : float
    fixed, rotating : list of dict
        :func:`~tyredamp.oma.rolling.compare_waves` rows (one per exact wave).
    false_modes : int
        Fixed-frame waves with no exact wave of that ``n`` and direction within 2 %.
    unresolved : int
        In-tyre peaks left unresolved.
    """

    speed_kmh: float
    wheel_speed_hz: float
    fixed: list[dict[str, Any]]
    rotating: list[dict[str, Any]]
    false_modes: int
    unresolved: int


@dataclass(frozen=True, eq=False)
class RollingStudy:
    """The rolling section of the demo: one :class:`RollingSpeed` per speed."""

    speeds: list[RollingSpeed]
    duration_s: float
    notes: list[str] = field(default_factory=list)


def _false(waves: list[Any], truth: list[dict[str, Any]]) -> int:
    return sum(
        not any(
            r["wave_number"] == w.wave_number
            # a wave whose direction the layout cannot tell (the Nyquist wave number
            # without an in-tyre sensor) is the truth's wave of either direction
            and (r["direction"] == w.direction or r["wave_number"] == 0 or w.direction is None)
            and abs(r["fixed_hz"] / w.fixed_hz - 1) < 0.02
            for r in truth
        )
        for w in waves
    )


def run_rolling(
    speeds_kmh: tuple[float, ...] = (40.0, 80.0),
    duration: float = 8.0,
    seed: int = 0,
    band: tuple[float, float] = (0.0, 200.0),
    settings: RollingSettings | None = None,
) -> RollingStudy:
    """Record and identify the rolling virtual tyre at each speed (module docstring).

    Parameters
    ----------
    speeds_kmh : tuple of float
        km/h.
    duration : float
        Seconds per record (512 Hz).
    seed : int
    band : (float, float)
        Hz: the band of the road force.
    settings : RollingSettings, optional
        Settings of the registered ``rolling`` step
        (:class:`~tyredamp.studies.steps.rolling.RollingStep`, the recipe of
        ``tyredamp rolling`` and of a campaign) that identifies each record;
        default: the demo's (:meth:`DemoSettings.step_settings`, no jackknife
        standard errors, the recording's band).

    Returns
    -------
    RollingStudy
    """
    from ..oma.rolling import compare_waves
    from ..virtual import rolling_test
    from .registry import STEPS
    from .settings import DemoSettings

    rs = DemoSettings().step_settings()["rolling"] if settings is None else settings
    out = []
    for k, v in enumerate(speeds_kmh):
        test = rolling_test(v, duration=duration, sample_rate=512.0, band=band, seed=seed + k)
        m, _ = STEPS["rolling"].run(test.data, rs)
        lo, hi = band[0] + 5.0, band[1] - 10.0  # waves away from the band edges
        table = test.truth.table()
        fixed_truth = [r for r in table if lo <= r["fixed_hz"] <= hi]
        rot_truth = [r for r in table if lo <= r["rotating_hz"] <= hi]
        out.append(
            RollingSpeed(
                speed_kmh=float(v),
                wheel_speed_hz=m.wheel_speed_hz,
                fixed=compare_waves(m.fixed, fixed_truth, "fixed"),
                rotating=compare_waves(m.rotating, rot_truth, "rotating"),
                false_modes=_false(m.fixed, fixed_truth),
                unresolved=sum(w.wave_number is None for w in m.rotating),
            )
        )
    return RollingStudy(out, float(duration))


def rolling_section(study: RollingStudy) -> dict[str, Any]:
    """The ``rolling`` section of results.json: per speed, each exact wave and its match."""

    def row(c: dict[str, Any], frame: str) -> dict[str, Any]:
        t = c["truth"]
        zk = "fixed_damping_ratio" if frame == "fixed" else "damping_ratio"
        return {
            "wave_number": t["wave_number"],
            "direction": t["direction"],
            "truth_hz": t[f"{frame}_hz"],
            "truth_damping_ratio": t[zk],
            "found": bool(c["found"]),
            "frequency_hz": c.get("frequency_hz"),
            "damping_ratio": c.get("damping_ratio"),
            "f_error_pct": None if not c["found"] else 100 * c["f_error"],
        }

    return {
        "duration_s": study.duration_s,
        "speeds": [
            {
                "speed_kmh": s.speed_kmh,
                "wheel_speed_hz": s.wheel_speed_hz,
                "false_modes": s.false_modes,
                "unresolved_in_tyre": s.unresolved,
                "fixed": [row(c, "fixed") for c in s.fixed],
                "in_tyre": [row(c, "rotating") for c in s.rotating],
            }
            for s in study.speeds
        ],
    }
