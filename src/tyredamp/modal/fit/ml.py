"""Maximum-likelihood refinement with the full per-line noise model.

The fits of :mod:`~tyredamp.modal.fit.fit` share one basis over the outputs, so
they can weight a known per-line variance ``V_jkf`` (output ``j``, input
``k``, line ``f``) only through its separable approximation ``sigma_j^2 g_f``
(:mod:`~tyredamp.modal.problem.problem`). When the variance is known, the final stage
(:func:`ml_refine`) starts from that weighted least-squares (WLS) fit and
minimises the Gaussian negative log-likelihood (times two) of the data with
the variance of every entry::

    L(theta, C) = sum_jkf |H_jkf - H^model_jkf(theta, C_j)|^2 / (V_jkf / 2)

(real and imaginary part each of variance ``V / 2``; Pintelon & Schoukens,
*System Identification*, 2nd ed. 2012, sec. 7.2 and 9.2, the frequency-domain
maximum-likelihood cost with a known noise model). The linear coefficients
``C_j`` of each output are eliminated with that output's weights (variable
projection, Golub & Pereyra 1973): for each output the weighted basis ``W_j
Phi`` is orthonormalised (``Q_j R_j``), the residual is ``r_j = (I - Q_j
Q_j^T) W_j y_j`` and Kaufman's Jacobian ``J_j = -(I - Q_j Q_j^T) W_j (dPhi /
dtheta) C_j``; Gauss-Newton/Levenberg-Marquardt steps on ``sum_j J_j^T J_j``
and ``sum_j J_j^T r_j`` (:func:`~tyredamp.modal.fit._linalg._levenberg_marquardt`).
The cost per evaluation is ``n_out`` QR factorisations of the ``(2 n_in
n_freq) x q`` basis: a few evaluations from the WLS start.

Standard errors from the Fisher information. ``J^T J`` above is the Fisher
information of the non-linear parameters with the linear ones profiled out
(the Schur complement of the full information; the variance is known, so it
is not scaled by the residual variance). When the variance is an estimate
with ``nu`` real degrees of freedom (:attr:`FitProblem.noise_dof`), the
weights ``1 / V^`` are noisy: with ``V^ / V ~ chi2_nu / nu`` independent of
the data, ``E[1 / V^] = nu / ((nu - 2) V)`` and ``E[1 / V^2] = nu^2 / ((nu
- 2)(nu - 4) V^2)``, so the covariance of the weighted estimate is ``(nu -
2) / (nu - 4)`` times the inverse information of the true weights while the
information computed with ``V^`` is ``nu / (nu - 2)`` times too large
(sums over many lines, where the law of large numbers holds): the inverse
information is multiplied by ``nu / (nu - 4)``. With ``nu <= 4`` (no finite
second moment) it is scaled by the residual variance ``cost / dof`` instead.
The standard errors of the mode shapes, the contributions and the mode
statistics ``T`` are kept from the WLS fit (the delta method of
:mod:`~tyredamp.modal.fit._scaling` and the extra sum of squares on the shared
basis).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import solve_triangular

from . import _basis
from ._linalg import _gram_chol, _levenberg_marquardt
from ._results import coefficient_parts, drive_phi2
from ._scaling import pole_std
from .fit import FitResult, ModalFitter, pole_bounds

__all__ = ["fisher_scale", "line_weights_full", "ml_refine"]


def line_weights_full(variance: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Row weights ``1 / sqrt(V / 2)`` of the fitter's real rows, shape (2 n_in n_f, n_out).

    Rows follow :class:`ModalFitter`'s layout (input, line; real and imaginary
    part interleaved). Entries without variance (exact lines) get the weight
    of the output's least noisy line. None when every variance is zero.
    """
    n_out, n_in, n_f = variance.shape
    v = np.array(variance, dtype=float).reshape(n_out, n_in * n_f)
    pos = v > 0
    if not np.any(pos):
        return None
    vmin = np.min(v[pos])
    floor = np.array([np.min(r[p]) if np.any(p) else vmin for r, p in zip(v, pos, strict=True)])
    v = np.where(pos, v, floor[:, None])
    return np.repeat(1.0 / np.sqrt(v / 2.0), 2, axis=1).T.copy()


def fisher_scale(noise_dof: float | None, cost: float, dof: int) -> float:
    """Factor of the inverse Fisher information (module docstring): 1 for a known
    variance, ``nu / (nu - 4)`` for one estimated with ``nu > 4`` degrees of
    freedom, ``cost / dof`` otherwise."""
    if noise_dof is None or not np.isfinite(noise_dof):
        return 1.0
    nu = float(noise_dof)
    if nu > 4.0:
        return nu / (nu - 4.0)
    return max(cost / max(dof, 1), 1e-300)


def _evaluate(
    fitter: ModalFitter,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    om: NDArray[np.float64],
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
    """Cost, ``J^T J``, ``J^T r`` and the coefficients ``C`` (q, n_out) at ``th``.

    With ``M_j = W_j (dPhi / dtheta) C_j = W_j E S_j^T`` (``E`` the distinct
    derivative columns, :meth:`ModalFitter.basis`, and ``S_j`` (n_par, n_e) one
    entry ``coef_d C_j[dcol_d]`` per derivative column) and ``Q_j^T r_j = 0``:
    ``J_j^T J_j = M_j^T M_j - (Q_j^T M_j)^T Q_j^T M_j = S_j (E^T W_j P_j W_j E)
    S_j^T`` and ``J_j^T r_j = -S_j E^T W_j r_j`` (``P_j`` the projector on the
    complement of the range of ``W_j Phi``). ``E^T W_j P_j W_j E`` is the Schur
    complement ``G_EE - X^T X``, ``X = R_j^-T G_PhiE``, of the Gram matrix ``G``
    of ``W_j [Phi | E]`` (one symmetric rank-k update per output; Golub & Van
    Loan, *Matrix Computations*, 4th ed. 2013, sec. 5.3.2, the normal
    equations); the residual ``r_j`` is formed explicitly (no cancellation in
    the cost). An output whose weighted basis is too ill-conditioned for the
    Gram route takes the Householder QR (:func:`_evaluate_qr`).
    """
    B, poles = fitter._basis_ek(th, m, ref, True)
    q = fitter.n_cols(m)
    lay = fitter._layout(m)
    coef = fitter._coef(lay, poles)
    n_par = th.size
    n_e = B.shape[1] - q
    jtj = np.zeros((n_par, n_par))
    jtr = np.zeros(n_par)
    C = np.zeros((q, fitter.n_out))
    cost = 0.0
    Y = fitter.Y
    bw = np.empty_like(B, order="F")
    for j in range(fitter.n_out):
        wj = om[:, j]
        np.multiply(B, wj[:, None], out=bw)
        yw = Y[:, j] * wj
        G = bw.T @ bw  # Gram matrix of W_j [Phi | E] (symmetric rank-k update)
        fac = _gram_chol(G[:q, :q])
        if fac is None:
            c_j, ge, etr, r = _evaluate_qr(bw, yw, q)
        else:
            rs, d = fac
            R = rs * d[None, :]
            c_j = solve_triangular(R, solve_triangular(R, bw[:, :q].T @ yw, trans="T"))
            r = yw - bw[:, :q] @ c_j  # the residual itself: no cancellation in the cost
            X = solve_triangular(R, G[:q, q:], trans="T")
            ge = G[q:, q:] - X.T @ X  # E^T W P W E
            etr = bw[:, q:].T @ r
        C[:, j] = c_j
        cost += float(r @ r)
        S = np.zeros((n_par, n_e))
        np.add.at(S, (lay.dpar, lay.ecol), coef * c_j[lay.dcol])
        jtj += S @ ge @ S.T
        jtr -= S @ etr
    phi = B[:, :q]
    return cost, 0.5 * (jtj + jtj.T), jtr, {"C": C, "phi": phi, "jtj": jtj}


def _evaluate_qr(
    bw: NDArray[np.float64], yw: NDArray[np.float64], q: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Coefficients, ``E^T W P W E``, ``E^T W r`` and the residual ``r`` of one output
    from the Householder QR of its weighted basis ``bw[:, :q]`` (Golub & Van Loan,
    sec. 5.3.3): the route of :func:`_evaluate` for an ill-conditioned basis."""
    c_j, qmap = _projection(bw[:, :q], yw)
    r = yw - bw[:, :q] @ c_j
    ew = bw[:, q:]
    qe = qmap(ew)
    ge = ew.T @ ew - qe.T @ qe
    return c_j, ge, ew.T @ r, r


def _projection(
    pw: NDArray[np.float64], yw: NDArray[np.float64]
) -> tuple[NDArray[np.float64], Any]:
    """Least-squares coefficients of ``yw`` on the columns of ``pw`` (n_rows, q) and
    the map ``X -> Q^T X`` of an orthonormal basis ``Q`` of their range.

    From the Cholesky factor of the unit-column Gram matrix ``pw^T pw`` when its
    condition estimate allows (:func:`~tyredamp.modal.fit._linalg._gram_chol`; ``pw =
    Q R`` with ``R^T R = pw^T pw``, so ``Q^T X = R^-T pw^T X`` and ``C = R^-1 Q^T
    yw``: the normal equations, Golub & Van Loan, *Matrix Computations*, 4th ed.
    2013, sec. 5.3.1-5.3.2, relative error ~ eps times the condition estimate);
    otherwise from the Householder QR of ``pw`` (sec. 5.3.3). The Gram product is
    a fraction of the time of the QR of a tall basis.
    """
    fac = _gram_chol(pw.T @ pw)
    if fac is None:
        Q, R = np.linalg.qr(pw)
        return solve_triangular(R, Q.T @ yw), lambda X: Q.T @ X
    rs, d = fac
    R = rs * d[None, :]
    qy = solve_triangular(R, pw.T @ yw, trans="T")
    return solve_triangular(R, qy), lambda X: solve_triangular(R, pw.T @ X, trans="T")


def ml_refine(
    fitter: ModalFitter,
    res: FitResult,
    variance: NDArray[np.float64],
    noise_dof: float | None = None,
    *,
    max_nfev: int = 20,
    tol: float = 1e-4,
) -> FitResult:
    """Maximum-likelihood refinement of a WLS fit with the per-line variance.

    Parameters
    ----------
    fitter : ModalFitter
        Fitter of the unweighted data (no ``line_weights``), the model kind and
        residual terms of ``res``.
    res : FitResult
        The weighted least-squares fit to start from (poles, participation).
    variance : ndarray, shape (n_out, n_in, n_freq)
        Variance of each line, in the units of ``fitter.H`` squared.
    noise_dof : float, optional
        Real degrees of freedom of an estimated variance (None: known).
    max_nfev, tol : int, float
        Evaluation limit and convergence threshold (units of the residual
        variance, :func:`~tyredamp.modal.fit._linalg._levenberg_marquardt`).

    Returns
    -------
    FitResult
        ``res`` with the maximum-likelihood poles, participation, residues,
        residual terms, model, cost (``L``) and Fisher standard errors of the
        frequencies, damping ratios and poles (module docstring).
    """
    floor = _floor(variance)
    if floor is None:
        return res
    m_all = int(res.poles.size)
    part = np.asarray(res.participation, complex)
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    th0 = fitter.pack(res.poles, part, ref)
    n_par = th0.size
    lb, ub = pole_bounds(m_all, n_par)  # the bounds of ModalFitter's refinement
    q = fitter.n_cols(m_all)
    n_obs = fitter.n_rows * fitter.n_out
    dof = max(n_obs - q * fitter.n_out - n_par, 1)
    parts = _basis.blocks(fitter, q + int(fitter._layout(m_all).ecol.max(initial=-1)) + 1)
    om = line_weights_full(variance) if len(parts) == 1 else None
    wts = (variance, floor, parts)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        th, nfev, ok, sol = _levenberg_marquardt(
            lambda x: (
                _evaluate(fitter, x, m_all, ref, om)
                if om is not None
                else _evaluate_blocks(fitter, x, m_all, ref, wts)
            ),
            np.clip(th0, lb + 1e-9, ub - 1e-9),
            lb,
            ub,
            max_nfev,
            dof=dof,
            tol=tol,
        )
    C = sol["C"]
    if om is not None:  # one block: the basis of every line is at hand
        cost = float(np.sum((om * (fitter.Y - sol["phi"] @ C)) ** 2))
        hw = np.ascontiguousarray((sol["phi"] @ C).T)  # (n_out, n_rows), re/im interleaved
        model = hw.view(np.complex128).reshape(fitter.n_out, fitter.n_in, fitter.n_f)
    else:
        cost, model = _model_blocks(fitter, th, m_all, ref, C, wts)
    cth = fisher_scale(noise_dof, cost, dof) * np.linalg.pinv(sol["jtj"], hermitian=True)
    return _as_result(fitter, res, th, ref, C, model, cth, cost, nfev, ok)


#: the weights of the blocked evaluation: the variance, each output's floor and the blocks
_Weights = tuple[NDArray[np.float64], NDArray[np.float64], list[slice]]


def _floor(variance: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Each output's smallest positive variance (the global one for an output with
    none), the variance of entries without one (:func:`line_weights_full`); None
    when every variance is zero."""
    n_out = variance.shape[0]
    v = np.asarray(variance, dtype=float).reshape(n_out, -1)
    low = np.array([np.min(r, where=r > 0, initial=np.inf) for r in v])
    if not np.isfinite(low).any():
        return None
    return np.where(np.isfinite(low), low, np.min(low))


def _rows_weights(wts: _Weights, sl: slice) -> NDArray[np.float64]:
    """The rows of :func:`line_weights_full` of the lines ``sl`` (2 n_in lines, n_out)."""
    variance, floor, _ = wts
    n_out = variance.shape[0]
    v = np.asarray(variance[:, :, sl], dtype=float).reshape(n_out, -1)
    v = np.where(v > 0, v, floor[:, None])
    return np.repeat(1.0 / np.sqrt(v / 2.0), 2, axis=1).T.copy()


def _evaluate_blocks(
    fitter: ModalFitter,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    wts: _Weights,
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], dict[str, Any]]:
    """:func:`_evaluate` with the Gram matrices and the residual summed over the
    blocks of lines of ``wts`` (no array of every line): a first pass sums each
    output's Gram matrix of ``W_j [Phi | E]`` and ``W_j [Phi | E]^T W_j y_j``, the
    coefficients follow from their Cholesky factors, and a second pass forms the
    residual ``r_j`` block by block for the cost and ``E^T W_j r_j`` (the same
    quantities as :func:`_evaluate`, summed in another order). An output whose
    basis is too ill-conditioned for the Gram route sends the evaluation to
    :func:`_evaluate` on every line at once (its Householder QR)."""
    q = fitter.n_cols(m)
    lay = fitter._layout(m)
    poles = fitter.unpack(th, m, ref)[0]
    coef = fitter._coef(lay, poles)
    n_par, n_out, parts = th.size, fitter.n_out, wts[2]
    G: list[Any] = [0.0] * n_out
    py: list[Any] = [0.0] * n_out
    for sl in parts:
        B = fitter._basis_ek(th, m, ref, True, sl)[0]
        om, Y = _rows_weights(wts, sl), _basis.ydata(fitter, sl)
        for j in range(n_out):
            bw = B * om[:, j, None]
            G[j] = G[j] + bw.T @ bw
            py[j] = py[j] + bw.T @ (Y[:, j] * om[:, j])
    C = np.zeros((q, n_out))
    ges = []
    for j in range(n_out):
        fac = _gram_chol(G[j][:q, :q])
        om_all = line_weights_full(wts[0]) if fac is None else None
        if om_all is not None:  # the QR route needs the basis whole
            return _evaluate(fitter, th, m, ref, om_all)
        if fac is None:
            raise ValueError("variance: every entry is zero")  # _floor said otherwise
        rs, d = fac
        R = rs * d[None, :]
        C[:, j] = solve_triangular(R, solve_triangular(R, py[j][:q], trans="T"))
        X = solve_triangular(R, G[j][:q, q:], trans="T")
        ges.append(G[j][q:, q:] - X.T @ X)  # E^T W P W E
    cost, etr = 0.0, np.zeros((B.shape[1] - q, n_out))
    for sl in parts:
        B = fitter._basis_ek(th, m, ref, True, sl)[0]
        om, Y = _rows_weights(wts, sl), _basis.ydata(fitter, sl)
        for j in range(n_out):
            bw = B * om[:, j, None]
            r = Y[:, j] * om[:, j] - bw[:, :q] @ C[:, j]  # the residual itself
            cost += float(r @ r)
            etr[:, j] += bw[:, q:].T @ r
    jtj = np.zeros((n_par, n_par))
    jtr = np.zeros(n_par)
    for j in range(n_out):
        S = np.zeros((n_par, etr.shape[0]))
        np.add.at(S, (lay.dpar, lay.ecol), coef * C[lay.dcol, j])
        jtj += S @ ges[j] @ S.T
        jtr -= S @ etr[:, j]
    return cost, 0.5 * (jtj + jtj.T), jtr, {"C": C, "jtj": jtj}


def _model_blocks(
    fitter: ModalFitter,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    C: NDArray[np.float64],
    wts: _Weights,
) -> tuple[float, NDArray[np.complex128]]:
    """The weighted cost ``sum (W (Y - Phi C))^2`` and the model ``Phi C`` (n_out,
    n_in, n_f) complex, block by block (:func:`_evaluate_blocks`)."""
    model = np.empty((fitter.n_out, fitter.n_in, fitter.n_f), complex)
    cost = 0.0
    for sl in wts[2]:
        mb = fitter._basis_ek(th, m, ref, False, sl)[0] @ C  # (rows, n_out)
        cost += float(np.sum((_rows_weights(wts, sl) * (_basis.ydata(fitter, sl) - mb)) ** 2))
        model[:, :, sl] = (
            np.ascontiguousarray(mb.T).view(np.complex128).reshape(fitter.n_out, fitter.n_in, -1)
        )
    return cost, model


def _as_result(
    fitter: ModalFitter,
    res: FitResult,
    th: NDArray[np.float64],
    ref: NDArray[np.intp],
    C: NDArray[np.float64],
    model: NDArray[np.complex128],
    cth: NDArray[np.float64],
    cost: float,
    nfev: int,
    ok: bool,
) -> FitResult:
    """The FitResult of the maximum-likelihood parameters (scaled as :class:`ModalFitter`)."""
    m = int(res.poles.size)
    poles, part = fitter.unpack(th, m, ref)
    didx = np.array([j for j, _ in fitter.drive], dtype=np.intp)
    b, psi_in, _ = fitter._scale(th, m, ref, C[:, didx].T, np.ones(didx.size))
    u, upper, lower = coefficient_parts(fitter, C, m)
    psi_out = u * b[None, :]
    phi2 = drive_phi2(fitter, poles, psi_out, psi_in) if didx.size else res.drive_phi2
    std_f, std_z, std_p = pole_std(fitter.w_ref, th, m, cth)
    status = "maximum likelihood" + ("" if ok else " (evaluation limit)")
    return dataclasses.replace(
        res,
        poles=poles,
        psi_out=psi_out,
        psi_in=psi_in,
        upper=upper,
        lower=lower,
        std_frequency_hz=std_f,
        std_damping_ratio=std_z,
        std_pole=std_p,
        model=model,
        cost=cost,
        n_iter=res.n_iter + nfev,
        status=status,
        theta=th,
        participation=part,
        drive_phi2=phi2,
        projection=None,
    )
