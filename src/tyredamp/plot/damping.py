"""Damping matrices as heat maps (paper Fig. 5)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ._axes import single_axes

__all__ = ["plot_matrix"]


def plot_matrix(
    matrix: ArrayLike,
    labels: Sequence[str] | None = None,
    title: str = "",
    unit: str = "",
    ax: Axes | None = None,
    symmetric_colors: bool = True,
    linthresh: float | None = None,
) -> Axes:
    """Heat map of a real matrix with a diverging colour map centred on 0.

    Negative entries (e.g. physical-coordinate damping from modal truncation)
    show in blue, positive in red.

    Parameters
    ----------
    linthresh : float, optional
        Symmetric logarithmic colour scale, linear within ``+-linthresh``
        (:class:`matplotlib.colors.SymLogNorm`): small off-diagonal terms of a
        diagonally dominant matrix (modal damping) stay visible beside the
        large diagonal. Default: linear scale.
    """
    from matplotlib.colors import SymLogNorm

    a = np.asarray(matrix, dtype=float)
    if a.ndim != 2:
        raise InputError(f"matrix: expected a 2-D array, got shape {a.shape}")
    ax = single_axes(ax, (4.6, 3.9))
    lim = float(np.max(np.abs(a))) or 1.0
    if linthresh is not None and linthresh > 0:
        norm = SymLogNorm(linthresh=float(linthresh), vmin=-lim, vmax=lim, base=10)
        im = ax.imshow(a, cmap="RdBu_r", norm=norm)
    else:
        vmin, vmax = (-lim, lim) if symmetric_colors else (None, None)
        im = ax.imshow(a, cmap="RdBu_r", vmin=vmin, vmax=vmax)
    fig = ax.figure
    fig.colorbar(im, ax=ax, label=unit)
    if labels is not None:
        ax.set_xticks(range(len(labels)), labels, rotation=90, fontsize="x-small")
        ax.set_yticks(range(len(labels)), labels, fontsize="x-small")
    ax.set_title(title, fontsize="small")
    return ax
