"""The main job: both studies of the papers on the built-in virtual tyres.

:func:`run_demo` runs, in memory and without printing:

* the **radial study** (paper 000, spec ``radial-damping.md``) on the virtual
  truck tyre (:class:`~tyredamp.virtual.RingTyre`): the modal test with a
  periodic chirp at the main pressure (7.5 bar) and at further pressures,
  FRFs (H1, cyclic), a linearity check at two force levels, a reciprocity
  check with two drive points, a data-quality check, the real-mode (eq.
  [2]/[3]) and complex-mode (eq. [10]) fits with their RMSD (eq. [19]) and
  the damping identification (eq. [14]-[18]); every identified value is
  paired with the exact value of the tyre (:class:`~tyredamp.virtual.TyreTruth`);
* the **lateral study** (paper 001, spec ``lateral-models.md``) on the
  virtual rolling-tyre rig (:class:`~tyredamp.virtual.VirtualLateralRig`):
  ground- and axle-force FRFs at both speeds and the three pressures, every
  model fitted to the ground-force FRF and ranked, axle-force predictions,
  the corner frequency of the proposed model (eq. 38-40), the single-DOF
  vehicle (eq. 41-44), the 2.73 Hz time response and the error of a causal
  approximation of the hysteretic tyre.

:func:`save_demo` writes what :func:`run_demo` returned into a directory:
``report.html`` (self-contained), ``results.json`` (schema
``tyredamp/schemas/results.schema.json``, described in the README), the
figures as PNG, the generated data as UFF 58 (binary 58b) and the modes and
damping JSON files of the main pressure. It writes into a temporary directory
beside the target and renames it into place at the end, so a failure leaves
no partial output.

Both take an optional progress callback ``progress(description, done,
total)``, called before each stage (``done`` stages finished out of
``total``) and once more at the end with ``done == total``.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from .. import __version__
from ..damping import DampingModel, identify_damping
from ..documents.jsonfile import json_text
from ..exceptions import InputError
from ..frf import FRF
from ..lateral import (
    DEFAULT_MODELS,
    CausalError,
    Figure7Curves,
    LateralData,
    LateralVehicle,
    Ranking,
    Resonance,
    causal_error,
    figure7_curves,
    harmonic_response,
    rank_models,
)
from ..modal.identify import ModalIdentification, identify_modes
from ..modal.model import ModalModel
from ..signal import CheckResult, estimate_frf, linearity_check, quality_check, reciprocity_check
from ..timedata import TimeData
from ..virtual import MeasurementLayout, RingTyre, RingTyreParameters, TyreTruth, run_modal_test
from ..virtual.lateral_rig import VirtualLateralRig, ViscoelasticStringTyre
from ..virtual.modal_rig import VirtualModalTest

__all__ = [
    "DEMO_MARKER",
    "DampingComparison",
    "DemoResult",
    "DemoSettings",
    "LateralCondition",
    "LateralStudy",
    "ModeMatch",
    "PressureRun",
    "ProgressCallback",
    "RadialStudy",
    "TimeTest",
    "VehicleStudy",
    "check_output_dir",
    "match_modes",
    "run_demo",
    "save_demo",
    "single_threaded_blas",
]

#: ``progress(description, done, total)``: called before each stage.
ProgressCallback = Callable[[str, int, int], None]

#: Value of ``"kind"`` in the demo's results.json (also how a directory is
#: recognised as an earlier demo output that may be replaced).
DEMO_MARKER = "tyredamp-demo-results"

BAR = 1.0e5
#: The six lateral models fitted by the demo: the paper's four, then the
#: relaxation-length and stretched-string models.
LATERAL_MODELS: tuple[str, ...] = (*DEFAULT_MODELS, "relaxation", "string")


# ------------------------------------------------------------------------------ settings
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
        Band of the linearity and reciprocity figures, Hz (below it the
        accelerance of a free tread band is tiny and noise dominates).
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

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready copy of the settings."""
        out: dict[str, Any] = {}
        for k, v in self.__dict__.items():
            out[k] = list(v) if isinstance(v, tuple) else v
        return out


# ------------------------------------------------------------------------------- results
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


def match_modes(
    identified_hz: Sequence[float] | NDArray[np.float64],
    true_hz: Sequence[float] | NDArray[np.float64],
    tolerance: float = 0.05,
) -> ModeMatch:
    """Pair identified and true natural frequencies one to one.

    The assignment minimises the sum of relative frequency differences
    (:func:`scipy.optimize.linear_sum_assignment`); pairs further apart than
    ``tolerance`` (relative) are left unmatched.

    Parameters
    ----------
    identified_hz, true_hz : array_like, shape (m,) and (n,)
        Natural frequencies in Hz (> 0).
    tolerance : float
        Largest relative difference ``|f_id - f_true| / f_true`` of a pair.

    Returns
    -------
    ModeMatch
    """
    fi = np.asarray(identified_hz, dtype=float)
    ft = np.asarray(true_hz, dtype=float)
    pairs: list[tuple[int | None, int | None]] = []
    used_t: set[int] = set()
    used_m: set[int] = set()
    if fi.size and ft.size:
        cost = np.abs(fi[None, :] - ft[:, None]) / ft[:, None]
        rows, cols = linear_sum_assignment(cost)
        for r, c in zip(rows, cols, strict=True):
            if cost[r, c] <= tolerance:
                pairs.append((int(r), int(c)))
                used_t.add(int(r))
                used_m.add(int(c))
    pairs += [(i, None) for i in range(ft.size) if i not in used_t]
    pairs += [(None, j) for j in range(fi.size) if j not in used_m]

    def key(p: tuple[int | None, int | None]) -> float:
        i_t, i_m = p
        return float(ft[i_t]) if i_t is not None else float(fi[i_m or 0])

    return ModeMatch(tuple(sorted(pairs, key=key)))


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
    """

    runs: list[PressureRun]
    linearity: CheckResult
    reciprocity: CheckResult
    quality: CheckResult
    linearity_frfs: list[FRF]
    reciprocity_frf: FRF
    damping: DampingModel
    damping_truth: DampingComparison

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


# ------------------------------------------------------------------------------- helpers
class _Stages:
    """Counts stages and reports them to the progress callback."""

    def __init__(self, total: int, progress: ProgressCallback | None) -> None:
        self.total = total
        self.done = 0
        self.progress = progress
        self.timings: dict[str, float] = {}
        self._name: str | None = None
        self._t0 = 0.0

    def start(self, name: str) -> None:
        self._close()
        self._name = name
        self._t0 = time.perf_counter()
        if self.progress is not None:
            self.progress(name, self.done, self.total)

    def _close(self) -> None:
        if self._name is not None:
            self.timings[self._name] = time.perf_counter() - self._t0
            self.done += 1
            self._name = None

    def finish(self) -> None:
        self._close()
        if self.progress is not None:
            self.progress("done", self.total, self.total)


def single_threaded_blas() -> contextlib.AbstractContextManager[Any]:
    """Context limiting BLAS/LAPACK to one thread (threadpoolctl; a no-op without it).

    The matrices here are small (a 128-DOF tyre, batched 130 x 130 solves,
    least squares of a few hundred columns): extra BLAS threads gain little
    and, on a machine whose cores are busy, slow everything down many times
    (measured on two shared cores: the full demo's computation took 111 s
    with the default two OpenBLAS threads and 7.9 s with one;
    ``benchmarks/demo_timing.py --compare-threads``).
    """
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def _tyre(pressure_bar: float, drive_points: tuple[int, ...] = (1,)) -> RingTyre:
    return RingTyre(
        RingTyreParameters(pressure=pressure_bar * BAR),
        MeasurementLayout(drive_points=drive_points),
    )


def _run_pressure(
    pressure_bar: float, n_periods: int, settings: DemoSettings, seed: int
) -> PressureRun:
    test = run_modal_test(
        _tyre(pressure_bar),
        n_periods=n_periods,
        force_rms=settings.force_levels_n[0],
        snr_db=settings.snr_db,
        seed=seed,
    )
    frf = estimate_frf(test.data, "H1")
    ident = identify_modes(frf, model="both")
    visible = test.truth.frequency_hz[test.truth.select("visible")]
    matches = {k: match_modes(m.frequency_hz, visible) for k, m in ident.models.items()}
    return PressureRun(pressure_bar, test, frf, ident, matches, n_periods)


def _compare_damping(run: PressureRun, dm: DampingModel) -> DampingComparison:
    truth = run.truth
    vis = truth.select("visible")
    matched = run.matches["complex"].matched
    ti = np.array([t for t, _ in matched], dtype=np.intp)
    mi = np.array([m for _, m in matched], dtype=np.intp)
    ct = truth.modal_damping[np.ix_(vis[ti], vis[ti])]
    phi_true = truth.phi_points[:, vis[ti]]
    basis = dm.basis[:, mi]
    sign = np.sign(np.sum(basis * phi_true, axis=0))
    sign[sign == 0] = 1.0
    ct = ct * np.outer(sign, sign)
    cid = dm.modal[np.ix_(mi, mi)]
    norm = float(np.linalg.norm(ct))
    if mi.size == 0 or norm == 0:  # no identified mode matches a true one
        nan = float("nan")
        return DampingComparison(ti, mi, ct, cid, nan, nan, nan, None, None)
    err = float(np.linalg.norm(cid - ct)) / norm
    err_sym = float(np.linalg.norm(0.5 * (cid + cid.T) - ct)) / norm
    dd = float(np.linalg.norm(np.diag(cid) - np.diag(ct)) / np.linalg.norm(np.diag(ct)))
    phys_true = None
    phys_err = None
    if mi.size == dm.n_modes and mi.size <= phi_true.shape[0]:
        pu = np.linalg.pinv(phi_true * sign)
        c_red = pu.T @ ct @ pu
        phys_true = 0.5 * (c_red + c_red.T)
        phys_err = float(
            np.linalg.norm(dm.physical_symmetric - phys_true) / np.linalg.norm(phys_true)
        )
    return DampingComparison(
        true_index=ti,
        model_index=mi,
        modal_true=ct,
        modal=cid,
        modal_error=err,
        modal_error_symmetric=err_sym,
        diagonal_error=dd,
        physical_true=phys_true,
        physical_error=phys_err,
    )


def _resonance(vehicle: LateralVehicle) -> Resonance | None:
    from ..exceptions import PhysicsError

    try:
        return vehicle.resonance((0.3, 20.0))
    except PhysicsError:
        return None


def _lateral_stages(settings: DemoSettings) -> list[tuple[float, float]]:
    return [(p, v) for p in settings.lateral_pressures_bar for v in settings.lateral_speeds_kmh]


# ------------------------------------------------------------------------------- running
def run_demo(
    settings: DemoSettings | None = None, progress: ProgressCallback | None = None
) -> DemoResult:
    """Run both studies on the virtual tyres (module docstring); no printing, no files.

    Parameters
    ----------
    settings : DemoSettings, optional
        Default :meth:`DemoSettings.full`.
    progress : callable, optional
        ``progress(description, done, total)`` before each stage.

    Returns
    -------
    DemoResult

    Raises
    ------
    InputError
        Invalid settings.
    ConvergenceError
        A fit that did not converge (not expected on the built-in tyres).
    """
    s = DemoSettings.full() if settings is None else settings
    if not isinstance(s, DemoSettings):
        raise InputError(f"settings: expected DemoSettings, got {type(s).__name__}")
    with single_threaded_blas():
        return _run(s, progress)


def _run(s: DemoSettings, progress: ProgressCallback | None) -> DemoResult:
    t_start = time.perf_counter()
    conditions = _lateral_stages(s)
    n_stages = len(s.radial_pressures_bar) + 3 + len(conditions) + 1
    st = _Stages(n_stages, progress)
    base = 1000 * s.seed

    # ---------------------------------------------------------------- radial study
    runs: list[PressureRun] = []
    for k, p in enumerate(s.radial_pressures_bar):
        st.start(f"radial: modal test, FRFs, real and complex fits at {p:g} bar")
        n = s.radial_periods if k == 0 else s.radial_side_periods
        runs.append(_run_pressure(p, n, s, base + 1 + k))
    main = runs[0]
    p0 = s.radial_pressures_bar[0]

    st.start(f"radial: linearity check at {s.force_levels_n[1]:g} N")
    high = run_modal_test(
        _tyre(p0),
        n_periods=s.check_periods,
        force_rms=s.force_levels_n[1],
        snr_db=s.snr_db,
        seed=base + 101,
    )
    frf_high = estimate_frf(high.data, "H1")
    lin = linearity_check([main.frf, frf_high], band=s.check_band_hz)
    quality = quality_check(main.test.data)

    st.start(f"radial: reciprocity check, drive points {s.reciprocity_points}")
    recip_test = run_modal_test(
        _tyre(p0, tuple(s.reciprocity_points)),
        n_periods=s.check_periods,
        force_rms=s.force_levels_n[0],
        snr_db=s.snr_db,
        seed=base + 102,
    )
    recip_frf = estimate_frf(recip_test.data, "H1")
    recip = reciprocity_check(recip_frf, band=s.check_band_hz)

    st.start(f"radial: damping identification ({s.damping_method})")
    dm = identify_damping(
        main.models["complex"],
        s.damping_method,  # type: ignore[arg-type]
        n_samples=s.damping_samples,
        seed=s.seed,
        meta={"source": f"demo, virtual truck tyre at {p0:g} bar", "model": "complex"},
    )
    radial = RadialStudy(
        runs=runs,
        linearity=lin,
        reciprocity=recip,
        quality=quality,
        linearity_frfs=[main.frf, frf_high],
        reciprocity_frf=recip_frf,
        damping=dm,
        damping_truth=_compare_damping(main, dm),
    )

    # --------------------------------------------------------------- lateral study
    rig = VirtualLateralRig()
    lat: list[LateralCondition] = []
    for p, v in conditions:
        st.start(f"lateral: {len(s.lateral_models)} model fits at {p:g} bar, {v:g} km/h")
        ground = rig.measure(v, p, "ground", s.seed)
        axle = rig.measure(v, p, "axle", s.seed)
        ranking = rank_models(ground, s.lateral_models)
        lat.append(LateralCondition(p, v, ground, axle, ranking, rig.truth(v, p)))
    ref_p, ref_v = s.reference_condition
    ref = next(c for c in lat if c.pressure_bar == ref_p and c.speed_kmh == ref_v)

    st.start(f"lateral: vehicle model and {s.time_test_frequency_hz:g} Hz time response")
    vehicles = {f.name: LateralVehicle(f.model, rig.body_mass) for f in ref.ranking.fits}
    truth_vehicle = rig.vehicle(ref_v, ref_p)
    vstudy = VehicleStudy(
        body_mass=rig.body_mass,
        vehicles=vehicles,
        truth=truth_vehicle,
        resonances={k: _resonance(veh) for k, veh in vehicles.items()},
        truth_resonance=_resonance(truth_vehicle),
    )
    amp = 500.0
    td = rig.time_test(ref_v, ref_p, s.time_test_frequency_hz, force_amplitude=amp, seed=base + 201)
    t = td.time
    measured_acc = td.data[1]
    window = (4.0, 6.0)
    win = (t >= window[0]) & (t <= window[1])
    preds: dict[str, NDArray[np.float64]] = {}
    errs: dict[str, float] = {}
    rms_meas = float(np.sqrt(np.mean(measured_acc[win] ** 2)))
    for name, veh in vehicles.items():
        a = harmonic_response(veh, s.time_test_frequency_hz, amp, t, "acceleration")
        preds[name] = a
        errs[name] = float(np.sqrt(np.mean((a[win] - measured_acc[win]) ** 2))) / rms_meas
    causal = causal_error(
        vehicles["hysteretic"], (0.05, 50.0), sine_frequency=s.time_test_frequency_hz
    )
    tt = TimeTest(td, s.time_test_frequency_hz, amp, preds, window, errs, causal)
    lateral = LateralStudy(rig, lat, ref, vstudy, tt, figure7_curves())
    st.finish()
    return DemoResult(
        settings=s,
        radial=radial,
        lateral=lateral,
        timings=dict(st.timings),
        elapsed_s=time.perf_counter() - t_start,
    )


# ------------------------------------------------------------------------------- writing
def check_output_dir(out: Path) -> None:
    """Refuse to replace anything but an empty directory or an earlier demo output.

    Raises
    ------
    InputError
        ``out`` is a file, or a non-empty directory without a demo results.json.
    """
    if not out.exists():
        return
    if not out.is_dir():
        raise InputError(f"--out: {out} exists and is not a directory")
    entries = list(out.iterdir())
    if not entries:
        return
    marker = out / "results.json"
    try:
        doc = json.loads(marker.read_text(encoding="utf-8"))
        ok = isinstance(doc, dict) and doc.get("kind") == DEMO_MARKER
    except (OSError, ValueError):
        ok = False
    if not ok:
        raise InputError(
            f"--out: {out} exists and is not an earlier tyredamp demo output "
            "(no demo results.json); choose another directory or remove it"
        )


def save_demo(
    result: DemoResult,
    out_dir: str | os.PathLike[str],
    progress: ProgressCallback | None = None,
    *,
    dpi: int = 100,
) -> dict[str, Path]:
    """Write the report, results.json, figures, data and JSON files of a demo run.

    Everything is written into a temporary directory beside ``out_dir`` that
    is renamed to ``out_dir`` at the end; an existing ``out_dir`` is replaced
    only if it is empty or an earlier demo output. On any error nothing is
    left behind and an existing ``out_dir`` is unchanged.

    Parameters
    ----------
    result : DemoResult
    out_dir : path-like
        Target directory.
    progress : callable, optional
        ``progress(description, done, total)``.
    dpi : int
        Resolution of the PNG figures.

    Returns
    -------
    dict of str to Path
        ``"report"``, ``"results"`` and every other file written, by name
        relative to ``out_dir`` (``"report.html"``, ``"results.json"``, ...);
        the paths point into ``out_dir``.
    """
    with single_threaded_blas():
        return _save(result, Path(out_dir), progress, dpi)


def _save(
    result: DemoResult, out: Path, progress: ProgressCallback | None, dpi: int
) -> dict[str, Path]:
    from ..documents.modes import modes_document
    from ..io import write_frf, write_timedata
    from ..report.build import build_demo_report
    from ..report.figures import demo_figures
    from .document import build_results

    check_output_dir(out)
    parent = out.resolve().parent
    parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".tmp", dir=parent))
    written: list[str] = []
    try:
        figs = demo_figures(result)
        total = len(figs) + 4
        done = 0

        def step(name: str) -> None:
            nonlocal done
            if progress is not None:
                progress(name, done, total)
            done += 1

        pngs: dict[str, bytes] = {}
        for name, (fig, _caption) in figs.items():
            step(f"figure {name}.png")
            buf = _png(fig, dpi)
            pngs[name] = buf
            (tmp / "figures").mkdir(exist_ok=True)
            (tmp / "figures" / f"{name}.png").write_bytes(buf)
            written.append(f"figures/{name}.png")

        step("data files (UFF 58)")
        data_dir = tmp / "data"
        data_dir.mkdir()
        for rel, obj in _data_files(result).items():
            if isinstance(obj, FRF):
                write_frf(obj, tmp / rel)
            else:
                write_timedata(obj, tmp / rel)
            written.append(rel)

        step("modes and damping JSON")
        main = result.radial.main
        p0 = f"{main.pressure_bar:g}bar"
        doc = modes_document(
            main.models,
            source=f"data/radial_{p0}_frf.uff",
            band_hz=main.identification.band_hz,
            frf_kind=main.identification.frf_kind,
        )
        (tmp / f"modes_{p0}.json").write_text(json_text(doc), encoding="utf-8")
        written.append(f"modes_{p0}.json")
        (tmp / f"damping_{p0}.json").write_text(
            json_text(result.radial.damping.to_dict()),
            encoding="utf-8",
        )
        written.append(f"damping_{p0}.json")

        step("results.json")
        files = sorted([*written, "report.html", "results.json"])
        results = build_results(result, files=files)
        (tmp / "results.json").write_text(json_text(results), encoding="utf-8")

        step("report.html")
        html = build_demo_report(result, results, {k: (pngs[k], figs[k][1]) for k in figs})
        (tmp / "report.html").write_text(html, encoding="utf-8")
        if progress is not None:
            progress("done", total, total)
        _normal_permissions(tmp)
        _move_into_place(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return {name: out / name for name in files}


def _png(fig: Any, dpi: int) -> bytes:
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def _data_files(result: DemoResult) -> dict[str, FRF | TimeData]:
    """Generated data by relative path (UFF 58b: time data type 1, FRFs type 4)."""
    files: dict[str, FRF | TimeData] = {}
    r = result.radial
    main = r.main
    p0 = f"{main.pressure_bar:g}bar"
    files[f"data/radial_{p0}_time.uff"] = main.test.data
    for run in r.runs:
        files[f"data/radial_{run.pressure_bar:g}bar_frf.uff"] = run.frf
    hi = result.settings.force_levels_n[1]
    files[f"data/radial_{p0}_{hi:g}N_frf.uff"] = r.linearity_frfs[1]
    files[f"data/radial_{p0}_reciprocity_frf.uff"] = r.reciprocity_frf
    for c in result.lateral.conditions:
        tag = f"{c.pressure_bar:g}bar_{c.speed_kmh:g}kmh"
        files[f"data/lateral_{tag}_ground_frf.uff"] = c.ground.frf
        files[f"data/lateral_{tag}_axle_frf.uff"] = c.axle.frf
    tt = result.lateral.time_test
    files[f"data/lateral_time_{tt.frequency_hz:g}Hz.uff"] = tt.data
    return files


def _normal_permissions(root: Path) -> None:
    """Give the temporary tree the usual permissions (mkdtemp/mkstemp create 0700/0600)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(root, 0o777 & ~umask)
    for dirpath, dirnames, filenames in os.walk(root):
        for d in dirnames:
            os.chmod(os.path.join(dirpath, d), 0o777 & ~umask)
        for f in filenames:
            os.chmod(os.path.join(dirpath, f), 0o666 & ~umask)


def _move_into_place(tmp: Path, out: Path) -> None:
    """Rename ``tmp`` to ``out``; an existing ``out`` (checked before) is replaced."""
    if not out.exists():
        os.replace(tmp, out)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.resolve().parent))
    old.rmdir()
    os.replace(out, old)
    try:
        os.replace(tmp, out)
    except BaseException:
        os.replace(old, out)
        raise
    with contextlib.suppress(OSError):
        shutil.rmtree(old)
