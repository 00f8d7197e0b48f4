"""Virtual tyres: the in-plane ring tyre and the virtual modal test rig."""

from __future__ import annotations

from .excitation import hadamard_drive_matrix, schroeder_multisine
from .parameters import Imperfection, MeasurementLayout, RingTyreParameters
from .rig import VirtualModalTest, periodic_initial_state, run_modal_test
from .ring import (
    RingConvergence,
    RingTyre,
    analytic_ring_frequencies,
    difference_symbol,
    ring_convergence,
    ring_dispersion,
    staggered_weights,
    wave_numbers,
)
from .truth import TyreTruth, modal_phase_collinearity

__all__ = [
    "Imperfection",
    "MeasurementLayout",
    "RingConvergence",
    "RingTyre",
    "RingTyreParameters",
    "TyreTruth",
    "VirtualModalTest",
    "analytic_ring_frequencies",
    "difference_symbol",
    "hadamard_drive_matrix",
    "modal_phase_collinearity",
    "periodic_initial_state",
    "ring_convergence",
    "ring_dispersion",
    "run_modal_test",
    "schroeder_multisine",
    "staggered_weights",
    "wave_numbers",
]
