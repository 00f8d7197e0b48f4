"""Likelihood intervals of the natural frequencies and damping ratios.

The standard errors of :mod:`~tyredamp.modal.fit` and :mod:`~tyredamp.modal.ml`
are linearised (Gauss-Newton, ``s^2 (J^T J)^-1``): the interval ``theta^ +-
1.96 sd`` is exact when the model is linear in its parameters near the
optimum. A mode's FRF is not linear in its pole on the scale of its half-power
half-width ``sigma = -Re p``: when the pole's standard error is a noticeable
fraction of ``sigma`` (a weak mode, a mode beside a stronger one, few lines
across the resonance), the linearised interval of a 95 % level covers its
true value far less often (on a weak mode one half-width from a strong one,
at a mode statistic of 46 / 68 / 129 in noise units: 71 / 85 / 92 %, 300
draws; the likelihood interval below 87 / 91 / 95 %).

For those modes the interval is the profile-likelihood interval (e.g. Seber
& Wild, *Nonlinear Regression*, 1989, sec. 5.4; Pawitan, *In All
Likelihood*, 2001, sec. 3.4): the set of values ``v`` of the natural
frequency (or damping ratio) whose profile cost ``P(v)`` -- the fit's
cost minimised over every other parameter with that one held at ``v``
(residues by variable projection, the other poles and participation by
Levenberg-Marquardt from the optimum) -- rises above the optimum by at most
``1.96^2 s^2``, with ``s^2`` the scale of the fit's covariance (the residual
variance of a weighted least-squares fit, the Fisher scale of a
maximum-likelihood one): the likelihood-ratio test of that value at 5 %.
For a model linear in its parameters it is the linearised interval exactly.

Its ends are found on the signed root ``r(v) = sign(v - v^) sqrt((P(v) -
P(v^)) / s^2)``, which is linear in ``v`` for a linear model and close to it
otherwise: secant steps from the linearised end, each a profile fit started
from the nearest profile point, until ``|r - 1.96| <= R_TOL`` (the end within
about 1 % of the interval's half-width).

Which modes: those whose pole's linearised standard error exceeds ``KAPPA``
times the half-power half-width ``sigma`` (real or imaginary part). The
curvature of the resonance ``1 / (i w - p)`` in ``p`` has the scale
``sigma``; the end of a linearised interval then errs by a share of the
order of ``1.96 sd / sigma`` of its half-width (measured:
``benchmarks/modal_intervals.py``), so below ``KAPPA`` the two intervals
agree to about a per cent and the profile fits would only cost time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._linalg import _levenberg_marquardt
from .fit import FitResult, ModalFitter
from .ml import _evaluate as ml_evaluate
from .ml import fisher_scale, line_weights_full
from .problem import FitProblem

__all__ = ["KAPPA", "Intervals", "fit_intervals", "likelihood_intervals", "needs_profile"]

#: a mode is profiled when its pole's standard error (real or imaginary part)
#: exceeds this share of its half-power half-width ``-Re p`` (module docstring)
KAPPA = 0.01
#: two-sided 95 % point of the standard normal (the signed root's target)
Z95 = 1.959963984540054
#: an end is accepted when its signed root is within this of ``Z95``
R_TOL = 0.02
#: secant steps per end, and evaluations per profile fit
MAX_STEPS = 6
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
    standard error below ``KAPPA`` half-widths, or a profile that failed)."""

    frequency_hz: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    likelihood: NDArray[np.bool_]


def needs_profile(poles: NDArray[np.complex128], std_pole: NDArray[np.complex128]) -> Any:
    """Modes whose pole's standard error exceeds ``KAPPA`` half-power half-widths."""
    sig = np.maximum(-np.asarray(poles).real, 1e-300)
    sd = np.asarray(std_pole)
    worst = np.maximum(np.abs(sd.real), np.abs(sd.imag))
    return np.isfinite(worst) & (worst > KAPPA * sig)


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
        return cost, a[np.ix_(free, free)], g[free], y

    z0 = np.clip(y0[free], lb[free] + 1e-12, ub[free] - 1e-12)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        try:
            _, _, _, y = _levenberg_marquardt(
                ev, z0, lb[free], ub[free], PROFILE_NFEV, dof=dof, tol=PROFILE_TOL
            )
            cost = float(evaluate(mode.to_x(y)[0])[0])
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
) -> float | None:
    """One end of the likelihood interval of ``u[j]`` (``side`` +1 upper, -1 lower):
    secant steps on the signed root from the linearised end, false position once
    the end is bracketed (module docstring). In the distance ``t = side (v - v^)``
    the root ``r(t)`` rises from 0."""
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
            return v_hat + side * t1
        if r1 < Z95:
            if t1 >= t_max:
                return v_hat + side * t1  # the data do not bound it within its range
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
    return None


def likelihood_intervals(
    evaluate: Evaluate,
    theta: NDArray[np.float64],
    poles: NDArray[np.complex128],
    std_f: NDArray[np.float64],
    std_z: NDArray[np.float64],
    std_pole: NDArray[np.complex128],
    n_band: int,
    w_ref: float,
    scale: tuple[float, float],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> Intervals:
    """95 % intervals of the natural frequency (Hz) and damping ratio of the first
    ``n_band`` modes (module docstring).

    Parameters
    ----------
    evaluate : callable
        ``evaluate(theta) -> (cost, J^T J, J^T r, by-product)`` of the fit
        (:meth:`~tyredamp.modal.fit.ModalFitter._solve` with its normal
        equations, or the maximum-likelihood cost of :mod:`~tyredamp.modal.ml`).
    theta : ndarray, shape (n_par,)
        The fit's optimum (poles first, :meth:`ModalFitter.pack` layout).
    poles, std_f, std_z, std_pole : ndarray
        Poles (rad/s) and the linearised standard errors (f in Hz, zeta, pole).
    n_band : int
        In-band modes (the first ``n_band``; the rest are residual modes).
    w_ref : float
        The fitter's reference frequency (rad/s) of the pole coordinates.
    scale : (float, float)
        The cost at ``theta`` and the scale ``s^2`` of the linearised covariance
        ``s^2 (J^T J)^-1`` (residual variance or Fisher scale).
    bounds : (ndarray, ndarray)
        Lower and upper bounds of ``theta`` (the refinement's).
    """
    cost0, s2 = scale
    f_hat = np.abs(poles[:n_band]) / (2 * np.pi)
    z_hat = -poles[:n_band].real / np.maximum(np.abs(poles[:n_band]), 1e-300)
    fi = np.stack([f_hat - Z95 * std_f[:n_band], f_hat + Z95 * std_f[:n_band]], axis=1)
    zi = np.stack([z_hat - Z95 * std_z[:n_band], z_hat + Z95 * std_z[:n_band]], axis=1)
    lik = np.zeros(n_band, bool)
    if not (np.isfinite(cost0) and np.isfinite(s2) and s2 > 0):
        return Intervals(fi, zi, lik)
    dof = max(round(cost0 / s2), 1)
    todo = np.flatnonzero(needs_profile(poles[:n_band], std_pole[:n_band]))
    for k in todo:
        mode = _Mode(int(k))
        y_hat = mode.to_u(theta)
        lb_u, ub_u = bounds[0].copy(), bounds[1].copy()
        i = mode.i
        lb_u[i], ub_u[i] = 1e-6, 20.0 * 1.5  # |p| / w_ref (Omega / w_ref <= 20)
        lb_u[i + 1], ub_u[i + 1] = 1e-9, 0.999  # zeta
        ctx = (cost0, s2, dof, (lb_u, ub_u))
        sd_u = (std_f[k] * 2 * np.pi / w_ref, std_z[k])
        ends: list[float] = []
        for j, sd in ((i, sd_u[0]), (i + 1, sd_u[1])):
            for side in (-1.0, 1.0):
                e = _end(evaluate, mode, j, y_hat, float(sd), side, ctx)
                if e is None:
                    break
                ends.append(e)
            if len(ends) % 2:
                break
        if len(ends) != 4:
            continue  # a profile failed: the linearised interval stands
        fi[k] = np.array(ends[:2]) * w_ref / (2 * np.pi)
        zi[k] = ends[2:]
        lik[k] = True
    return Intervals(fi, zi, lik)


def fit_intervals(
    problem: FitProblem,
    cfit: ModalFitter,
    res: FitResult,
    n_band: int,
    sigma0: NDArray[np.float64] | None,
) -> Intervals | None:
    """The intervals of a final complex fit ``res`` of ``cfit`` (weighted least
    squares with the noise ``sigma0`` per output, or its maximum-likelihood
    refinement, :func:`~tyredamp.modal.final.maximum_likelihood`), or None when
    the fit's own cost cannot be evaluated again at its optimum (a fit on
    output combinations, a fit without refinement): the linearised intervals
    then stand."""
    m_all = int(res.poles.size)
    th = np.asarray(res.theta, dtype=np.float64)
    if n_band == 0 or sigma0 is None or th.size < 2 * m_all or res.std_frequency_hz.size < n_band:
        return None
    part = np.asarray(res.participation, complex)
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    n_par = th.size
    evaluate: Evaluate
    if res.status.startswith("maximum likelihood"):
        if problem.variance is None:
            return None
        om = line_weights_full(problem.variance)
        if om is None:
            return None
        plain = ModalFitter(
            problem.frequency,
            problem.H,
            problem.power,
            cfit.kind,
            problem.drive,
            upper=cfit.use_upper,
            lower=cfit.use_lower,
        )

        def evaluate(x: NDArray[np.float64]) -> tuple[float, Any, Any, Any]:
            return ml_evaluate(plain, x, m_all, ref, om)

        q = plain.n_cols(m_all)
        dof = max(plain.n_rows * plain.n_out - q * plain.n_out - n_par, 1)
        cost0 = float(evaluate(th)[0])
        s2 = fisher_scale(problem.noise_dof, cost0, dof)
    else:
        w = cfit.weights(sigma0)

        def evaluate(x: NDArray[np.float64]) -> tuple[float, Any, Any, Any]:
            sol = cfit._solve(x, m_all, ref, w, residual=False)
            jtj, jtr = cfit._normal(sol, n_par)
            return float(sol["cost"]), jtj, jtr, sol

        cost0 = float(evaluate(th)[0])
        s2 = cost0 / max(res.n_obs - res.n_par, 1)
    if not abs(cost0 - res.cost) <= 1e-6 * max(abs(res.cost), 1e-300):
        return None  # not the fit's own cost at its optimum
    lb = np.full(n_par, -np.inf)
    ub = np.full(n_par, np.inf)
    # the refinement's bounds (ModalFitter._refine): sigma in [1e-7, 5] w_ref, Omega in (0, 20]
    lb[0 : 2 * m_all : 2], ub[0 : 2 * m_all : 2] = np.log(1e-7), np.log(5.0)
    lb[1 : 2 * m_all : 2], ub[1 : 2 * m_all : 2] = 1e-6, 20.0
    return likelihood_intervals(
        evaluate,
        th,
        res.poles,
        res.std_frequency_hz,
        res.std_damping_ratio,
        res.std_pole,
        n_band,
        cfit.w_ref,
        (cost0, s2),
        (lb, ub),
    )
