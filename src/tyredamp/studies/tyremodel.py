"""The tyre-model step of the demo: flexible and rigid ring from the modes at every pressure.

:func:`tyre_model_from_runs` takes the pressure runs of the radial study and
calls :func:`tyredamp.tyremodel.build_tyre_model` (as ``tyredamp tyre-model``
does) on their complex modes (real ones where a run has no complex fit), with
the belt radius and the shaker attachment (point mass, local damper) of the
tested virtual tyre itself. Beside the result it keeps the tyre's own values:

* the ring parameters of :class:`~tyredamp.virtual.RingTyreParameters`
  under the names of the fit (:func:`ring_truth`; ``T_c = 0``: the virtual
  tension is exactly ``p b R``; ``eta_b = eta / omega_ref``, the band's
  Kelvin-Voigt time constant);
* the rigid-ring parameters computed by the same formulas from the exact
  modes of each tested tyre (``TyreTruth.modal_model("visible")``): the
  reference for the rigid ring;
* the same ring fit on those exact modes (``exact_ring``): the virtual tyre
  is a finite-difference ring (64 nodes), whose discretisation lowers the
  higher modes a little; the continuous ring model reads that as about 3 %
  less ``EI`` even without noise (0.4 % at 128 nodes), so the fit to the
  exact modes tells that part of a gap from the identification's.

A fit that cannot be made (no usable ``n = 1`` mode, too few modes, a
failed least-squares problem) does not stop the demo: the study then holds
the reason (``error``) and no result.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import InputError, TyredampError
from ..tyremodel import RigidRingParameters, build_tyre_model, rigid_ring_from_modes
from ..virtual import MeasurementLayout, RingTyreParameters
from .results import TyreModelStudy
from .settings import BAR

if TYPE_CHECKING:
    from ..modal.model import ModalModel
    from ..tyremodel import RingFit
    from .results import PressureRun

__all__ = [
    "TYRE_MODEL_DIR",
    "TyreModelStudy",
    "ring_truth",
    "ring_verdict_groups",
    "tyre_model_files",
    "tyre_model_from_runs",
    "tyre_model_section",
]

#: What the demo fits: ``build_tyre_model`` may raise these on data it cannot use.
_FIT_ERRORS = (TyredampError, ValueError, ArithmeticError, np.linalg.LinAlgError)


def ring_truth(params: RingTyreParameters, fit: RingFit) -> dict[str, float | None]:
    """The virtual tyre's value of every parameter of ``fit`` (None: no single true value).

    Parameters
    ----------
    params : RingTyreParameters
        The tested tyre (its ``pressure`` is not used: the laws are).
    fit : RingFit
        The updated ring, whose parameter names decide the mapping: several
        pressures with the linear law ``EI, b, T_c, k_r0, k_rp, k_t0, k_tp,
        rhoA``; one pressure ``EI, T0, k_r, k_t, rhoA`` at that pressure;
        damping ``c_r, c_t, eta_b`` (``c_d``: the attachment damper).

    Returns
    -------
    dict of str to float or None
        SI, as the fit's units.
    """
    single = params.with_pressure(float(fit.pressures[0]))
    one_p = fit.pressures.size == 1
    known: dict[str, float | None] = {
        "EI": params.bending_stiffness,
        "b": params.width,
        "T_c": 0.0,
        "k_r0": params.radial_stiffness_base,
        "k_rp": params.radial_stiffness_per_pressure,
        "k_t0": params.tangential_stiffness_base,
        "k_tp": params.tangential_stiffness_per_pressure,
        "rhoA": params.mass_per_length,
        "T0": single.hoop_tension if one_p else None,
        # the "constant" foundation law over several pressures has no single true k_r, k_t
        "k_r": single.radial_stiffness if one_p else None,
        "k_t": single.tangential_stiffness if one_p else None,
        "c_r": params.radial_damping,
        "c_t": params.tangential_damping,
        "eta_b": params.band_loss_factor / (2 * math.pi * params.band_loss_frequency),
    }
    return {n: known.get(n) for n in (*fit.names, *fit.damping_names)}


def _modes(run: PressureRun) -> ModalModel:
    for name in ("complex", "real"):
        if name in run.models:
            return run.models[name]
    raise InputError(f"{run.pressure_bar:g} bar: no modal model identified")


def tyre_model_from_runs(runs: Sequence[PressureRun]) -> TyreModelStudy:
    """Flexible ring across the pressures of ``runs`` and rigid ring per pressure, with truth.

    Parameters
    ----------
    runs : sequence of PressureRun
        The radial study's runs (one per pressure, the same virtual tyre).

    Returns
    -------
    TyreModelStudy
        ``result`` None and ``error`` the reason when the fit cannot be made.
    """
    if not runs:
        return TyreModelStudy(
            result=None,
            error="no pressure run to fit",
            pressures_bar=(),
            params=None,
            layout=None,
            rigid_truth=None,
            models=(),
        )
    tyre = runs[0].test.tyre
    params: RingTyreParameters = tyre.params
    layout: MeasurementLayout = tyre.layout
    pressures = tuple(float(r.pressure_bar) for r in runs)
    kinds = tuple("complex" if "complex" in r.models else "real" for r in runs)
    try:
        res = build_tyre_model(
            [(r.pressure_bar * BAR, _modes(r), f"{r.pressure_bar:g} bar") for r in runs],
            radius=params.radius,
            attachment_mass=layout.attachment_mass,
            attachment_damping=layout.attachment_damping,
        )
    except _FIT_ERRORS as exc:
        return TyreModelStudy(
            result=None,
            error=f"{type(exc).__name__}: {exc}",
            pressures_bar=pressures,
            params=params,
            layout=layout,
            rigid_truth=None,
            models=kinds,
        )
    try:
        exact = build_tyre_model(
            [(r.pressure_bar * BAR, r.truth.modal_model("visible"), "exact") for r in runs],
            radius=params.radius,
            attachment_mass=layout.attachment_mass,
            attachment_damping=layout.attachment_damping,
        ).ring
    except _FIT_ERRORS:
        exact = None
    rigid_truth: list[RigidRingParameters | None] = []
    for r in runs:
        try:
            rigid_truth.append(
                rigid_ring_from_modes(
                    r.truth.modal_model("visible"),
                    pressure=r.pressure_bar * BAR,
                    attachment_mass=layout.attachment_mass,
                    attachment_damping=layout.attachment_damping,
                    radius=params.radius,
                )
            )
        except _FIT_ERRORS:
            rigid_truth.append(None)
    return TyreModelStudy(
        result=res,
        error=None,
        pressures_bar=pressures,
        params=params,
        layout=layout,
        rigid_truth=tuple(rigid_truth),
        models=kinds,
        exact_ring=exact,
    )


# ------------------------------------------------------------------ documents
#: Folder of the demo output holding the tyre-model files.
TYRE_MODEL_DIR = "tyre_model"


def tyre_model_files(study: TyreModelStudy) -> dict[str, dict[str, Any] | str]:
    """The tyre-model files of the demo output by relative path (none when the fit failed).

    ``tyre_model/ring.json`` and ``tyre_model/rigid_ring.json`` (dict: JSON
    documents as ``tyredamp tyre-model`` writes them) and one
    ``tyre_model/tyre_inplane_<p>bar.tir`` per pressure (str: the text).
    """
    res = study.result
    if res is None:
        return {}
    out: dict[str, dict[str, Any] | str] = {
        f"{TYRE_MODEL_DIR}/ring.json": res.ring_document(),
        f"{TYRE_MODEL_DIR}/rigid_ring.json": res.rigid_document(),
    }
    for name, text in res.tir_files().items():
        out[f"{TYRE_MODEL_DIR}/{name}"] = text
    return out


def _compare(value: float, stderr: float, true: float | None) -> dict[str, Any]:
    """Value, standard error, truth and the gap (relative and in standard errors)."""
    rel = None
    sig = None
    if true is not None and true != 0 and math.isfinite(value):
        rel = value / true - 1.0
    if true is not None and math.isfinite(stderr) and stderr > 0:
        sig = (value - true) / stderr
    return {"value": value, "stderr": stderr, "true": true, "relative_gap": rel, "gap_sigma": sig}


def tyre_model_section(study: TyreModelStudy) -> dict[str, Any]:
    """The ``radial.tyre_model`` section of results.json (layout in docs/reference/results-json.md).

    ``status`` ``"ok"`` or ``"failed"`` (then ``error`` says why and the
    other lists are empty); the ring's parameters with standard errors,
    verdicts, the virtual tyre's values and the gaps; tension and foundation
    stiffnesses per pressure; the rigid ring per pressure beside the values
    from the exact modes; the files written.
    """
    res = study.result
    lay = study.layout
    base: dict[str, Any] = {
        "status": "ok" if res is not None else "failed",
        "error": study.error,
        "pressures_bar": list(study.pressures_bar),
        "models": list(study.models),
        "radius_m": None if study.params is None else study.params.radius,
        "attachment_mass_kg": None if lay is None else lay.attachment_mass,
        "attachment_damping_ns_m": None if lay is None else lay.attachment_damping,
        "fit": None,
        "parameters": [],
        "not_identifiable": [],
        "per_pressure": [],
        "rigid_ring": [],
        "files": sorted(tyre_model_files(study)),
    }
    if res is None or study.params is None:
        return base
    ring = res.ring
    truth = ring_truth(study.params, ring)
    exact = study.exact_ring
    params = []
    for row in ring.table():
        name = row["name"]
        ex = None
        if exact is not None and name in (*exact.names, *exact.damping_names):
            ex = exact.param(name)[0]
        params.append(
            {
                "name": row["name"],
                "unit": row["unit"],
                **_compare(float(row["value"]), float(row["stderr"]), truth.get(row["name"])),
                "verdict": row["verdict"],
                "relative_se": row["relative_se"],
                "correlated_with": list(row["correlated_with"]),
                "from_exact_modes": ex,
            }
        )
    per_p = []
    for p in ring.pressures:
        tp = study.params.with_pressure(float(p))
        entry_p: dict[str, Any] = {"pressure_bar": float(p / BAR)}
        for key, fn, tv in (
            ("T0", "tension", tp.hoop_tension),
            ("k_r", "radial_stiffness", tp.radial_stiffness),
            ("k_t", "tangential_stiffness", tp.tangential_stiffness),
        ):
            v, se = getattr(ring, fn)(p)
            entry_p[key] = {
                **_compare(float(v), float(se), tv),
                "from_exact_modes": None if exact is None else float(getattr(exact, fn)(p)[0]),
            }
        per_p.append(entry_p)
    rigid = []
    rt = study.rigid_truth or (None,) * len(res.rigid)
    for r, t in zip(res.rigid, rt, strict=True):
        entry: dict[str, Any] = {
            "pressure_bar": None if r.pressure is None else r.pressure / BAR,
            "splitting_hz": r.splitting_hz,
            "not_given": dict(r.not_given),
        }
        for key, attr, unit in (
            ("BELT_MASS", "belt_mass", "kg"),
            ("FREQ_LONG", "freq_long", "Hz"),
            ("DAMP_LONG", "damp_long", "1"),
            ("k_long", "k_long", "N/m"),
            ("c_long", "c_long", "N s/m"),
        ):
            rtv = None if t is None else float(getattr(t, attr))
            entry[key] = {
                "unit": unit,
                **_compare(float(getattr(r, attr)), float(getattr(r, f"{attr}_std")), rtv),
            }
        rigid.append(entry)
    base.update(
        {
            "fit": {
                "weights": ring.weights,
                "n_modes": len(ring.observations),
                "chi2": ring.chi2,
                "dof": ring.dof,
                "p_value": ring.p_value,
                "scaled_covariance": ring.scaled_covariance,
                "foundation_law": ring.foundation_law,
                "fit_time_s": ring.fit_time_s,
                "skipped": list(ring.skipped),
            },
            "parameters": params,
            "not_identifiable": [p["name"] for p in params if p["verdict"] != "identified"],
            "per_pressure": per_p,
            "rigid_ring": rigid,
        }
    )
    return base


def ring_verdict_groups(section: dict[str, Any]) -> dict[str, list[str]]:
    """The ring parameters of a :func:`tyre_model_section` that are not
    identified, split by verdict: ``"model-limited"`` (a value with a
    model-error term) and ``"not identified"`` (the others), in their order."""
    verdict = {p["name"]: str(p["verdict"]) for p in section["parameters"]}
    names = section["not_identifiable"]
    limited = [n for n in names if verdict[n].startswith("model-limited")]
    return {"model-limited": limited, "not identified": [n for n in names if n not in limited]}
