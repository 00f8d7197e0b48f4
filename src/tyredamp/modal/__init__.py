"""Modal identification: poles, residues, real and complex mode fits, indicators.

The usual entry point is :func:`identify_modes` (FRFs in, real and complex
:class:`ModalModel` out, with standard errors); the stages are public too:
:func:`plscf` (poles over model orders), :func:`stability_flags` and
:func:`cluster_poles` (automatic selection), :class:`ModalFitter` (LSFD and
variable-projection refinement), and :mod:`.indicators`. The modes JSON
file is :mod:`tyredamp.documents.modes`.
"""

from __future__ import annotations

from .fit import FitResult, ModalFitter
from .identify import ModalIdentification, identify_modes
from .indicators import (
    auto_mac,
    discrepancy,
    equivalent_real_modes,
    mac,
    mean_phase_deviation,
    modal_phase_collinearity,
    relative_error,
    rmsd,
)
from .lscf import PoleSet, plscf
from .model import ModalModel, ModeKind
from .selection import Cluster, StabilityFlags, cluster_poles, stability_flags

__all__ = [
    "Cluster",
    "FitResult",
    "ModalFitter",
    "ModalIdentification",
    "ModalModel",
    "ModeKind",
    "PoleSet",
    "StabilityFlags",
    "auto_mac",
    "cluster_poles",
    "discrepancy",
    "equivalent_real_modes",
    "identify_modes",
    "mac",
    "mean_phase_deviation",
    "modal_phase_collinearity",
    "plscf",
    "relative_error",
    "rmsd",
    "stability_flags",
]
