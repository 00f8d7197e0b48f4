"""Tyre-model figures: measured against updated-ring frequencies per wave number and pressure."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..tyremodel.ring import RingFit

__all__ = ["plot_ring_frequencies"]


def plot_ring_frequencies(fit: RingFit, ax: Axes | None = None, **line_kw: Any) -> Axes:
    """Identified frequencies (markers, 1-sigma bars) and the updated ring (lines) against n.

    One colour per test pressure. The lines are the ring's member with an
    antinode at the drive point (with the attachment mass, as measured on a
    perfect ring); hollow markers are the members the model places elsewhere
    (``"sin"``), filled ones the driven (``"cos"``) or single members.

    Parameters
    ----------
    fit : RingFit
        From :func:`tyredamp.tyremodel.fit_ring`.
    ax : Axes, optional
        Where to draw; a new figure otherwise.
    **line_kw
        Passed to the model lines.

    Returns
    -------
    Axes
    """
    if ax is None:
        ax = Figure(figsize=(6.5, 4.0), layout="constrained").subplots()
    n_all = np.array([o.n for o in fit.observations])
    n_line = np.arange(1, int(n_all.max()) + 1)
    for i, p in enumerate(fit.pressures):
        color = f"C{i}"
        sel = [k for k, o in enumerate(fit.observations) if o.pressure == p]
        for k in sel:
            o = fit.observations[k]
            err = o.frequency_std if o.frequency_std is not None else 0.0
            ax.errorbar(
                o.n,
                o.frequency_hz,
                yerr=err,
                marker="o",
                ms=5,
                color=color,
                mfc="none" if o.member == "sin" else color,
                ls="none",
            )
        f_mod, _ = fit.predict(p, n_line, drive_phi2=fit.drive_member_phi2(n_line))
        ax.plot(n_line, f_mod, color=color, label=f"{p / 1e5:g} bar", **line_kw)
    ax.set_xlabel("circumferential wave number n")
    ax.set_ylabel("natural frequency (Hz)")
    ax.set_xticks(n_line)
    ax.grid(True, alpha=0.3)
    ax.legend(title="updated ring (lines), identified (markers)", fontsize="small")
    return ax
