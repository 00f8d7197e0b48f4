"""Parameters of the virtual truck tyre (in-plane ring on an elastic foundation).

All values are SI. The defaults describe a 295/80R22.5 truck tyre at 7.5 bar
(the tyre of paper 000, Popov & Geng 2005); see spec ``virtual-tyre.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ..exceptions import InputError, PhysicsError

__all__ = ["Imperfection", "MeasurementLayout", "RingTyreParameters"]


def _check_field(obj: object, name: str, *, allow_zero: bool) -> None:
    value = getattr(obj, name)
    cls = type(obj).__name__
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{cls}.{name}: expected a number, got {value!r}") from None
    if not math.isfinite(v):
        raise InputError(f"{cls}.{name}: expected a finite number, got {v}")
    if v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise PhysicsError(f"{cls}.{name}: expected a value {bound}, got {v:g}")


@dataclass(frozen=True)
class RingTyreParameters:
    """Tread band, sidewalls and damping of the in-plane ring tyre model.

    The tread band is a thin ring (radius ``radius``, width ``width``) with
    mass per unit length ``mass_per_length``, in-plane bending stiffness
    ``bending_stiffness`` and membrane stiffness ``membrane_stiffness``, under
    the hoop tension ``T0 = p b R`` of the inflation pressure; the sidewalls
    are an elastic foundation with radial and tangential stiffness per unit
    length ``k_r``, ``k_t`` (Kung, Soedel & Yang 1986; Pacejka, *Tire and
    Vehicle Dynamics*, ch. 9; Gong 1993). Defaults: 295/80R22.5 at 7.5 bar.

    Parameters
    ----------
    radius : float
        Belt (tread-band centre line) radius ``R`` in m. Default 0.50: the
        overall diameter of a 295/80R22.5 is 22.5 in + 2 * 0.80 * 295 mm =
        1.04 m (outer radius 0.52 m), minus about 20 mm of tread rubber.
    width : float
        Belt width ``b`` in m. Default 0.24 (about 0.8 of the 295 mm section
        width; spec ``virtual-tyre.md``).
    pressure : float
        Inflation (gauge) pressure ``p`` in Pa, >= 0. Default 7.5e5 (the
        7.5 bar of paper 000, figures 2-5).
    mass_per_length : float
        Tread-band mass per unit length ``rho A`` in kg/m. Default 11: a band
        (tread rubber, steel belts, carcass crown) of about 35 kg of a
        60 kg truck tyre over the circumference 2 pi R = 3.14 m.
    bending_stiffness : float
        In-plane bending stiffness ``EI`` of the band in N m^2. Default 50
        (spec ``virtual-tyre.md``; equivalent to E = 0.74 GPa over a 15 mm
        thick, 0.24 m wide rubber-steel composite).
    membrane_stiffness : float
        Circumferential membrane stiffness ``EA`` of the band in N. Default
        2e7: three to four steel belt plies of about 60 mm^2 steel each at
        E = 200 GPa, reduced for the cord angle. Large enough that the
        extensible ring is within 0.1 % of the inextensible frequencies
        below 200 Hz (checked in the tests).
    radial_stiffness_base, radial_stiffness_per_pressure : float
        Radial sidewall (foundation) stiffness per unit length
        ``k_r = k_r0 + k_rp * p``: ``k_r0`` in N/m^2 (rubber sidewall at zero
        pressure) and ``k_rp`` dimensionless (N/m^2 per Pa). A pressurised
        sidewall acts as a membrane with meridional tension ``N_s ~ p h/2``
        (h the section height); displacing the belt edge of the two sidewalls
        by ``w`` gives a restoring force of about ``2 N_s w / l_s`` per unit
        length (``l_s`` the free meridian length, ``h / l_s ~ 1.2``), so the
        pressure part is ``k_rp p`` with ``k_rp`` of order one. Defaults
        1.5e5 and 1.8 give ``k_r = 1.5e6`` N/m^2 at 7.5 bar (spec reference
        value), 90 % of it from inflation: a truck tyre's vertical stiffness
        is nearly proportional to pressure (the Goodyear 335/65R22.5 .tir
        values of Project Chrono ``feda`` fit ``92 kN/m + 116 kN/m/bar``
        within 1.5 % from 2.7 to 6.5 bar, a pressure-independent part of
        11 % at 6.5 bar; Rhyne, Tire Sci. Technol. 33(3), 2005, finds the
        same linear law with a small structural term).
    tangential_stiffness_base, tangential_stiffness_per_pressure : float
        Tangential sidewall stiffness ``k_t = k_t0 + k_tp * p`` (same units
        and argument as the radial one). Defaults 5e4 and 0.6 give
        ``k_t = 5e5`` N/m^2 at 7.5 bar (spec reference value), with the same
        10 % pressure-independent share as the radial one (assumed: no
        published value separates it).
    radial_damping, tangential_damping : float
        Viscous sidewall dampers per unit length ``c_r``, ``c_t`` in
        N s/m^2. Defaults 280 and 30. They are *not* proportional to
        ``k_r``, ``k_t``: the pressure part of the sidewall stiffness is
        lossless (gas), only the rubber dissipates. 280 N s/m^2 is a loss
        factor ``c omega / k_r`` of 0.12 at 100 Hz (rubber 0.05-0.2). With
        the drive-point damper they give modal damping ratios of 2-5 % at
        5-9 bar, falling with frequency.
    band_loss_factor : float
        Loss factor of the band *bending* only (Kelvin-Voigt damping
        ``eta / omega_ref`` times the bending stiffness matrix), >= 0.
        Default 0.05. The tension term carries no band loss.
    band_loss_frequency : float
        Reference frequency ``omega_ref / 2 pi`` in Hz at which the band loss
        factors are matched. Default 200.
    membrane_loss_factor : float
        Loss factor of the band's circumferential (membrane) strain, >= 0,
        Kelvin-Voigt on the membrane stiffness matrix like the bending loss.
        Default 0: the membrane strain is carried by the steel belt cords,
        which lose far less than the rubber that bending shears (steel-cord
        rubber composites 0.01-0.05), and the in-band flexural modes are
        nearly inextensible, so a realistic 0.02 changes no in-band modal
        damping term by more than 0.2 % (``damping_decomposition``); as a
        Kelvin-Voigt loss it grows with frequency and overdamps the
        10-30 kHz membrane waves of a fine grid (``n_ring`` 128), which the
        conjugate-pair modal form cannot hold.

    Notes
    -----
    With these values the inextensible formula (spec ``virtual-tyre.md``)
    gives about 48, 71, 96, 124, 153 and 184 Hz for n = 1..6 and 216 Hz for
    n = 7, inside the 50-250 Hz range of published truck-tyre in-plane
    resonances; the rotation mode (n = 0, tangential) is at
    ``sqrt(k_t / rho A) / 2 pi`` = 34 Hz and has no radial motion.

    Raises
    ------
    PhysicsError
        A negative pressure or damping, or a non-positive geometry, mass or
        stiffness (the message names the field).
    InputError
        A NaN, infinite or non-numeric field.
    """

    radius: float = 0.50
    width: float = 0.24
    pressure: float = 7.5e5
    mass_per_length: float = 11.0
    bending_stiffness: float = 50.0
    membrane_stiffness: float = 2.0e7
    radial_stiffness_base: float = 1.5e5
    radial_stiffness_per_pressure: float = 1.8
    tangential_stiffness_base: float = 5.0e4
    tangential_stiffness_per_pressure: float = 0.6
    radial_damping: float = 280.0
    tangential_damping: float = 30.0
    band_loss_factor: float = 0.05
    band_loss_frequency: float = 200.0
    membrane_loss_factor: float = 0.0

    _NON_NEGATIVE = frozenset(
        {
            "pressure",
            "radial_stiffness_per_pressure",
            "tangential_stiffness_per_pressure",
            "radial_damping",
            "tangential_damping",
            "band_loss_factor",
            "membrane_loss_factor",
        }
    )

    def __post_init__(self) -> None:
        for f in fields(self):
            _check_field(self, f.name, allow_zero=f.name in self._NON_NEGATIVE)
            object.__setattr__(self, f.name, float(getattr(self, f.name)))

    # ---------------------------------------------------------- derived
    @property
    def hoop_tension(self) -> float:
        """Hoop tension ``T0 = p b R`` of the inflated band in N."""
        return self.pressure * self.width * self.radius

    @property
    def radial_stiffness(self) -> float:
        """Radial foundation stiffness ``k_r = k_r0 + k_rp p`` in N/m^2."""
        return self.radial_stiffness_base + self.radial_stiffness_per_pressure * self.pressure

    @property
    def tangential_stiffness(self) -> float:
        """Tangential foundation stiffness ``k_t = k_t0 + k_tp p`` in N/m^2."""
        return (
            self.tangential_stiffness_base + self.tangential_stiffness_per_pressure * self.pressure
        )

    @property
    def band_mass(self) -> float:
        """Mass of the whole tread band ``2 pi R rho A`` in kg."""
        return 2 * np.pi * self.radius * self.mass_per_length

    def with_pressure(self, pressure: float) -> RingTyreParameters:
        """The same tyre at another inflation pressure (Pa); ``T0``, ``k_r``, ``k_t`` follow."""
        return replace(self, pressure=pressure)


@dataclass(frozen=True)
class MeasurementLayout:
    """Measured points and shaker attachments of the virtual modal test (paper 000).

    Parameters
    ----------
    n_points : int
        Number of equally spaced radial measurement points on the centre
        circumference (default 16, i.e. 22.5 deg apart as in paper 000).
        Point ``k`` (1-based node number) is at ``(k - 1) * 360 / n_points``
        deg.
    drive_points : tuple of int
        Point numbers (1-based) where radial shakers are attached (default
        ``(1,)``: one drive point as in the paper; several for
        multi-reference tests).
    attachment_mass : float
        Mass in kg added radially at each drive point: the mass below the
        force gauge's sensing element (gauge base, mounting stud and a glued
        2 x 2 cm tip; ISO 7626-2:2015, sec. 6: only this mass belongs to the
        tested structure, the shaker and drive rod act beyond the gauge; the
        drive rod is flexible across its axis, so the mass acts radially
        only). Default 0.01.
    attachment_damping : float
        Local radial viscous damper in N s/m at each drive point: the tread
        rubber worked under the glued tip. Default 2.0. The tread under the
        tip is a spring in series between the tip mass and the band, so it
        dissipates only through their relative motion
        (:func:`~tyredamp.virtual.sources.tip_loss_damping`): with 10 g on
        the 4e4 N/m of a 2 x 2 cm patch of the tread (2 MPa over 20 mm; tip
        resonance 318 Hz) and the tread loss factor 0.15, the equivalent
        dashpot is 0.1 N s/m at 100 Hz and 1.9 N s/m at 200 Hz, the top of
        the band (the default). The 30 N s/m of the tread spring's own loss,
        ``eta k / omega``, would be a tip held still by the shaker, which a
        force gauge at the surface does not do.
    """

    n_points: int = 16
    drive_points: tuple[int, ...] = (1,)
    attachment_mass: float = 0.01
    attachment_damping: float = 2.0

    def __post_init__(self) -> None:
        if not isinstance(self.n_points, int | np.integer) or self.n_points < 3:
            raise InputError(
                f"MeasurementLayout.n_points: expected an integer >= 3, got {self.n_points!r}"
            )
        dp = tuple(np.atleast_1d(np.asarray(self.drive_points)).tolist())
        if len(dp) == 0 or not all(isinstance(d, int) for d in dp):
            raise InputError(
                "MeasurementLayout.drive_points: expected a non-empty list of point numbers, "
                f"got {self.drive_points!r}"
            )
        bad = [d for d in dp if not 1 <= d <= self.n_points]
        if bad:
            raise InputError(
                f"MeasurementLayout.drive_points: expected point numbers in 1..{self.n_points}, "
                f"got {bad}"
            )
        if len(set(dp)) != len(dp):
            raise InputError(f"MeasurementLayout.drive_points: repeated points in {dp}")
        object.__setattr__(self, "drive_points", dp)
        object.__setattr__(self, "n_points", int(self.n_points))
        _check_field(self, "attachment_mass", allow_zero=True)
        _check_field(self, "attachment_damping", allow_zero=True)
        object.__setattr__(self, "attachment_mass", float(self.attachment_mass))
        object.__setattr__(self, "attachment_damping", float(self.attachment_damping))

    @property
    def angles_deg(self) -> np.ndarray:
        """Angles of the measured points in deg, shape (n_points,)."""
        return np.arange(self.n_points) * (360.0 / self.n_points)


@dataclass(frozen=True)
class Imperfection:
    """A local change of the ring that splits its double modes.

    Applied at the ring node nearest to ``angle_deg``.

    Parameters
    ----------
    angle_deg : float
        Position in deg (0 deg is measurement point 1).
    mass : float
        Added lumped mass in kg (a heavy spot: tread splice, balancing
        weight); it moves radially with the node and tangentially with the
        two adjacent tangential DOFs (half each). Default 0.
    stiffness : float
        Added radial spring to ground in N/m (a stiff sidewall spot).
        Default 0.
    damping : float
        Added radial dashpot to ground in N s/m (a sidewall defect). Default 0.
    """

    angle_deg: float
    mass: float = 0.0
    stiffness: float = 0.0
    damping: float = 0.0

    def __post_init__(self) -> None:
        try:
            a = float(self.angle_deg)
        except (TypeError, ValueError):
            raise InputError(
                f"Imperfection.angle_deg: expected a number, got {self.angle_deg!r}"
            ) from None
        if not math.isfinite(a):
            raise InputError(f"Imperfection.angle_deg: expected a finite angle, got {a}")
        object.__setattr__(self, "angle_deg", a)
        for name in ("mass", "stiffness", "damping"):
            _check_field(self, name, allow_zero=True)
            object.__setattr__(self, name, float(getattr(self, name)))
