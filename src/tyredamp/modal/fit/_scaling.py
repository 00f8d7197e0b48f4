"""Mass-normalised scaling of a modal fit and the standard errors of its shapes.

Functions of a :class:`~tyredamp.modal.fit.fit.ModalFitter` (its methods
``_scale``, ``_scale_jacobian`` and ``_shape_std``); the equations are stated
in the docstring of :mod:`tyredamp.modal.fit.fit` (scaling, uncertainty).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import lapack

from ._state import FitterState


def scale(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    cd_w: NDArray[np.float64],
    wd: NDArray[np.float64],
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.float64]]:
    """Scale factors ``b`` (m,) with ``psi_out = u b``; ``psi_in`` (n_in, m); ``a^2`` check.

    ``cd_w`` (n_drive, q) are the weighted coefficients of the drive outputs.
    """
    poles, part = fitter.unpack(th, m, ref)
    if fitter.kind == "complex":
        ud = np.asarray(
            (cd_w[:, 0 : 2 * m : 2] + 1j * cd_w[:, 1 : 2 * m : 2]) / wd[:, None], complex
        )
    else:
        ud = np.asarray(cd_w[:, :m] / wd[:, None], complex)
    if ud.shape[0] == 0:
        a = np.ones(m, complex)
        a2r = np.ones(m)
    else:
        ks = np.array([k for _, k in fitter.drive])
        lk = part[:, ks].T  # (n_drive, m)
        den = np.sum(np.abs(ud) ** 2, axis=0)
        a2 = np.sum(np.conj(ud) * lk, axis=0) / np.where(den > 0, den, 1.0)
        a2r = a2.real.copy()
        a = np.sqrt(np.abs(a2.real)) + 0j if fitter.kind == "real" else np.sqrt(a2)
        a = np.where(a == 0, 1.0, a)
    psi_in = (part / a[:, None]).T
    b = a.copy()
    if fitter.kind == "real":
        root = np.sqrt(2j * poles.imag)
        b = a / root
        psi_in = psi_in / root[None, :]
    return b, psi_in, a2r


def scale_jacobian(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    cd_w: NDArray[np.float64],
    wd: NDArray[np.float64],
) -> NDArray[np.complex128]:
    """``d b / d G`` (n_par + n_drive q, m) of :meth:`_scale`, analytically.

    ``G = [theta, cd_w.ravel()]``. With ``a^2 = N / den``, ``N = sum_d conj(u_d)
    l_{k_d}``, ``den = sum_d |u_d|^2`` (``u_d = cd_w[d] / wd[d]``):
    ``d a^2 / d Re u_d = (l - 2 a^2 Re u_d) / den``, ``d a^2 / d Im u_d =
    (-i l - 2 a^2 Im u_d) / den``, ``d a^2 / d l_k = sum_{d: k_d = k} conj(u_d)
    / den``; complex modes ``b = a = sqrt(a^2)``, real modes ``a = |Re
    a^2|^(1/2)`` and ``b = a / sqrt(2 i Omega)``.
    """
    n_par = th.size
    nd, q = cd_w.shape
    beta = np.zeros((n_par + nd * q, m), complex)
    if nd == 0:
        return beta
    poles, part = fitter.unpack(th, m, ref)
    ks = np.array([k for _, k in fitter.drive], dtype=np.intp)
    cplx = fitter.kind == "complex"
    if cplx:
        u_raw = (cd_w[:, 0 : 2 * m : 2] + 1j * cd_w[:, 1 : 2 * m : 2]) / wd[:, None]
    else:
        u_raw = cd_w[:, :m] / wd[:, None]
    ud = np.asarray(u_raw, dtype=complex)
    lk = part[:, ks].T  # (nd, m)
    den = np.sum(np.abs(ud) ** 2, axis=0)
    den = np.where(den > 0, den, 1.0)
    a2 = np.sum(np.conj(ud) * lk, axis=0) / den
    d_re = (lk - 2 * a2[None, :] * ud.real) / den[None, :]
    d_im = (-1j * lk - 2 * a2[None, :] * ud.imag) / den[None, :]
    d_l = np.zeros((m, fitter.n_in), complex)  # d a^2 / d l_k (a real l_k step)
    for d, k in enumerate(ks):
        d_l[:, k] += np.conj(ud[d]) / den
    if cplx:
        a = np.sqrt(a2)
        fac = np.where(a == 0, 0.0, 0.5 / np.where(a == 0, 1.0, a))  # d a / d a^2

        def conv(x: NDArray[np.complex128]) -> NDArray[np.complex128]:
            return np.asarray(fac * x)

    else:
        a = np.sqrt(np.abs(a2.real))
        root = np.sqrt(2j * poles.imag)
        sgn = np.sign(a2.real)
        fac_r = np.where(a == 0, 0.0, 0.5 * sgn / np.where(a == 0, 1.0, a))

        def conv(x: NDArray[np.complex128]) -> NDArray[np.complex128]:
            return np.asarray(fac_r * x.real / root)

        b = np.where(a == 0, 1.0, a) / root
        ar = np.arange(m)
        beta[2 * ar + 1, ar] = -b * fitter.w_ref / (2 * poles.imag)
    ar = np.arange(m)
    for d in range(nd):
        base = n_par + d * q
        if cplx:
            beta[base + 2 * ar, ar] = conv(d_re[d]) / wd[d]
            beta[base + 2 * ar + 1, ar] = conv(d_im[d]) / wd[d]
        else:
            beta[base + ar, ar] = conv(d_re[d]) / wd[d]
    i = 2 * m
    for n in range(m):
        for k in range(fitter.n_in):
            if k == ref[n]:
                continue
            beta[i, n] = conv(d_l[:, k])[n]
            i += 1
            if cplx:  # imaginary part of l_k
                beta[i, n] = conv(1j * d_l[:, k])[n]
                i += 1
    return beta


def shape_std(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    w: NDArray[np.float64],
    sol: dict[str, Any],
    cth: NDArray[np.float64],
    s2: float,
    b: NDArray[np.complex128],
    u: NDArray[np.complex128],
    didx: NDArray[np.intp],
) -> NDArray[np.float64]:
    """``sqrt(E|d psi_out|^2)`` per entry (n_out, m) by the delta method."""
    C = sol["C"]
    q = C.shape[0]
    n_par = th.size
    nd = didx.size
    F, M, MC = _coefficient_sensitivity(sol, cth)
    # Var of the coefficient of mode n for output j
    cov_cc_diag = s2 * np.diag(F)[None, :] + np.einsum("jak,jak->ja", MC, M)
    if fitter.kind == "complex":
        var_u = cov_cc_diag[:, 0 : 2 * m : 2] + cov_cc_diag[:, 1 : 2 * m : 2]
    else:
        var_u = cov_cc_diag[:, :m]
    term1 = np.abs(b[None, :]) ** 2 * var_u / w[:, None] ** 2
    if nd == 0:
        # unscaled shapes: only the coefficient noise and the participation
        return np.asarray(np.sqrt(np.maximum(term1, 0.0)))
    # global quantities G = [theta, C_D (n_d * q)] and d b / d G
    beta = scale_jacobian(fitter, th, m, ref, C[:, didx].T, w[didx])
    MD = M[didx]  # (nd, q, n_par)
    sgg = _global_cov(cth, MC[didx], MD, s2, F)
    v3 = np.real(np.sum(beta.conj() * (sgg @ beta), axis=0))
    term3 = np.abs(u) ** 2 * v3[None, :]
    # cross_jn = sum_g Sigma_cG_j[a_n, g] beta[g, n] with Sigma_cG_j = [MC_j,
    # MC_j MD^T + s2 F (j = drive)] (a_n the coefficient rows of mode n), summed
    # without forming the (n_out, q, ng) matrix: T = beta_theta + MD^T beta_D
    beta_d = beta[n_par:]  # (nd q, m)
    T = beta[:n_par] + MD.reshape(nd * q, n_par).T @ beta_d  # (n_par, m)
    bd = beta_d.reshape(nd, q, m)
    fb = s2 * np.matmul(F, bd)  # (nd, q, m)
    rsel = (
        [np.arange(0, 2 * m, 2), np.arange(1, 2 * m, 2)]
        if fitter.kind == "complex"
        else [np.arange(m)]
    )
    cross = np.zeros((fitter.n_out, m), complex)
    for sign, rr in zip((1.0, -1j), rsel, strict=False):
        part_ = np.einsum("jnk,kn->jn", MC[:, rr, :], T)
        for i, j in enumerate(didx):
            part_[j] += fb[i, rr, np.arange(m)]
        cross += sign * part_
    term2 = 2 * np.real(np.conj(b)[None, :] / w[:, None] * u * cross)
    return np.asarray(np.sqrt(np.maximum(term1 + term2 + term3, 0.0)))


def _coefficient_sensitivity(
    sol: dict[str, Any], cth: NDArray[np.float64], rows: NDArray[np.intp] | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``F = (Phi^T Phi)^-1`` (q, q), ``M_j = -Phi^+ dPhi/dtheta C_j`` and
    ``Cov(C_j, theta) = M_j cth`` (each (n_rows, q, n_par)) of the outputs ``rows``
    (default all) of the projection's solution ``sol``:
    ``M[j, a, k] = -sum_d E[a, d] C[dcol_d, j] A[d, k]`` with ``E = Phi^+ D``."""
    C, lay = sol["C"], sol["lay"]
    rinv = lapack.dtrtri(sol["R"])[0]
    F = rinv @ rinv.T
    E = rinv @ (sol["QtE"][:, lay.ecol] * sol["coef"][None, :])  # Phi^+ D, (q, n_d)
    cd = C[lay.dcol] if rows is None else C[lay.dcol][:, rows]
    ec = E[None, :, :] * cd.T[:, None, :]  # (n_rows, q, n_d)
    n_rows, q = ec.shape[:2]
    n_par = cth.shape[0]
    M = -(ec.reshape(n_rows * q, -1) @ lay.A).reshape(n_rows, q, n_par)
    MC = (M.reshape(n_rows * q, n_par) @ cth).reshape(M.shape)
    return F, M, MC


def _global_cov(
    cth: NDArray[np.float64],
    cdt: NDArray[np.float64],
    MD: NDArray[np.float64],
    s2: float,
    F: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Covariance of ``G = [theta, C_D]``: the parameters and the drive outputs'
    coefficients (``cdt = Cov(C_D, theta)`` and ``MD = -Phi^+ dPhi/dtheta C_D``,
    each (n_d, q, n_par); ``F = (Phi^T Phi)^-1``)."""
    nd, q, n_par = cdt.shape
    ng = n_par + nd * q
    sgg = np.zeros((ng, ng))
    sgg[:n_par, :n_par] = cth
    sgg[n_par:, :n_par] = cdt.reshape(nd * q, n_par)
    sgg[:n_par, n_par:] = sgg[n_par:, :n_par].T
    dd = cdt.reshape(nd * q, n_par) @ MD.reshape(nd * q, n_par).T  # MD cth MD^T
    dd += s2 * np.kron(np.eye(nd), F)
    sgg[n_par:, n_par:] = dd
    return sgg


def input_shape_std(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    w: NDArray[np.float64],
    sol: dict[str, Any],
    cth: NDArray[np.float64],
    s2: float,
    b: NDArray[np.complex128],
    didx: NDArray[np.intp],
) -> NDArray[np.float64]:
    """``sqrt(E|d psi_in|^2)`` per entry (n_in, m) by the delta method.

    ``psi_in[k, n] = l_kn c_n`` with the participation ``l`` (parameters of
    ``theta``; the reference input's is 1) and the scale ``c_n = 1 / b_n``
    (complex modes) or ``1 / (b_n 2 i Omega_n)`` (real modes, ``psi = phi /
    sqrt(2 i Omega)``), :func:`scale`. Over ``G = [theta, C_D]`` (the drive
    outputs' coefficients fix ``b``, :func:`scale_jacobian`):
    ``d psi_in[k, n] = c_n (d l_kn - l_kn (d b_n / b_n + d Omega_n / Omega_n))``
    (the last term for real modes only) and ``E|d psi|^2 = Re(g^H Sigma_GG g)``.
    Without a drive point ``c_n = 1`` (complex) and only ``theta`` counts.
    """
    n_par = th.size
    if didx.size:
        F, MD, MC = _coefficient_sensitivity(sol, cth, didx)
        sgg = _global_cov(cth, MC, MD, s2, F)
        beta = scale_jacobian(fitter, th, m, ref, sol["C"][:, didx].T, w[didx])
    else:
        sgg, beta = cth, np.zeros((n_par, m), complex)
    return input_std_given(fitter, th, m, ref, sgg, beta, b, bool(didx.size))


def input_std_given(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    sgg: NDArray[np.float64],
    beta: NDArray[np.complex128],
    b: NDArray[np.complex128],
    drive: bool,
) -> NDArray[np.float64]:
    """``sqrt(E|d psi_in|^2)`` (n_in, m) of :func:`input_shape_std` from a given covariance
    ``sgg`` of ``G = [theta, C_D]`` (or of ``theta`` alone without a drive point, then
    ``beta`` is zero) and ``beta = d b / d G`` (:func:`scale_jacobian`)."""
    poles, part = fitter.unpack(th, m, ref)
    cplx = fitter.kind == "complex"
    omega = poles.imag
    if drive:
        bb = np.where(b == 0, 1.0, b)
        c = 1.0 / bb if cplx else 1.0 / (bb * 2j * omega)
    else:
        bb = np.ones(m, complex)
        c = np.ones(m, complex) if cplx else 1.0 / np.sqrt(2j * omega)
    out = np.zeros((fitter.n_in, m))
    idx = 2 * m
    for n in range(m):
        ln = part[n]
        dlog = -beta[:, n] / bb[n]
        if not cplx:  # d ln Omega of 1 / (2 i Omega), or of 1 / sqrt(2 i Omega) without b
            dlog[2 * n + 1] -= (1.0 if drive else 0.5) * fitter.w_ref / omega[n]
        for k in range(fitter.n_in):
            g = ln[k] * dlog
            if k != ref[n]:
                g[idx] += 1.0
                idx += 1
                if cplx:
                    g[idx] += 1j
                    idx += 1
            g = c[n] * g
            out[k, n] = np.sqrt(max(float(np.real(np.conj(g) @ (sgg @ g))), 0.0))
    return out


def pole_std(
    w_ref: float, th: NDArray[np.float64], m: int, cth: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128]]:
    """Standard errors of f (Hz), zeta and the pole (rad/s) of the ``m`` modes by the
    delta method from the covariance ``cth`` of the parameters ``th`` (poles first:
    ``sigma = w_ref exp(x1)``, ``Omega = w_ref x2``, the pole parametrisation of
    :class:`~tyredamp.modal.fit.fit.ModalFitter`)."""
    ar = np.arange(m)
    sig = w_ref * np.exp(th[0 : 2 * m : 2])
    om = w_ref * th[1 : 2 * m : 2]
    mag = np.hypot(sig, om)
    v11 = cth[2 * ar, 2 * ar]
    v22 = cth[2 * ar + 1, 2 * ar + 1]
    v12 = cth[2 * ar, 2 * ar + 1]
    # d|p|/dx1 = sig^2 / |p|, d|p|/dx2 = w_ref om / |p|; zeta = sig / |p|
    a1, a2 = sig * sig / mag / (2 * np.pi), w_ref * om / mag / (2 * np.pi)
    z1, z2 = om**2 * sig / mag**3, -sig * om * w_ref / mag**3
    var_f = a1 * a1 * v11 + 2 * a1 * a2 * v12 + a2 * a2 * v22
    var_z = z1 * z1 * v11 + 2 * z1 * z2 * v12 + z2 * z2 * v22
    std_p = np.sqrt(np.maximum(v11, 0)) * sig + 1j * np.sqrt(np.maximum(v22, 0)) * w_ref
    return np.sqrt(np.maximum(var_f, 0.0)), np.sqrt(np.maximum(var_z, 0.0)), std_p
