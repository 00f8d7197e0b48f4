"""The :class:`DampingModel` result object and its JSON form.

Layout of :meth:`DampingModel.to_dict` (all matrices as nested lists of
floats, row-major; units SI for mass-normalised shapes in 1/sqrt(kg)); the
damping JSON file (:mod:`tyredamp.documents.damping`) puts ``"kind":
"damping"`` and ``"version"`` around it::

    {"method": "first" | "improved" | "refined",
     "normalised": bool,
     "modes": {"frequency_hz": [m], "damping_ratio": [m],
               "poles": [[re, im] x m]},            # rad/s
     "points": [{"node", "direction", "angle_deg", "name"} x N],
     "modal": [[m] x m],          # C' (1/s), eq. [14], not symmetrised
     "modal_symmetric": [[m] x m],     # (C' + C'^T) / 2
     "physical": [[N] x N],       # C (N s/m) at the points
     "physical_symmetric": [[N] x N],  # (C + C^T) / 2
     "mass": [[N] x N],           # reduced M (kg), rank m
     "stiffness": [[N] x N],      # reduced K (N/m), rank m
     "basis": [[m] x N],          # real mass-normalised shapes Phi (1/sqrt(kg))
     "lancaster_physical": [[N] x N] | null,   # exact C when m == N
     "std": {"modal": [[m] x m], "physical": [[N] x N]} | {},
     "uncertainty": {"method": "monte_carlo", "n_samples", "n_failed", "seed"} | {},
     "diagnostics": {...DampingDiagnostics fields...},
     "proportional": {...ProportionalComparison fields...},
     "findings": [str, ...],
     "meta": {...}}
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._validate import check_positive_definite
from ..exceptions import InputError, PhysicsError
from ..frf import Channel
from ..mechanics import MCKSystem
from .diagnostics import DampingDiagnostics
from .proportional import ProportionalComparison

__all__ = ["DampingModel"]


@dataclass(frozen=True, eq=False)
class DampingModel:
    """Identified viscous damping in modal and physical coordinates.

    Attributes
    ----------
    modal : ndarray, shape (m, m)
        ``C'`` in undamped modal coordinates (eq. [14]), 1/s; not symmetrised.
    physical : ndarray, shape (N, N)
        ``C = pinv(Phi)^T C' pinv(Phi)`` at the points, N s/m (rank ``m``).
    mass, stiffness : ndarray, shape (N, N)
        Reduced ``M = pinv(Phi)^T pinv(Phi)`` (kg) and
        ``K = pinv(Phi)^T diag(omega^2) pinv(Phi)`` (N/m) at the points.
    basis : ndarray, shape (N, m)
        Real mass-normalised shapes ``Phi`` at the points, 1/sqrt(kg).
    poles : ndarray, complex, shape (m,)
        Identified poles, rad/s.
    frequency_hz : ndarray, shape (m,)
        Undamped natural frequencies of the modal coordinates, Hz.
    damping_ratio : ndarray, shape (m,)
        ``zeta_n`` of the identified poles.
    points : tuple of Channel
        The ``N`` measured points (rows/columns of the physical matrices).
    method : str
        "first" (eq. [16]), "improved" (eq. [18]) or "refined".
    normalised : bool
        Whether the ``alpha_n^(n) = 1`` normalisation was applied.
    diagnostics : DampingDiagnostics
    proportional : ProportionalComparison
    findings : tuple of str
        Plain-English conclusions.
    std : dict of str to ndarray
        ``"modal"`` (m, m) and ``"physical"`` (N, N) standard errors; empty
        when the modal model carried no uncertainty.
    uncertainty : dict
        How ``std`` was obtained (``{"method": "monte_carlo", "n_samples",
        "n_failed", "seed"}``).
    lancaster_physical : ndarray, shape (N, N), or None
        Exact ``C`` by Lancaster's formula when the modal set is complete.
    meta : dict
        Free information (source file, model name).
    """

    modal: NDArray[np.float64]
    physical: NDArray[np.float64]
    mass: NDArray[np.float64]
    stiffness: NDArray[np.float64]
    basis: NDArray[np.float64]
    poles: NDArray[np.complex128]
    frequency_hz: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    points: tuple[Channel, ...]
    method: str
    normalised: bool
    diagnostics: DampingDiagnostics
    proportional: ProportionalComparison
    findings: tuple[str, ...]
    std: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    uncertainty: dict[str, Any] = field(default_factory=dict)
    lancaster_physical: NDArray[np.float64] | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        """Number of modes ``m``."""
        return int(self.modal.shape[0])

    @property
    def n_points(self) -> int:
        """Number of points ``N``."""
        return int(self.physical.shape[0])

    @property
    def modal_symmetric(self) -> NDArray[np.float64]:
        """``(C' + C'^T) / 2``, 1/s, shape (m, m).

        The true ``C'`` is symmetric, and the symmetric matrices form a
        subspace on which this is the orthogonal (Frobenius) projection, so
        the symmetric part is never further from the truth than ``C'``; the
        antisymmetric part is pure error (noise, and leakage from modes outside
        the identified set, which enters mostly antisymmetrically).
        """
        return 0.5 * (self.modal + self.modal.T)

    @property
    def physical_symmetric(self) -> NDArray[np.float64]:
        """``(C + C^T) / 2 = pinv(Phi)^T sym(C') pinv(Phi)``, N s/m, shape (N, N)."""
        return 0.5 * (self.physical + self.physical.T)

    @property
    def omega_n(self) -> NDArray[np.float64]:
        """Undamped natural frequencies of the modal coordinates, rad/s."""
        return 2 * np.pi * self.frequency_hz

    def mck(self) -> MCKSystem:
        """The reduced model at the points as an :class:`MCKSystem`.

        Only possible for a complete modal set (``m == N``); the damping is
        :attr:`physical_symmetric` (the asymmetry is in
        ``diagnostics.symmetry_physical``).

        Raises
        ------
        PhysicsError
            If the reduced mass matrix is singular (``m < N``: it has rank
            ``m``) or the damping is indefinite; use the arrays instead.
        """
        if self.n_modes < self.n_points:
            raise PhysicsError(
                f"mck: {self.n_modes} modes at {self.n_points} points give rank-{self.n_modes} "
                "M, C and K (singular mass matrix); use DampingModel.mass/physical/stiffness "
                "as arrays, or identify at most as many points as modes"
            )
        m = 0.5 * (self.mass + self.mass.T)
        check_positive_definite(m, "mass")
        return MCKSystem(
            m, 0.5 * (self.physical + self.physical.T), 0.5 * (self.stiffness + self.stiffness.T)
        )

    def rayleigh_physical(self) -> NDArray[np.float64]:
        """Best Rayleigh damping ``alpha M + beta K`` at the points, N s/m, shape (N, N)."""
        return (
            self.proportional.rayleigh_alpha * self.mass
            + self.proportional.rayleigh_beta * self.stiffness
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary; the layout is in the module docstring."""
        return {
            "method": self.method,
            "normalised": self.normalised,
            "modes": {
                "frequency_hz": self.frequency_hz.tolist(),
                "damping_ratio": self.damping_ratio.tolist(),
                "poles": np.stack([self.poles.real, self.poles.imag], axis=-1).tolist(),
            },
            "points": [
                {"node": c.node, "direction": c.direction, "angle_deg": c.angle_deg, "name": c.name}
                for c in self.points
            ],
            "modal": self.modal.tolist(),
            "modal_symmetric": self.modal_symmetric.tolist(),
            "physical": self.physical.tolist(),
            "physical_symmetric": self.physical_symmetric.tolist(),
            "mass": self.mass.tolist(),
            "stiffness": self.stiffness.tolist(),
            "basis": self.basis.tolist(),
            "lancaster_physical": (
                None if self.lancaster_physical is None else self.lancaster_physical.tolist()
            ),
            "std": {k: np.asarray(v).tolist() for k, v in self.std.items()},
            "uncertainty": dict(self.uncertainty),
            "diagnostics": self.diagnostics.to_dict(),
            "proportional": self.proportional.to_dict(),
            "findings": list(self.findings),
            "meta": _jsonable(self.meta),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> DampingModel:
        """Inverse of :meth:`to_dict`; raises :class:`InputError` naming a missing key."""
        try:
            if d.get("kind", "damping") != "damping":  # the damping document's envelope
                raise InputError(f"damping model: expected kind 'damping', got {d.get('kind')!r}")
            poles = np.asarray(d["modes"]["poles"], dtype=float).reshape(-1, 2)
            lp = d.get("lancaster_physical")
            return cls(
                modal=np.asarray(d["modal"], dtype=float),
                physical=np.asarray(d["physical"], dtype=float),
                mass=np.asarray(d["mass"], dtype=float),
                stiffness=np.asarray(d["stiffness"], dtype=float),
                basis=np.asarray(d["basis"], dtype=float),
                poles=poles[:, 0] + 1j * poles[:, 1],
                frequency_hz=np.asarray(d["modes"]["frequency_hz"], dtype=float),
                damping_ratio=np.asarray(d["modes"]["damping_ratio"], dtype=float),
                points=tuple(Channel(**c) for c in d["points"]),
                method=str(d["method"]),
                normalised=bool(d["normalised"]),
                diagnostics=DampingDiagnostics.from_dict(d["diagnostics"]),
                proportional=ProportionalComparison.from_dict(d["proportional"]),
                findings=tuple(str(s) for s in d["findings"]),
                std={k: np.asarray(v, dtype=float) for k, v in d.get("std", {}).items()},
                uncertainty=dict(d.get("uncertainty", {})),
                lancaster_physical=None if lp is None else np.asarray(lp, dtype=float),
                meta=dict(d.get("meta", {})),
            )
        except KeyError as exc:
            raise InputError(f"damping model: missing key {exc.args[0]!r}") from None
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"damping model: malformed entry ({exc})") from None

    def __repr__(self) -> str:
        return (
            f"DampingModel({self.method}, {self.n_modes} modes at {self.n_points} points, "
            f"C' {self.diagnostics.definiteness_modal})"
        )


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, complex):
        return [x.real, x.imag]
    return x
