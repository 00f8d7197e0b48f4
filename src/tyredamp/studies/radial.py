"""The radial damping study of paper 000 as named steps.

Each step takes typed inputs and returns a typed result; the command line
(``tyredamp frf``, ``check``, ``modal``, ``damping``), the demo and any batch
processing call these, so the pipeline exists once::

    time data --frf_from_time--> FRF --check_linearity/_reciprocity/_quality--> CheckResult
                                 FRF --modes_from_frf--> ModalIdentification (real, complex)
              complex ModalModel --damping_from_modes--> DampingModel

On the virtual tyre (known truth): :func:`virtual_tyre`,
:func:`run_pressure` (modal test -> FRF -> modes, matched to the true modes
by :func:`match_modes`), :func:`compare_damping` and :func:`run_radial`, the
whole study of the demo.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from ..damping import DampingModel, Method, identify_damping
from ..exceptions import InputError
from ..frf import FRF, Channel
from ..modal.identify import ModalIdentification, ModelChoice, identify_modes
from ..modal.model import ModalModel
from ..modal.poles.estimators import PoleEstimator
from ..modal.statistics.stats import FALSE_ALARM
from ..signal import CheckResult, linearity_check, quality_check, reciprocity_check
from ..signal.checks import merge_inputs
from ..signal.estimators import Estimator, estimate_frf
from ..signal.estimators import Method as FRFMethod
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
from .results import DampingComparison, ModeMatch, PressureRun, RadialStudy
from .settings import BAR, DemoSettings
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
def frf_from_time(
    data: TimeData,
    estimator: Estimator = "H1",
    *,
    reference: Sequence[Channel | int | str] | None = None,
    method: FRFMethod | None = None,
    segment_samples: int | None = None,
    period_samples: int | None = None,
    settle_samples: int | None = None,
    band: tuple[float, float] | None = None,
    detect: bool = True,
) -> FRF:
    """FRFs with coherence from force and response time data (spec step 2).

    Parameters
    ----------
    data : TimeData
        Force and response channels.
    estimator : {"H1", "H2", "Hv"}
        FRF estimator.
    reference : sequence of Channel, int or str, optional
        Force channels; default: every force channel.
    method : {"cyclic", "welch", "transient", "lrm", "lpm"}, optional
        Averaging method; default chosen from the data's acquisition record
        or, when ``detect``, from the force itself (cyclic for periodic
        excitation); see :func:`tyredamp.signal.estimate_frf`.
    segment_samples : int, optional
        Segment length of Welch/transient averaging, samples.
    period_samples : int, optional
        Excitation period, samples (overrides the acquisition record).
    settle_samples : int, optional
        Samples dropped at the start of the record or of each run (start
        transient); default from the record or detected.
    band : (float, float), optional
        Lines to keep, Hz.
    detect : bool
        Detect periodicity and the start transient from the data when the
        acquisition record does not state them
        (:mod:`tyredamp.signal.periodicity`).
    """
    return estimate_frf(
        data,
        estimator,
        reference=list(reference) if reference else None,
        method=method,
        segment_samples=segment_samples,
        period_samples=period_samples,
        settle_samples=settle_samples,
        band=band,
        detect=detect,
    )


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
    coherence_min: float = 0.9,
    max_low_fraction: float = 0.1,
    band: tuple[float, float] | None = None,
) -> CheckResult:
    """Data quality: clipping, dead channels, low coherence, drive-point passivity."""
    return quality_check(
        data, coherence_min=coherence_min, max_low_coherence_fraction=max_low_fraction, band=band
    )


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


def damping_from_modes(
    models: dict[str, ModalModel],
    *,
    model: str = "complex",
    method: Method = "improved",
    normalise: bool = True,
    n_samples: int = 200,
    seed: int = 0,
    meta: dict[str, Any] | None = None,
    modes: Sequence[int] | None = None,
    band: tuple[float, float] | None = None,
) -> DampingModel:
    """The damping matrix in modal and physical coordinates (eq. [14]-[18]).

    The shapes are taken where they are (:func:`tyredamp.damping.modeset.at_shape_points`:
    at the inputs of a roving-hammer test), the modes chosen by ``modes`` and
    ``band`` (:func:`~tyredamp.damping.modeset.select_modes`), and unscaled
    modes are refused (:func:`~tyredamp.damping.modeset.scaling_problem`):
    without mass-normalised shapes the damping, mass and stiffness matrices
    have no meaning. ``meta`` of the result records ``modes_used`` (1-based
    numbers in the file), ``n_modes_available``, ``shape_points``
    (``"outputs"`` or ``"inputs"``) and ``scaling``.

    Parameters
    ----------
    models : dict of str to ModalModel
        Identified models by name (``"complex"``, ``"real"``).
    model : str
        Which of them to use.
    method, normalise, n_samples, seed, meta
        See :func:`tyredamp.damping.identify_damping`.
    modes : sequence of int, optional
        Mode numbers to use (1-based, in order of frequency); default all.
    band : (float, float), optional
        Natural frequency range of the modes to use, Hz.

    Raises
    ------
    InputError
        Unknown model, mode numbers or band that choose nothing, unscaled modes.
    ShapeError
        More modes than shape points (the message says how many the points allow).
    """
    from ..damping.modeset import (
        at_shape_points,
        check_point_count,
        scaling_problem,
        select_modes,
    )

    if model not in models:
        raise InputError(
            f"model (--model): the modes file holds the {' and '.join(sorted(models))} model(s), "
            f"not {model!r}"
        )
    full = at_shape_points(models[model])
    why = scaling_problem(full)
    if why:
        src = (meta or {}).get("source") or "the modes"
        raise InputError(
            f"{src}: the mode shapes are unscaled ({why}); a damping matrix from them would be "
            "meaningless. Scale them with a drive-point FRF (an input at the node and direction "
            "of a response) in the modal fit, or give the modal A (complex modes) or modal mass "
            "(real modes) with the shapes"
        )
    chosen, numbers = select_modes(full, modes, band)
    check_point_count(chosen, full.n_modes if chosen.n_modes == full.n_modes else None)
    info = dict(meta or {})
    info["modes_used"] = numbers
    info["n_modes_available"] = full.n_modes
    info["shape_points"] = str(full.meta.get("shapes_from", "outputs"))
    info["scaling"] = "mass-normalised"
    dm = identify_damping(
        chosen, method, normalise=normalise, n_samples=n_samples, seed=seed, meta=info
    )
    if info["shape_points"] == "inputs" and dm.std and "psi_out" not in chosen.std:
        from dataclasses import replace

        note = (
            "The shapes at the excitation points carry no standard errors (the fit gives them "
            "at the responses only): the standard errors of C' and C cover the uncertainty of "
            "the poles, not of the shapes, and understate the spread."
        )
        dm = replace(dm, findings=(*dm.findings, note))
    return dm


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
    pressure_bar: float, n_periods: int, *, force_rms: float, snr_db: float, seed: int
) -> PressureRun:
    """The modal test at one pressure, its FRFs and fits, matched to the true modes.

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
    """
    test = run_modal_test(
        virtual_tyre(pressure_bar),
        n_periods=n_periods,
        force_rms=force_rms,
        snr_db=snr_db,
        seed=seed,
    )
    frf = frf_from_time(test.data, "H1")
    ident = modes_from_frf(frf, model="both")
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

    base = 1000 * s.seed
    runs: list[PressureRun] = []
    for k, p in enumerate(s.radial_pressures_bar):
        start(f"radial: modal test, FRFs, real and complex fits at {p:g} bar")
        n = s.radial_periods if k == 0 else s.radial_side_periods
        runs.append(
            run_pressure(p, n, force_rms=s.force_levels_n[0], snr_db=s.snr_db, seed=base + 1 + k)
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
    frf_high = frf_from_time(high.data, "H1")
    lin = check_linearity([main.frf, frf_high], band=s.check_band_hz)
    quality = check_quality(main.test.data, band=s.check_band_hz)  # the band of the other checks

    start(f"radial: reciprocity check, drive points {s.reciprocity_points}")
    recip_test = run_modal_test(
        virtual_tyre(p0, tuple(s.reciprocity_points)),
        n_periods=s.check_periods,
        force_rms=s.force_levels_n[0],
        snr_db=s.snr_db,
        seed=base + 102,
    )
    recip_frf = frf_from_time(recip_test.data, "H1")
    recip = check_reciprocity([recip_frf], band=s.check_band_hz)

    start(f"radial: damping identification ({s.damping_method})")
    dm = damping_from_modes(
        main.models,
        model="complex",
        method=s.damping_method,  # type: ignore[arg-type]
        n_samples=s.damping_samples,
        seed=s.seed,
        meta={"source": f"demo, virtual truck tyre at {p0:g} bar", "model": "complex"},
    )

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
