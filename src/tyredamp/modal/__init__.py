"""Modal identification: poles, residues, real and complex mode fits, indicators.

The usual entry point is :func:`identify_modes` (FRFs in, real and complex
:class:`ModalModel` out, with standard errors and a :class:`FitQuality`); the
stages are public too: :func:`build_problem` (band cut, normalisation, noise
model), a :class:`PoleEstimator` (default :func:`plscf`, poles over model
orders), :func:`stability_flags` and :func:`cluster_poles` (automatic
selection), :mod:`.search` (mode test, residual search), :class:`ModalFitter`
(LSFD and variable-projection refinement), :mod:`.stats` and
:mod:`.indicators`. The modes JSON file is :mod:`tyredamp.documents.modes`.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .estimators import PoleEstimator
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
    from .problem import FitProblem, build_problem
    from .quality import FitQuality, RejectedMode
    from .selection import Cluster, StabilityFlags, cluster_poles, stability_flags

#: public name -> submodule; a name is imported on first access (PEP 562), so that
#: ``import tyredamp.modal.model`` (the command line, the modes file) does not load
#: the identification and SciPy's optimisers
_WHERE = {
    "Cluster": "selection",
    "FitProblem": "problem",
    "FitQuality": "quality",
    "FitResult": "fit",
    "ModalFitter": "fit",
    "ModalIdentification": "identify",
    "ModalModel": "model",
    "ModeKind": "model",
    "PoleEstimator": "estimators",
    "PoleSet": "lscf",
    "RejectedMode": "quality",
    "StabilityFlags": "selection",
    "auto_mac": "indicators",
    "build_problem": "problem",
    "cluster_poles": "selection",
    "discrepancy": "indicators",
    "equivalent_real_modes": "indicators",
    "identify_modes": "identify",
    "mac": "indicators",
    "mean_phase_deviation": "indicators",
    "modal_phase_collinearity": "indicators",
    "plscf": "lscf",
    "relative_error": "indicators",
    "rmsd": "indicators",
    "stability_flags": "selection",
}

__all__ = [
    "Cluster",
    "FitProblem",
    "FitQuality",
    "FitResult",
    "ModalFitter",
    "ModalIdentification",
    "ModalModel",
    "ModeKind",
    "PoleEstimator",
    "PoleSet",
    "RejectedMode",
    "StabilityFlags",
    "auto_mac",
    "build_problem",
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


def __getattr__(name: str) -> Any:
    """The public names on first access (PEP 562, see ``_WHERE``)."""
    mod = _WHERE.get(name)
    if mod is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f"{__name__}.{mod}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
