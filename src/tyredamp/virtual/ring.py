"""The in-plane ring tyre: analytic ring on an elastic foundation and its discretisation.

Continuous model (spec ``virtual-tyre.md``)
-------------------------------------------
A thin ring of radius ``R`` (radial displacement ``w`` positive outwards,
tangential ``v`` positive with ``theta``) on radial and tangential foundations
``k_r``, ``k_t`` (per unit length), with hoop tension ``T0 = p b R``. With
primes for ``d/dtheta`` the potential energy of the extensible ring is

``U = 1/2 int [ EA eps^2 + EI kappa^2 + T0/R^2 ((v' + w)^2 + w'^2 - w^2)
+ k_r w^2 + k_t v^2 ] R dtheta``

with membrane strain ``eps = (v' + w)/R`` and change of curvature
``kappa = (v' - w'')/R^2`` (Soedel, *Vibrations of Shells and Plates*). The
pre-stress term is derived here: the second-order part of the Green strain
under ``T0``, ``T0/(2R) int ((w' - v)^2 + (w + v')^2) dtheta``, minus the work
of the pressure on the enclosed area, ``p b/2 int (w^2 - 2 v w' + v^2)
dtheta``; with ``p b = T0/R`` the sum is ``T0/(2R) int ((v' + w)^2 + w'^2 -
w^2) dtheta`` (the first-order terms cancel by the equilibrium ``T0 = p b
R``). Kinetic energy ``1/2 int rho A (w_t^2 + v_t^2) R dtheta``.

For ``w = a cos n theta``, ``v = c sin n theta`` this gives a 2x2 eigenproblem
per wave number ``n`` (:func:`ring_dispersion`). In the inextensible limit
``EA -> inf`` (``v' = -w``) it reduces to the formula of the spec,

``omega_n^2 = [EI n^2 (n^2-1)^2 / R^4 + T0 n^2 (n^2-1) / R^2 + k_r n^2 + k_t]
/ [rho A (1 + n^2)]``  (:func:`analytic_ring_frequencies`),

which is the energy (Rayleigh) result of Kung, Soedel & Yang (J. Sound Vib.
107(2), 1986) and of the flexible-ring tyre models (Pacejka, *Tire and Vehicle
Dynamics*, ch. 9; Gong, TU Delft thesis 1993).

Discretisation
--------------
``n_ring`` nodes at ``theta_i = i h`` (``h = 2 pi / n_ring``) carry the radial
DOFs ``w_i``; the tangential DOFs ``v_j`` sit at the mid-points
``theta_{j+1/2}`` (a staggered grid). Derivatives between the two grids are
central staggered differences of order 2, 4 (default) or 6, ``D`` (mid-points
to nodes) and ``G = -D^T`` (nodes to mid-points), so that ``w'' = D G w`` and
``K`` is a sum of squares (symmetric, positive semi-definite by construction);
the energy integrals are mid-point sums and the mass is lumped
(``rho A R h`` per DOF). The staggered grid has no spurious zero-energy
(odd-even) mode and the discrete inextensibility constraint ``D v + w = 0``
leaves an ``n_ring - 1``-dimensional subspace, so a large ``EA`` does not
lock. For the axisymmetric ring the discrete modes are exact harmonics and
their frequencies are the continuous 2x2 result with ``n`` replaced by the
difference symbol ``s(n) = (2/h) sum_k a_k sin((k - 1/2) n h)``
(``s(n) = n (1 - O((n h)^order))``); the error against the analytic
frequencies therefore falls as ``n_ring^-order``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError, PhysicsError
from ..frf import Channel
from ..mechanics import MCKSystem, proportional_part
from .assembly import Splice, ring_blocks, with_cavity
from .cavity import Cavity, cavity_blocks
from .contact import ContactPatch, contact_blocks, patch_intrusion, solve_patch
from .dispersion import (
    _ORDERS,
    analytic_ring_frequencies,
    difference_symbol,
    ring_dispersion,
    staggered_weights,
)
from .parameters import Imperfection, MeasurementLayout, RingTyreParameters
from .truth import TyreTruth, wave_numbers

__all__ = [
    "RingConvergence",
    "RingTyre",
    "analytic_ring_frequencies",
    "difference_symbol",
    "ring_convergence",
    "ring_dispersion",
    "staggered_weights",
]


# -------------------------------------------------------------- discrete ring
@dataclass(frozen=True)
class _Operators:
    D: NDArray[np.float64]  # mid-points -> nodes, (N, N)
    h: float


def _operators(n_ring: int, order: int) -> _Operators:
    off, a = staggered_weights(order)
    h = 2 * np.pi / n_ring
    eye = np.eye(n_ring)
    d = np.zeros((n_ring, n_ring))
    for o, ak in zip(off, a, strict=True):
        k = int(o + 0.5)
        # v_j lives at theta_{j+1/2}: theta_i + o h is mid-point j = i + k - 1,
        # theta_i - o h is mid-point j = i - k
        d += (ak / h) * (np.roll(eye, k - 1, axis=1) - np.roll(eye, -k, axis=1))
    return _Operators(D=d, h=h)


def _rubber_parts(
    p: RingTyreParameters, d: NDArray[np.float64], k_bend: NDArray[np.float64], n_dof: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The sidewall foundation's and the band's stiffness (N/m), padded to ``n_dof``.

    The same terms as the ring's stiffness (module docstring): ``k_r w^2 + k_t v^2``
    of the sidewall and the band's membrane ``EA eps^2`` plus bending ``EI kappa^2``;
    :mod:`tyredamp.virtual.rubber` gives them a viscoelastic modulus. Extra DOFs (the
    air cavity's) get zero rows.
    """
    n = d.shape[0]
    arc = p.radius * 2.0 * math.pi / n
    eye = np.eye(n)
    e_op = np.hstack([eye, d])  # R * membrane strain at nodes
    side = np.zeros((n_dof, n_dof))
    idx = np.arange(n)
    side[idx, idx] = arc * p.radial_stiffness
    side[n + idx, n + idx] = arc * p.tangential_stiffness
    band = np.zeros((n_dof, n_dof))
    band[: 2 * n, : 2 * n] = arc * p.membrane_stiffness / p.radius**2 * (e_op.T @ e_op) + k_bend
    return side, band


class RingTyre:
    """The discretised in-plane ring tyre with its measurement layout (the virtual tyre).

    Builds ``M``, ``C`` and ``K`` of the staggered-grid ring (module docstring)
    with the drive-point attachments of ``layout`` and optional
    ``imperfections``. DOF order: ``w_0 .. w_{N-1}`` (radial, nodes at
    ``i * 360/N`` deg), then ``v_0 .. v_{N-1}`` (tangential, at
    ``(i + 1/2) * 360/N`` deg), ``N = n_ring``.

    Damping
    -------
    The physical damping ``C_phys`` is: sidewall dashpots ``c_r``, ``c_t`` per
    unit length (not proportional to ``k_r``, ``k_t``), a band loss on the
    bending stiffness only (``eta / omega_ref K_bend``), the local radial
    dampers at the drive points and at imperfections. The damping actually
    used is

    ``C = C_p + nu (C_phys - C_p)``,

    where ``C_p = M Phi diag(C'_nn) Phi^T M`` is the proportional part of
    ``C_phys`` (the diagonal of ``C' = Phi^T C_phys Phi``, eq. [14]) and
    ``nu = nonproportionality`` in [0, 1]. Every ``nu`` gives the same
    diagonal of ``C'`` (the same modal damping ratios to first order, eq.
    [15]); only the off-diagonal terms, which make the modes complex (eq.
    [16]), scale with ``nu``. ``nu = 0`` is exactly proportional (real modes),
    ``nu = 1`` (the default) is the physical distribution. An axisymmetric
    distributed damping only couples modes of the same wave number (flexural
    with the kHz extensional branch); the in-band non-proportionality comes
    from what breaks the symmetry or mixes losses in one mode: the
    drive-point tip, the air cavity, a splice, the tread in a loaded contact
    patch. ``damping_sources`` holds the damping of each source and
    :func:`~tyredamp.virtual.damping_decomposition` splits ``C'_off`` among
    them.

    Parameters
    ----------
    params : RingTyreParameters, optional
        The tyre (default 295/80R22.5 at 7.5 bar).
    layout : MeasurementLayout, optional
        Measured points and drive points (default 16 points, drive at point 1).
    n_ring : int
        Number of ring nodes, a multiple of ``layout.n_points`` (default 64:
        128 DOFs; with the default sixth-order differences n = 1..7 within
        0.01 % of the continuous ring, below the frequency uncertainty of an
        identified mode, so a ring model fitted to the virtual modes is not
        biased by the discretisation).
    fd_order : {2, 4, 6}
        Order of the staggered differences (default 6).
    nonproportionality : float
        The knob ``nu`` in [0, 1]. Default 1 (the physical distribution).
        The bare ring with its 2 N s/m drive-point tip is nearly
        proportional (MPC above 0.999); the coupling of well separated modes
        is bounded by the damping (eq. [16]), so strongly complex modes need
        close modes: a loaded ``contact``, an imperfection or ``splice`` that
        splits the doubles, or several drive points.
    imperfections : sequence of Imperfection, optional
        Local masses, springs or dampers that split the double modes.
    splice : Splice, optional
        A tread splice (:mod:`tyredamp.virtual.assembly`). Default none.
    cavity : Cavity, optional
        The air cavity (:mod:`tyredamp.virtual.cavity`), adding ``n_ring - 1``
        air DOFs after the ring's (``cavity_dofs``). Default none.
    contact : ContactPatch, optional
        A static load on a flat road (:mod:`tyredamp.virtual.contact`); the
        solved patch is in ``patch``. Default none (free tyre).

    Attributes
    ----------
    system : MCKSystem
        ``M`` (kg), ``C`` (N s/m, after the knob) and ``K`` (N/m) of the full
        discretisation, shape (n_dof, n_dof) each (``n_dof = 2 n_ring``, plus
        ``n_ring - 1`` with a cavity).
    physical_system : MCKSystem
        The same with the physical damping ``C_phys`` (``nu = 1``).
    damping_sources : dict of str to ndarray, shape (n_dof, n_dof)
        ``C_phys`` split by physical source (N s/m); they sum to ``C_phys``.
    patch : PatchState or None
        The solved contact patch (half-length, deflection, hub stiffness).
    K_bend : ndarray, shape (2 n_ring, 2 n_ring)
        The bending part of ``K`` (N/m), which carries the band loss.

    Raises
    ------
    InputError
        Bad ``n_ring``, ``fd_order`` or ``nonproportionality``.
    PhysicsError
        Via the parameter classes, or a matrix that is not physical.
    """

    def __init__(
        self,
        params: RingTyreParameters | None = None,
        layout: MeasurementLayout | None = None,
        *,
        n_ring: int = 64,
        fd_order: int = 6,
        nonproportionality: float = 1.0,
        imperfections: Sequence[Imperfection] = (),
        splice: Splice | None = None,
        cavity: Cavity | None = None,
        contact: ContactPatch | None = None,
    ) -> None:
        self.params = params if params is not None else RingTyreParameters()
        self.layout = layout if layout is not None else MeasurementLayout()
        if not isinstance(self.params, RingTyreParameters):
            raise InputError(
                f"params: expected RingTyreParameters, got {type(self.params).__name__}"
            )
        if not isinstance(self.layout, MeasurementLayout):
            raise InputError(
                f"layout: expected MeasurementLayout, got {type(self.layout).__name__}"
            )
        if not isinstance(n_ring, int | np.integer) or isinstance(n_ring, bool):
            raise InputError(f"n_ring: expected an integer, got {n_ring!r}")
        n_ring = int(n_ring)
        npts = self.layout.n_points
        if n_ring < npts or n_ring % npts:
            raise InputError(
                f"n_ring: expected a multiple of layout.n_points = {npts} (so that every "
                f"measured point is a ring node), got {n_ring}"
            )
        if fd_order not in _ORDERS:
            raise InputError(f"fd_order: expected one of {_ORDERS}, got {fd_order!r}")
        if n_ring < 2 * fd_order:
            raise InputError(
                f"n_ring: expected at least {2 * fd_order} nodes for fd_order "
                f"{fd_order}, got {n_ring}"
            )
        try:
            nu = float(nonproportionality)
        except (TypeError, ValueError):
            raise InputError(
                f"nonproportionality: expected a number in [0, 1], got {nonproportionality!r}"
            ) from None
        if not np.isfinite(nu) or not 0.0 <= nu <= 1.0:
            raise InputError(f"nonproportionality: expected a number in [0, 1], got {nu}")
        imps = tuple(imperfections)
        for i, imp in enumerate(imps):
            if not isinstance(imp, Imperfection):
                raise InputError(
                    f"imperfections[{i}]: expected Imperfection, got {type(imp).__name__}"
                )
        self.n_ring = n_ring
        self.fd_order = int(fd_order)
        self.nonproportionality = nu
        self.imperfections = imps
        for name, obj, cls in (
            ("splice", splice, Splice),
            ("cavity", cavity, Cavity),
            ("contact", contact, ContactPatch),
        ):
            if obj is not None and not isinstance(obj, cls):
                raise InputError(
                    f"{name}: expected {cls.__name__} or None, got {type(obj).__name__}"
                )
        self.splice = splice
        self.cavity = cavity
        self.contact = contact
        self.cavity_basis: NDArray[np.float64] | None = None
        self._build()

    # ------------------------------------------------------------ assembly
    def _build(self) -> None:
        p = self.params
        n = self.n_ring
        d = _operators(n, self.fd_order).D
        k, k_bend, m, sources = ring_blocks(p, d, self.splice)
        step = n // self.layout.n_points
        self._point_nodes = np.arange(self.layout.n_points) * step
        self._drive_nodes = np.array([(dp - 1) * step for dp in self.layout.drive_points])
        c_att = np.zeros_like(k)
        for node in self._drive_nodes:
            m[node, node] += self.layout.attachment_mass
            c_att[node, node] += self.layout.attachment_damping
        self._imperfection_nodes = []
        c_imp = np.zeros_like(k)
        for imp in self.imperfections:
            node = int(np.round(imp.angle_deg / 360.0 * n)) % n
            self._imperfection_nodes.append(node)
            m[node, node] += imp.mass
            m[n + node, n + node] += imp.mass / 2  # mid-point i + 1/2
            m[n + (node - 1) % n, n + (node - 1) % n] += imp.mass / 2  # mid-point i - 1/2
            k[node, node] += imp.stiffness
            c_imp[node, node] += imp.damping
        sources["attachment"] = c_att
        sources["imperfections"] = c_imp
        k = 0.5 * (k + k.T)
        self.patch = None
        area_change = None
        if self.contact is not None:
            self.patch = solve_patch(k, self.contact, p.radius)
            k_c, c_c = contact_blocks(self.patch, self.contact)
            k = k + k_c
            sources["contact"] = c_c
            area_change = -p.width * patch_intrusion(self.patch, self.contact, p.radius, n)
        if self.cavity is not None:
            blk = cavity_blocks(
                self.cavity, d, pressure=p.pressure, band_width=p.width, area_change=area_change
            )
            self.cavity_basis = blk.basis
            m, k, sources = with_cavity(m, k, sources, blk)
        sources = {name: c for name, c in sources.items() if np.any(c)}
        self.damping_sources: dict[str, NDArray[np.float64]] = sources
        self.K_bend = k_bend
        # the rubber parts (virtual.rubber): sidewall foundation and band (membrane + bending)
        self.K_sidewall, self.K_band = _rubber_parts(p, d, k_bend, k.shape[0])
        c = sum(sources.values(), np.zeros_like(k))
        self.physical_system = MCKSystem(m, 0.5 * (c + c.T), k)
        nu = self.nonproportionality
        if nu == 1.0:
            self.system = self.physical_system
        else:
            c_p = proportional_part(self.physical_system)
            c_nu = c_p if nu == 0.0 else c_p + nu * (self.physical_system.C - c_p)
            self.system = self.physical_system.with_damping(0.5 * (c_nu + c_nu.T))

    # ------------------------------------------------------------ geometry
    @property
    def n_dof(self) -> int:
        """Number of DOFs: ``2 n_ring``, plus ``n_ring - 1`` air DOFs with a cavity."""
        return int(self.physical_system.M.shape[0])

    @property
    def cavity_dofs(self) -> NDArray[np.intp]:
        """DOF indices of the reduced air coordinates (empty without a cavity)."""
        return np.arange(2 * self.n_ring, self.n_dof, dtype=np.intp)

    @property
    def M(self) -> NDArray[np.float64]:
        """Mass matrix in kg, shape (n_dof, n_dof)."""
        return self.system.M

    @property
    def C(self) -> NDArray[np.float64]:
        """Damping matrix in N s/m (after the ``nonproportionality`` knob), (n_dof, n_dof)."""
        return self.system.C

    @property
    def K(self) -> NDArray[np.float64]:
        """Stiffness matrix in N/m, shape (n_dof, n_dof)."""
        return self.system.K

    @property
    def node_angles_deg(self) -> NDArray[np.float64]:
        """Angles of the radial DOFs (ring nodes) in deg, shape (n_ring,)."""
        return np.arange(self.n_ring, dtype=np.float64) * (360.0 / self.n_ring)

    @property
    def tangential_angles_deg(self) -> NDArray[np.float64]:
        """Angles of the tangential DOFs (mid-points) in deg, shape (n_ring,)."""
        return (np.arange(self.n_ring, dtype=np.float64) + 0.5) * (360.0 / self.n_ring)

    @property
    def radial_dofs(self) -> NDArray[np.intp]:
        """DOF indices of all radial displacements, shape (n_ring,)."""
        return np.arange(self.n_ring, dtype=np.intp)

    @property
    def tangential_dofs(self) -> NDArray[np.intp]:
        """DOF indices of all tangential displacements, shape (n_ring,)."""
        return np.arange(self.n_ring, 2 * self.n_ring, dtype=np.intp)

    @property
    def point_dofs(self) -> NDArray[np.intp]:
        """DOF index of the radial displacement at each measured point, shape (n_points,)."""
        return self._point_nodes.astype(np.intp)

    @property
    def drive_dofs(self) -> NDArray[np.intp]:
        """DOF index of each drive point (radial), shape (n_drive,)."""
        return self._drive_nodes.astype(np.intp)

    @property
    def imperfection_angles_deg(self) -> NDArray[np.float64]:
        """Angles (deg) of the nodes where the imperfections were applied, shape (k,)."""
        return np.array(self._imperfection_nodes, dtype=float) * (360.0 / self.n_ring)

    @property
    def point_angles_deg(self) -> NDArray[np.float64]:
        """Angles of the measured points in deg, shape (n_points,)."""
        return self.layout.angles_deg

    @property
    def output_channels(self) -> tuple[Channel, ...]:
        """Acceleration channels: node = point number, radial (direction 3), name ``A<k>``."""
        return tuple(
            Channel(node=k + 1, direction=3, angle_deg=float(a), name=f"A{k + 1}")
            for k, a in enumerate(self.point_angles_deg)
        )

    @property
    def input_channels(self) -> tuple[Channel, ...]:
        """Force channels at the drive points, named ``F<k>``."""
        ang = self.point_angles_deg
        return tuple(
            Channel(node=dp, direction=3, angle_deg=float(ang[dp - 1]), name=f"F{dp}")
            for dp in self.layout.drive_points
        )

    def __repr__(self) -> str:
        return (
            f"RingTyre(n_ring={self.n_ring}, n_dof={self.n_dof}, p={self.params.pressure:g} Pa, "
            f"drive_points={self.layout.drive_points}, nu={self.nonproportionality:g}, "
            f"imperfections={len(self.imperfections)})"
        )

    # --------------------------------------------------------------- modes
    def mode_wave_numbers(self) -> tuple[NDArray[np.int_], NDArray[np.float64]]:
        """Wave number and purity of every undamped mode (see :func:`wave_numbers`).

        Returns
        -------
        n, purity : ndarray, shape (n_dof,)
            In the order of ``system.undamped_modes()`` (ascending frequency).
        """
        phi = self.system.undamped_modes().phi
        return wave_numbers(phi[: self.n_ring], phi[self.n_ring : 2 * self.n_ring])

    def ring_frequencies(self, n_max: int = 6) -> NDArray[np.float64]:
        """Undamped frequencies of the two flexural modes of each wave number 1..n_max.

        The modes are classified by the Fourier analysis of their shapes
        (:func:`wave_numbers`), so the cos/sin members of each double are
        paired correctly even where branches interleave in frequency.

        Parameters
        ----------
        n_max : int
            Largest wave number, below ``n_ring / 2``.

        Returns
        -------
        ndarray, shape (n_max, 2)
            Row ``n - 1``: the two lowest frequencies (Hz) with wave number
            ``n``, ascending.

        Raises
        ------
        PhysicsError
            If fewer than two modes have wave number ``n`` (a strongly
            imperfect ring whose shapes mix harmonics).
        """
        if not isinstance(n_max, int | np.integer) or not 1 <= n_max < self.n_ring / 2:
            raise InputError(
                f"n_max: expected an integer in 1..{self.n_ring // 2 - 1}, got {n_max!r}"
            )
        f = self.system.undamped_modes().frequency_hz
        nn, _ = self.mode_wave_numbers()
        out = np.empty((int(n_max), 2))
        for n in range(1, int(n_max) + 1):
            idx = np.flatnonzero(nn == n)
            if idx.size < 2:
                raise PhysicsError(
                    f"ring_frequencies: found {idx.size} mode(s) with wave number {n}, expected 2"
                )
            out[n - 1] = np.sort(f[idx])[:2]
        return out

    def truth(self, band: tuple[float, float] = (0.0, 200.0)) -> TyreTruth:
        """The exact modal truth of this tyre in ``band`` (Hz); see :class:`TyreTruth`."""
        return TyreTruth.from_tyre(self, band)


@dataclass(frozen=True)
class RingConvergence:
    """Discrete ring frequencies against the analytic ones for several ``n_ring``.

    Attributes
    ----------
    n_ring : ndarray of int, shape (k,)
        Numbers of ring nodes.
    wave_number : ndarray of int, shape (n_max,)
        ``1 .. n_max``.
    frequency_hz : ndarray, shape (k, n_max, 2)
        The two discrete frequencies (cos and sin member) of each wave number,
        identified by Fourier analysis of the mode shapes.
    analytic_hz : ndarray, shape (n_max,)
        Inextensible formula (spec ``virtual-tyre.md``).
    extensible_hz : ndarray, shape (n_max,)
        Continuous extensible ring (finite ``EA``), the limit of the
        discretisation as ``n_ring`` grows.
    fd_order : int
        Order of the staggered differences.
    """

    n_ring: NDArray[np.int_]
    wave_number: NDArray[np.int_]
    frequency_hz: NDArray[np.float64]
    analytic_hz: NDArray[np.float64]
    extensible_hz: NDArray[np.float64]
    fd_order: int

    @property
    def relative_error(self) -> NDArray[np.float64]:
        """``max |f - f_analytic| / f_analytic`` over each pair, shape (k, n_max)."""
        a = self.analytic_hz[None, :, None]
        return np.max(np.abs(self.frequency_hz - a) / a, axis=2)

    @property
    def discretisation_error(self) -> NDArray[np.float64]:
        """Error against the continuous *extensible* ring, shape (k, n_max)."""
        e = self.extensible_hz[None, :, None]
        return np.max(np.abs(self.frequency_hz - e) / e, axis=2)

    @property
    def observed_order(self) -> NDArray[np.float64]:
        """``-d log(discretisation error) / d log(n_ring)`` between rows, shape (k - 1, n_max)."""
        err = np.maximum(self.discretisation_error, 1e-300)
        return -np.diff(np.log(err), axis=0) / np.diff(np.log(self.n_ring))[:, None]

    def format(self) -> str:
        """The table as text: lower-member frequency (Hz) and |error| vs analytic (%) per n."""
        head = "n_ring " + " ".join(f"{'n=' + str(n):>17s}" for n in self.wave_number)
        lines = [head, "analyt " + " ".join(f"{f:10.3f} Hz     " for f in self.analytic_hz)]
        for i, nr in enumerate(self.n_ring):
            cells = [
                f"{self.frequency_hz[i, j, 0]:10.3f} {100 * self.relative_error[i, j]:6.3f}%"
                for j in range(self.wave_number.size)
            ]
            lines.append(f"{nr:6d} " + " ".join(cells))
        return "\n".join(lines)


def ring_convergence(
    params: RingTyreParameters | None = None,
    n_rings: Sequence[int] = (16, 32, 48, 64, 96, 128),
    n_max: int = 6,
    fd_order: int = 6,
) -> RingConvergence:
    """Convergence of the discrete ring frequencies with ``n_ring`` (bare ring).

    The ring is built without drive-point attachments or imperfections, so
    each wave number has an exact double mode; modes are paired by wave number
    with :meth:`RingTyre.ring_frequencies`. Only the undamped problem is
    solved.

    Parameters
    ----------
    params : RingTyreParameters, optional
        Default: the 295/80R22.5 at 7.5 bar.
    n_rings : sequence of int
        Node counts; each needs ``gcd(n_ring, 16) >= 3`` (for the layout) and
        ``n_ring > 2 n_max``.
    n_max : int
        Largest wave number.
    fd_order : {2, 4, 6}
        Order of the staggered differences.

    Returns
    -------
    RingConvergence
    """
    prm = params if params is not None else RingTyreParameters()
    nr = [int(x) for x in n_rings]
    if not nr:
        raise InputError("n_rings: expected at least one node count")
    freqs = np.empty((len(nr), n_max, 2))
    for i, n in enumerate(nr):
        npts = math.gcd(n, 16)
        if npts < 3 or n <= 2 * n_max:
            raise InputError(
                f"n_rings: {n} nodes cannot carry wave numbers up to {n_max} with a 16-point "
                "compatible layout; use multiples of 4 above 2 n_max"
            )
        layout = MeasurementLayout(n_points=npts, attachment_mass=0.0, attachment_damping=0.0)
        tyre = RingTyre(prm, layout, n_ring=n, fd_order=fd_order, nonproportionality=1.0)
        freqs[i] = tyre.ring_frequencies(n_max)
    wn = np.arange(1, n_max + 1)
    return RingConvergence(
        n_ring=np.array(nr),
        wave_number=wn,
        frequency_hz=freqs,
        analytic_hz=analytic_ring_frequencies(prm, wn),
        extensible_hz=ring_dispersion(prm, wn),
        fd_order=int(fd_order),
    )
