"""Stabilisation diagram of an output-only identification (:mod:`tyredamp.oma`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes

from ._axes import single_axes

__all__ = ["plot_oma_stabilisation"]


def plot_oma_stabilisation(res: Any, ax: Axes | None = None) -> Axes:
    """Pole frequencies against model order, with the selected modes.

    Grey dots: admissible poles; green: stable against the previous order
    (frequency 1 %, damping 5 %, MAC 0.98); blue circles: poles of the
    selected clusters; vertical lines: the modes kept, red dashed lines the
    harmonics kept out.

    Parameters
    ----------
    res : OMAResult
        From :func:`tyredamp.oma.oma`.
    ax : Axes, optional

    Returns
    -------
    Axes
    """
    ax = single_axes(ax, (7.0, 4.5))
    op, st = res.poleset, res.stab
    f = op.frequency_hz
    a = st.admissible
    ax.scatter(f[a & ~st.stable], op.order[a & ~st.stable], s=5, color="0.6", label="admissible")
    ax.scatter(f[st.stable], op.order[st.stable], s=10, color="C2", marker="d", label="stable")
    for j, fr in enumerate(np.asarray(res.frequency_hz)):
        ax.axvline(fr, color="C0", lw=0.8, label="mode" if j == 0 else None)
    for j, h in enumerate(res.harmonics):
        ax.axvline(
            h["frequency_hz"], color="C3", ls="--", lw=0.8, label="harmonic" if j == 0 else None
        )
    ax.set_xlim(*res.band_hz)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model order")
    ax.legend(loc="upper right", fontsize="small")
    return ax
