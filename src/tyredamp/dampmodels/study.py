"""The damping-model comparison of an identified modal model (``tyredamp damping --models``).

From the modes alone: the Adhikari-Woodhouse part 2 test (is the part-1 viscous
estimate consistent with viscous damping, and which relaxation parameter
explains its asymmetry). With the measured FRFs and their noise (the variance
of each FRF value): each requested model fitted to the FRFs, ranked by BIC with
likelihood-ratio tests (:func:`~tyredamp.dampmodels.compare_models`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..frf import FRF
from ..modal import ModalModel
from .choice import ModelComparison, compare_models
from .frffit import MODELS, start_from_modes
from .fromodes import exponential_from_modes

__all__ = ["models_report", "parse_models"]


def parse_models(text: str) -> tuple[str, ...]:
    """``"viscous,hysteretic"`` as a tuple of model names (checked)."""
    names = tuple(dict.fromkeys(t.strip() for t in text.split(",") if t.strip()))
    bad = [n for n in names if n not in MODELS]
    if bad or not names:
        raise InputError(
            f"models: expected a comma-separated list of {', '.join(MODELS)}, got {text!r}"
        )
    return names


def models_report(
    mm: ModalModel,
    models: Sequence[str],
    modes: Sequence[int] | None = None,
    at_inputs: bool = False,
    frf: FRF | None = None,
) -> tuple[dict[str, Any], list[str]]:
    """The comparison document and its summary lines.

    Parameters
    ----------
    mm : ModalModel
        Identified modes (poles and eq. [10] shapes).
    models : sequence of str
        Models to compare (names in :data:`~tyredamp.dampmodels.MODELS`).
    modes : sequence of int, optional
        The modes used (numbered from 1), default all.
    at_inputs : bool
        Take the shapes at the inputs (roving-hammer test) instead of the outputs.
    frf : FRF, optional
        The receptances the modes came from, with ``variance``; enables the
        likelihood ranking. Its inputs must be at response points.

    Returns
    -------
    document : dict
        ``{"models": [...], "aw_part2": {...} | null, "ranking": {...} | null, "note": str}``.
    lines : list of str
    """
    idx = np.arange(mm.poles.size) if modes is None else np.asarray(modes, dtype=int) - 1
    p = mm.poles[idx]
    psi = (mm.psi_in if at_inputs else mm.psi_out)[:, idx]
    shapes = psi * np.sqrt(2j * p.imag)
    doc: dict[str, Any] = {"models": list(models), "aw_part2": None, "ranking": None}
    lines: list[str] = []
    if p.size >= 2:
        aw = exponential_from_modes(p, shapes)
        doc["aw_part2"] = aw.to_dict()
        lines.append(aw.format())
    if frf is None:
        doc["note"] = (
            "no FRF file given: the models are not ranked by likelihood (give the FRFs "
            "the modes came from, with their variance)"
        )
        lines.append(doc["note"])
        return doc, lines
    cmp = _rank(frf, shapes, p, models, at_inputs)
    doc["ranking"] = cmp.to_dict()
    doc["note"] = cmp.verdict
    lines += cmp.summary()
    return doc, lines


def _rank(
    frf: FRF,
    shapes: np.ndarray,
    p: np.ndarray,
    models: Sequence[str],
    at_inputs: bool,
) -> ModelComparison:
    """The likelihood ranking on the FRFs (band: 0.8 to 1.2 times the modes' range)."""
    if at_inputs:
        raise InputError(
            "--frf: the likelihood ranking needs the shapes at the responses (not a "
            "roving-hammer test)"
        )
    if frf.variance is None:
        raise InputError(
            "--frf: the FRF file carries no variance of the FRF values; the likelihood "
            "ranking needs the measured noise"
        )
    if frf.H.shape[0] != shapes.shape[0]:
        raise InputError(
            f"--frf: {frf.H.shape[0]} responses, the modes have shapes at {shapes.shape[0]} points"
        )
    labels = [c.label for c in frf.outputs]
    rows = []
    for c in frf.inputs:
        if c.label not in labels:
            raise InputError(
                f"--frf: input {c.label} is not at a response point; the ranking needs a "
                "drive point for each input"
            )
        rows.append(labels.index(c.label))
    fz = np.abs(p) / (2 * np.pi)
    band = (frf.frequency >= 0.8 * fz.min()) & (frf.frequency <= 1.2 * fz.max())
    h = frf.receptance().H
    # the variance converts with H: receptance = H / (i w)^k, the same factor on the noise
    sig = (
        np.sqrt(np.maximum(frf.variance, 1e-300) / 2)
        * np.abs(h)
        / np.maximum(np.abs(frf.H), 1e-300)
    )
    start = start_from_modes(p, shapes)
    return compare_models(frf.frequency[band], h[:, :, band], sig[:, :, band], rows, start, models)
