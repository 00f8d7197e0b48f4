"""Non-viscous damping from complex modes (Adhikari & Woodhouse 2001, part 2).

For an exponential kernel ``G(s) = C mu/(s + mu)`` (A-W part 2, eq. (4)) the
first-order complex modes are (A-W part 2, eq. (13)-(14), ``theta = 1/mu``)

``lambda_j = omega_j + i G'_jj(omega_j)/2``,
``z_j = x_j + sum_{k != j} i omega_j G'_kj(omega_j)/(omega_j^2 - omega_k^2) x_k``

with ``G'(omega) = C'/(1 + i omega theta)`` in modal coordinates. The part-1
viscous estimate (eq. (15)-(16) of part 1, :func:`tyredamp.damping.modal_damping_from_modes`)
fitted to such modes returns, column by column,

``C1_kj = C'_kj / (1 + omega_j^2 theta^2)``,

so a non-viscous kernel shows as an asymmetric fitted viscous matrix
(A-W part 2, sec. 3). Requiring ``C1 diag(1 + omega^2 theta^2)`` to be
symmetric gives, with ``t = theta^2``, one linear equation per pair ``k < j``:

``(C1_kj - C1_jk) + t (C1_kj omega_j^2 - C1_jk omega_k^2) = 0``,

solved by least squares for ``t``; then ``C' = sym(C1 diag(1 + omega^2 t))``.
The A-W viscous-consistency test asks whether ``t`` differs from 0 beyond
the scatter of the pair equations (a one-sided t-test on the least-squares
``t``) and the kernel removes most of the asymmetry; ``gamma = theta / T_min``
with ``T_min = 2 pi/omega_max`` is the
non-dimensional relaxation time of A-W part 2 (their figures use ``gamma =
0.02`` for a nearly viscous and ``gamma = 0.5`` for a strongly non-viscous case).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.stats import t as t_dist

from ..damping import modal_damping_from_modes
from ..exceptions import InputError

__all__ = ["RelaxationEstimate", "exponential_from_modes"]

#: One-sided level of the viscous-consistency test.
CONSISTENCY_LEVEL = 0.01


@dataclass(frozen=True)
class RelaxationEstimate:
    """The exponential model identified from complex modes (module docstring).

    Attributes
    ----------
    theta : float
        Relaxation time ``1/mu`` in s (0 when the fit gives ``t <= 0``).
    theta_std : float
        Standard error of ``theta`` from the scatter of the pair equations, s
        (``inf`` for ``theta = 0``).
    t_statistic : float
        ``t / std(t)``: how many standard errors ``theta^2`` lies above 0.
    p_value : float
        One-sided probability of a ``t`` at least this large if the damping were
        viscous.
    gamma : float
        ``theta / T_min``, ``T_min = 2 pi / max(omega)``.
    c_modal : ndarray, shape (m, m)
        ``C'`` of the kernel in modal coordinates, 1/s.
    c_viscous : ndarray, shape (m, m)
        The part-1 viscous estimate ``C1`` (not symmetrised), 1/s.
    omega : ndarray, shape (m,)
        Natural frequencies used, rad/s.
    asymmetry : float
        ``||C1 - C1^T|| / ||C1 + C1^T||`` (Frobenius).
    asymmetry_after : float
        The same for ``C1 diag(1 + omega^2 theta^2)``.
    """

    theta: float
    theta_std: float
    t_statistic: float
    p_value: float
    gamma: float
    c_modal: NDArray[np.float64]
    c_viscous: NDArray[np.float64]
    omega: NDArray[np.float64]
    asymmetry: float
    asymmetry_after: float

    @property
    def mu(self) -> float:
        """Relaxation parameter ``1/theta`` in 1/s (``inf`` when viscous)."""
        return 1.0 / self.theta if self.theta > 0 else float("inf")

    @property
    def viscous_consistent(self) -> bool:
        """The modes are consistent with viscous damping (A-W part 2 test).

        Inconsistent when ``theta^2 > 0`` at the one-sided level
        :data:`CONSISTENCY_LEVEL` *and* the kernel explains most of the
        asymmetry (``asymmetry_after < asymmetry / 2``): exact viscous modes
        leave an asymmetry of order ``zeta^2`` (the first-order theory's own
        error) that no ``theta`` removes.
        """
        return self.p_value >= CONSISTENCY_LEVEL or self.asymmetry_after > 0.5 * self.asymmetry

    def format(self) -> str:
        """One line for people."""
        if self.viscous_consistent:
            return (
                f"Adhikari-Woodhouse test: the modes are consistent with viscous damping "
                f"(theta = {self.theta:.3g} s, gamma = {self.gamma:.3g}, p = {self.p_value:.3g})"
            )
        return (
            f"Adhikari-Woodhouse test: the modes are not consistent with viscous damping: "
            f"relaxation time theta = {self.theta:.3g} +- {self.theta_std:.2g} s "
            f"(mu = {self.mu:.4g} 1/s, gamma = {self.gamma:.3g}, {self.t_statistic:.1f} "
            f"standard errors, p = {self.p_value:.2g}); fitted viscous C' asymmetry "
            f"{100 * self.asymmetry:.2g} %, {100 * self.asymmetry_after:.2g} % after"
        )

    def to_dict(self) -> dict[str, object]:
        """Plain dictionary (strict JSON)."""
        big = 1e300
        return {
            "theta_s": self.theta,
            "theta_std_s": min(self.theta_std, big),
            "mu_per_s": min(self.mu, big),
            "gamma": self.gamma,
            "t_statistic": self.t_statistic,
            "p_value": self.p_value,
            "viscous_consistent": self.viscous_consistent,
            "asymmetry": self.asymmetry,
            "asymmetry_after": self.asymmetry_after,
            "c_modal": self.c_modal.tolist(),
        }


def _asym(c: NDArray[np.float64]) -> float:
    return float(np.linalg.norm(c - c.T)) / max(float(np.linalg.norm(c + c.T)), 1e-300)


def exponential_from_modes(poles: ArrayLike, shapes: ArrayLike) -> RelaxationEstimate:
    """Identify ``theta = 1/mu`` and ``C'`` of an exponential kernel (module docstring).

    Parameters
    ----------
    poles : array_like, complex, shape (m,)
        ``p_n`` in rad/s (``Im p > 0``, ``Re p < 0``), ``m >= 2``.
    shapes : array_like, complex, shape (N, m)
        Second-order complex shapes ``Psi^_n`` at ``N >= m`` points, 1/sqrt(kg).

    Returns
    -------
    RelaxationEstimate
    """
    p = np.atleast_1d(np.asarray(poles, dtype=complex))
    if p.size < 2:
        raise InputError(
            f"poles: the relaxation parameter needs at least 2 modes (pairs of modes), got {p.size}"
        )
    est = modal_damping_from_modes(p, shapes, method="first")
    c1, w = est.c_modal, est.omega
    iu = np.triu_indices(w.size, 1)
    a = (c1 - c1.T)[iu]
    g = (c1 * w[None, :] ** 2 - c1.T * w[:, None] ** 2)[iu]
    gg = float(g @ g)
    t = -float(a @ g) / gg if gg > 0 else 0.0
    dof = a.size - 1
    if dof > 0 and gg > 0:
        res = a + t * g
        t_std = float(np.sqrt((res @ res) / dof / gg))
    else:
        t_std = float("inf")
    stat = t / t_std if t_std > 0 else (np.inf if t > 0 else 0.0)
    p_val = (
        float(t_dist.sf(stat, dof)) if dof > 0 and np.isfinite(stat) else (0.0 if stat > 0 else 1.0)
    )
    theta = float(np.sqrt(t)) if t > 0 else 0.0
    theta_std = t_std / (2 * theta) if theta > 0 else float("inf")
    cs = c1 * (1 + w[None, :] ** 2 * theta**2)
    return RelaxationEstimate(
        theta=theta,
        theta_std=theta_std,
        t_statistic=float(stat),
        p_value=p_val,
        gamma=theta * float(w.max()) / (2 * np.pi),
        c_modal=0.5 * (cs + cs.T),
        c_viscous=c1.copy(),
        omega=w.copy(),
        asymmetry=_asym(c1),
        asymmetry_after=_asym(cs),
    )
