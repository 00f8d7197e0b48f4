"""Measurement processing: excitation signals, FRF estimators, coherence, checks.

Implements steps 1-2 of spec ``radial-damping.md``: FRFs from time data,
ensemble averaged, with coherence (:func:`estimate_frf`), and linearity,
reciprocity and data-quality checks with numbers (:mod:`.checks`).
"""

from __future__ import annotations

from .checks import (
    CheckResult,
    clipping,
    linearity_check,
    merge_inputs,
    quality_check,
    reciprocity_check,
)
from .estimators import (
    ESTIMATORS,
    METHODS,
    RESPONSE_KIND,
    CrossSpectra,
    cross_spectra,
    estimate_frf,
    frf_from_spectra,
    multiple_coherence,
    ordinary_coherence,
    resolve_channels,
)
from .excitation import (
    Excitation,
    amplitude_spectrum,
    band_lines,
    burst_random,
    periodic_chirp,
    pseudo_random,
    schroeder_multisine,
    swept_chirp,
)
from .windows import exponential_window, force_window, segment_window

__all__ = [
    "ESTIMATORS",
    "METHODS",
    "RESPONSE_KIND",
    "CheckResult",
    "CrossSpectra",
    "Excitation",
    "amplitude_spectrum",
    "band_lines",
    "burst_random",
    "clipping",
    "cross_spectra",
    "estimate_frf",
    "exponential_window",
    "force_window",
    "frf_from_spectra",
    "linearity_check",
    "merge_inputs",
    "multiple_coherence",
    "ordinary_coherence",
    "periodic_chirp",
    "pseudo_random",
    "quality_check",
    "reciprocity_check",
    "resolve_channels",
    "schroeder_multisine",
    "segment_window",
    "swept_chirp",
]
