"""The :class:`~tyredamp.modal.model.ModalModel` of a final fit, with its quality.

:func:`to_model` turns a final fit of the normalised data (:mod:`tyredamp.modal.final`)
into the model in the data's units (:func:`unscale`) with its fit indicators
(RMSD eq. [19], relative error), the goodness of fit against the noise
(:func:`goodness`), each in-band mode's local dispersion
(:func:`local_dispersion`) and 95 % intervals (likelihood or linearised,
scaled by that dispersion), the statement of every mode kept or rejected
(:class:`~tyredamp.modal.statistics.quality.FitQuality`) and the out-of-band
modes used as residual terms.
"""

from __future__ import annotations

import dataclasses
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..mechanics.modal_sum import pole_quantities
from .fit.fit import FitResult
from .fit.profile import Z95
from .model import ModalModel
from .problem.problem import FitProblem
from .search.narrow import unresolved_damping
from .search.residual_peaks import local_ratio
from .statistics.indicators import mean_phase_deviation, modal_phase_collinearity
from .statistics.quality import FitQuality, RejectedMode, threshold_text
from .statistics.stats import (
    DIFFERENCE_INFLATION,
    GoodnessOfFit,
    difference_noise,
    goodness_of_fit,
)

__all__ = ["ModelContext", "goodness", "local_dispersion", "to_model", "unscale"]


def _abs2(z: NDArray[np.complex128]) -> NDArray[np.float64]:
    return np.asarray(z.real**2 + z.imag**2)


#: lines per block of the per-line residual powers (no temporaries of the data's size)
_BLOCK = 16384


def _abs2_diff(a: NDArray[np.complex128], b: NDArray[np.complex128]) -> NDArray[np.float64]:
    """``|a - b|^2`` (same shape, lines last), computed over blocks of lines."""
    out = np.empty(a.shape)
    for i in range(0, a.shape[-1], _BLOCK):
        sl = slice(i, i + _BLOCK)
        out[..., sl] = _abs2(a[..., sl] - b[..., sl])
    return out


def unscale(res: FitResult, c: float, drive: bool) -> FitResult:
    """The fit of data ``H / c`` turned into that of ``H``: residues times ``c``.

    With drive points the shapes are mass-normalised (``R = psi_out psi_in``):
    both scale by ``sqrt(c)``; without, ``psi_in`` is the participation and
    ``psi_out`` scales by ``c``.
    """
    so = np.sqrt(c) if drive else c
    si = np.sqrt(c) if drive else 1.0
    return dataclasses.replace(
        res,
        psi_out=res.psi_out * so,
        psi_in=res.psi_in * si,
        std_psi_out=res.std_psi_out * so,
        std_psi_in=res.std_psi_in * si,
        upper=None if res.upper is None else res.upper * c,
        lower=None if res.lower is None else res.lower * c,
        sigma_out=res.sigma_out * c,
        drive_phi2=res.drive_phi2 * c,
    )


def goodness(
    problem: FitProblem, sq: NDArray[np.float64], n_par: int, n_rejected: int, false_alarm: float
) -> GoodnessOfFit:
    """Goodness of fit of ``sq = |H_model - H|^2`` (normalised units, (n_out, n_in, n_f)).

    A known variance: chi-square; one estimated with ``nu`` degrees of freedom
    (``problem.noise_dof``): the ``F``-corrected test of
    :mod:`tyredamp.modal.statistics.stats` (one with ``nu <= 4``, too few averages for the
    cost to have a variance, is set aside by
    :func:`~tyredamp.modal.problem.problem.build_problem`); none: the second-difference
    noise of each FRF, estimated from the lines the cost sums (the scaled chi-square
    of eq. (GoF-1) of :mod:`tyredamp.modal.statistics.stats`).
    """
    n_obs = 2 * sq.size
    nu = problem.noise_dof
    if problem.variance is not None:
        v = problem.variance
        pos = v > 0
        # E|e|^2 = V: real and imaginary part each of variance V / 2, 2 dof per entry
        chi2 = 2.0 * float(np.sum(sq[pos] / v[pos]))
        if problem.noise_note:
            label = problem.noise_note
        elif problem.noise_source == "variance" and nu is None:
            label = "per-line variance given"
        else:
            what = "variance" if problem.noise_source == "variance" else "variance from coherence"
            n_avg = problem.n_averages
            src = f"{n_avg} averages, " if n_avg is not None else ""
            label = f"per-line {what} estimated from {src}nu = {nu:.3g} dof"
        return goodness_of_fit(
            chi2,
            n_obs - n_par,
            label,
            n_rejected=n_rejected,
            false_alarm=false_alarm,
            noise_dof=nu,
        )
    var = difference_noise(problem.H, per_input=True)  # (n_out, n_in): each FRF's noise
    if not np.all(np.isfinite(var)) or np.any(var <= 0):
        return goodness_of_fit(
            float("nan"), n_obs - n_par, "unknown", n_rejected=n_rejected, false_alarm=false_alarm
        )
    # |e|^2 / (s^2 / 2) per real and imaginary part: 2 dof per entry; the noise is
    # estimated from the same lines: the cost's variance is DIFFERENCE_INFLATION
    # times the chi-square's (eq. (GoF-1) of modal.statistics.stats)
    chi2 = 2.0 * float(np.einsum("okf,ok->", sq, 1.0 / var))
    label = "from second differences of adjacent lines"
    return goodness_of_fit(
        chi2,
        n_obs - n_par,
        label,
        n_rejected=n_rejected,
        false_alarm=false_alarm,
        inflation=DIFFERENCE_INFLATION,
    )


def _unresolved(poles: NDArray[np.complex128], f: NDArray[np.float64]) -> list[str]:
    """The statements of the modes whose damping the lines ``f`` (Hz) do not resolve."""
    df = float(f[1] - f[0]) if f.size > 1 else 0.0
    fn, zeta = pole_quantities(poles)
    out = (unresolved_damping(float(a), float(b), df) for a, b in zip(fn, zeta, strict=True))
    return [w for w in out if w]


@dataclasses.dataclass(frozen=True)
class ModelContext:
    """What :func:`to_model` needs besides the fit."""

    problem: FitProblem
    kind: Literal["complex", "real"]
    max_order: int
    order_step: int
    threshold: float
    false_alarm: float
    kept: tuple[str, ...] | None
    rejected: tuple[RejectedMode, ...]
    method: str
    #: the threshold applied to each in-band mode (fit order): the base
    #: ``threshold`` raised where the noise lies along the response
    #: (:func:`final_complex`); None: ``threshold`` for every mode
    thresholds: NDArray[np.float64] | None = None
    #: each in-band mode's noise along the response over the fit's noise, where it
    #: exceeds its scatter (fit order; :func:`noise_along_response`); None: not measured
    along: NDArray[np.float64] | None = None
    #: the factors of the variances of each in-band mode's frequency and damping
    #: ratio under the noise's structure across outputs (n_band, 2; fit order;
    #: :func:`~tyredamp.modal.final.sandwiched`, whose fit then holds the shapes'
    #: errors under it too); None: not known, ``along`` stands for it
    pole_ratio: NDArray[np.float64] | None = None


def local_dispersion(
    problem: FitProblem, res: FitResult, sq: NDArray[np.float64], n_band: int
) -> NDArray[np.float64]:
    """Each in-band mode's local dispersion: the mean residual power per line
    within two half-widths of the mode over its mean over the band
    (:func:`~tyredamp.modal.search.residual_peaks.local_ratio`), at least 1 (n_band,).

    The standard errors of a weighted least-squares or maximum-likelihood fit
    assume that the residual is noise of the estimated level everywhere; where
    the model misses structure near a mode (a missed neighbour, a mode that
    stands for two), the residual there exceeds the noise, the estimate is
    biased by that structure and its linearised standard error too small.
    Scaling a mode's standard errors by the square root of the dispersion of
    its own lines (the quasi-likelihood dispersion of McCullagh & Nelder 1989,
    sec. 9.2, estimated locally) widens the intervals of those modes and, for a
    model that explains the data to the noise, leaves them within the few
    per cent of the ratio's sampling scatter. The residual power of a line is
    summed over the FRFs in units of each output's noise (``res.sigma_out``)
    with the fit's line weights, or of each entry's variance when the problem
    has one; ``sq`` is ``|H_model - H|^2`` (n_out, n_in, n_f).
    """
    if n_band == 0:
        return np.ones(0)
    if problem.variance is not None:
        v = np.asarray(problem.variance, dtype=np.float64)
        pw = np.sum(np.where(v > 0, sq / np.where(v > 0, v, 1.0), 0.0), axis=(0, 1))
    else:
        s2 = np.maximum(np.asarray(res.sigma_out, dtype=np.float64) ** 2, 1e-300)
        pw = np.einsum("jkf,j->f", sq, 1.0 / s2)
        if problem.line_weights is not None:
            pw = pw * np.asarray(problem.line_weights, dtype=np.float64) ** 2
    f = problem.frequency
    if not float(np.mean(pw)) > 0 or f.size < 2:
        return np.ones(n_band)
    rho, _ = local_ratio(f, pw, res.poles[:n_band])
    return np.asarray(np.maximum(rho, 1.0))


def _intervals_95(
    res: FitResult,
    u: FitResult,
    o: NDArray[np.intp],
    poles: NDArray[np.complex128],
    inflations: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> tuple[dict[str, ArrayLike], dict[str, object]]:
    """The standard errors and 95 % intervals of the in-band modes (sorted by ``o``;
    ``u`` the unscaled fit, ``inflations`` the factors of the shapes (n,) and of the
    frequencies and damping ratios (n, 2): the square root of each mode's local
    dispersion): the likelihood interval where it was formed
    (:mod:`~tyredamp.modal.fit.profile`), else the linearised one, each half scaled by
    the local dispersion; the standard error of a mode with a likelihood interval
    is the half-width of the symmetric interval that holds it, over 1.96. Returns
    the ``std`` entries and the ``meta`` entries of the intervals."""
    f_hat, z_hat = np.abs(poles) / (2 * np.pi), -poles.real / np.abs(poles)
    sd_f, sd_z = u.std_frequency_hz[o], u.std_damping_ratio[o]
    iv = res.intervals
    lik = np.zeros(o.size, bool) if iv is None else np.asarray(iv.likelihood)[o]
    opn = np.zeros(o.size, bool) if iv is None else np.asarray(iv.open)[o]
    half_f = np.stack([Z95 * sd_f, Z95 * sd_f], axis=1)
    half_z = np.stack([Z95 * sd_z, Z95 * sd_z], axis=1)
    if iv is not None and lik.any():
        fi, zi = np.asarray(iv.frequency_hz)[o], np.asarray(iv.damping_ratio)[o]
        half_f[lik] = np.abs(fi[lik] - f_hat[lik, None])
        half_z[lik] = np.abs(zi[lik] - z_hat[lik, None])
    inflate, fz = inflations
    half_f, half_z = half_f * fz[:, 0, None], half_z * fz[:, 1, None]
    std: dict[str, ArrayLike] = {
        "frequency_hz": np.where(lik, np.max(half_f, axis=1) / Z95, sd_f * fz[:, 0]),
        "damping_ratio": np.where(lik, np.max(half_z, axis=1) / Z95, sd_z * fz[:, 1]),
        "psi_out": u.std_psi_out[:, o] * inflate[None, :],
    }
    sin = u.std_psi_in
    if sin.ndim == 2 and sin.shape[1] == u.std_psi_out.shape[1] and np.isfinite(sin[:, o]).all():
        std["psi_in"] = sin[:, o] * inflate[None, :]
    f_lo, f_hi = f_hat - half_f[:, 0], f_hat + half_f[:, 1]
    meta: dict[str, object] = {
        "interval_frequency_hz": np.stack([f_lo, f_hi], axis=1),
        "interval_damping_ratio": np.stack([z_hat - half_z[:, 0], z_hat + half_z[:, 1]], axis=1),
        "interval_method": [
            (f"likelihood, {MERGED}" if merged else "likelihood") if b else "linearised"
            for b, merged in zip(lik, opn | _holds_other(f_hat, f_lo, f_hi), strict=True)
        ],
    }
    return std, meta


#: the interval method of a mode whose likelihood interval holds another mode's
#: frequency, or has an end where the profile never reached the cut
MERGED = "not told from a neighbour"


def _holds_other(
    f_hat: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """Whether each mode's frequency interval ``[lo, hi]`` holds another mode's
    frequency (the data do not tell the two apart at that level)."""
    inside = (f_hat[None, :] >= lo[:, None]) & (f_hat[None, :] <= hi[:, None])
    np.fill_diagonal(inside, False)
    return np.asarray(np.any(inside, axis=1))


def _inflations(
    ctx: ModelContext, disp: NDArray[np.float64], o: NDArray[np.intp]
) -> tuple[NDArray[np.float64], ...]:
    """The in-band modes' noise along the response (sorted by ``o``), the factors of the
    variances of their frequencies and damping ratios (n, 2), and the factors of the
    standard errors of the shapes (n,) and of frequency and damping ratio (n, 2):
    the square root of the larger of the local dispersion ``disp`` and the noise
    along the response; where the sandwich is known (:attr:`ModelContext.pole_ratio`)
    the sandwich's factor for frequency and damping ratio, and for the shapes, whose
    errors are then the sandwich's own (:func:`~tyredamp.modal.final.sandwiched`), the
    square root of the local dispersion alone."""
    n = o.size
    along = np.ones(n) if ctx.along is None else np.asarray(ctx.along, dtype=float)[o]
    ratio = np.repeat(along[:, None], 2, axis=1)
    shapes = np.sqrt(np.maximum(disp, along))
    if ctx.pole_ratio is not None:
        ratio = np.asarray(ctx.pole_ratio, dtype=float)[o]
        shapes = np.sqrt(disp)
    return along, ratio, shapes, np.sqrt(np.maximum(disp[:, None], ratio))


def to_model(
    res: FitResult, n_band: int, ctx: ModelContext
) -> tuple[ModalModel, NDArray[np.float64]]:
    """ModalModel of one fit (normalised data) in the data's units, and its
    discrepancy per line (RMS over FRFs, FRF unit).

    Fit indicators: RMSD eq. [19] (as :func:`~tyredamp.modal.statistics.indicators.rmsd`), its
    value per FRF and the relative error (as ``relative_error``), computed in
    the normalised units and scaled back (no overflow for any data magnitude).
    """
    pr = ctx.problem
    c = pr.scale
    sq = _abs2_diff(res.model, pr.H)
    gof = goodness(pr, sq, res.n_par, len(ctx.rejected), ctx.false_alarm)
    u = unscale(res, c, bool(pr.drive))
    data = pr.frf
    resid_modes = None
    if len(res.poles) > n_band:
        resid_modes = ModalModel(
            u.poles[n_band:],
            u.psi_out[:, n_band:],
            u.psi_in[:, n_band:],
            mode_kind=ctx.kind,
            outputs=data.outputs,
            inputs=data.inputs,
            meta={"role": "out-of-band modes used as residual terms"},
        )
    # in-band modes, sorted by Im p as ModalModel sorts them (keeps meta arrays aligned)
    o = np.argsort(u.poles[:n_band].imag)
    poles, psi_out, psi_in = u.poles[o], u.psi_out[:, o], u.psi_in[:, o]
    disp = local_dispersion(pr, res, sq, n_band)[o]
    along, ratio, inflate, inflate_fz = _inflations(ctx, disp, o)
    std, intervals = _intervals_95(res, u, o, poles, (inflate, inflate_fz))
    n_f = pr.H.shape[-1]
    rmsd = float(c * np.sqrt(sq.sum()) / sq.size)
    rel = float(np.sqrt(sq.sum() / max(float(np.vdot(pr.H, pr.H).real), 1e-300)))
    per_frf = c * np.sqrt(sq.sum(axis=-1)) / n_f
    stat = res.significance[:n_band][o]
    base = ctx.threshold
    thr = np.full(n_band, base) if ctx.thresholds is None else np.asarray(ctx.thresholds)[o]
    kept = ctx.kept
    if kept is None:  # automatic mode count
        why_not = (
            "a mode of the complex model, not significant as a real mode"
            if ctx.kind == "real"
            else "the only mode left, not significant (no mode passes the test)"
        )
        kept = tuple(
            f"T = {t:.3g} > {threshold_text(h, base)} (false-alarm rate {ctx.false_alarm:g})"
            if t > h
            else f"{why_not}: T = {t:.3g} <= {threshold_text(h, base)}"
            for t, h in zip(stat, thr, strict=True)
        )
    else:
        kept = tuple(kept[int(i)] for i in o)
    quality = FitQuality(
        rmsd=rmsd,
        relative_error=rel,
        rmsd_per_frf=per_frf,
        n_lines=n_f,
        noise_source=pr.noise_source,
        noise_rms_per_output=u.sigma_out,
        chi2=gof.chi2,
        dof=gof.dof,
        p_value=gof.p_value,
        passed=gof.passed,
        verdict=gof.verdict,
        statistic=stat,
        threshold=base,
        false_alarm=ctx.false_alarm,
        kept=kept,
        rejected=ctx.rejected,
        status=res.status,
        n_evaluations=res.n_iter,
        thresholds=thr,
    )
    unresolved = _unresolved(poles, pr.frequency)
    meta = {
        "band_hz": [pr.band[0], pr.band[1]],
        "frf_kind": data.kind,
        "rmsd": rmsd,
        "relative_error": rel,
        "rmsd_per_frf": per_frf,
        "n_lines": int(n_f),
        "method": ctx.method,
        "max_order": ctx.max_order,
        "order_step": int(ctx.order_step),
        "refinement": res.status,
        "n_evaluations": res.n_iter,
        "noise_rms_per_output": u.sigma_out,
        "mpc": modal_phase_collinearity(psi_out),
        "mpd_deg": mean_phase_deviation(psi_out),
        "contribution": res.contribution[o],
        "significance": stat,
        "drive_point_phi2": u.drive_phi2[o],
        "std_pole": res.std_pole[o].real * inflate_fz[:, 1]
        + 1j * res.std_pole[o].imag * inflate_fz[:, 0],
        "local_dispersion": disp,
        "noise_along_response": along,
        "pole_variance_ratio": ratio,
        **intervals,
        "n_residual_modes": len(res.poles) - n_band,
        "warnings": list(res.warnings) + unresolved,
    }
    mdl = ModalModel(
        poles,
        psi_out,
        psi_in,
        mode_kind=ctx.kind,
        outputs=data.outputs,
        inputs=data.inputs,
        upper_residual=u.upper,
        lower_residual=u.lower,
        std=std,
        meta=meta,
        residual_modes=resid_modes,
        quality=quality,
    )
    return mdl, c * np.sqrt(np.mean(sq, axis=(0, 1)))
