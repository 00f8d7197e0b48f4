"""Operational modal analysis: modes from output-only records.

* :mod:`.correlation`: output correlations by FFT over blocks, streamed;
* :mod:`.ssi`: covariance-driven SSI (Peeters & De Roeck 1999);
* :mod:`.spectra`: half-spectra and pLSCF on them;
* :mod:`.selection`: stabilisation and automatic selection from the data;
* :mod:`.uncertainty`: delete-one-segment jackknife standard errors;
* :mod:`.harmonics`: wheel orders told apart from modes (kurtosis test);
* :mod:`.waves`: forward and backward travelling waves, the rotating sensor;
* :mod:`.identify`: all of it behind :func:`oma`.
"""

from __future__ import annotations

from .correlation import CorrelationAccumulator, Correlations, correlations
from .identify import OMAResult, oma
from .ssi import OrderPoles, ssi_cov
from .waves import RotatingPeak, WaveContent, resolve_rotating, wave_content

__all__ = [
    "CorrelationAccumulator",
    "Correlations",
    "OMAResult",
    "OrderPoles",
    "RotatingPeak",
    "WaveContent",
    "correlations",
    "oma",
    "resolve_rotating",
    "ssi_cov",
    "wave_content",
]
