"""Measurement processing: excitation signals, FRF estimators, coherence, checks.

Implements steps 1-2 of spec ``radial-damping.md``: FRFs from time data,
ensemble averaged, with coherence and per-line variance
(:func:`estimate_frf`; the local rational method :func:`local_frf`), the
excitation detected from the data when a file does not state it
(:func:`detect_excitation`), and linearity, reciprocity and data-quality
checks with numbers (:mod:`.checks`).
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
    frf_variance,
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
from .lrm import local_frf
from .periodicity import ExcitationDetection, detect_excitation, transient_periods
from .windows import exponential_window, force_window, segment_window

__all__ = [
    "ESTIMATORS",
    "METHODS",
    "RESPONSE_KIND",
    "CheckResult",
    "CrossSpectra",
    "Excitation",
    "ExcitationDetection",
    "amplitude_spectrum",
    "band_lines",
    "burst_random",
    "clipping",
    "cross_spectra",
    "detect_excitation",
    "estimate_frf",
    "exponential_window",
    "force_window",
    "frf_from_spectra",
    "frf_variance",
    "linearity_check",
    "local_frf",
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
    "transient_periods",
]
