"""Trend plots of a test campaign: a quantity of one mode family against one condition."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["plot_trend"]


def plot_trend(
    points: Sequence[Mapping[str, Any]],
    fit: Any,
    condition: str,
    quantity: str,
    *,
    ax: Any = None,
    label: str | None = None,
    color: Any = None,
    scale: float = 1.0,
) -> dict[str, Any]:
    """Observations with standard errors, the fitted trend and its +-1.96 sigma band.

    Parameters
    ----------
    points : sequence of dict
        Rows of the campaign's mode table (keys ``condition``, ``quantity``
        and ``quantity + "_std"`` or the frequency's ``frequency_std_hz``).
    fit : TrendFit
        The trend (:func:`tyredamp.campaign.tracking.fit_trend`), with ``predict``.
    condition, quantity : str
        Column names of the x and y values.
    ax : matplotlib Axes, optional
        Axes to draw on (default: a new :class:`matplotlib.figure.Figure`).
    label : str, optional
        Legend label of the series.
    color : optional
        Matplotlib colour of the series.
    scale : float
        Factor on the y values (e.g. 100 for percent).

    Returns
    -------
    dict
        ``ax``, ``points`` (the errorbar container), ``line`` and ``band``.
    """
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(5, 3.4)).add_subplot()
    std_key = "frequency_std_hz" if quantity == "frequency_hz" else f"{quantity}_std"
    x = np.array([float(p[condition]) for p in points])
    y = np.array([float(p[quantity]) for p in points]) * scale
    s = np.array([np.nan if p.get(std_key) is None else float(p[std_key]) for p in points]) * scale
    eb = ax.errorbar(
        x,
        y,
        yerr=np.where(np.isfinite(s), s, 0.0),
        fmt="o",
        ms=4,
        color=color,
        label=label,
        capsize=2,
    )
    col = eb[0].get_color()
    xf = np.linspace(x.min(), x.max(), 100)
    yf, sf = fit.predict(xf)
    (line,) = ax.plot(xf, yf * scale, "-", color=col, lw=1.2)
    band = ax.fill_between(
        xf, (yf - 1.96 * sf) * scale, (yf + 1.96 * sf) * scale, color=col, alpha=0.2, lw=0
    )
    ax.set_xlabel(condition)
    ax.set_ylabel(quantity)
    return {"ax": ax, "points": eb, "line": line, "band": band}
