"""Virtual rolling-tyre rig: a lateral vibrator on a rolling agricultural tyre.

Mirrors the paper's validation experiment (spec "Validation experiment"): a
tyre rolling at 5 and 10 km/h and inflated to 1.28, 1.7 and 2.4 bar is
shaken laterally; the rig measures the lateral acceleration of the wheel and
the lateral force at the axle; the ground force is
``Fy_ground = Fy_axle - M_w y''``. The FRFs cover about 0.25-9 Hz.

Truth model (richer than any of the four candidates, and not one of them):

* :class:`ViscoelasticStringTyre`: Pacejka's stretched string with contact
  half-length ``a`` (transport delay ``e^{-2 s a/V}``, paper eq. 10) whose
  foundation stiffness is viscoelastic, ``c_c(omega) = c_c0 G(omega)`` with a
  fractional Zener (standard linear solid) modulus
  ``G = (1 + b (i omega tau)^beta) / (1 + (i omega tau)^beta)`` (Bagley &
  Torvik, J. Rheology 30 (1986) 133-155; causal and passive for
  ``0 < beta < 1``, ``b > 1``). The string tension is elastic (inflation
  pressure), so the relaxation length follows ``sigma = sqrt(S/c_c)``, i.e.
  ``sigma(omega) = sigma0 / sqrt(G(omega))``. The modulus is evaluated at the
  excitation frequency (material-history effects of rolling through the
  contact are neglected, as in Pacejka's linear string analysis).
* The wheel mass ``M_w`` between the force transducer and the tyre.
* Measurement noise on each FRF line: complex Gaussian, relative
  (``relative_noise``) plus a floor proportional to the largest response
  (``noise_floor``); the coherence that such noise implies is attached.

None of the candidate models has a delay, a frequency-dependent stiffness or a
fractional loss, so none is favoured by construction: the classic model lacks
the road damper, Maxwell lacks carcass damping, and the visco-plastic and
hysteretic carcasses have loss rising with frequency and constant loss,
where the truth has a slowly varying loss factor of about 0.09-0.11 together
with the string's own delay-induced damping.

Tyre parameters (:class:`AgriculturalTyre`), plausible for a mid-size
agricultural tyre (radius 0.6 m, 12 kN load), chosen within the ranges of:

* lateral and radial stiffness of tractor tyres of order 10^5 N/m, rising
  roughly linearly with inflation pressure (Lines & Murphy, "The stiffness of
  agricultural tractor tyres", J. Terramechanics 28 (1991) 49-64);
* cornering stiffness rising weakly with pressure, relaxation length of the
  order of the tyre radius, ``C_alpha = 2 c_c (sigma + a)^2`` and standing
  lateral stiffness ``C_alpha/(sigma + a)`` (Pacejka, *Tire and Vehicle
  Dynamics*, 3rd ed., 2012, ch. 5);
* contact half-length from the geometric chord of the deflected tyre,
  ``a = sqrt(2 R d - d^2)`` with deflection ``d = W / k_radial`` (longer at
  lower pressure);
* loss factor about 0.1 (tread rubber 0.1-0.2, Gehman, paper ref. [26]; the
  whole carcass is somewhat lower);
* wheel mass 100 kg; body mass for the time test such that the body
  resonance is near 3.3 Hz (paper, 2.73 Hz test).

These values are not taken from a table of one tyre; they are order-of-
magnitude choices, documented so that users can change them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import check_positive
from ..exceptions import InputError
from ..frf import FRF, Channel
from ..lateral.fit import LateralData
from ..lateral.models import LateralModel
from ..lateral.response import ForceKind, _check_force, as_freq, string_impedance
from ..lateral.timedomain import harmonic_response
from ..lateral.vehicle import LateralVehicle
from ..timedata import TimeData

__all__ = [
    "KMH",
    "AgriculturalTyre",
    "VirtualLateralRig",
    "ViscoelasticStringTyre",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: One km/h in m/s.
KMH = 1.0 / 3.6


@dataclass(frozen=True)
class ViscoelasticStringTyre(LateralModel):
    """Stretched string with contact length on a fractional-Zener foundation (rig truth).

    Mobility ``1 / string_impedance(omega, c_c0 G, sigma0/sqrt(G), a, V)``
    (:func:`tyredamp.lateral.models.string_impedance`) with
    ``G(omega) = (1 + b (i omega tau)^beta) / (1 + (i omega tau)^beta)``,
    ``G(0) = 1``, ``G(inf) = b``.

    Parameters
    ----------
    C_alpha : float
        Static cornering stiffness ``2 c_c0 (sigma0 + a)^2``, N/rad (> 0).
    sigma : float
        Static relaxation length ``sigma0``, m (> 0).
    a : float
        Contact half-length, m (>= 0).
    speed : float
        Travel speed, m/s (> 0).
    beta : float
        Fractional order, 0 < beta < 1.
    ratio : float
        High- to low-frequency modulus ratio ``b`` (> 1).
    tau : float
        Relaxation time, s (> 0).
    """

    C_alpha: float
    sigma: float
    a: float
    speed: float
    beta: float
    ratio: float
    tau: float

    name: ClassVar[str] = "viscoelastic_string"
    label: ClassVar[str] = "viscoelastic stretched string (rig truth)"
    param_names: ClassVar[tuple[str, ...]] = ("C_alpha", "sigma", "a", "beta", "ratio", "tau")
    param_units: ClassVar[tuple[str, ...]] = ("N/rad", "m", "m", "-", "-", "s")
    condition_names: ClassVar[tuple[str, ...]] = ("speed",)

    def __post_init__(self) -> None:
        for n in ("C_alpha", "sigma", "speed", "tau"):
            object.__setattr__(self, n, check_positive(getattr(self, n), n))
        object.__setattr__(self, "a", check_positive(self.a, "a", allow_zero=True))
        b = float(self.beta)
        if not 0 < b < 1:
            raise InputError(f"beta: expected 0 < beta < 1, got {b:g}")
        object.__setattr__(self, "beta", b)
        r = float(self.ratio)
        if not (math.isfinite(r) and r > 1):
            raise InputError(f"ratio: expected a value > 1, got {r:g}")
        object.__setattr__(self, "ratio", r)

    @property
    def c_c0(self) -> float:
        """Static foundation stiffness per unit length, N/m^2."""
        return self.C_alpha / (2.0 * (self.sigma + self.a) ** 2)

    @property
    def static_lateral_stiffness(self) -> float:
        """Standing-tyre static lateral stiffness ``C_alpha/(sigma + a)``, N/m."""
        return self.C_alpha / (self.sigma + self.a)

    def modulus(self, freq_hz: ArrayLike) -> ComplexArray:
        """Normalised complex modulus ``G`` at ``freq_hz`` (Hz, >= 0)."""
        return self._g(2.0 * np.pi * as_freq(freq_hz))

    def _g(self, omega: FloatArray) -> ComplexArray:
        z = (np.asarray(omega, dtype=float) * self.tau) ** self.beta * np.exp(
            1j * self.beta * np.pi / 2.0
        )
        return np.asarray((1.0 + self.ratio * z) / (1.0 + z), dtype=complex)

    def _mobility(self, omega: FloatArray) -> ComplexArray:
        w = np.asarray(omega, dtype=float)
        g = self._g(w)
        return 1.0 / string_impedance(w, self.c_c0 * g, self.sigma / np.sqrt(g), self.a, self.speed)


@dataclass(frozen=True)
class AgriculturalTyre:
    """Pressure-dependent parameters of the virtual agricultural tyre (module docstring).

    Parameters
    ----------
    radius : float
        Unloaded radius ``R``, m.
    load : float
        Vertical load ``W``, N.
    radial_stiffness_0, radial_stiffness_per_bar : float
        Radial stiffness ``k_r = k_r0 + k_rp p`` (p in bar), N/m and N/m per bar.
    lateral_stiffness_0, lateral_stiffness_per_bar : float
        Static standing lateral stiffness ``k_y = k_y0 + k_yp p``, N/m and N/m per bar.
    cornering_stiffness_ref : float
        ``C_alpha`` at ``pressure_ref``, N/rad.
    cornering_exponent : float
        ``C_alpha = C_ref (p / p_ref)^n``.
    pressure_ref : float
        Reference pressure, bar.
    beta, ratio, tau : float
        Fractional Zener foundation (:class:`ViscoelasticStringTyre`).
    """

    radius: float = 0.6
    load: float = 12e3
    radial_stiffness_0: float = 150e3
    radial_stiffness_per_bar: float = 120e3
    lateral_stiffness_0: float = 50e3
    lateral_stiffness_per_bar: float = 30e3
    cornering_stiffness_ref: float = 80e3
    cornering_exponent: float = 0.3
    pressure_ref: float = 1.7
    beta: float = 0.35
    ratio: float = 2.2
    tau: float = 0.02

    def __post_init__(self) -> None:
        for n in (
            "radius",
            "load",
            "radial_stiffness_0",
            "lateral_stiffness_0",
            "cornering_stiffness_ref",
            "pressure_ref",
            "tau",
        ):
            object.__setattr__(self, n, check_positive(getattr(self, n), n))
        for n in ("radial_stiffness_per_bar", "lateral_stiffness_per_bar", "cornering_exponent"):
            object.__setattr__(self, n, check_positive(getattr(self, n), n, allow_zero=True))

    def _p(self, pressure_bar: float) -> float:
        return check_positive(pressure_bar, "pressure_bar")

    def radial_stiffness(self, pressure_bar: float) -> float:
        """``k_r0 + k_rp p`` in N/m."""
        return self.radial_stiffness_0 + self.radial_stiffness_per_bar * self._p(pressure_bar)

    def lateral_stiffness(self, pressure_bar: float) -> float:
        """Static standing lateral stiffness ``k_y0 + k_yp p`` in N/m."""
        return self.lateral_stiffness_0 + self.lateral_stiffness_per_bar * self._p(pressure_bar)

    def cornering_stiffness(self, pressure_bar: float) -> float:
        """``C_ref (p/p_ref)^n`` in N/rad."""
        p = self._p(pressure_bar)
        return self.cornering_stiffness_ref * (p / self.pressure_ref) ** self.cornering_exponent

    def contact_half_length(self, pressure_bar: float) -> float:
        """Geometric chord ``sqrt(2 R d - d^2)``, ``d = W / k_r``, in m."""
        d = self.load / self.radial_stiffness(pressure_bar)
        if d >= self.radius:
            raise InputError(f"pressure_bar: deflection {d:.3g} m exceeds the radius")
        return math.sqrt(2.0 * self.radius * d - d * d)

    def relaxation_length(self, pressure_bar: float) -> float:
        """``sigma = C_alpha / k_y - a`` in m (Pacejka's string relations)."""
        s = self.cornering_stiffness(pressure_bar) / self.lateral_stiffness(
            pressure_bar
        ) - self.contact_half_length(pressure_bar)
        if s <= 0:
            raise InputError(f"pressure_bar: relaxation length {s:.3g} m is not positive")
        return s

    def model(self, speed: float, pressure_bar: float) -> ViscoelasticStringTyre:
        """Truth model at ``speed`` (m/s) and ``pressure_bar`` (bar)."""
        return ViscoelasticStringTyre(
            C_alpha=self.cornering_stiffness(pressure_bar),
            sigma=self.relaxation_length(pressure_bar),
            a=self.contact_half_length(pressure_bar),
            speed=speed,
            beta=self.beta,
            ratio=self.ratio,
            tau=self.tau,
        )


@dataclass(frozen=True)
class VirtualLateralRig:
    """Lateral vibrator on a rolling tyre, measuring FRFs and time data.

    Parameters
    ----------
    tyre : AgriculturalTyre
        Tyre parameters.
    wheel_mass : float
        Wheel mass between the axle force transducer and the tyre, kg.
    body_mass : float
        Body mass of the single-degree-of-freedom vehicle for the time test
        (spec eq. 41), kg; 280 kg puts the body resonance near 3.3 Hz at
        1.7 bar.
    relative_noise : float
        Standard deviation of the relative complex noise per FRF line.
    noise_floor : float
        Standard deviation of the absolute complex noise per line, as a
        fraction of the largest ``|A|`` of the FRF.
    f_min, f_max, df : float
        Frequency lines ``f_min, f_min + df, ... <= f_max`` in Hz.
    """

    tyre: AgriculturalTyre = field(default_factory=AgriculturalTyre)
    wheel_mass: float = 100.0
    body_mass: float = 280.0
    relative_noise: float = 0.03
    noise_floor: float = 0.002
    f_min: float = 0.25
    f_max: float = 9.0
    df: float = 0.05

    #: Conditions of the paper's experiment.
    SPEEDS_KMH: ClassVar[tuple[float, ...]] = (5.0, 10.0)
    PRESSURES_BAR: ClassVar[tuple[float, ...]] = (1.28, 1.7, 2.4)
    #: Highest speed the rig accepts, km/h (above any road tyre's speed rating).
    MAX_SPEED_KMH: ClassVar[float] = 400.0
    #: Highest relative noise accepted (1000 % of the response).
    MAX_RELATIVE_NOISE: ClassVar[float] = 10.0

    def __post_init__(self) -> None:
        for n in ("wheel_mass", "body_mass", "f_min", "f_max", "df"):
            object.__setattr__(self, n, check_positive(getattr(self, n), n))
        for n in ("relative_noise", "noise_floor"):
            object.__setattr__(self, n, check_positive(getattr(self, n), n, allow_zero=True))
        if self.relative_noise > self.MAX_RELATIVE_NOISE:
            raise InputError(
                f"relative_noise: expected a value <= {self.MAX_RELATIVE_NOISE:g}, "
                f"got {self.relative_noise:g}"
            )
        if self.f_max <= self.f_min + self.df:
            raise InputError(f"f_max: expected > f_min + df, got {self.f_max:g}")

    @property
    def frequency(self) -> FloatArray:
        """Measured lines in Hz."""
        n = math.floor((self.f_max - self.f_min) / self.df + 1e-9) + 1
        return np.asarray(self.f_min + self.df * np.arange(n), dtype=float)

    def truth(self, speed_kmh: float, pressure_bar: float) -> ViscoelasticStringTyre:
        """The truth tyre model at a speed (km/h) and pressure (bar)."""
        v = check_positive(speed_kmh, "speed_kmh")
        if v > self.MAX_SPEED_KMH:
            raise InputError(
                f"speed_kmh: expected a speed <= {self.MAX_SPEED_KMH:g} km/h, got {v:g}"
            )
        return self.tyre.model(v * KMH, pressure_bar)

    def measure(
        self,
        speed_kmh: float,
        pressure_bar: float,
        force: ForceKind = "ground",
        seed: int | None = 0,
    ) -> LateralData:
        """A noisy accelerance FRF at one condition.

        Parameters
        ----------
        speed_kmh : float
            Travel speed, km/h.
        pressure_bar : float
            Inflation pressure, bar.
        force : {"ground", "axle"}
            Force the FRF refers to.
        seed : int or None
            Random seed (the noise also depends on the condition, so
            conditions measured with one seed are independent).

        Returns
        -------
        LateralData
            ``frf`` (kind ``"accelerance"``, with coherence and meta keys
            ``speed_m_s``, ``speed_kmh``, ``pressure_bar``, ``force``,
            ``wheel_mass_kg``, ``label``, ``truth``), speed in m/s, force and
            wheel mass.
        """
        _check_force(force)
        truth = self.truth(speed_kmh, pressure_bar)
        f = self.frequency
        a = truth.response(f, "accelerance", force, self.wheel_mass)
        entropy = [
            0 if seed is None else int(seed),
            round(speed_kmh * 1000),
            round(pressure_bar * 1000),
            0 if force == "ground" else 1,
        ]
        rng = np.random.default_rng(None if seed is None else np.random.SeedSequence(entropy))
        floor = self.noise_floor * float(np.max(np.abs(a)))
        sd = np.sqrt((self.relative_noise * np.abs(a)) ** 2 + floor**2)
        noise = sd * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / math.sqrt(2)
        meas = a + noise
        coh = np.abs(a) ** 2 / (np.abs(a) ** 2 + sd**2)
        label = f"{pressure_bar:g} bar, {speed_kmh:g} km/h"
        frf = FRF(
            f,
            meas,
            kind="accelerance",
            outputs=[Channel(node=1, direction=2, name="lateral acceleration")],
            inputs=[Channel(node=1, direction=2, name=f"{force} force")],
            coherence=coh,
            meta={
                "source": "tyredamp.virtual.lateral_rig.VirtualLateralRig",
                "speed_m_s": truth.speed,
                "speed_kmh": float(speed_kmh),
                "pressure_bar": float(pressure_bar),
                "force": force,
                "wheel_mass_kg": self.wheel_mass,
                "label": label,
                "seed": seed,
                "truth": truth.to_dict(),
            },
        )
        return LateralData(
            frf=frf, speed=truth.speed, force=force, wheel_mass=self.wheel_mass, label=label
        )

    def measure_all(
        self,
        force: ForceKind = "ground",
        seed: int | None = 0,
        speeds_kmh: Sequence[float] | None = None,
        pressures_bar: Sequence[float] | None = None,
    ) -> list[LateralData]:
        """All conditions (default the paper's 2 speeds x 3 pressures), pressure-major order."""
        sp = self.SPEEDS_KMH if speeds_kmh is None else tuple(speeds_kmh)
        pr = self.PRESSURES_BAR if pressures_bar is None else tuple(pressures_bar)
        return [self.measure(v, p, force, seed) for p in pr for v in sp]

    def vehicle(self, speed_kmh: float, pressure_bar: float) -> LateralVehicle:
        """Body of :attr:`body_mass` on the truth tyre (spec eq. 41-42)."""
        return LateralVehicle(self.truth(speed_kmh, pressure_bar), self.body_mass)

    def time_test(
        self,
        speed_kmh: float = 5.0,
        pressure_bar: float = 1.7,
        frequency: float = 2.73,
        force_amplitude: float = 500.0,
        duration: float = 6.0,
        sample_rate: float = 200.0,
        seed: int | None = 0,
    ) -> TimeData:
        """Sinusoidal lateral excitation of the vehicle body (the paper's 2.73 Hz test).

        The steady state is exact (frequency domain, :func:`harmonic_response`
        on the causal truth). Noise: ``relative_noise`` times each channel's
        amplitude, white.

        Returns
        -------
        TimeData
            Channels: force on the body (N), body lateral acceleration
            (m/s^2), tyre ground force (N). ``meta`` holds the conditions and
            the body mass.
        """
        fs = check_positive(sample_rate, "sample_rate")
        t = np.arange(round(check_positive(duration, "duration") * fs)) / fs
        veh = self.vehicle(speed_kmh, pressure_bar)
        f0 = check_positive(frequency, "frequency")
        amp = check_positive(force_amplitude, "force_amplitude")
        force = amp * np.cos(2.0 * np.pi * f0 * t)
        acc = harmonic_response(veh, f0, amp, t, "acceleration")
        ground = force - self.body_mass * acc
        rng = np.random.default_rng(seed)
        data = np.vstack([force, acc, ground])
        scale = np.max(np.abs(data), axis=1, keepdims=True)
        data = data + self.relative_noise * scale * rng.standard_normal(data.shape)
        return TimeData(
            data,
            fs,
            channels=[
                Channel(node=1, direction=2, name="body force"),
                Channel(node=1, direction=2, name="body acceleration"),
                Channel(node=2, direction=2, name="ground force"),
            ],
            quantities=["force", "acceleration", "force"],
            meta={
                "speed_kmh": float(speed_kmh),
                "pressure_bar": float(pressure_bar),
                "frequency_hz": f0,
                "body_mass_kg": self.body_mass,
                "truth": veh.tyre.to_dict(),
            },
        )
