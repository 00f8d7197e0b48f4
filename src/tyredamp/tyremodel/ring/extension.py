"""A specification test of the inextensible ring against the extensible one.

The ring of eqs. (1)-(3) (:mod:`~tyredamp.tyremodel.ring.model`) is the
limit ``EA -> inf`` of the extensible ring
(:func:`~tyredamp.tyremodel.ring.model.extensible_ring`). A finite membrane
stiffness shifts each mode's motion a little from radial to tangential
(``s_r`` below ``n^2/(1+n^2)`` by ~``k_r R^2/(n^2 EA)``), lowers the
frequencies by a fraction of a percent and, because the radial share
carries the large radial damper ``c_r``, moves damping that eq. (3) can only
put on the tangential damper ``c_t``. Neither misfit stands out of the
noise of identified modes, yet both bias the parameters.

Test (Hausman, *Specification tests in econometrics*, Econometrica 46(6),
1978, Lemma 2.1 and eq. (2.6)): the ring is fitted again with the membrane
compliance ``C = 1/EA`` as one more parameter. Under the inextensible
model both fits are consistent and the restricted one efficient, so the
difference ``q = theta_ext - theta`` has covariance ``V_ext - V`` and, with one
added parameter, the test statistic is ``z = C_hat / se(C_hat)``; ``|z|`` above
the two-sided 1 % point (2.576) rejects the inextensible ring. The damping
parameters of the extended ring (eq. (3) with the extensible ring's radial
share and bending quotient, :func:`~tyredamp.tyremodel.ring.model.share_columns`)
differ by ``q_d`` with variance ``(d c / d C)^2 se(C)^2`` (the damping noise is
common to both). Every parameter carries the term ``sqrt(q^2 + var q)``: the
root mean square error of the reported (inextensible) value about the
extended fit, so the interval ``sqrt(se^2 + q^2 + var q)`` holds the bias of
a ring that stretches whether or not the test detects it. A parameter whose
shift exceeds its own standard error when the test rejects is flagged
``model-limited``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from .damping import DampingTarget, solve_damping
from .identifiability import central_jacobian
from .model import extensible_ring, share_columns

__all__ = ["REJECT_Z", "Extension", "admit_extension", "extension_test"]

_Array = NDArray[np.float64]
#: Two-sided 1 % point of the standard normal: |z| above it rejects the inextensible ring.
REJECT_Z = 2.576


@dataclass(frozen=True)
class Extension:
    """Result of the test (module docstring); shifts in the parameters' units.

    Attributes
    ----------
    compliance, compliance_stderr : float
        ``C_hat = 1/EA`` and its standard error in 1/N.
    z : float
        ``C_hat / se``.
    rejected : bool
        ``|z| > REJECT_Z``: the data see the ring stretch.
    shift, shift_sd : ndarray, shape (P,)
        ``q`` and ``sqrt(var q)`` of the stiffness/mass parameters.
    damping_shift, damping_shift_sd : ndarray, shape (D,)
        The same for the damping parameters.
    """

    compliance: float
    compliance_stderr: float
    z: float
    rejected: bool
    shift: _Array
    shift_sd: _Array
    damping_shift: _Array
    damping_shift_sd: _Array

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "membrane_compliance_per_n": self.compliance,
            "membrane_compliance_stderr": self.compliance_stderr,
            "z": self.z,
            "inextensible_rejected": self.rejected,
        }


def _extended_dmat(problem: Any, theta: _Array, comp: float, m_a: float, with_cd: bool) -> _Array:
    """Design of eq. (3) with the extensible ring's shares at ``theta`` and compliance ``comp``."""
    x, r = problem.x, problem.radius
    ei, t0, kr, kt, rho = problem.layout.unpack(theta, x.p, r)
    rho = problem.rho_fixed if problem.rho_fixed is not None else rho
    _, s_r, bend = extensible_ring(
        x.n,
        radius=r,
        bending_stiffness=ei,
        tension=t0,
        radial_stiffness=kr,
        tangential_stiffness=kt,
        compliance=comp,
    )
    return share_columns(s_r, bend, x.phi2, float(rho), m_a, with_cd)


def _compliance_scale(problem: Any, theta: _Array) -> float:
    """``0.01 / max(T0, k_r R^2)`` at the mean pressure: a compliance of a ~1 % effect (1/N)."""
    p_mean = np.array([float(np.mean(np.unique(problem.x.p)))])
    _, t0, kr, _, _ = problem.layout.unpack(theta, p_mean, problem.radius)
    big = max(abs(float(t0[0])), abs(float(kr[0])) * problem.radius**2, 1e-300)
    return 0.01 / big


def extension_test(
    problem: Any,
    theta: _Array,
    u: _Array,
    covariance: _Array,
    cov_factor: float,
    damping: _Array,
    tgt: DampingTarget,
    m_a: float,
) -> Extension | None:
    """Fit the extensible ring and compare (module docstring); None when it cannot be fitted.

    Parameters
    ----------
    problem : _StiffnessProblem
        The weighted stiffness problem of :func:`~tyredamp.tyremodel.ring.fit_ring`.
    theta, u : ndarray, shape (P,)
        Its solution in SI and in scaled units.
    covariance : ndarray, shape (P, P)
        Its covariance (SI), scaled by ``cov_factor``.
    cov_factor : float
        The factor the restricted fit's ``(J^T J)^-1`` was scaled by (applied alike).
    damping : ndarray, shape (D,)
        The damping parameters of the restricted fit.
    tgt : DampingTarget
    m_a : float
        Attachment mass in kg.
    """
    if problem.n_values <= u.size + 1:
        return None
    c_sc = _compliance_scale(problem, theta)

    def resid(v: _Array) -> _Array:
        return np.asarray(problem.residual(v[:-1], float(v[-1]) * c_sc), dtype=np.float64)

    v0 = np.concatenate([u, [0.0]])
    # a step of the search may reach a compliance where the ring has no flexural root
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        try:
            res = least_squares(resid, v0, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
        except (ValueError, np.linalg.LinAlgError):
            return None
        if res.status <= 0 or not np.all(np.isfinite(res.x)):
            return None
        v = np.asarray(res.x, dtype=float)
        jac = central_jacobian(resid, v)
    if not np.all(np.isfinite(jac)):
        return None
    sc = np.concatenate([problem.scales, [c_sc]])
    cov_e = np.linalg.pinv(jac.T @ jac, rcond=1e-12) * cov_factor * np.outer(sc, sc)
    theta_e = v[:-1] * problem.scales
    comp = float(v[-1]) * c_sc
    se_c = math.sqrt(max(float(cov_e[-1, -1]), 0.0))
    if not se_c > 0 or not np.all(np.isfinite(cov_e)):
        return None
    z = comp / se_c
    var_q = np.clip(np.diag(cov_e)[:-1] - np.diag(covariance), 0.0, None)
    with_cd = tgt.with_cd
    d_e = solve_damping(_extended_dmat(problem, theta_e, comp, m_a, with_cd), tgt)[0]
    h = 1e-3 * se_c
    d_p = solve_damping(_extended_dmat(problem, theta_e, comp + h, m_a, with_cd), tgt)[0]
    d_m = solve_damping(_extended_dmat(problem, theta_e, comp - h, m_a, with_cd), tgt)[0]
    g = (d_p - d_m) / (2 * h)
    return Extension(
        compliance=comp,
        compliance_stderr=se_c,
        z=float(z),
        rejected=bool(abs(z) > REJECT_Z),
        shift=np.asarray(theta_e - theta, dtype=np.float64),
        shift_sd=np.sqrt(var_q),
        damping_shift=np.asarray(d_e - damping, dtype=np.float64),
        damping_shift_sd=np.asarray(np.abs(g) * se_c, dtype=np.float64),
    )


def admit_extension(
    out: dict[str, dict[str, Any]],
    theta: _Array,
    se: _Array,
    shift: _Array,
    shift_sd: _Array,
    ext: Extension,
) -> dict[str, dict[str, Any]]:
    """Verdicts with the extension term ``sqrt(q^2 + var q)`` and the flag (module docstring).

    Parameters
    ----------
    out : dict
        Verdicts in parameter order (changed copies are returned).
    theta, se : ndarray, shape (P,)
        The reported values and their standard errors.
    shift, shift_sd : ndarray, shape (P,)
        ``q`` and ``sqrt(var q)`` in the parameters' units.
    ext : Extension
    """
    res: dict[str, dict[str, Any]] = {}
    for i, (name, v) in enumerate(out.items()):
        w = dict(v)
        q, sd = float(shift[i]), float(shift_sd[i])
        w["extension_shift"] = q
        w["extension_error"] = math.hypot(q, sd)
        limited = ext.rejected and abs(q) > float(se[i])
        if limited and not w.get("model_limited") and not w["verdict"].startswith("not"):
            w["model_limited"] = True
            w["verdict"] = (
                f"model-limited (the data see the ring stretch, z = {ext.z:.2g}: a ring that "
                f"stretches gives {float(theta[i]) + q:.5g}, "
                f"{abs(q) / max(float(se[i]), 1e-300):.2g} standard errors away)"
            )
        res[name] = w
    return res
