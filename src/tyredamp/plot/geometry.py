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

__all__ = ["geometry_view", "mode_displacements", "plot_mode_shapes_geometry"]

#: Third principal extent (relative to the first) above which a structure is drawn in 3-D.
_FLAT = 0.1


def mode_displacements(model: ModalModel, geometry: Geometry) -> NDArray[np.complex128]:
    """Complex displacement vector of every geometry node in every mode.

    Each output channel adds its second-order shape entry along its measuring
    direction (:meth:`Geometry.direction_vectors`); nodes without a channel do
    not move, and channels at nodes not in the geometry are left out. Shape
    (n_modes, n_nodes, 3).

    Raises
    ------
    InputError
        No translational output at a node of the geometry.
    """
    out = np.zeros((model.n_modes, geometry.n_nodes, 3), dtype=complex)
    known = set(geometry.nodes)
    rows = [
        i for i, c in enumerate(model.outputs) if abs(c.direction) in (1, 2, 3) and c.node in known
    ]
    if not rows:
        raise InputError(
            "model: no translational output at a node of the geometry to draw on it "
            "(the shapes' node numbers are not those of the geometry)"
        )
    chans = [model.outputs[i] for i in rows]
    vec = geometry.direction_vectors(chans)
    shapes = model.second_order_shapes()  # (n_out, m)
    for k, (i, c) in enumerate(zip(rows, chans, strict=True)):
        out[:, geometry.index(c.node), :] += shapes[i][:, None] * vec[k][None, :]
    return out


def geometry_view(
    geometry: Geometry, displacements: NDArray[np.complex128] | None = None
) -> tuple[int, NDArray[np.float64]]:
    """The view that shows the structure and its motion: ``(2, basis)`` or ``(3, eye)``.

    The principal axes of the node coordinates together with the (real)
    displacements, each mode scaled to the size of the structure: when the
    third principal extent is below a tenth of the first, the plane of the
    first two (a flat structure moving in its plane, or a beam with the
    plane of its bending) shows everything; otherwise the view is 3-D.
    ``basis`` has shape (3, 2) for a plane (its first column along the
    structure's longer extent) and is the identity for 3-D.
    """
    xyz = geometry.coordinates
    c0 = xyz.mean(axis=0)
    cloud = [xyz - c0]
    size = float(np.ptp(xyz, axis=0).max()) or 1.0
    if displacements is not None:
        for d in displacements.real:
            peak = float(np.max(np.linalg.norm(d, axis=1)))
            if peak > 0:
                cloud.append(size * d / peak)
    pts = np.vstack(cloud)
    _, sv, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
    if sv.size >= 3 and sv[2] > _FLAT * sv[0]:
        return 3, np.eye(3)
    basis = vt[:2].T
    ext = np.ptp((xyz - c0) @ basis, axis=0)
    if ext[1] > ext[0]:  # the structure's longer side across the page
        basis = basis[:, ::-1]
    return 2, basis


def plot_mode_shapes_geometry(
    model: ModalModel,
    geometry: Geometry,
    modes: Sequence[int] | None = None,
    axes: Sequence[Axes] | None = None,
    scale: float = 0.15,
) -> list[Axes]:
    """Each mode as a deformed wireframe over the undeformed one.

    The view is decided from the data (:func:`geometry_view`): a plane
    showing the structure and its motion (a ring face on, a beam with its
    bending), or 3-D axes for a structure that needs them. The real part of
    the displacement (:func:`mode_displacements`), normalised to its largest
    node, is drawn at ``scale`` times the size of the geometry; trace lines
    and element outlines join the nodes (the nodes alone when the geometry
    has none). Given ``axes`` must be 3-D axes when the view is 3-D.
    """
    idx = list(range(model.n_modes)) if modes is None else list(modes)
    disp = mode_displacements(model, geometry)
    dim, basis = geometry_view(geometry, disp[idx])
    xyz = geometry.coordinates
    c0 = xyz.mean(axis=0)
    size = float(np.ptp((xyz - c0) @ basis, axis=0).max()) or 1.0
    if axes is None:
        ncol = min(3, max(1, len(idx)))
        nrow = int(np.ceil(len(idx) / ncol))
        ext = np.ptp((xyz - c0) @ basis, axis=0)
        # a slender structure (a beam seen from the side) gets flat panels
        aspect = 1.0 if dim == 3 else float(np.clip((ext[1] + 2 * scale * size) / size, 0.3, 1.0))
        fig = Figure(figsize=(3.4 * ncol, (3.0 * aspect + 0.5) * nrow), layout="constrained")
        kw3: dict[str, Any] = {"projection": "3d"} if dim == 3 else {}
        ax_list = [fig.add_subplot(nrow, ncol, k + 1, **kw3) for k in range(len(idx))]
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
        for line in lines:
            rows = [geometry.index(v) for v in line]
            ax.plot(*p0[rows].T, color="0.75", **kw)
            ax.plot(*p1[rows].T, color="C0", **kw)
        ax.plot(*p0.T, ".", color="0.6", ms=3)
        ax.plot(*p1.T, "o", color="C0", ms=3)
        if dim == 2:
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        else:
            lo, hi = p0.min(axis=0), p0.max(axis=0)
            ax.set_box_aspect(tuple(np.maximum(hi - lo, 0.05 * size)))
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_zticks([])
        ax.set_title(
            f"{model.frequency_hz[n]:.1f} Hz, zeta {100 * model.damping_ratio[n]:.2f} %",
            fontsize="small",
        )
    return ax_list
