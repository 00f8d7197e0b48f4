"""Damping identification from a :class:`~tyredamp.modal.ModalModel` (spec step 7).

:func:`identify_damping` runs the whole step: ``C'`` in modal coordinates
(eq. [14]-[18], see :mod:`tyredamp.damping.identify`), the physical matrices
at the points, Lancaster's exact cross-check for a complete modal set, the
best proportional models, diagnostics with plain-English findings and Monte
Carlo standard errors.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ConvergenceError, InputError, ShapeError
from ..mechanics.modal_sum import modal_sum_receptance
from ..modal.model import ModalModel
from .diagnostics import compute_diagnostics, findings
from .identify import METHODS, Method, modal_damping_from_modes, physical_matrices
from .lancaster import lancaster_matrices
from .model import DampingModel
from .proportional import compare_proportional, comparison_grid
from .uncertainty import MonteCarloResult, missing_std, monte_carlo_std

__all__ = ["identify_damping", "no_std_note"]


def no_std_note(missing: str) -> str:
    """The finding when some standard errors of the modes are unusable (:func:`missing_std`)."""
    return (
        "No standard errors: the modes give no usable standard error (NaN, infinite or "
        f"negative) for {missing}; the Monte Carlo propagation needs all of them, so C' and C "
        "are given without standard errors."
    )


def _residual_fraction(model: ModalModel) -> float | None:
    """RMS of the residual terms (and residual modes) over the RMS of the model receptance.

    Evaluated on the comparison grid of the identified modes; None when the
    model has no residual terms.
    """
    if (
        model.lower_residual is None
        and model.upper_residual is None
        and model.residual_modes is None
    ):
        return None
    f = comparison_grid(model.poles)
    total = model.receptance(f)
    modes = modal_sum_receptance(f, model.poles, model.psi_out, model.psi_in)
    return float(np.linalg.norm(total - modes) / max(float(np.linalg.norm(total)), 1e-300))


def _theory_change(
    model: ModalModel, shapes: NDArray[np.complex128], est: Any, max_iter: int
) -> float | None:
    """``||C'_est - C'_refined|| / ||C'_refined||``: what the small-damping formula neglects."""
    try:
        ref = modal_damping_from_modes(model.poles, shapes, "refined", max_iter=max_iter)
    except ConvergenceError:
        return None
    return float(np.linalg.norm(est.c_modal - ref.c_modal) / np.linalg.norm(ref.c_modal))


def _lancaster(
    model: ModalModel, c_phys: NDArray[np.float64]
) -> tuple[NDArray[np.float64] | None, float | None]:
    """Lancaster's exact C for a complete modal set and its difference to ``c_phys``."""
    if model.n_modes != model.psi_out.shape[0]:
        return None, None
    lm = lancaster_matrices(model.poles, model.psi_out)
    diff = float(np.linalg.norm(c_phys - lm.C) / max(float(np.linalg.norm(lm.C)), 1e-300))
    return lm.C, diff


def _uncertainty_notes(mc: MonteCarloResult | None, n_samples: int, missing: str) -> list[str]:
    """Why standard errors are missing, or how many Monte Carlo samples failed."""
    if missing and n_samples > 0:
        return [no_std_note(missing)]
    if mc is None:
        return [
            "No standard errors: the modal model carries no uncertainty (std) to propagate."
            if n_samples > 0
            else "Standard errors not computed (n_samples = 0)."
        ]
    if mc.n_failed:
        return [
            f"{mc.n_failed} of {mc.n_samples} Monte Carlo samples failed to identify and were "
            "left out of the standard errors."
        ]
    return []


def identify_damping(
    model: ModalModel,
    method: Method = "improved",
    *,
    normalise: bool = True,
    n_samples: int = 200,
    seed: int = 0,
    max_iter: int = 200,
    meta: dict[str, Any] | None = None,
) -> DampingModel:
    """Identify the viscous damping matrix from complex modes (spec step 7).

    Parameters
    ----------
    model : ModalModel
        Identified (or exact) modes with ``psi_out`` at ``N`` points in the
        eq. [10] scaling; ``N >= m``. Real-mode models are accepted and give a
        diagonal ``C'`` (flagged in the findings).
    method : {"first", "improved", "refined"}
        Eq. [16], eq. [18] (the paper's improved form, default) or the
        bias-corrected iteration (see :mod:`tyredamp.damping.identify`).
    normalise : bool
        Normalise the complex shapes so that ``alpha_n^(n) = 1`` before
        ``"first"``/``"improved"`` (recommended, default).
    n_samples : int
        Monte Carlo samples for the standard errors (0 to skip). Used only when
        ``model.std`` holds uncertainties.
    seed : int
        Seed of the Monte Carlo generator.
    max_iter : int
        Iteration limit of the normalisation and refinement.
    meta : dict, optional
        Stored in the result (for example the source file).

    Returns
    -------
    DampingModel

    Raises
    ------
    ShapeError
        Fewer points than modes or no modes.
    PhysicsError
        Linearly dependent shapes or unstable poles.
    ConvergenceError
        The normalisation or (for ``"refined"``) the refinement did not converge.
    """
    if not isinstance(model, ModalModel):
        raise InputError(f"model: expected a ModalModel, got {type(model).__name__}")
    if method not in METHODS:
        raise InputError(f"method: expected one of {METHODS}, got {method!r}")
    if model.n_modes == 0:
        raise ShapeError("model: expected at least one mode, got none")
    if n_samples < 0:
        raise InputError(f"n_samples: expected >= 0, got {n_samples}")
    shapes = model.second_order_shapes()
    est = modal_damping_from_modes(model.poles, shapes, method, normalise, max_iter)
    mass, c_phys, stiff = physical_matrices(est.basis, est.c_modal, est.omega)

    theory_change = None if method == "refined" else _theory_change(model, shapes, est, max_iter)
    lanc, lanc_diff = _lancaster(model, c_phys)

    prop = compare_proportional(model.poles, model.psi_out, est.basis, est.c_modal, est.omega)
    diag = compute_diagnostics(
        c_modal=est.c_modal,
        c_phys=c_phys,
        shapes=est.shapes,
        basis=est.basis,
        damping_ratio=model.damping_ratio,
        residual_fraction=_residual_fraction(model),
        normalisation_phase=est.normalisation_phase,
        basis_residual=est.basis_residual,
        theory_change=theory_change,
        lancaster_difference=lanc_diff,
    )

    mc = None
    missing = missing_std(model.std, model.frequency_hz, [c.label for c in model.outputs])
    if n_samples > 0 and not missing:
        mc = monte_carlo_std(
            model.poles, model.psi_out, shapes, model.std, method, normalise, n_samples, seed
        )
    std: dict[str, np.ndarray] = {} if mc is None else {"modal": mc.modal, "physical": mc.physical}
    unc: dict[str, Any] = {}
    if mc is not None:
        unc = {
            "method": "monte_carlo",
            "n_samples": mc.n_samples,
            "n_failed": mc.n_failed,
            "seed": mc.seed,
        }
    notes = findings(diag, method, prop, std.get("modal"), est.c_modal)
    notes += _uncertainty_notes(mc, n_samples, missing)
    return DampingModel(
        modal=est.c_modal,
        physical=c_phys,
        mass=mass,
        stiffness=stiff,
        basis=est.basis,
        poles=model.poles,
        frequency_hz=est.omega / (2 * np.pi),
        damping_ratio=model.damping_ratio,
        points=model.outputs,
        method=method,
        normalised=bool(normalise and method != "refined"),
        diagnostics=diag,
        proportional=prop,
        findings=tuple(notes),
        std=std,
        uncertainty=unc,
        lancaster_physical=lanc,
        meta=dict(meta or {}),
    )
