"""Best proportional damping models and how well each describes the modal data.

Two proportional models are compared with the identified full ``C'``:

* modal (diagonal) damping, ``C'_d = diag(C'_nn)``, which keeps every pole;
* Rayleigh damping ``C = alpha M + beta K``; in mass-normalised modal
  coordinates ``C' = diag(alpha + beta omega_n^2)``, i.e. damping ratios
  ``zeta_n = alpha / (2 omega_n) + beta omega_n / 2`` (spec eq. [2]), fitted to
  the identified ``zeta_n`` by non-negative least squares (``alpha, beta >= 0``
  keeps ``C`` positive semi-definite).

Each model's receptance at the points,
``H(omega) = Phi (diag(omega_n^2) - omega^2 I + i omega C')^-1 Phi^T``, is compared
with the complex-mode model it was identified from (eq. [10], no residual
terms), on a frequency grid that resolves every resonance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import nnls

from ..mechanics.modal_sum import modal_sum_receptance, pole_quantities

__all__ = [
    "ProportionalComparison",
    "compare_proportional",
    "comparison_grid",
    "fit_rayleigh",
    "reduced_receptance",
]


@dataclass(frozen=True)
class ProportionalComparison:
    """Proportional damping models against the identified ``C'``.

    Attributes
    ----------
    rayleigh_alpha : float
        Mass-proportional coefficient, 1/s.
    rayleigh_beta : float
        Stiffness-proportional coefficient, s.
    zeta_identified : ndarray, shape (m,)
        ``C'_nn / (2 omega_n)``, the identified modal damping ratios.
    zeta_rayleigh : ndarray, shape (m,)
        ``alpha / (2 omega_n) + beta omega_n / 2``.
    zeta_fit_error : float
        RMS of ``(zeta_rayleigh - zeta_identified) / zeta_identified``.
    frf_error_full, frf_error_modal, frf_error_rayleigh : float
        Relative FRF error ``||H_model - H_data|| / ||H_data||`` (Frobenius over
        point pairs and grid lines) of the full ``C'``, the diagonal ``C'`` and
        the Rayleigh model against the complex-mode data.
    n_lines : int
        Number of frequency lines in the comparison grid.
    """

    rayleigh_alpha: float
    rayleigh_beta: float
    zeta_identified: NDArray[np.float64]
    zeta_rayleigh: NDArray[np.float64]
    zeta_fit_error: float
    frf_error_full: float
    frf_error_modal: float
    frf_error_rayleigh: float
    n_lines: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary of the fields."""
        return {
            "rayleigh_alpha": self.rayleigh_alpha,
            "rayleigh_beta": self.rayleigh_beta,
            "zeta_identified": self.zeta_identified.tolist(),
            "zeta_rayleigh": self.zeta_rayleigh.tolist(),
            "zeta_fit_error": self.zeta_fit_error,
            "frf_error_full": self.frf_error_full,
            "frf_error_modal": self.frf_error_modal,
            "frf_error_rayleigh": self.frf_error_rayleigh,
            "n_lines": self.n_lines,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ProportionalComparison:
        """Inverse of :meth:`to_dict`."""
        return cls(
            rayleigh_alpha=float(d["rayleigh_alpha"]),
            rayleigh_beta=float(d["rayleigh_beta"]),
            zeta_identified=np.asarray(d["zeta_identified"], dtype=float),
            zeta_rayleigh=np.asarray(d["zeta_rayleigh"], dtype=float),
            zeta_fit_error=float(d["zeta_fit_error"]),
            frf_error_full=float(d["frf_error_full"]),
            frf_error_modal=float(d["frf_error_modal"]),
            frf_error_rayleigh=float(d["frf_error_rayleigh"]),
            n_lines=int(d["n_lines"]),
        )


def fit_rayleigh(
    omega: NDArray[np.float64], zeta: NDArray[np.float64]
) -> tuple[float, float, NDArray[np.float64]]:
    """Least-squares ``alpha, beta >= 0`` of ``zeta_n = alpha/(2 omega_n) + beta omega_n/2``.

    Parameters
    ----------
    omega : ndarray, shape (m,)
        Undamped natural frequencies, rad/s.
    zeta : ndarray, shape (m,)
        Damping ratios to fit.

    Returns
    -------
    alpha : float
        1/s.
    beta : float
        s.
    zeta_fit : ndarray, shape (m,)
    """
    # scale the columns so that nnls sees numbers of order zeta
    a = np.column_stack([1 / (2 * omega), omega / 2])
    scale = np.linalg.norm(a, axis=0)
    coef, _ = nnls(a / scale, zeta)
    alpha, beta = coef / scale
    return float(alpha), float(beta), a @ np.array([alpha, beta])


def comparison_grid(
    poles: NDArray[np.complex128], points_per_mode: int = 41, n_uniform: int = 200
) -> NDArray[np.float64]:
    """Frequency lines (Hz) resolving each resonance: +-8 half-power bandwidths plus a uniform grid.

    Parameters
    ----------
    poles : ndarray, complex, shape (m,)
        rad/s.
    points_per_mode : int
        Lines across each resonance.
    n_uniform : int
        Lines of the uniform grid from 0.3 f_min to 1.3 f_max.

    Returns
    -------
    ndarray, shape (n_lines,)
        Strictly increasing, positive.
    """
    f, z = pole_quantities(poles)
    t = np.linspace(-8.0, 8.0, points_per_mode)
    local = (f[:, None] * (1 + np.maximum(z, 1e-6)[:, None] * t[None, :])).ravel()
    uniform = np.linspace(0.3 * f.min(), 1.3 * f.max(), n_uniform)
    grid = np.unique(np.concatenate([local, uniform]))
    return np.asarray(grid[grid > 0], dtype=float)


def reduced_receptance(
    frequency: NDArray[np.float64],
    basis: NDArray[np.float64],
    c_modal: NDArray[np.float64],
    omega: NDArray[np.float64],
) -> NDArray[np.complex128]:
    """Receptance at the points of the modal-coordinate model, shape (N, N, n_freq).

    ``H = Phi (diag(omega_n^2) - omega^2 I + i omega C')^-1 Phi^T`` (m/N).
    """
    w = 2 * np.pi * frequency
    m = omega.size
    dyn = (
        np.diag(omega**2)[None, :, :]
        - (w**2)[:, None, None] * np.eye(m)[None, :, :]
        + 1j * w[:, None, None] * c_modal[None, :, :]
    )
    q = np.linalg.solve(dyn, np.broadcast_to(basis.T.astype(complex), (w.size, m, basis.shape[0])))
    return np.einsum("im,fmj->ijf", basis, q)


def compare_proportional(
    poles: NDArray[np.complex128],
    psi: NDArray[np.complex128],
    basis: NDArray[np.float64],
    c_modal: NDArray[np.float64],
    omega: NDArray[np.float64],
) -> ProportionalComparison:
    """Fit the proportional models and compare FRFs at the points (module docstring).

    Parameters
    ----------
    poles : ndarray, complex, shape (m,)
        Identified poles, rad/s.
    psi : ndarray, complex, shape (N, m)
        Identified shapes at the points in the eq. [10] scaling (the data).
    basis : ndarray, shape (N, m)
        Real mass-normalised shapes of the damping model, 1/sqrt(kg).
    c_modal : ndarray, shape (m, m)
        Identified ``C'``, 1/s.
    omega : ndarray, shape (m,)
        Undamped natural frequencies of the damping model, rad/s.
    """
    zeta = np.diag(c_modal) / (2 * omega)
    alpha, beta, zfit = fit_rayleigh(omega, zeta)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(zeta > 0, (zfit - zeta) / zeta, np.nan)
    zerr = float(np.sqrt(np.nanmean(rel**2))) if np.any(np.isfinite(rel)) else float("nan")
    f = comparison_grid(poles)
    h_data = modal_sum_receptance(f, poles, psi, psi)
    norm = float(np.linalg.norm(h_data))

    def err(cp: NDArray[np.float64]) -> float:
        return float(np.linalg.norm(reduced_receptance(f, basis, cp, omega) - h_data) / norm)

    return ProportionalComparison(
        rayleigh_alpha=alpha,
        rayleigh_beta=beta,
        zeta_identified=zeta,
        zeta_rayleigh=zfit,
        zeta_fit_error=zerr,
        frf_error_full=err(c_modal),
        frf_error_modal=err(np.diag(np.diag(c_modal))),
        frf_error_rayleigh=err(np.diag(alpha + beta * omega**2)),
        n_lines=int(f.size),
    )
