"""Which modes, at which points, in which scaling: the mode set a damping run uses.

A modal model from a test or from another program is not always a tyre's
16-point radial set with a drive point:

* **Shape points.** A roving-hammer test (one accelerometer fixed, the hammer
  roving over the points) has one output and many inputs: by reciprocity
  ``H_1j = H_j1`` the residues ``R_1jn = psi_out[1, n] psi_in[j, n]`` give the
  shape at the *inputs* ``j``. :func:`shape_side` decides from the channel
  counts where the shapes are (the side with more channels; the outputs on
  a tie) and :func:`at_shape_points` returns the model written from the
  other side (outputs and inputs exchanged, the residual terms transposed),
  so that everything that reads shapes at the outputs (the damping
  identification, the plots) reads them where they are.
* **Scaling.** The damping matrix, modal mass and reduced mass and stiffness
  need mass-normalised shapes (unit modal A in the eq. [10] scaling). A fit
  of FRFs without a drive point (an output at the node and direction of an
  input) cannot scale its shapes, nor can a UFF 55 file whose modal A (or
  modal mass) is not given; :func:`scaling_problem` says why a model is
  unscaled, in words.
* **Subsets.** A mode set of 13 modes at 8 points cannot give a damping
  matrix (eq. [14]-[18] need at least as many points as modes):
  :func:`select_modes` keeps the modes chosen by number or by band, and
  :func:`check_point_count` says how many modes the points allow.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

from ..exceptions import InputError, ShapeError
from ..frf import Channel, drive_pairs
from ..modal.model import ModalModel

__all__ = [
    "ShapeSide",
    "at_shape_points",
    "check_point_count",
    "negative_mass_modes",
    "parse_mode_numbers",
    "scaling_problem",
    "select_modes",
    "shape_side",
]

ShapeSide = Literal["outputs", "inputs"]

#: Lists in a model's ``meta`` that are not one entry per mode (whatever their length).
_NOT_PER_MODE = frozenset(
    {"band_hz", "warnings", "assumptions", "noise_rms_per_output", "rmsd_per_frf", "modes_used"}
)


def shape_side(model: ModalModel) -> ShapeSide:
    """Where the mode shapes of ``model`` are: ``"outputs"`` or ``"inputs"``.

    ``model.meta["shapes_at"]`` when it says so; else the side with more
    channels (a roving-hammer test, one output and several inputs, has its
    shapes at the inputs), the outputs on a tie.
    """
    stated = model.meta.get("shapes_at")
    if stated in ("outputs", "inputs"):
        return "inputs" if stated == "inputs" else "outputs"
    return "inputs" if len(model.inputs) > len(model.outputs) else "outputs"


def _transposed(model: ModalModel) -> ModalModel:
    def t(r: Any) -> Any:
        return None if r is None else np.asarray(r).T

    std: dict[str, Any] = {k: v for k, v in model.std.items() if k not in ("psi_out", "psi_in")}
    if "psi_in" in model.std:  # the shapes' errors go with the shapes
        std["psi_out"] = model.std["psi_in"]
    if "psi_out" in model.std:
        std["psi_in"] = model.std["psi_out"]
    rm = model.residual_modes
    return ModalModel(
        model.poles,
        model.psi_in,
        model.psi_out,
        mode_kind=model.mode_kind,
        outputs=model.inputs,
        inputs=model.outputs,
        lower_residual=t(model.lower_residual),
        upper_residual=t(model.upper_residual),
        std=std,
        meta=dict(model.meta),
        residual_modes=None if rm is None else _transposed(rm),
        quality=model.quality,
    )


def at_shape_points(model: ModalModel) -> ModalModel:
    """``model`` with its shape points as the outputs.

    Unchanged when the shapes are at the outputs (:func:`shape_side`); else
    the reciprocal model: ``psi_out`` and ``psi_in`` exchanged with their
    channels, residual terms transposed (the receptance of the result is the
    transpose of the model's, equal to it by reciprocity), with
    ``meta["shapes_from"] = "inputs"`` (and ``meta["shapes_at"] = "outputs"``,
    so that a second call changes nothing). The standard errors go with what they
    belong to: those of the shapes at the inputs become those at the outputs and
    the other way round; the modes' frequency and damping errors are kept.
    """
    if shape_side(model) == "outputs":
        return model
    out = _transposed(model)
    out.meta["shapes_at"] = "outputs"  # of this reciprocal model
    out.meta["shapes_from"] = "inputs"
    out.meta["shapes_from_note"] = (
        f"shapes at the {len(model.inputs)} inputs (roving-hammer test: one response, "
        "the excitation moved over the points; by reciprocity H_1j = H_j1)"
    )
    return out


def negative_mass_modes(model: ModalModel) -> tuple[list[float], str]:
    """The modes to which a drive point of ``model`` gives a negative modal mass.

    With the eq. [10] scaling the residue of mode ``n`` at a drive point
    (output ``k`` at the node of input ``j``) is ``R_kjn = psi_out[k, n]
    psi_in[j, n]``, and ``2 i Omega_n R_kjn = phi_k phi_j`` (spec eq. [3];
    the complex modes' ``1 / a_n`` in eq. [10]) is the inverse modal mass
    seen at that point: ``phi_k^2 > 0`` for every mode of a passive structure
    when the response is measured at the excitation point and in its
    direction (a direction of the opposite sense turns every sign). A mode
    with ``Re(2 i Omega_n R_kjn) <= 0`` at a drive point therefore says that
    the point is not one, for that mode (the response is beside the
    excitation, on a node line of the mode's neighbour, or across the
    structure), or that the mode is not physical; the drive-point scaling
    of its shape is then meaningless. A mode set whose drive points were not
    stated (``meta["drive_points_stated"] is False``: a UFF 55 file of another
    program, every point taken as an input) has no measured drive point to
    test.

    Returns
    -------
    frequencies : list of float
        Natural frequencies (Hz) of those modes, ascending.
    point : str
        The drive point that shows it (e.g. ``"1+Z"``), ``""`` when none.
    """
    if model.meta.get("drive_points_stated") is False:  # inputs assumed, not measured
        return [], ""
    omega = np.abs(np.asarray(model.poles).imag)
    for k, j in sorted(drive_pairs(model.outputs, model.inputs)):  # output by output
        co, ci = model.outputs[k], model.inputs[j]
        if not co.direction:  # a scalar channel has no sense to compare
            continue
        sense = 1.0 if co.direction * ci.direction > 0 else -1.0
        a = sense * np.real(2j * omega * model.psi_out[k] * model.psi_in[j])
        bad = np.flatnonzero(~(a > 0))
        if bad.size:
            point = Channel(co.node, co.direction).label  # node and direction, not a name
            return sorted(float(x) for x in model.frequency_hz[bad]), point
    return [], ""


def scaling_problem(model: ModalModel, per_mode: bool = False) -> str:
    """Why the shapes of ``model`` are not mass-normalised, or ``""`` when they are.

    Unscaled are the modes of a UFF 55 file without modal A (complex modes) or
    modal mass (real modes), ``meta["scaled"] is False``, and the modes fitted
    to FRFs without a drive point (no input at the node and direction of an
    output, so no residue fixes the scale). A model that states
    ``meta["scaled"] is True`` is scaled. With ``per_mode`` the modes to which
    the drive point gives a negative modal mass (:func:`negative_mass_modes`)
    are unscaled too.
    """
    if per_mode:
        bad, point = negative_mass_modes(model)
        if bad:
            hz = ", ".join(f"{f:.4g}" for f in bad)
            return (
                f"the drive point {point} gives the mode(s) at {hz} Hz a negative modal mass, "
                "which a response measured at the excitation point and in its direction never "
                "does: for these modes the response is not at the drive point (or the modes are "
                "not physical), so their shapes cannot be mass-normalised"
            )
    scaled = model.meta.get("scaled")
    if scaled is True:
        return ""
    if scaled is False:
        why = model.meta.get("scaling_note")
        return str(why) if why else "the modes are not scaled"
    if not model.inputs:
        return "the modes have no drive point to scale them"
    if drive_pairs(model.outputs, model.inputs):
        return ""
    return (
        "the FRFs have no drive point (no input at the node and direction of an output), "
        "so the fit cannot scale the shapes"
    )


def parse_mode_numbers(text: str) -> list[int]:
    """Mode numbers (1-based) from text such as ``"1,2,5-7"`` (ranges inclusive).

    Raises
    ------
    InputError
        Not numbers and ranges separated by commas, numbers below 1, an empty
        range or a repeated mode.
    """
    out: list[int] = []
    for part in str(text).replace(";", ",").split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part[1:]:
                a, b = part.split("-", 1) if not part.startswith("-") else ("", part)
                lo, hi = int(a), int(b)
                if hi < lo:
                    raise ValueError
                out += list(range(lo, hi + 1))
            else:
                out.append(int(part))
        except ValueError:
            raise InputError(
                f"modes: expected mode numbers and ranges such as 1,2,5-7, got {text!r}"
            ) from None
    if not out:
        raise InputError(f"modes: expected at least one mode number, got {text!r}")
    if min(out) < 1:
        raise InputError(f"modes: mode numbers start at 1, got {text!r}")
    if len(set(out)) != len(out):
        raise InputError(f"modes: a mode is repeated in {text!r}")
    return out


def select_modes(
    model: ModalModel,
    modes: Sequence[int] | None = None,
    band: tuple[float, float] | None = None,
) -> tuple[ModalModel, list[int]]:
    """The modes of ``model`` chosen by number and/or band.

    Parameters
    ----------
    model : ModalModel
    modes : sequence of int, optional
        Mode numbers, 1-based in the model's order (increasing frequency).
    band : (float, float), optional
        Natural frequency range in Hz (inclusive); with ``modes`` both apply.

    Returns
    -------
    model : ModalModel
        The chosen modes (shapes, standard errors, per-mode fit records and
        per-mode ``meta`` lists); ``meta["modes_used"]`` holds their numbers.
    numbers : list of int
        Their 1-based numbers in ``model``.

    Raises
    ------
    InputError
        A mode number beyond the model's, an empty or inverted band, or no
        mode left.
    """
    m = model.n_modes
    keep = np.ones(m, bool)
    if modes is not None:
        nums = [int(k) for k in modes]
        bad = [k for k in nums if not 1 <= k <= m]
        if bad:
            raise InputError(f"modes: mode {bad[0]} does not exist; the modes are 1 to {m}")
        keep[:] = False
        keep[[k - 1 for k in nums]] = True
    if band is not None:
        lo, hi = float(band[0]), float(band[1])
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo or lo < 0:
            raise InputError(f"band: expected 0 <= F1 < F2 in Hz, got {lo:g} {hi:g}")
        f = model.frequency_hz
        keep &= (f >= lo) & (f <= hi)
    idx = np.flatnonzero(keep)
    if idx.size == 0:
        have = ", ".join(f"{x:.1f}" for x in model.frequency_hz)
        raise InputError(f"modes: no mode chosen; the modes are at {have} Hz")
    numbers = [int(i) + 1 for i in idx]
    if idx.size == m and modes is None and band is None:
        return model, numbers
    std: dict[str, Any] = {}
    for k, v in model.std.items():
        a = np.asarray(v)
        std[k] = a[..., idx] if a.ndim and a.shape[-1] == m else a
    meta: dict[str, Any] = {}
    for k, v in model.meta.items():
        if isinstance(v, list | tuple | np.ndarray) and len(v) == m and k not in _NOT_PER_MODE:
            meta[k] = [v[int(i)] for i in idx]
        else:
            meta[k] = v
    meta["modes_used"] = numbers
    sub = ModalModel(
        model.poles[idx],
        model.psi_out[:, idx],
        model.psi_in[:, idx],
        mode_kind=model.mode_kind,
        outputs=model.outputs,
        inputs=model.inputs,
        lower_residual=model.lower_residual,
        upper_residual=model.upper_residual,
        std=std,
        meta=meta,
        residual_modes=model.residual_modes,
        quality=None if model.quality is None else model.quality.reordered(idx),
    )
    return sub, numbers


def check_point_count(model: ModalModel, n_all: int | None = None) -> None:
    """Refuse a damping run with more modes than shape points, saying what the points allow.

    Parameters
    ----------
    model : ModalModel
        The modes to use, shapes at the outputs (:func:`at_shape_points`).
    n_all : int, optional
        Number of modes in the file (to say that a subset can be chosen).

    Raises
    ------
    ShapeError
        ``n_modes > n_points``.
    """
    n_pts = len(model.outputs)
    m = model.n_modes
    if m <= n_pts:
        return
    pts = ", ".join(c.label for c in model.outputs[:12]) + (", ..." if n_pts > 12 else "")
    raise ShapeError(
        f"{m} modes at {n_pts} points ({pts}): the damping matrix needs at least as many "
        f"points as modes, so these points allow at most {n_pts} modes; choose them with "
        f"--modes (e.g. --modes 1-{n_pts}) or --band F1 F2 (modes=, band= in Python)"
        + (f" (the file has {n_all} modes)" if n_all is not None else "")
    )
