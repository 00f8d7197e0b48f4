"""Modal figures: discrepancy against frequency (paper Fig. 4), mode shapes on the tyre."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..frf import FRF
from ..modal.model import ModalModel
from ._axes import single_axes

__all__ = ["plot_discrepancy", "plot_mode_shapes_ring"]


def plot_discrepancy(
    measured: FRF,
    fitted: Mapping[str, FRF],
    rmsd: Mapping[str, float] | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Discrepancy ``sqrt(sum_jk |H_th - H_exp|^2)`` per line for each fit (paper Fig. 4).

    Parameters
    ----------
    measured : FRF
        The data.
    fitted : mapping of label to FRF
        Synthesised FRFs on the same lines and channels.
    rmsd : mapping of label to float, optional
        RMSD values (spec eq. [19]) shown in the legend.
    """
    ax = single_axes(ax, (7.0, 3.0))
    for i, (name, fr) in enumerate(fitted.items()):
        d = np.sqrt(np.sum(np.abs(fr.to(measured.kind).H - measured.H) ** 2, axis=(0, 1)))
        lab = name if rmsd is None or name not in rmsd else f"{name} (RMSD {rmsd[name]:.3g})"
        ax.semilogy(measured.frequency, d, label=lab, color=f"C{i}")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"|H_fit - H_meas| ({measured.unit})")
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(fontsize="small")
    return ax


def plot_mode_shapes_ring(
    model: ModalModel,
    modes: Sequence[int] | None = None,
    axes: Sequence[Axes] | None = None,
    scale: float = 0.3,
    **line_kw: Any,
) -> list[Axes]:
    """Radial mode shapes drawn around the tyre circumference (polar axes).

    The real part of the second-order shape ``Re Psi^`` (spec step 7) at the
    measured angles (``Channel.angle_deg``) is drawn as a deformation of the
    unit circle, normalised to the largest entry; the imaginary part dashed.
    Outputs without an angle are placed equally spaced. The wave-number label
    of each mode (``model.meta["wave_number_label"]``, written by ``tyredamp
    modal``; :func:`tyredamp.tyremodel.wave_number_analysis`) is added to its
    title when present.
    """
    idx = list(range(model.n_modes)) if modes is None else list(modes)
    ang = np.array(
        [
            c.angle_deg if c.angle_deg is not None else 360.0 * i / len(model.outputs)
            for i, c in enumerate(model.outputs)
        ]
    )
    order = np.argsort(ang)
    th = np.radians(np.append(ang[order], ang[order][0] + 360.0))
    if axes is None:
        ncol = min(3, max(1, len(idx)))
        nrow = int(np.ceil(len(idx) / ncol))
        fig = Figure(figsize=(3.0 * ncol, 3.0 * nrow), layout="constrained")
        axs = fig.subplots(nrow, ncol, subplot_kw={"projection": "polar"}, squeeze=False).ravel()
        for extra in axs[len(idx) :]:
            extra.set_visible(False)
        ax_list = list(axs[: len(idx)])
    else:
        ax_list = list(axes)
    shapes = model.second_order_shapes()
    labels = model.meta.get("wave_number_label")
    if not isinstance(labels, list) or len(labels) != model.n_modes:
        labels = None
    for ax, n in zip(ax_list, idx, strict=False):
        s = shapes[order, n]
        s = s / np.max(np.abs(s))
        re = np.append(s.real, s.real[0])
        im = np.append(s.imag, s.imag[0])
        ax.plot(th, np.ones_like(th), color="0.7", lw=0.8)
        ax.plot(th, 1 + scale * re, marker="o", ms=3, **line_kw)
        ax.plot(th, 1 + scale * im, ls="--", lw=0.8, **line_kw)
        ax.set_ylim(0, 1 + 1.5 * scale)
        ax.set_yticks([])
        lab = labels[n] if labels is not None else ""
        ax.set_title(
            f"{model.frequency_hz[n]:.1f} Hz, zeta {100 * model.damping_ratio[n]:.2f} %"
            + (f"\n{lab}" if lab else ""),
            fontsize="small",
        )
    return ax_list
