"""Fitting the flexible ring to identified modes (:func:`fit_ring`).

Stiffness and mass parameters: weighted least squares
(:func:`scipy.optimize.least_squares`) of the residuals
``(f_model - f)/sigma_f`` and ``(A_model - A)/sigma_A`` of eqs. (1)-(2)
(:mod:`~tyredamp.tyremodel.ring.model`) with the modal standard errors
(``ModalModel.std``) as ``sigma``; without them, relative weights
(``sigma = f``, ``sigma = A``) and the covariance scaled by the residual
variance. The starting values are ``rho A`` from eq. (2) (median over the
modes) and a linear least-squares solve of eq. (1) for the stiffnesses. The
parameters are scaled by their "contribution scale" (``T_c`` by the mean
tension, ``k_rp`` by ``k_r(p_mean)/p_mean`` ...), so the scaled Jacobian
compares like with like. Damping: weighted linear least squares of eq. (3)
with ``sigma = 2 omega sigma_zeta``, given the fitted ``EI`` and ``rho A``
(:mod:`~tyredamp.tyremodel.ring.damping`). Uncertainty and verdicts:
:mod:`~tyredamp.tyremodel.ring.identifiability`; with modal standard errors
the inextensible ring is tested against the extensible one and every
parameter carries that model's term (:mod:`~tyredamp.tyremodel.ring.extension`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..._validate import check_positive
from ...exceptions import ConvergenceError, InputError, PhysicsError
from ...modal.model import ModalModel
from .damping import DampingFit, damping_target, fit_damping
from .extension import Extension, admit_extension, extension_test
from .identifiability import (
    MODEL_LIMITED,
    admit_model_error,
    central_jacobian,
    chi2_scaling,
    collinearity,
    correlation,
    verdicts,
)
from .model import (
    FoundationLaw,
    ParameterLayout,
    damping_columns,
    extensible_ring,
    ring_frequency,
)
from .observations import RingObservation, gather_observations
from .result import RingFit

__all__ = ["fit_ring"]

_Array = NDArray[np.float64]


@dataclass(frozen=True)
class _Observed:
    """The observations as arrays, one entry per mode (SI)."""

    n: _Array  # wave numbers (float)
    p: _Array  # pressures, Pa
    f: _Array  # natural frequencies, Hz
    phi2: _Array  # drive-point phi_d^2, 1/kg
    amp: _Array  # mass-normalised radial amplitudes, 1/sqrt(kg)
    use_a: NDArray[np.bool_]  # amplitude usable for rho A
    share: _Array  # ring's share of the modal mass, 1 - m_a phi_d^2


@dataclass(frozen=True)
class _StiffnessProblem:
    """Weighted residuals of eqs. (1)-(2) in the scaled parameters ``u = theta / scales``."""

    x: _Observed
    layout: ParameterLayout
    radius: float
    rho_fixed: float | None  # rho A when given (None: fitted, the last parameter)
    sig_f: _Array
    sig_a: _Array
    scales: _Array  # contribution scale of each parameter
    have_std: bool  # sig_f, sig_a are the modal standard errors (else relative weights)
    n_values: int  # frequencies plus amplitudes used

    def model(self, theta: _Array, compliance: float = 0.0) -> tuple[_Array, _Array]:
        """Model frequencies (Hz) and amplitudes (1/sqrt(kg)) at the parameters ``theta``.

        ``compliance`` ``1/EA`` (1/N) > 0 evaluates the extensible ring
        (:func:`~tyredamp.tyremodel.ring.model.extensible_ring`) instead of eqs. (1)-(2).
        """
        x, r = self.x, self.radius
        ei, t0, kr, kt, rho = self.layout.unpack(theta, x.p, r)
        rho = self.rho_fixed if self.rho_fixed is not None else rho
        if compliance != 0.0:
            lam, s_r, _ = extensible_ring(
                x.n,
                radius=r,
                bending_stiffness=ei,
                tension=t0,
                radial_stiffness=kr,
                tangential_stiffness=kt,
                compliance=compliance,
            )
            fm_e = np.sqrt(np.clip(lam / rho, 0.0, None) * x.share) / (2 * np.pi)
            return fm_e, np.sqrt(s_r * x.share / (np.pi * r * rho))
        fm = ring_frequency(
            x.n,
            radius=r,
            bending_stiffness=ei,
            tension=t0,
            radial_stiffness=kr,
            tangential_stiffness=kt,
            mass_per_length=rho,
        ) * np.sqrt(x.share)
        n2 = x.n**2
        am = np.sqrt(n2 * x.share / (np.pi * r * rho * (1 + n2)))
        return fm, am

    def residual(self, u: _Array, compliance: float = 0.0) -> _Array:
        """Weighted residuals: frequencies, then the amplitudes used for ``rho A``."""
        fm, am = self.model(u * self.scales, compliance)
        parts = [(fm - self.x.f) / self.sig_f]
        if self.rho_fixed is None:
            parts.append(((am - self.x.amp) / self.sig_a)[self.x.use_a])
        return np.concatenate(parts)


@dataclass(frozen=True)
class _StiffnessFit:
    """Fitted stiffness/mass parameters with their uncertainty (SI, layout order)."""

    theta: _Array
    covariance: _Array
    stderr: _Array
    correlation: _Array
    singular_values: _Array
    verdicts: dict[str, dict[str, Any]]
    fitted_frequency_hz: _Array
    fitted_amplitude: _Array
    chi2: float
    dof: int
    p_value: float | None
    scaled: bool
    discrepancy: float | None = None
    u: _Array | None = None  # scaled solution
    cov_factor: float = 1.0  # factor applied to (J^T J)^-1


def fit_ring(
    data: Sequence[tuple[float, ModalModel]] | Sequence[RingObservation],
    *,
    radius: float,
    attachment_mass: float = 0.0,
    mass_per_length: float | None = None,
    foundation_law: FoundationLaw = "linear",
    drive_point_damper: bool = True,
    attachment_damping: float | None = None,
    band_loss_frequency: float = 200.0,
) -> RingFit:
    """Update the flexible ring to identified modes at one or several pressures.

    Parameters
    ----------
    data : sequence of (pressure, ModalModel) or of RingObservation
        Identified modes with the test pressure in Pa (labelled with
        :func:`~tyredamp.tyremodel.ring_observations`), or ready observations.
    radius : float
        Belt radius ``R`` in m (geometry, not fitted).
    attachment_mass : float
        Known point mass at each drive point in kg (default 0).
    mass_per_length : float, optional
        Known ``rho A`` in kg/m; default: fitted from the mass-normalised
        shape amplitudes, eq. (2).
    foundation_law : {"linear", "constant"}
        Pressure dependence of ``k_r`` and ``k_t`` across pressures.
    drive_point_damper : bool
        Fit the local damper ``c_d`` at the drive point(s) (eq. (3)) when
        ``attachment_damping`` is not given.
    attachment_damping : float, optional
        Known local radial damper at each drive point in N s/m; then ``c_d``
        is fixed to it instead of fitted.
    band_loss_frequency : float
        ``omega_ref / 2 pi`` in Hz for the reported band loss factor.

    Returns
    -------
    RingFit

    Raises
    ------
    InputError
        Too few usable modes for the parameters, bad options.
    ConvergenceError
        The least-squares fit did not converge.
    """
    t_start = time.perf_counter()
    r = check_positive(radius, "radius")
    m_a = check_positive(attachment_mass, "attachment_mass", allow_zero=True)
    if foundation_law not in ("linear", "constant"):
        raise InputError(f"foundation_law: expected 'linear' or 'constant', got {foundation_law!r}")
    check_positive(band_loss_frequency, "band_loss_frequency")
    c_known = None
    if attachment_damping is not None:
        c_known = check_positive(attachment_damping, "attachment_damping", allow_zero=True)
    obs, skipped = gather_observations(data)
    x = _observed(obs, m_a)
    rho_fixed = None
    if mass_per_length is not None:
        rho_fixed = check_positive(mass_per_length, "mass_per_length")
    layout = ParameterLayout(x.p, foundation_law, rho_fixed is None)
    problem, theta0 = _stiffness_problem(obs, x, layout, r, rho_fixed)
    stiff = _fit_stiffness(problem, theta0)
    ei_hat = float(stiff.theta[layout.names.index("EI")])
    rho_hat = float(stiff.theta[layout.names.index("rhoA")]) if rho_fixed is None else rho_fixed
    tgt = damping_target(obs, x.phi2, x.f, c_known, drive_point_damper)
    damp = fit_damping(damping_columns(x.n, x.phi2, ei_hat, rho_hat, r, m_a, tgt.with_cd), tgt)
    ext = None
    if problem.have_std and stiff.u is not None:
        ext = extension_test(
            problem, stiff.theta, stiff.u, stiff.covariance, stiff.cov_factor, damp.values, tgt, m_a
        )
    if ext is not None:
        stiff = replace(
            stiff,
            verdicts=admit_extension(
                stiff.verdicts, stiff.theta, stiff.stderr, ext.shift, ext.shift_sd, ext
            ),
        )
        damp = replace(
            damp,
            verdicts=admit_extension(
                damp.verdicts,
                damp.values,
                damp.stderr,
                ext.damping_shift,
                ext.damping_shift_sd,
                ext,
            ),
        )
    return _result(
        problem,
        stiff,
        damp,
        obs=obs,
        skipped=skipped,
        attachment_mass=m_a,
        attachment_damping=c_known,
        fit_time_s=time.perf_counter() - t_start,
        band_loss_frequency=float(band_loss_frequency),
        foundation_law=foundation_law,
        extension=ext,
    )


# ---------------------------------------------------------------- stiffness and mass, eqs. (1)-(2)
def _observed(obs: Sequence[RingObservation], m_a: float) -> _Observed:
    """The observations as arrays; refuses an attachment mass above a modal mass."""
    phi2 = np.array([o.drive_phi2 for o in obs])
    if np.any(m_a * phi2 >= 1):
        raise PhysicsError(
            "attachment_mass: m_a phi_d^2 >= 1 for some mode; the attachment mass exceeds the "
            "modal mass (check the mass and the shape scaling)"
        )
    return _Observed(
        n=np.array([o.n for o in obs], dtype=float),
        p=np.array([o.pressure for o in obs]),
        f=np.array([o.frequency_hz for o in obs]),
        phi2=phi2,
        amp=np.array([o.amplitude for o in obs]),
        use_a=np.array([o.use_amplitude for o in obs]),
        share=1.0 - m_a * phi2,
    )


def _stiffness_problem(
    obs: Sequence[RingObservation],
    x: _Observed,
    layout: ParameterLayout,
    r: float,
    rho_fixed: float | None,
) -> tuple[_StiffnessProblem, _Array]:
    """The weighted problem of eqs. (1)-(2) (module docstring) and its starting values.

    Raises
    ------
    InputError
        No amplitude to fix ``rho A``, or no more values than parameters.
    """
    fit_mass = rho_fixed is None
    if fit_mass and not np.any(x.use_a):
        raise InputError(
            "no mode amplitude to fix the ring's mass per length (rho A): give it "
            "(--mass-per-length, mass_per_length in Python)"
        )
    sf_list = [o.frequency_std for o in obs]
    sa_list = [o.amplitude_std for o in obs]
    have_std = all(s is not None and s > 0 for s in sf_list) and (
        not fit_mass
        or all(s is not None and s > 0 for s, u in zip(sa_list, x.use_a, strict=True) if u)
    )
    sig_f = np.array(sf_list, dtype=float) if have_std else x.f.copy()
    sig_a = (
        np.array([s if s is not None else np.nan for s in sa_list], dtype=float)
        if have_std
        else x.amp.copy()
    )
    n_res = x.n.size + (int(x.use_a.sum()) if fit_mass else 0)
    if n_res <= len(layout.names):
        raise InputError(
            f"data: {n_res} usable values (frequencies and amplitudes) for {len(layout.names)} "
            f"parameters {list(layout.names)}; identify more modes or fix parameters"
        )
    theta0, rho0 = _starting_values(x, layout, r, rho_fixed)
    problem = _StiffnessProblem(
        x=x,
        layout=layout,
        radius=r,
        rho_fixed=rho_fixed,
        sig_f=sig_f,
        sig_a=sig_a,
        scales=_contribution_scales(layout, theta0, x.p, r, rho0),
        have_std=have_std,
        n_values=n_res,
    )
    return problem, theta0


def _starting_values(
    x: _Observed, layout: ParameterLayout, r: float, rho_fixed: float | None
) -> tuple[_Array, float]:
    """``rho A`` from eq. (2) (median over the modes), then linear least squares of eq. (1)."""
    n, p, share, use_a = x.n, x.p, x.share, x.use_a
    if rho_fixed is None:
        rho_i = n[use_a] ** 2 * share[use_a] / (np.pi * r * (1 + n[use_a] ** 2) * x.amp[use_a] ** 2)
        rho0 = float(np.median(rho_i))
    else:
        rho0 = rho_fixed
    y = rho0 * (1 + n**2) * (2 * np.pi * x.f) ** 2 / share
    n2 = n**2
    g_ei = n2 * (n2 - 1) ** 2 / r**4
    g_t = n2 * (n2 - 1) / r**2
    cols: dict[str, _Array] = {"EI": g_ei}
    if layout.multi:
        cols["b"] = g_t * p * r
        cols["T_c"] = g_t
    else:
        cols["T0"] = g_t
    if "k_r0" in layout.names:
        cols.update({"k_r0": n2, "k_rp": n2 * p, "k_t0": np.ones_like(n), "k_tp": p})
    else:
        cols.update({"k_r": n2, "k_t": np.ones_like(n)})
    lin_names = [nm for nm in layout.names if nm != "rhoA"]
    x_design = np.column_stack([cols[nm] for nm in lin_names])
    wrow = 1.0 / y
    sol, *_ = np.linalg.lstsq(x_design * wrow[:, None], y * wrow, rcond=None)
    theta0 = np.concatenate([sol, [rho0]]) if rho_fixed is None else sol.copy()
    return np.asarray(theta0, dtype=np.float64), rho0


def _contribution_scales(
    layout: ParameterLayout, theta0: _Array, p: _Array, r: float, rho0: float
) -> _Array:
    """Contribution scale of each parameter at the starting values (module docstring)."""
    p_mean = float(np.mean(np.unique(p)))
    d0 = dict(zip(layout.names, theta0, strict=True))
    t_mean = abs(d0["b"] * p_mean * r + d0["T_c"]) if layout.multi else abs(d0["T0"])
    kr_mean = abs(d0["k_r0"] + d0["k_rp"] * p_mean) if "k_r0" in d0 else abs(d0["k_r"])
    kt_mean = abs(d0["k_t0"] + d0["k_tp"] * p_mean) if "k_t0" in d0 else abs(d0["k_t"])
    kt_mean = max(kt_mean, 1e-3 * kr_mean)
    sc = {
        "EI": abs(d0["EI"]),
        "T0": t_mean,
        "b": t_mean / (p_mean * r) if p_mean > 0 else 1.0,
        "T_c": t_mean,
        "k_r": kr_mean,
        "k_r0": kr_mean,
        "k_rp": kr_mean / p_mean if p_mean > 0 else 1.0,
        "k_t": kt_mean,
        "k_t0": kt_mean,
        "k_tp": kt_mean / p_mean if p_mean > 0 else 1.0,
        "rhoA": rho0,
    }
    return np.array([sc[nm] if sc[nm] > 0 else 1.0 for nm in layout.names])


def _fit_stiffness(problem: _StiffnessProblem, theta0: _Array) -> _StiffnessFit:
    """Solve the weighted least squares; covariance, correlations and verdicts at the solution.

    Raises
    ------
    ConvergenceError
        The least-squares fit did not converge.
    """
    scales = problem.scales
    residual = problem.residual
    u0 = theta0 / scales
    res = least_squares(residual, u0, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    if res.status <= 0 or not np.all(np.isfinite(res.x)):
        raise ConvergenceError(
            f"the ring model's least-squares fit did not converge ({res.message})"
        )
    u = np.asarray(res.x, dtype=float)
    rvec = residual(u)
    rss = float(rvec @ rvec)
    jac = central_jacobian(residual, u)
    dof = problem.n_values - u.size
    sv, _ = collinearity(jac)
    cov_u = np.linalg.pinv(jac.T @ jac, rcond=1e-12)
    pval, scaled = chi2_scaling(rss, dof, problem.have_std)
    # the frequencies' own reduced chi-square: a systematic frequency misfit hides in the
    # global one when the many amplitudes carry larger noise
    nf = problem.x.f.size
    dof_f = max(nf - (u.size - (1 if problem.rho_fixed is None else 0)), 1)
    disc = max(rss / dof, float(rvec[:nf] @ rvec[:nf]) / dof_f) if problem.have_std else None
    factor = 1.0
    if disc is not None and disc > MODEL_LIMITED:
        factor = disc  # Birge ratio of the worst block
        scaled = True
    elif scaled:
        factor = rss / dof
    cov_u = cov_u * factor
    theta = u * scales
    cov = np.asarray(cov_u * np.outer(scales, scales), dtype=np.float64)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    corr = correlation(cov)
    # verdict scale: the parameter itself, floored at 1 % of its contribution scale (a term
    # that is zero to within 1 % of what it modifies is determined); the tension offset T_c
    # is judged against the tension itself
    names = problem.layout.names
    vscale = np.maximum(np.abs(theta), 0.01 * scales)
    if "T_c" in names:
        vscale[names.index("T_c")] = scales[names.index("T_c")]
    fm, am = problem.model(theta)
    return _StiffnessFit(
        theta=theta,
        covariance=cov,
        stderr=se,
        correlation=corr,
        singular_values=sv,
        verdicts=admit_model_error(
            verdicts(names, se / vscale, corr, jac),
            theta,
            se,
            disc,
            int(dof_f),
        ),
        fitted_frequency_hz=fm,
        fitted_amplitude=am,
        chi2=rss,
        dof=int(dof),
        p_value=pval,
        scaled=scaled,
        discrepancy=disc,
        u=u,
        cov_factor=factor,
    )


# ------------------------------------------------------------------------------------- result
def _result(
    problem: _StiffnessProblem,
    stiff: _StiffnessFit,
    damp: DampingFit,
    *,
    obs: Sequence[RingObservation],
    skipped: Sequence[str],
    attachment_mass: float,
    attachment_damping: float | None,
    fit_time_s: float,
    band_loss_frequency: float,
    foundation_law: FoundationLaw,
    extension: Extension | None,
) -> RingFit:
    """The :class:`RingFit` of the two stages."""
    return RingFit(
        names=problem.layout.names,
        units=problem.layout.units,
        values=stiff.theta,
        stderr=stiff.stderr,
        correlation=stiff.correlation,
        covariance=stiff.covariance,
        scales=problem.scales,
        verdicts=stiff.verdicts,
        singular_values=stiff.singular_values,
        damping_names=damp.names,
        damping_units=damp.units,
        damping_values=damp.values,
        damping_stderr=damp.stderr,
        damping_verdicts=damp.verdicts,
        radius=problem.radius,
        attachment_mass=attachment_mass,
        attachment_damping=attachment_damping,
        mass_per_length_fixed=problem.rho_fixed,
        pressures=np.unique(problem.x.p),
        observations=tuple(obs),
        fitted_frequency_hz=stiff.fitted_frequency_hz,
        fitted_amplitude=stiff.fitted_amplitude,
        fitted_damping_ratio=damp.fitted_damping_ratio,
        chi2=stiff.chi2,
        discrepancy_chi2=stiff.discrepancy,
        dof=stiff.dof,
        p_value=stiff.p_value,
        scaled_covariance=stiff.scaled,
        weights="modal standard errors" if problem.have_std else "relative (no standard errors)",
        skipped=tuple(skipped),
        fit_time_s=fit_time_s,
        band_loss_frequency=band_loss_frequency,
        foundation_law=foundation_law,
        extension=extension,
    )
