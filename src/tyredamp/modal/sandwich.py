"""Standard errors of a maximum-likelihood modal fit whose noise is correlated across outputs.

The maximum-likelihood fit (:mod:`~tyredamp.modal.fit.ml`) weights every entry
of the FRF by its own variance ``V_jkf`` as if the entries' errors were
independent. The error of an H1 (or cyclic) estimate with a noisy force is
not: with ``X + N`` measured, the error of column ``k`` holds ``-H_k(f) n_kf``
with one complex noise ``n_kf = N / X`` shared by every output (errors in
variables; Pintelon & Schoukens, *System Identification*, 2nd ed. 2012, sec.
2.5 and 7.2; Bendat & Piersol, *Random Data*, 4th ed. 2010, sec. 9.2), so per
line and input the covariance of the outputs' errors is::

    Sigma_f = D_f + r_f h_f h_f^H,    D_f = diag(V_f) - r_f diag(|h_f|^2)

(``r_f = E|n_f|^2`` the relative input-noise variance,
:attr:`~tyredamp.frf.FRF.input_noise`; ``h_f`` the column of ``H``). The
variance ``V`` counts the common part on the diagonal only. The estimate of the
weighted fit is then still consistent but its covariance is White's sandwich
(White, "A heteroskedasticity-consistent covariance matrix estimator",
*Econometrica* 48(4), 1980, eq. (3); Pintelon & Schoukens 2012, sec. 7.2.4 and
17.2, the covariance of a weighted least-squares estimate under a noise model
other than its weighting)::

    Cov(theta) = A^-1 B A^-1,   A = J^T J,   B = J^T W Sigma W J       (1)

with ``J`` the Jacobian of the whitened residual ``W (y - model)`` (the
variable-projection Jacobian of Kaufman, the linear coefficients profiled out,
as :mod:`~tyredamp.modal.fit.ml` uses it) and ``W`` the fit's weights ``1 /
sqrt(V / 2)`` per real row. Since ``W diag(V) W = I``, ``B`` is ``A`` plus, per line
and input, a rank-two update for the common part and minus the diagonal it
replaces. Writing ``n = a + i b`` (``a``, ``b`` independent, each of variance
``r / 2``), the common part adds to ``J^T W e`` the term ``a u_f + b v_f`` with::

    u_f = sum_j w_jf (J_j,re(f) Re h_jf + J_j,im(f) Im h_jf)
    v_f = sum_j w_jf (J_j,im(f) Re h_jf - J_j,re(f) Im h_jf)              (2)

(``J_j,re(f)``, ``J_j,im(f)`` the rows of output ``j``'s real and imaginary part at
line ``f``), so::

    B = A + sum_f r_f / 2 (u_f u_f^T + v_f v_f^T)
          - sum_jf d_jf w_jf^2 / 2 (J_j,re(f)^T J_j,re(f) + J_j,im(f)^T J_j,im(f))   (3)

with ``d_jf = min(r_f |h_jf|^2, V_jf)`` the common part's share of the diagonal
(``D_f >= 0``). The cost is that of one more evaluation of ``J`` plus
``O(n_lines n_par^2)`` for the updates. ``h`` is the fitted model (not the noisy
data). The fit reports ``s A^-1`` (``s`` its Fisher scale for an estimated
variance, :func:`~tyredamp.modal.fit.ml.fisher_scale`); the final stage
(:func:`~tyredamp.modal.final.sandwiched`) takes, for the frequency and the
damping ratio of each mode, the variance of (1) over the variance the fit
reports by the delta method, the factor the reported variances are multiplied
by. The sandwich holds for any weights ``W``: for the weighted least-squares
fit with the separable weights ``1 / (sigma_j sqrt(g_f))`` its diagonal part
is ``J^T W diag(D) W J`` (not ``A``).
:func:`sandwich_shapes` extends it to the shapes (the residues are linear given
the poles: their errors under ``Sigma_f`` plus the poles' part, eq. (S1)-(S2) of
its docstring) and gives the factor (S3) by which the common part raises the
variance of each shape's amplitude along itself; the final stage takes the
covariance of ``theta`` it returns too.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from .fit import _basis
from .fit._results import coefficient_parts
from .fit._scaling import input_std_given

if TYPE_CHECKING:
    from .fit.fit import FitResult, ModalFitter

__all__ = ["sandwich_covariance", "sandwich_shapes"]


def _solve_gram(gram: NDArray[np.float64], rhs: NDArray[np.float64]) -> NDArray[np.float64]:
    """``gram^-1 rhs`` of a Gram matrix, its columns scaled to unit norm first (Jacobi);
    a pseudo-inverse where the Cholesky factor fails."""
    d = 1.0 / np.sqrt(np.maximum(np.diag(gram), 1e-300))
    g = gram * d[:, None] * d[None, :]
    b = rhs * d.reshape(-1, *([1] * (rhs.ndim - 1)))
    try:
        x = scipy.linalg.cho_solve(scipy.linalg.cho_factor(g), b)
    except (np.linalg.LinAlgError, ValueError):
        x = np.linalg.pinv(g, hermitian=True) @ b
    return np.asarray(x * d.reshape(-1, *([1] * (rhs.ndim - 1))))


def _row_weights(variance: NDArray[np.float64], sl: slice) -> NDArray[np.float64]:
    """``1 / sqrt(V / 2)`` of the real rows of lines ``sl`` (2 n_in lines, n_out), an entry
    without variance weighted as its output's least noisy line (as the fit does)."""
    n_out = variance.shape[0]
    v_all = variance.reshape(n_out, -1)
    low = np.array([np.min(r, where=r > 0, initial=np.inf) for r in v_all])
    low = np.where(np.isfinite(low), low, np.min(low))
    v = np.asarray(variance[:, :, sl], dtype=float).reshape(n_out, -1)
    v = np.where(v > 0, v, low[:, None])
    return np.repeat(1.0 / np.sqrt(v / 2.0), 2, axis=1).T


def _rows(
    fitter: ModalFitter, variance: NDArray[np.float64], out_weights: NDArray[np.float64] | None
) -> Callable[[slice], NDArray[np.float64]]:
    """The row weights (rows, n_out) of the lines ``sl`` as the fit weights them: each
    real row by ``1 / sqrt(V / 2)`` (``out_weights`` None: the maximum-likelihood fit)
    or each output by its ``out_weights`` (the weighted least-squares fit)."""
    n_out, n_in = fitter.n_out, fitter.n_in

    def rows(sl: slice) -> NDArray[np.float64]:
        if out_weights is None:
            return _row_weights(variance, sl)
        return np.broadcast_to(
            np.asarray(out_weights, float), (2 * n_in * _count(fitter, sl), n_out)
        )

    return rows


def _noise_weights(
    fitter: ModalFitter, rows: Callable[[slice], NDArray[np.float64]], sl: slice
) -> NDArray[np.float64]:
    """The weight ``w_jf`` of each line's noise (n_in nb, n_out): the output's row weight
    times the fitter's line weight."""
    lw = fitter.line_weights
    return rows(sl)[0::2] * (1.0 if lw is None else np.tile(lw[sl], fitter.n_in)[:, None])


def _own_noise(
    vj: NDArray[np.float64], r: NDArray[np.float64], hj: NDArray[Any], w: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``D_f w^2 / 2`` of one output per real row (2 n_in nb, 1): its own noise, the
    variance ``vj`` less the common part's share ``min(r |h|^2, V)`` (eq. (3)), each
    of the (n_in, nb) entries twice (real and imaginary row)."""
    dj = vj - np.minimum(r * np.abs(hj) ** 2, vj)
    return np.repeat((dj * w**2 / 2.0).reshape(-1), 2)[:, None]


def sandwich_covariance(
    fitter: ModalFitter,
    res: FitResult,
    out_weights: NDArray[np.float64] | None,
    variance: NDArray[np.float64],
    input_noise: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``A^-1`` and ``A^-1 B A^-1`` of eq. (1) (module docstring) for the fit ``res``.

    Parameters
    ----------
    fitter : ModalFitter
        The fitter of ``res`` (its line weights, if any, are part of its rows).
    res : FitResult
        The fit (poles, participation, model).
    out_weights : ndarray, shape (n_out,), or None
        The weight of each output's rows in the weighted least-squares fit
        (``1 / sigma_j``, :meth:`ModalFitter.weights`); None: the fit of ``res`` is the
        maximum-likelihood one, every real row weighted by ``1 / sqrt(V / 2)``.
    variance : ndarray, shape (n_out, n_in, n_freq)
        The variance ``V`` of each entry (units of ``fitter.H`` squared).
    input_noise : ndarray, shape (n_in, n_freq)
        Relative input-noise variance ``r`` (dimensionless).

    Returns
    -------
    ainv, cov, theta : ndarray, shapes (n_par, n_par), (n_par, n_par), (n_par,)
        The inverse information, the sandwich covariance (units of the fit's
        parameters ``theta``, :meth:`ModalFitter.pack`) and ``theta``.
    """
    n_in = fitter.n_in
    v = np.asarray(variance, dtype=float)
    rows = _rows(fitter, v, out_weights)
    th, blocks = _jacobians(fitter, res, rows)
    n_par = th.size
    a = np.zeros((n_par, n_par))
    b = np.zeros((n_par, n_par))
    for sl, jac in blocks:
        nb = _count(fitter, sl)
        om = _noise_weights(fitter, rows, sl)
        h = np.asarray(res.model[:, :, sl])  # (n_out, n_in, nb)
        r = np.asarray(input_noise[:, sl], dtype=float)  # (n_in, nb)
        u, w2 = np.zeros((n_in, nb, n_par)), np.zeros((n_in, nb, n_par))
        for j, jj in enumerate(jac):
            a += jj.T @ jj
            w = om[:, j].reshape(n_in, nb)
            u1, v1 = _common(jj, h[j].real * w, h[j].imag * w)  # eq. (2)
            u += u1
            w2 += v1
            b += (jj * _own_noise(v[j][:, sl], r, h[j], w)).T @ jj  # eq. (3), the diagonal D
        b += _rank_two(u, w2, u, w2, (r / 2.0)[..., None])  # eq. (3), the common part
    ainv = np.asarray(np.linalg.pinv(0.5 * (a + a.T), hermitian=True), dtype=np.float64)
    cov = np.asarray(ainv @ (0.5 * (b + b.T)) @ ainv, dtype=np.float64)
    return ainv, cov, th


class _Projection(NamedTuple):
    """The variable projection of a fit, output by output (:func:`_project`)."""

    th: NDArray[np.float64]  # the fit's parameters (n_par,)
    ref: NDArray[np.intp]  # each mode's reference input (m,)
    q: int  # columns of the basis Phi
    parts: list[slice]  # blocks of lines
    sol: list[NDArray[np.float64]]  # per output G_PhiPhi^-1 [Phi^T W^2 y | G_PhiE] (q, 1 + n_e)
    s: list[NDArray[np.float64]]  # per output S_j (n_par, n_e)
    ginv: list[NDArray[np.float64]]  # per output G_PhiPhi^-1 (q, q)


def _project(
    fitter: ModalFitter, res: FitResult, rows: Callable[[slice], NDArray[np.float64]]
) -> _Projection:
    """The Gram matrices of each output's weighted basis ``W_j [Phi | E]`` summed over
    the blocks of lines, solved for the coefficients ``C_j`` and ``X_j = G_PhiPhi^-1
    G_PhiE`` (:func:`_jacobians`)."""
    m = int(res.poles.size)
    part = np.asarray(res.participation, complex)
    ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
    th = fitter.pack(res.poles, part, ref)
    q, lay = fitter.n_cols(m), fitter._layout(m)
    coef = fitter._coef(lay, fitter.unpack(th, m, ref)[0])
    n_out = fitter.n_out
    parts = _basis.blocks(fitter, q + int(lay.ecol.max(initial=-1)) + 1)
    gram: list[NDArray[np.float64]] = [np.zeros(0)] * n_out
    py: list[NDArray[np.float64]] = [np.zeros(0)] * n_out
    for k, sl in enumerate(parts):
        bb = fitter._basis_ek(th, m, ref, True, sl)[0]
        om, yy = rows(sl), _basis.ydata(fitter, sl)
        for j in range(n_out):
            bw = bb * om[:, j, None]
            g, p = bw.T @ bw, bw[:, :q].T @ (yy[:, j] * om[:, j])
            gram[j], py[j] = (g, p) if k == 0 else (gram[j] + g, py[j] + p)
    sol = [
        _solve_gram(g[:q, :q], np.column_stack([p, g[:q, q:]]))
        for g, p in zip(gram, py, strict=True)
    ]
    s = []
    for j in range(n_out):
        sj = np.zeros((th.size, gram[j].shape[0] - q))
        np.add.at(sj, (lay.dpar, lay.ecol), coef * sol[j][lay.dcol, 0])
        s.append(sj)
    ginv = [_solve_gram(g[:q, :q], np.eye(q)) for g in gram]
    return _Projection(th, ref, q, parts, sol, s, ginv)


def _outputs(
    fitter: ModalFitter,
    pr: _Projection,
    rows: Callable[[slice], NDArray[np.float64]],
    sl: slice,
    coefficients: bool = False,
) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Output by output on the lines ``sl``: Kaufman's Jacobian ``J_j = P_j W_j E S_j^T``
    (rows, n_par) and, with ``coefficients``, ``W_j Phi G_PhiPhi^-1`` (rows, q), the
    map of the whitened noise ``W_j e_j`` to the coefficients' error (``C_j + d C_j =
    G^-1 (W_j Phi)^T W_j (y_j + e_j)``; else an empty array)."""
    m = len(pr.ref)
    q = pr.q
    bb = fitter._basis_ek(pr.th, m, pr.ref, True, sl)[0]
    om = rows(sl)
    for j in range(fitter.n_out):  # one output's Jacobian at a time: memory of one
        bw = bb * om[:, j, None]
        jac = (bw[:, q:] - bw[:, :q] @ pr.sol[j][:, 1:]) @ pr.s[j].T
        yield jac, (bw[:, :q] @ pr.ginv[j] if coefficients else np.zeros((0, q)))


def _jacobians(
    fitter: ModalFitter, res: FitResult, rows: Callable[[slice], NDArray[np.float64]]
) -> tuple[NDArray[np.float64], Iterator[tuple[slice, Iterator[NDArray[np.float64]]]]]:
    """The parameters ``theta`` of ``res`` and, block by block of lines, Kaufman's
    variable-projection Jacobian ``J_j = P_j W_j E S_j^T`` (rows, n_par) of every
    output (as :func:`~tyredamp.modal.fit.ml._evaluate` forms ``J^T J``), ``rows(sl)``
    the row weights (rows, n_out) of the lines ``sl`` (the outputs' Jacobians of a
    block one after the other): ``P_j W_j E = W_j (E - Phi
    X_j)`` with ``X_j = G_PhiPhi^-1 G_PhiE`` and the coefficients ``C_j`` from each
    output's Gram matrix of ``W_j [Phi | E]`` (Golub & Pereyra, "The
    differentiation of pseudo-inverses and nonlinear least squares problems whose
    variables separate", *SIAM J. Numer. Anal.* 10(2), 1973; Kaufman's
    approximation, *BIT* 15, 1975)."""
    pr = _project(fitter, res, rows)

    def outputs(sl: slice) -> Iterator[NDArray[np.float64]]:
        return (jac for jac, _ in _outputs(fitter, pr, rows, sl))

    return pr.th, ((sl, outputs(sl)) for sl in pr.parts)


def _count(fitter: ModalFitter, sl: slice) -> int:
    """Lines in the slice ``sl`` of the fitter's lines."""
    return len(range(fitter.n_f)[sl])


def _common(
    x: NDArray[np.float64], hr: NDArray[np.float64], hi: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``u_f``, ``v_f`` of eq. (2) of one output's rows ``x`` (2 n_in nb, k) with the
    weighted model ``hr = w Re h``, ``hi = w Im h`` (n_in, nb): each (n_in, nb, k)."""
    n_in, nb = hr.shape
    xr = x[0::2].reshape(n_in, nb, -1)
    xi = x[1::2].reshape(n_in, nb, -1)
    return xr * hr[..., None] + xi * hi[..., None], xi * hr[..., None] - xr * hi[..., None]


def _rank_two(
    u1: NDArray[np.float64],
    v1: NDArray[np.float64],
    u2: NDArray[np.float64],
    v2: NDArray[np.float64],
    rr: NDArray[np.float64],
) -> NDArray[np.float64]:
    """``sum_f r_f / 2 (u1_f u2_f^T + v1_f v2_f^T)`` (eq. (3), the common part) of the
    projections ``u``, ``v`` (n_in, nb, k) of eq. (2); ``rr = r / 2`` (n_in, nb, 1)."""
    k, n = u1.shape[-1], u2.shape[-1]
    a = (u1 * rr).reshape(-1, k).T @ u2.reshape(-1, n)
    return np.asarray(a + (v1 * rr).reshape(-1, k).T @ v2.reshape(-1, n))


class _Sums(NamedTuple):
    """The sums of :func:`_shape_sums` (raw: before ``A^-1`` is applied)."""

    a: NDArray[np.float64]  # J^T J (n_par, n_par)
    bg: NDArray[np.float64]  # Cov(z) of the scores z = [J^T W e, K_D W e_D] (n_g, n_g)
    own: NDArray[np.float64]  # Cov(o_j) of each output's own mode coefficients (n_out, p, p)
    own_d: NDArray[np.float64]  # the part of the outputs' own noise D in it (n_out, p, p)
    cross: NDArray[np.float64]  # Cov(o_j, z) (n_out, p, n_g)


def _shape_sums(
    fitter: ModalFitter,
    pr: _Projection,
    rows: Callable[[slice], NDArray[np.float64]],
    variance: NDArray[np.float64],
    input_noise: NDArray[np.float64],
    didx: NDArray[np.intp],
    res_model: NDArray[np.complex128],
) -> _Sums:
    """The second moments of eq. (S2) (:func:`sandwich_shapes`) under ``Sigma_f = D_f +
    r_f h_f h_f^H``, the common part by eq. (2) and (3), two passes over each block
    of lines (the common part's sums over the outputs first)."""
    n_out, n_in, q = fitter.n_out, fitter.n_in, pr.q
    n_par, m = pr.th.size, len(pr.ref)
    p = 2 * m if fitter.kind == "complex" else m
    ng = n_par + didx.size * q
    v = np.asarray(variance, dtype=float)
    a, bg = np.zeros((n_par, n_par)), np.zeros((ng, ng))
    own, cross = np.zeros((n_out, p, p)), np.zeros((n_out, p, ng))
    own_d = np.zeros((n_out, p, p))
    model = np.asarray(res_model)

    def scores(j: int, jac: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
        z = np.zeros((jac.shape[0], ng))
        z[:, :n_par] = jac
        for i in np.flatnonzero(didx == j):
            z[:, n_par + i * q : n_par + (i + 1) * q] = x
        return z

    for sl in pr.parts:
        nb = _count(fitter, sl)
        om = _noise_weights(fitter, rows, sl)
        h = model[:, :, sl]
        r = np.asarray(input_noise[:, sl], dtype=float)
        rr = (r / 2.0)[..., None]
        ug, vg = np.zeros((n_in, nb, ng)), np.zeros((n_in, nb, ng))
        dd = []
        for j, (jac, x) in enumerate(_outputs(fitter, pr, rows, sl, True)):
            a += jac.T @ jac
            w = om[:, j].reshape(n_in, nb)
            dd.append(_own_noise(v[j][:, sl], r, h[j], w))  # D_f, the outputs' own noise
            z = scores(j, jac, x)
            bg += (z * dd[j]).T @ z  # eq. (3), the diagonal D
            u1, v1 = _common(z, h[j].real * w, h[j].imag * w)
            ug += u1
            vg += v1
        bg += _rank_two(ug, vg, ug, vg, rr)
        for j, (jac, x) in enumerate(_outputs(fitter, pr, rows, sl, True)):
            w = om[:, j].reshape(n_in, nb)
            xm, z = x[:, :p], scores(j, jac, x)
            own_d[j] += (xm * dd[j]).T @ xm
            own[j] += (xm * dd[j]).T @ xm
            cross[j] += (xm * dd[j]).T @ z
            u1, v1 = _common(xm, h[j].real * w, h[j].imag * w)
            own[j] += _rank_two(u1, v1, u1, v1, rr)
            cross[j] += _rank_two(u1, v1, ug, vg, rr)
    return _Sums(a, bg, own, own_d, cross)


def _model(fitter: ModalFitter, res: FitResult, pr: _Projection) -> NDArray[np.complex128]:
    """The fitted FRFs ``h`` (n_out, n_in, n_f): the fit's, or of the projection's
    coefficients where the fit kept none."""
    if res.model.shape == (fitter.n_out, fitter.n_in, fitter.n_f):
        return np.asarray(res.model)
    c = np.column_stack([sj[:, 0] for sj in pr.sol])
    return np.asarray(_basis.synth(fitter, pr.th, len(pr.ref), pr.ref, c))


def sandwich_shapes(
    fitter: ModalFitter,
    res: FitResult,
    out_weights: NDArray[np.float64] | None,
    variance: NDArray[np.float64],
    input_noise: NDArray[np.float64],
    scale: float = 1.0,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The sandwich covariance of ``theta`` and the standard errors of the shapes at the
    outputs and at the inputs under ``Sigma_f = D_f + r_f h_f h_f^H`` (module docstring).

    Given ``theta`` the coefficients are linear in the data: ``d C_j = K_j W_j e_j +
    M_j d theta`` with ``K_j = G_j^-1 (W_j Phi)^T`` and ``M_j = -X_j S_j^T`` (the
    derivative of the projection's solution, Golub & Pereyra 1973, Kaufman's
    approximation), and ``d theta = A^-1 J^T W e`` (the linearised estimate of eq.
    (1)). The global quantities ``G = [theta, C_D]`` (the drive outputs'
    coefficients, which fix the scale ``b`` of
    :func:`~tyredamp.modal.fit._scaling.scale_jacobian`) are then ``d G = T z`` with
    the scores ``z = [J^T W e, K_D W e_D]`` and ``T = [[A^-1, 0], [M_D A^-1, I]]``;
    each output's own mode coefficients ``o_j = K_j W_j e_j`` add to the shape::

        d psi_jn = alpha_n^T o_j + g_jn^T d G,   g_jn = b_n M_j[n] (theta part)
                                                      + u_jn d b_n / d G           (S1)
        E|d psi_jn|^2 = alpha^H Cov(o_j) alpha + g^H T Cov(z) T^T g
                        + 2 Re(alpha^H Cov(o_j, z) T^T g)                          (S2)

    (``alpha_n`` the mode's coefficient rows times ``b_n``: ``b_n (e_re + i e_im)`` for
    complex modes; ``u_jn`` the unscaled shape). The second moments of (S2) sum
    the outputs' own noise ``D`` row by row and the common part by eq. (2) and (3)
    with the functionals in place of ``J`` (the delta method under White's
    sandwich, White 1980, eq. (3); Pintelon & Schoukens 2012, sec. 7.2.4). With
    ``r = 0`` and ``W diag(V) W = I`` it is the delta method of
    :func:`~tyredamp.modal.fit._scaling.shape_std` with ``s^2 = 1``. ``psi_in`` from
    ``Cov(G)`` as :func:`~tyredamp.modal.fit._scaling.input_shape_std`. Arguments as
    :func:`sandwich_covariance`; ``scale`` multiplies every covariance (the fit's
    Fisher scale).

    The common part of the noise lies along the mode's shape: the entries' errors
    are correlated across outputs, which a consumer that takes them independent
    (a harmonic fit of the shape, a modal mass from its amplitude) does not see.
    For the shape's amplitude along itself, the weighted least-squares projection
    ``a_n = sum_j lambda_jn d psi_jn`` with ``lambda_jn = conj(psi_jn) / s_jn^2 /
    sum_k |psi_kn|^2 / s_kn^2`` (``s`` the standard errors of (S2)), the ratio::

        kappa_n = E|a_n|^2 / Var_ind(a_n),   Var_ind(a_n) = 1 / sum_j |psi_jn|^2 / s_jn^2   (S3)

    is the factor of its variance over the one the independent entries give
    (``E|a_n|^2`` from the same second moments, the own parts' common noise summed
    over the outputs in a third pass over the lines; the generalised least-squares
    variance of a weighted mean, Seber & Lee, *Linear Regression Analysis*, 2nd ed.
    2003, sec. 3.10).

    Returns
    -------
    cov, std_psi_out, std_psi_in, kappa : ndarray
        The covariance of ``theta`` (n_par, n_par; :func:`sandwich_covariance` times
        ``scale``), ``sqrt(E|d psi|^2)`` of each entry (n_out, m) and (n_in, m) (units
        of the fit's data over the square root of a modal mass with a drive point; of
        the data without) and ``kappa`` of (S3) (m,).
    """
    n_out = fitter.n_out
    v = np.asarray(variance, dtype=float)
    rows = _rows(fitter, v, out_weights)
    pr = _project(fitter, res, rows)
    didx = np.array([j for j, _ in fitter.drive], dtype=np.intp)
    model = _model(fitter, res, pr)
    sums = _shape_sums(fitter, pr, rows, v, input_noise, didx, model)
    th, ref, q, m = pr.th, pr.ref, pr.q, len(pr.ref)
    n_par, nd = th.size, didx.size
    ainv = np.asarray(np.linalg.pinv(0.5 * (sums.a + sums.a.T), hermitian=True), np.float64)
    mj = [-sj[:, 1:] @ s_.T for sj, s_ in zip(pr.sol, pr.s, strict=True)]  # M_j (q, n_par)
    t = np.eye(n_par + nd * q)
    t[:n_par, :n_par] = ainv
    for i, d in enumerate(didx):
        t[n_par + i * q : n_par + (i + 1) * q, :n_par] = mj[d] @ ainv
    cov_g = scale * t @ (0.5 * (sums.bg + sums.bg.T)) @ t.T
    c = np.column_stack([sj[:, 0] for sj in pr.sol])  # the coefficients (q, n_out)
    b = fitter._scale(th, m, ref, c[:, didx].T, np.ones(nd))[0]
    u = coefficient_parts(fitter, c, m)[0]
    beta = fitter._scale_jacobian(th, m, ref, c[:, didx].T, np.ones(nd))
    if nd == 0:  # the scale of real modes' shapes, 1 / sqrt(2 i Omega), held
        beta = np.zeros((n_par, m), complex)
    cplx = fitter.kind == "complex"
    alpha = np.zeros((m, sums.own.shape[1]), complex)  # b_n (e_re + i e_im) or b_n e_n
    ar = np.arange(m)
    if cplx:
        alpha[ar, 2 * ar], alpha[ar, 2 * ar + 1] = b, 1j * b
    else:
        alpha[ar, ar] = b
    crs = scale * sums.cross @ t.T  # Cov(o_j, G) (n_out, p, n_g)
    g = u[:, :, None] * beta.T[None, :, :]  # g_jn of eq. (S1) (n_out, m, n_g)
    for j in range(n_out):
        mrow = mj[j][0 : 2 * m : 2] + 1j * mj[j][1 : 2 * m : 2] if cplx else mj[j][:m] + 0j
        g[j, :, :n_par] += b[:, None] * mrow
    var = (
        scale * np.real(np.einsum("np,jpk,nk->jn", alpha.conj(), sums.own, alpha))
        + np.real(np.einsum("jnk,kl,jnl->jn", g.conj(), cov_g, g))
        + 2.0 * np.real(np.einsum("np,jpk,jnk->jn", alpha.conj(), crs, g))
    )
    std = np.sqrt(np.maximum(var, 0.0))
    psi = u * b[None, :]
    k_own, k_glob = _amplitude_ratio(
        fitter, pr, rows, (v, input_noise, didx, model), sums, (psi, std, alpha, g, crs, cov_g)
    )
    kappa = scale * k_own + k_glob  # the own part's E|Q|^2 was summed unscaled
    std_in = input_std_given(fitter, th, m, ref, cov_g, beta, b, bool(nd))
    return np.asarray(cov_g[:n_par, :n_par]), std, std_in, np.asarray(kappa)


def _amplitude_ratio(
    fitter: ModalFitter,
    pr: _Projection,
    rows: Callable[[slice], NDArray[np.float64]],
    noise: tuple[Any, ...],
    sums: _Sums,
    entries: tuple[NDArray[Any], ...],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The two parts of ``E|a_n|^2 / Var_ind(a_n)`` (own, global; their sum after the
    own part is scaled) for each mode's amplitude along its shape (eq. (S3),
    :func:`sandwich_shapes`): a third pass over the lines for the own parts' common
    noise summed over the outputs. ``noise`` = (V, r, drive outputs, model h);
    ``entries`` = (psi, std, alpha, g, Cov(o_j, G), Cov(G)) of eq. (S1)-(S2)."""
    _, input_noise, _, model = noise
    psi, std, alpha, g, crs, cov_g = entries
    n_in = fitter.n_in
    m = psi.shape[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        info = np.abs(psi) ** 2 / std**2
        info = np.where(np.isfinite(info), info, 0.0)
        tot = np.sum(info, axis=0)
        lam = np.where(std > 0, np.conj(psi) / std**2, 0.0) / np.where(tot > 0, tot, 1.0)
    c = lam[:, :, None] * alpha[None, :, :]  # c_jn = lambda_jn alpha_n (n_out, m, p)
    y = np.concatenate([c.real, c.imag], axis=1)  # (n_out, 2m, p): Re Q_n and Im Q_n
    own = np.einsum("jap,jpk,jak->a", y, sums.own_d, y)  # the outputs' own noise D
    for sl in pr.parts:
        nb = _count(fitter, sl)
        om = _noise_weights(fitter, rows, sl)
        h = model[:, :, sl]
        rr = (np.asarray(input_noise[:, sl], dtype=float) / 2.0)[..., None]
        uq, vq = np.zeros((n_in, nb, 2 * m)), np.zeros((n_in, nb, 2 * m))
        for j, (_, x) in enumerate(_outputs(fitter, pr, rows, sl, True)):
            w = om[:, j].reshape(n_in, nb)
            u1, v1 = _common(x[:, : y.shape[2]] @ y[j].T, h[j].real * w, h[j].imag * w)
            uq += u1
            vq += v1
        own += np.sum(rr * (uq**2 + vq**2), axis=(0, 1))  # eq. (3), the common part
    own_q = own[:m] + own[m:]  # E|Q_n|^2 (unscaled)
    gam = np.einsum("jn,jnk->nk", lam, g)  # Gamma_n = sum_j lambda_jn g_jn (m, n_g)
    glob = np.real(np.einsum("nk,kl,nl->n", gam.conj(), cov_g, gam))
    glob = glob + 2.0 * np.real(np.einsum("jnp,jpk,nk->n", c.conj(), crs, gam))
    with np.errstate(divide="ignore", invalid="ignore"):
        ind = np.where(tot > 0, 1.0 / tot, np.nan)  # Var_ind(a_n)
        return np.asarray(own_q / ind), np.asarray(glob / ind)
