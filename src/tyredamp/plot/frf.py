"""FRF figures: Bode (amplitude and phase) and real/imaginary parts."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..exceptions import InputError
from ..frf import FRF
from ._axes import axes_grid

__all__ = ["plot_frf", "plot_frf_comparison"]

Style = Literal["bode", "reim", "all"]


def _new_axes(n: int, axes: Sequence[Axes] | None) -> list[Axes]:
    return axes_grid(axes, n, (7.0, 2.2 * n))


def plot_frf(
    frf: FRF,
    out: int = 0,
    inp: int = 0,
    style: Style = "bode",
    axes: Sequence[Axes] | None = None,
    label: str | None = None,
    **line_kw: Any,
) -> list[Axes]:
    """Draw one FRF ``H[out, inp]``.

    Parameters
    ----------
    frf : FRF
        Data to draw.
    out, inp : int
        Output and input positions.
    style : {"bode", "reim", "all"}
        ``"bode"``: amplitude (dB re 1 unit) and phase (deg); ``"reim"``: real
        and imaginary parts; ``"all"``: the four panels of the paper's
        Figures 2 and 3 (real, imaginary, amplitude, phase).
    axes : sequence of Axes, optional
        Axes to draw on (2 or 4 by ``style``); new ones on a new figure if
        omitted (the figure is ``axes[0].figure``).
    label : str, optional
        Legend label.

    Returns
    -------
    list of Axes
    """
    h = frf.H[out, inp]
    f = frf.frequency
    panels = {"bode": ["amp", "phase"], "reim": ["re", "im"], "all": ["re", "im", "amp", "phase"]}
    if style not in panels:
        raise InputError(f"style: expected one of {tuple(panels)}, got {style!r}")
    names = panels[style]
    ax_list = _new_axes(len(names), axes)
    lab = label or f"{frf.outputs[out].label}/{frf.inputs[inp].label}"
    for ax, name in zip(ax_list, names, strict=True):
        if name == "amp":
            ax.plot(f, 20 * np.log10(np.maximum(np.abs(h), 1e-300)), label=lab, **line_kw)
            ax.set_ylabel(f"|H| dB re 1 {frf.unit}")
        elif name == "phase":
            ax.plot(f, np.degrees(np.angle(h)), label=lab, **line_kw)
            ax.set_ylabel("phase (deg)")
        elif name == "re":
            ax.plot(f, h.real, label=lab, **line_kw)
            ax.set_ylabel(f"Re H ({frf.unit})")
        else:
            ax.plot(f, h.imag, label=lab, **line_kw)
            ax.set_ylabel(f"Im H ({frf.unit})")
        ax.grid(True, alpha=0.3)
    ax_list[-1].set_xlabel("frequency (Hz)")
    return ax_list


def plot_frf_comparison(
    measured: FRF,
    fitted: dict[str, FRF],
    out: int = 0,
    inp: int = 0,
    style: Style = "all",
    axes: Sequence[Axes] | None = None,
) -> list[Axes]:
    """Measured against one or more fitted FRFs (the paper's Figures 2 and 3).

    ``fitted`` maps a legend label (e.g. ``"real-mode fit"``) to a synthesised
    FRF on the same kind; each is drawn over the measured data.
    """
    ax_list = plot_frf(
        measured, out, inp, style, axes, label="measured", color="0.3", lw=0, marker=".", ms=2
    )
    for i, (name, fr) in enumerate(fitted.items()):
        plot_frf(fr.to(measured.kind), out, inp, style, ax_list, label=name, color=f"C{i}")
    ax_list[0].legend(fontsize="small")
    return ax_list


def figure_of(ax: Axes) -> Figure:
    """The figure that holds ``ax``."""
    fig = ax.figure
    assert isinstance(fig, Figure)
    return fig
