"""The mode statistic with the neighbours' poles refitted (the final fit's last word).

The mode statistic ``T`` of a fit (:attr:`FitResult.significance
<tyredamp.modal.fit.fit.FitResult.significance>`) is the rise of the cost when the
mode is removed and the linear terms refitted, the *other poles held*. That is
the likelihood ratio of the nested models only when the other poles would not
move without the mode. Beside a much stronger mode they do: a second pole
half a half-width from a strong one shifts the strong one's estimate, and
removing the second with the strong pole held at the shifted value leaves the
strong mode's misfit in the residual, a rise many times the threshold (150
systems of the corpus of ``benchmarks/modal_statistics.py`` at 40 dB, seeds
200-799: ``T`` 129 held against 41 refitted, threshold 59; 3700 held against
350 refitted). The likelihood
ratio of Wilks' theorem, the test's own law, maximises both models (Seber & Wild 1989, *Nonlinear
Regression*, sec. 5.9.1).

:func:`refitted_statistics` therefore refits, for each mode that passes with
its poles held and has an overlapping stronger neighbour (damped frequencies
within twice the sum of the two half-power half-widths ``sigma_i + sigma_j``,
rad/s: where one resonance's pole can take up the other's response) or an
overlapping residual mode, the model without it (every pole free, from the
final fit's values), and takes ``T`` as the drop of the residual power when
the mode is added to that refitted model, in units of each output's noise (as
the search's trials, :func:`~tyredamp.modal.search.trials._trial`). Modes without
such a neighbour keep ``T`` (their neighbours' poles do not move), so a band
of separated modes costs no refit; a mode whose ``T`` stays above its
threshold with twice the Gauss-Newton decrement of the model without it taken
off (the predicted drop of refitting the others) is not refitted either, and a
refit stops after ``REFIT_NFEV`` evaluations (an upper bound of its ``T``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...exceptions import ConvergenceError
from ..fit._linalg import _gn_point
from ..fit.fit import FitResult, ModalFitter
from .joint import JOINT_NFEV, SEARCH_TOL
from .search import ModeSet

__all__ = ["OVERLAP", "REFIT_NFEV", "overlapping", "refit_candidates", "refitted_statistics"]

#: resonances overlap when their damped frequencies lie within this many times
#: the sum of their half-power half-widths (rad/s)
OVERLAP = 2.0
#: evaluations of a refit without a mode: the cost falls monotonically, so a
#: refit stopped there bounds the refitted statistic from above; a mode is dropped
#: only when that bound fails the test (the first Gauss-Newton steps take most
#: of what the neighbours can take up; dense bands of modes 1e4-1e9 times the
#: threshold took 10-30 evaluations per refit, none of which changed a verdict)
REFIT_NFEV = 4


def refit_candidates(
    res: FitResult, m: int, t: NDArray[np.float64], thr: NDArray[np.float64]
) -> NDArray[np.intp]:
    """The in-band modes (of the first ``m`` poles of ``res``) whose held-pole
    statistic ``t`` passes ``thr`` and whose resonance overlaps a stronger in-band
    mode's or a residual mode's (module docstring)."""
    near = overlapping(res.poles)
    stronger = np.any(near[:m, :m] & (t[None, :m] > t[:m, None]), axis=1)
    by_residual = np.any(near[:m, m:], axis=1)
    return np.flatnonzero((t[:m] > thr[:m]) & (stronger | by_residual)).astype(np.intp)


def overlapping(poles: NDArray[np.complex128]) -> NDArray[np.bool_]:
    """Which resonances overlap (n, n; the diagonal False): damped frequencies within
    ``OVERLAP`` times the sum of the two half-power half-widths (rad/s), where one
    pole can take up the other's response."""
    sig, wd = -poles.real, poles.imag
    near = np.abs(wd[:, None] - wd[None, :]) < OVERLAP * (sig[:, None] + sig[None, :])
    np.fill_diagonal(near, False)
    return np.asarray(near)


def refitted_statistics(
    fitter: ModalFitter,
    res: FitResult,
    cur: ModeSet,
    t: NDArray[np.float64],
    thr: NDArray[np.float64],
    sigma: NDArray[np.float64] | None,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``T`` of each in-band mode of ``cur`` (the final fit ``res``), refitted where a
    neighbour could take the mode up (:func:`refit_candidates`); otherwise ``t``.

    The refit without a mode stops after ``REFIT_NFEV`` evaluations: its
    statistic is then an upper bound of the refitted one (the cost only falls),
    which the mode fails or passes as it stands. Both models are fitted by
    ``fitter`` (the final fit's, or its fitter on
    re-weighted output combinations) with the weights ``1 / sigma``
    (``res.sigma_out`` when None), one pass, to the search's tolerance
    (``SEARCH_TOL``, 10 noise variances: the joint fits that decide the search's
    modes), the model with every mode and each model without one candidate from
    the final fit's values, so that their tolerances largely cancel in the
    difference. Returns the statistics and which of them were refitted. A refit
    that fails leaves the mode's ``t``.
    """
    out = np.array(t, dtype=float)
    done = np.zeros(out.size, bool)
    cand = refit_candidates(res, cur.m, out, thr)
    if cand.size == 0:
        return out, done
    p_all, l_all = cur.all()
    s = res.sigma_out if sigma is None else sigma
    kw: dict[str, object] = {
        "refine": True,
        "passes": 1,
        "sigma": s,
        "tol": SEARCH_TOL,
        "uncertainty": False,
        "max_nfev": JOINT_NFEV,
    }
    try:
        full = fitter.fit(p_all, l_all, **kw)  # type: ignore[arg-type]
    except (ConvergenceError, np.linalg.LinAlgError, ValueError):
        return out, done
    n_all = p_all.size
    dof1 = max(fitter.n_rows - fitter.n_cols(n_all), 1)
    dof0 = max(fitter.n_rows - fitter.n_cols(n_all - 1), 1)
    s2 = np.maximum(full.sigma_out**2, np.maximum(fitter.noise_floor**2, 1e-300))
    ss1 = full.sigma_out**2 * dof1  # residual power of each output (data units)
    s2_w = full.cost / max(full.n_obs - full.n_par, 1)  # weighted, per real row
    for i in cand:
        keep = np.arange(n_all) != i
        # screen: the Gauss-Newton decrement of the model without the mode at the
        # held values predicts what refitting its neighbours takes up; a mode that
        # passes with twice that taken off is kept without the refit
        dec = _decrement(fitter, p_all[keep], l_all[keep], s)
        if dec is not None and out[i] - 2.0 * dec / max(s2_w, 1e-300) > thr[i]:
            continue
        try:
            without = fitter.fit(
                p_all[keep],
                l_all[keep],
                **{**kw, "max_nfev": REFIT_NFEV},  # type: ignore[arg-type]
            )
        except (ConvergenceError, np.linalg.LinAlgError, ValueError):
            continue
        ss0 = without.sigma_out**2 * dof0
        out[i] = min(out[i], float(np.sum((ss0 - ss1) / s2)))
        done[i] = True
    return out, done


def _decrement(
    fitter: ModalFitter,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    sigma: NDArray[np.float64],
) -> float | None:
    """The Gauss-Newton decrement ``g^T A^-1 g`` of the weighted cost of the modes
    ``poles`` (the predicted drop of a full Gauss-Newton step, in the fit's cost
    units) at these values, with the weights :meth:`ModalFitter.fit` gives
    ``sigma``; one evaluation. None when it cannot be formed."""
    m = int(poles.size)
    part = np.asarray(part, complex).reshape(m, fitter.n_in)
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    w = fitter.weights(sigma)
    try:
        th = fitter.pack(np.asarray(poles, complex), part, ref)
        x, _, _, sol = fitter._refine(th, m, ref, w, 1)
    except (np.linalg.LinAlgError, ValueError):
        return None
    lb, ub = sol["lm"][:2]
    point = _gn_point(x, sol["jtj"], sol["jtr"], lb, ub)
    return 0.0 if point is None else float(point[4])
