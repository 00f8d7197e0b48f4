"""From the modal test to the tyre models that vehicle simulation uses (issue 18).

* :mod:`.wavenumber` -- circumferential wave number of every identified mode
  from its shape (spatial Fourier fit over the measured angles), cos/sin
  members, pair splitting and orientation, spatial aliasing.
* :mod:`.ring` -- flexible-ring model updating (EI, tension law, foundation,
  mass per length, damping) across pressures, with standard errors and
  identifiability verdicts; predictions of modes and FRFs.
"""

from __future__ import annotations

from .ring import (
    RingFit,
    RingObservation,
    fit_ring,
    ring_amplitude,
    ring_frequency,
    ring_observations,
)
from .wavenumber import (
    ModeWaveNumber,
    WaveNumberAnalysis,
    alias_candidates,
    harmonic_fit,
    resolved_wave_numbers,
    wave_number_analysis,
)

__all__ = [
    "ModeWaveNumber",
    "RingFit",
    "RingObservation",
    "WaveNumberAnalysis",
    "alias_candidates",
    "fit_ring",
    "harmonic_fit",
    "resolved_wave_numbers",
    "ring_amplitude",
    "ring_frequency",
    "ring_observations",
    "wave_number_analysis",
]
