"""Time-domain responses of the lateral models (spec "Causality").

Two routes:

* **Exact steady states in the frequency domain.** A harmonic force
  ``F0 cos(2 pi f t + phi)`` gives ``Re(H(f) F0 e^{i(2 pi f t + phi)})``
  (:func:`harmonic_response`); a periodic force gives its periodic steady
  state line by line through the FFT (:func:`periodic_response`). These are
  exact for every model, including the non-causal hysteretic one (the
  paper's 2.73 Hz test is such a steady state). Real signals imply
  ``H(-omega) = conj(H(omega))``, i.e. ``K + i h sign(omega)``.
* **Transients** need a causal model. :func:`fit_generalized_maxwell` fits a
  generalised Maxwell (Prony) series
  ``Z_c(omega) = k0 + sum_j k_j i omega tau_j / (1 + i omega tau_j)`` (all
  ``k >= 0``, so passive and causal) to ``K + i h`` over a band;
  :class:`GeneralizedMaxwellTyre` puts it in series with the road damper
  ``C_r``. :func:`state_space` builds the exact linear state-space model of
  a body on any rational tyre (classic, Maxwell, relaxation, visco-plastic,
  generalised Maxwell), and :func:`transient_response` simulates it exactly
  for a piecewise-linear force (:func:`scipy.signal.lsim`, matrix
  exponential). Constant loss over a band is not consistent with the
  Kramers-Kronig relations, so the series cannot match ``K + i h`` exactly;
  :func:`causal_error` reports the error.

:func:`impulse_response` inverts ``H`` by FFT (ideal model, precursor
included) and :func:`precursor` gives the size of the part before ``t = 0``
(about 2 % of the peak for the 260 kN/m, 600 kg, ``h/K = 0.077``
oscillator of spec eq. 43).

The generalised Maxwell tyre and its fit are :mod:`tyredamp.lateral.prony`;
:func:`causal_error` is :mod:`tyredamp.lateral.causality`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import StateSpace, lsim

from .._validate import as_finite, check_positive
from ..exceptions import InputError
from .models import (
    ClassicModel,
    HystereticModel,
    LateralModel,
    MaxwellModel,
    RelaxationLengthModel,
    ViscoPlasticModel,
)
from .prony import GeneralizedMaxwellTyre, fit_generalized_maxwell
from .vehicle import LateralVehicle

__all__ = [
    "ImpulseResponse",
    "Output",
    "Precursor",
    "TransientResponse",
    "harmonic_response",
    "impulse_response",
    "periodic_response",
    "precursor",
    "state_space",
    "transient_response",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
Output = Literal["displacement", "velocity", "acceleration"]
_KIND = {"displacement": "receptance", "velocity": "mobility", "acceleration": "accelerance"}


class _Responsive(Protocol):
    def mobility(self, freq_hz: ArrayLike) -> ComplexArray: ...  # pragma: no cover

    def receptance(self, freq_hz: ArrayLike) -> ComplexArray: ...  # pragma: no cover

    def accelerance(self, freq_hz: ArrayLike) -> ComplexArray: ...  # pragma: no cover


def _kind(output: str) -> str:
    if output not in _KIND:
        raise InputError(f"output: expected one of {tuple(_KIND)}, got {output!r}")
    return _KIND[output]


def _eval(system: _Responsive, f: ArrayLike, output: str) -> ComplexArray:
    k = _kind(output)
    if k == "receptance":
        return system.receptance(f)
    if k == "mobility":
        return system.mobility(f)
    return system.accelerance(f)


# ----------------------------------------------------------------------- exact steady state
def harmonic_response(
    system: _Responsive,
    frequency: float,
    amplitude: float,
    time: ArrayLike,
    output: Output = "acceleration",
    phase: float = 0.0,
) -> FloatArray:
    """Steady-state response to ``Fy = amplitude cos(2 pi f t + phase)`` (exact).

    Parameters
    ----------
    system : LateralModel or LateralVehicle
        Anything with ``receptance``, ``mobility`` and ``accelerance``.
    frequency : float
        Excitation frequency in Hz (> 0).
    amplitude : float
        Force amplitude in N.
    time : array_like
        Times in s.
    output : {"displacement", "velocity", "acceleration"}
        Response quantity (m, m/s, m/s^2).
    phase : float
        Force phase in rad.

    Returns
    -------
    ndarray, same shape as ``time``
    """
    f = check_positive(frequency, "frequency")
    t = as_finite(time, "time", dtype=float)
    amp = float(as_finite(amplitude, "amplitude"))
    h = complex(_eval(system, np.array([f]), output)[0])
    return np.asarray((h * amp * np.exp(1j * (2.0 * np.pi * f * t + phase))).real, dtype=float)


def periodic_response(
    system: _Responsive,
    force: ArrayLike,
    sample_rate: float,
    output: Output = "acceleration",
) -> FloatArray:
    """Periodic steady-state response to one period of a sampled force (exact per line).

    The force samples are taken as one period of a periodic signal (the
    period is ``n / sample_rate``); each FFT line is multiplied by the FRF at
    its frequency and transformed back. For a displacement output of a tyre
    with a series damper the mean force must be 0 (else the displacement
    drifts) and the mean displacement is returned as 0.

    Parameters
    ----------
    system : LateralModel or LateralVehicle
    force : array_like, shape (n,)
        Force samples in N over one period (n >= 2).
    sample_rate : float
        Hz.
    output : {"displacement", "velocity", "acceleration"}

    Returns
    -------
    ndarray, shape (n,)
        Response samples (m, m/s or m/s^2).
    """
    x = as_finite(force, "force", ndim=1)
    if x.size < 2:
        raise InputError(f"force: expected at least 2 samples, got {x.size}")
    fs = check_positive(sample_rate, "sample_rate")
    n = x.size
    spec = np.fft.rfft(x)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    h = np.zeros(f.size, dtype=complex)
    h[1:] = _eval(system, f[1:], output)
    try:
        h[0] = _eval(system, f[:1], output)[0]
    except InputError:
        if abs(spec[0]) > 1e-9 * max(float(np.max(np.abs(spec))), np.finfo(float).tiny):
            raise InputError(
                "force: has a non-zero mean, and the displacement of this system under a "
                "static force grows without bound; remove the mean or use velocity/acceleration"
            ) from None
        h[0] = 0.0
    return np.asarray(np.fft.irfft(spec * h, n=n), dtype=float)


# ------------------------------------------------------------------------- impulse response
@dataclass(frozen=True, eq=False)
class ImpulseResponse:
    """Impulse response on a time axis centred on 0 (negative times included).

    Attributes
    ----------
    time : ndarray, shape (n,)
        s, increasing, from ``-duration/2``.
    response : ndarray, shape (n,)
        Response to a unit impulse (1 N s), m (displacement), m/s or m/s^2.
    output : str
        Response quantity.
    """

    time: FloatArray
    response: FloatArray
    output: str


def impulse_response(
    system: _Responsive,
    sample_rate: float = 1000.0,
    duration: float = 64.0,
    output: Output = "displacement",
) -> ImpulseResponse:
    """Impulse response of the (possibly non-causal) model by inverse FFT of its FRF.

    The FRF is sampled at ``k / duration`` up to ``sample_rate / 2`` and
    inverted with Hermitian symmetry. A displacement output of a system whose
    receptance is infinite at 0 Hz (a series damper: the body keeps a
    permanent offset ``V(0)`` per unit impulse) is handled by subtracting
    ``G = V(0) b / (i omega (i omega + b))``, i.e. ``V(0)(1 - e^{-b t})``
    for ``t >= 0`` with ``b = 100/duration`` rad/s, inverting the regular
    remainder (0 Hz value extrapolated quadratically) and adding ``g(t)``
    back exactly.

    Parameters
    ----------
    system : LateralModel or LateralVehicle
    sample_rate : float
        Hz; sets the time step and the highest frequency used.
    duration : float
        Length of the time window in s; the response must have decayed (or
        settled) within ``duration/2``.
    output : {"displacement", "velocity", "acceleration"}
        Velocity and acceleration responses of a body contain a step or an
        impulse at ``t = 0`` that the FFT resolves only with Gibbs ripple;
        displacement is the clean choice.

    Returns
    -------
    ImpulseResponse
    """
    fs = check_positive(sample_rate, "sample_rate")
    tt = check_positive(duration, "duration")
    n = round(fs * tt)
    if n < 16:
        raise InputError(f"sample_rate * duration: expected >= 16 samples, got {n}")
    f = np.fft.rfftfreq(n, 1.0 / fs)
    h = np.empty(f.size, dtype=complex)
    h[1:] = _eval(system, f[1:], output)
    g_time: FloatArray | None = None
    time = (np.arange(n) - n // 2) / fs
    try:
        h[0] = _eval(system, f[:1], output)[0]
    except InputError:
        v0 = complex(system.mobility(np.array([0.0]))[0]).real
        b = 100.0 / tt
        w = 2.0 * np.pi * f[1:]
        h[1:] -= v0 * b / (1j * w * (1j * w + b))
        h[0] = 3.0 * h[1] - 3.0 * h[2] + h[3]
        g_time = np.where(time >= 0, v0 * (1.0 - np.exp(-b * np.clip(time, 0.0, None))), 0.0)
    x = np.fft.irfft(h, n=n) * fs
    x = np.roll(x, n // 2)
    if g_time is not None:
        x = x + g_time
    return ImpulseResponse(time=time, response=np.asarray(x, dtype=float), output=output)


@dataclass(frozen=True, eq=False)
class Precursor:
    """Size of the non-causal part of an impulse response.

    Attributes
    ----------
    ratio : float
        ``max_{t<0} |x| / max_t |x|`` (0 for a causal system, up to the FFT's
        aliasing).
    time_of_max : float
        Time (< 0) of the largest precursor value, s.
    peak : float
        ``max_t |x|`` in the output's unit.
    impulse : ImpulseResponse
        The response used.
    """

    ratio: float
    time_of_max: float
    peak: float
    impulse: ImpulseResponse


def precursor(
    system: _Responsive,
    sample_rate: float = 1000.0,
    duration: float = 64.0,
    output: Output = "displacement",
) -> Precursor:
    """Non-causal precursor of the impulse response (spec "Causality").

    Parameters are those of :func:`impulse_response`. For the 260 kN/m,
    600 kg, ``h/K = 0.077`` oscillator of spec eq. 43
    (``LateralVehicle(HystereticModel(260e3, 0.077 * 260e3, inf), 600)``)
    the ratio is 2.02 % (spec: about 2 %).

    Returns
    -------
    Precursor
    """
    ir = impulse_response(system, sample_rate, duration, output)
    neg = ir.time < 0
    a = np.abs(ir.response)
    i = int(np.argmax(np.where(neg, a, -1.0)))
    peak = float(a.max())
    return Precursor(ratio=float(a[i] / peak), time_of_max=float(ir.time[i]), peak=peak, impulse=ir)


# --------------------------------------------------------------------------- state space
_OUTPUTS = ("displacement", "velocity", "acceleration", "tyre_force")


def _rational_parts(tyre: LateralModel) -> tuple[float, float, list[tuple[float, float]], float]:
    """(k0, c_parallel, [(k_j, tau_j)], c_road) of a rational tyre."""
    if isinstance(tyre, ClassicModel):
        return tyre.k, tyre.c, [], math.inf
    if isinstance(tyre, MaxwellModel):
        return tyre.k, 0.0, [], tyre.c
    if isinstance(tyre, RelaxationLengthModel):
        m = tyre.maxwell()
        return m.k, 0.0, [], m.c
    if isinstance(tyre, ViscoPlasticModel):
        return tyre.k, tyre.c1, [], tyre.c2
    if isinstance(tyre, GeneralizedMaxwellTyre):
        return tyre.k0, 0.0, list(zip(tyre.stiffness, tyre.tau, strict=True)), tyre.C_r
    if isinstance(tyre, HystereticModel):
        raise InputError(
            "tyre: the hysteretic model is not causal and has no state-space form; "
            "approximate it first with fit_generalized_maxwell(model, band)"
        )
    raise InputError(
        f"tyre: {type(tyre).__name__} is not a rational (finite-state) model; "
        "state space is available for classic, Maxwell, relaxation, visco-plastic and "
        "generalised Maxwell tyres"
    )


def state_space(vehicle: LateralVehicle) -> StateSpace:
    """Exact linear state-space model of a body on a rational tyre (spec eq. 41).

    States ``[y, y', z, q_1 .. q_n]``: body displacement and velocity, the
    displacement ``z`` of the node between road damper and carcass (absent
    without a road damper) and the damper displacements ``q_j`` of the
    Maxwell arms. With carcass deflection ``x_c = y - z`` and carcass force
    ``F_c = k0 x_c + c_p x_c' + sum_j k_j (x_c - q_j)``:
    ``C_r z' = F_c``, ``tau_j q_j' = x_c - q_j``, ``M y'' = F - F_c``.

    Parameters
    ----------
    vehicle : LateralVehicle
        Body and tyre; the tyre must be rational (classic, Maxwell,
        relaxation, visco-plastic or :class:`GeneralizedMaxwellTyre`).

    Returns
    -------
    scipy.signal.StateSpace
        Input: force on the body (N). Outputs: displacement (m), velocity
        (m/s), acceleration (m/s^2), tyre (ground) force (N).
    """
    k0, cp, arms, cr = _rational_parts(vehicle.tyre)
    m = vehicle.mass
    has_z = not math.isinf(cr)
    nq = len(arms)
    n = 2 + int(has_z) + nq
    iy, iv = 0, 1
    iz = 2 if has_z else -1
    q0 = 2 + int(has_z)
    # x_c = y - z as a row over the states
    xc = np.zeros(n)
    xc[iy] = 1.0
    if has_z:
        xc[iz] = -1.0
    # Elastic part of the carcass force: k0 x_c + sum k_j (x_c - q_j)
    el = k0 * xc
    for j, (k, _) in enumerate(arms):
        el = el + k * xc
        el[q0 + j] -= k
    a = np.zeros((n, n))
    fc = np.zeros(n)  # carcass force as a row over the states
    if has_z:
        # z' (cr + cp) = el + cp v  (the parallel damper sees v - z')
        zdot = el.copy()
        zdot[iv] += cp
        zdot /= cr + cp
        a[iz] = zdot
        fc = cr * zdot
    else:
        fc = el.copy()
        fc[iv] += cp
    a[iy, iv] = 1.0
    a[iv] = -fc / m
    for j, (_, t) in enumerate(arms):
        row = xc / t
        row[q0 + j] -= 1.0 / t
        a[q0 + j] = row
    b = np.zeros((n, 1))
    b[iv, 0] = 1.0 / m
    c = np.zeros((4, n))
    d = np.zeros((4, 1))
    c[0, iy] = 1.0
    c[1, iv] = 1.0
    c[2] = a[iv]
    d[2, 0] = 1.0 / m
    c[3] = fc
    return StateSpace(a, b, c, d)


@dataclass(frozen=True, eq=False)
class TransientResponse:
    """Simulated response of a body on a causal tyre.

    Attributes
    ----------
    time : ndarray, shape (n,)
        s.
    displacement, velocity, acceleration : ndarray, shape (n,)
        Body motion, m, m/s, m/s^2.
    tyre_force : ndarray, shape (n,)
        Ground force of the tyre on the body, N.
    tyre : LateralModel
        The causal tyre simulated (the approximation for a hysteretic tyre).
    """

    time: FloatArray
    displacement: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    tyre_force: FloatArray
    tyre: LateralModel


def _causal_vehicle(
    vehicle: LateralVehicle,
    band: tuple[float, float] | None,
    per_decade: int,
    f_ref: float | None,
) -> LateralVehicle:
    if isinstance(vehicle.tyre, HystereticModel):
        if band is None:
            raise InputError("band: needed to approximate the hysteretic tyre causally (Hz)")
        return LateralVehicle(
            fit_generalized_maxwell(vehicle.tyre, band, per_decade, f_ref), vehicle.mass
        )
    return vehicle


def transient_response(
    vehicle: LateralVehicle,
    force: ArrayLike,
    sample_rate: float,
    *,
    band: tuple[float, float] | None = None,
    per_decade: int = 3,
    f_ref: float | None = None,
    initial_state: ArrayLike | None = None,
) -> TransientResponse:
    """Transient response of a body on a tyre, from rest, to a sampled force.

    The force is linear between samples; the state-space model
    (:func:`state_space`) is integrated exactly (matrix exponential,
    :func:`scipy.signal.lsim`). A hysteretic tyre is first replaced by its
    generalised Maxwell approximation over ``band``
    (:func:`fit_generalized_maxwell`).

    Parameters
    ----------
    vehicle : LateralVehicle
    force : array_like, shape (n,)
        Force on the body, N.
    sample_rate : float
        Hz.
    band : (float, float), optional
        Approximation band in Hz (required for a hysteretic tyre).
    per_decade : int
        Maxwell arms per decade for the approximation.
    f_ref : float, optional
        Frequency where the approximation's storage stiffness equals ``K``
        (Hz; default the band centre; the resonance is a good choice).
    initial_state : array_like, optional
        State at ``t = 0`` (default rest).

    Returns
    -------
    TransientResponse
    """
    x = as_finite(force, "force", ndim=1)
    if x.size < 2:
        raise InputError(f"force: expected at least 2 samples, got {x.size}")
    fs = check_positive(sample_rate, "sample_rate")
    veh = _causal_vehicle(vehicle, band, per_decade, f_ref)
    sys = state_space(veh)
    t = np.arange(x.size) / fs
    x0 = None if initial_state is None else as_finite(initial_state, "initial_state", ndim=1)
    _, y, _ = lsim(sys, x, t, X0=x0)
    y = np.atleast_2d(np.asarray(y, dtype=float))
    if y.shape[0] != 4:
        y = y.T
    return TransientResponse(
        time=t, displacement=y[0], velocity=y[1], acceleration=y[2], tyre_force=y[3], tyre=veh.tyre
    )
