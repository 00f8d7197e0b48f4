"""Test geometry: node coordinates and trace lines, attached to measured channels."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_finite
from .exceptions import InputError, ShapeError
from .frf import Channel

__all__ = ["Geometry"]

#: Unit vector of each UFF translation direction code (rotations have none).
_AXES = {1: 0, 2: 1, 3: 2}


@dataclass(frozen=True, eq=False)
class Geometry:
    """Node coordinates (global Cartesian, m) and trace lines of a test.

    Parameters
    ----------
    nodes : sequence of int
        Node numbers (unique).
    coordinates : array_like, shape (n_nodes, 3)
        Global x, y, z of every node in m.
    trace_lines : sequence of sequence of int, optional
        Polylines through node numbers (drawn as a wireframe).
    directions : array_like, shape (n_nodes, 3, 3), optional
        Unit vectors of each node's displacement x, y, z axes in the global
        frame (rows); default the global axes. A channel's direction code
        1/2/3 (+-) picks a row.
    """

    nodes: tuple[int, ...]
    coordinates: NDArray[np.float64]
    trace_lines: tuple[tuple[int, ...], ...] = ()
    directions: NDArray[np.float64] | None = None

    def __init__(
        self,
        nodes: Sequence[int],
        coordinates: ArrayLike,
        trace_lines: Sequence[Sequence[int]] = (),
        directions: ArrayLike | None = None,
    ) -> None:
        nd = tuple(int(n) for n in nodes)
        if not nd:
            raise ShapeError("nodes: expected at least one node")
        if len(set(nd)) != len(nd):
            raise InputError("nodes: node numbers must be unique")
        xyz = as_finite(coordinates, "coordinates", ndim=2)
        if xyz.shape != (len(nd), 3):
            raise ShapeError(f"coordinates: expected shape ({len(nd)}, 3), got {xyz.shape}")
        known = set(nd)
        lines = tuple(tuple(int(n) for n in line) for line in trace_lines)
        for line in lines:
            missing = [n for n in line if n not in known]
            if missing:
                raise InputError(f"trace_lines: node {missing[0]} is not a node of the geometry")
        d = np.tile(np.eye(3), (len(nd), 1, 1))
        if directions is not None:
            d = as_finite(directions, "directions")
            if d.shape != (len(nd), 3, 3):
                raise ShapeError(f"directions: expected shape ({len(nd)}, 3, 3), got {d.shape}")
        xyz = xyz.copy()
        d = np.array(d, dtype=float)
        xyz.setflags(write=False)
        d.setflags(write=False)
        object.__setattr__(self, "nodes", nd)
        object.__setattr__(self, "coordinates", xyz)
        object.__setattr__(self, "trace_lines", lines)
        object.__setattr__(self, "directions", d)

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return len(self.nodes)

    def index(self, node: int) -> int:
        """Row of ``node`` in :attr:`coordinates`."""
        try:
            return self.nodes.index(int(node))
        except ValueError:
            raise InputError(f"node {node}: not in the geometry") from None

    def positions(self, channels: Sequence[Channel]) -> NDArray[np.float64]:
        """Coordinates of the channels' nodes, shape (n_channels, 3), m."""
        return np.array([self.coordinates[self.index(c.node)] for c in channels])

    def direction_vectors(self, channels: Sequence[Channel]) -> NDArray[np.float64]:
        """Global unit vector of each channel's measuring direction, shape (n_channels, 3)."""
        assert self.directions is not None
        out = np.zeros((len(channels), 3))
        for k, c in enumerate(channels):
            if abs(c.direction) not in _AXES:
                raise InputError(f"channel {c.label}: direction {c.direction} is not a translation")
            out[k] = (
                np.sign(c.direction) * self.directions[self.index(c.node)][_AXES[abs(c.direction)]]
            )
        return out

    def ring_angles(
        self, channels: Sequence[Channel], rtol: float = 1e-3
    ) -> NDArray[np.float64] | None:
        """Angles (deg, 0-360) of the channels' nodes on a circle, or None if not on one.

        The plane is fitted through the points (SVD), then a circle in it
        (algebraic least squares, Kasa); the points are on a circle when
        their distances from the plane and from the circle are all below
        ``rtol`` times its radius. Angle 0 is the first channel's point,
        increasing with the right-hand rule about the plane normal oriented
        so the second distinct point has a positive angle below 180 deg.
        """
        pts = self.positions(channels)
        uniq = np.unique(pts, axis=0)
        if uniq.shape[0] < 3:
            return None
        c0 = uniq.mean(axis=0)
        _, _, vt = np.linalg.svd(uniq - c0)
        e1, e2, normal = vt[0], vt[1], vt[2]
        uv = (pts - c0) @ np.array([e1, e2]).T
        a = np.column_stack([2 * uv, np.ones(len(uv))])
        sol, *_ = np.linalg.lstsq(a, np.sum(uv**2, axis=1), rcond=None)
        center, r = sol[:2], float(np.sqrt(sol[2] + sol[:2] @ sol[:2]))
        if not np.isfinite(r) or r <= 0:
            return None
        off_plane = np.abs((pts - c0) @ normal)
        off_circle = np.abs(np.linalg.norm(uv - center, axis=1) - r)
        if off_plane.max() > rtol * r or off_circle.max() > rtol * r:
            return None
        ang = np.degrees(np.arctan2(uv[:, 1] - center[1], uv[:, 0] - center[0]))
        rel = (ang - ang[0]) % 360.0
        nz = rel[rel > 1e-9]
        if nz.size and nz[0] > 180.0:
            rel = (-rel) % 360.0
        return rel

    def with_angles(self, channels: Sequence[Channel]) -> tuple[Channel, ...]:
        """The channels with ``angle_deg`` from :meth:`ring_angles` (unchanged if not a ring)."""
        ang = self.ring_angles(channels)
        if ang is None:
            return tuple(channels)
        return tuple(
            Channel(c.node, c.direction, float(a), c.name)
            for c, a in zip(channels, ang, strict=True)
        )
