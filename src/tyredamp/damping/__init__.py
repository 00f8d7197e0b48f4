"""Damping identification from complex modes (spec step 7, eq. [14]-[18]).

Main entry point: :func:`identify_damping` (a :class:`~tyredamp.modal.ModalModel`
in, a :class:`DampingModel` out). Lower-level pieces: the estimators of ``C'``
(:func:`modal_damping_from_modes`, after Adhikari & Woodhouse 2001), the
physical matrices at the points (:func:`physical_matrices`), Lancaster's exact
formulas for a complete modal set (:func:`lancaster_matrices`), proportional
damping fits (:func:`compare_proportional`) and Monte Carlo standard errors
(:func:`monte_carlo_std`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:
    from .diagnostics import DampingDiagnostics, definiteness, findings
    from .estimate import identify_damping, no_std_note
    from .identify import (
        METHODS,
        Method,
        ModalDampingEstimate,
        align_signs,
        first_order_damping,
        modal_damping_from_modes,
        modal_system_shapes,
        normalise_shapes,
        physical_matrices,
    )
    from .lancaster import LancasterMatrices, lancaster_matrices
    from .model import DampingModel
    from .proportional import (
        ProportionalComparison,
        compare_proportional,
        comparison_grid,
        fit_rayleigh,
        reduced_receptance,
    )
    from .uncertainty import MonteCarloResult, missing_std, monte_carlo_std

#: the module of each public name: loaded on first access (PEP 562), so that
#: reading where a mode set's shapes are (:mod:`.modeset`) does not load the
#: estimators and their optimisers
_WHERE = {
    "DampingDiagnostics": "diagnostics",
    "DampingModel": "model",
    "LancasterMatrices": "lancaster",
    "METHODS": "identify",
    "Method": "identify",
    "ModalDampingEstimate": "identify",
    "MonteCarloResult": "uncertainty",
    "ProportionalComparison": "proportional",
    "align_signs": "identify",
    "compare_proportional": "proportional",
    "comparison_grid": "proportional",
    "definiteness": "diagnostics",
    "findings": "diagnostics",
    "first_order_damping": "identify",
    "fit_rayleigh": "proportional",
    "identify_damping": "estimate",
    "lancaster_matrices": "lancaster",
    "missing_std": "uncertainty",
    "modal_damping_from_modes": "identify",
    "modal_system_shapes": "identify",
    "monte_carlo_std": "uncertainty",
    "no_std_note": "estimate",
    "normalise_shapes": "identify",
    "physical_matrices": "identify",
    "reduced_receptance": "proportional",
}

__all__ = [
    "METHODS",
    "DampingDiagnostics",
    "DampingModel",
    "LancasterMatrices",
    "Method",
    "ModalDampingEstimate",
    "MonteCarloResult",
    "ProportionalComparison",
    "align_signs",
    "compare_proportional",
    "comparison_grid",
    "definiteness",
    "findings",
    "first_order_damping",
    "fit_rayleigh",
    "identify_damping",
    "lancaster_matrices",
    "missing_std",
    "modal_damping_from_modes",
    "modal_system_shapes",
    "monte_carlo_std",
    "no_std_note",
    "normalise_shapes",
    "physical_matrices",
    "reduced_receptance",
]

__getattr__, __dir__ = lazy_names(__name__, _WHERE, __all__, globals())
