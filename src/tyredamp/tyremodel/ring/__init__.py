"""Flexible-ring model updating: ring parameters from identified modes at one or more pressures.

The inextensible inflated ring on an elastic foundation, with its tension
following the inflation pressure, is fitted to the identified modes
(frequencies, mass-normalised shape amplitudes, damping ratios) of one or
several tests, with standard errors and identifiability verdicts, and then
predicts modes and FRFs at other pressures.

* :mod:`.model` -- the ring: natural frequencies (eq. (1)), mode amplitudes
  (eq. (2)), modal damping (eq. (3)), the parameters and pressure laws.
* :mod:`.observations` -- the identified modes the ring describes
  (:func:`ring_observations`).
* :mod:`.fit` -- :func:`fit_ring`: weighted least squares of the stiffness and
  mass parameters, then of the damping (:mod:`.damping`).
* :mod:`.extension` -- the test of the inextensible ring against the
  extensible one and each parameter's term for it.
* :mod:`.identifiability` -- covariance scaling, correlations, collinearity
  and the per-parameter verdicts.
* :mod:`.result` -- :class:`RingFit`: parameters, predictions, FRFs, tables.
"""

from __future__ import annotations

from .fit import fit_ring
from .model import FoundationLaw, ring_amplitude, ring_frequency
from .observations import RingObservation, ring_observations
from .result import RingFit

__all__ = [
    "FoundationLaw",
    "RingFit",
    "RingObservation",
    "fit_ring",
    "ring_amplitude",
    "ring_frequency",
    "ring_observations",
]
