"""Linear algebra of the modal fits: variable projection from Gram blocks,
orthogonalisation, the extra sum of squares of a mode, and the bounded
Levenberg-Marquardt iteration (used by :class:`~tyredamp.modal.fit.ModalFitter`)."""

from __future__ import annotations

import contextlib
import math
from typing import Any

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray
from scipy.linalg import lapack

#: largest condition estimate of the unit-column Gram matrix of the basis for which
#: the projection is taken from the Gram blocks (relative error ~ eps * this)
_MAX_GRAM_COND = 1e6
#: a squared norm ``||x||^2 - ||Q^T x||^2`` smaller than this fraction of the
#: subtracted term (relative error ~ eps / this) is formed from the explicit residual
_CANCEL_TOL = 1e-6
#: fit_added: an added column whose squared norm drops below this fraction when the
#: fixed basis is projected out is projected explicitly
_PROJ_TOL = 1e-4


def _extra_ss(
    R: NDArray[np.float64], C: NDArray[np.float64], per: int, m: int
) -> NDArray[np.float64]:
    """Extra sum of squares of each mode: the rise of the (weighted) cost when
    the ``per`` columns of mode ``n`` are removed and the other linear
    coefficients refitted at the same poles, summed over the outputs.

    With ``Phi = Q R`` and ``F = (Phi^T Phi)^-1 = R^-1 R^-T``, the rise for
    output ``j`` is ``c_nj^T (F_nn)^-1 c_nj`` (``c_nj`` the coefficients of
    mode ``n``, ``F_nn`` their block; the partial F-test numerator, e.g.
    Seber & Lee, *Linear Regression Analysis*, 2003, sec. 4.3). Returns shape (m,).
    """
    if m == 0:
        return np.zeros(0)
    rinv = lapack.dtrtri(R)[0]
    rb = rinv[: per * m].reshape(m, per, -1)  # rows of R^-1 of each mode: F_nn = rb rb^T
    fnn = np.matmul(rb, rb.transpose(0, 2, 1))
    cn = C[: per * m].reshape(m, per, -1)  # (m, per, n_out)
    try:
        sol = np.linalg.solve(fnn, cn)
    except np.linalg.LinAlgError:  # a singular block: mode by mode, 0 where singular
        sol = np.zeros_like(cn)
        for n in range(m):
            with contextlib.suppress(np.linalg.LinAlgError):
                sol[n] = np.linalg.solve(fnn[n], cn[n])
    return np.asarray(np.sum(cn * sol, axis=(1, 2)))


def _gram_chol(
    g: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Cholesky factor of a Gram matrix with unit diagonal scaling, or None.

    ``g = Phi^T Phi``: returns ``rs`` (upper) and ``d`` with ``g = diag(d) rs^T rs
    diag(d)`` (so ``Phi = Q R`` with ``R = rs diag(d)``), or None when a column
    vanishes, the factorisation fails or the condition estimate of ``rs^T rs``
    exceeds ``_MAX_GRAM_COND``.
    """
    dg = g.diagonal()
    if g.shape[0] == 0 or not (dg.min() > 0.0 and dg.max() < np.inf):  # NaN: False
        return None
    d = np.sqrt(dg)
    gs = g / np.multiply.outer(d, d)
    rs, info = lapack.dpotrf(gs, lower=0, clean=1)
    if info != 0:
        return None
    rcond, info = lapack.dpocon(rs, float(abs(gs).sum(axis=0).max()))
    if info != 0 or not rcond * _MAX_GRAM_COND >= 1.0:
        return None
    return rs, d


def _vp_solve(
    G: NDArray[np.float64],
    P: NDArray[np.float64],
    q: int,
    yy: NDArray[np.float64],
    explicit: Any,
    *,
    residual: bool,
    gradient: bool,
    cancel: NDArray[np.float64] | None = None,
) -> dict[str, Any]:
    """Variable projection from the Gram blocks of ``B = [Phi | E]``.

    Parameters
    ----------
    G : ndarray, shape (q + n_e, q + n_e)
        ``B^T B``.
    P : ndarray, shape (q + n_e, n_out)
        ``B^T Y``.
    q : int
        Number of basis columns (the first ``q`` of ``B``).
    yy : ndarray, shape (n_out,)
        ``||Y_j||^2`` per column.
    explicit : callable
        Returns ``(B, Y)`` (n_rows rows), called only to orthogonalise an
        ill-conditioned basis or to form the residual.
    residual : bool
        Form the residual ``r = Y - Phi C`` (else only when ``cost`` loses
        accuracy by cancellation: ``cost_j < _CANCEL_TOL cancel_j``).
    gradient : bool
        Return ``E^T r``.
    cancel : ndarray, shape (n_out,), optional
        Reference of the cancellation test (default ``||Q^T Y_j||^2``).

    Returns
    -------
    dict
        ``R`` (``Phi = Q R``), ``C`` (q, n_out) coefficients, ``Ct = Q^T Y``,
        ``QtE = Q^T E``, ``GE = E^T P E`` (``P`` the projector on the complement
        of ``Phi``), ``Etr = E^T r`` (or None), ``cost``, ``cost_out``, ``resid``
        (or None) and ``Q`` (None unless the basis was orthogonalised).

    Notes
    -----
    With ``R`` from the Cholesky factor of ``Phi^T Phi`` (:func:`_gram_chol`):
    ``Q^T X = R^-T Phi^T X`` for ``X = E, Y``, ``C = R^-1 Q^T Y``, ``cost_j =
    ||Y_j||^2 - ||Q^T Y_j||^2``, ``E^T P E = E^T E - (Q^T E)^T Q^T E`` and ``E^T r =
    E^T Y - (Q^T E)^T Q^T Y``. When the Gram matrix is too ill-conditioned
    ``Q`` comes from :func:`_orth` of the explicit basis.
    """
    ne = G.shape[0] - q
    fac = _gram_chol(G[:q, :q])
    Q = None
    Bx = Yx = None
    if fac is not None:
        rs, d = fac
        rhs = np.concatenate([G[:q, q:], P[:q]], axis=1) / d[:, None]
        x = lapack.dtrtrs(rs, rhs, trans=1)[0]
        QtE, Ct = x[:, :ne], x[:, ne:]
        R = rs * d[None, :]
        C = lapack.dtrtrs(rs, Ct)[0] / d[:, None]
    else:
        Bx, Yx = explicit()
        phi = Bx[:, :q]
        Q, R = _orth(phi)
        QtE = Q.T @ Bx[:, q:]
        Ct = Q.T @ Yx
        diag = np.abs(np.diag(R))
        if diag.min() <= 1e-13 * diag.max():
            C = np.linalg.lstsq(phi, Yx, rcond=None)[0]
        else:
            C = sla.solve_triangular(R, Ct)
    ct2 = (Ct * Ct).sum(axis=0)
    cost_out = yy - ct2
    GE = G[q:, q:] - QtE.T @ QtE
    resid = Etr = None
    if residual or (cost_out < _CANCEL_TOL * (ct2 if cancel is None else cancel)).any():
        if Bx is None:
            Bx, Yx = explicit()
        resid = Yx - (Bx[:, :q] @ C if Q is None else Q @ Ct)
        cost_out = np.einsum("ij,ij->j", resid, resid)
        if gradient:
            Etr = Bx[:, q:].T @ resid
    elif gradient:
        Etr = P[q:] - QtE.T @ Ct
    return {
        "R": R,
        "C": C,
        "Ct": Ct,
        "Q": Q,
        "QtE": QtE,
        "GE": GE,
        "Etr": Etr,
        "resid": resid,
        "cost": float(cost_out.sum()),
        "cost_out": cost_out,
    }


def _orth(phi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Thin QR ``phi = Q R`` by CholeskyQR2 (Yamamoto et al. 2015), Householder fallback.

    Two Cholesky passes on the Gram matrix of the column-scaled basis give
    ``Q`` orthonormal to round-off whenever ``cond(phi) < ~1e7`` and cost two
    ``n x q`` Gram products and triangular solves -- several times faster than
    LAPACK's Householder QR with an explicit ``Q`` for the tall bases here.
    Householder QR for small bases and when a Cholesky factor is singular or
    too ill-conditioned.
    """
    n, q = phi.shape
    if n * q * q < 4e6:  # small: LAPACK's call overhead is lower than two Cholesky passes
        return _householder(phi)
    nrm = np.sqrt(np.einsum("ij,ij->j", phi, phi))
    if np.all(nrm > 0) and np.all(np.isfinite(nrm)):
        g1 = (phi.T @ phi) / np.outer(nrm, nrm)
        try:
            r1 = np.linalg.cholesky(g1).T
            d1 = np.abs(np.diag(r1))
            if d1.min() > 1e-7 * d1.max():
                eye = np.eye(r1.shape[0])
                q1 = phi @ (sla.solve_triangular(r1, eye) / nrm[:, None])
                r2 = np.linalg.cholesky(q1.T @ q1).T
                q = q1 @ sla.solve_triangular(r2, eye)
                return q, (r2 @ r1) * nrm[None, :]
        except np.linalg.LinAlgError:
            pass
    return _householder(phi)


def _householder(phi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Thin Householder QR by LAPACK ``dgeqrf`` + ``dorgqr`` (less call overhead
    than :func:`numpy.linalg.qr` for the small bases); NumPy's on failure."""
    n, q = phi.shape
    if n >= q > 0:
        qr, tau, _, info = lapack.dgeqrf(phi)
        if info == 0:
            r = np.triu(qr[:q])
            qm, _, info = lapack.dorgqr(qr, tau, overwrite_a=1)
            if info == 0:
                return qm, r
    qn, rn = np.linalg.qr(phi)
    return qn, rn


def _lu_solve(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
    """``a x = b`` by LAPACK ``dgesv`` (LU, partial pivoting) and its ``info`` (> 0: singular)."""
    x, info = lapack.dgesv(a, b)[2:]
    return x, int(info)


def _levenberg_marquardt(
    evaluate: Any,
    x0: NDArray[np.float64],
    lb: NDArray[np.float64],
    ub: NDArray[np.float64],
    max_nfev: int,
    dof: int,
    tol: float = 1e-6,
) -> tuple[NDArray[np.float64], int, bool, Any]:
    """Bounded Levenberg-Marquardt on the normal equations of a least-squares cost.

    ``evaluate(x)`` returns the cost ``||r||^2``, ``J^T J``, ``J^T r`` (the
    variable-projection quantities of :meth:`ModalFitter._normal`; the
    residual itself is never formed) and any by-product, returned for the
    final point. Steps solve ``(J^T J + lam diag(J^T J))
    d = -J^T r`` over the free parameters; a parameter at a bound whose
    gradient points outwards is held there (projected step). The damping
    ``lam`` follows Nielsen's rule (gain ratio ``rho``: ``lam *= max(1/3,
    1 - (2 rho - 1)^3)`` on success, doubled growth on failure).

    Convergence is statistical: the iteration stops when the Gauss-Newton
    decrement ``(J^T r)^T (J^T J)^-1 J^T r`` (the predicted cost reduction of
    a full Gauss-Newton step) is below ``tol s^2`` with ``s^2 = cost / dof`` the residual
    variance -- with the default ``tol = 1e-6`` the remaining step is about
    1e-3 standard deviations of the parameters, far below their uncertainty --
    or below ``1e-24`` times the starting cost (noise-free data), or when no
    step reduces the cost any more (round-off).

    Returns the parameters, the number of evaluations, whether it converged
    and the by-product of ``evaluate`` at the returned parameters.
    """
    x = np.clip(np.asarray(x0, float), lb, ub)
    cost, A, g, aux = evaluate(x)
    cost0 = max(cost, 1e-300)
    nfev = 1
    lam = 1e-3
    nu = 2.0
    n = x.size
    new_point = True  # the quantities of the current point are computed once
    while nfev < max_nfev:
        if new_point:
            if not math.isfinite(cost):
                return x, nfev, False, aux
            diag = A.diagonal()
            d_a = np.sqrt(np.maximum(diag, 1e-300))
            # held: at a bound with the descent direction -g pointing outwards, or
            # without information (e.g. the damping of a residual mode far outside
            # the band: its column of J vanishes)
            held = ((x <= lb) & (g > 0)) | ((x >= ub) & (g < 0))
            held |= diag <= 1e-13 * max(float(diag.max()), 1e-300)
            free: NDArray[np.intp] | None = None
            d_f = d_a
            if held.any():
                idx = np.flatnonzero(~held)
                if idx.size == 0:
                    return x, nfev, True, aux
                free, d_f = idx, d_a[idx]
                An = A[np.ix_(idx, idx)] / np.outer(d_f, d_f)
                gn = g[idx] / d_f
            else:
                An = A / np.outer(d_a, d_a)
                gn = g / d_a
            eye = np.eye(gn.size)
            # Gauss-Newton decrement at this point (convergence test)
            gn_step, info = _lu_solve(An + 1e-12 * eye, -gn)
            if info != 0:
                gn_step = -gn
            decrement = float(-gn @ gn_step)
            if decrement <= max(tol * cost / dof, 1e-24 * cost0):
                return x, nfev, True, aux
            new_point = False
        step_n, info = _lu_solve(An + lam * eye, -gn)
        if info != 0:  # singular
            lam *= nu
            nu *= 2
            continue
        if free is None:
            d = step_n / d_f
        else:
            d = np.zeros(n)
            d[free] = step_n / d_f
        x_new = np.minimum(np.maximum(x + d, lb), ub)
        d = x_new - x
        if np.all(np.abs(d) <= 1e-15 * (1.0 + np.abs(x))):
            return x, nfev, True, aux
        pred = -(2.0 * float(g @ d) + float(d @ A @ d))  # predicted cost reduction
        c_new, A_new, g_new, aux_new = evaluate(x_new)
        nfev += 1
        rho = (cost - c_new) / pred if pred > 0 else -1.0
        if math.isfinite(c_new) and c_new < cost and rho > 1e-4:
            x, cost, A, g, aux = x_new, c_new, A_new, g_new, aux_new
            lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            nu = 2.0
            new_point = True
        else:
            lam *= nu
            nu *= 2.0
            if lam > 1e12:  # no descent left at round-off level
                return x, nfev, True, aux
    return x, nfev, False, aux
