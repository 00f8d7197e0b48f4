"""How far the causal approximation of a hysteretic vehicle is from the ideal model.

:func:`causal_error` compares a body on the generalised Maxwell tyre
(:mod:`tyredamp.lateral.prony`) with the body on the ideal hysteretic tyre:
carcass stiffness and receptance over the band, the impulse response (ideal
by FFT, causal by the state-space model) and a switched-on sine against its
exact steady state (:mod:`tyredamp.lateral.timedomain`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import lsim

from .._validate import check_positive
from ..exceptions import InputError, PhysicsError
from .models import HystereticModel
from .prony import GeneralizedMaxwellTyre
from .timedomain import (
    _causal_vehicle,
    harmonic_response,
    precursor,
    state_space,
    transient_response,
)
from .vehicle import LateralVehicle

__all__ = ["CausalError", "causal_error"]


@dataclass(frozen=True, eq=False)
class CausalError:
    """Error of a causal approximation of a hysteretic vehicle against the ideal model.

    Attributes
    ----------
    band : (float, float)
        Approximation band, Hz.
    n_arms : int
        Maxwell arms used.
    stiffness_error : float
        ``max |Z_c - (K + i h)| / |K + i h|`` over the band.
    frf_error : float
        ``max |Y_causal - Y_ideal| / |Y_ideal|`` of the body receptance over the band.
    impulse_error : float
        ``max_{t >= 0} |x_causal - x_ideal| / max |x_ideal|`` of the displacement
        impulse responses (ideal by FFT, causal by the state-space model).
    precursor_ratio : float
        Precursor of the ideal model (:func:`precursor`).
    sine_error : float
        After ``settle`` s of a sine switched on at ``t = 0``: max error of the
        causal transient against the exact steady state, relative to the
        steady-state amplitude (acceleration).
    sine_frequency : float
        Hz.
    tyre : GeneralizedMaxwellTyre
        The approximation.
    """

    band: tuple[float, float]
    n_arms: int
    stiffness_error: float
    frf_error: float
    impulse_error: float
    precursor_ratio: float
    sine_error: float
    sine_frequency: float
    tyre: GeneralizedMaxwellTyre


def causal_error(
    vehicle: LateralVehicle,
    band: tuple[float, float],
    *,
    per_decade: int = 3,
    f_ref: float | None = None,
    sine_frequency: float = 2.73,
    sample_rate: float = 500.0,
    duration: float = 64.0,
    settle: float = 30.0,
) -> CausalError:
    """Compare the causal approximation of a hysteretic body-on-tyre model with the ideal one.

    Parameters
    ----------
    vehicle : LateralVehicle
        Body on a :class:`~tyredamp.lateral.models.HystereticModel` tyre.
    band : (float, float)
        Approximation band, Hz.
    per_decade : int
        Maxwell arms per decade.
    f_ref : float, optional
        Frequency where the storage stiffness is matched, Hz (default the
        body resonance, or the band centre if there is none).
    sine_frequency : float
        Frequency of the switched-on sine test, Hz (default 2.73, the paper's).
    sample_rate : float
        Hz, for the impulse and sine simulations.
    duration : float
        Impulse-response window, s.
    settle : float
        Time after which the sine transient is compared, s (the sine lasts
        ``settle + 5`` s).

    Returns
    -------
    CausalError
    """
    if not isinstance(vehicle.tyre, HystereticModel):
        raise InputError("vehicle: expected a body on a HystereticModel tyre")
    if f_ref is None:
        try:
            f_ref = vehicle.resonance(band).frequency
        except PhysicsError:
            f_ref = None
    causal = _causal_vehicle(vehicle, band, per_decade, f_ref)
    gm = causal.tyre
    assert isinstance(gm, GeneralizedMaxwellTyre)
    f = np.logspace(math.log10(band[0]), math.log10(band[1]), 400)
    target = vehicle.tyre.K + 1j * vehicle.tyre.h
    st_err = float(np.max(np.abs(gm.carcass_stiffness(f) - target)) / abs(target))
    yi, yc = vehicle.receptance(f), causal.receptance(f)
    frf_err = float(np.max(np.abs(yc - yi) / np.abs(yi)))
    pre = precursor(vehicle, sample_rate, duration, "displacement")
    ir = pre.impulse
    pos = ir.time >= 0
    tpos = ir.time[pos]
    sys = state_space(causal)
    x0 = np.asarray(sys.B[:, 0], dtype=float)  # a unit impulse sets the state to B
    _, yimp, _ = lsim(sys, np.zeros(tpos.size), tpos, X0=x0)
    yimp = np.atleast_2d(np.asarray(yimp, dtype=float))
    if yimp.shape[0] != 4:
        yimp = yimp.T
    imp_err = float(np.max(np.abs(yimp[0] - ir.response[pos])) / pre.peak)
    fs = check_positive(sample_rate, "sample_rate")
    fsin = check_positive(sine_frequency, "sine_frequency")
    t = np.arange(round((settle + 5.0) * fs)) / fs
    force = np.sin(2.0 * np.pi * fsin * t)
    tr = transient_response(causal, force, fs)
    exact = harmonic_response(vehicle, fsin, 1.0, t, "acceleration", phase=-np.pi / 2)
    late = t >= settle
    amp = float(np.max(np.abs(exact[late])))
    sine_err = float(np.max(np.abs(tr.acceleration[late] - exact[late])) / amp)
    return CausalError(
        band=(float(band[0]), float(band[1])),
        n_arms=len(gm.stiffness),
        stiffness_error=st_err,
        frf_error=frf_err,
        impulse_error=imp_err,
        precursor_ratio=pre.ratio,
        sine_error=sine_err,
        sine_frequency=fsin,
        tyre=gm,
    )
