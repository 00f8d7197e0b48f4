"""Automatic modal identification: FRFs in, real and complex modal models out.

Pipeline of :func:`identify_modes` (spec ``radial-damping.md`` steps 3-6):

1. poles of the model orders ``max_order / 4 .. max_order`` (every
   ``order_step``-th, default every second) by pLSCF
   (:func:`~tyredamp.modal.lscf.plscf`);
2. stabilisation and automatic selection (:mod:`~tyredamp.modal.selection`),
   no frequencies needed; a mode count or approximate frequencies may be given;
3. residues by LSFD with the complex-mode model; modes whose contribution to
   the FRFs is negligible are rejected (rule below) and the fit repeated;
4. for each requested model (``"complex"``: eq. [10]; ``"real"``: eq. [2]/[3])
   non-linear refinement of poles, participation and residues over all FRFs
   together (:class:`~tyredamp.modal.fit.ModalFitter`), mass-normalised
   scaling from the drive points, standard errors, fit indicators.

Automatic order of step 1 (``max_order`` not given; ``n = n_in`` inputs, ``m``
persistent clusters in the diagram of highest order ``p``, which has ``p n``
roots; ``limit = 2 n_freq / (n_in + 1) - 2``):

* start at ``ceil(60 / n)``, or ``ceil((4 n_modes + 16) / n)`` (at least
  ``30 / n``) with a mode count or frequencies;
* *sizing*: while ``p n < 4 (m + 2)`` (fewer than twice the roots of the ``m``
  modes and of two residual terms), raise ``p`` to ``max(2 p, 4 (m + 2) / n)``;
* *settling*: a sized diagram whose persistent clusters hold fewer than two
  thirds of its stable poles is unsettled. Such a share is the signature of an
  order too low for the band: with about as many modes as root pairs, the
  roots are shared among the modes and move from order to order, and few
  columns persist, so ``m`` is small and the sizing rule is met although most
  modes are missing (30 modes in 10-190 Hz at order 60: 3-5 persistent
  clusters holding 24-55 % of the stable poles; the settled diagrams of the
  virtual tyre, the rings and synthetic bands of 6-20 modes hold 67-100 %).
  An order too high also lowers the share: its surplus roots fit the noise
  and are now and then stable. A trial at ``2 p + 8 / n`` (what the sizing
  rule asks when every root pair of order ``p`` is a mode) tells the two
  apart. It is kept, and sizing and settling go on from it, only when its
  diagram has more persistent clusters *and* a larger persistent share:
  modes that were not resolved form columns at the higher order, whereas a
  higher order only adds noise poles to a resolved band, so the share falls.
  Otherwise order ``p`` and its diagram are kept as they were and the
  search stops.

No order exceeds ``limit``. Settled diagrams (the virtual tyre, the rings,
bands of up to about 20 modes) take no trial and cost what the sizing rule
alone costs; each raise or trial recomputes pLSCF at the higher order, and a
rejected trial costs one pLSCF at about twice the final order.

Rejection rule of step 3 (automatic selection only): a mode is dropped when
its synthesised FRF has an RMS below ``min_contribution`` (default 0.2 %) of
the RMS of the data, or when its energy is below ``min_significance``
(default 25) times the energy that fitting pure noise with the same number
of parameters would give. After the refinement a mode that left the band, or
that merged with another (poles closer than 0.05 % of ``|p|``), is dropped
and the fit repeated.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_band, as_finite
from ..exceptions import ConvergenceError, InputError
from ..frf import FRF, KIND_POWER
from .fit import FitResult, ModalFitter, _compress, combine_outputs
from .indicators import mean_phase_deviation, modal_phase_collinearity
from .lscf import PoleSet, plscf
from .model import ModalModel
from .selection import Cluster, StabilityFlags, cluster_poles, stability_flags

__all__ = ["ModalIdentification", "ModelChoice", "identify_modes"]

ModelChoice = Literal["real", "complex", "both"]
#: a stabilisation diagram: poles of all orders, their flags, kept and weak clusters
_Diagram = tuple[PoleSet, StabilityFlags, list[Cluster], list[Cluster]]
#: convergence thresholds of the intermediate fits, in units of the residual
#: variance s^2 (ModalFitter.fit ``tol``): the joint fits of the search and of the
#: rejection stop when a further step would lower the cost by less than 10 s^2, a
#: trial residual mode by less than 1 s^2. They only choose the modes (the F test
#: of a trial has 2 n_out + 2 n_in parameters, so 10 s^2 moves F by < 10 / 34 on
#: the smallest data set) and start the final fit, which converges to _FINAL_TOL.
_SEARCH_TOL = 10.0
_TRIAL_TOL = 1.0
#: evaluation limit of the search's first joint fit: before the residual modes are
#: found, the modes near a band edge absorb the out-of-band ones and converge slowly
#: (linearly) to that biased optimum; one Gauss-Newton step takes most of the gain
#: from the pLSCF poles, the later joint fits and the final fit do the rest
_FIRST_NFEV = 2
#: the final fits stop when a full Gauss-Newton step would lower the cost by less
#: than 1e-4 s^2: the remaining step is about 0.01 standard deviations of the
#: parameters, far below their uncertainty (ModalFitter.fit's default is 1e-6)
_FINAL_TOL = 1e-4
#: a residual mode below the band (damped frequency in [f_lo / 2, f_lo]) shapes the
#: FRFs mainly near f_lo; with fewer lines than this in [f_lo, 2 f_lo] (a band that
#: starts at the first lines) it cannot be told from the lower residual term
_MIN_LOW_LINES = 10
#: output compression (fit.compress_outputs) of the search when n_out > 1.5 rank,
#: and of the final refinement when n_out > 4 rank (module docstring of identify)
_COMPRESS_SEARCH = 1.5
_COMPRESS_FINAL = 4.0
#: automatic order (module docstring): a stabilisation diagram is settled when at
#: least this share of its stable poles belongs to persistent clusters. Settled
#: diagrams of the test cases (virtual tyre, rings, synthetic 6-20 modes at 20-60 dB)
#: have 0.67-1.0; a band with more modes than the order can hold has 0.1-0.55
_SETTLED_SHARE = 2.0 / 3.0


@dataclass(frozen=True)
class ModalIdentification:
    """Result of :func:`identify_modes`.

    Attributes
    ----------
    models : dict of str to ModalModel
        ``"complex"`` and/or ``"real"``; each has ``meta["rmsd"]`` (eq. [19],
        FRF unit), ``meta["relative_error"]``, ``meta["warnings"]``,
        ``meta["mpc"]``, ``meta["mpd_deg"]`` and fit details, and standard
        errors in ``std``.
    band_hz : (float, float)
        Analysis band.
    frf_kind : str
        Kind of the fitted FRFs.
    poles : PoleSet
        Stabilisation data (poles of all orders).
    flags : StabilityFlags
        Per-pole stability flags.
    clusters : list of Cluster
        Persistent clusters (candidate modes before the residue fit).
    rejected : list of dict
        Candidates dropped, each ``{"frequency_hz", "damping_ratio", "reason"}``.
    frequency : ndarray, shape (n_freq,)
        Lines used (Hz).
    discrepancy : dict of str to ndarray
        ``|H_model - H_data|`` RMS over FRFs per line, for each model.
    warnings : list of str
        Pipeline-level remarks.
    """

    models: dict[str, ModalModel]
    band_hz: tuple[float, float]
    frf_kind: str
    poles: PoleSet
    flags: StabilityFlags
    clusters: list[Cluster]
    rejected: list[dict[str, Any]]
    frequency: NDArray[np.float64]
    discrepancy: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def _default_order(n_in: int, n_freq: int, n_modes: int | None) -> int:
    base = 60 if n_modes is None else max(30, 4 * n_modes + 16)
    p = int(np.ceil(base / n_in))
    limit = (2 * n_freq) // (n_in + 1) - 2
    return max(2, min(p, limit))


def _persistent_share(flags: StabilityFlags, kept: list[Cluster]) -> float:
    """Share of the stable poles that belong to the persistent clusters ``kept``.

    0 when no pole is stable (nothing settled).
    """
    n_stable = int(np.count_nonzero(flags.stable))
    if n_stable == 0:
        return 0.0
    return sum(c.members.size for c in kept) / n_stable


def identify_modes(
    frf: FRF,
    band: tuple[float, float] | None = None,
    model: ModelChoice = "both",
    *,
    n_modes: int | None = None,
    frequencies: ArrayLike | None = None,
    max_order: int | None = None,
    order_step: int = 2,
    residuals: bool = True,
    refine: bool = True,
    max_damping: float = 0.2,
    cluster_distance: float = 0.01,
    min_fraction: float = 0.3,
    min_contribution: float = 0.002,
    min_significance: float = 25.0,
    max_helpers: int = 4,
) -> ModalIdentification:
    """Identify modes from measured FRFs without hand-holding.

    Parameters
    ----------
    frf : FRF
        Measured FRFs, shape (n_out, n_in, n_freq), any kind. Drive points
        (an output at the node and direction of an input) fix the mass
        normalisation; without one the shapes are unscaled (a warning says so).
    band : (float, float), optional
        Analysis band in Hz; default the whole axis (0 Hz lines are skipped).
    model : {"both", "complex", "real"}
        Which modal models to fit (default both).
    n_modes : int, optional
        Number of modes to keep (the most persistent clusters); default
        automatic.
    frequencies : array_like of float, optional
        Approximate natural frequencies (Hz) of the wanted modes; the nearest
        stable pole of each is used. Overrides ``n_modes``.
    max_order : int, optional
        Highest pLSCF order, used as given. Default automatic: from
        ``ceil(60 / n_in)`` (or more when ``n_modes`` is large), raised while
        the highest order has fewer than two roots per mode found plus two,
        or while the diagram is unsettled (fewer than two thirds of its
        stable poles in persistent clusters) and a trial at about twice the
        order finds more persistent modes in a more settled diagram (module
        docstring); capped by the number of lines.
    order_step : int
        Orders of the stabilisation diagram: every ``order_step``-th from
        ``max_order`` down to ``max_order / 4`` (default 2; 1 for every
        order). Stability is judged against the previous computed order.
    residuals : bool
        Fit upper and lower residual terms (default True).
    refine : bool
        Non-linear refinement of poles and residues (default True); without
        it the poles stay at their pLSCF values (the standard errors then
        still come from the Gauss-Newton covariance at those values).
    max_damping, cluster_distance, min_fraction : float
        Selection rules, see :mod:`tyredamp.modal.selection`.
    min_contribution, min_significance : float
        Rejection rule for modes that do not contribute (module docstring).
        With more outputs than about four times the number of modes, the
        residual-mode search and this rule run on principal combinations of
        the outputs (:func:`~tyredamp.modal.fit.compress_outputs`); the final
        fits always use every output.
    max_helpers : int
        Largest number of out-of-band residual modes on each side of the band
        (default 4; 0 for none). They are kept in ``ModalModel.residual_modes``.

    Returns
    -------
    ModalIdentification

    Raises
    ------
    InputError
        Bad arguments, a band without lines, or no mode found.
    """
    if not isinstance(frf, FRF):
        raise InputError(f"frf: expected an FRF, got {type(frf).__name__}")
    if model not in ("both", "complex", "real"):
        raise InputError(f"model: expected 'both', 'complex' or 'real', got {model!r}")
    lo, hi = (float(frf.frequency[0]), float(frf.frequency[-1])) if band is None else as_band(band)
    fa = frf.frequency
    lines = np.flatnonzero((fa >= lo) & (fa <= hi) & (fa > 0))  # 0 Hz lines are skipped
    if lines.size == 0:
        frf.band(max(lo, 0.0), hi)  # raises the error naming the band and the data
        raise InputError(f"band: no line above 0 Hz in [{lo:g}, {hi:g}] Hz")
    # the validated FRF's lines, sliced without building (and re-checking) a new FRF
    data = frf
    f = fa[lines]
    H = np.asarray(frf.H) if lines.size == fa.size else np.asarray(frf.H[:, :, lines])
    n_out, n_in, n_f = H.shape
    power = KIND_POWER[data.kind]
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise InputError(f"n_modes: expected a positive integer, got {n_modes!r}")
    fr = None
    if frequencies is not None:
        fr = np.sort(as_finite(frequencies, "frequencies", ndim=1))
        if np.any((fr < lo) | (fr > hi)):
            raise InputError(f"frequencies: expected values inside the band [{lo:g}, {hi:g}] Hz")
    nm_hint = int(n_modes) if n_modes is not None else (None if fr is None else fr.size)
    p_max = _default_order(n_in, n_f, nm_hint) if max_order is None else int(max_order)
    limit = (2 * n_f) // (n_in + 1) - 2

    def diagram(p: int) -> _Diagram:
        # orders below p / 4 do not count for persistence (most modes need a
        # minimum order to appear at all)
        ps_ = plscf(
            f,
            H,
            p,
            band=(float(f[0]), float(f[-1])),
            min_order=max(1, p // 4),
            order_step=order_step,
        )
        flags_ = stability_flags(ps_, band=(lo, hi), max_damping=max_damping)
        kept_, weak_ = cluster_poles(
            ps_, flags_, cluster_distance=cluster_distance, min_fraction=min_fraction
        )
        return ps_, flags_, kept_, weak_

    # automatic order (module docstring): the sizing rule, and trial raises of an
    # unsettled diagram that are kept only when they reveal more persistent modes
    # in a more settled diagram
    ps, flags, kept, weak = diagram(p_max)
    trial: tuple[int, float, _Diagram] | None = None  # order, share, diagram before a trial
    while max_order is None:
        share = _persistent_share(flags, kept)
        if trial is not None:
            p_prev, share_prev, prev = trial
            trial = None
            if len(kept) <= len(prev[2]) or share <= share_prev:
                p_max, (ps, flags, kept, weak) = p_prev, prev
                break
        # sizing: the highest order must give at least 2 poles per pole needed
        # (kept modes + 2 for residual effects, conjugates counted)
        need = 2 * 2 * (len(kept) + 2)
        if p_max >= limit:
            break
        if p_max * n_in < need:
            p_max = min(limit, max(2 * p_max, int(np.ceil(need / n_in))))
        elif share < _SETTLED_SHARE:
            # as if every root pair of the top order were a mode: p n_in / 2 modes
            trial = (p_max, share, (ps, flags, kept, weak))
            p_max = min(limit, 2 * p_max + int(np.ceil(8 / n_in)))
        else:
            break
        ps, flags, kept, weak = diagram(p_max)
    rejected: list[dict[str, Any]] = [
        _rej(c.pole, f"present in {c.fraction:.0%} of orders < {min_fraction:.0%}") for c in weak
    ]
    warnings: list[str] = []
    auto = fr is None and n_modes is None
    extra: list[Cluster] = []  # other persistent modes, fitted as residual modes
    if fr is not None:
        cand = _pick_frequencies(fr, kept + weak, ps, flags)
    elif n_modes is not None:
        pool = sorted(kept + weak, key=lambda c: -c.fraction)
        if len(pool) < n_modes:
            warnings.append(f"n_modes: asked for {n_modes}, only {len(pool)} stable clusters")
        cand = sorted(pool[: int(n_modes)], key=lambda c: c.frequency_hz)
        chosen = {id(c) for c in cand}
        rejected = [r for r, c in zip(rejected, weak, strict=True) if id(c) not in chosen]
    else:
        cand = kept
    if not auto:
        # modes the user did not ask for still shape the FRFs: keep the persistent
        # clusters that are not chosen (and not within 1 % of a chosen one) as
        # residual modes, so that the refinement does not pull the chosen poles
        for c in kept:
            if all(abs(c.pole - d.pole) > 0.01 * abs(d.pole) for d in cand):
                extra.append(c)
    if not cand:
        raise InputError(
            f"no stable mode found in [{lo:g}, {hi:g}] Hz up to order {p_max}; raise "
            "--max-order, widen the band or give --frequencies"
        )
    poles = np.array([c.pole for c in cand])
    part = np.array([c.participation for c in cand])
    drive = data.drive_points()
    cfit = ModalFitter(f, H, power, "complex", drive, upper=residuals, lower=residuals)
    # the searches (residual modes, rejection) refit many times: with more outputs
    # than 1.5 times ``rank`` they run on principal output combinations; so does
    # the final refinement with more than 4 times ``rank`` (_COMPRESS_FINAL), whose
    # residues, standard errors and model then use every output
    rank = 2 * (len(poles) + len(extra) + max_helpers + 2 * n_in) + 16
    sfit = cfit
    patterns = None
    if n_out > _COMPRESS_SEARCH * rank:
        h_comb, patterns = _compress(H, rank)
        sfit = ModalFitter(
            f,
            h_comb,
            power,
            "complex",
            [],
            upper=residuals,
            lower=residuals,
            unit_weights=True,
        )
    # ---- step 3: refine, add out-of-band residual modes, reject modes that do not contribute
    hp = np.array([c.pole for c in extra], dtype=complex)
    hl = np.array([c.participation for c in extra], dtype=complex).reshape(len(extra), n_in)
    n_extra = len(extra)
    last: FitResult | None = None  # latest search fit of all current modes, on sfit
    if refine and max_helpers > 0:
        poles, part, hp2, hl2, dropped0, n_extra, last = _search_helpers(
            sfit,
            np.concatenate([poles, hp]),
            np.concatenate([part, hl]),
            (lo, hi),
            (float(f[0]), float(f[-1])),
            max_helpers,
            min_significance,
            n_free=n_extra,
        )
        rejected += [_rej(p, f"complex fit: {why}") for p, why in dropped0]
        m0 = len(poles) - n_extra
        hp = np.concatenate([poles[m0:], hp2])
        hl = np.concatenate([part[m0:], hl2])
        poles, part = poles[:m0], part[:m0]
    if auto:
        for _ in range(len(poles)):
            if last is None:
                last = sfit.fit(
                    np.concatenate([poles, hp]),
                    np.concatenate([part, hl]),
                    refine=refine,
                    passes=1,
                    tol=_SEARCH_TOL,
                    uncertainty=False,
                )
            res = last
            m = len(poles)
            con, sig = res.contribution[:m], res.significance[:m]
            bad = (con < min_contribution) | (sig < min_significance)
            poles, part = res.poles[:m], res.participation[:m]
            hp, hl = res.poles[m:], res.participation[m:]
            if not np.any(bad) or np.all(bad):
                break
            worst = int(np.argmin(np.where(bad, sig, np.inf)))
            why = (
                f"contribution {con[worst]:.2%} < {min_contribution:.2%}"
                if con[worst] < min_contribution
                else f"significance {sig[worst]:.3g} < {min_significance:g}"
            )
            rejected.append(_rej(poles[worst], why))
            poles = np.delete(poles, worst)
            part = np.delete(part, worst, axis=0)
            last = None
    # noise level per output for the final fit's weights (its second pass in
    # the 2-pass scheme of ModalFitter.fit): from the latest search fit when
    # it ran on every output, else from a linear fit at the current poles
    sigma0 = None
    if refine and last is not None and sfit is cfit:
        sigma0 = last.sigma_out
    elif refine:
        sigma0 = cfit.fit(
            np.concatenate([poles, hp]),
            np.concatenate([part, hl]),
            refine=False,
            uncertainty=False,
        ).sigma_out
    # ---- step 4: each model
    kinds = ["complex", "real"] if model == "both" else [model]
    models: dict[str, ModalModel] = {}
    disc: dict[str, NDArray[np.float64]] = {}
    base: tuple[FitResult, int, int] | None = None  # complex result, n in band, n free
    for kind in kinds:
        if (
            kind == "complex"
            and sigma0 is not None
            and patterns is not None
            and n_out > _COMPRESS_FINAL * rank
        ):
            # the search's output patterns re-weighted by 1 / sigma (one product)
            rms = np.sqrt(np.mean(_abs2(H), axis=(1, 2)))
            wts = 1.0 / np.maximum(sigma0, np.maximum(1e-9 * rms, 1e-300))
            ffit = ModalFitter(
                f,
                combine_outputs(H, patterns, wts),
                power,
                "complex",
                [],
                upper=residuals,
                lower=residuals,
                unit_weights=True,
            )
            r0, n_band, dropped, nf = _fit_checked(
                ffit,
                poles,
                part,
                hp,
                hl,
                True,
                (lo, hi),
                n_free=n_extra,
                passes=1,
                tol=_FINAL_TOL,
                uncertainty=False,
            )
            res = cfit.fit(r0.poles, r0.participation, refine=False, sigma=sigma0)
            res.status, res.n_iter = r0.status, r0.n_iter
            rejected += [_rej(p, f"complex fit: {why}") for p, why in dropped]
            base = (res, n_band, nf)
            extra_warn: list[str] = []
        elif kind == "complex":
            res, n_band, dropped, nf = _fit_checked(
                cfit,
                poles,
                part,
                hp,
                hl,
                refine,
                (lo, hi),
                n_free=n_extra,
                passes=1 if sigma0 is not None else 2,
                sigma=sigma0,
                tol=_FINAL_TOL,
            )
            rejected += [_rej(p, f"complex fit: {why}") for p, why in dropped]
            base = (res, n_band, nf)
            extra_warn = []
        else:
            res, n_band, extra_warn = _fit_real(
                f,
                H,
                power,
                drive,
                residuals,
                refine,
                sfit is not cfit,
                sfit.H,
                poles,
                part,
                hp,
                hl,
                n_extra,
                (lo, hi),
                base,
            )
        hm = res.model
        res.warnings.extend(extra_warn)
        sq = _abs2(hm - H)
        mdl = _to_model(res, n_band, kind, data, H, (lo, hi), p_max, sq)
        mdl.meta["order_step"] = int(order_step)
        models[kind] = mdl
        disc[kind] = np.sqrt(np.mean(sq, axis=(0, 1)))
    return ModalIdentification(
        models=models,
        band_hz=(lo, hi),
        frf_kind=data.kind,
        poles=ps,
        flags=flags,
        clusters=kept,
        rejected=rejected,
        frequency=f,
        discrepancy=disc,
        warnings=warnings,
    )


def _abs2(z: NDArray[np.complex128]) -> NDArray[np.float64]:
    """``|z|^2`` without the square root of ``np.abs``."""
    return np.asarray(z.real**2 + z.imag**2)


def _rej(p: complex, why: str) -> dict[str, Any]:
    return {
        "frequency_hz": float(abs(p) / (2 * np.pi)),
        "damping_ratio": float(-p.real / abs(p)),
        "reason": why,
    }


def _pick_frequencies(
    fr: NDArray[np.float64], clusters: list[Cluster], ps: PoleSet, flags: StabilityFlags
) -> list[Cluster]:
    """The cluster (or, failing that, the admissible pole) nearest to each frequency."""
    out: list[Cluster] = []
    used: set[int] = set()
    adm = np.flatnonzero(flags.admissible)
    for fi in fr:
        best = None
        if clusters:
            d = np.array([abs(c.frequency_hz - fi) / fi for c in clusters])
            for i in np.argsort(d):
                if d[i] <= 0.05 and int(i) not in used:
                    best = clusters[int(i)]
                    used.add(int(i))
                    break
        if best is None:
            if adm.size == 0:
                raise InputError(f"frequencies: no admissible pole near {fi:g} Hz")
            top = ps.order[adm].max()
            cand = adm[ps.order[adm] >= top - 2]
            j = cand[np.argmin(np.abs(ps.frequency_hz[cand] - fi))]
            if abs(ps.frequency_hz[j] - fi) > 0.1 * fi:
                raise InputError(f"frequencies: no admissible pole within 10 % of {fi:g} Hz")
            best = Cluster(
                pole=complex(ps.poles[j]),
                participation=ps.participation[j],
                members=np.array([j]),
                fraction=0.0,
                spread_frequency=0.0,
            )
        out.append(best)
    return out


def _search_helpers(
    fitter: ModalFitter,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    band: tuple[float, float],
    data_band: tuple[float, float],
    max_helpers: int,
    min_significance: float,
    n_free: int = 0,
) -> tuple[
    NDArray[np.complex128],
    NDArray[np.complex128],
    NDArray[np.complex128],
    NDArray[np.complex128],
    list[tuple[complex, str]],
    int,
    FitResult,
]:
    """Refine, then add out-of-band residual modes while they are significant.

    A trial pole is started at ``1.1 f_hi`` (then ``1.3 f_hi``, ...) above the
    band, and at ``0.9 f_lo`` (...) below it when ``f_lo > 0`` and at least
    ``_MIN_LOW_LINES`` lines lie in ``[f_lo, 2 f_lo]``, with the median
    damping of the in-band modes. Only the trial mode is refined, with every
    other mode held fixed (:meth:`~tyredamp.modal.fit.ModalFitter.fit_added`:
    their basis is projected out of the data once) and its damped frequency
    kept outside the band but within a factor 2 of its edge. It is kept when
    it did not stop at one of these limits and the residual sum of squares
    dropped significantly: ``F = sum_j dof (s2_before,j - s2_after,j) /
    s2_after,j / n_added`` (per-output residual variances) reaches
    ``min_significance``; all modes are then refined together, and the search
    stops instead if that moves the trial mode out of its range or an in-band
    mode out of the band. A rejected trial thus costs one small fit, not a
    joint refinement. The fits of the search converge to ``_SEARCH_TOL``
    residual variances (they only choose modes and start the final fit) and
    skip the standard errors; the last accepted joint fit is returned too.
    """
    lo, hi = band
    m0 = len(poles) - n_free
    res, m0, dropped, n_free = _fit_checked(
        fitter,
        poles[:m0],
        part[:m0],
        poles[m0:],
        part[m0:],
        True,
        band,
        n_free=n_free,
        passes=1,
        tol=_SEARCH_TOL,
        uncertainty=False,
        max_nfev=_FIRST_NFEV,
    )
    m = m0 + n_free
    cur_p, cur_l = res.poles, res.participation
    sig_cur = res.sigma_out
    per = 2 if fitter.kind == "complex" else 1
    dof = fitter.n_rows
    zeta0 = float(np.clip(np.median(-cur_p.real / np.abs(cur_p)), 0.005, 0.1))
    # below the band only when the data can tell a mode there from the lower
    # residual: at least _MIN_LOW_LINES lines in [f_lo, 2 f_lo]
    n_low = int(np.count_nonzero((fitter.f >= lo) & (fitter.f <= 2 * lo)))
    sides = [1.0] + ([-1.0] if data_band[0] > 0 and n_low >= _MIN_LOW_LINES else [])
    for side in sides:
        for k in range(max_helpers):
            fh = hi * (1.1 + 0.2 * k) if side > 0 else lo * (0.9 - 0.2 * k)
            if fh <= 0:
                break
            wh = 2 * np.pi * fh
            ph = complex(-zeta0 * wh, wh * np.sqrt(1 - zeta0**2))
            lh = np.ones(fitter.n_in, complex)
            try:
                # only the trial mode moves (the others are projected out once),
                # kept on its side of the band, within a factor 2 of the edge
                edge = (hi, 2 * hi) if side > 0 else (lo / 2, lo)
                w_lim = (2 * np.pi * edge[0], 2 * np.pi * edge[1])
                p_t, l_t, sig_t = fitter.fit_added(
                    cur_p, cur_l, ph, lh, omega_bounds=w_lim, tol=_TRIAL_TOL, theta=res.theta
                )
            except (np.linalg.LinAlgError, ValueError):
                break
            fd = p_t.imag / (2 * np.pi)
            # a trial pole stopped at a limit did not find a mode there
            tol = 1e-4 * (edge[1] - edge[0])
            outside = edge[0] + tol < fd < edge[1] - tol
            s2a = np.maximum(sig_t**2, 1e-300)
            n_added = per * fitter.n_out + 2 * fitter.n_in
            fstat = float(np.sum(dof * (sig_cur**2 - s2a) / s2a)) / n_added
            if not (outside and fstat >= min_significance):
                break
            # accepted: refine every mode together before the next trial
            try:
                trial = fitter.fit(
                    np.append(cur_p, p_t),
                    np.concatenate([cur_l, l_t[None, :]]),
                    passes=1,
                    tol=_SEARCH_TOL,
                    uncertainty=False,
                )
            except (np.linalg.LinAlgError, ValueError):
                break
            fd = trial.poles[-1].imag / (2 * np.pi)
            fin = trial.poles[: m - n_free].imag / (2 * np.pi)
            outside = (hi < fd <= 2 * hi) if side > 0 else (lo / 2 <= fd < lo)
            if not (outside and np.all((fin >= lo) & (fin <= hi))):
                break
            sig_cur = trial.sigma_out
            cur_p, cur_l = trial.poles, trial.participation
            res = trial
    return cur_p[:m], cur_l[:m], cur_p[m:], cur_l[m:], dropped, n_free, res


def _problem(res: FitResult, m: int, n_free: int, band: tuple[float, float]) -> str:
    """Why a fit is not acceptable ("" when it is): a mode crossed a band edge, or two merged."""
    p = res.poles
    fd = p.imag / (2 * np.pi)
    inb = (fd >= band[0]) & (fd <= band[1])
    free = np.zeros(len(p) - m, bool)
    free[:n_free] = True
    wrong = np.flatnonzero(np.concatenate([~inb[:m], inb[m:] & ~free]))
    if wrong.size:
        return f"a pole crossed the band edge ({fd[wrong[0]]:.2f} Hz)"
    d = np.abs(p[:, None] - p[None, :]) / np.abs(p)[:, None]
    np.fill_diagonal(d, np.inf)
    if d.size and d.min() < 5e-4:
        return "two poles merged"
    return ""


def _fit_real(
    f: NDArray[np.float64],
    H: NDArray[np.complex128],
    power: int,
    drive: list[tuple[int, int]],
    residuals: bool,
    refine: bool,
    compressed: bool,
    h_search: NDArray[np.complex128],
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    hp: NDArray[np.complex128],
    hl: NDArray[np.complex128],
    n_free: int,
    band: tuple[float, float],
    base: tuple[FitResult, int, int] | None,
) -> tuple[FitResult, int, list[str]]:
    """Real-mode fit (pole-pair optimisation) started from the complex-mode poles.

    The real model keeps the modes of the complex model. When its refinement
    is not acceptable (a pole crosses a band edge or two merge: real modes
    that cannot describe strongly complex data), the poles are kept at the
    complex-mode values, only the real residues are fitted, and a warning
    says so.
    """
    if base is not None:
        cres, m, nf = base
        p0, l0 = cres.poles, cres.participation
    else:
        m, nf = len(poles), n_free
        p0, l0 = np.concatenate([poles, hp]), np.concatenate([part, hl])
    fitter = ModalFitter(f, H, power, "real", drive, upper=residuals, lower=residuals)
    if not refine:
        return fitter.fit(p0, l0, refine=False), m, []
    start_p, start_l = p0, l0
    if compressed:
        # real modes start far from the complex optimum: pre-fit on the combinations
        pre = ModalFitter(
            f, h_search, power, "real", [], upper=residuals, lower=residuals, unit_weights=True
        ).fit(p0, l0, passes=1)
        why = _problem(pre, m, nf, band)
        start_p, start_l = pre.poles, pre.participation
    else:
        why = ""
    if not why:
        # the evaluation limit bounds the time spent on data that real modes cannot fit
        res = fitter.fit(start_p, start_l, refine=True, max_nfev=100, tol=_FINAL_TOL)
        why = _problem(res, m, nf, band)
        if not why:
            return res, m, []
    res = fitter.fit(p0, l0, refine=False)
    return (
        res,
        m,
        [
            f"real-mode refinement not acceptable ({why}): poles kept at the complex-mode "
            "values, real residues fitted"
        ],
    )


def _fit_checked(
    fitter: ModalFitter,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    hp: NDArray[np.complex128],
    hl: NDArray[np.complex128],
    refine: bool,
    band: tuple[float, float],
    n_free: int = 0,
    passes: int = 2,
    sigma: NDArray[np.float64] | None = None,
    tol: float = 1e-6,
    uncertainty: bool = True,
    max_nfev: int = 200,
) -> tuple[FitResult, int, list[tuple[complex, str]], int]:
    """Fit modes and residual modes; drop any that left its side of the band or merged.

    Returns the fit, the number of in-band modes, the dropped modes and the
    number of in-band residual modes left. ``passes``, ``sigma``, ``tol``,
    ``uncertainty`` and ``max_nfev`` go to :meth:`~tyredamp.modal.fit.ModalFitter.fit`.

    ``hp`` holds first ``n_free`` in-band residual modes (not checked against
    the band), then out-of-band ones (which must stay outside).
    """
    dropped: list[tuple[complex, str]] = []
    for _ in range(len(poles) + len(hp) + 1):
        m = len(poles)
        res = fitter.fit(
            np.concatenate([poles, hp]),
            np.concatenate([part, hl]),
            refine=refine,
            passes=passes,
            sigma=sigma,
            tol=tol,
            uncertainty=uncertainty,
            max_nfev=max_nfev,
        )
        p = res.poles
        fd = p.imag / (2 * np.pi)
        inb = (fd >= band[0]) & (fd <= band[1])
        free = np.zeros(len(hp), bool)
        free[:n_free] = True
        wrong = np.flatnonzero(np.concatenate([~inb[:m], inb[m:] & ~free]))
        bad: int | None = None
        why = ""
        if wrong.size:
            bad = int(wrong[0])
            why = f"crossed the band edge during refinement ({fd[bad]:.2f} Hz)"
        else:
            d = np.abs(p[:, None] - p[None, :]) / np.abs(p)[:, None]
            np.fill_diagonal(d, np.inf)
            if d.size and d.min() < 5e-4:
                i, j = np.unravel_index(np.argmin(d), d.shape)
                bad = int(i if res.contribution[i] < res.contribution[j] else j)
                why = "merged with another mode during refinement"
        if bad is None:
            return res, m, dropped, n_free
        if bad < m:
            if m == 1:
                raise ConvergenceError(f"the only mode {why}")
            dropped.append((complex(poles[bad]), why))
            poles = np.delete(poles, bad)
            part = np.delete(part, bad, axis=0)
        else:
            if bad - m < n_free:
                n_free -= 1
            hp = np.delete(hp, bad - m)
            hl = np.delete(hl, bad - m, axis=0)
    raise ConvergenceError("refinement kept losing modes")


def _to_model(
    res: FitResult,
    n_band: int,
    kind: str,
    data: FRF,
    H: NDArray[np.complex128],
    band: tuple[float, float],
    p_max: int,
    sq: NDArray[np.float64],
) -> ModalModel:
    """ModalModel of one fit; ``data`` gives the channels and kind, ``H`` (n_out, n_in,
    n_freq) the fitted lines, and ``sq = |H_model - H|^2`` the
    fit indicators: RMSD eq. [19] (as :func:`~tyredamp.modal.indicators.rmsd`), its
    value per FRF and the relative error (as ``relative_error``)."""
    mk: Literal["complex", "real"] = "complex" if kind == "complex" else "real"
    data_ss = float(np.sum(_abs2(H)))
    resid_modes = None
    if len(res.poles) > n_band:
        resid_modes = ModalModel(
            res.poles[n_band:],
            res.psi_out[:, n_band:],
            res.psi_in[:, n_band:],
            mode_kind=mk,
            outputs=data.outputs,
            inputs=data.inputs,
            meta={"role": "out-of-band modes used as residual terms"},
        )
    # in-band modes, sorted by Im p as ModalModel sorts them (keeps meta arrays aligned)
    o = np.argsort(res.poles[:n_band].imag)
    poles, psi_out, psi_in = res.poles[o], res.psi_out[:, o], res.psi_in[:, o]
    std: dict[str, ArrayLike] = {
        "frequency_hz": res.std_frequency_hz[o],
        "damping_ratio": res.std_damping_ratio[o],
        "psi_out": res.std_psi_out[:, o],
    }
    meta = {
        "band_hz": [band[0], band[1]],
        "frf_kind": data.kind,
        "rmsd": float(np.sqrt(sq.sum()) / sq.size),
        "relative_error": float(np.sqrt(sq.sum() / max(data_ss, 1e-300))),
        "rmsd_per_frf": np.sqrt(sq.sum(axis=-1)) / sq.shape[-1],
        "n_lines": int(H.shape[-1]),
        "method": "pLSCF poles, automatic selection, LSFD, variable-projection refinement",
        "max_order": p_max,
        "refinement": res.status,
        "n_evaluations": res.n_iter,
        "noise_rms_per_output": res.sigma_out,
        "mpc": modal_phase_collinearity(psi_out),
        "mpd_deg": mean_phase_deviation(psi_out),
        "contribution": res.contribution[o],
        "significance": res.significance[o],
        "drive_point_phi2": res.drive_phi2[o],
        "std_pole": res.std_pole[o],
        "n_residual_modes": len(res.poles) - n_band,
        "warnings": list(res.warnings),
    }
    return ModalModel(
        poles,
        psi_out,
        psi_in,
        mode_kind=mk,
        outputs=data.outputs,
        inputs=data.inputs,
        upper_residual=res.upper,
        lower_residual=res.lower,
        std=std,
        meta=meta,
        residual_modes=resid_modes,
    )
