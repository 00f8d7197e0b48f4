"""The outcome of a modal fit: :class:`FitResult` and its assembly at the optimum.

Functions of a :class:`~tyredamp.modal.fit.fit.ModalFitter` (its methods
``_pole_std`` and ``_result``) that turn the parameters and the linear
coefficients at the end of a fit into a :class:`FitResult`: the mass-normalised
shapes and residual terms (:mod:`._scaling`), the Gauss-Newton standard errors
by the delta method, the fitted FRFs, each mode's contribution and its
extra-sum-of-squares significance. The equations are stated in the docstring
of :mod:`tyredamp.modal.fit.fit` (scaling, uncertainty).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _basis, _scaling
from ._linalg import _extra_ss
from ._state import FitterState

__all__ = ["FitResult", "assemble", "pole_and_shape_std"]


@dataclass
class FitResult:
    """Outcome of one fit (internal layout; :mod:`identify` turns it into a ModalModel).

    All shapes refer to ``m`` modes, ``n_out`` outputs and ``n_in`` inputs.
    """

    poles: NDArray[np.complex128]
    psi_out: NDArray[np.complex128]
    psi_in: NDArray[np.complex128]
    upper: NDArray[np.float64] | None
    lower: NDArray[np.float64] | None
    std_frequency_hz: NDArray[np.float64]
    std_damping_ratio: NDArray[np.float64]
    std_psi_out: NDArray[np.float64]
    std_pole: NDArray[np.complex128]
    model: NDArray[np.complex128]  # fitted FRFs in the data's kind (empty for intermediate fits)
    sigma_out: NDArray[np.float64]
    cost: float
    n_iter: int
    status: str
    warnings: list[str] = field(default_factory=list)
    contribution: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    #: extra-sum-of-squares statistic of each mode (:func:`_extra_ss` / s^2)
    significance: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    #: number of (weighted) real observations and of fitted parameters
    n_obs: int = 0
    n_par: int = 0
    theta: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    participation: NDArray[np.complex128] = field(default_factory=lambda: np.zeros((0, 0), complex))
    drive_phi2: NDArray[np.complex128] = field(default_factory=lambda: np.zeros(0, complex))
    #: not filled any more (the fits keep no per-line array); kept for compatibility
    projection: tuple[Any, ...] | None = None
    #: ``(weights, tol)`` of an intermediate one-pass refinement that stopped at
    #: rest here: the same refinement started at this result stops at once
    #: (``ModalFitter.fit(..., start=this)``); None when not known to be at rest
    rest: tuple[NDArray[np.float64], float] | None = None
    #: standard errors of ``psi_in`` (n_in, m; magnitude of the complex error),
    #: empty when not computed
    std_psi_in: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))
    #: 95 % intervals of the in-band modes' f and zeta (fit order;
    #: :class:`~tyredamp.modal.fit.profile.Intervals`), set by the final stage
    intervals: Any = None


def pole_and_shape_std(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    w: NDArray[np.float64],
    sol: dict[str, Any],
    s2: float,
    shapes: tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.intp]],
    uncertainty: bool,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.complex128],
    NDArray[np.float64],
    NDArray[np.float64],
]:
    """Standard errors of f, zeta, the pole and the shapes at the outputs and at
    the inputs (NaN without ``uncertainty``): Gauss-Newton covariance ``s^2
    (J^T J)^-1`` at the optimum and the delta method."""
    b, u, didx = shapes
    n_par = th.size
    nan = np.full(m, np.nan)
    std_f, std_z, std_pole = nan, nan.copy(), nan + 0j
    std_psi = np.full((fitter.n_out, m), np.nan)
    std_in = np.full((fitter.n_in, m), np.nan)
    if uncertainty:
        jtj = sol["jtj"] if "jtj" in sol else fitter._normal(sol, n_par)[0]
        cth = s2 * np.linalg.pinv(jtj, hermitian=True)
        std_f, std_z, std_pole = _scaling.pole_std(fitter.w_ref, th, m, cth)
        std_psi = _scaling.shape_std(fitter, th, m, ref, w, sol, cth, s2, b, u, didx)
        std_in = _scaling.input_shape_std(fitter, th, m, ref, w, sol, cth, s2, b, didx)
    return std_f, std_z, std_pole, std_psi, std_in


def coefficient_parts(
    fitter: FitterState, C: NDArray[np.float64], m: int
) -> tuple[NDArray[np.complex128], NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """The unscaled output shapes ``u`` (n_out, m) and the upper and lower
    residual terms (n_out, n_in, or None when not fitted) from the linear
    coefficients ``C`` (n_col, n_out) of the projection: per mode the real and
    imaginary parts of its column (complex modes) or its real column (real
    modes), then the residual terms' columns."""
    complex_modes = fitter.kind == "complex"
    u = C[0 : 2 * m : 2].T + 1j * C[1 : 2 * m : 2].T if complex_modes else C[:m].T + 0j
    off = (2 if complex_modes else 1) * m
    upper = lower = None
    if fitter.use_upper:
        upper = C[off : off + fitter.n_in].T.copy()
        off += fitter.n_in
    if fitter.use_lower:
        lower = C[off : off + fitter.n_in].T.copy()
    return np.asarray(u, dtype=np.complex128), upper, lower


def drive_phi2(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    psi_out: NDArray[np.complex128],
    psi_in: NDArray[np.complex128],
) -> NDArray[np.complex128]:
    """``2 i Omega_n R_kkn`` (m,) averaged over the drive points (output ``j`` at
    input ``k`` of ``fitter.drive``): ``phi_kn^2`` for a real mode (eq. [3])."""
    out = np.array([j for j, _ in fitter.drive], dtype=np.intp)
    kin = np.array([k for _, k in fitter.drive], dtype=np.intp)
    return np.asarray(
        np.mean(2j * poles.imag[None, :] * psi_out[out] * psi_in[kin], axis=0), np.complex128
    )


def assemble(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    w: NDArray[np.float64],
    sol: dict[str, Any],
    sig_out: NDArray[np.float64],
    nit: int,
    status: str,
    warn: list[str],
    uncertainty: bool = True,
) -> FitResult:
    """The :class:`FitResult` of parameters ``th`` (``m`` modes) and the solution
    ``sol`` of the projection at the optimum (weights ``w`` per output)."""
    n_par = th.size
    C = sol["C"]
    q = C.shape[0]
    Cu = C / w[None, :]
    poles, _ = fitter.unpack(th, m, ref)
    didx = np.array([j for j, _ in fitter.drive], dtype=np.intp)
    wd = w[didx]
    b, psi_in, a2r = _scaling.scale(fitter, th, m, ref, C[:, didx].T, wd)
    u, upper, lower = coefficient_parts(fitter, Cu, m)
    psi_out = u * b[None, :]
    if didx.size == 0:
        warn.append("no drive point (output at an input): shapes are not mass-normalised")
        phi2 = np.full(m, np.nan + 0j)
    else:
        phi2 = drive_phi2(fitter, poles, psi_out, psi_in)
    for n in range(m):
        f_n = abs(poles[n]) / (2 * np.pi)
        if didx.size and fitter.kind == "real" and a2r[n] <= 0:
            warn.append(
                f"mode at {f_n:.2f} Hz: drive-point residue gives phi^2 = 2 i Omega R_kk "
                "<= 0 (not real positive); shape scaled with |phi^2|"
            )
        if didx.size and fitter.kind == "complex" and phi2[n].real <= 0:
            warn.append(
                f"mode at {f_n:.2f} Hz: drive-point residue has Re(2 i Omega R_kk) <= 0 "
                "(negative modal mass); check the drive point and the mode"
            )
    # ---- uncertainty (Gauss-Newton at the optimum + delta method)
    n_obs = fitter.n_rows * fitter.n_out
    dof = max(n_obs - q * fitter.n_out - n_par, 1)
    s2 = sol["cost"] / dof
    std_f, std_z, std_pole, std_psi, std_in = pole_and_shape_std(
        fitter, th, m, ref, w, sol, s2, (b, u, didx), uncertainty
    )
    # ---- model (final fits only), contributions
    model = np.zeros((0, fitter.n_in, fitter.n_f), complex)
    if uncertainty:
        model = _basis.synth(fitter, th, m, ref, Cu)
    per = 2 if fitter.kind == "complex" else 1
    data_ss = fitter.data_ss
    # ||Phi_n C_n||^2 per output from the (per x per) Gram block of each mode's
    # columns, a diagonal block of Phi^T Phi = R^T R: no (n_rows x n_out) array
    rb = sol["R"][:, : per * m].reshape(-1, m, per)
    gram = np.matmul(rb.transpose(1, 2, 0), rb.transpose(1, 0, 2))  # (m, per, per)
    cb = C[: per * m].reshape(m, per, fitter.n_out)
    ss = np.sum(cb * np.matmul(gram, cb), axis=1)  # (m, n_out)
    contrib = np.sqrt(np.sum(ss / w[None, :] ** 2, axis=1) / max(data_ss, 1e-300))
    s2_floor = float(np.mean((w * fitter.noise_floor) ** 2))
    signif = _extra_ss(sol["R"], C, per, m) / max(s2, s2_floor, 1e-300)
    return FitResult(
        poles=poles,
        psi_out=psi_out,
        psi_in=psi_in,
        upper=upper,
        lower=lower,
        std_frequency_hz=std_f,
        std_damping_ratio=std_z,
        std_psi_out=std_psi,
        std_pole=std_pole,
        std_psi_in=std_in,
        model=model,
        sigma_out=sig_out,
        cost=float(sol["cost"]),
        n_iter=nit,
        status=status,
        warnings=warn,
        contribution=contrib,
        significance=signif,
        n_obs=n_obs,
        n_par=q * fitter.n_out + n_par,
        theta=th,
        participation=fitter.unpack(th, m, ref)[1],
        drive_phi2=phi2,
    )
