"""A microphone in the air cavity of the virtual tyre: the acoustic pressure at a rim point.

The accelerometers on the tread see the band; the cavity modes (the air
ring of :mod:`tyredamp.virtual.cavity`, n = 1 near 145 Hz) move the band
only through their coupling, so their shapes at the 16 points can look alike
and the damping between them stays undetermined. A pressure sensor on the
rim observes the air directly. With the condensation of the cavity model,

``s_i = (D q)_i / (R_c A_i) + b w_i / A_i``

(``q = A u`` the volume displacements at the mid-points, ``D`` the
staggered difference, ``w`` the band's radial motion over the width ``b``;
Webster's horn equation with a moving wall, Pierce, *Acoustics*, 3rd ed.,
2019, sec. 7.6), the acoustic pressure at node ``i`` is the bulk modulus
``rho c^2`` times the condensation,

``p_i = -rho c^2 s_i = -rho c^2 (u_a'/R_c + b w / A_c)``

(the linearised equation of state ``p = -rho c^2 div(xi)`` for the
particle displacement ``xi``, Pierce 2019, ch. 1; here the divergence of the
duct's volume displacement per unit volume, the same ``s_i`` whose square is
the potential energy of :mod:`~tyredamp.virtual.cavity`),

a fixed linear function of the DOFs (:func:`microphone_row`). Pressure is
in phase with displacement, so the pressure FRF ``p / F``
(:func:`pressure_frf`) is receptance-like (Pa/N).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError
from .contact import patch_intrusion

if TYPE_CHECKING:
    from .ring import RingTyre

__all__ = ["microphone_node", "microphone_row", "pressure_frf"]


def microphone_node(tyre: RingTyre, angle_deg: float) -> int:
    """Ring node (0-based) of a rim microphone at ``angle_deg`` (must be a node angle)."""
    try:
        a = float(angle_deg)
    except (TypeError, ValueError):
        raise InputError(f"microphone angle: expected a number in deg, got {angle_deg!r}") from None
    pos = a / 360.0 * tyre.n_ring
    node = round(pos)
    if not math.isfinite(a) or abs(pos - node) > 1e-6:
        raise InputError(
            f"microphone angle: expected a multiple of {360.0 / tyre.n_ring:g} deg (a ring "
            f"node of the {tyre.n_ring}-node tyre), got {a:g} deg"
        )
    return int(node % tyre.n_ring)


def microphone_row(tyre: RingTyre, angle_deg: float = 0.0) -> NDArray[np.float64]:
    """Pressure (Pa) at a rim point per unit DOF: ``p = row @ x``, shape (n_dof,).

    ``row`` is ``-rho c^2`` times the condensation at the node (module
    docstring), with the section ``A_i`` of the loaded cavity (flattened by
    the contact patch) when the tyre is loaded.

    Parameters
    ----------
    tyre : RingTyre
        A tyre built with a ``cavity``.
    angle_deg : float
        Position of the microphone in deg (0 deg is measurement point 1), on a
        ring node. Default 0.

    Returns
    -------
    ndarray, shape (n_dof,)
        Pa per m (ring DOFs) and per reduced air coordinate.

    Raises
    ------
    InputError
        A tyre without a cavity or an angle between nodes.
    """
    from .ring import _operators

    if tyre.cavity is None or tyre.cavity_basis is None:
        raise InputError("microphone: the tyre has no air cavity; build it with cavity=Cavity()")
    node = microphone_node(tyre, angle_deg)
    cav, p = tyre.cavity, tyre.params
    n = tyre.n_ring
    area = np.full(n, cav.area)
    if tyre.patch is not None and tyre.contact is not None:
        area = area - p.width * patch_intrusion(tyre.patch, tyre.contact, p.radius, n)
    d = _operators(n, tyre.fd_order).D
    bulk = cav.density(p.pressure) * cav.sound_speed**2
    row = np.zeros(tyre.n_dof)
    row[node] = -bulk * p.width / area[node]
    row[tyre.cavity_dofs] = -bulk * (d[node] @ tyre.cavity_basis) / (cav.mean_radius * area[node])
    return row


def pressure_frf(
    tyre: RingTyre, frequency: ArrayLike, angle_deg: float = 0.0
) -> NDArray[np.complex128]:
    """Exact pressure FRF ``p / F`` (Pa/N) at a rim microphone for each drive point.

    ``H_p(omega) = row (K - omega^2 M + i omega C)^{-1} B`` with ``B`` the
    drive-point columns (eq. [1] of the radial spec solved directly).

    Parameters
    ----------
    tyre : RingTyre
    frequency : array_like, shape (n_freq,)
        Frequencies in Hz.
    angle_deg : float
        Microphone position (:func:`microphone_row`).

    Returns
    -------
    ndarray, shape (n_drive, n_freq)
    """
    f = np.atleast_1d(as_finite(frequency, "frequency"))
    row = microphone_row(tyre, angle_deg)
    sys = tyre.system
    b = np.zeros((tyre.n_dof, tyre.drive_dofs.size))
    b[tyre.drive_dofs, np.arange(tyre.drive_dofs.size)] = 1.0
    out = np.empty((tyre.drive_dofs.size, f.size), dtype=complex)
    for k, fk in enumerate(f):
        w = 2 * np.pi * fk
        out[:, k] = row @ np.linalg.solve(sys.K - w * w * sys.M + 1j * w * sys.C, b)
    return out
