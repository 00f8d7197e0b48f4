"""The virtual measurement of a rolling ring tyre: fixed and in-tyre sensors.

The tyre is simulated exactly in its rotating frame
(:class:`~tyredamp.virtual.RotatingRing`): each state-space mode ``q' = p q +
U f`` is integrated over a step with a first-order hold of the nodal forces
(the one-step coefficients of :func:`tyredamp.mechanics.step_coefficients`),
and the field is ``x = 2 Re sum V q`` (:mod:`tyredamp.mechanics.gyroscopic`).

Road force
----------
The road pushes radially at a point fixed in space (``contact.angle_deg``).
In the rotating frame that point moves: when the tyre has turned by
``Omega t`` the load acts at the material angle ``phi_c - Omega t``, and its
nodal loads are the trigonometric-interpolation weights of that angle
(:func:`~tyredamp.virtual.rotation.trig_interpolation`, the transpose of
reading the field there, so load and sensor are consistent). A contact patch
is any object with the same ``nodal_load(turned, n_ring)`` method
(:class:`ContactLoad`). The random road force is band-limited Gaussian noise;
an optional known force (impulses or a periodic chirp) acts at the same point
and is recorded.

Sensors
-------
* Fixed sensors at angles ``phi_k`` (e.g. laser vibrometers around the
  tyre): the material moves past them, so they see ``u = w(phi_k - Omega t,
  t)``, evaluated with the trigonometric interpolant of the nodal field, not
  the nearest node; velocity ``w_t - Omega w_theta`` and acceleration
  ``w_tt - 2 Omega w_theta,t + Omega^2 w_theta,theta`` follow exactly.
* In-tyre sensors at material angles ``theta_s`` (accelerometers on the
  inner liner): ``w(theta_s, t)`` and its time derivatives in the rotating
  frame (the steady centripetal ``Omega^2 R`` and gravity are left out).

The response is simulated ``oversample`` times faster than ``sample_rate``
and decimated with an anti-alias polyphase filter
(:func:`scipy.signal.resample_poly`); ``settle`` seconds from rest are
simulated and dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import lfilter, resample_poly

from .._validate import as_band, check_positive
from ..exceptions import InputError
from ..frf import Channel
from ..mechanics import step_coefficients
from ..mechanics.gyroscopic import StateModes
from ..signal.excitation import periodic_chirp
from ..timedata import Acquisition, TimeData
from .ring import RingTyre
from .rolling_truth import RollingTruth
from .rotation import RotatingRing, critical_speed_kmh, trig_interpolation

__all__ = [
    "ContactLoad",
    "PointContact",
    "RollingTest",
    "rolling_response",
    "rolling_test",
]

Quantity = Literal["displacement", "velocity", "acceleration"]
KnownExcitation = Literal["none", "impulse", "chirp"]
_CHUNK = 8192


class ContactLoad(Protocol):
    """A road load fixed in space: its nodal distribution on the turning ring."""

    def nodal_load(self, turned: NDArray[np.float64], n_ring: int) -> NDArray[np.float64]:
        """Radial nodal forces per newton of road force, shape (m, n_ring).

        ``turned`` (rad, shape (m,)) is the angle ``Omega t`` by which the
        tyre has turned at each instant.
        """


@dataclass(frozen=True)
class PointContact:
    """A radial point load fixed in space at ``angle_deg`` (deg, in the direction of rotation)."""

    angle_deg: float = 0.0

    def __post_init__(self) -> None:
        a = float(self.angle_deg)
        if not np.isfinite(a):
            raise InputError(f"contact angle: expected a finite angle in deg, got {a}")
        object.__setattr__(self, "angle_deg", a)

    def nodal_load(self, turned: NDArray[np.float64], n_ring: int) -> NDArray[np.float64]:
        """Trigonometric-interpolation weights at the material angle ``phi_c - turned``."""
        return trig_interpolation(np.deg2rad(self.angle_deg) - turned, n_ring)


def _harmonics(x: NDArray[np.float64]) -> NDArray[np.complex128]:
    """Weighted harmonics ``c_k X_k / N`` of nodal fields (columns), shape (N/2 + 1, L).

    The trigonometric interpolant (:func:`trig_interpolation`) of the field is
    then ``Re sum_k H_k e^{i k theta}``.
    """
    n = x.shape[0]
    h = np.fft.rfft(x, axis=0) / n
    h[1:] *= 2.0
    if n % 2 == 0:
        h[-1] = 0.0  # the grid's standing Nyquist pattern (see trig_interpolation)
    return h


def _sensor_signal(
    h: tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]],
    theta: NDArray[np.float64],
    omega: float,
    quantity: str,
    fixed: bool,
) -> NDArray[np.float64]:
    """One sensor over a chunk from the harmonics ``h`` of (x, x', x'') of the radial nodes.

    A fixed sensor (material angle ``theta(t) = phi - Omega t``) adds the convected
    terms ``-Omega d/dtheta`` of the time derivative; an in-tyre one does not.
    """
    k = np.arange(h[0].shape[0])[:, None]
    ik = 1j * k
    om = omega if fixed else 0.0
    if quantity == "displacement":
        coef = h[0]
    elif quantity == "velocity":
        coef = h[1] - om * ik * h[0]
    else:
        coef = h[2] - 2 * om * ik * h[1] + om**2 * ik**2 * h[0]
    z = np.exp(1j * theta)
    acc = coef[-1].copy()
    for row in coef[-2::-1]:  # Horner: sum_k coef_k z^k
        acc = acc * z + row
    return np.asarray(np.real(acc), dtype=np.float64)


def rolling_response(
    ring: RotatingRing,
    force: ArrayLike,
    sample_rate: float,
    *,
    fixed_deg: ArrayLike = (),
    rotating_deg: ArrayLike = (),
    contact: ContactLoad | None = None,
    quantity: Quantity = "acceleration",
    modes: StateModes | None = None,
    q0: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Signals of fixed and in-tyre radial sensors of a rolling ring (module docstring).

    Parameters
    ----------
    ring : RotatingRing
        The spinning tyre.
    force : array_like, shape (L,)
        Radial road force in N at the contact, sampled at ``sample_rate``
        (first-order hold between samples); zeros for a free response.
    sample_rate : float
        Simulation rate in Hz.
    fixed_deg : array_like, shape (n_f,)
        Angles of the fixed sensors in deg (in space).
    rotating_deg : array_like, shape (n_r,)
        Material angles of the in-tyre sensors in deg.
    contact : ContactLoad, optional
        Default ``PointContact(0.0)``.
    quantity : {"displacement", "velocity", "acceleration"}
        What the sensors give (m, m/s, m/s^2).
    modes : StateModes, optional
        ``ring.system.state_modes()``, if already computed.
    q0 : array_like, complex, shape (m,), optional
        Initial modal state (one entry per mode of ``modes``); default rest.
        A single non-zero entry starts one travelling wave.

    Returns
    -------
    ndarray, shape (n_f + n_r, L)
        Fixed sensors first, then the in-tyre sensors.
    """
    if quantity not in ("displacement", "velocity", "acceleration"):
        raise InputError(
            f"quantity: expected displacement, velocity or acceleration, got {quantity!r}"
        )
    fs = check_positive(sample_rate, "sample_rate")
    f = np.asarray(force, dtype=float).ravel()
    cm = modes if modes is not None else ring.system.state_modes()
    load = contact if contact is not None else PointContact()
    n = ring.n_ring
    phi_f = np.deg2rad(np.atleast_1d(np.asarray(fixed_deg, dtype=float)))
    th_r = np.deg2rad(np.atleast_1d(np.asarray(rotating_deg, dtype=float)))
    q = np.zeros(cm.poles.size, complex) if q0 is None else np.asarray(q0, complex).copy()
    if q.shape != cm.poles.shape:
        raise InputError(f"q0: expected {cm.poles.size} modal amplitudes, got shape {q.shape}")
    phi, e0, e1 = step_coefficients(cm.poles, 1.0 / fs)
    u_w = cm.input[:, :n]
    inv_mass = 1.0 / np.diag(ring.system.M)[:n]
    zi: NDArray[np.complex128] | None = None
    out = np.empty((phi_f.size + th_r.size, f.size))
    for start in range(0, f.size, _CHUNK):
        stop = min(start + _CHUNK, f.size)
        turned = np.asarray(ring.omega * np.arange(start, stop) / fs, dtype=np.float64)
        nodal = load.nodal_load(turned, n) * f[start:stop, None]  # (L, N)
        g = u_w @ nodal.T
        if zi is None:
            zi = q - e1 * g[:, 0]
        qc = np.empty_like(g)
        for j in range(g.shape[0]):
            b = np.array([e1[j], e0[j] - e1[j]])
            qc[j], zf = lfilter(b, np.array([1.0, -phi[j]]), g[j], zi=zi[j : j + 1])
            zi[j] = zf[0]
        x = 2 * np.real(cm.displacement[:n] @ qc)
        xd = 2 * np.real(cm.velocity[:n] @ qc)
        xdd = 2 * np.real(cm.velocity[:n] @ (cm.poles[:, None] * qc)) + inv_mass[:, None] * nodal.T
        hx = (_harmonics(x), _harmonics(xd), _harmonics(xdd))
        for i, a in enumerate(phi_f):
            out[i, start:stop] = _sensor_signal(hx, a - turned, ring.omega, quantity, True)
        for i, a in enumerate(th_r):
            theta = np.full(stop - start, a)
            out[phi_f.size + i, start:stop] = _sensor_signal(hx, theta, 0.0, quantity, False)
    return out


@dataclass(frozen=True, eq=False)
class RollingTest:
    """Result of :func:`rolling_test`: the recording, the rolling truth and the ring.

    Attributes
    ----------
    data : TimeData
        The known force (channel ``F1``, only with a known excitation), the
        fixed sensors ``A1..`` (``angle_deg`` in space) and the in-tyre
        sensors ``T1..`` (``angle_deg`` on the tyre); ``data.meta`` holds
        ``rolling_truth`` (:meth:`RollingTruth.table`), the speed and the
        options.
    truth : RollingTruth
        The exact waves in the band, in both frames.
    ring : RotatingRing
        The simulated tyre.
    """

    data: TimeData
    truth: RollingTruth
    ring: RotatingRing


def _road_force(
    rng: np.random.Generator, n: int, fs: float, band: tuple[float, float], rms: float
) -> NDArray[np.float64]:
    """Gaussian noise band-limited to ``band`` (ideal filter) with the given RMS, shape (n,)."""
    spec = np.fft.rfft(rng.standard_normal(n))
    fr = np.fft.rfftfreq(n, 1.0 / fs)
    spec[(fr < band[0]) | (fr > band[1])] = 0.0
    x = np.fft.irfft(spec, n)
    s = np.std(x)
    return x * (rms / s) if s > 0 and rms > 0 else np.zeros(n)


def _known_force(
    kind: str, n: int, fs: float, band: tuple[float, float], level: float
) -> tuple[NDArray[np.float64], int | None]:
    """Impulses (2 ms half-sines, peak ``level`` N, one per second) or a 4 s periodic chirp."""
    if kind == "none":
        return np.zeros(n), None
    if kind == "impulse":
        width = max(round(0.002 * fs), 2)
        pulse = level * np.sin(np.pi * np.arange(width) / width)
        f = np.zeros(n)
        for s0 in range(int(0.5 * fs), n - width, int(fs)):
            f[s0 : s0 + width] = pulse
        return f, None
    if kind == "chirp":
        p = round(4.0 * fs)
        lo = max(band[0], fs / p)
        sig = periodic_chirp(fs, p, (lo, band[1]), rms=level, n_periods=n // p + 1).signal
        return np.asarray(sig[:n], dtype=float), p
    raise InputError(f"known excitation: expected none, impulse or chirp, got {kind!r}")


def _check_speed(speed_kmh: float, tyre: RingTyre) -> float:
    try:
        ring_speed = float(speed_kmh)
    except (TypeError, ValueError):
        ring_speed = np.nan
    if not np.isfinite(ring_speed) or ring_speed < 0:
        raise InputError(f"speed: expected a finite speed >= 0 km/h, got {speed_kmh!r}")
    v_c = critical_speed_kmh(tyre.params)
    if ring_speed >= v_c:
        raise InputError(
            f"speed: expected a speed below the critical (standing-wave) speed of this tyre, "
            f"{v_c:.0f} km/h at {tyre.params.pressure / 1e5:g} bar, got {ring_speed:g} km/h"
        )
    return ring_speed


def rolling_test(
    speed_kmh: float,
    *,
    tyre: RingTyre | None = None,
    n_sensors: int = 16,
    rotating_deg: ArrayLike = (0.0,),
    contact: ContactLoad | None = None,
    duration: float = 16.0,
    sample_rate: float = 1024.0,
    band: tuple[float, float] = (0.0, 250.0),
    road_force_rms: float = 100.0,
    known_excitation: KnownExcitation = "none",
    known_force: float = 50.0,
    snr_db: float | None = 40.0,
    seed: int | np.random.Generator | None = None,
    oversample: int = 4,
    settle: float = 2.0,
    quantity: Quantity = "acceleration",
) -> RollingTest:
    """Record a rolling tyre with fixed and in-tyre sensors under a random road force.

    Parameters
    ----------
    speed_kmh : float
        Rolling speed in km/h, ``0 <= V <`` :func:`critical_speed_kmh`.
    tyre : RingTyre, optional
        The static tyre (default: the default tyre without shaker
        attachments, physical damping; see :class:`RotatingRing`).
    n_sensors : int
        Fixed sensors, equally spaced in space from the contact angle
        (default 16: every 22.5 deg); 0 for none.
    rotating_deg : array_like of float
        Material angles (deg) of the in-tyre sensors (default one, at 0 deg);
        empty for none.
    contact : ContactLoad, optional
        The road load (default :class:`PointContact` at 0 deg).
    duration : float
        Recorded seconds (default 16).
    sample_rate : float
        Acquisition rate in Hz (default 1024).
    band : (float, float)
        Band of the road force and of the truth in Hz (default 0-250).
    road_force_rms : float
        RMS of the random road force in N (default 100); 0 for none.
    known_excitation : {"none", "impulse", "chirp"}
        A recorded force at the contact: 2 ms half-sine impulses once a
        second, or a 4 s periodic chirp over ``band``.
    known_force : float
        Peak of each impulse or RMS of the chirp in N (default 50).
    snr_db : float or None
        Signal-to-noise ratio of every channel in dB (default 40; ``None``
        for no noise).
    seed : int, Generator or None
        Seed of the road force and the noise.
    oversample : int
        Simulation rate / ``sample_rate`` (default 4).
    settle : float
        Seconds simulated from rest and dropped (default 2).
    quantity : {"displacement", "velocity", "acceleration"}
        What the sensors give.

    Returns
    -------
    RollingTest

    Raises
    ------
    InputError
        A bad speed (NaN, negative, at or above the critical speed) or option.
    """
    ring_tyre = tyre if tyre is not None else RotatingRing().tyre
    speed = _check_speed(speed_kmh, ring_tyre)
    fs, dur, bnd, rot = _checked_options(
        sample_rate, duration, band, oversample, n_sensors, settle, rotating_deg
    )
    ring = RotatingRing(ring_tyre, speed)
    modes = ring.system.state_modes()
    truth = RollingTruth.from_modes(ring, modes, bnd)
    rng = np.random.default_rng(seed)
    r, fs_sim = oversample, fs * oversample
    n_keep = round(dur * fs)
    n_settle = round(settle * fs)
    n_tail = 64  # filter run-out, dropped
    n_sim = (n_settle + n_keep + n_tail) * r
    road = _road_force(rng, n_sim, fs_sim, bnd, float(road_force_rms))
    known, period = _known_force(known_excitation, n_sim, fs_sim, bnd, float(known_force))
    load = contact if contact is not None else PointContact()
    phi_c = float(getattr(load, "angle_deg", 0.0))
    fixed = np.asarray(phi_c + np.arange(n_sensors) * (360.0 / max(n_sensors, 1)), dtype=np.float64)
    sig = rolling_response(
        ring, road + known, fs_sim, fixed_deg=fixed, rotating_deg=rot, contact=load,
        quantity=quantity, modes=modes,
    )  # fmt: skip
    rows = [known[None, :], sig] if known_excitation != "none" else [sig]
    clean = resample_poly(np.vstack(rows), 1, r, axis=1)[:, n_settle : n_settle + n_keep]
    measured, noise_std = _noise(clean, snr_db, rng)
    channels, quantities = _channels(known_excitation != "none", phi_c, fixed, rot, quantity)
    meta = {
        "source": "virtual rolling ring tyre (tyredamp.virtual.rolling_test)",
        "speed_kmh": speed,
        "rotation_hz": ring.rotation_hz,
        "critical_speed_kmh": critical_speed_kmh(ring_tyre.params),
        "contact_deg": phi_c,
        "road_force_rms": float(road_force_rms),
        "known_excitation": known_excitation,
        **_noise_notes(snr_db, noise_std, seed),
        "settle_s": n_settle / fs,
        "rolling_truth": truth.table(),
    }
    acquisition = Acquisition(
        period_samples=None if period is None else period // r,
        band_hz=bnd,
        excitation="road_random" if known_excitation == "none" else known_excitation,
    )
    data = TimeData(measured, fs, channels, quantities, meta, acquisition=acquisition)
    return RollingTest(data=data, truth=truth, ring=ring)


def _checked_options(
    sample_rate: float,
    duration: float,
    band: tuple[float, float],
    oversample: int,
    n_sensors: int,
    settle: float,
    rotating_deg: ArrayLike,
) -> tuple[float, float, tuple[float, float], NDArray[np.float64]]:
    fs = check_positive(sample_rate, "sample_rate")
    dur = check_positive(duration, "duration")
    bnd = as_band(band)
    if bnd[1] >= fs / 2:
        raise InputError(f"band: expected an upper edge below sample_rate/2 = {fs / 2:g} Hz")
    if not isinstance(oversample, int) or oversample < 1:
        raise InputError(f"oversample: expected an integer >= 1, got {oversample!r}")
    if not isinstance(n_sensors, int) or n_sensors < 0:
        raise InputError(f"n_sensors: expected an integer >= 0, got {n_sensors!r}")
    if not np.isfinite(settle) or settle < 0:
        raise InputError(f"settle: expected a duration >= 0 s, got {settle!r}")
    rot = np.atleast_1d(np.asarray(rotating_deg, dtype=float))
    if not np.all(np.isfinite(rot)):
        raise InputError(f"rotating_deg: expected finite angles in deg, got {rot.tolist()}")
    if n_sensors + rot.size == 0:
        raise InputError("sensors: expected at least one fixed or in-tyre sensor")
    return fs, dur, (float(bnd[0]), float(bnd[1])), rot


def _noise(
    clean: NDArray[np.float64], snr_db: float | None, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    if snr_db is None or np.isinf(snr_db):
        return clean, np.zeros(clean.shape[0])
    if not np.isfinite(snr_db):
        raise InputError(f"snr_db: expected a number of dB or None, got {snr_db!r}")
    std = np.sqrt(np.mean(clean**2, axis=1)) * 10 ** (-snr_db / 20)
    return clean + std[:, None] * rng.standard_normal(clean.shape), std


def _noise_notes(
    snr_db: float | None, noise_std: NDArray[np.float64], seed: object
) -> dict[str, Any]:
    return {
        "snr_db": snr_db,
        "noise_std": noise_std.tolist(),
        "seed": seed if isinstance(seed, int) else None,
    }


def _channels(
    with_force: bool,
    phi_c: float,
    fixed: NDArray[np.float64],
    rot: NDArray[np.float64],
    quantity: str,
) -> tuple[list[Channel], list[str]]:
    ch = [Channel(node=1, direction=3, angle_deg=phi_c % 360, name="F1")] if with_force else []
    ch += [
        Channel(node=k + 1, direction=3, angle_deg=float(a % 360), name=f"A{k + 1}")
        for k, a in enumerate(fixed)
    ]
    ch += [
        Channel(node=101 + k, direction=3, angle_deg=float(a % 360), name=f"T{k + 1}")
        for k, a in enumerate(rot)
    ]
    q = (["force"] if with_force else []) + [quantity] * (fixed.size + rot.size)
    return ch, q
