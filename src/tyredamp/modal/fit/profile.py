"""Likelihood intervals of the natural frequencies and damping ratios.

The standard errors of :mod:`~tyredamp.modal.fit.fit` and :mod:`~tyredamp.modal.fit.ml`
are linearised (Gauss-Newton, ``s^2 (J^T J)^-1``): the interval ``theta^ +-
1.96 sd`` is exact when the model is linear in its parameters near the
optimum. A mode's FRF is not linear in its pole on the scale of its half-power
half-width ``sigma = -Re p``: when the pole's standard error is a noticeable
fraction of ``sigma`` (a weak mode, a mode beside a stronger one, few lines
across the resonance), the linearised interval of a 95 % level covers the
true value far less often. On a weak mode one half-width above a strong one
(four outputs), identified as a user would, with a mode statistic of about 60
/ 120 in noise units, the linearised intervals of f cover 77 / 92 % and of
zeta 83 / 92 %; the symmetric intervals that hold the likelihood intervals
below (the ``std`` reported) 93 / 97 % and 94 / 97 % (150 draws,
``benchmarks/modal_intervals.py``).

For those modes the interval is the profile-likelihood interval (Seber &
Wild, *Nonlinear Regression*, 1989, sec. 5.4; Pawitan, *In All Likelihood*,
2001, sec. 3.4): the values ``v`` of the natural frequency (or damping ratio)
whose profile cost ``P(v)`` -- the cost minimised over every other parameter
with that one held at ``v`` (residues by variable projection, the other
poles and participation by Levenberg-Marquardt from the optimum) -- rises
above the optimum by at most ``1.96^2 s^2``, ``s^2`` the noise scale of the
fit: the likelihood-ratio test of that value at 5 %. For a model linear in
its parameters it is the linearised interval exactly.

:func:`profile_mode` finds its ends on the signed root ``r(v) = sign(v - v^)
sqrt((P(v) - P(v^)) / s^2)``, linear in ``v`` for a linear model and close to
it otherwise: secant steps from the linearised end, each a profile fit
started from the nearest profile point, false position once the end is
bracketed, until ``|r - 1.96| <= R_TOL`` (the end within about 1 % of the
half-width). Pushed toward a neighbour that the data do not tell apart, the
profile can dip where the two modes trade places; the interval then holds
the neighbour's frequency (or, never reaching the cut, its end is *open*),
and the model says so (``meta["interval_method"]``).

The final stage (:func:`fit_intervals`) profiles each mode on its own lines
(within ``WINDOW`` half-widths, the fitted response of the modes and
residual terms beyond subtracted) and stretches each half of the whole fit's
linearised interval by the factor by which the local likelihood interval's
half exceeds the local linearised one: the cost does not grow with the band
or the mode count, and the whole fit's standard errors (weighted least
squares or maximum likelihood) stand in the linear limit.

Which modes: those whose pole's linearised standard error exceeds ``KAPPA``
times the half-width ``sigma`` (real or imaginary part). The curvature of the
resonance ``1 / (i w - p)`` in ``p`` has the scale ``sigma``; the ends of the
linearised interval of an isolated mode err by about 1.3-1.4 times that ratio
of the half-width (measured at 1.5 and 5 %: ``benchmarks/modal_intervals.py``), so below
``KAPPA`` the two intervals agree to about a per cent (0.3 points of
coverage) and profiles would only cost time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _basis
from ._linalg import _levenberg_marquardt
from .fit import FitResult, ModalFitter, pole_bounds

__all__ = [
    "KAPPA",
    "Intervals",
    "fit_intervals",
    "fitter_cost",
    "likelihood_intervals",
    "needs_profile",
    "profile_mode",
]

#: a mode is profiled when its pole's standard error (real or imaginary part)
#: exceeds this share of its half-power half-width ``-Re p`` (module docstring)
KAPPA = 0.01
#: two-sided 95 % point of the standard normal (the signed root's target)
Z95 = 1.959963984540054
#: an end is accepted when its signed root is within this of ``Z95``
R_TOL = 0.02
#: secant steps per end, and evaluations per profile fit
MAX_STEPS = 8
PROFILE_NFEV = 20
#: convergence of a profile fit, in units of ``s^2`` (the cut is ``Z95^2 s^2``)
PROFILE_TOL = 1e-3

Evaluate = Callable[[NDArray[np.float64]], tuple[float, Any, Any, Any]]


@dataclass(frozen=True)
class Intervals:
    """95 % intervals of the in-band modes (fit order).

    ``frequency_hz`` and ``damping_ratio``: (m, 2) lower and upper ends;
    ``likelihood``: (m,) True where the ends are the profile-likelihood
    interval's, False where they are the linearised ``+-1.96 sd`` (the pole's
    standard error below ``KAPPA`` half-widths, or a profile that failed);
    ``open``: where an end of the likelihood interval is open."""

    frequency_hz: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    likelihood: NDArray[np.bool_]
    #: (m,) an end of the likelihood interval is open (the profile stayed below the
    #: cut: the mode is not told from a neighbour at this level, :func:`_end`)
    open: NDArray[np.bool_]


def needs_profile(
    poles: NDArray[np.complex128], std_pole: NDArray[np.complex128]
) -> NDArray[np.bool_]:
    """Modes whose pole's standard error exceeds ``KAPPA`` half-power half-widths."""
    sig = np.maximum(-np.asarray(poles).real, 1e-300)
    sd = np.asarray(std_pole)
    worst = np.maximum(np.abs(sd.real), np.abs(sd.imag))
    return np.asarray(np.isfinite(worst) & (worst > KAPPA * sig))


class _Mode:
    """The pole of mode ``k`` in the coordinates ``u = (|p| / w_ref, zeta)`` in place
    of the fitter's ``x = (log(sigma / w_ref), Omega / w_ref)`` (theta entries
    ``2k, 2k + 1``)."""

    def __init__(self, k: int) -> None:
        self.i = 2 * k

    def to_u(self, th: NDArray[np.float64]) -> NDArray[np.float64]:
        y = th.copy()
        s, om = np.exp(th[self.i]), th[self.i + 1]
        mag = float(np.hypot(s, om))
        y[self.i], y[self.i + 1] = mag, s / mag
        return y

    def to_x(self, y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """theta of ``y`` and the Jacobian block ``dx / du`` (2, 2)."""
        u1, u2 = float(y[self.i]), float(y[self.i + 1])
        c = np.sqrt(max(1.0 - u2 * u2, 1e-300))
        th = y.copy()
        th[self.i], th[self.i + 1] = np.log(u1 * u2), u1 * c
        jac = np.array([[1.0 / u1, 1.0 / u2], [c, -u1 * u2 / c]])
        return th, jac


def _profile_cost(
    evaluate: Evaluate,
    mode: _Mode,
    j: int,
    value: float,
    y0: NDArray[np.float64],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
    dof: int,
) -> tuple[float, NDArray[np.float64]] | None:
    """The profile cost with ``u[j]`` held at ``value`` (``j`` an index into ``y``),
    every other coordinate refined from ``y0``; and the point (None: failed).
    ``dof``: the cost's degrees of freedom, so that ``cost / dof`` is the scale
    ``s^2`` of the convergence test (``PROFILE_TOL``)."""
    lb, ub = bounds
    free = np.flatnonzero(np.arange(y0.size) != j)
    i = mode.i

    def ev(z: NDArray[np.float64]) -> tuple[float, Any, Any, Any]:
        y = y0.copy()
        y[free] = z
        y[j] = value
        th, jac = mode.to_x(y)
        cost, a, g, _ = evaluate(th)
        a = np.array(a, dtype=float)
        g = np.array(g, dtype=float)
        # chain rule on the block of the mode: A_u = T^T A T, g_u = T^T g
        a[:, i : i + 2] = a[:, i : i + 2] @ jac
        a[i : i + 2, :] = jac.T @ a[i : i + 2, :]
        g[i : i + 2] = jac.T @ g[i : i + 2]
        return cost, a[np.ix_(free, free)], g[free], (cost, y)

    z0 = np.clip(y0[free], lb[free] + 1e-12, ub[free] - 1e-12)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        try:
            _, _, _, (cost, y) = _levenberg_marquardt(
                ev, z0, lb[free], ub[free], PROFILE_NFEV, dof=dof, tol=PROFILE_TOL
            )
        except (np.linalg.LinAlgError, ValueError, FloatingPointError):
            return None
    if not np.isfinite(cost):
        return None
    return cost, y


def _end(
    evaluate: Evaluate,
    mode: _Mode,
    j: int,
    y_hat: NDArray[np.float64],
    sd: float,
    side: float,
    ctx: tuple[float, float, int, tuple[NDArray[np.float64], NDArray[np.float64]]],
) -> tuple[float, bool] | None:
    """One end of the likelihood interval of ``u[j]`` (``side`` +1 upper, -1 lower)
    and whether it is open; None when a profile fit failed.

    Secant steps on the signed root from the linearised end, false position once
    the end is bracketed (module docstring); in the distance ``t = side (v -
    v^)`` the root ``r(t)`` rises from 0. After ``MAX_STEPS`` profile fits a
    bracketed end is the false-position point of its bracket; an end never
    bracketed is *open*: the profile stayed below the cut (it can turn down
    where the mode takes a neighbour's place: the data do not tell the two
    apart at this level), and the farthest point below the cut is returned."""
    cost0, s2, dof, bounds = ctx
    lb, ub = bounds
    v_hat = float(y_hat[j])
    t_max = (ub[j] - v_hat) if side > 0 else (v_hat - lb[j])
    lo_pt, hi_pt = (0.0, 0.0), None  # (t, r) below and above the target
    last = (0.0, 0.0)
    y_near = y_hat
    t1 = Z95 * sd
    for _ in range(MAX_STEPS):
        t1 = float(min(t1, t_max))
        got = _profile_cost(evaluate, mode, j, v_hat + side * t1, y_near, bounds, dof)
        if got is None:
            return None
        cost, y_near = got
        r1 = float(np.sqrt(max(cost - cost0, 0.0) / s2))
        if abs(r1 - Z95) <= R_TOL:
            return v_hat + side * t1, False
        if r1 < Z95:
            if t1 >= t_max:
                return v_hat + side * t1, True  # not bounded within the parameter's range
            lo_pt = max(lo_pt, (t1, r1))
        elif hi_pt is None or t1 < hi_pt[0]:
            hi_pt = (t1, r1)
        if hi_pt is not None:  # bracketed: false position
            (ta, ra), (tb, rb) = lo_pt, hi_pt
            t2 = ta + (tb - ta) * (Z95 - ra) / max(rb - ra, 1e-12)
        else:
            t0, r0 = last
            slope = (r1 - r0) / (t1 - t0) if t1 != t0 else 0.0
            t2 = t1 + (Z95 - r1) / slope if slope > 0 else 2.0 * t1
            t2 = min(t2, 4.0 * t1)  # at most four times as far
        last = (t1, r1)
        t1 = t2
    if hi_pt is not None:
        return v_hat + side * t1, False
    return v_hat + side * lo_pt[0], True


def profile_mode(
    evaluate: Evaluate,
    theta: NDArray[np.float64],
    k: int,
    sd: tuple[float, float],
    w_ref: float,
    scale: tuple[float, float],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> tuple[float, float, float, float, bool] | None:
    """The 95 % likelihood interval of mode ``k``'s natural frequency (Hz) and damping
    ratio: ``(f_lo, f_hi, zeta_lo, zeta_hi, open)`` (``open``: an end where the
    profile never reached the cut, :func:`_end`), None when a profile failed.

    ``evaluate(theta) -> (cost, J^T J, J^T r, by-product)`` is the fit's cost
    (:meth:`~tyredamp.modal.fit.fit.ModalFitter._solve` with its normal equations),
    ``theta`` its optimum (poles first, :meth:`ModalFitter.pack` layout), ``sd``
    the linearised standard errors of f (Hz) and zeta (the first steps),
    ``w_ref`` the fitter's reference frequency (rad/s), ``scale`` the cost at
    ``theta`` and the scale ``s^2`` of the linearised covariance ``s^2 (J^T
    J)^-1``, ``bounds`` those of ``theta`` (the refinement's)."""
    cost0, s2 = scale
    if not (np.isfinite(cost0) and np.isfinite(s2) and s2 > 0):
        return None
    dof = max(round(cost0 / s2), 1)
    mode = _Mode(int(k))
    y_hat = mode.to_u(theta)
    lb_u, ub_u = bounds[0].copy(), bounds[1].copy()
    i = mode.i
    lb_u[i], ub_u[i] = 1e-6, 30.0  # |p| / w_ref (Omega / w_ref <= 20)
    lb_u[i + 1], ub_u[i + 1] = 1e-9, 0.999  # zeta
    ctx = (cost0, s2, dof, (lb_u, ub_u))
    ends: list[float] = []
    is_open = False
    for j, sd_j in ((i, sd[0] * 2 * np.pi / w_ref), (i + 1, sd[1])):
        for side in (-1.0, 1.0):
            e = _end(evaluate, mode, j, y_hat, float(sd_j), side, ctx)
            if e is None:
                return None
            ends.append(e[0])
            is_open |= e[1]
    c = w_ref / (2 * np.pi)
    return ends[0] * c, ends[1] * c, ends[2], ends[3], is_open


def likelihood_intervals(
    evaluate: Evaluate,
    theta: NDArray[np.float64],
    poles: NDArray[np.complex128],
    std: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128]],
    n_band: int,
    w_ref: float,
    scale: tuple[float, float],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> Intervals:
    """95 % intervals of the first ``n_band`` modes of one fit (its cost ``evaluate``
    and optimum ``theta``, arguments as :func:`profile_mode`; ``std`` the linearised
    standard errors of f, zeta and the poles): the likelihood interval of the
    modes that :func:`needs_profile` names, the linearised one elsewhere."""
    std_f, std_z, std_pole = std
    fi, zi = _linearised(poles[:n_band], std_f[:n_band], std_z[:n_band])
    lik = np.zeros(n_band, bool)
    opn = np.zeros(n_band, bool)
    for k in np.flatnonzero(needs_profile(poles[:n_band], std_pole[:n_band])):
        got = profile_mode(evaluate, theta, int(k), (std_f[k], std_z[k]), w_ref, scale, bounds)
        if got is not None:
            fi[k], zi[k], lik[k], opn[k] = got[:2], got[2:4], True, got[4]
    return Intervals(fi, zi, lik, opn)


def _linearised(
    poles: NDArray[np.complex128], std_f: NDArray[np.float64], std_z: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The linearised 95 % intervals ``+-1.96 sd`` of f (Hz) and zeta, (m, 2) each."""
    f_hat = np.abs(poles) / (2 * np.pi)
    z_hat = -poles.real / np.maximum(np.abs(poles), 1e-300)
    fi = np.stack([f_hat - Z95 * std_f, f_hat + Z95 * std_f], axis=1)
    zi = np.stack([z_hat - Z95 * std_z, z_hat + Z95 * std_z], axis=1)
    return fi, zi


def fitter_cost(
    fitter: ModalFitter, m: int, ref: NDArray[np.intp], w: NDArray[np.float64]
) -> Evaluate:
    """The weighted least-squares cost of ``fitter`` for ``m`` modes (reference inputs
    ``ref``, output weights ``w``) as :func:`profile_mode` evaluates it."""

    def evaluate(x: NDArray[np.float64]) -> tuple[float, Any, Any, Any]:
        sol = fitter._solve(x, m, ref, w, residual=False)
        jtj, jtr = fitter._normal(sol, x.size)
        return float(sol["cost"]), jtj, jtr, sol

    return evaluate


def fit_intervals(
    cfit: ModalFitter,
    res: FitResult,
    n_band: int,
    sigma0: NDArray[np.float64] | None,
) -> Intervals | None:
    """The 95 % intervals of the in-band modes of a final fit ``res`` of ``cfit``
    (complex or real modes; weighted least squares with the noise ``sigma0`` per
    output, or its maximum-likelihood refinement); None without a model or
    standard errors.

    The intervals are the linearised ones, ``+-1.96 sd``, with each half of a
    mode that :func:`needs_profile` names stretched by the factor by which the
    likelihood interval's half exceeds the linearised one *on the mode's own
    lines*: the lines within ``WINDOW`` half-power half-widths of it, with the
    fitted response of the modes and residual terms beyond them subtracted (the
    model of the data there: the modes near it, free, and residual terms), fitted
    by weighted least squares with ``sigma0``, and profiled with the noise scale
    of the whole fit. The information on a mode's pole lies in its own lines
    (92 % of its resonance's energy within 8 half-widths) and its correlation
    with modes beyond them is small, so the local profile has the shape of the
    whole one at a cost independent of the band's size and mode count; the
    factor carries its non-linearity onto the whole fit's standard errors
    (WLS or ML), which stand in the linear limit. A local fit that does not
    come back to the mode (its optimum outside the mode's linearised interval)
    or a profile that fails leaves the linearised interval."""
    m_all = int(res.poles.size)
    std_f, std_z = np.asarray(res.std_frequency_hz), np.asarray(res.std_damping_ratio)
    if n_band == 0 or sigma0 is None or res.model.size == 0 or std_f.size < n_band:
        return None
    fi, zi = _linearised(res.poles[:n_band], std_f[:n_band], std_z[:n_band])
    lik = np.zeros(n_band, bool)
    opn = np.zeros(n_band, bool)
    todo = np.flatnonzero(needs_profile(res.poles[:n_band], res.std_pole[:n_band]))
    if not todo.size:
        return Intervals(fi, zi, lik, opn)
    w = cfit.weights(sigma0)
    lw = cfit.line_weights
    r = (cfit.H - res.model) * w[:, None, None]
    if lw is not None:
        r = r * lw
    s2 = float(np.vdot(r, r).real) / max(res.n_obs - res.n_par, 1)
    residues = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    fn = np.abs(res.poles) / (2 * np.pi)
    hw = -res.poles.real / (2 * np.pi)  # half-power half-widths (Hz)
    f = cfit.f
    df = float(np.min(np.diff(f))) if f.size > 1 else 1.0
    inb = np.arange(m_all) < n_band
    for k in todo:
        half = max(WINDOW * hw[k], MIN_LINES * df)
        i0, i1 = int(np.searchsorted(f, fn[k] - half)), int(np.searchsorted(f, fn[k] + half))
        near = inb & (np.abs(fn - fn[k]) <= half + 2 * hw)
        if i1 - i0 < 2 * MIN_LINES or not near[k]:
            continue
        far = ~near
        lines = slice(i0, i1)
        h_loc = _basis.residual_lines(
            cfit, res.poles[far], residues[:, :, far], (res.upper, res.lower), lines
        )
        if lw is not None:
            h_loc = h_loc / lw[lines]
        got = _local_factors(cfit, f[lines], h_loc, lw, lines, res, near, int(k), sigma0, s2)
        if got is None:
            continue
        (a_flo, a_fhi, a_zlo, a_zhi), opn[k] = got
        f_hat, z_hat = fn[k], -res.poles[k].real / abs(res.poles[k])
        fi[k] = [f_hat - a_flo * Z95 * std_f[k], f_hat + a_fhi * Z95 * std_f[k]]
        zi[k] = [z_hat - a_zlo * Z95 * std_z[k], z_hat + a_zhi * Z95 * std_z[k]]
        lik[k] = True
    return Intervals(fi, zi, lik, opn)


#: a mode's own lines: within this many half-power half-widths of it (92 % of its
#: resonance's energy), and at least MIN_LINES lines either side
WINDOW = 8.0
MIN_LINES = 5


def _local_factors(
    cfit: ModalFitter,
    f: NDArray[np.float64],
    h_loc: NDArray[np.complex128],
    lw: NDArray[np.float64] | None,
    lines: slice,
    res: FitResult,
    near: NDArray[np.bool_],
    k: int,
    sigma0: NDArray[np.float64],
    s2: float,
) -> tuple[tuple[float, float, float, float], bool] | None:
    """The factors by which the halves of mode ``k``'s likelihood interval (f low, f
    high, zeta low, zeta high) exceed the linearised ones on its own lines
    (:func:`fit_intervals`) and whether an end is open, or None."""
    loc = ModalFitter(
        f,
        h_loc,
        cfit.power,
        cfit.kind,
        [],
        upper=cfit.use_upper,
        lower=cfit.use_lower,
        line_weights=None if lw is None else lw[lines],
    )
    idx = np.flatnonzero(near)
    kk = int(np.flatnonzero(idx == k)[0])
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            r = loc.fit(
                res.poles[idx], res.participation[idx], passes=1, sigma=sigma0, tol=PROFILE_TOL
            )
    except (np.linalg.LinAlgError, ValueError):
        return None
    m = idx.size
    f_k = abs(r.poles[kk]) / (2 * np.pi)
    z_k = -r.poles[kk].real / abs(r.poles[kk])
    f0 = abs(res.poles[k]) / (2 * np.pi)
    z0 = -res.poles[k].real / abs(res.poles[k])
    sd_f, sd_z = float(res.std_frequency_hz[k]), float(res.std_damping_ratio[k])
    if not (abs(f_k - f0) <= Z95 * sd_f and abs(z_k - z0) <= Z95 * sd_z):
        return None  # the local fit did not come back to the mode
    # the local linearised standard errors at the whole fit's noise scale
    c = np.sqrt(s2 / max(r.cost / max(r.n_obs - r.n_par, 1), 1e-300))
    lf, lz = float(r.std_frequency_hz[kk]) * c, float(r.std_damping_ratio[kk]) * c
    if not (lf > 0 and lz > 0 and np.isfinite(lf) and np.isfinite(lz)):
        return None
    ref = np.argmax(np.abs(r.participation), axis=1).astype(np.intp)
    th = loc.pack(r.poles, r.participation, ref)
    ev = fitter_cost(loc, m, ref, loc.weights(sigma0))
    got = profile_mode(ev, th, kk, (lf, lz), loc.w_ref, (r.cost, s2), pole_bounds(m, th.size))
    if got is None:
        return None
    flo, fhi, zlo, zhi, is_open = got
    factors = (
        (f_k - flo) / (Z95 * lf),
        (fhi - f_k) / (Z95 * lf),
        (z_k - zlo) / (Z95 * lz),
        (zhi - z_k) / (Z95 * lz),
    )
    return factors, is_open
