"""The one axes helper of the figures: given axes are checked, missing ones made.

Figures are :class:`matplotlib.figure.Figure` objects with the constrained
layout (no pyplot, no global state).
"""

from __future__ import annotations

from collections.abc import Sequence

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..exceptions import InputError

__all__ = ["axes_grid", "single_axes"]


def single_axes(ax: Axes | None, figsize: tuple[float, float]) -> Axes:
    """``ax``, or the axes of a new ``figsize`` (inches) figure."""
    if ax is not None:
        return ax
    return Figure(figsize=figsize, layout="constrained").subplots()


def axes_grid(
    axes: Sequence[Axes] | None,
    n: int,
    figsize: tuple[float, float],
    *,
    columns: bool = False,
    sharex: bool = True,
) -> list[Axes]:
    """``n`` panels: the given ``axes`` (exactly ``n``), or a new figure of ``n`` rows.

    Parameters
    ----------
    axes : sequence of Axes, optional
        Axes to draw into.
    n : int
        Panels needed.
    figsize : (float, float)
        Size of a new figure, inches.
    columns : bool
        New panels side by side (one row) instead of stacked.
    sharex : bool
        Stacked new panels share the frequency axis.

    Raises
    ------
    InputError
        ``axes`` given with a number other than ``n``.
    """
    if axes is not None:
        out = list(axes)
        if len(out) != n:
            raise InputError(f"axes: expected {n} axes, got {len(out)}")
        return out
    fig = Figure(figsize=figsize, layout="constrained")
    if columns:
        return list(fig.subplots(1, n, squeeze=False)[0, :])
    return list(fig.subplots(n, 1, sharex=sharex, squeeze=False)[:, 0])
