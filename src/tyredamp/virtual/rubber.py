"""Rubber for the virtual tyre: frequency-dependent viscoelastic laws and their exact truth.

A rubber law gives the complex modulus ``E*(s)`` (Pa, Laplace variable ``s``
in rad/s, ``s = i omega`` on the frequency axis):

``PronySeries``
    generalised Maxwell model ``E*(s) = E_inf + sum_k E_k s tau_k/(1 + s tau_k)``
    (Tschoegl, *The Phenomenological Theory of Linear Viscoelastic Behavior*,
    Springer 1989, eq. (3.4-19) with ``s = i omega``): exponential relaxation,
    hence an exact finite state space and time simulation;
``FractionalZener``
    ``E*(s) = (E_0 + E_inf (s tau)^alpha)/(1 + (s tau)^alpha)`` (Pritz, J. Sound
    Vib. 195(1) (1996) 103-115, eq. (1); Bagley & Torvik, J. Rheol. 30 (1986)
    133-155): four parameters for a broad loss peak;
``ConstantLoss``
    ``E*(i omega) = E (1 + i eta)`` for ``omega > 0``: the hysteretic law, not
    causal, frequency-domain data only.

Temperature: the time-temperature superposition ``E*(omega, T) = E*(omega a_T, T_0)``
with the WLF shift ``log10 a_T = -C1 (T - T_r)/(C2 + T - T_r)`` (Williams,
Landel & Ferry, J. Am. Chem. Soc. 77 (1955) 3701-3707, eq. (1); universal
constants ``C1 = 17.44``, ``C2 = 51.6 K`` with ``T_r = T_g``), relative to the
temperature at which the law is given.

Applied to the ring tyre (:class:`~tyredamp.virtual.ring.RingTyre`) the rubber
scales the stiffness of the chosen parts (sidewall foundation ``k_r, k_t``
and the band's membrane and bending stiffness) by ``E*(s)/E'(omega_ref)``, so
that at the reference frequency the storage stiffness is the ring's own.
The ring's viscous dashpots are replaced by the rubber. The result is a
:class:`~tyredamp.dampmodels.DampedSystem`: exact FRFs and exact modes (the
augmented state space for a Prony series, Newton's method otherwise), the
truth against which viscous estimates are compared.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import nnls

from ..dampmodels import DampedSystem, DampingLaw, Exponential, Hysteretic
from ..exceptions import InputError, PhysicsError
from .ring import RingTyre

__all__ = [
    "DEFAULT_TREAD",
    "WLF",
    "ConstantLoss",
    "FractionalZener",
    "ModalBand",
    "ModulusLaw",
    "PronySeries",
    "RubberLaw",
    "fit_prony",
    "fit_zener",
    "modal_band_system",
    "rubber_system",
]


@dataclass(frozen=True)
class WLF:
    """WLF shift ``log10 a_T = -C1 (T - T_r)/(C2 + T - T_r)`` (WLF 1955, eq. (1)).

    Parameters
    ----------
    c1 : float
        Dimensionless, default 17.44 (universal, with ``T_r = T_g``).
    c2 : float
        K, default 51.6 (universal).
    t_ref : float
        ``T_r`` in deg C; default -45, a glass temperature typical of an SBR
        tread compound (an assumption, not a measured value).
    """

    c1: float = 17.44
    c2: float = 51.6
    t_ref: float = -45.0

    def log_shift(self, temperature: float) -> float:
        """``log10 a_T`` at ``temperature`` (deg C), > ``t_ref - c2``."""
        dt = temperature - self.t_ref
        if self.c2 + dt <= 0:
            raise PhysicsError(
                f"temperature: {temperature} deg C is below the WLF law's range "
                f"(above {self.t_ref - self.c2:g} deg C)"
            )
        return -self.c1 * dt / (self.c2 + dt)


class RubberLaw(ABC):
    """A complex modulus ``E*(s)`` (module docstring)."""

    name: ClassVar[str]

    @abstractmethod
    def modulus(self, s: complex) -> complex:
        """``E*(s)`` in Pa."""

    @abstractmethod
    def dmodulus(self, s: complex) -> complex:
        """``dE*/ds`` in Pa s."""

    @abstractmethod
    def shifted(self, factor: float) -> RubberLaw:
        """The law with its times multiplied by ``factor`` (``a_T``)."""

    def at_temperature(
        self, temperature: float, given_at: float = 20.0, wlf: WLF | None = None
    ) -> RubberLaw:
        """The law at ``temperature`` (deg C) from the law given at ``given_at`` (WLF shift)."""
        w = wlf or WLF()
        return self.shifted(10 ** (w.log_shift(temperature) - w.log_shift(given_at)))

    def loss_factor(self, frequency: ArrayLike) -> NDArray[np.float64]:
        """``tan delta = E''/E'`` at ``frequency`` (Hz)."""
        e = np.array([self.modulus(2j * np.pi * f) for f in np.atleast_1d(frequency)])
        return np.asarray(e.imag / e.real, dtype=float)


@dataclass(frozen=True)
class PronySeries(RubberLaw):
    """``E*(s) = E_inf + sum_k E_k s tau_k/(1 + s tau_k)`` (Tschoegl 1989, eq. (3.4-19)).

    Parameters
    ----------
    e_inf : float
        Relaxed (long-time) modulus, Pa.
    e_k : array_like, shape (n_k,)
        Spring moduli of the Maxwell arms, Pa (>= 0).
    tau_k : array_like, shape (n_k,)
        Their relaxation times, s (> 0).
    """

    e_inf: float
    e_k: NDArray[np.float64]
    tau_k: NDArray[np.float64]
    name: ClassVar[str] = "prony"

    def __post_init__(self) -> None:
        e = np.atleast_1d(np.asarray(self.e_k, dtype=float))
        t = np.atleast_1d(np.asarray(self.tau_k, dtype=float))
        if e.shape != t.shape or np.any(e < 0) or np.any(t <= 0) or not self.e_inf > 0:
            raise InputError(
                "PronySeries: expected e_inf > 0, e_k >= 0 and tau_k > 0 of one length"
            )
        object.__setattr__(self, "e_k", e)
        object.__setattr__(self, "tau_k", t)

    def modulus(self, s: complex) -> complex:
        return complex(self.e_inf + np.sum(self.e_k * s * self.tau_k / (1 + s * self.tau_k)))

    def dmodulus(self, s: complex) -> complex:
        return complex(np.sum(self.e_k * self.tau_k / (1 + s * self.tau_k) ** 2))

    def shifted(self, factor: float) -> PronySeries:
        return replace(self, tau_k=self.tau_k * factor)


@dataclass(frozen=True)
class FractionalZener(RubberLaw):
    """``E*(s) = (E_0 + E_inf (s tau)^alpha)/(1 + (s tau)^alpha)`` (Pritz 1996, eq. (1)).

    Parameters
    ----------
    e0, e_inf : float
        Relaxed and unrelaxed (glassy) moduli, Pa, ``0 < e0 < e_inf``.
    tau : float
        Relaxation time, s.
    alpha : float
        Fractional order, ``0 < alpha <= 1``.
    """

    e0: float
    e_inf: float
    tau: float
    alpha: float
    name: ClassVar[str] = "fractional-zener"

    def __post_init__(self) -> None:
        if not (0 < self.e0 < self.e_inf and self.tau > 0 and 0 < self.alpha <= 1):
            raise InputError(
                "FractionalZener: expected 0 < e0 < e_inf, tau > 0 and 0 < alpha <= 1, got "
                f"{self.e0}, {self.e_inf}, {self.tau}, {self.alpha}"
            )

    def modulus(self, s: complex) -> complex:
        x = complex(s * self.tau) ** self.alpha
        return (self.e0 + self.e_inf * x) / (1 + x)

    def dmodulus(self, s: complex) -> complex:
        x = complex(s * self.tau) ** self.alpha
        dx = self.alpha * x / complex(s)
        return (self.e_inf - self.e0) * dx / (1 + x) ** 2

    def shifted(self, factor: float) -> FractionalZener:
        return replace(self, tau=self.tau * factor)


@dataclass(frozen=True)
class ConstantLoss(RubberLaw):
    """``E*(i omega) = E (1 + i eta sign omega)``: constant loss factor (not causal).

    Parameters
    ----------
    e : float
        Storage modulus, Pa.
    eta : float
        Loss factor.
    """

    e: float
    eta: float
    name: ClassVar[str] = "constant-loss"

    def modulus(self, s: complex) -> complex:
        return self.e * (1 + 1j * self.eta * (1.0 if complex(s).imag >= 0 else -1.0))

    def dmodulus(self, s: complex) -> complex:
        return 0j

    def shifted(self, factor: float) -> ConstantLoss:
        return self


#: A representative carbon-black-filled tread compound at 20 deg C: rubbery
#: modulus 7 MPa, glassy 0.7 GPa, storage modulus 9 MPa and loss factor 0.07,
#: 0.12 and 0.15 at 10, 100 and 300 Hz (the rubbery side of the glass
#: transition). Chosen values in the range of tread compounds, not a fit to
#: one published master curve.
DEFAULT_TREAD = FractionalZener(e0=7e6, e_inf=7e8, tau=1e-11, alpha=0.3)


def fit_zener(frequency: ArrayLike, storage: ArrayLike, loss_factor: ArrayLike) -> FractionalZener:
    """The fractional Zener law closest to a measured master curve (least squares).

    Fits ``E*(i omega) = (E_0 + E_inf x)/(1 + x)``, ``x = (i omega tau)^alpha``
    (Pritz 1996, eq. (1)) to storage moduli ``E'`` and loss factors
    ``tan delta = E''/E'`` at one reference temperature, minimising the
    squared differences of ``ln E'`` and of ``ln E''`` (both moduli matter over
    decades; Pritz 1996, sec. 3, fits the same four parameters to measured
    master curves). The curve must reach over the loss peak, or ``E_inf`` and
    ``tau`` are not determined separately.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Reduced frequencies of the master curve, Hz (> 0), ``n >= 4``.
    storage : array_like, shape (n,)
        ``E'``, Pa (> 0).
    loss_factor : array_like, shape (n,)
        ``tan delta`` (> 0).

    Returns
    -------
    FractionalZener

    Raises
    ------
    InputError
        Fewer than four points, or values that are not positive.
    """
    from scipy.optimize import least_squares
    from scipy.special import expit

    f = np.asarray(frequency, dtype=float).ravel()
    e1 = np.asarray(storage, dtype=float).ravel()
    eta = np.asarray(loss_factor, dtype=float).ravel()
    if not f.size == e1.size == eta.size or f.size < 4:
        raise InputError(
            "frequency, storage, loss_factor: expected at least 4 points of each, one per "
            f"frequency, got {f.size}, {e1.size}, {eta.size}"
        )
    if not (np.all(f > 0) and np.all(e1 > 0) and np.all(eta > 0) and np.all(np.isfinite(f))):
        raise InputError("frequency, storage, loss_factor: expected finite values > 0")
    target = np.concatenate([np.log(e1), np.log(e1 * eta)])
    w = 2 * np.pi * f

    def unpack(p: NDArray[np.float64]) -> tuple[float, float, float, float]:
        e0 = float(np.exp(p[0]))
        return e0, e0 * (1 + float(np.exp(p[1]))), float(np.exp(p[2])), float(expit(p[3]))

    def resid(p: NDArray[np.float64]) -> NDArray[np.float64]:
        e0, e_inf, tau, alpha = unpack(p)
        x = (1j * w * tau) ** alpha
        e = (e0 + e_inf * x) / (1 + x)
        return np.concatenate([np.log(e.real), np.log(np.abs(e.imag))]) - target

    peak = float(w[np.argmax(eta)])
    ratio = max(float(e1.max() / e1.min()), 1.0 + 1e-6)
    best = None
    for a in (0.2, 0.4, 0.6):
        # loss peak of the law near omega tau = (E_0/E_inf)^(1/(2 alpha))
        tau0 = ratio ** (-1 / (2 * a)) / peak
        p0 = np.array([np.log(e1.min()), np.log(ratio - 1), np.log(tau0), np.log(a / (1 - a))])
        sol = least_squares(resid, p0, method="trf", x_scale="jac", max_nfev=2000)
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None
    e0, e_inf, tau, alpha = unpack(best.x)
    return FractionalZener(e0, e_inf, tau, min(alpha, 1.0))


def fit_prony(
    law: RubberLaw, f_lo: float, f_hi: float, per_decade: int = 2, n_lines: int = 200
) -> PronySeries:
    """A Prony series fitted to ``law`` on ``[f_lo, f_hi]`` Hz (time-simulatable).

    Relaxation times log-spaced ``per_decade`` per decade one decade beyond the
    band at each end, moduli by non-negative least squares on the relative
    complex error (Park & Schapery, Int. J. Solids Struct. 36 (1999)
    1653-1675, sec. 3; NNLS: Lawson & Hanson, *Solving Least Squares
    Problems*, 1974, ch. 23).
    """
    if not 0 < f_lo < f_hi:
        raise InputError(f"f_lo, f_hi: expected 0 < f_lo < f_hi Hz, got {f_lo}, {f_hi}")
    f = np.geomspace(f_lo, f_hi, n_lines)
    s = 2j * np.pi * f
    e = np.array([law.modulus(si) for si in s])
    lo, hi = np.log10(1 / (2 * np.pi * f_hi)) - 1, np.log10(1 / (2 * np.pi * f_lo)) + 1
    tau = np.logspace(lo, hi, int(np.ceil((hi - lo) * per_decade)) + 1)
    cols = (
        np.column_stack([np.ones_like(s), *(s * t / (1 + s * t) for t in tau)]) / np.abs(e)[:, None]
    )
    A = np.vstack([cols.real, cols.imag])
    b = np.concatenate([(e / np.abs(e)).real, (e / np.abs(e)).imag])
    x, _ = nnls(A, b)
    e_inf = max(float(x[0]), 1e-9 * float(np.abs(e).min()))
    keep = x[1:] > 0
    return PronySeries(e_inf, x[1:][keep], tau[keep])


@dataclass(frozen=True)
class ModulusLaw(DampingLaw):
    """``Z(s) = K_r (E*(s)/E_ref - 1)``: a rubber law on the stiffness ``K_r``.

    Parameters
    ----------
    K_r : ndarray, shape (n, n)
        Stiffness carried by the rubber at the reference (N/m).
    rubber : RubberLaw
    e_ref : float
        ``E'`` at the reference frequency, Pa.
    """

    K_r: NDArray[np.float64]
    rubber: RubberLaw
    e_ref: float
    name: ClassVar[str] = "rubber"

    @property
    def n_dof(self) -> int:
        return int(self.K_r.shape[0])

    def term(self, s: complex) -> NDArray[np.complex128]:
        return np.asarray(self.K_r * (self.rubber.modulus(s) / self.e_ref - 1), dtype=complex)

    def dterm(self, s: complex) -> NDArray[np.complex128]:
        return np.asarray(self.K_r * (self.rubber.dmodulus(s) / self.e_ref), dtype=complex)

    def parameters(self) -> dict[str, object]:
        return {"rubber": self.rubber.name, "e_ref": self.e_ref}


def rubber_system(
    ring: RingTyre,
    rubber: RubberLaw = DEFAULT_TREAD,
    parts: Sequence[str] = ("sidewall", "band"),
    reference_hz: float = 100.0,
) -> DampedSystem:
    """The ring tyre with ``rubber`` in ``parts``: the exact damped system (module docstring).

    Parameters
    ----------
    ring : RingTyre
        Provides ``M``, ``K``, ``K_sidewall`` and ``K_band`` (N/m).
    rubber : RubberLaw
    parts : sequence of {"sidewall", "band"}
    reference_hz : float
        Frequency at which the storage stiffness equals the ring's, Hz.

    Returns
    -------
    DampedSystem
        With an :class:`~tyredamp.dampmodels.Exponential` law for a Prony
        series (exact state space), :class:`~tyredamp.dampmodels.Hysteretic`
        for a constant loss, :class:`ModulusLaw` otherwise.
    """
    M = np.array(ring.M, dtype=np.float64)
    K = np.array(ring.K, dtype=np.float64)
    K_r = _rubber_stiffness(ring, parts)
    e_ref = rubber.modulus(2j * np.pi * reference_hz).real
    if isinstance(rubber, PronySeries):
        C = np.stack(
            [K_r * (ek * tk / e_ref) for ek, tk in zip(rubber.e_k, rubber.tau_k, strict=True)]
        )
        K0 = K + K_r * (rubber.e_inf / e_ref - 1)
        return DampedSystem(M, K0, Exponential(C, 1 / rubber.tau_k))
    if isinstance(rubber, ConstantLoss):
        return DampedSystem(M, K, Hysteretic(rubber.eta * K_r))
    return DampedSystem(M, K, ModulusLaw(K_r, rubber, e_ref))


@dataclass(frozen=True, eq=False)
class ModalBand:
    """The ring tyre with a fractional Zener rubber, reduced to the modes of one band.

    Attributes
    ----------
    system : DampedSystem
        Mass ``I``, stiffness and damping in the relaxed modal coordinates.
    shapes : ndarray, shape (16, m)
        Mass-normalised relaxed mode shapes at the measurement points, 1/sqrt(kg).
    drive : int
        Row of ``shapes`` at the drive point.
    omega : ndarray, shape (m,)
        Relaxed natural frequencies ``omega_0``, rad/s.
    c_fractional : ndarray, shape (m, m)
        ``C'`` of the fractional law ``C' s^alpha`` that the rubber is in the band
        (to first order in ``(s tau)^alpha``), 1/s^(2 - alpha).
    alpha : float
        The rubber's fractional order.
    """

    system: DampedSystem
    shapes: NDArray[np.float64]
    drive: int
    omega: NDArray[np.float64]
    c_fractional: NDArray[np.float64]
    alpha: float


def modal_band_system(
    ring: RingTyre,
    band_hz: tuple[float, float],
    rubber: FractionalZener = DEFAULT_TREAD,
    parts: Sequence[str] = ("sidewall", "band"),
    reference_hz: float = 100.0,
    drive: int = 0,
) -> ModalBand:
    """The modes of ``band_hz`` of the rubber tyre, one per pair, as a small exact system.

    The rubber on ``K_r`` gives ``D(s) = s^2 M + K + K_r (E*(s)/E_ref - 1)``
    (:func:`rubber_system`). With the relaxed stiffness ``K_0 = K + K_r
    (E_0/E_ref - 1)`` and its mass-normalised modes ``Phi_0`` this is
    ``s^2 I + diag(omega_0^2) + Phi_0^T K_r Phi_0 (E*(s) - E_0)/E_ref``, and
    since ``E* - E_0 = (E_inf - E_0) x/(1 + x)``, ``x = (s tau)^alpha``
    (Pritz 1996, eq. (1)), the damping is the fractional law ``C' s^alpha`` with
    ``C' = Phi_0^T K_r Phi_0 (E_inf - E_0) tau^alpha / E_ref`` to first order in
    ``|x|`` (Bagley & Torvik 1983, eq. (1)). The ring's modes come in pairs
    (``cos`` and ``sin`` of each wave number): of each pair only the
    combination seen from the drive point is kept (the other has no
    amplitude there), and only the modes whose relaxed frequency lies in
    ``band_hz``; the kept vectors ``P`` are rotated to the modes of
    ``(P^T K_0 P, P^T M P)`` (Rayleigh-Ritz), so the reduced system is exactly
    ``P^T D(s) P``.

    Parameters
    ----------
    ring : RingTyre
    band_hz : (float, float)
        Relaxed natural frequencies kept, Hz.
    rubber : FractionalZener
    parts : sequence of {"sidewall", "band"}
    reference_hz : float
        Frequency at which the storage stiffness is the ring's, Hz.
    drive : int
        Measurement point of the drive (index into ``ring.point_dofs``).

    Returns
    -------
    ModalBand
    """
    if not 0 <= band_hz[0] < band_hz[1]:
        raise InputError(f"band_hz: expected 0 <= low < high Hz, got {band_hz}")
    M = np.array(ring.M, dtype=np.float64)
    K_r = _rubber_stiffness(ring, parts)
    e_ref = rubber.modulus(2j * np.pi * reference_hz).real
    K0 = np.array(ring.K, dtype=np.float64) + K_r * (rubber.e0 / e_ref - 1)
    w2, phi = sla.eigh(0.5 * (K0 + K0.T), M)
    w = np.sqrt(np.clip(w2, 0.0, None))
    d = int(np.asarray(ring.point_dofs)[drive])
    cols: list[NDArray[np.float64]] = []
    j = 0
    while j < w.size:
        k = j + 1
        while k < w.size and w[k] - w[j] <= 1e-2 * w[j]:  # a pair (split by rounding)
            k += 1
        if band_hz[0] <= w[j] / (2 * np.pi) <= band_hz[1]:
            a = phi[d, j:k]
            if np.linalg.norm(a) > 1e-9 * np.abs(phi[:, j:k]).max():
                cols.append(phi[:, j:k] @ (a / np.linalg.norm(a)))
        j = k
    if not cols:
        raise InputError(f"band_hz: no mode seen from the drive point in {band_hz} Hz")
    P = np.column_stack(cols)
    # Rayleigh-Ritz on the kept vectors: a pair split by the discretisation is not
    # exactly degenerate, so its combination is rotated to the small problem's modes
    w2r, rot = sla.eigh(0.5 * (P.T @ K0 @ P + (P.T @ K0 @ P).T), P.T @ M @ P)
    P = P @ rot
    om = np.sqrt(np.clip(w2r, 0.0, None))
    kr = P.T @ K_r @ P
    kr = 0.5 * (kr + kr.T)
    law = ModulusLaw(kr, rubber, e_ref)
    # K such that K + kr (E*/E_ref - 1) = diag(omega^2) + kr (E* - E_0)/E_ref
    system = DampedSystem(np.eye(om.size), np.diag(om**2) + kr * (1 - rubber.e0 / e_ref), law)
    c = kr * (rubber.e_inf - rubber.e0) * rubber.tau**rubber.alpha / e_ref
    pts = np.asarray(ring.point_dofs)
    return ModalBand(system, P[pts], drive, om, c, rubber.alpha)


def _rubber_stiffness(ring: RingTyre, parts: Sequence[str]) -> NDArray[np.float64]:
    """``K_r``: the symmetrised stiffness of ``parts`` of the ring, N/m."""
    known = {"sidewall": "K_sidewall", "band": "K_band"}
    bad = [p for p in parts if p not in known]
    if bad or not parts:
        raise InputError(f"parts: expected some of sidewall, band, got {', '.join(bad) or 'none'}")
    K_r = np.zeros_like(np.array(ring.K, dtype=np.float64))
    for part in parts:
        K_r += getattr(ring, known[part])
    return 0.5 * (K_r + K_r.T)
