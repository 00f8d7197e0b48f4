"""Virtual tyres and rigs with a known truth: the radial ring tyre and its modal
test rig (paper 000), the rolling-tyre lateral rig (paper 001).

* :class:`RingTyreParameters`, :class:`MeasurementLayout`, :class:`Imperfection`:
  the 295/80R22.5 truck tyre at 7.5 bar (defaults), the 16 measured points and
  the shaker attachments of paper 000, local changes that split double modes.
* :func:`analytic_ring_frequencies` (inextensible ring, spec
  ``virtual-tyre.md``), :func:`ring_dispersion` (extensible ring, continuous or
  discretised), :func:`ring_convergence` (discrete against analytic).
* :class:`RingTyre`: the staggered finite-difference ring with ``M``, ``C``,
  ``K`` (:class:`~tyredamp.mechanics.MCKSystem`), index maps and the
  ``nonproportionality`` knob; :meth:`RingTyre.truth` gives the exact modal
  truth at the points (:class:`TyreTruth`).
* Physical additions to the ring (:class:`RingTyre` keywords): :class:`Splice`
  (:mod:`.assembly`), the air cavity :class:`Cavity` (:mod:`.cavity`), a
  loaded :class:`ContactPatch` with its hub stiffness (:mod:`.contact`);
  :func:`damping_decomposition` (:mod:`.sources`) splits the non-proportional
  damping by physical source.
* :func:`run_modal_test`: the virtual test rig (periodic chirp, noise,
  multi-reference), returning :class:`VirtualModalTest` (``TimeData`` + truth).
* :class:`RotatingRing` (:mod:`.rotation`): the ring spinning at a rolling
  speed (Coriolis, centrifugal, centrifugal tension), its closed-form
  dispersion :func:`rotating_ring_dispersion`; :func:`rolling_test`
  (:mod:`.rolling_rig`): fixed and in-tyre sensors under a road force, with
  the forward/backward waves in both frames (:class:`RollingTruth`).
* :class:`VirtualLateralRig` (:mod:`.lateral_rig`): the rolling-tyre rig of
  paper 001 with its exact tyre (:class:`ViscoelasticStringTyre`,
  :class:`AgriculturalTyre`), FRFs and time tests.

Examples
--------
>>> from tyredamp.virtual import RingTyre, run_modal_test
>>> test = run_modal_test(RingTyre(), seed=1)
>>> test.data
TimeData(n_channels=17, n_samples=32768, sample_rate=1024 Hz, forces=1)
>>> round(test.truth.table("visible")[0]["frequency_hz"], 2)  # the n = 1 mode, Hz
47.94
"""

from __future__ import annotations

from .assembly import Splice
from .cavity import Cavity
from .contact import ContactPatch
from .dispersion import (
    analytic_ring_frequencies,
    difference_symbol,
    ring_dispersion,
    staggered_weights,
)
from .excitation import hadamard_drive_matrix, schroeder_multisine
from .lateral_rig import KMH, AgriculturalTyre, VirtualLateralRig, ViscoelasticStringTyre
from .modal_rig import VirtualModalTest, periodic_initial_state, run_modal_test
from .parameters import Imperfection, MeasurementLayout, RingTyreParameters
from .ring import RingConvergence, RingTyre, ring_convergence
from .rolling_rig import ContactLoad, PointContact, RollingTest, rolling_response, rolling_test
from .rolling_truth import RollingTruth
from .rotation import (
    RotatingRing,
    critical_speed_kmh,
    inextensible_rotating_frequencies,
    rotating_ring_dispersion,
    rotating_ring_roots,
)
from .sources import DampingDecomposition, damping_decomposition
from .tangential import WindupTruth, bare_ring_windup, tangential_tyre, windup_truth
from .truth import TyreTruth, modal_phase_collinearity, wave_numbers

__all__ = [
    "KMH",
    "AgriculturalTyre",
    "Cavity",
    "ContactLoad",
    "ContactPatch",
    "DampingDecomposition",
    "Imperfection",
    "MeasurementLayout",
    "PointContact",
    "RingConvergence",
    "RingTyre",
    "RingTyreParameters",
    "RollingTest",
    "RollingTruth",
    "RotatingRing",
    "Splice",
    "TyreTruth",
    "VirtualLateralRig",
    "VirtualModalTest",
    "ViscoelasticStringTyre",
    "WindupTruth",
    "analytic_ring_frequencies",
    "bare_ring_windup",
    "critical_speed_kmh",
    "damping_decomposition",
    "difference_symbol",
    "hadamard_drive_matrix",
    "inextensible_rotating_frequencies",
    "modal_phase_collinearity",
    "periodic_initial_state",
    "ring_convergence",
    "ring_dispersion",
    "rolling_response",
    "rolling_test",
    "rotating_ring_dispersion",
    "rotating_ring_roots",
    "run_modal_test",
    "schroeder_multisine",
    "staggered_weights",
    "tangential_tyre",
    "wave_numbers",
    "windup_truth",
]
