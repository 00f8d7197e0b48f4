"""MCK mechanics core: modes, FRFs, small-damping perturbation, time response.

Implements spec ``radial-damping.md`` eq. [1]-[18] for a linear viscously
damped system ``M x'' + C x' + K x = f``.
"""

from __future__ import annotations

from .gyroscopic import GyroscopicSystem, StateModes
from .modal_sum import (
    kind_factor,
    modal_sum_receptance,
    pole_from_frequency_damping,
    pole_quantities,
)
from .perturbation import (
    SmallDampingError,
    SmallDampingModes,
    alpha_coefficients,
    small_damping_error,
    small_damping_modes,
)
from .proportional import (
    modal_damping_matrix,
    proportional_part,
    rayleigh_coefficients,
    rayleigh_damping,
    rayleigh_damping_ratios,
)
from .response import (
    TimeResponse,
    continuous_periodic_lines,
    foh_fourier_lines,
    periodic_response_lines,
    step_coefficients,
    time_response,
)
from .system import ComplexModes, MCKSystem, UndampedModes, normalisation_constants

__all__ = [
    "ComplexModes",
    "GyroscopicSystem",
    "MCKSystem",
    "SmallDampingError",
    "SmallDampingModes",
    "StateModes",
    "TimeResponse",
    "UndampedModes",
    "alpha_coefficients",
    "continuous_periodic_lines",
    "foh_fourier_lines",
    "kind_factor",
    "modal_damping_matrix",
    "modal_sum_receptance",
    "normalisation_constants",
    "periodic_response_lines",
    "pole_from_frequency_damping",
    "pole_quantities",
    "proportional_part",
    "rayleigh_coefficients",
    "rayleigh_damping",
    "rayleigh_damping_ratios",
    "small_damping_error",
    "small_damping_modes",
    "step_coefficients",
    "time_response",
]
