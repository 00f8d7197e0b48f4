"""The lateral tyre-dynamics study of paper 001 as named steps.

Each step takes typed inputs and returns a typed result; ``tyredamp lateral
fit``, the demo and batch processing call these::

    FRF --lateral_data--> LateralData --fit_models--> Ranking (every model, best first)

On the virtual rolling-tyre rig (known truth): :func:`measure_condition`
(ground- and axle-force FRFs, every model fitted and ranked),
:func:`vehicle_study` (eq. 41-44), :func:`time_test` (the sine test and the
causal approximation) and :func:`run_lateral`, the whole study of the demo.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..exceptions import PhysicsError
from ..lateral import (
    LateralVehicle,
    Resonance,
    causal_error,
    figure7_curves,
    harmonic_response,
)
from ..virtual.lateral_rig import VirtualLateralRig
from .results import LateralCondition, LateralStudy, TimeTest, VehicleStudy
from .settings import DemoSettings
from .steps import LateralFitSettings
from .steps.lateral_fit import fit_models, lateral_data

__all__ = [
    "fit_models",
    "lateral_data",
    "measure_condition",
    "run_lateral",
    "time_test",
    "vehicle_study",
]

#: ``stage(description)``: called before each stage of :func:`run_lateral`.
StageCallback = Callable[[str], None]


# ---------------------------------------------------------------------------- steps
# --------------------------------------------------------------- on the virtual rig
def measure_condition(
    rig: VirtualLateralRig,
    pressure_bar: float,
    speed_kmh: float,
    fit: LateralFitSettings,
    seed: int,
) -> LateralCondition:
    """Ground- and axle-force FRFs of the rig at one condition, every model fitted to the ground.

    The fit is the registered ``fit`` step
    (:class:`~tyredamp.studies.steps.LateralFitStep`, the recipe of ``tyredamp
    lateral fit`` and of a campaign) with the settings ``fit``
    (the demo's: :meth:`DemoSettings.step_settings`); the speed, force and
    wheel mass come from the rig's FRF.
    """
    from .registry import STEPS

    ground = rig.measure(speed_kmh, pressure_bar, "ground", seed)
    axle = rig.measure(speed_kmh, pressure_bar, "axle", seed)
    (ranking, _), _ = STEPS["fit"].run(ground.frf, fit)
    return LateralCondition(
        pressure_bar, speed_kmh, ground, axle, ranking, rig.truth(speed_kmh, pressure_bar)
    )


def _resonance(vehicle: LateralVehicle) -> Resonance | None:
    try:
        return vehicle.resonance((0.3, 20.0))
    except PhysicsError:
        return None


def vehicle_study(rig: VirtualLateralRig, ref: LateralCondition) -> VehicleStudy:
    """The single-DOF vehicle (eq. 41-44) on each fitted tyre of ``ref`` and on the truth."""
    vehicles = {f.name: LateralVehicle(f.model, rig.body_mass) for f in ref.ranking.fits}
    truth_vehicle = rig.vehicle(ref.speed_kmh, ref.pressure_bar)
    return VehicleStudy(
        body_mass=rig.body_mass,
        vehicles=vehicles,
        truth=truth_vehicle,
        resonances={k: _resonance(veh) for k, veh in vehicles.items()},
        truth_resonance=_resonance(truth_vehicle),
    )


def time_test(
    rig: VirtualLateralRig,
    ref: LateralCondition,
    vehicles: dict[str, LateralVehicle],
    frequency_hz: float,
    *,
    force_amplitude: float = 500.0,
    window_s: tuple[float, float] = (4.0, 6.0),
    seed: int = 0,
) -> TimeTest:
    """The sinusoidal time test (paper Fig. 15) and each fitted vehicle's prediction.

    Parameters
    ----------
    rig : VirtualLateralRig
    ref : LateralCondition
        The condition of the test.
    vehicles : dict of str to LateralVehicle
        One per fitted model; must hold ``"hysteretic"`` (causal approximation).
    frequency_hz : float
        Sine frequency, Hz.
    force_amplitude : float
        Body force amplitude, N.
    window_s : (float, float)
        Comparison window, s.
    seed : int
        Noise seed.
    """
    td = rig.time_test(
        ref.speed_kmh, ref.pressure_bar, frequency_hz, force_amplitude=force_amplitude, seed=seed
    )
    t = td.time
    measured_acc = td.data[1]
    win = (t >= window_s[0]) & (t <= window_s[1])
    preds: dict[str, NDArray[np.float64]] = {}
    errs: dict[str, float] = {}
    rms_meas = float(np.sqrt(np.mean(measured_acc[win] ** 2)))
    for name, veh in vehicles.items():
        a = harmonic_response(veh, frequency_hz, force_amplitude, t, "acceleration")
        preds[name] = a
        errs[name] = float(np.sqrt(np.mean((a[win] - measured_acc[win]) ** 2))) / rms_meas
    causal = causal_error(vehicles["hysteretic"], (0.05, 50.0), sine_frequency=frequency_hz)
    return TimeTest(td, frequency_hz, force_amplitude, preds, window_s, errs, causal)


def run_lateral(s: DemoSettings, stage: StageCallback | None = None) -> LateralStudy:
    """The lateral study of the demo: every condition, the vehicle and the time test.

    Parameters
    ----------
    s : DemoSettings
        Conditions, models, reference condition, time-test frequency, seed.
    stage : callable, optional
        ``stage(description)`` before each stage.
    """

    def start(name: str) -> None:
        if stage is not None:
            stage(name)

    rig = VirtualLateralRig()
    fit = s.step_settings()["fit"]
    lat: list[LateralCondition] = []
    for p, v in conditions(s):
        start(f"lateral: {len(s.lateral_models)} model fits at {p:g} bar, {v:g} km/h")
        lat.append(measure_condition(rig, p, v, fit, s.seed))
    ref_p, ref_v = s.reference_condition
    ref = next(c for c in lat if c.pressure_bar == ref_p and c.speed_kmh == ref_v)

    start(f"lateral: vehicle model and {s.time_test_frequency_hz:g} Hz time response")
    vstudy = vehicle_study(rig, ref)
    tt = time_test(rig, ref, vstudy.vehicles, s.time_test_frequency_hz, seed=1000 * s.seed + 201)
    return LateralStudy(rig, lat, ref, vstudy, tt, figure7_curves())


def conditions(s: DemoSettings) -> list[tuple[float, float]]:
    """``(pressure_bar, speed_kmh)`` of every rig condition of the demo."""
    return [(p, v) for p in s.lateral_pressures_bar for v in s.lateral_speeds_kmh]
