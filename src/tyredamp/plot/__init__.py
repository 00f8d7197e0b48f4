"""Figures (matplotlib only; imported lazily by result objects' ``.plot()``).

Every function takes ``ax=None`` (or ``axes=None``), draws, and returns what
it drew; none calls ``show()``. The numerical core never imports this package.
"""

from __future__ import annotations

from .damping import plot_matrix
from .frf import plot_frf, plot_frf_comparison
from .modal import plot_discrepancy, plot_mode_shapes_ring

__all__ = [
    "plot_discrepancy",
    "plot_frf",
    "plot_frf_comparison",
    "plot_matrix",
    "plot_mode_shapes_ring",
]
