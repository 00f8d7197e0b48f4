"""The rotating ring tyre: Coriolis, centrifugal and centrifugal-tension terms.

Rotating frame (Huang & Soedel 1987)
------------------------------------
The ring of :mod:`.ring` spins at ``Omega`` (rad/s, positive in the direction
of ``theta``). In the frame that rotates with it, a material point at
``(R + w) e_r + v e_theta`` has the inertial velocity
``(w_t - Omega v) e_r + (v_t + Omega (R + w)) e_theta``, so the kinetic energy
``1/2 int rho A |velocity|^2 R dtheta`` adds to the static ring (Huang &
Soedel, "Effects of Coriolis acceleration on the free and forced in-plane
vibrations of rotating rings on elastic foundation", J. Sound Vib. 115(2),
1987, 253-274):

* the Coriolis (gyroscopic) terms ``-2 rho A Omega v_t`` in the radial and
  ``+2 rho A Omega w_t`` in the tangential equation;
* the centrifugal softening ``-rho A Omega^2 w`` and ``-rho A Omega^2 v``;
* the steady centrifugal force ``rho A Omega^2 R``, carried by the hoop
  tension ``N0 = rho A R^2 Omega^2`` (the free-ring value used by Huang &
  Soedel; on the foundation the belt carries ``EA / (EA + k_r R^2)`` of it,
  98 % for the default tyre). ``N0`` acts through the second-order Green
  strain ``N0/(2R) int ((w' - v)^2 + (w + v')^2) dtheta``; unlike the gas
  pressure it does no extra work on the enclosed area.

Dispersion relation (derived here)
----------------------------------
For ``w = a e^{i(n theta + omega t)}``, ``v = -i c e^{i(n theta + omega
t)}`` the equations become the 2x2 quadratic eigenproblem

``[Q(n) + N0/R^2 [[n^2 + 1, 2n], [2n, n^2 + 1]] - rho A Omega^2 I
- rho A omega^2 I - 2 rho A Omega omega J] (a, c)^T = 0``,
``J = [[0, 1], [1, 0]]``,

with ``Q(n)`` the static matrix of :func:`~tyredamp.virtual.ring_dispersion`.
Its determinant is the quartic

``m^2 omega^4 - (m (q11 + q22) + g^2) omega^2 + 2 g q12 omega
+ (q11 q22 - q12^2) = 0``, ``m = rho A``, ``g = 2 rho A Omega``,

(:func:`rotating_ring_roots`). A positive root ``omega`` is a wave travelling
against the rotation (``theta = -omega t / n``: *backward*), a negative one a
wave travelling with it (*forward*). In the inextensible limit ``c = -a/n``
the quartic reduces to

``omega = 2 n Omega/(n^2 + 1) +- sqrt(omega_0^2 + Omega^2 n^2 (n^2 - 1)^2
/ (n^2 + 1)^2)``

(:func:`inextensible_rotating_frequencies`), ``omega_0`` the static
inextensible frequency (derived here). Its term linear in ``Omega`` is
Bryan's effect (G. H. Bryan, Proc. Cambridge Phil. Soc. 7, 1890, 101-111):
the vibration pattern lags the ring at ``2 Omega / (n^2 + 1)``; and with
``omega_0 = 0`` (a free ring with no bending stiffness) the backward wave
stands still in space.

Fixed frame (Doppler)
---------------------
A point at the fixed angle ``phi`` sees the material angle ``theta = phi -
Omega t``, so the wave ``e^{i(k theta + omega t)}`` (``k = +-n``) appears at
``omega - k Omega``: the forward wave at ``|omega_f| + n Omega``, the backward
wave at ``omega_b - n Omega``. With the full centrifugal tension the
backward wave never stands still in space (``omega_b > n Omega`` for every
``omega_0 > 0``); the classical critical speed of a tyre belt is given by
:func:`critical_speed_kmh`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..exceptions import InputError
from ..mechanics.gyroscopic import GyroscopicSystem
from .dispersion import difference_symbol
from .parameters import MeasurementLayout, RingTyreParameters
from .ring import RingTyre, _operators

__all__ = [
    "KMH_PER_MS",
    "RotatingRing",
    "critical_speed_kmh",
    "inextensible_rotating_frequencies",
    "rotating_ring_dispersion",
    "rotating_ring_roots",
    "spin_rate",
    "trig_interpolation",
]

#: km/h per m/s.
KMH_PER_MS = 3.6


def spin_rate(speed_kmh: float, radius: float) -> float:
    """Spin rate ``Omega = V / R`` in rad/s of a ring of ``radius`` (m) rolling at ``speed_kmh``.

    Raises
    ------
    InputError
        A speed that is NaN, infinite or negative.
    """
    try:
        v = float(speed_kmh)
    except (TypeError, ValueError):
        raise InputError(f"speed: expected a number of km/h, got {speed_kmh!r}") from None
    if not np.isfinite(v) or v < 0:
        raise InputError(f"speed: expected a finite speed >= 0 km/h, got {v:g}")
    return v / KMH_PER_MS / radius


def _static_q(
    params: RingTyreParameters, s: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``q11, q12, q22`` of the static ring (same as :func:`ring_dispersion`)."""
    r = params.radius
    ea, ei, t0 = params.membrane_stiffness, params.bending_stiffness, params.hoop_tension
    q11 = (ea + t0) / r**2 + ei * s**4 / r**4 + t0 * (s**2 - 1) / r**2 + params.radial_stiffness
    q12 = (ea + t0) * s / r**2 + ei * s**3 / r**4
    q22 = (ea + t0) * s**2 / r**2 + ei * s**2 / r**4 + params.tangential_stiffness
    return q11, q12, q22


def _rotating_q(
    params: RingTyreParameters, s: NDArray[np.float64], omega: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The stiffness of the 2x2 rotating problem (module docstring), ``N0 = rho A R^2 Omega^2``."""
    q11, q12, q22 = _static_q(params, s)
    m = params.mass_per_length
    n0r2 = m * omega**2  # N0 / R^2
    return (
        q11 + n0r2 * (s**2 + 1) - m * omega**2,
        q12 + n0r2 * 2 * s,
        q22 + n0r2 * (s**2 + 1) - m * omega**2,
    )


def _wave_numbers(n: ArrayLike, n_ring: int | None) -> NDArray[np.float64]:
    arr = np.atleast_1d(np.asarray(n, dtype=float))
    if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr < 1) or np.any(arr % 1):
        raise InputError(f"n: expected integer wave numbers >= 1, got {arr.tolist()}")
    if n_ring is not None and np.any(arr >= n_ring / 2):
        raise InputError(f"n: expected wave numbers below n_ring/2 = {n_ring / 2:g}")
    return arr


def rotating_ring_roots(
    params: RingTyreParameters,
    n: ArrayLike,
    speed_kmh: float,
    *,
    n_ring: int | None = None,
    fd_order: int = 6,
) -> NDArray[np.float64]:
    """The four roots ``omega`` (rad/s) of the rotating ring's quartic for each ``n``.

    ``m^2 omega^4 - (m (q11 + q22) + g^2) omega^2 + 2 g q12 omega + (q11 q22
    - q12^2) = 0`` (module docstring), derived from the rotating-frame
    equations of Huang & Soedel (J. Sound Vib. 115(2), 1987) for the
    extensible ring of :mod:`.ring`. Each root belongs to the wave
    ``e^{i(n theta + omega t)}`` in the rotating frame: ``omega > 0``
    travels against the rotation (backward), ``omega < 0`` with it
    (forward).

    Parameters
    ----------
    params : RingTyreParameters
    n : array_like of int, shape (k,)
        Wave numbers >= 1.
    speed_kmh : float
        Rolling speed ``V`` in km/h; ``Omega = V / R``.
    n_ring : int, optional
        Nodes of the staggered discretisation: ``n`` is replaced by the
        difference symbol ``s(n)`` in the stiffness (which the discrete
        :class:`RotatingRing` then reproduces); ``None`` for the continuous
        ring.
    fd_order : {2, 4, 6}
        Order of the staggered differences.

    Returns
    -------
    ndarray, shape (k, 4)
        The roots in rad/s, ascending; complex roots (a diverged ring) are
        returned as NaN.
    """
    nn = _wave_numbers(n, n_ring)
    omega = spin_rate(speed_kmh, params.radius)
    s = difference_symbol(nn, n_ring, fd_order)
    q11, q12, q22 = _rotating_q(params, s, omega)
    m = params.mass_per_length
    g = 2 * m * omega
    out = np.empty((nn.size, 4))
    for i in range(nn.size):
        coeffs = [m**2, 0.0, -(m * (q11[i] + q22[i]) + g**2), 2 * g * q12[i]]
        coeffs.append(q11[i] * q22[i] - q12[i] ** 2)
        poly = np.array(coeffs) / m**2
        r = np.roots(poly)
        tol = 1e-7 * np.max(np.abs(r))
        real = np.where(np.abs(r.imag) <= tol, r.real, np.nan)
        deriv = np.polyder(poly)
        for _ in range(3):  # Newton polish of the companion-matrix roots
            real = real - np.polyval(poly, real) / np.polyval(deriv, real)
        out[i] = np.sort(real)
    return out


def rotating_ring_dispersion(
    params: RingTyreParameters,
    n: ArrayLike,
    speed_kmh: float,
    *,
    frame: str = "rotating",
    n_ring: int | None = None,
    fd_order: int = 6,
) -> NDArray[np.float64]:
    """Frequencies of the forward and backward flexural waves of wave number ``n``.

    The flexural roots are the two of smallest magnitude of
    :func:`rotating_ring_roots` (the other two are the membrane branch):
    the negative one is the forward wave, the positive one the backward
    wave. In the fixed frame they appear at ``|omega_f| + n Omega`` and
    ``omega_b - n Omega`` (Doppler; module docstring); a negative fixed-frame
    backward frequency means the backward wave is carried forward past a
    fixed point (above the critical speed).

    Parameters
    ----------
    params : RingTyreParameters
    n : array_like of int, shape (k,)
        Wave numbers >= 1.
    speed_kmh : float
        Rolling speed in km/h (``Omega = V / R``).
    frame : {"rotating", "fixed"}
        Frame in which the frequencies are seen.
    n_ring, fd_order
        As in :func:`rotating_ring_roots`.

    Returns
    -------
    ndarray, shape (k, 2)
        Columns forward, backward, in Hz.
    """
    if frame not in ("rotating", "fixed"):
        raise InputError(f"frame: expected 'rotating' or 'fixed', got {frame!r}")
    roots = rotating_ring_roots(params, n, speed_kmh, n_ring=n_ring, fd_order=fd_order)
    nn = _wave_numbers(n, n_ring)
    order = np.argsort(np.abs(np.nan_to_num(roots, nan=np.inf)), axis=1)
    flex = np.take_along_axis(roots, order[:, :2], axis=1)
    fwd = -np.min(flex, axis=1)
    bwd = np.max(flex, axis=1)
    if frame == "fixed":
        omega = spin_rate(speed_kmh, params.radius)
        fwd, bwd = fwd + nn * omega, bwd - nn * omega
    return np.column_stack([fwd, bwd]) / (2 * np.pi)


def inextensible_rotating_frequencies(
    params: RingTyreParameters, n: ArrayLike, speed_kmh: float
) -> NDArray[np.float64]:
    """Forward and backward rotating-frame frequencies of the inextensible ring (Hz).

    ``omega_{f,b} = -+ 2 n Omega/(n^2 + 1) + sqrt(omega_0^2 + Omega^2 n^2
    (n^2 - 1)^2/(n^2 + 1)^2)`` with ``omega_0`` from
    :func:`~tyredamp.virtual.analytic_ring_frequencies` (the quartic of
    :func:`rotating_ring_roots` with ``v' = -w``, derived here; its linear
    term in ``Omega`` is Bryan's effect, Proc. Cambridge Phil. Soc. 7, 1890).
    The limit of :func:`rotating_ring_dispersion` as ``EA -> inf``.

    Returns
    -------
    ndarray, shape (k, 2)
        Columns forward, backward, in Hz (rotating frame).
    """
    from .dispersion import analytic_ring_frequencies

    nn = _wave_numbers(n, None)
    omega = spin_rate(speed_kmh, params.radius)
    w0 = 2 * np.pi * analytic_ring_frequencies(params, nn)
    gyro = 2 * nn * omega / (nn**2 + 1)
    root = np.sqrt(w0**2 + omega**2 * nn**2 * (nn**2 - 1) ** 2 / (nn**2 + 1) ** 2)
    return np.column_stack([root - gyro, root + gyro]) / (2 * np.pi)


def critical_speed_kmh(params: RingTyreParameters) -> float:
    """Classical critical (standing-wave) speed of the tyre belt in km/h.

    ``V_c^2 = (T0 + 2 sqrt(k_r EI)) / rho A``: the lowest speed at which a
    load moving along a tensioned beam on an elastic foundation (the belt
    unrolled) meets a wave that stands still under it. With ``w =
    exp(i beta (x - V t))`` the beam ``EI w_xxxx - T0 w_xx + rho A w_tt + k_r w
    = 0`` gives ``EI beta^4 - (rho A V^2 - T0) beta^2 + k_r = 0``, whose
    double root is at ``rho A V^2 - T0 = 2 sqrt(k_r EI)`` (Fryba, *Vibration
    of Solids and Structures under Moving Loads*, 3rd ed., 1999, ch. 1; for
    tyres: Clark, *Mechanics of Pneumatic Tires*, 1981, ch. 8). Real tyres
    form standing waves near this speed. The rotating ring of
    :class:`RotatingRing` carries the full centrifugal tension
    ``rho A V^2``, which cancels the ``rho A V^2`` above (a spinning chain
    holds any shape still in space), so it has no standing wave of its own;
    the rolling rig refuses speeds at or above ``V_c`` because the model is
    not trusted there.

    Returns
    -------
    float
        ``V_c`` in km/h.
    """
    t0 = params.hoop_tension
    ei = params.bending_stiffness
    v2 = (t0 + 2 * np.sqrt(params.radial_stiffness * ei)) / params.mass_per_length
    return float(np.sqrt(v2) * KMH_PER_MS)


def trig_interpolation(
    angles: ArrayLike,
    n_nodes: int,
    offset: float = 0.0,
    derivative: int = 0,
    *,
    nyquist: bool = False,
) -> NDArray[np.float64]:
    """Weights of the trigonometric (Fourier) interpolant on ``n_nodes`` equally spaced angles.

    For samples ``f_j`` at ``theta_j = (j + offset) h``, ``h = 2 pi /
    n_nodes``, the interpolant is ``f(theta) = (1/N) sum_{k=0}^{N/2} c_k
    sum_j f_j cos(k (theta - theta_j))`` (``c_0 = 1``, ``c_k = 2``; Trefethen,
    *Spectral Methods in MATLAB*, SIAM 2000, ch. 3). It reproduces every
    harmonic below ``N/2`` exactly, which is the ring's own discrete
    representation. The harmonic ``k = N/2`` of an even ``N`` (``c = 1``
    with ``nyquist=True``) is left out by default: on the grid it is a
    standing pattern ``cos(N theta / 2)`` that cannot travel, so a moving
    load or sensor would couple it to itself at ``+- N Omega`` (a grid
    artefact, not a wave of the ring).

    Parameters
    ----------
    angles : array_like, shape (m,)
        Where to evaluate, in rad.
    n_nodes : int
        Number of samples ``N``.
    offset : float
        Grid offset in steps (0 for the ring nodes, 0.5 for the mid-points).
    derivative : {0, 1, 2}
        Derivative order in ``theta`` of the interpolant.
    nyquist : bool
        Keep the harmonic ``N/2`` (the classical interpolant through the
        samples); default False.

    Returns
    -------
    ndarray, shape (m, n_nodes)
        ``f(angles) = W @ f_nodes`` (or its ``theta`` derivative).
    """
    a = np.atleast_1d(np.asarray(angles, dtype=float))
    n = int(n_nodes)
    k = np.arange(n // 2 + 1, dtype=float)
    c = np.full(k.size, 2.0)
    c[0] = 1.0
    if n % 2 == 0:
        c[-1] = 1.0 if nyquist else 0.0
    theta = (np.arange(n) + offset) * (2 * np.pi / n)
    e = np.exp(1j * a[:, None] * k[None, :]) * (c * (1j * k) ** derivative)[None, :]
    basis = np.exp(-1j * k[:, None] * theta[None, :])
    return np.asarray(np.real(e @ basis) / n, dtype=np.float64)


class RotatingRing:
    """The discretised ring tyre spinning at a rolling speed, in its rotating frame.

    ``M x'' + (C + G) x' + (K + K_Omega) x = f`` with ``M``, ``C``, ``K`` of
    the static :class:`~tyredamp.virtual.RingTyre` (same DOF order: radial
    ``w`` at the nodes, then tangential ``v`` at the mid-points) and

    * ``G``: Coriolis, ``G_wv = -Omega (M_w P + P M_v)``, ``G_vw = -G_wv^T``
      (``2 rho A Omega`` per unit length, Huang & Soedel 1987), where ``P``
      interpolates the mid-point ``v`` to the nodes with the trigonometric
      interpolant (:func:`trig_interpolation`, exact for every harmonic
      below ``n_ring/2``);
    * ``K_Omega = N0 R h/R^2 (E^T E + B^T B) - Omega^2 M``: the centrifugal
      tension ``N0 = rho A R^2 Omega^2`` through the Green strain, with
      ``E w,v = w + D v`` at the nodes and ``B w,v = G w - v`` at the
      mid-points (the staggered differences of :mod:`.ring`), and the
      centrifugal softening of every mass.

    The axisymmetric ring's discrete waves follow :func:`rotating_ring_roots`
    with ``n`` replaced by ``s(n)`` (``n_ring=``), to rounding. Masses of
    :class:`~tyredamp.virtual.Imperfection` spin with the ring: they enter
    ``G`` and ``-Omega^2 M`` through ``M`` (for a point mass the Coriolis
    coupling is then the mean of its radial and tangential lumped shares, an
    approximation). Anything fixed in space (the road, a contact patch) must
    not be part of ``tyre``: it acts through the load of the rolling rig.

    Parameters
    ----------
    tyre : RingTyre, optional
        The static tyre. Default: the default tyre with no shaker attached
        (``attachment_mass = attachment_damping = 0``) and its physical
        damping (``nonproportionality = 1``).
    speed_kmh : float
        Rolling speed ``V`` in km/h; the belt radius gives ``Omega = V / R``.

    Raises
    ------
    InputError
        A bad speed or tyre.
    """

    def __init__(self, tyre: RingTyre | None = None, speed_kmh: float = 0.0) -> None:
        if tyre is None:
            layout = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
            tyre = RingTyre(layout=layout, nonproportionality=1.0)
        if not isinstance(tyre, RingTyre):
            raise InputError(f"tyre: expected a RingTyre, got {type(tyre).__name__}")
        for part, what in ((tyre.cavity, "an air cavity"), (tyre.contact, "a contact patch")):
            if part is not None:
                raise InputError(
                    f"tyre: expected a ring tyre without {what} (the rotating ring does not "
                    f"model it), got one with {what}"
                )
        self.tyre = tyre
        self.speed_kmh = float(speed_kmh)
        self.omega = spin_rate(speed_kmh, tyre.params.radius)
        self._build()

    def _build(self) -> None:
        t = self.tyre
        n, p, om = t.n_ring, t.params, self.omega
        ops = _operators(n, t.fd_order)
        d = ops.D
        g = -d.T
        eye = np.eye(n)
        e_op = np.hstack([eye, d])
        b_op = np.hstack([g, -eye])
        m = t.system.M
        n0 = p.mass_per_length * p.radius**2 * om**2
        arc = p.radius * ops.h
        k_om = arc * n0 / p.radius**2 * (e_op.T @ e_op + b_op.T @ b_op) - om**2 * m
        self.K_rotation = 0.5 * (k_om + k_om.T)
        interp = trig_interpolation(2 * np.pi * np.arange(n) / n, n, offset=0.5)
        mw = np.diag(np.diag(m)[:n])
        mv = np.diag(np.diag(m)[n:])
        gwv = -om * (mw @ interp + interp @ mv)
        gyro = np.zeros((2 * n, 2 * n))
        gyro[:n, n:] = gwv
        gyro[n:, :n] = -gwv.T
        self.G = gyro
        self.system = GyroscopicSystem(m, t.system.C + gyro, t.system.K + self.K_rotation)

    @property
    def n_ring(self) -> int:
        """Number of ring nodes."""
        return self.tyre.n_ring

    @property
    def rotation_hz(self) -> float:
        """Wheel rotation frequency ``Omega / 2 pi`` in Hz."""
        return self.omega / (2 * np.pi)

    @property
    def hoop_tension(self) -> float:
        """Total hoop tension ``T0 + rho A R^2 Omega^2`` in N."""
        p = self.tyre.params
        return p.hoop_tension + p.mass_per_length * p.radius**2 * self.omega**2

    def __repr__(self) -> str:
        return f"RotatingRing(speed={self.speed_kmh:g} km/h, n_ring={self.n_ring})"
