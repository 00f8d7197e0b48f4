"""The radial damping study of paper 000: its functions and the demo's study.

The recipe of each step is its registered step
(:data:`tyredamp.studies.registry.STEPS`: ``frf``, ``checks``, ``modal``,
``damping``), which the command line, a campaign and the demo run with typed
settings. The functions here give the same computations to Python with plain
arguments::

    time data --frf_from_time--> FRF --check_linearity/_reciprocity/_quality--> CheckResult
                                 FRF --modes_from_frf--> ModalIdentification (real, complex)
              complex ModalModel --damping_from_modes--> DampingModel

On the virtual tyre (known truth): :func:`virtual_tyre`,
:func:`run_pressure` (modal test -> the ``frf`` and ``modal`` steps, matched
to the true modes by :func:`match_modes`), :func:`compare_damping` and
:func:`run_radial`, the whole study of the demo, whose knobs become the
steps' settings in one place (:meth:`DemoSettings.step_settings`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from ..damping import DampingModel
from ..exceptions import InputError
from ..frf import FRF
from ..modal.identify import ModalIdentification, ModelChoice, identify_modes
from ..modal.poles.estimators import PoleEstimator
from ..modal.statistics.stats import FALSE_ALARM
from ..signal import CheckResult, linearity_check, reciprocity_check
from ..signal.checks import merge_inputs
from ..timedata import TimeData
from ..virtual import (
    Cavity,
    ContactPatch,
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
    Splice,
    run_modal_test,
)
from .registry import STEPS
from .results import DampingComparison, ModeMatch, PressureRun, RadialStudy
from .settings import BAR, DemoSettings
from .steps import QualitySettings, QualityStep
from .steps.damping import damping_from_modes
from .steps.frf import frf_from_time
from .steps.modal import label_wave_numbers
from .tyremodel import tyre_model_from_runs

__all__ = [
    "check_linearity",
    "check_quality",
    "check_reciprocity",
    "compare_damping",
    "damping_from_modes",
    "frf_from_time",
    "label_wave_numbers",
    "match_modes",
    "modes_from_frf",
    "run_pressure",
    "run_radial",
    "virtual_tyre",
]

#: ``stage(description)``: called before each stage of :func:`run_radial`.
StageCallback = Callable[[str], None]


# ---------------------------------------------------------------------------- steps
def check_linearity(
    frfs: Sequence[FRF], threshold: float = 0.05, band: tuple[float, float] | None = None
) -> CheckResult:
    """Linearity: FRFs at two or more force levels against the first (spec step 3)."""
    if len(frfs) < 2:
        raise InputError(f"linearity: expected two or more FRFs, got {len(frfs)}")
    return linearity_check(frfs, threshold, band)


def check_reciprocity(
    frfs: Sequence[FRF], threshold: float = 0.05, band: tuple[float, float] | None = None
) -> CheckResult:
    """Reciprocity ``H_jk = H_kj`` in one MIMO FRF or several tests, inputs joined (step 3)."""
    if not frfs:
        raise InputError("reciprocity: expected one or more FRFs")
    return reciprocity_check(merge_inputs(list(frfs)), threshold, band)


def check_quality(
    data: TimeData | FRF,
    *,
    coherence_min: float = QualitySettings.coherence_min,
    max_low_fraction: float = QualitySettings.max_low_fraction,
    band: tuple[float, float] | None = None,
) -> CheckResult:
    """Data quality: clipping, dead channels, low coherence, drive-point passivity.

    The ``checks`` step (:class:`~tyredamp.studies.steps.QualityStep`) with
    these thresholds (:class:`~tyredamp.studies.steps.QualitySettings`).
    """
    settings = QualitySettings(
        coherence_min=coherence_min, max_low_fraction=max_low_fraction, band=band
    )
    return QualityStep.run(data, settings)[0]


def modes_from_frf(
    frf: FRF,
    *,
    band: tuple[float, float] | None = None,
    model: ModelChoice = "both",
    n_modes: int | None = None,
    frequencies: ArrayLike | None = None,
    max_order: int | None = None,
    order_step: int = 2,
    residuals: bool = True,
    false_alarm: float = FALSE_ALARM,
    search: bool = True,
    variance: ArrayLike | None = None,
    estimator: PoleEstimator | None = None,
) -> ModalIdentification:
    """Real-mode (eq. [2]/[3]) and complex-mode (eq. [10]) fits with RMSD (eq. [19]).

    Poles from the stabilisation diagram with automatic selection, then
    residues and poles refined together, the mode count decided by the mode
    test at ``false_alarm`` and a residual search (``search``) for missed
    modes; ``variance`` is the per-line noise variance (default
    ``FRF.variance``, else from the coherence); see
    :func:`tyredamp.modal.identify_modes` for every parameter.
    """
    return identify_modes(
        frf,
        band=band,
        model=model,
        n_modes=n_modes,
        frequencies=frequencies,
        max_order=max_order,
        order_step=order_step,
        residuals=residuals,
        false_alarm=false_alarm,
        search=search,
        variance=variance,
        estimator=estimator,
    )


# ---------------------------------------------------------------- on the virtual tyre
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


def virtual_tyre(
    pressure_bar: float,
    drive_points: tuple[int, ...] = (1,),
    *,
    load_n: float = 0.0,
    cavity: bool = True,
    splice: bool = False,
    attachment_damping: float = 2.0,
) -> RingTyre:
    """The virtual truck tyre at ``pressure_bar`` with shakers at ``drive_points`` (1-based).

    The tyre of paper 000: free on a rigid wheel (no load), with its air
    cavity (docs ``virtual-tyre.md``). ``splice=True`` adds a tread splice,
    which splits each double by 0.06-0.7 Hz but adds almost nothing to the
    non-proportional damping. ``load_n`` > 0 (N) presses it on a
    flat road at 180 deg (:class:`~tyredamp.virtual.ContactPatch`);
    ``attachment_damping`` (N s/m) is the tread loss under each shaker tip
    (:class:`~tyredamp.virtual.MeasurementLayout`).
    """
    return RingTyre(
        RingTyreParameters(pressure=pressure_bar * BAR),
        MeasurementLayout(drive_points=drive_points, attachment_damping=attachment_damping),
        cavity=Cavity() if cavity else None,
        splice=Splice() if splice else None,
        contact=ContactPatch(load_n) if load_n > 0 else None,
    )


def run_pressure(
    pressure_bar: float,
    n_periods: int,
    *,
    force_rms: float,
    snr_db: float,
    seed: int,
    settings: DemoSettings | None = None,
) -> PressureRun:
    """The modal test at one pressure, its FRFs and fits, matched to the true modes.

    The FRF and the modes are the registered steps ``frf`` and ``modal``
    (:data:`~tyredamp.studies.registry.STEPS`) with the settings the demo
    gives them (:meth:`DemoSettings.step_settings`): the recipe of ``tyredamp
    frf``, ``tyredamp modal`` and of a campaign. The verdicts of the ``modal``
    step are not kept: the demo judges each fit against the true modes
    (:func:`tyredamp.studies.findings.pressure_verdicts`).

    Parameters
    ----------
    pressure_bar : float
        Inflation pressure, bar.
    n_periods : int
        Chirp periods (averages).
    force_rms : float
        RMS shaker force, N.
    snr_db : float
        Signal-to-noise ratio of every channel, dB.
    seed : int
        Noise seed.
    settings : DemoSettings, optional
        The demo's settings (default :class:`DemoSettings`); only the steps'
        settings are taken from it.
    """
    steps = (DemoSettings() if settings is None else settings).step_settings()
    test = run_modal_test(
        virtual_tyre(pressure_bar),
        n_periods=n_periods,
        force_rms=force_rms,
        snr_db=snr_db,
        seed=seed,
    )
    frf, _ = STEPS["frf"].run(test.data, steps["frf"])
    ident, _ = STEPS["modal"].run(frf, steps["modal"])
    visible = test.truth.frequency_hz[test.truth.select("visible")]
    matches = {k: match_modes(m.frequency_hz, visible) for k, m in ident.models.items()}
    return PressureRun(pressure_bar, test, frf, ident, matches, n_periods)


def compare_damping(run: PressureRun, dm: DampingModel) -> DampingComparison:
    """Identified ``C'`` of ``dm`` against the exact damping of the tested tyre."""
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


def run_radial(s: DemoSettings, stage: StageCallback | None = None) -> RadialStudy:
    """The radial study of the demo: tests at every pressure, checks, damping, tyre model.

    Parameters
    ----------
    s : DemoSettings
        Pressures, averages, force levels, drive points, SNR, band, damping.
    stage : callable, optional
        ``stage(description)`` before each stage.

    Returns
    -------
    RadialStudy
    """

    def start(name: str) -> None:
        if stage is not None:
            stage(name)

    steps = s.step_settings()
    base = 1000 * s.seed
    runs: list[PressureRun] = []
    for k, p in enumerate(s.radial_pressures_bar):
        start(f"radial: modal test, FRFs, real and complex fits at {p:g} bar")
        n = s.radial_periods if k == 0 else s.radial_side_periods
        runs.append(
            run_pressure(
                p, n, force_rms=s.force_levels_n[0], snr_db=s.snr_db, seed=base + 1 + k, settings=s
            )
        )
    main = runs[0]
    p0 = s.radial_pressures_bar[0]

    start(f"radial: linearity check at {s.force_levels_n[1]:g} N")
    high = run_modal_test(
        virtual_tyre(p0),
        n_periods=s.check_periods,
        force_rms=s.force_levels_n[1],
        snr_db=s.snr_db,
        seed=base + 101,
    )
    frf_high, _ = STEPS["frf"].run(high.data, steps["frf"])
    lin = check_linearity([main.frf, frf_high], band=s.check_band_hz)
    quality, _ = STEPS["checks"].run(main.test.data, steps["checks"])

    start(f"radial: reciprocity check, drive points {s.reciprocity_points}")
    recip_test = run_modal_test(
        virtual_tyre(p0, tuple(s.reciprocity_points)),
        n_periods=s.check_periods,
        force_rms=s.force_levels_n[0],
        snr_db=s.snr_db,
        seed=base + 102,
    )
    recip_frf, _ = STEPS["frf"].run(recip_test.data, steps["frf"])
    recip = check_reciprocity([recip_frf], band=s.check_band_hz)

    start(f"radial: damping identification ({s.damping_method})")
    meta = {"source": f"demo, virtual truck tyre at {p0:g} bar", "model": "complex"}
    dm, _ = STEPS["damping"].run(main.models, steps["damping"], meta)

    start(f"radial: tyre model (flexible ring, rigid ring) at {len(runs)} pressure(s)")
    tyre_model = tyre_model_from_runs(runs)
    return RadialStudy(
        runs=runs,
        linearity=lin,
        reciprocity=recip,
        quality=quality,
        linearity_frfs=[main.frf, frf_high],
        reciprocity_frf=recip_frf,
        damping=dm,
        damping_truth=compare_damping(main, dm),
        tyre_model=tyre_model,
    )
