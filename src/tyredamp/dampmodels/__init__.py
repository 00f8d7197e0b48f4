"""Which damping model does the structure have? Damping laws, exact modes, identification, choice.

Damping laws (:mod:`.laws`): viscous, hysteretic (complex stiffness), exponential
relaxation kernels and fractional derivative, each the damping part ``Z(s)``
of the dynamic stiffness ``D(s) = s^2 M + K + Z(s)`` (Adhikari & Woodhouse,
J. Sound Vib. 243(1) (2001) 63-88). :class:`DampedSystem` gives their exact
FRFs and exact modes.
"""

from __future__ import annotations

from .laws import LAWS, DampingLaw, Exponential, Fractional, Hysteretic, Viscous
from .system import DampedSystem, ExactModes, newton_mode

__all__ = [
    "LAWS",
    "DampedSystem",
    "DampingLaw",
    "ExactModes",
    "Exponential",
    "Fractional",
    "Hysteretic",
    "Viscous",
    "newton_mode",
]
