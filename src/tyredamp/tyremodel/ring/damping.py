"""The damping stage of the ring fit: weighted linear least squares of eq. (3).

``2 zeta omega`` of each mode (:mod:`~tyredamp.tyremodel.ring.model`, eq. (3))
is linear in ``c_r, c_t, eta_b`` (and the drive-point damper ``c_d``) once
``EI`` and ``rho A`` are fixed from the stiffness stage; the weights are
``sigma = 2 omega sigma_zeta`` from the modal standard errors (relative
weights and the covariance scaled by the residual variance without them).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .identifiability import admit_model_error, chi2_scaling, correlation, verdicts
from .observations import RingObservation

__all__ = ["DampingFit", "DampingTarget", "damping_target", "fit_damping", "solve_damping"]

_Array = NDArray[np.float64]
_NAMES = ("c_r", "c_t", "eta_b", "c_d")
_UNITS = ("N s/m^2", "N s/m^2", "s", "N s/m")


@dataclass(frozen=True)
class DampingTarget:
    """The measured ``2 zeta omega`` (1/s, known drive-point damper removed) and its sigma."""

    yd: _Array
    sig_d: _Array
    have_std: bool
    phi2: _Array  # drive-point phi_d^2, 1/kg
    omega: _Array  # rad/s
    with_cd: bool  # c_d is fitted
    c_known: float | None


@dataclass(frozen=True)
class DampingFit:
    """Fitted damping parameters of eq. (3)."""

    names: tuple[str, ...]
    units: tuple[str, ...]
    values: _Array
    stderr: _Array
    verdicts: dict[str, dict[str, Any]]
    fitted_damping_ratio: _Array


def damping_target(
    obs: Sequence[RingObservation],
    phi2: _Array,
    f: _Array,
    c_known: float | None,
    drive_point_damper: bool,
) -> DampingTarget:
    """``2 zeta omega`` of the modes with their weights (module docstring)."""
    zeta = np.array([o.damping_ratio for o in obs])
    omega = 2 * np.pi * f
    yd = 2 * zeta * omega
    sz_list = [o.damping_std for o in obs]
    have_zstd = all(s is not None and s > 0 for s in sz_list)
    sig_d = 2 * omega * np.array(sz_list, dtype=float) if have_zstd else yd.copy()
    if c_known is not None:
        yd = yd - c_known * phi2
    with_cd = bool(c_known is None and drive_point_damper and np.ptp(phi2) > 0)
    return DampingTarget(yd, sig_d, have_zstd, phi2, omega, with_cd, c_known)


def solve_damping(dmat: _Array, tgt: DampingTarget) -> tuple[_Array, _Array, float, int]:
    """Weighted least squares of ``dmat @ c = yd``: solution, covariance, RSS and dof.

    The covariance is scaled by ``RSS/dof`` when :func:`chi2_scaling` says so.
    """
    dw = dmat / tgt.sig_d[:, None]
    # columns differ by ~1e9 in scale (eta_b against c_r): solve and invert normalised
    cn = np.linalg.norm(dw, axis=0)
    cn = np.where(cn > 0, cn, 1.0)
    dsol_n, *_ = np.linalg.lstsq(dw / cn, tgt.yd / tgt.sig_d, rcond=None)
    dsol = np.asarray(dsol_n / cn, dtype=np.float64)
    dres = tgt.yd / tgt.sig_d - dw @ dsol
    drss = float(dres @ dres)
    ddof = max(tgt.yd.size - dsol.size, 1)
    dwn = dw / cn
    dcov = np.asarray(np.linalg.pinv(dwn.T @ dwn, rcond=1e-12) / np.outer(cn, cn), dtype=float)
    if chi2_scaling(drss, ddof, tgt.have_std)[1]:
        dcov = dcov * (drss / ddof)
    return dsol, dcov, drss, int(ddof)


def fit_damping(dmat: _Array, tgt: DampingTarget) -> DampingFit:
    """The damping parameters of eq. (3) with their verdicts, given the design ``dmat``.

    Parameters
    ----------
    dmat : ndarray, shape (M, 3) or (M, 4)
        :func:`~tyredamp.tyremodel.ring.model.damping_columns` at the fitted ``EI``, ``rho A``.
    tgt : DampingTarget
    """
    dsol, dcov, drss, ddof = solve_damping(dmat, tgt)
    dse = np.sqrt(np.clip(np.diag(dcov), 0.0, None))
    names = _NAMES[: dmat.shape[1]]
    # verdict scale of each damping term: its value, floored at 1 % of the value that alone
    # would carry the mean measured 2 zeta omega
    colmean = np.mean(np.abs(dmat), axis=0)
    dscale = float(np.mean(np.abs(tgt.yd))) / np.where(colmean > 0, colmean, 1.0)
    dscale = np.maximum(np.abs(dsol), 0.01 * dscale)
    return DampingFit(
        names=names,
        units=_UNITS[: dmat.shape[1]],
        values=dsol,
        stderr=dse,
        verdicts=admit_model_error(
            verdicts(names, dse / dscale, correlation(dcov), dmat / tgt.sig_d[:, None]),
            dsol,
            dse,
            drss / ddof if tgt.have_std else None,
            ddof,
        ),
        fitted_damping_ratio=(dmat @ dsol + (tgt.c_known or 0.0) * tgt.phi2) / (2 * tgt.omega),
    )
