"""Figures (matplotlib only; imported lazily by result objects' ``.plot()``).

Every function takes ``ax=None`` (or ``axes=None``), draws, and returns what
it drew; none calls ``show()``. The numerical core never imports this package.
"""

from __future__ import annotations

from .frf import plot_frf, plot_frf_comparison

__all__ = ["plot_frf", "plot_frf_comparison"]
