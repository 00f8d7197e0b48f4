"""The whole step from identified modes (one or more pressures) to tyre-model parameters.

:func:`build_tyre_model` labels every mode with its wave number, updates the
flexible ring jointly across the pressures, derives the rigid-ring in-plane
parameters per pressure, optionally adds the lateral carcass quantities, and
returns the documents the command line writes (``tyredamp tyre-model``):

* ``ring.json`` -- wave numbers per pressure, the updated ring (parameters,
  standard errors, correlations, verdicts, per-pressure tension and
  foundation stiffness), predictions at extra pressures;
* ``rigid_ring.json`` -- rigid-ring parameters per pressure, what the test
  cannot give, lateral carcass quantities;
* one ``.tir`` subset per pressure (:func:`~tyredamp.tyremodel.tir_text`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import __version__
from ..exceptions import InputError
from ..modal.model import ModalModel
from .budget import Assumptions, UncertaintyBudget, rigid_ring_budget
from .checks import check_lateral, check_modes, check_rigid, check_ring
from .lateral import LateralCarcass
from .rigid import RigidRingParameters, rigid_ring_from_modes
from .ring import FoundationLaw, RingFit, fit_ring, ring_observations
from .tir import tir_text
from .tirmerge import merged_text
from .wavenumber import WaveNumberAnalysis, wave_number_analysis

__all__ = ["TyreModelResult", "build_tyre_model"]

_BAR = 1e5


@dataclass(frozen=True, eq=False)
class TyreModelResult:
    """Everything :func:`build_tyre_model` derived.

    Attributes
    ----------
    pressures : tuple of float
        Test pressures in Pa, in input order.
    sources : tuple of str
    analyses : tuple of WaveNumberAnalysis
        One per input.
    ring : RingFit
    rigid : tuple of RigidRingParameters
        One per input.
    lateral : tuple of LateralCarcass
    predictions : list of dict
        Modes of the updated ring at the requested extra pressures.
    budgets : tuple of UncertaintyBudget
        Uncertainty budget of each pressure's rigid-ring values.
    warnings : tuple of str
    """

    pressures: tuple[float, ...]
    sources: tuple[str, ...]
    analyses: tuple[WaveNumberAnalysis, ...]
    ring: RingFit
    rigid: tuple[RigidRingParameters, ...]
    lateral: tuple[LateralCarcass, ...]
    predictions: list[dict[str, Any]]
    budgets: tuple[UncertaintyBudget, ...] = ()
    warnings: tuple[str, ...] = ()

    def ring_document(self) -> dict[str, Any]:
        """The ``ring.json`` document."""
        return {
            "tyredamp_version": __version__,
            "kind": "tyre-ring-model",
            "inputs": [
                {"source": s, "pressure_bar": p / _BAR, "wave_numbers": a.to_dict()}
                for s, p, a in zip(self.sources, self.pressures, self.analyses, strict=True)
            ],
            "ring": self.ring.to_dict(),
            "predictions": self.predictions,
        }

    def rigid_document(self) -> dict[str, Any]:
        """The ``rigid_ring.json`` document."""
        return {
            "tyredamp_version": __version__,
            "kind": "tyre-rigid-ring",
            "rigid_ring": [
                {"source": s, **r.to_dict(), "uncertainty_budget": b.to_dict()}
                for s, r, b in zip(self.sources, self.rigid, self.budgets, strict=True)
            ],
            "lateral_carcass": [c.to_dict() for c in self.lateral],
            "warnings": list(self.warnings),
        }

    def tir_files(self) -> dict[str, str]:
        """``{file name: text}`` of the ``.tir`` fragments, one per pressure."""
        out: dict[str, str] = {}
        comments = [c.comment() for c in self.lateral] + [f"warning: {w}" for w in self.warnings]
        for s, p, r, b in zip(self.sources, self.pressures, self.rigid, self.budgets, strict=True):
            name = f"tyre_inplane_{p / _BAR:g}bar.tir"
            k = 2
            while name in out:
                name = f"tyre_inplane_{p / _BAR:g}bar_{k}.tir"
                k += 1
            out[name] = tir_text(r, source=s, extra_comments=comments, budget=b)
        return out

    def merged_tir(self, base_text: str, base_name: str, *, force: bool = False) -> str:
        """The identified values merged into a complete base ``.tir`` (:mod:`.tirmerge`).

        The test whose pressure is nearest the base's is used; see
        :func:`~tyredamp.tyremodel.tirmerge.merged_text` for what is refused.
        """
        return merged_text(self, base_text, base_name, force=force)


def build_tyre_model(
    inputs: Sequence[tuple[float, ModalModel, str]],
    *,
    radius: float,
    attachment_mass: float = 0.0,
    attachment_damping: float | None = None,
    mass_per_length: float | None = None,
    foundation_law: FoundationLaw = "linear",
    predict_pressures: Sequence[float] = (),
    lateral: Sequence[LateralCarcass] = (),
    assumptions: Assumptions | None = None,
    force: bool = False,
) -> TyreModelResult:
    """Wave numbers, ring updating, rigid ring and lateral bridge in one call.

    Parameters
    ----------
    inputs : sequence of (pressure, ModalModel, source)
        Identified modes of each test with its pressure in Pa and a name.
    radius : float
        Belt radius in m.
    attachment_mass, attachment_damping, mass_per_length, foundation_law :
        As in :func:`~tyredamp.tyremodel.fit_ring`.
    predict_pressures : sequence of float
        Extra pressures (Pa) at which to predict the ring's modes (needs two
        or more test pressures).
    lateral : sequence of LateralCarcass
        Lateral carcass quantities to carry into the outputs.
    assumptions : Assumptions, optional
        Calibration and attachment uncertainties for the budgets (default
        :class:`~tyredamp.tyremodel.budget.Assumptions`).
    force : bool
        Keep lateral tests at another pressure than the radial ones (with a
        warning) instead of refusing them.

    Raises
    ------
    InputError
        What :mod:`~tyredamp.tyremodel.checks` refuses: unstable modes, the
        same modes or pressure twice, a ring whose tension does not follow
        the pressure, lateral tests at another pressure (without ``force``).
    """
    items = list(inputs)
    if not items:
        raise InputError("inputs: expected at least one modes file")
    for _, mdl, src in items:
        if not isinstance(mdl, ModalModel):
            raise InputError(f"{src}: expected a ModalModel, got {type(mdl).__name__}")
    check_modes(items)
    warnings = check_lateral(lateral, [p for p, _, _ in items], force)
    analyses = []
    obs = []
    skipped = []
    for p, mdl, src in items:
        wa = wave_number_analysis(mdl)
        analyses.append(wa)
        o, s = ring_observations(mdl, p, analysis=wa)
        obs += o
        skipped += [f"{src}: {x}" for x in s]
    ring = fit_ring(
        obs,
        radius=radius,
        attachment_mass=attachment_mass,
        attachment_damping=attachment_damping,
        mass_per_length=mass_per_length,
        foundation_law=foundation_law,
    )
    ring = _with_skipped(ring, skipped)
    check_ring(ring)
    rigid = tuple(
        rigid_ring_from_modes(
            mdl,
            pressure=p,
            analysis=wa,
            attachment_mass=attachment_mass,
            attachment_damping=attachment_damping or 0.0,
            radius=radius,
        )
        for (p, mdl, _), wa in zip(items, analyses, strict=True)
    )
    check_rigid(rigid, [s for _, _, s in items])
    budgets = tuple(
        rigid_ring_budget(
            mdl,
            r,
            analysis=wa,
            attachment_mass=attachment_mass,
            attachment_damping=attachment_damping or 0.0,
            assumptions=assumptions,
        )
        for (_, mdl, _), wa, r in zip(items, analyses, rigid, strict=True)
    )
    preds = _predictions(ring, predict_pressures)
    return TyreModelResult(
        pressures=tuple(float(p) for p, _, _ in items),
        sources=tuple(str(s) for _, _, s in items),
        analyses=tuple(analyses),
        ring=ring,
        rigid=rigid,
        lateral=tuple(lateral),
        predictions=preds,
        budgets=budgets,
        warnings=tuple(warnings),
    )


def _with_skipped(ring: RingFit, skipped: list[str]) -> RingFit:
    from dataclasses import replace

    return replace(ring, skipped=tuple(skipped) + ring.skipped)


def _predictions(ring: RingFit, predict_pressures: Sequence[float]) -> list[dict[str, Any]]:
    """The updated ring's modes at extra pressures (Pa), bare and with the driven member."""
    n_max = max(o.n for o in ring.observations)
    nn = np.arange(1, n_max + 1)
    preds = []
    for pp in predict_pressures:
        f_b, z_b = ring.predict(pp, nn)
        f_d, z_d = ring.predict(pp, nn, drive_phi2=ring.drive_member_phi2(nn))
        preds.append(
            {
                "pressure_bar": pp / _BAR,
                "n": nn.tolist(),
                "frequency_hz_bare": f_b.tolist(),
                "damping_ratio_bare": z_b.tolist(),
                "frequency_hz_driven_member": f_d.tolist(),
                "damping_ratio_driven_member": z_d.tolist(),
                "tension_N": ring.tension(pp)[0],
                "k_r": ring.radial_stiffness(pp)[0],
                "k_t": ring.tangential_stiffness(pp)[0],
            }
        )
    return preds
