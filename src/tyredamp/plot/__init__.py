"""Figures (matplotlib only; imported lazily by result objects' ``.plot()``).

Every function takes ``ax=None`` (or ``axes=None``), draws, and returns what
it drew; none calls ``show()`` or uses pyplot (figures are
:class:`matplotlib.figure.Figure` objects). The numerical core never imports
this package.

=====================================  =========================================
function                               figure
=====================================  =========================================
:func:`plot_frf`                       FRF: Bode, real/imaginary, or all four
:func:`plot_frf_comparison`            measured vs fitted FRFs (paper Figs. 2, 3)
:func:`plot_discrepancy`               discrepancy against frequency (Fig. 4)
:func:`plot_matrix`                    damping matrices as heat maps (Fig. 5)
:func:`plot_mode_shapes_ring`          mode shapes around the circumference
:func:`plot_mode_shapes_geometry`      mode shapes on the test geometry (wireframe)
:func:`plot_mode_shapes_points`        mode shapes against the point (no ring, no geometry)
:func:`plot_mode_shapes`               every view the data call for (geometry, ring, points)
:func:`plot_stabilisation`             stabilisation diagram of the pole search
:func:`plot_figure7`                   lateral amplitude ratio, asymptotes, f0 (Fig. 7)
:func:`plot_lateral_fit`               one lateral fit (Figs. 11-14)
:func:`plot_ranking`                   every ranked lateral fit (Figs. 11, 12)
:func:`plot_lateral_models`            measured vs predictions and truth (Figs. 11-14)
:func:`plot_time_comparison`           lateral time response (Fig. 15)
:func:`plot_ring_frequencies`          measured vs updated-ring frequencies per n and pressure
=====================================  =========================================
"""

from __future__ import annotations

from .comparison import plot_lateral_models
from .damping import plot_matrix
from .frf import plot_frf, plot_frf_comparison
from .geometry import plot_mode_shapes_geometry
from .lateral import plot_figure7, plot_lateral_fit, plot_ranking, plot_time_comparison
from .modal import plot_discrepancy, plot_mode_shapes_ring
from .modeshapes import plot_mode_shapes, plot_mode_shapes_points
from .stabilisation import plot_stabilisation
from .tyremodel import plot_ring_frequencies

__all__ = [
    "plot_discrepancy",
    "plot_figure7",
    "plot_frf",
    "plot_frf_comparison",
    "plot_lateral_fit",
    "plot_lateral_models",
    "plot_matrix",
    "plot_mode_shapes",
    "plot_mode_shapes_geometry",
    "plot_mode_shapes_points",
    "plot_mode_shapes_ring",
    "plot_ranking",
    "plot_ring_frequencies",
    "plot_stabilisation",
    "plot_time_comparison",
]
