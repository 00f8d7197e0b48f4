"""Mode shapes exchanged as Universal File Format data set 55 (data at nodes) via pyuff.

One data set per mode, analysis type 2 (normal mode: frequency, modal mass,
viscous damping ratio, real shape) or 3 (complex eigenvalue: pole, modal A,
modal B, complex shape), 3 translations per node (data characteristic 2),
specific data type 8 (displacement).

Scaling (stated assumptions)
----------------------------
tyredamp's :class:`~tyredamp.modal.ModalModel` keeps shapes ``psi`` in the
scaling of spec eq. [10], ``H(omega) = sum_n psi_n psi_n^T / (i omega - p_n)
+ conj``, i.e. unit modal A.

* Complex modes (type 3) with modal A ``a_n``: the residue is
  ``phi phi^T / a_n`` (first-order, state-space normalisation), so
  ``psi = phi / sqrt(a_n)``. A modal A of 0 (not given) is taken as 1 and
  the modes are marked unscaled (``meta["scaled"] = False``): another
  program writes 0 when it has no scale (no drive point), and the shapes
  then hold no mass information. tyredamp writes ``a_n = 1`` and
  ``b_n = -p_n a_n`` (the identity ``b = -lambda a`` of that normalisation).
* Real modes (type 2) with modal mass ``m_n``, viscous ratio ``zeta_n`` and
  frequency ``f_n`` (undamped, Hz): ``phi phi^T / (m_n (omega_n^2 - omega^2 +
  2 i zeta_n omega_n omega))`` equals the eq. [10] form with the pole
  ``p_n = -zeta_n omega_n + i omega_n sqrt(1 - zeta_n^2)`` and
  ``psi = phi / sqrt(m_n 2 i Omega_n)``, ``Omega_n = Im p_n``. A modal mass of
  0 (not given) is taken as 1 and the modes are marked unscaled, as for
  modal A; without a viscous ratio, a hysteretic loss factor ``eta`` gives
  ``zeta = eta / 2``.

``meta["drive_points_stated"]`` says whether the drive points were known
(given, or stored by tyredamp). ``meta["scaled"]`` is True when every mode
states its modal A (modal mass), False otherwise, with the reason in
``meta["scaling_note"]``.

Channels and drive points: every node and direction (X, Y, Z = UFF codes 1,
2, 3) with a non-zero value in some mode becomes an output. The drive points
(``inputs``) are not part of data set 55: tyredamp writes them as JSON on ID
line 2 (``{"tyredamp_inputs": [[node, dir], ...]}``); a file from another
program without them gets every output as an input (the full receptance
matrix of the modes), unless ``inputs`` is given.

Precision: records 8 and 10 are fixed 13-character fields (``E13.5`` in the
standard, read by pyuff with that width); tyredamp writes ``E13.6``, seven
significant digits (relative rounding <= 5e-7), the most those fields hold.
"""

from __future__ import annotations

import gc
import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pyuff

from ..exceptions import FileFormatError, InputError
from ..frf import Channel
from ._atomic import atomic_path
from ._common import check_input_file, uff_set_types
from ._guard import guarded_read
from ._uff_load import check_delimiters

__all__ = ["read_uff55", "uff_has_modes", "write_uff55"]

_MARK = "tyredamp_inputs"
_NO_A = "modal A not given (0): shapes unscaled, taken as unity modal A"
_NO_MASS = "modal mass not given (0): shapes unscaled, taken as mass-normalised"


def _field(v: float) -> str:
    """One E13.6 field (13 characters); magnitudes below 1e-99 written as 0."""
    v = float(v)
    if not np.isfinite(v):
        raise InputError(f"value {v!r} cannot be written to a UFF 55 field")
    if abs(v) < 1e-99:
        v = 0.0
    s = f"{v:13.6E}"
    if len(s) != 13:
        raise InputError(f"value {v!r} does not fit a 13-character UFF field")
    return s


def write_uff55(model: Any, path: str | os.PathLike[str]) -> Path:
    """Write the modes of a :class:`~tyredamp.modal.ModalModel` as UFF 55 (atomically).

    Complex models go as analysis type 3 (pole, modal A = 1, modal B = -p),
    real models as type 2 (undamped frequency, modal mass 1, viscous ratio,
    shapes ``phi = Re(psi sqrt(2 i Omega))``). Output and input channels
    must have translational directions (+-1, +-2, +-3).

    Returns
    -------
    Path
    """
    from ..modal.model import ModalModel

    if not isinstance(model, ModalModel):
        raise InputError(f"model: expected a ModalModel, got {type(model).__name__}")
    chans = list(model.outputs) + list(model.inputs)
    shapes = np.vstack([model.psi_out, model.psi_in])  # (n_ch, m)
    values: dict[int, np.ndarray] = {}
    for c in chans:
        if abs(c.direction) not in (1, 2, 3):
            raise InputError(
                f"model: channel {c.label} has direction {c.direction}; UFF 55 holds "
                "translations X, Y, Z only"
            )
        values.setdefault(c.node, np.zeros((3, model.n_modes), dtype=complex))
    for c, row in zip(chans, shapes, strict=True):
        values[c.node][abs(c.direction) - 1] = np.sign(c.direction) * row
    inputs = json.dumps({_MARK: [[c.node, c.direction] for c in model.inputs]})
    if len(inputs) > 80:
        inputs = "NONE"  # too many drive points for one ID line: a reader assumes all
    real = model.mode_kind == "real"
    lines: list[str] = []
    for n in range(model.n_modes):
        p = complex(model.poles[n])
        lines += ["    -1", "    55"]
        lines.append(f"tyredamp {'real' if real else 'complex'} mode {n + 1}"[:80].ljust(80))
        lines.append(inputs.ljust(80))
        lines += ["NONE".ljust(80)] * 3
        lines.append(f"{1:10d}{2 if real else 3:10d}{2:10d}{8:10d}{2 if real else 5:10d}{3:10d}")
        if real:
            wn = abs(p)
            zeta = -p.real / wn
            lines.append(f"{2:10d}{4:10d}{1:10d}{n + 1:10d}")
            lines.append(_field(wn / (2 * np.pi)) + _field(1.0) + _field(zeta) + _field(0.0))
            scale = np.sqrt(2j * p.imag)
        else:
            lines.append(f"{2:10d}{6:10d}{1:10d}{n + 1:10d}")
            lines.append("".join(_field(v) for v in (p.real, p.imag, 1.0, 0.0, -p.real, -p.imag)))
            scale = 1.0
        for node in sorted(values):
            v = values[node][:, n] * scale
            lines.append(f"{node:10d}")
            if real:
                lines.append("".join(_field(x.real) for x in v))
            else:
                lines.append("".join(_field(x.real) + _field(x.imag) for x in v))
        lines.append("    -1")
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="ascii")
    return Path(path)


def _load55(p: Path) -> list[dict[str, Any]]:
    check_delimiters(p, p.read_bytes())
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ResourceWarning)
            uff = pyuff.UFF(str(p))
            types = list(uff.get_set_types())
            idx = [k for k, t in enumerate(types) if t == 55]
            if not idx:
                raise FileFormatError(
                    f"{p}: no data set 55 (mode shapes); found types {sorted(set(types))}"
                )
            sets = uff.read_sets(idx)
            gc.collect()
    except FileFormatError:
        raise
    except Exception as exc:  # pyuff raises bare Exception, and others on garbage
        raise FileFormatError(f"{p}: corrupt UFF data set 55 ({exc})") from None
    return [sets] if isinstance(sets, dict) else list(sets)


def uff_has_modes(path: str | os.PathLike[str]) -> bool:
    """True when the UFF file holds data sets 55 and no data set 58."""
    types = uff_set_types(path)
    return 55 in types and 58 not in types


def _num(s: dict[str, Any], key: str, where: str) -> float:
    try:
        v = float(s.get(key, 0.0) or 0.0)
    except (TypeError, ValueError):
        raise FileFormatError(f"{where}: field {key!r} is not a number") from None
    if not np.isfinite(v):
        raise FileFormatError(f"{where}: field {key!r} is {v}")
    return v


def read_uff55(path: str | os.PathLike[str], inputs: list[Channel] | None = None) -> Any:
    """Read the modes of a UFF file (data sets 55) into a ModalModel.

    Parameters
    ----------
    path : path-like
    inputs : list of Channel, optional
        Drive points (node and direction of measured channels). Default: the
        ones tyredamp stored on ID line 2, else every output.

    Returns
    -------
    ModalModel
        ``mode_kind`` ``"real"`` (all sets of analysis type 2) or
        ``"complex"`` (type 3); ``meta`` states the scaling assumptions used.

    Raises
    ------
    FileFormatError
        No data set 55, mixed or unsupported analysis types, modes on
        different nodes, shapes that are all zero, invalid numbers.
    """
    with guarded_read(path):
        return _read55(check_input_file(path), inputs)


def _read55(p: Path, inputs: list[Channel] | None) -> Any:
    from ..modal.model import ModalModel

    sets = _load55(p)
    kinds = {int(s.get("analysis_type", 0)) for s in sets}
    if kinds - {2, 3}:
        raise FileFormatError(
            f"{p}: data set 55 analysis type(s) {sorted(kinds - {2, 3})} are not modes; "
            "expected 2 (normal mode) or 3 (complex eigenvalue)"
        )
    if len(kinds) > 1:
        raise FileFormatError(f"{p}: real (type 2) and complex (type 3) modes in one file")
    real = kinds == {2}
    nodes0 = None
    poles, shapes = [], []
    notes: set[str] = set()
    for k, s in enumerate(sets):
        where = f"{p}: data set 55 #{k + 1}"
        nodes = np.asarray(s.get("node_nums", []), dtype=int)
        if nodes.size == 0:
            raise FileFormatError(f"{where}: no node values")
        try:
            vals = np.array([np.asarray(s[f"r{d}"]) for d in (1, 2, 3)], dtype=complex)
        except (KeyError, TypeError, ValueError):
            raise FileFormatError(f"{where}: expected X, Y, Z values per node") from None
        if vals.shape != (3, nodes.size) or not np.all(np.isfinite(vals)):
            raise FileFormatError(f"{where}: malformed or non-finite node values")
        order = np.argsort(nodes, kind="stable")
        nodes, vals = nodes[order], vals[:, order]
        twice = nodes[1:][nodes[1:] == nodes[:-1]]
        if twice.size:
            raise FileFormatError(f"{where}: node {int(twice[0])} appears more than once")
        if nodes0 is None:
            nodes0 = nodes
        elif not np.array_equal(nodes0, nodes):
            raise FileFormatError(f"{where}: mode on different nodes than the first mode")
        pole, psi = _mode(s, vals, real, where, notes)
        poles.append(pole)
        shapes.append(psi)
    assert nodes0 is not None
    arr = np.array(shapes)  # (m, 3, n_nodes)
    used = np.any(arr != 0, axis=0)  # (3, n_nodes)
    outs = [
        Channel(node=int(nodes0[j]), direction=d + 1)
        for j in range(nodes0.size)
        for d in range(3)
        if used[d, j]
    ]
    if not outs:
        raise FileFormatError(f"{p}: every mode shape is zero")
    psi_out = np.array([arr[:, c.direction - 1, list(nodes0).index(c.node)] for c in outs])
    if inputs is None:
        inputs = _stored_inputs(sets[0])
    stated = inputs is not None
    if inputs is None:
        inputs = list(outs)
        notes.add("no drive points stated: every measured DOF taken as an input")
    rows = []
    for c in inputs:
        hit = [
            i for i, o in enumerate(outs) if o.node == c.node and o.direction == abs(c.direction)
        ]
        if not hit:
            raise FileFormatError(f"{p}: drive point {c.label} has no mode-shape value")
        rows.append(np.sign(c.direction) * psi_out[hit[0]])
    meta: dict[str, Any] = {"source": str(p), "format": "uff55", "assumptions": sorted(notes)}
    meta["drive_points_stated"] = stated
    missing = "modal A" if _NO_A in notes else "modal mass" if _NO_MASS in notes else ""
    meta["scaled"] = not missing
    if missing:
        meta["scaling_note"] = f"the UFF 55 file gives no {missing} (0 in the file)"
    return ModalModel(
        np.array(poles),
        psi_out,
        np.array(rows),
        mode_kind="real" if real else "complex",
        outputs=outs,
        inputs=[Channel(node=c.node, direction=c.direction) for c in inputs],
        meta=meta,
    )


def _mode(
    s: dict[str, Any], vals: np.ndarray, real: bool, where: str, notes: set[str]
) -> tuple[complex, np.ndarray]:
    """Pole and eq. [10] shape (3, n_nodes) of one data set 55 (module docstring)."""
    if real:
        f = _num(s, "freq", where)
        m = _num(s, "modal_m", where)
        zeta = _num(s, "modal_damp_vis", where)
        if zeta == 0.0 and _num(s, "modal_damp_his", where) > 0:
            zeta = _num(s, "modal_damp_his", where) / 2.0
            notes.add("hysteretic loss factor eta taken as viscous zeta = eta / 2")
        if f <= 0 or not 0.0 <= zeta < 1.0:
            raise FileFormatError(
                f"{where}: expected frequency > 0 and damping ratio in [0, 1), got {f} Hz, {zeta}"
            )
        if m == 0.0:
            m = 1.0
            notes.add(_NO_MASS)
        if m < 0:
            raise FileFormatError(f"{where}: negative modal mass {m}")
        wn = 2 * np.pi * f
        pole = complex(-zeta * wn, wn * np.sqrt(1 - zeta * zeta))
        psi = np.real(vals) / np.sqrt(m * 2j * pole.imag)
    else:
        try:
            pole = complex(s["eig"])
        except (KeyError, TypeError, ValueError):
            raise FileFormatError(f"{where}: no complex eigenvalue") from None
        if not np.isfinite(pole) or pole.imag == 0.0:
            raise FileFormatError(f"{where}: eigenvalue {pole} is not an oscillating pole")
        a = complex(s.get("modal_a", 0.0) or 0.0)
        if not np.isfinite(a):
            raise FileFormatError(f"{where}: modal A {a} is not finite")
        if a == 0:
            a = 1.0
            notes.add(_NO_A)
        if pole.imag < 0:  # the other pole of the pair: conjugate everything
            pole, vals, a = pole.conjugate(), vals.conj(), a.conjugate()
        psi = vals / np.sqrt(a)
    return pole, psi


def _stored_inputs(s: dict[str, Any]) -> list[Channel] | None:
    text = str(s.get("id2", "")).strip()
    if not text.startswith("{"):
        return None
    try:
        d = json.loads(text)
        pairs = d[_MARK]
        return [Channel(node=int(a), direction=int(b)) for a, b in pairs]
    except (json.JSONDecodeError, KeyError, TypeError, ValueError, InputError):
        return None
