"""Result types of the two studies and of the demo (plain frozen dataclasses).

:mod:`.radial` and :mod:`.lateral` fill them; the report, the results
document (:mod:`.document`) and the command line read them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__
from ..damping import DampingModel
from ..exceptions import InputError
from ..frf import FRF
from ..lateral import CausalError, Figure7Curves, LateralData, LateralVehicle, Ranking, Resonance
from ..modal.identify import ModalIdentification
from ..modal.model import ModalModel
from ..signal import CheckResult
from ..timedata import TimeData
from ..tyremodel import RigidRingParameters, RingFit, TyreModelResult
from ..virtual import MeasurementLayout, RingTyreParameters, TyreTruth
from ..virtual.lateral_rig import VirtualLateralRig, ViscoelasticStringTyre
from ..virtual.modal_rig import VirtualModalTest
from .settings import DemoSettings

__all__ = [
    "DampingComparison",
    "DemoResult",
    "LateralCondition",
    "LateralStudy",
    "ModeMatch",
    "PressureRun",
    "RadialStudy",
    "TimeTest",
    "TyreModelStudy",
    "VehicleStudy",
]


@dataclass(frozen=True)
class ModeMatch:
    """Identified modes paired with the visible modes of the virtual tyre.

    ``pairs`` holds ``(i_true, i_model)``: ``i_true`` indexes
    ``truth.select("visible")`` and ``i_model`` the model's modes; an unmatched
    mode has ``None`` on the other side. Pairs are sorted by frequency.
    """

    pairs: tuple[tuple[int | None, int | None], ...]

    @property
    def matched(self) -> list[tuple[int, int]]:
        """Only the pairs with both sides."""
        return [(t, m) for t, m in self.pairs if t is not None and m is not None]


@dataclass(frozen=True, eq=False)
class PressureRun:
    """The modal test, FRFs and fits at one inflation pressure.

    Attributes
    ----------
    pressure_bar : float
    test : VirtualModalTest
        Time data and the exact truth of the tested tyre.
    frf : FRF
        Estimated accelerance, shape (16, 1, n_lines), with coherence.
    identification : ModalIdentification
        Real and complex modal models with RMSD and standard errors, and the
        stabilisation data.
    matches : dict of str to ModeMatch
        ``"complex"`` and ``"real"`` against the visible true modes.
    n_periods : int
        Averages.
    """

    pressure_bar: float
    test: VirtualModalTest
    frf: FRF
    identification: ModalIdentification
    matches: dict[str, ModeMatch]
    n_periods: int

    @property
    def truth(self) -> TyreTruth:
        """The exact modes of the tested tyre."""
        return self.test.truth

    @property
    def models(self) -> dict[str, ModalModel]:
        """``"complex"`` and ``"real"`` modal models."""
        return self.identification.models

    @property
    def fitted_frf(self) -> FRF:
        """The measured FRF on the lines used by the fits."""
        keep = np.flatnonzero(np.isin(self.frf.frequency, self.identification.frequency))
        return self.frf.select_lines(keep)

    def synthesised(self, name: str) -> FRF:
        """FRF of a fitted model on the fitted lines, kind of the data."""
        meas = self.fitted_frf
        return self.models[name].frf(meas.frequency, meas.kind)

    def exact(self) -> FRF:
        """Exact FRF of the tested tyre on the fitted lines (no noise)."""
        meas = self.fitted_frf
        return self.truth.frf(meas.frequency, meas.kind)


@dataclass(frozen=True, eq=False)
class DampingComparison:
    """Identified ``C'`` against the exact damping of the virtual tyre.

    ``C'_kn`` carries the signs of the basis columns ``k`` and ``n``; the true
    matrix (eq. [14] on the undamped modes) is given in the signs of the
    identified basis.

    Attributes
    ----------
    true_index : ndarray of int, shape (q,)
        Matched true modes (indices into ``truth.select("visible")``).
    model_index : ndarray of int, shape (q,)
        The same modes in the damping model.
    modal_true : ndarray, shape (q, q)
        True ``C'`` of the matched modes, 1/s.
    modal : ndarray, shape (q, q)
        Identified ``C'`` of the matched modes, 1/s.
    modal_error : float
        ``||C'_id - C'_true||_F / ||C'_true||_F``.
    modal_error_symmetric : float
        The same for the symmetric part of ``C'_id``.
    diagonal_error : float
        ``||diag C'_id - diag C'_true|| / ||diag C'_true||``.
    physical_true : ndarray, shape (N, N) or None
        True damping reduced to the points by the same projection on the
        true undamped shapes of the matched modes (when every identified mode
        is matched), N s/m.
    physical_error : float or None
        ``||sym C_id - C_true,red||_F / ||C_true,red||_F``.
    """

    true_index: NDArray[np.intp]
    model_index: NDArray[np.intp]
    modal_true: NDArray[np.float64]
    modal: NDArray[np.float64]
    modal_error: float
    modal_error_symmetric: float
    diagonal_error: float
    physical_true: NDArray[np.float64] | None
    physical_error: float | None


@dataclass(frozen=True, eq=False)
class TyreModelStudy:
    """Flexible and rigid ring from the modes at every pressure, beside the tyre's own values.

    Filled by :func:`tyredamp.studies.tyremodel.tyre_model_from_runs`.

    Attributes
    ----------
    result : TyreModelResult or None
        :func:`tyredamp.tyremodel.build_tyre_model` on the runs' modes; None
        when the fit could not be made.
    error : str or None
        Why there is no result (the exception's type and message).
    pressures_bar : tuple of float
        Pressures of the runs fitted, bar.
    params : RingTyreParameters or None
        The tested virtual tyre (its ring parameters are the truth).
    layout : MeasurementLayout or None
        Its measurement layout (radius and attachment given to the fit).
    rigid_truth : tuple of (RigidRingParameters or None) or None
        Rigid-ring parameters from the exact modes of the tyre at each
        pressure (same formulas), None where they cannot be computed.
    models : tuple of str
        Which modal model of each run was used (``"complex"`` or ``"real"``).
    exact_ring : RingFit or None
        The same ring fit on the exact modes of the tested tyres: what the
        method gives without noise, so that a gap to the tyre's parameters
        splits into the finite-difference ring's discretisation (in this one
        too) and the identification (the difference between the two fits).
    """

    result: TyreModelResult | None
    error: str | None
    pressures_bar: tuple[float, ...]
    params: RingTyreParameters | None
    layout: MeasurementLayout | None
    rigid_truth: tuple[RigidRingParameters | None, ...] | None
    models: tuple[str, ...]
    exact_ring: RingFit | None = None

    @property
    def ok(self) -> bool:
        """True when the fit was made."""
        return self.result is not None


@dataclass(frozen=True, eq=False)
class RadialStudy:
    """Everything of the radial study (paper 000).

    Attributes
    ----------
    runs : list of PressureRun
        The first is the main pressure.
    linearity, reciprocity, quality : CheckResult
        Checks with numbers at the main pressure.
    linearity_frfs : list of FRF
        The FRFs at the two force levels (first = main test).
    reciprocity_frf : FRF
        The two-drive-point FRF matrix (16 x 2).
    damping : DampingModel
        From the complex modes at the main pressure.
    damping_truth : DampingComparison
    tyre_model : TyreModelStudy
        Flexible ring across the pressures and rigid ring per pressure
        (:func:`tyredamp.studies.tyremodel.tyre_model_from_runs`).
    """

    runs: list[PressureRun]
    linearity: CheckResult
    reciprocity: CheckResult
    quality: CheckResult
    linearity_frfs: list[FRF]
    reciprocity_frf: FRF
    damping: DampingModel
    damping_truth: DampingComparison
    tyre_model: TyreModelStudy

    @property
    def main(self) -> PressureRun:
        """The run at the main pressure."""
        return self.runs[0]


@dataclass(frozen=True, eq=False)
class LateralCondition:
    """One rig condition: measured FRFs, fits, ranking and the truth.

    Attributes
    ----------
    pressure_bar, speed_kmh : float
    ground, axle : LateralData
        Accelerance per ground force (fitted) and per axle force (predicted).
    ranking : Ranking
        Every model fitted to ``ground``, best first.
    truth : ViscoelasticStringTyre
        The rig's exact tyre at this condition.
    """

    pressure_bar: float
    speed_kmh: float
    ground: LateralData
    axle: LateralData
    ranking: Ranking
    truth: ViscoelasticStringTyre

    @property
    def label(self) -> str:
        """``"1.7 bar, 5 km/h"``."""
        return f"{self.pressure_bar:g} bar, {self.speed_kmh:g} km/h"

    def fit(self, name: str) -> Any:
        """The :class:`~tyredamp.lateral.LateralFit` of one model."""
        for f in self.ranking.fits:
            if f.name == name:
                return f
        raise InputError(f"name: no fit of model {name!r} at {self.label}")

    @property
    def corner_frequency_hz(self) -> float:
        """``f0 = K / (2 pi C_r)`` of the fitted proposed model (eq. 38), Hz."""
        return float(self.fit("hysteretic").model.corner_frequency())

    @property
    def true_road_damping(self) -> float:
        """The truth's tyre-road damper ``C_alpha / V``, N s/m."""
        return float(self.truth.C_alpha / self.truth.speed)


@dataclass(frozen=True, eq=False)
class VehicleStudy:
    """The single-DOF vehicle (eq. 41-44) on each fitted tyre and on the truth.

    Attributes
    ----------
    body_mass : float
        kg.
    vehicles : dict of str to LateralVehicle
        One per fitted model at the reference condition.
    truth : LateralVehicle
    resonances : dict of str to Resonance or None
        Body resonance (receptance peak) of each; ``None`` when over-damped.
    truth_resonance : Resonance or None
    """

    body_mass: float
    vehicles: dict[str, LateralVehicle]
    truth: LateralVehicle
    resonances: dict[str, Resonance | None]
    truth_resonance: Resonance | None


@dataclass(frozen=True, eq=False)
class TimeTest:
    """The sinusoidal time test (paper Fig. 15) and the models' predictions.

    Attributes
    ----------
    data : TimeData
        Measured body force, body acceleration and ground force.
    frequency_hz, force_amplitude : float
    predictions : dict of str to ndarray
        Exact steady-state body acceleration of each fitted model, m/s^2,
        on ``data.time``.
    window_s : (float, float)
        Comparison window (paper: 4-6 s).
    errors : dict of str to float
        RMS of prediction minus measurement over the window relative to the
        RMS of the measurement.
    causal : CausalError
        Error of the causal (generalised Maxwell) approximation of the fitted
        hysteretic tyre and the precursor of the ideal one.
    """

    data: TimeData
    frequency_hz: float
    force_amplitude: float
    predictions: dict[str, NDArray[np.float64]]
    window_s: tuple[float, float]
    errors: dict[str, float]
    causal: CausalError


@dataclass(frozen=True, eq=False)
class LateralStudy:
    """Everything of the lateral study (paper 001)."""

    rig: VirtualLateralRig
    conditions: list[LateralCondition]
    reference: LateralCondition
    vehicle: VehicleStudy
    time_test: TimeTest
    figure7: Figure7Curves


@dataclass(frozen=True, eq=False)
class DemoResult:
    """What :func:`run_demo` returns: both studies, settings and timings (s)."""

    settings: DemoSettings
    radial: RadialStudy
    lateral: LateralStudy
    timings: dict[str, float] = field(default_factory=dict)
    elapsed_s: float = 0.0
    version: str = __version__
    #: the rolling tyre identified output-only (:class:`~tyredamp.studies.rolling.RollingStudy`)
    rolling: Any = None
    #: which damping model the virtual tyre's FRFs support
    #: (:class:`~tyredamp.studies.dampmodels.DampModelStudy`)
    damping_models: Any = None
