"""From the modal test to the tyre models that vehicle simulation uses.

* :mod:`.wavenumber` -- circumferential wave number of every identified mode
  from its shape (spatial Fourier fit over the measured angles), cos/sin
  members, pair splitting and orientation, spatial aliasing; on
  :mod:`.harmonics` (what the measured angles resolve, aliases, the
  single-harmonic fit).
* :mod:`.ring` -- flexible-ring model updating (EI, tension law, foundation,
  mass per length, damping) across pressures, with standard errors and
  identifiability verdicts; predictions of modes and FRFs.
* :mod:`.rigid` -- in-plane rigid-ring (MF-Swift) parameters from the n = 1
  modes, with what a radial test cannot give stated.
* :mod:`.windup` -- the belt's wind-up (``FREQ_WINDUP``, ``DAMP_WINDUP``,
  ``BELT_IYY``) from the ``n = 0`` mode of a tangential test.
* :mod:`.tir` -- the in-plane ``.tir`` fragment (writer) and a reader of
  every public ``.tir`` property file; :mod:`.tirmerge` -- identified
  values merged into a complete base ``.tir``.
* :mod:`.budget` -- the uncertainty budget of the written values
  (calibration, attachment, rigid translation); :mod:`.checks` -- what is
  refused (unstable modes, repeated files or pressures, a ring whose tension
  does not follow the pressure, lateral tests at another pressure).
* :mod:`.lateral` -- lateral carcass stiffness and relaxation length from the
  lateral fits of paper 001.
* :mod:`.pipeline` -- all of it in one call (:func:`build_tyre_model`), as
  ``tyredamp tyre-model`` runs it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:
    from .harmonics import alias_candidates, harmonic_fit, resolved_wave_numbers
    from .lateral import LateralCarcass, lateral_carcass, read_lateral_carcass
    from .pipeline import TyreModelResult, build_tyre_model
    from .rigid import NOT_FROM_RADIAL_TEST, RigidRingParameters, rigid_ring_from_modes
    from .ring import (
        RingFit,
        RingObservation,
        fit_ring,
        ring_amplitude,
        ring_frequency,
        ring_observations,
    )
    from .tir import parse_tir, tir_text
    from .wavenumber import ModeWaveNumber, WaveNumberAnalysis, wave_number_analysis
    from .windup import WindupParameters, windup_budget, windup_from_modes

#: the module of each public name: loaded on first access (PEP 562), so that a
#: step that needs the wave numbers does not load the lateral fits, the ring
#: updating and their optimisers
_WHERE = {
    "NOT_FROM_RADIAL_TEST": "rigid",
    "LateralCarcass": "lateral",
    "ModeWaveNumber": "wavenumber",
    "RigidRingParameters": "rigid",
    "RingFit": "ring",
    "RingObservation": "ring",
    "TyreModelResult": "pipeline",
    "WaveNumberAnalysis": "wavenumber",
    "alias_candidates": "harmonics",
    "build_tyre_model": "pipeline",
    "fit_ring": "ring",
    "harmonic_fit": "harmonics",
    "lateral_carcass": "lateral",
    "parse_tir": "tir",
    "read_lateral_carcass": "lateral",
    "resolved_wave_numbers": "harmonics",
    "rigid_ring_from_modes": "rigid",
    "ring_amplitude": "ring",
    "ring_frequency": "ring",
    "ring_observations": "ring",
    "tir_text": "tir",
    "wave_number_analysis": "wavenumber",
    "WindupParameters": "windup",
    "windup_budget": "windup",
    "windup_from_modes": "windup",
}

__all__ = [
    "NOT_FROM_RADIAL_TEST",
    "LateralCarcass",
    "ModeWaveNumber",
    "RigidRingParameters",
    "RingFit",
    "RingObservation",
    "TyreModelResult",
    "WaveNumberAnalysis",
    "WindupParameters",
    "alias_candidates",
    "build_tyre_model",
    "fit_ring",
    "harmonic_fit",
    "lateral_carcass",
    "parse_tir",
    "read_lateral_carcass",
    "resolved_wave_numbers",
    "rigid_ring_from_modes",
    "ring_amplitude",
    "ring_frequency",
    "ring_observations",
    "tir_text",
    "wave_number_analysis",
    "windup_budget",
    "windup_from_modes",
]

__getattr__, __dir__ = lazy_names(__name__, _WHERE, __all__, globals())
