"""Assembly of the ring tyre's matrices: the bare ring with its named damping sources,
a tread splice, and the coupling of the air cavity (used by :class:`RingTyre`).

The energies are those of the module docstring of :mod:`tyredamp.virtual.ring`
(Soedel, *Vibrations of Shells and Plates*; Kung, Soedel & Yang, J. Sound Vib.
107(2), 1986); the losses are viscous sidewall dashpots and Kelvin-Voigt
losses ``eta / omega_ref K`` on the band's bending and membrane stiffness
(spec ``virtual-tyre.md``, "Damping").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError
from .cavity import CavityBlocks
from .contact import _cell_overlap
from .parameters import RingTyreParameters, _check_field

__all__ = ["Splice", "ring_blocks", "splice_weights", "with_cavity"]


@dataclass(frozen=True)
class Splice:
    """A tread/belt splice: more mass, stiffness and loss over a short arc of the band.

    Parameters
    ----------
    angle_deg : float
        Centre of the splice in deg (0 deg is measurement point 1). Default
        100 (not on a measured point or a symmetry line of the layout).
    arc_length : float
        Length of the splice along the band in m, > 0. Default 0.04 (tread
        and belt-ply overlaps of a few cm).
    mass_fraction : float
        Added band mass over the arc, relative to ``rho A``, >= 0. Default
        0.3 (overlapping tread and ply: about 0.13 kg in all).
    stiffness_fraction : float
        Added bending stiffness over the arc, relative to ``EI``, >= 0.
        Default 0.5.
    loss_factor : float
        Loss factor of the splice joint on its own bending stiffness
        (overlap rubber and cord ends), >= 0. Default 0.3 (a joint works
        its rubber in shear; tread compounds 0.1-0.3).
    """

    angle_deg: float = 100.0
    arc_length: float = 0.04
    mass_fraction: float = 0.3
    stiffness_fraction: float = 0.5
    loss_factor: float = 0.3

    def __post_init__(self) -> None:
        try:
            a = float(self.angle_deg)
        except (TypeError, ValueError):
            raise InputError(
                f"Splice.angle_deg: expected a number, got {self.angle_deg!r}"
            ) from None
        if not math.isfinite(a):
            raise InputError(f"Splice.angle_deg: expected a finite angle, got {a}")
        object.__setattr__(self, "angle_deg", a)
        _check_field(self, "arc_length", allow_zero=False)
        for name in ("mass_fraction", "stiffness_fraction", "loss_factor"):
            _check_field(self, name, allow_zero=True)
        for name in ("arc_length", "mass_fraction", "stiffness_fraction", "loss_factor"):
            object.__setattr__(self, name, float(getattr(self, name)))


def splice_weights(
    splice: Splice, radius: float, n_ring: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Share of each node cell and mid-point cell covered by the splice, in [0, 1].

    Returns
    -------
    nodes, mids : ndarray, shape (n_ring,)
        Covered fraction of the cell ``[theta - h/2, theta + h/2]`` around each
        node and each mid-point.
    """
    h = 2 * np.pi / n_ring
    c = math.radians(splice.angle_deg) % (2 * np.pi)
    half = 0.5 * splice.arc_length / radius
    th = np.arange(n_ring) * h
    return (
        _cell_overlap(th, h, c - half, c + half) / h,
        _cell_overlap(th + h / 2, h, c - half, c + half) / h,
    )


def ring_blocks(
    p: RingTyreParameters, d: NDArray[np.float64], splice: Splice | None
) -> tuple[
    NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], dict[str, NDArray[np.float64]]
]:
    """Stiffness, bending stiffness, mass and named damping blocks of the bare ring.

    Returns ``K``, ``K_bend`` (N/m), ``M`` (kg), each ``(2N, 2N)``, and the
    damping of each source (N s/m): the sidewall dashpots ``c_r``, ``c_t``,
    the band's Kelvin-Voigt losses on bending and membrane strain and the
    splice (:class:`~tyredamp.virtual.sources.Splice`).
    """
    n = d.shape[0]
    h = 2 * np.pi / n
    g = -d.T
    r = p.radius
    eye = np.eye(n)
    zero = np.zeros((n, n))
    e_op = np.hstack([eye, d])  # R * membrane strain at nodes
    b_op = np.hstack([-d @ g, d])  # R^2 * curvature change at nodes
    gw_op = np.hstack([g, zero])  # w' at mid-points
    w_sel = np.hstack([eye, zero])
    v_sel = np.hstack([zero, eye])
    arc = r * h
    ete = e_op.T @ e_op
    k_bend = arc * p.bending_stiffness / r**4 * (b_op.T @ b_op)
    k_mem = arc * p.membrane_stiffness / r**2 * ete
    k = (
        k_mem
        + k_bend
        + arc * p.hoop_tension / r**2 * (ete - w_sel.T @ w_sel + gw_op.T @ gw_op)
        + arc * p.radial_stiffness * (w_sel.T @ w_sel)
        + arc * p.tangential_stiffness * (v_sel.T @ v_sel)
    )
    m = p.mass_per_length * arc * np.eye(2 * n)
    omega_ref = 2 * np.pi * p.band_loss_frequency
    sources = {
        "sidewall radial": arc * p.radial_damping * (w_sel.T @ w_sel),
        "sidewall tangential": arc * p.tangential_damping * (v_sel.T @ v_sel),
        "band bending": p.band_loss_factor / omega_ref * k_bend,
        "band membrane": p.membrane_loss_factor / omega_ref * k_mem,
    }
    if splice is not None:
        nodes, mids = splice_weights(splice, r, n)
        k_sp = (
            arc
            * p.bending_stiffness
            / r**4
            * splice.stiffness_fraction
            * (b_op.T @ (nodes[:, None] * b_op))
        )
        k = k + k_sp
        k_bend = k_bend + k_sp
        m = m + p.mass_per_length * arc * splice.mass_fraction * np.diag(
            np.concatenate([nodes, mids])
        )
        sources["splice"] = (p.band_loss_factor + splice.loss_factor) / omega_ref * k_sp
    return k, k_bend, m, sources


def with_cavity(
    m: NDArray[np.float64],
    k: NDArray[np.float64],
    sources: dict[str, NDArray[np.float64]],
    blk: CavityBlocks,
) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, NDArray[np.float64]]]:
    """Append the reduced air DOFs of ``blk`` to the ring's ``M``, ``K`` and damping sources."""
    na = blk.m_air.shape[0]
    nr = m.shape[0]
    za = np.zeros((nr, na))
    m2 = np.block([[m, za], [za.T, blk.m_air]])
    k2 = np.block([[k + blk.k_ring, blk.k_cross], [blk.k_cross.T, blk.k_air]])
    out = {name: np.block([[c, za], [za.T, np.zeros((na, na))]]) for name, c in sources.items()}
    out["cavity"] = np.block([[blk.c_ring, blk.c_cross], [blk.c_cross.T, blk.c_air]])
    return m2, 0.5 * (k2 + k2.T), out
