"""Modal identification: poles, residues, real and complex mode fits, indicators.

The usual entry point is :func:`identify_modes` (FRFs in, real and complex
:class:`ModalModel` out, with standard errors and a :class:`FitQuality`); the
stages are public too: :func:`build_problem` (band cut, normalisation, noise
model), a :class:`PoleEstimator` (default :func:`plscf`, poles over model
orders), :func:`stability_flags` and :func:`cluster_poles` (automatic
selection), :mod:`.search.search` (mode test, residual search),
:class:`ModalFitter` (LSFD and variable-projection refinement),
:mod:`.statistics.stats` and :mod:`.statistics.indicators`. The modes JSON file
is :mod:`tyredamp.documents.modes`.

Map of the package (one group per step of the method; a group imports only
from the groups below it; the layering test of the package enforces it):

``identify.py``, ``starts.py``, ``mode_count.py``, ``final.py``, ``assemble.py``,
``replicates.py`` (top)
    The pipeline: :func:`identify_modes` runs the steps below in order (the
    modes it starts from in ``starts``, the mode count in ``mode_count``),
    ``final`` makes the last fit (maximum-likelihood stage, likelihood
    intervals) and ``assemble`` turns it into a :class:`ModalModel` with its
    quality (intervals, goodness of fit); ``replicates`` finds each mode
    again in independent measurements identified alone.
``search/``
    Which modes the data hold: the mode test and the residual search on one
    fitter (``search``), the joint refit of a trial mode and the split of a
    mode in two (``joint``), its mode set (``modeset``), out-of-band residual
    modes (``out_of_band``), a trial mode against fixed ones (``trials``),
    where trials start (``search_starts``, ``residual_peaks``), each mode's
    threshold (``thresholds``, ``span_noise``), poles narrower than the lines
    (``narrow``, ``resolution``) and the statistic with the neighbours
    refitted (``refitted``). Its own group because it decides the mode count from
    fits: it uses the fitter and the diagram's poles, neither uses it.
``poles/`` and ``fit/`` (side by side, independent of each other)
    ``poles/``: the stabilisation diagram, from the FRFs to candidate poles
    without residues: pLSCF (``lscf``), the estimator protocol and registry
    (``estimators``), stability flags and clusters (``selection``), the model
    order (``order``). ``fit/``: residues and poles fitted to the FRFs for a
    given set of modes: :class:`ModalFitter` (``fit``) with its basis,
    linear algebra, scaling, added-mode projection and result (``_basis``,
    ``_linalg``, ``_scaling``, ``_added``, ``_results``, ``_state``), the
    maximum-likelihood refinement (``ml``) and likelihood intervals
    (``profile``). A diagram never fits residues and a fit never builds a
    diagram: the two methods split here.
``problem/``
    The data as the fits see them: the band-limited, normalised FRFs and their
    noise model (``problem``), principal combinations of many outputs
    (``compress``) and the noise level raised by the model error
    (``model_error``, which reads a :class:`ModalModel`).
``model.py``
    The result: :class:`ModalModel` (poles and mode shapes that synthesise
    FRFs), light to import (the command line and the modes file load it
    without the identification).
``statistics/`` (ground)
    How a fit is judged, on plain arrays: the mode test, noise estimates and
    goodness of fit (``stats``), MAC, MPC and the fit indicators
    (``indicators``) and the fit-quality record (``quality``). Imports nothing
    else of the package.

The subpackages' ``__init__`` modules hold only their docstring (nothing is
imported with them), so a deep import loads only what it names.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:
    from .fit.fit import FitResult, ModalFitter
    from .identify import ModalIdentification, identify_modes
    from .model import ModalModel, ModeKind
    from .poles.estimators import PoleEstimator
    from .poles.lscf import PoleSet, plscf
    from .poles.selection import Cluster, StabilityFlags, cluster_poles, stability_flags
    from .problem.problem import FitProblem, build_problem
    from .statistics.indicators import (
        auto_mac,
        discrepancy,
        equivalent_real_modes,
        mac,
        mean_phase_deviation,
        modal_phase_collinearity,
        relative_error,
        rmsd,
    )
    from .statistics.quality import FitQuality, RejectedMode

#: public name -> submodule; a name is imported on first access (PEP 562), so that
#: ``import tyredamp.modal.model`` (the command line, the modes file) does not load
#: the identification and SciPy's optimisers
_WHERE = {
    "Cluster": "poles.selection",
    "FitProblem": "problem.problem",
    "FitQuality": "statistics.quality",
    "FitResult": "fit.fit",
    "ModalFitter": "fit.fit",
    "ModalIdentification": "identify",
    "ModalModel": "model",
    "ModeKind": "model",
    "PoleEstimator": "poles.estimators",
    "PoleSet": "poles.lscf",
    "RejectedMode": "statistics.quality",
    "StabilityFlags": "poles.selection",
    "auto_mac": "statistics.indicators",
    "build_problem": "problem.problem",
    "cluster_poles": "poles.selection",
    "discrepancy": "statistics.indicators",
    "equivalent_real_modes": "statistics.indicators",
    "identify_modes": "identify",
    "mac": "statistics.indicators",
    "mean_phase_deviation": "statistics.indicators",
    "modal_phase_collinearity": "statistics.indicators",
    "plscf": "poles.lscf",
    "relative_error": "statistics.indicators",
    "rmsd": "statistics.indicators",
    "stability_flags": "poles.selection",
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

__getattr__, __dir__ = lazy_names(__name__, _WHERE, __all__, globals())
