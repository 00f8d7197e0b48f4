"""Mode shapes drawn the way the data call for: on the geometry, around a ring, or per point.

:func:`plot_mode_shapes` decides from the data, not from a flag: the shapes
are first taken where they are (at the inputs of a roving-hammer test,
:func:`tyredamp.damping.modeset.at_shape_points`); then

* a geometry whose nodes carry the shapes: the deformed wireframe
  (:func:`~tyredamp.plot.plot_mode_shapes_geometry`);
* points evenly spaced on a circle (a tyre's tread: the channels' angles, or
  the geometry's coordinates; :func:`tyredamp.tyremodel.layout.ring_angles`):
  the polar ring view (:func:`~tyredamp.plot.plot_mode_shapes_ring`; of the
  shapes as measured when every node has one channel, as tyredamp's tyre
  data; of the radial part of each node's motion when a geometry gives
  several directions per node, :func:`tyredamp.tyremodel.layout.radial_ring_model`),
  as well as the wireframe when there is a geometry;
* anything else: the shape against the point (:func:`plot_mode_shapes_points`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Literal

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..damping.modeset import at_shape_points
from ..exceptions import InputError
from ..frf import Channel
from ..geometry import Geometry
from ..modal.model import ModalModel
from ..tyremodel.layout import radial_ring_model, ring_angles
from .geometry import plot_mode_shapes_geometry
from .modal import plot_mode_shapes_ring

__all__ = ["ShapeView", "plot_mode_shapes", "plot_mode_shapes_points", "shape_views"]

ShapeView = Literal["geometry", "ring", "points"]


def plot_mode_shapes_points(
    model: ModalModel,
    modes: Sequence[int] | None = None,
    axes: Sequence[Axes] | None = None,
) -> list[Axes]:
    """Each mode's shape against the point (outputs in their order), one panel per mode.

    The second-order shape ``Psi^`` (spec step 7) normalised to its largest
    entry: real part solid with markers, imaginary part dashed; the points
    are labelled on the horizontal axis. For shapes at the inputs call with
    :func:`tyredamp.damping.modeset.at_shape_points` first (as
    :func:`plot_mode_shapes` does).
    """
    idx = list(range(model.n_modes)) if modes is None else list(modes)
    if axes is None:
        ncol = min(3, max(1, len(idx)))
        nrow = int(np.ceil(len(idx) / ncol))
        fig = Figure(figsize=(3.4 * ncol, 2.6 * nrow), layout="constrained")
        axs = fig.subplots(nrow, ncol, squeeze=False).ravel()
        for extra in axs[len(idx) :]:
            extra.set_visible(False)
        ax_list = list(axs[: len(idx)])
    else:
        ax_list = list(axes)
    shapes = model.second_order_shapes()
    x = np.arange(len(model.outputs))
    labels = [c.label for c in model.outputs]
    step = max(1, len(labels) // 12)
    for ax, n in zip(ax_list, idx, strict=False):
        s = shapes[:, n]
        s = s / (np.max(np.abs(s)) or 1.0)
        ax.axhline(0.0, color="0.7", lw=0.8)
        ax.plot(x, s.real, marker="o", ms=3, color="C0", label="real")
        ax.plot(x, s.imag, ls="--", lw=0.8, color="C1", label="imaginary")
        ax.set_xticks(x[::step])
        ax.set_xticklabels(
            labels[::step], rotation=90 if len(labels) > 6 else 0, fontsize="x-small"
        )
        ax.set_ylim(-1.15, 1.15)
        ax.set_title(
            f"{model.frequency_hz[n]:.1f} Hz, zeta {100 * model.damping_ratio[n]:.2f} %",
            fontsize="small",
        )
    if ax_list:
        ax_list[0].legend(fontsize="x-small", loc="best")
    return ax_list


def shape_views(model: ModalModel, geometry: Geometry | None = None) -> list[ShapeView]:
    """The views :func:`plot_mode_shapes` draws for ``model`` (and ``geometry``), in order."""
    pts = at_shape_points(model)
    geo = geometry if geometry is not None and _on_geometry(pts, geometry) else None
    views: list[ShapeView] = []
    if geo is not None:
        views.append("geometry")
    if _ring(pts, geo) is not None:
        views.append("ring")
    if not views:
        views.append("points")
    return views


def _on_geometry(model: ModalModel, geometry: Geometry) -> bool:
    return any(c.node in geometry.nodes for c in model.outputs)


def _ring(model: ModalModel, geometry: Geometry | None) -> tuple[Channel, ...] | None:
    """The outputs with their ring angles when they are a ring, else None."""
    ang = ring_angles(model.outputs, geometry)
    if ang is None:
        return None
    return tuple(
        Channel(c.node, c.direction, float(a), c.name)
        for c, a in zip(model.outputs, ang, strict=True)
    )


def _ring_model(model: ModalModel, geometry: Geometry | None) -> ModalModel | None:
    """The shapes around the ring: one channel per node as measured (tyredamp's tyre data),
    several (X, Y, Z) as the radial part of each node's motion; None without radial motion."""
    geo = geometry if geometry is not None and _on_geometry(model, geometry) else None
    nodes = [c.node for c in model.outputs]
    if geo is None or len(set(nodes)) == len(nodes):
        ring = _ring(model, geo)
        return None if ring is None else replace(model, outputs=ring)
    try:
        return radial_ring_model(model, geo)
    except InputError:
        return None


def plot_mode_shapes(
    model: ModalModel, geometry: Geometry | None = None, modes: Sequence[int] | None = None
) -> list[tuple[ShapeView, list[Axes]]]:
    """Draw the mode shapes in every view the data call for (module docstring).

    Parameters
    ----------
    model : ModalModel
        The modes; their shapes are taken where they are (outputs, or the
        inputs of a roving-hammer test).
    geometry : Geometry, optional
        Node coordinates and trace lines (UFF 15/2411, 82, 2412).
    modes : sequence of int, optional
        Which modes (0-based); default all.

    Returns
    -------
    list of (view, axes)
        One entry per figure: ``"geometry"``, ``"ring"`` or ``"points"`` and
        the axes drawn (each list on one new figure).
    """
    pts = at_shape_points(model)
    out: list[tuple[ShapeView, list[Axes]]] = []
    for view in shape_views(model, geometry):
        if view == "geometry":
            assert geometry is not None
            out.append((view, plot_mode_shapes_geometry(pts, geometry, modes)))
        elif view == "ring":
            on_ring = _ring_model(pts, geometry)
            if on_ring is not None:
                out.append((view, plot_mode_shapes_ring(on_ring, modes)))
        else:
            out.append((view, plot_mode_shapes_points(pts, modes)))
    return out
