"""Mode shapes drawn on the test geometry: deformed wireframe over the trace lines."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ..exceptions import InputError
from ..geometry import Geometry
from ..modal.model import ModalModel

__all__ = ["mode_displacements", "plot_mode_shapes_geometry"]


def mode_displacements(model: ModalModel, geometry: Geometry) -> NDArray[np.complex128]:
    """Complex displacement vector of every geometry node in every mode.

    Each output channel adds its second-order shape entry along its measuring
    direction (:meth:`Geometry.direction_vectors`); nodes without a channel do
    not move. Shape (n_modes, n_nodes, 3).
    """
    out = np.zeros((model.n_modes, geometry.n_nodes, 3), dtype=complex)
    chans = [c for c in model.outputs if abs(c.direction) in (1, 2, 3)]
    if not chans:
        raise InputError("model: no translational output channel to draw on the geometry")
    rows = [i for i, c in enumerate(model.outputs) if abs(c.direction) in (1, 2, 3)]
    vec = geometry.direction_vectors(chans)  # raises for a node not in the geometry
    shapes = model.second_order_shapes()  # (n_out, m)
    for k, (i, c) in enumerate(zip(rows, chans, strict=True)):
        out[:, geometry.index(c.node), :] += shapes[i][:, None] * vec[k][None, :]
    return out


def plot_mode_shapes_geometry(
    model: ModalModel,
    geometry: Geometry,
    modes: Sequence[int] | None = None,
    axes: Sequence[Axes] | None = None,
    scale: float = 0.15,
) -> list[Axes]:
    """Each mode as a deformed wireframe over the undeformed one (2-D view).

    The view is the plane of the two largest principal axes of the node
    coordinates (a ring is seen face on). The real part of the displacement
    (:func:`mode_displacements`), normalised to its largest node, is drawn
    at ``scale`` times the size of the geometry; trace lines join the
    nodes (the nodes alone when the file has no trace lines).
    """
    idx = list(range(model.n_modes)) if modes is None else list(modes)
    disp = mode_displacements(model, geometry)
    xyz = geometry.coordinates
    c0 = xyz.mean(axis=0)
    _, _, vt = np.linalg.svd(xyz - c0)
    basis = vt[:2].T  # (3, 2)
    size = float(np.ptp((xyz - c0) @ basis, axis=0).max()) or 1.0
    if axes is None:
        ncol = min(3, max(1, len(idx)))
        nrow = int(np.ceil(len(idx) / ncol))
        fig = Figure(figsize=(3.2 * ncol, 3.2 * nrow), layout="constrained")
        axs = fig.subplots(nrow, ncol, squeeze=False).ravel()
        for extra in axs[len(idx) :]:
            extra.set_visible(False)
        ax_list = list(axs[: len(idx)])
    else:
        ax_list = list(axes)
    lines = geometry.trace_lines
    for ax, n in zip(ax_list, idx, strict=False):
        d = disp[n].real
        peak = float(np.max(np.linalg.norm(d, axis=1))) or 1.0
        moved = xyz + scale * size * d / peak
        p0 = (xyz - c0) @ basis
        p1 = (moved - c0) @ basis
        kw: dict[str, Any] = {"lw": 0.8}
        if lines:
            for line in lines:
                rows = [geometry.index(v) for v in line]
                ax.plot(p0[rows, 0], p0[rows, 1], color="0.75", **kw)
                ax.plot(p1[rows, 0], p1[rows, 1], color="C0", **kw)
        ax.plot(p0[:, 0], p0[:, 1], ".", color="0.6", ms=3)
        ax.plot(p1[:, 0], p1[:, 1], "o", color="C0", ms=3)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(
            f"{model.frequency_hz[n]:.1f} Hz, zeta {100 * model.damping_ratio[n]:.2f} %",
            fontsize="small",
        )
    return ax_list
