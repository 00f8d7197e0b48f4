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

A tangential test at a pressure (``tangential=``) adds the belt's wind-up
(``FREQ_WINDUP``, ``DAMP_WINDUP``, ``BELT_IYY``, :mod:`.windup`) to that
pressure's rigid ring, budget and ``.tir``.
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
from .windup import WINDUP_KEYS, WindupParameters, windup_budget, windup_from_modes

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
        Uncertainty budget of each pressure's rigid-ring values (and wind-up).
    warnings : tuple of str
    windups : tuple of WindupParameters or None
        The wind-up of each pressure from its tangential test (None: no
        tangential test at that pressure).
    tangential_sources : tuple of str or None
        The tangential test of each pressure.
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
    windups: tuple[WindupParameters | None, ...] = ()
    tangential_sources: tuple[str | None, ...] = ()

    def windup(self, k: int) -> WindupParameters | None:
        """The wind-up of input ``k`` (None without a tangential test)."""
        return self.windups[k] if k < len(self.windups) else None

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
                {
                    "source": s,
                    **r.to_dict(),
                    **_windup_entry(self.windup(k), self.tangential_source(k), r),
                    "uncertainty_budget": b.to_dict(),
                }
                for k, (s, r, b) in enumerate(
                    zip(self.sources, self.rigid, self.budgets, strict=True)
                )
            ],
            "lateral_carcass": [c.to_dict() for c in self.lateral],
            "warnings": list(self.warnings),
        }

    def tir_files(self) -> dict[str, str]:
        """``{file name: text}`` of the ``.tir`` fragments, one per pressure."""
        out: dict[str, str] = {}
        comments = [c.comment() for c in self.lateral] + [f"warning: {w}" for w in self.warnings]
        rows = zip(self.sources, self.pressures, self.rigid, self.budgets, strict=True)
        for i, (s, p, r, b) in enumerate(rows):
            name = f"tyre_inplane_{p / _BAR:g}bar.tir"
            k = 2
            while name in out:
                name = f"tyre_inplane_{p / _BAR:g}bar_{k}.tir"
                k += 1
            ts = self.tangential_source(i)
            src = s if ts is None else f"{s} (radial), {ts} (tangential)"
            out[name] = tir_text(
                r, source=src, extra_comments=comments, budget=b, windup=self.windup(i)
            )
        return out

    def tangential_source(self, k: int) -> str | None:
        """The tangential test of input ``k``, if any."""
        return self.tangential_sources[k] if k < len(self.tangential_sources) else None

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
    tangential: Sequence[tuple[float | None, ModalModel, str]] = (),
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
    tangential : sequence of (pressure or None, ModalModel, source)
        Identified modes of tangential tests (:mod:`.windup`), each paired
        with the radial test of the same pressure (within 2 %; a test without
        a pressure goes with the only radial test).

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
    pairs, windups, budgets = _with_windups(
        items, tangential, budgets, radius, attachment_mass, attachment_damping or 0.0, assumptions
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
        windups=windups,
        tangential_sources=tuple(None if t is None else t[2] for t in pairs),
    )


_Test = tuple[float | None, ModalModel, str]


def _with_windups(
    items: list[tuple[float, ModalModel, str]],
    tangential: Sequence[_Test],
    budgets: tuple[UncertaintyBudget, ...],
    radius: float,
    attachment_mass: float,
    attachment_damping: float,
    assumptions: Assumptions | None,
) -> tuple[list[_Test | None], tuple[WindupParameters | None, ...], tuple[UncertaintyBudget, ...]]:
    """The tangential test, wind-up and joined budget of each radial pressure (:mod:`.windup`)."""
    pairs = _pair_tangential(tangential, [p for p, _, _ in items])
    windups = tuple(
        None
        if t is None
        else windup_from_modes(
            t[1],
            radius=radius,
            pressure=items[i][0],
            attachment_mass=attachment_mass,
            attachment_damping=attachment_damping,
            source=t[2],
        )
        for i, t in enumerate(pairs)
    )
    for w, t in zip(windups, pairs, strict=True):
        if w is not None and t is not None and not (w.damp_windup > 0 and w.belt_iyy > 0):
            raise InputError(
                f"{t[2]}: the wind-up damping ratio is {w.damp_windup:.3g} once the attachment "
                "damping is removed: the given attachment damping exceeds the measured losses "
                "(a .tir with a negative damper would be unstable)"
            )
    budgets = tuple(
        b
        if w is None or t is None
        else b.joined(
            windup_budget(
                t[1],
                w,
                analysis=wave_number_analysis(t[1]),
                attachment_mass=attachment_mass,
                attachment_damping=attachment_damping,
                assumptions=assumptions,
            )
        )
        for b, w, t in zip(budgets, windups, pairs, strict=True)
    )
    return pairs, windups, budgets


def _pair_tangential(
    tangential: Sequence[tuple[float | None, ModalModel, str]], pressures: list[float]
) -> list[tuple[float | None, ModalModel, str] | None]:
    """The tangential test of each radial pressure (or None); refuses unpaired tests."""
    out: list[tuple[float | None, ModalModel, str] | None] = [None] * len(pressures)
    for t in tangential:
        p, mdl, src = t
        if not isinstance(mdl, ModalModel):
            raise InputError(f"{src}: expected a ModalModel, got {type(mdl).__name__}")
        if p is None:
            if len(pressures) != 1:
                raise InputError(
                    f"{src}: the tangential test records no pressure and there are "
                    f"{len(pressures)} radial tests; give its pressure (command line: "
                    "--tangential-pressure)"
                )
            k = 0
        else:
            near = [i for i, q in enumerate(pressures) if abs(q - p) <= 0.02 * q]
            if not near:
                have = ", ".join(f"{q / _BAR:g}" for q in pressures)
                raise InputError(
                    f"{src}: tangential test at {p / _BAR:g} bar, but the radial tests are at "
                    f"{have} bar; the wind-up is written beside a radial test of its pressure"
                )
            k = near[0]
        if out[k] is not None:
            raise InputError(
                f"{src}: a second tangential test at {pressures[k] / _BAR:g} bar "
                f"(the first: {out[k][2]})"  # type: ignore[index]
            )
        out[k] = t
    return out


def _windup_entry(
    w: WindupParameters | None, source: str | None, r: RigidRingParameters
) -> dict[str, Any]:
    """The wind-up keys of one pressure's ``rigid_ring.json`` entry and what is left."""
    if w is None:
        return {}
    left = {k: v for k, v in r.not_given.items() if k not in WINDUP_KEYS}
    return {"tangential_source": source, "windup": w.to_dict(), "not_given": left}


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
