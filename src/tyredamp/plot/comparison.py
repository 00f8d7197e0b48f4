"""Measured data against several model predictions, with the truth of a virtual rig.

:func:`plot_lateral_models` draws what the paper's Figures 11-14 show (the
measured lateral FRF with the prediction of every model), for predictions
that are not fits to the drawn data (for example axle-force FRFs predicted
from ground-force fits, Figs. 13 and 14) and with the exact FRF of the
virtual rig beside them. For fits to the drawn data see
:func:`tyredamp.plot.lateral.plot_ranking`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Literal

import numpy as np
from matplotlib.axes import Axes
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ._axes import axes_grid

__all__ = ["MODEL_COLORS", "model_color", "plot_lateral_models"]

Style = Literal["reim", "bode"]

#: One colour per lateral model, shared by every demo figure.
MODEL_COLORS = {
    "classic": "C0",
    "maxwell": "C1",
    "viscoplastic": "C2",
    "hysteretic": "C3",
    "relaxation": "C4",
    "string": "C5",
}


def model_color(name: str, i: int = 0) -> str:
    """Colour of a lateral model by registry name (a free one for other names)."""
    return MODEL_COLORS.get(name, f"C{(i + 6) % 10}")


def plot_lateral_models(
    frequency: ArrayLike,
    measured: ArrayLike,
    predictions: Mapping[str, ArrayLike],
    style: Style = "reim",
    truth: ArrayLike | None = None,
    axes: Sequence[Axes] | None = None,
    unit: str = "m/(s^2 N)",
    title: str | None = None,
) -> list[Axes]:
    """Measured lateral FRF against model predictions (paper Figs. 11-14).

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Hz.
    measured : array_like, complex, shape (n,)
        Measured FRF (accelerance per ground or axle force in the paper).
    predictions : mapping of str to array_like, complex, shape (n,)
        Model name to its FRF on the same lines.
    style : {"reim", "bode"}
        Real and imaginary parts (as Figs. 11, 12) or amplitude and phase
        (as Figs. 13, 14).
    truth : array_like, complex, shape (n,), optional
        Exact (noise-free) FRF of a virtual rig, drawn dotted black.
    axes : sequence of two Axes, optional
        Where to draw; a new figure with two panels side by side otherwise.
    unit : str
        Unit of the FRF for the axis labels.
    title : str, optional
        Put above the first panel.

    Returns
    -------
    list of Axes
        The two panels.
    """
    if style not in ("reim", "bode"):
        raise InputError(f"style: expected 'reim' or 'bode', got {style!r}")
    f = np.asarray(frequency, dtype=float)
    meas = np.asarray(measured, dtype=complex)
    if meas.shape != f.shape:
        raise InputError(f"measured: expected shape {f.shape}, got {meas.shape}")
    ax_list = axes_grid(axes, 2, (9.0, 3.4), columns=True)

    def parts(h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if style == "reim":
            return h.real, h.imag
        return np.abs(h), np.degrees(np.angle(h))

    for ax, y in zip(ax_list, parts(meas), strict=True):
        ax.plot(f, y, ls="none", marker=".", ms=3, color="0.25", label="measured")
    if truth is not None:
        for ax, y in zip(ax_list, parts(np.asarray(truth, dtype=complex)), strict=True):
            ax.plot(f, y, color="k", lw=0.8, ls=":", label="rig truth")
    for i, (name, pred) in enumerate(predictions.items()):
        for ax, y in zip(ax_list, parts(np.asarray(pred, dtype=complex)), strict=True):
            ax.plot(f, y, color=model_color(name, i), lw=1.2, label=name)
    if style == "reim":
        ax_list[0].set_ylabel(f"real part ({unit})")
        ax_list[1].set_ylabel(f"imaginary part ({unit})")
    else:
        ax_list[0].set_ylabel(f"amplitude ratio ({unit})")
        ax_list[1].set_ylabel("phase angle (deg)")
    for ax in ax_list:
        ax.set_xlabel("frequency (Hz)")
        ax.grid(True, alpha=0.3)
    ax_list[0].legend(fontsize="x-small")
    if title:
        ax_list[0].set_title(title, fontsize="small", loc="left")
    return ax_list
