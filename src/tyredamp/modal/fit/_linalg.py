"""Linear algebra of the modal fits: variable projection from Gram blocks or a
blocked QR, the extra sum of squares of a mode, and the bounded
Levenberg-Marquardt iteration (used by :class:`~tyredamp.modal.fit.fit.ModalFitter`)."""

from __future__ import annotations

import contextlib
import math
from typing import Any

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray
from scipy.linalg import blas, lapack

#: largest condition estimate of the unit-column Gram matrix of the basis for which
#: the projection is taken from the Gram blocks (relative error ~ eps * this)
_MAX_GRAM_COND = 1e6
#: largest condition estimate of that Gram matrix for which the basis is
#: orthogonalised by Cholesky QR twice (:func:`_cholqr2`; beyond, by the blocked
#: Householder QR): ``eps cond`` must stay far below 1 for the first
#: Cholesky factor to be accurate enough for the second pass to orthogonalise
_MAX_CQR2_COND = 1e10
#: a squared norm ``||x||^2 - ||Q^T x||^2`` smaller than this fraction of the
#: subtracted term (relative error ~ eps / this) is formed from the explicit residual
_CANCEL_TOL = 1e-6
#: fit_added: an added column whose squared norm drops below this fraction when the
#: fixed basis is projected out is projected explicitly
_PROJ_TOL = 1e-4


def _one_or(one: Any, blocks: Any) -> Any:
    """``blocks`` (a callable returning an iterator of row blocks), or one that
    returns the single block ``one`` when it is given."""
    if one is None:
        return blocks
    return lambda: iter((one,))


def _fixed_range(
    blocks: Any,
    q: int,
    yy: NDArray[np.float64],
    one: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    n_rows: int | None = None,
    sums: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The range of a fixed basis ``Phi``; ``blocks()`` returns its row blocks ``(Phi_b,
    Y_b)`` with those of the data (called again when a second pass is needed).

    Returns ``T`` (q, r) with ``Q_r^T X = T^T Phi^T X`` for an orthonormal basis
    ``Q_r`` of the range of ``Phi``, ``Q_r^T Y`` (r, n_out) and ``||P Y_j||^2``
    (``P`` the projector on the complement of the range). From the Gram blocks
    when the column-scaled Gram matrix is well conditioned (:func:`_gram_chol`:
    ``T = R^-1``, ``Q^T Y = R^-T Phi^T Y``, ``||P Y||^2 = ||Y||^2 - ||Q^T Y||^2``)
    and that difference keeps its accuracy; otherwise from the blocked QR
    (:func:`_qr_blocks`) and the SVD ``R = U S V^T`` (``r`` singular values above
    ``1e-13`` times the largest): ``Q_r = Q U_r = Phi V_r S_r^-1``, so ``T = V_r
    S_r^-1`` and ``Q_r^T Y = U_r^T Q^T Y`` (a rank-deficient ``Phi`` included).
    ``one = (Phi, Y)`` when they are one block; ``sums``: ``(Phi^T Phi, Phi^T Y)``
    when the caller summed them already (no first pass). An ill-conditioned ``Phi`` of full
    rank (condition estimate up to :data:`_MAX_CQR2_COND`) is orthogonalised by
    CholeskyQR2 first, block by block (:func:`_cholqr2`: ``T = D^-1 R_1^-1
    R_2^-1``, ``Q^T Y = R_2^-T Q_1^T Y``), with the same cancellation test.
    """
    if sums is not None:
        G, P = sums
    else:
        G = np.zeros((q, q))
        P = np.zeros((q, yy.size))
        for Pb, Yb in blocks():
            G += Pb.T @ Pb
            P += Pb.T @ Yb
    fac = _gram_chol(G)
    if fac is not None:
        rs, d = fac
        qty = lapack.dtrtrs(rs, P / d[:, None], trans=1)[0]
        yyp = yy - np.einsum("ij,ij->j", qty, qty)
        if not (yyp < _CANCEL_TOL * yy).any():
            tmap = lapack.dtrtri(rs)[0] / d[:, None]  # R^-1 with R = rs diag(d)
            return np.asarray(tmap), np.asarray(qty), np.asarray(yyp)
    cq = None if fac is not None else _cqr2_products(G, q, _one_or(one, blocks), n_rows)
    if cq is not None:
        r1, r2, d, q1y = cq
        qty = lapack.dtrtrs(r2, q1y, trans=1)[0]
        yyp = yy - np.einsum("ij,ij->j", qty, qty)
        if not (yyp < _CANCEL_TOL * yy).any():
            tmap = (lapack.dtrtri(r1)[0] @ lapack.dtrtri(r2)[0]) / d[:, None]
            return np.asarray(tmap), np.asarray(qty), np.asarray(yyp)
    R, Z, rho = _qr_blocks(blocks(), q, yy.size)
    u, sv, vt = np.linalg.svd(R)
    r = int(np.count_nonzero(sv > 1e-13 * sv.max())) if sv.size and sv.max() > 0 else 0
    # the leading directions of Q outside the range (Q U_r+1.., a rank-deficient Phi)
    # hold part of ||P Y||^2 as well
    zo = u[:, r:].T @ Z
    yyp = rho + np.einsum("ij,ij->j", zo, zo)
    return np.asarray(vt[:r].T / sv[:r]), np.asarray(u[:, :r].T @ Z), np.asarray(yyp)


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
    g: NDArray[np.float64], max_cond: float | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Cholesky factor of a Gram matrix with unit diagonal scaling, or None.

    ``g = Phi^T Phi``: returns ``rs`` (upper) and ``d`` with ``g = diag(d) rs^T rs
    diag(d)`` (so ``Phi = Q R`` with ``R = rs diag(d)``), or None when a column
    vanishes, the factorisation fails or the condition estimate of ``rs^T rs``
    exceeds ``max_cond`` (None: ``_MAX_GRAM_COND``, read at the call).
    """
    dg = g.diagonal()
    if g.shape[0] == 0 or not all(0.0 < v < math.inf for v in dg.tolist()):  # NaN: False
        return None
    d = np.sqrt(dg)
    gs = g / np.multiply.outer(d, d)
    rs, info = lapack.dpotrf(gs, lower=0, clean=1)
    if info != 0:
        return None
    rcond, info = lapack.dpocon(rs, float(abs(gs).sum(axis=0).max()))
    limit = _MAX_GRAM_COND if max_cond is None else max_cond
    if info != 0 or not rcond * limit >= 1.0:
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
    one: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    n_rows: int | None = None,
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
        Returns an iterable of row blocks ``(B_b, Y_b)`` of ``B`` and ``Y``
        (together every row once), called only when the basis is too
        ill-conditioned for its Gram matrix or the cost would lose accuracy:
        the projection then comes from CholeskyQR2 of ``Phi`` (:func:`_cholqr2`)
        or a QR factorisation of ``[Phi | E]`` accumulated block by block
        (:func:`_qr_blocks`); no ``n_rows`` array is formed.
    residual : bool
        Take the projection from the QR route whatever the conditioning (else
        only when ``cost`` loses accuracy by cancellation: ``cost_j < _CANCEL_TOL
        cancel_j``).
    gradient : bool
        Return ``E^T r``.
    cancel : ndarray, shape (n_out,), optional
        Reference of the cancellation test (default ``||Q^T Y_j||^2``).
    one : (ndarray, ndarray), optional
        ``B`` and ``Y`` themselves when they are one block (used, not rebuilt,
        by the passes of :func:`_cholqr2`). An ill-conditioned ``Phi`` is
        orthogonalised by :func:`_cholqr2` (when its condition allows), not by
        the Householder QR.
    n_rows : int, optional
        Number of rows of ``B`` (the shift of the shifted CholeskyQR3 start,
        :func:`_shifted_start`).

    Returns
    -------
    dict
        ``R`` (``Phi = Q R``), ``C`` (q, n_out) coefficients, ``Ct = Q^T Y``,
        ``QtE = Q^T E``, ``GE = E^T P E`` (``P`` the projector on the complement
        of ``Phi``), ``Etr = E^T r`` (or None), ``cost``, ``cost_out`` and
        ``qr`` (True when the QR route was taken).

    Notes
    -----
    With ``R`` from the Cholesky factor of ``Phi^T Phi`` (:func:`_gram_chol`):
    ``Q^T X = R^-T Phi^T X`` for ``X = E, Y``, ``C = R^-1 Q^T Y``, ``cost_j =
    ||Y_j||^2 - ||Q^T Y_j||^2``, ``E^T P E = E^T E - (Q^T E)^T Q^T E`` and ``E^T r =
    E^T Y - (Q^T E)^T Q^T Y``. The QR route factors ``[Phi | E] = Q_B R_B`` with
    ``R_B = [[R, Q^T E], [0, R_2]]`` and ``Q_B^T Y = [Q^T Y; X]`` plus the rows
    beyond, whose squared norm ``rho_j`` is the part of ``Y`` outside the span
    of ``[Phi | E]``: ``E^T P E = R_2^T R_2``, ``E^T r = R_2^T X`` and ``cost_j =
    ||X_j||^2 + rho_j``, free of cancellation (Golub & Van Loan, *Matrix
    Computations*, 4th ed. 2013, sec. 5.3 and 5.6: least squares by QR of the
    augmented matrix).
    """
    ne = G.shape[0] - q
    fac = _gram_chol(G[:q, :q])
    if fac is not None and not residual:
        rs, d = fac
        rhs = np.concatenate([G[:q, q:], P[:q]], axis=1) / d[:, None]
        x = lapack.dtrtrs(rs, rhs, trans=1)[0]
        QtE, Ct = x[:, :ne], x[:, ne:]
        ct2 = (Ct * Ct).sum(axis=0)
        cost_out = yy - ct2
        if not (cost_out < _CANCEL_TOL * (ct2 if cancel is None else cancel)).any():
            R, C = rs * d[None, :], lapack.dtrtrs(rs, Ct)[0] / d[:, None]
            return _gram_solution(G, P, q, (R, C, Ct, QtE), cost_out, gradient, qr=False)
    if fac is None and not residual:
        blocks = _one_or(one, explicit)
        got = _cholqr2(G, P, q, yy, blocks, gradient=gradient, cancel=cancel, n_rows=n_rows)
        if got is not None:
            return got
    Rb, Z, rho = _qr_blocks(explicit(), G.shape[0], P.shape[1])
    R, QtE, R2 = Rb[:q, :q], Rb[:q, q:], Rb[q:, q:]
    Ct, X = Z[:q], Z[q:]
    diag = np.abs(np.diag(R))
    cost_out = np.einsum("ij,ij->j", X, X) + rho
    Etr = R2.T @ X if gradient else None
    if diag.size and diag.min() <= 1e-13 * diag.max():
        C = np.linalg.lstsq(R, Ct, rcond=None)[0]  # minimum-norm, as lstsq(Phi, Y)
        # a rank-deficient Phi leaves part of Q^T Y unexplained: r = Q (Ct - R C) + ...
        top = Ct - R @ C
        cost_out = cost_out + np.einsum("ij,ij->j", top, top)
        if Etr is not None:
            Etr = Etr + QtE.T @ top
    else:
        C = sla.solve_triangular(R, Ct)
    return {
        "R": R,
        "C": C,
        "Ct": Ct,
        "QtE": QtE,
        "GE": R2.T @ R2,
        "Etr": Etr,
        "cost": float(cost_out.sum()),
        "cost_out": cost_out,
        "qr": True,
    }


def _shifted_start(
    g: NDArray[np.float64], q: int, blocks: Any, n_rows: int | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The first step of shifted CholeskyQR3 for a Gram matrix ``g`` beyond
    :data:`_MAX_CQR2_COND`: ``R_1`` (upper) and ``D`` with ``Q_1 = Phi D^-1 R_1^-1``
    well enough conditioned for CholeskyQR2, or None.

    With ``X = Phi D^-1`` (unit columns), ``R_0`` is the Cholesky factor of ``X^T X +
    s I`` for the shift ``s = 11 (m q + q (q + 1)) u ||X||_2^2`` (``m`` rows, ``u`` the
    unit round-off), which keeps the factorisation of the computed Gram matrix from
    breaking down; ``X R_0^-1`` has a condition number of about ``(s /
    sigma_min^2)^(1/2)``, its Gram matrix is summed over the blocks and factored again
    (``R_s``), and ``R_1 = R_s R_0`` (Fukaya, Kannan, Nakatsukasa, Zhang & Yamamoto,
    *SIAM J. Sci. Comput.* 42, 2020, Algorithm 4.1 and eq. 4.2). ``n_rows`` None
    counts a million rows (a larger shift: a little less range of condition).
    """
    dg = g.diagonal()
    if g.shape[0] == 0 or not all(0.0 < v < math.inf for v in dg.tolist()):
        return None
    d = np.sqrt(dg)
    gs = g / np.multiply.outer(d, d)
    m = 1_000_000 if n_rows is None else max(int(n_rows), q)
    shift = 11.0 * (m * q + q * (q + 1)) * np.finfo(float).eps / 2 * np.linalg.eigvalsh(gs)[-1]
    r0, info = lapack.dpotrf(_plus_diag(gs, shift), lower=0, clean=1)
    if info != 0:
        return None
    s0 = np.zeros((q, q))
    for B, _ in blocks():
        x0 = blas.dtrsm(1.0, r0, B[:, :q] / d, side=1, lower=0)  # Phi_b D^-1 R_0^-1
        s0 += x0.T @ x0
    fac = _gram_chol(s0, _MAX_CQR2_COND)
    if fac is None:
        return None
    rs, ds = fac
    return (rs * ds[None, :]) @ r0, d


def _cqr2_products(
    g: NDArray[np.float64], q: int, blocks: Any, n_rows: int | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], Any] | None:
    """CholeskyQR2 of ``Phi`` (Gram matrix ``g``; ``blocks()`` yields the row blocks
    ``(B_b, Y_b)`` of ``B = [Phi | E]`` and the data): ``R_1``, ``R_2``, ``D`` and
    ``Q_1^T [E | Y]`` with ``Q_1 = Phi D^-1 R_1^-1`` (:func:`_cholqr2`), or None when a
    factorisation fails or ``Phi`` is too ill-conditioned even for the shifted start.

    ``R_1`` is the Cholesky factor of ``D^-1 g D^-1`` when its condition estimate is
    within :data:`_MAX_CQR2_COND`; beyond, the shifted start of
    :func:`_shifted_start` (shifted CholeskyQR3, one more pass over the blocks).
    ``Q_1`` is formed one block of rows at a time (``Q_1^T Q_1`` and ``Q_1^T [E |
    Y]`` are sums over the blocks), so a basis held in several blocks costs one more
    pass of matrix products, not a Householder QR per block.
    """
    fac = _gram_chol(g, _MAX_CQR2_COND)
    if fac is not None:
        rs, d = fac
        r1 = rs
    else:
        start = _shifted_start(g, q, blocks, n_rows)
        if start is None:
            return None
        r1, d = start
    s = np.zeros((q, q))
    xy: Any = 0.0
    for B, Y in blocks():
        q1 = blas.dtrsm(1.0, r1, B[:, :q] / d, side=1, lower=0)  # Phi_b D^-1 R_1^-1
        s += q1.T @ q1
        xy = xy + np.concatenate([q1.T @ B[:, q:], q1.T @ Y], axis=1)
    r2, info = lapack.dpotrf(s, lower=0, clean=1)
    if info != 0:
        return None
    return r1, r2, d, xy


def _cholqr2(
    G: NDArray[np.float64],
    P: NDArray[np.float64],
    q: int,
    yy: NDArray[np.float64],
    blocks: Any,
    *,
    gradient: bool,
    cancel: NDArray[np.float64] | None,
    n_rows: int | None = None,
) -> dict[str, Any] | None:
    """The projection of :func:`_vp_solve` with ``Phi`` orthogonalised by Cholesky
    QR twice, or None (condition beyond :data:`_MAX_CQR2_COND`, a failed
    factorisation, or a cost that would lose accuracy by cancellation).

    ``blocks()``: the row blocks ``(B_b, Y_b)`` of ``B = [Phi | E]`` and of the data
    (together every row once; called again for each pass); ``n_rows`` their number
    of rows (the shift of :func:`_shifted_start`). With ``D``
    the column norms of ``Phi`` and ``R_1`` the Cholesky factor of ``D^-1 Phi^T
    Phi D^-1``, ``Q_1 = Phi D^-1 R_1^-1`` is formed explicitly; the Cholesky
    factor ``R_2`` of ``Q_1^T Q_1`` (condition ``1 + O(eps cond(Phi)^2)``) gives
    ``Phi = Q R`` with ``Q = Q_1 R_2^-1`` orthonormal to working precision and
    ``R = R_2 R_1 D`` (CholeskyQR2: Fukaya, Nakatsukasa, Yanagisawa & Yamamoto,
    2014; Yamamoto, Nakatsukasa, Yanagisawa & Fukaya, *ETNA* 44, 2015, stable
    for ``cond(Phi)`` up to about ``eps^-1/2``). ``Q^T E = R_2^-T Q_1^T E`` and
    ``Q^T Y = R_2^-T Q_1^T Y`` are products with that explicit basis (no
    ``cond(Phi)^2`` amplification); the rest follows the Gram route of
    :func:`_vp_solve` (``E^T P E``, ``E^T r`` and the cost by subtraction, the
    same cancellation test).
    """
    ne = G.shape[0] - q
    fac = _cqr2_products(G[:q, :q], q, blocks, n_rows)
    if fac is None:
        return None
    r1, r2, d, xy = fac
    x = lapack.dtrtrs(r2, xy, trans=1)[0]
    QtE, Ct = x[:, :ne], x[:, ne:]
    ct2 = (Ct * Ct).sum(axis=0)
    cost_out = yy - ct2
    if (cost_out < _CANCEL_TOL * (ct2 if cancel is None else cancel)).any():
        return None
    c = lapack.dtrtrs(r1, lapack.dtrtrs(r2, Ct)[0])[0] / d[:, None]  # R C = Q^T Y
    R = (r2 @ r1) * d[None, :]
    return _gram_solution(G, P, q, (R, c, Ct, QtE), cost_out, gradient, qr=True)


def _gram_solution(
    G: NDArray[np.float64],
    P: NDArray[np.float64],
    q: int,
    factors: tuple[NDArray[np.float64], ...],
    cost_out: NDArray[np.float64],
    gradient: bool,
    *,
    qr: bool,
) -> dict[str, Any]:
    """The projection of :func:`_vp_solve` from ``R``, ``C``, ``Ct = Q^T Y`` and
    ``QtE = Q^T E`` of a route that has the Gram blocks ``G = [Phi E]^T [Phi E]`` and
    ``P = [Phi E]^T Y``: ``E^T (I - Q Q^T) E`` and ``E^T r`` follow from them."""
    R, C, Ct, QtE = factors
    return {
        "R": R,
        "C": C,
        "Ct": Ct,
        "QtE": QtE,
        "GE": G[q:, q:] - QtE.T @ QtE,
        "Etr": P[q:] - QtE.T @ Ct if gradient else None,
        "cost": float(cost_out.sum()),
        "cost_out": cost_out,
        "qr": qr,
    }


def _qr_blocks(
    blocks: Any, n_col: int, n_out: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """QR of a tall ``B`` given as row blocks, with ``Q^T`` applied to ``Y``.

    ``blocks`` yields ``(B_b, Y_b)``. Each block is stacked under the triangle
    of the blocks before it and factored again (Householder, LAPACK ``dgeqrf``
    and ``dormqr``; the tall-skinny QR of Demmel et al. 2012), so that only
    one block and an ``n_col`` triangle are held. Returns ``R`` (n_col, n_col,
    upper; zero rows when ``B`` has fewer rows), ``Z`` (n_col, n_out) the
    leading rows of ``Q^T Y`` and ``rho`` (n_out,) the squared norms of its
    other rows.
    """
    R = np.zeros((0, n_col))
    Z = np.zeros((0, n_out))
    rho = np.zeros(n_out)
    for Bb, Yb in blocks:
        A = np.concatenate([R, Bb])
        Yst = np.concatenate([Z, Yb])
        qr, tau, _, info = lapack.dgeqrf(A, overwrite_a=1)
        if info != 0:
            raise np.linalg.LinAlgError("QR of the basis failed")
        k = min(A.shape[0], n_col)
        lwork = max(1, Yst.shape[1]) * 64
        # the reflectors are the first k columns (fewer rows than columns: k rows)
        qty, _, info = lapack.dormqr("L", "T", qr[:, :k], tau[:k], Yst, lwork, overwrite_c=1)
        if info != 0:
            raise np.linalg.LinAlgError("QR of the basis failed")
        rest = qty[k:]
        rho += np.einsum("ij,ij->j", rest, rest)
        R, Z = np.triu(qr[:k]), np.array(qty[:k])
    if R.shape[0] < n_col:  # fewer rows than columns
        R = np.concatenate([R, np.zeros((n_col - R.shape[0], n_col))])
        Z = np.concatenate([Z, np.zeros((n_col - Z.shape[0], n_out))])
    return R, Z, rho


def _plus_diag(a: NDArray[np.float64], lam: float) -> NDArray[np.float64]:
    """``a + lam I`` (a new array; the same numbers as ``a + lam * np.eye(n)``)."""
    out = np.array(a)
    out.flat[:: a.shape[0] + 1] += lam
    return out


def _lu_solve(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
    """``a x = b`` by LAPACK ``dgesv`` (LU, partial pivoting) and its ``info`` (> 0: singular)."""
    x, info = lapack.dgesv(a, b)[2:]
    return x, int(info)


def _gn_point(
    x: NDArray[np.float64],
    A: NDArray[np.float64],
    g: NDArray[np.float64],
    lb: NDArray[np.float64],
    ub: NDArray[np.float64],
) -> tuple[NDArray[np.intp] | None, NDArray[np.float64], Any, Any, float] | None:
    """The free parameters of a point of :func:`_levenberg_marquardt` and its
    Gauss-Newton decrement (None when every parameter is held).

    Returns the free indices (None: all), their scales ``sqrt(diag A)``, the
    scaled ``A`` and ``g`` of the free parameters and the decrement ``-g^T
    A^-1 g`` (``A`` regularised by ``1e-12`` of its scaled diagonal).
    """
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
            return None
        free, d_f = idx, d_a[idx]
        An = A[np.ix_(idx, idx)] / np.multiply.outer(d_f, d_f)
        gn = g[idx] / d_f
    else:
        An = A / np.multiply.outer(d_a, d_a)
        gn = g / d_a
    # Gauss-Newton decrement at this point (convergence test)
    gn_step, info = _lu_solve(_plus_diag(An, 1e-12), -gn)
    if info != 0:
        gn_step = -gn
    return free, d_f, An, gn, float(-gn @ gn_step)


def at_rest(
    x: NDArray[np.float64],
    cost: float,
    A: NDArray[np.float64],
    g: NDArray[np.float64],
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]],
    tol: float,
    dof: int,
) -> bool:
    """Would :func:`_levenberg_marquardt` started at ``x`` (cost, ``J^T J = A``,
    ``J^T r = g``) stop there at once, with ``tol`` and ``dof``?"""
    point = _gn_point(x, A, g, *bounds)
    return point is None or point[4] <= max(tol * cost / dof, 1e-24 * max(cost, 1e-300))


def interest_decrement(
    free: NDArray[np.intp] | None,
    An: NDArray[np.float64],
    gn: NDArray[np.float64],
    interest: NDArray[np.intp],
) -> float:
    """The Gauss-Newton decrement of the parameters ``interest`` alone, the others
    (nuisance) profiled out: ``s_1^T (C_11)^-1 s_1`` with ``s = -A^-1 g`` the full
    Gauss-Newton step and ``C = A^-1`` (``An``, ``gn``: the scaled ``A`` and ``g``
    of the free parameters ``free`` of :func:`_gn_point`; None: all free).

    It equals the decrement ``g_1'^T S^-1 g_1'`` of the profile cost (the cost
    minimised over the nuisance parameters) in the quadratic model, with ``S =
    A_11 - A_12 A_22^-1 A_21`` (the Schur complement, ``= C_11^-1``) and ``g_1' =
    g_1 - A_12 A_22^-1 g_2``: the squared distance, in units of the noise, of the
    parameters of interest from their Gauss-Newton optimum. It never exceeds the
    full decrement (a marginal Mahalanobis distance is at most the joint one;
    e.g. Seber & Wild, *Nonlinear Regression*, 1989, sec. 2.2 on the profile
    cost). Held parameters of interest count as converged (0 when every one is
    held)."""
    sel = interest if free is None else np.flatnonzero(np.isin(free, interest))
    if sel.size == 0:
        return 0.0
    a = _plus_diag(An, 1e-12)
    try:
        c = np.linalg.inv(a)
    except np.linalg.LinAlgError:
        return math.inf
    s1 = -(c @ gn)[sel]
    c11 = np.ascontiguousarray(c[np.ix_(sel, sel)], np.float64)
    x, info = _lu_solve(c11, s1)
    return float(s1 @ x) if info == 0 else math.inf


def _levenberg_marquardt(
    evaluate: Any,
    x0: NDArray[np.float64],
    lb: NDArray[np.float64],
    ub: NDArray[np.float64],
    max_nfev: int,
    dof: int,
    tol: float = 1e-6,
    interest: NDArray[np.intp] | None = None,
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
    step reduces the cost any more (round-off). With ``interest`` (indices of
    the parameters whose values matter; the others are nuisance parameters) it
    also stops when the decrement of those parameters alone, the nuisance ones
    profiled out (:func:`interest_decrement`), is below ``tol s^2``: they are
    then within ``sqrt(tol)`` standard deviations of their Gauss-Newton optimum
    whatever the nuisance parameters still do (a residual mode far outside the
    band whose damping the data hardly hold can creep along a flat valley for
    hundreds of steps while the modes of the band stand still).

    Returns the parameters, the number of evaluations, whether it converged
    and the by-product of ``evaluate`` at the returned parameters.
    """
    x = np.minimum(np.maximum(np.asarray(x0, float), lb), ub)
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
            point = _gn_point(x, A, g, lb, ub)
            if point is None:
                return x, nfev, True, aux
            free, d_f, An, gn, decrement = point
            limit = max(tol * cost / dof, 1e-24 * cost0)
            if decrement <= limit:
                return x, nfev, True, aux
            if interest is not None and interest_decrement(free, An, gn, interest) <= limit:
                return x, nfev, True, aux
            new_point = False
        step_n, info = _lu_solve(_plus_diag(An, lam), -gn)
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
