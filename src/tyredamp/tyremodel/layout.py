"""Is a mode set a tyre's ring? The layout of the shape points, decided from the data.

A tyre test measures points evenly spaced around the tread (tyredamp's own
tyre data: ``Channel.angle_deg`` on every channel); modes from another
program carry node coordinates instead (a UFF geometry). :func:`ring_angles`
gives the circumferential angle of every channel when the points are a ring
(on one circle, within ``rtol`` of its radius, and spread around all of it:
no gap between neighbouring points wider than ``max_gap`` times the even
spacing), else None. A beam, a plate or a car body is not a ring, whatever
its number of points.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..frf import Channel
from ..geometry import Geometry
from ..modal.model import ModalModel

__all__ = ["evenly_around", "radial_ring_model", "ring_angles"]


def evenly_around(angles_deg: Sequence[float] | NDArray[np.float64], max_gap: float = 1.5) -> bool:
    """Whether angles (deg) of three or more distinct points go around the whole circle.

    True when no gap between neighbouring angles (with the wrap at 360 deg)
    is wider than ``max_gap`` times ``360 / n`` (``n`` distinct angles).
    """
    a = np.unique(np.round(np.mod(np.asarray(angles_deg, dtype=float), 360.0), 6))
    if a.size < 3:
        return False
    gaps = np.diff(np.append(a, a[0] + 360.0))
    return bool(gaps.max() <= max_gap * 360.0 / a.size)


def ring_angles(
    channels: Sequence[Channel],
    geometry: Geometry | None = None,
    rtol: float = 0.02,
    max_gap: float = 1.5,
) -> NDArray[np.float64] | None:
    """Angle (deg) of every channel on the ring, or None when the points are not a ring.

    Parameters
    ----------
    channels : sequence of Channel
        The shape points.
    geometry : Geometry, optional
        Node coordinates; used when every channel's node is in it
        (:meth:`Geometry.ring_angles`: a plane and a circle fitted through
        the points, distances within ``rtol`` times the radius). Without a
        geometry the channels' ``angle_deg`` are used when all have one.
    rtol : float
        Tolerance of the circle, relative to its radius.
    max_gap : float
        Widest gap between neighbouring points allowed, in units of the even
        spacing (:func:`evenly_around`).
    """
    chans = list(channels)
    if len(chans) < 3:
        return None
    ang: NDArray[np.float64] | None = None
    if geometry is not None and all(c.node in geometry.nodes for c in chans):
        ang = geometry.ring_angles(chans, rtol=rtol)
    elif all(c.angle_deg is not None for c in chans):
        ang = np.array([float(c.angle_deg) for c in chans])  # type: ignore[arg-type]
    if ang is None or not evenly_around(ang, max_gap):
        return None
    return ang


def radial_ring_model(
    model: ModalModel, geometry: Geometry, drive_points: bool = True
) -> ModalModel:
    """The radial shapes of a ring's modes at its nodes, with their angles.

    Every node of the outputs contributes the component of its displacement
    (the translations X, Y, Z of its channels along the node's measuring
    axes, :meth:`Geometry.direction_vectors`) along the outward radius of
    the fitted circle; the outputs become one radial channel per node
    (direction 1, ``angle_deg`` from :meth:`Geometry.ring_angles`, name
    ``"radial"``). The inputs are mapped the same way when they are nodes of
    the ring; an input that is not is dropped, and all are when
    ``drive_points`` is False (the file did not say where the excitation
    was: its "inputs" are only the measured points).

    Raises
    ------
    InputError
        The output nodes are not a ring (:func:`ring_angles`), or the shapes
        have no radial component there.
    """
    from ..exceptions import InputError

    def radial(chans: Sequence[Channel], psi: NDArray[np.complex128]) -> tuple[list[Channel], Any]:
        nodes = sorted({c.node for c in chans}, key=[c.node for c in chans].index)
        keep = [c for c in chans if abs(c.direction) in (1, 2, 3) and c.node in geometry.nodes]
        rows = [i for i, c in enumerate(chans) if c in keep]
        vec = geometry.direction_vectors(keep) if keep else np.zeros((0, 3))
        pos = geometry.positions([Channel(n) for n in nodes])
        out = np.zeros((len(nodes), psi.shape[1]), complex)
        for k, (i, c) in enumerate(zip(rows, keep, strict=True)):
            j = nodes.index(c.node)
            out[j] += psi[i] * float(vec[k] @ e_r(pos[j]))
        return [Channel(n) for n in nodes], out

    pts = [Channel(n) for n in sorted({c.node for c in model.outputs})]
    ang = ring_angles(pts, geometry)
    if ang is None:
        raise InputError(
            "the nodes of the mode shapes are not a ring (points evenly spaced on one circle, "
            "as around a tyre's tread)"
        )
    xyz = geometry.positions(pts)
    c0 = xyz.mean(axis=0)
    _, _, vt = np.linalg.svd(xyz - c0)
    uv = (xyz - c0) @ vt[:2].T
    a = np.column_stack([2 * uv, np.ones(len(uv))])
    sol, *_ = np.linalg.lstsq(a, np.sum(uv**2, axis=1), rcond=None)
    centre = c0 + sol[:2] @ vt[:2]

    def e_r(p: NDArray[np.float64]) -> NDArray[np.float64]:
        d = p - centre
        d = d - (d @ vt[2]) * vt[2]
        return d / np.linalg.norm(d)

    angle = {c.node: float(a_) for c, a_ in zip(pts, ang, strict=True)}
    outs, psi_out = radial(model.outputs, model.psi_out)
    ins_all = [c for c in model.inputs if c.node in angle and drive_points]
    rows_in = [i for i, c in enumerate(model.inputs) if c.node in angle and drive_points]
    ins, psi_in = radial(ins_all, model.psi_in[rows_in]) if ins_all else ([], np.zeros((0, 0)))
    if not ins:
        psi_in = np.zeros((0, model.n_modes), complex)

    if not np.any(np.abs(psi_out) > 1e-9 * np.max(np.abs(model.psi_out))):
        raise InputError(
            "the mode shapes have no radial motion at the ring's nodes (the measured "
            "directions are all across the radius)"
        )

    def lab(cs: list[Channel]) -> list[Channel]:
        return [Channel(c.node, 1, angle[c.node], "radial") for c in cs]

    return ModalModel(
        model.poles,
        psi_out,
        psi_in,
        mode_kind=model.mode_kind,
        outputs=lab(outs),
        inputs=lab(ins),
        std={k: v for k, v in model.std.items() if k in ("frequency_hz", "damping_ratio")},
        meta={**model.meta, "ring_from_geometry": True},
    )
