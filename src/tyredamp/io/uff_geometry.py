"""Test geometry from UFF: nodes (15, 2411), trace lines (82), elements (2412), systems (18, 2420).

Node coordinates are given in their definition coordinate system (record
field ``def_cs``); systems come from data set 2420 (a 4 x 3 matrix per system:
rows 1-3 the unit vectors of the local x, y, z axes in the global frame,
row 4 the origin) or 18 (origin, a point on the +x axis and a point in the
+xz plane, in a reference system resolved recursively). System 0, and any
``def_cs`` not defined in the file when it is 0 or 1, is the global
Cartesian frame. Types: 0 Cartesian (x, y, z), 1 cylindrical (r, theta in
degrees, z), 2 spherical (r, theta, phi in degrees; theta from +z). The
displacement system ``disp_cs`` of a node sets its measuring axes
(:attr:`~tyredamp.geometry.Geometry.directions`; for cylindrical and
spherical systems the local radial, tangential, axial axes at the node).
Units: data set 164's length factor (file units per metre, as the standard
says: divide by it for SI); without 164, metres are assumed. Trace lines
(82) are split at node 0 ("move to") into polylines; each element of data
set 2412 (triangles, quadrilaterals, beams) adds its outline as a closed
polyline. The same file may hold mode shapes (data sets 55) beside the
geometry, as some modal programs export them: :func:`read_uff_geometry`
reads the geometry part, :func:`uff_geometry_or_none` only when there is one.
"""

from __future__ import annotations

import gc
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pyuff
from numpy.typing import NDArray

from ..exceptions import FileFormatError
from ..geometry import Geometry
from ._common import check_input_file, uff_set_types
from ._guard import guarded_read
from ._uff_load import check_delimiters

__all__ = ["read_uff_geometry", "uff_geometry_or_none", "uff_has_geometry"]

_WANTED = (15, 2411, 82, 2412, 18, 2420, 164)


class _CS:
    def __init__(self, kind: int, rot: NDArray[np.float64], origin: NDArray[np.float64]):
        self.kind, self.rot, self.origin = kind, rot, origin  # rot rows: local axes in global

    def to_global(
        self, a: float, b: float, c: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Global position and local measuring axes (rows) of a point given in this system."""
        if self.kind == 1:  # cylindrical r, theta (deg), z
            t = np.radians(b)
            local = np.array([a * np.cos(t), a * np.sin(t), c])
            axes = np.array(
                [[np.cos(t), np.sin(t), 0.0], [-np.sin(t), np.cos(t), 0.0], [0, 0, 1.0]]
            )
        elif self.kind == 2:  # spherical r, theta (deg from +z), phi (deg)
            th, ph = np.radians(b), np.radians(c)
            local = a * np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
            er = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
            et = np.array([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)])
            ep = np.array([-np.sin(ph), np.cos(ph), 0.0])
            axes = np.array([er, et, ep])
        else:
            local = np.array([a, b, c])
            axes = np.eye(3)
        return self.origin + local @ self.rot, axes @ self.rot


def _load(p: Any) -> list[dict[str, Any]]:
    check_delimiters(p, p.read_bytes())
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ResourceWarning)
            uff = pyuff.UFF(str(p))
            types = list(uff.get_set_types())
            idx = [k for k, t in enumerate(types) if t in _WANTED]
            try:
                sets = uff.read_sets(idx) if idx else []
            except Exception:  # an element kind pyuff cannot parse: the geometry without it
                idx = [k for k in idx if types[k] != 2412]
                if len(idx) == len([k for k, t in enumerate(types) if t in _WANTED]):
                    raise
                sets = uff.read_sets(idx) if idx else []
            gc.collect()
    except Exception as exc:  # pyuff raises bare Exception, and others on garbage
        raise FileFormatError(f"{p}: not a readable UFF file ({exc})") from None
    if isinstance(sets, dict):
        sets = [sets]
    if not any(int(s.get("type", 0)) in (15, 2411) for s in sets):
        raise FileFormatError(f"{p}: no node data set (15 or 2411) in the UFF file")
    return list(sets)


def uff_has_geometry(path: str | os.PathLike[str]) -> bool:
    """True when the UFF file holds nodes (15 or 2411) and no data set 58 or 55."""
    types = uff_set_types(path)
    return bool(types & {15, 2411}) and not types & {55, 58}


def uff_geometry_or_none(path: str | os.PathLike[str]) -> Geometry | None:
    """The geometry of a UFF file that holds nodes (15 or 2411), else None.

    For a file of mode shapes (data sets 55) that carries its geometry, or a
    geometry file; errors in the geometry records raise as in
    :func:`read_uff_geometry`.
    """
    if not uff_set_types(path) & {15, 2411}:
        return None
    return read_uff_geometry(path)


def _element_lines(p: Any, s: dict[str, Any]) -> list[list[int]]:
    """Closed outlines of the elements of one data set 2412 (pyuff's layout)."""
    out: list[list[int]] = []
    for key, val in s.items():
        if key == "type" or not isinstance(val, dict) or "nodes_nums" not in val:
            continue
        try:
            for nn in val["nodes_nums"]:
                ring = [int(v) for v in np.atleast_1d(np.asarray(nn, dtype=float))]
                if len(ring) > 2:
                    ring.append(ring[0])
                if len(ring) > 1:
                    out.append(ring)
        except (TypeError, ValueError) as exc:
            raise FileFormatError(f"{p}: malformed element data set 2412 ({exc})") from None
    return out


def _systems(p: Any, sets: list[dict[str, Any]]) -> dict[int, _CS]:
    cs: dict[int, _CS] = {0: _CS(0, np.eye(3), np.zeros(3))}
    pending: list[
        tuple[int, int, int, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    ] = []
    for s in sets:
        t = int(s.get("type", 0))
        try:
            if t == 2420:
                for lab, kind, mat in zip(
                    s["CS_sys_labels"], s["CS_types"], s["CS_matrices"], strict=True
                ):
                    m = np.asarray(mat, dtype=float).reshape(4, 3)
                    if not np.all(np.isfinite(m)):
                        raise ValueError("non-finite matrix")
                    cs[int(lab)] = _CS(int(kind), m[:3], m[3])
            elif t == 18:
                for k in range(len(np.atleast_1d(s["cs_num"]))):
                    pending.append(
                        (
                            int(np.atleast_1d(s["cs_num"])[k]),
                            int(np.atleast_1d(s["cs_type"])[k]),
                            int(np.atleast_1d(s["ref_cs_num"])[k]),
                            np.atleast_2d(s["ref_o"])[k].astype(float),
                            np.atleast_2d(s["x_point"])[k].astype(float),
                            np.atleast_2d(s["xz_point"])[k].astype(float),
                        )
                    )
        except (KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(
                f"{p}: malformed coordinate system data set {t} ({exc})"
            ) from None
    for _ in range(len(pending) + 1):
        left = []
        for num, kind, ref, o, xp, xzp in pending:
            if ref not in cs:
                left.append((num, kind, ref, o, xp, xzp))
                continue
            base = cs[ref]
            og, _ = base.to_global(*o)
            xg, _ = base.to_global(*xp)
            xzg, _ = base.to_global(*xzp)
            ex = xg - og
            ez = np.cross(ex, xzg - og)
            if np.linalg.norm(ex) == 0 or np.linalg.norm(ez) == 0:
                raise FileFormatError(f"{p}: coordinate system {num} has degenerate axes")
            ex, ez = ex / np.linalg.norm(ex), ez / np.linalg.norm(ez)
            cs[num] = _CS(kind, np.array([ex, np.cross(ez, ex), ez]), og)
        if not left:
            break
        pending = left
    else:  # pragma: no cover - the loop always breaks or leaves pending
        pass
    if pending and any(ref not in cs for _, _, ref, *_ in pending):
        raise FileFormatError(f"{p}: coordinate system references form a cycle or are missing")
    return cs


def read_uff_geometry(path: str | os.PathLike[str]) -> Geometry:
    """Read nodes, coordinate systems, trace lines and units from a UFF file.

    Raises
    ------
    FileFormatError
        No node data set, a node in an undefined coordinate system, malformed
        or non-finite records, duplicate nodes, trace lines through unknown
        nodes.
    """
    with guarded_read(path):
        return _read_geometry(check_input_file(path))


def _read_geometry(p: Path) -> Geometry:
    sets = _load(p)
    cs = _systems(p, sets)
    length = 1.0
    for s in sets:
        if int(s.get("type", 0)) == 164:
            length = float(s.get("length", 1.0) or 1.0)
            if not np.isfinite(length) or length <= 0:
                raise FileFormatError(f"{p}: data set 164 length factor {length} is not positive")
    nodes: list[int] = []
    seen: set[int] = set()
    xyz: list[NDArray[np.float64]] = []
    axes: list[NDArray[np.float64]] = []
    for s in sets:
        if int(s.get("type", 0)) not in (15, 2411):
            continue
        try:
            nums = np.atleast_1d(np.asarray(s["node_nums"], dtype=float)).astype(int)
            x = np.atleast_1d(np.asarray(s["x"], dtype=float))
            y = np.atleast_1d(np.asarray(s["y"], dtype=float))
            z = np.atleast_1d(np.asarray(s["z"], dtype=float))
            dcs = np.atleast_1d(np.asarray(s.get("def_cs", np.zeros(nums.size)), dtype=float))
            pcs = np.atleast_1d(np.asarray(s.get("disp_cs", np.zeros(nums.size)), dtype=float))
        except (KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(f"{p}: malformed node data set ({exc})") from None
        if not (nums.size == x.size == y.size == z.size):
            raise FileFormatError(f"{p}: node data set with unequal record counts")
        for k in range(nums.size):
            d, q = int(dcs[k]) if k < dcs.size else 0, int(pcs[k]) if k < pcs.size else 0
            for c in (d, q):
                if c not in cs and c not in (0, 1):
                    raise FileFormatError(
                        f"{p}: node {nums[k]} refers to coordinate system {c}, not in the file"
                    )
            pos, _ = cs.get(d, cs[0]).to_global(x[k], y[k], z[k])
            disp = cs.get(q, cs[0])
            # measuring axes of the displacement system at the node's position
            if disp.kind in (1, 2):
                rel = (pos - disp.origin) @ disp.rot.T
                r = float(np.linalg.norm(rel))
                if disp.kind == 1:
                    theta = np.degrees(np.arctan2(rel[1], rel[0]))
                    _, ax = disp.to_global(np.hypot(rel[0], rel[1]), theta, rel[2])
                else:
                    th = np.degrees(np.arccos(rel[2] / r)) if r > 0 else 0.0
                    ph = np.degrees(np.arctan2(rel[1], rel[0]))
                    _, ax = disp.to_global(r, th, ph)
            else:
                ax = disp.rot
            if int(nums[k]) in seen:
                raise FileFormatError(f"{p}: node {int(nums[k])} is defined more than once")
            seen.add(int(nums[k]))
            nodes.append(int(nums[k]))
            xyz.append(pos / length)
            axes.append(ax)
    lines: list[list[int]] = []
    for s in sets:
        if int(s.get("type", 0)) == 2412:  # outlines through nodes the file does not give
            known = set(nodes)  # (finite-element nodes not exported) are left out
            lines += [e for e in _element_lines(p, s) if known.issuperset(e)]
        if int(s.get("type", 0)) != 82:
            continue
        try:
            seq = [int(v) for v in np.atleast_1d(np.asarray(s["nodes"], dtype=float))]
        except (KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(f"{p}: malformed trace line data set 82 ({exc})") from None
        cur: list[int] = []
        for v in seq:
            if v == 0:
                if len(cur) > 1:
                    lines.append(cur)
                cur = []
            else:
                cur.append(v)
        if len(cur) > 1:
            lines.append(cur)
    try:
        return Geometry(nodes, np.array(xyz), lines, np.array(axes))
    except (ValueError, TypeError) as exc:
        raise FileFormatError(f"{p}: {exc}") from None
