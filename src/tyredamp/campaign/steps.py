"""The one place where the campaign knows how a test is processed.

A *study* (``"radial"`` or ``"lateral"``) is a chain of named *steps*; each
step takes the test file, the documents of the steps before it and its own
settings, and returns one JSON-ready document. The rest of
:mod:`tyredamp.campaign` (spec, cache, runner, tracking, outputs) only sees
step names, settings dictionaries and documents, never the processing
itself, so pointing this module at :mod:`tyredamp.studies` changes nothing
else.

The steps are those of :data:`tyredamp.studies.registry.STEPS`, run with
their typed settings (:mod:`tyredamp.studies.steps`), the very ``run`` the
single-test commands call, and their documents are those of
:mod:`tyredamp.documents` (the files the commands write); the chain of each
study is :data:`tyredamp.studies.registry.STUDIES`:

* radial ``modal``: :func:`tyredamp.io.read` (time data or FRFs); for time
  data :class:`~tyredamp.studies.steps.FrfStep` as ``tyredamp frf``;
  :class:`~tyredamp.studies.steps.QualityStep` as ``tyredamp check
  quality``; :class:`~tyredamp.studies.steps.ModalStep` (modes, wave
  numbers, verdicts) as ``tyredamp modal``; the document is its modes
  document (``docs/modes-json.md``) with a ``"campaign"`` entry holding the
  FRF summary and the quality check;
* radial ``damping``: :class:`~tyredamp.studies.steps.DampingStep` on the
  models of that modes document
  (:func:`tyredamp.documents.modes.models_from_document`), as ``tyredamp
  damping``; the document is
  :func:`tyredamp.documents.damping.damping_document` (``docs/damping-json.md``);
* lateral ``fit``: :class:`~tyredamp.studies.steps.LateralFitStep` as
  ``tyredamp lateral fit`` (a test where no model fits fails with the
  reasons); the document is
  :func:`tyredamp.documents.lateral.lateral_fit_document`;
* any other registered step of a chain: its ``run_file(path, upstream,
  settings, conditions)``.

Skipped steps
-------------
A step that cannot run on a test's data is *skipped*, not failed: it raises
:class:`StepSkipped` with the reason in words (which step, why, what data
would let it run) before any computation, and the campaign records a *skip
document* (:func:`skip_document`, ``kind`` ``"tyredamp-campaign-skip"``) in
the step's place. A skip is cached under the step's key like any result
(the same file, settings and tyredamp give the same skip), and every later
step of the test is skipped with it. A *failed* step is a genuine error (a
corrupt file, no modes, a bad setting); a step that ran but whose quality
check or fit verdict failed has its document like any other. The radial
``damping`` step is skipped when

* the tracked model has fewer response points (outputs) than modes: the
  damping matrix in physical coordinates inverts the real parts of the
  shapes at the points (``N >= m``); or
* no response was measured at an excitation point (no drive point): the
  shapes are then not mass-normalised and ``C'`` has no physical scale.

Settings
--------
Each study's settings are a nested dictionary ``{section: {key: value}}``,
one section per step of its chain (the modal step also reads the ``frf`` and
``checks`` sections): the fields of the step's settings class with their
defaults (the single-test commands' defaults), plus the step's switch
(``damping.enabled``, ``checks.quality``) when it has one; see
``docs/campaign.md``. :func:`validate_settings` checks a campaign file's
table against the classes (unknown keys refused); :func:`settings_schema`
gives the ``settings`` part of the campaign file's JSON schema.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import InputError
from ..studies import registry as _registry
from ..studies.steps import knobs
from .skips import (
    SKIP_KIND,
    StepSkipped,
    damping_skip_reason,
    is_skip,
    skip_document,
    upstream_skip,
)

__all__ = [
    "DEFAULTS",
    "SKIP_KIND",
    "STUDIES",
    "StepSkipped",
    "StudySteps",
    "TestResult",
    "damping_skip_reason",
    "is_skip",
    "mode_records",
    "process_lateral_test",
    "process_radial_test",
    "run_step",
    "skip_document",
    "step_settings",
    "validate_settings",
]

#: The studies a campaign test can belong to, and their chains of steps (the registry's).
STUDIES = _registry.STUDIES
#: Kept for readers of the old name: a study's chain of steps.
StudySteps = _registry.Study


def _section_defaults(section: str) -> dict[str, Any]:
    step = _registry.STEPS[section]
    switch = getattr(step, "switch", None)
    table = {switch: True} if switch else {}
    return {**table, **_registry.settings_class(section).defaults()}


def defaults(study: str) -> dict[str, dict[str, Any]]:
    """The default settings of ``study``, ``{section: {key: value}}`` (from the step classes)."""
    return {sec: _section_defaults(sec) for sec in STUDIES[study].sections}


#: Default settings of each study (the defaults of the single-test commands), from the
#: settings classes of :mod:`tyredamp.studies.steps` when this module was imported.
DEFAULTS: dict[str, dict[str, dict[str, Any]]] = {s: defaults(s) for s in STUDIES}


def validate_settings(study: str, table: Any, where: str) -> dict[str, dict[str, Any]]:
    """Check one study's settings table and fill in the defaults.

    Each section is the settings class of its step
    (:func:`tyredamp.studies.registry.settings_class`; unknown keys refused),
    plus the step's switch (``enabled``, ``quality``) when it has one.

    Parameters
    ----------
    study : str
        ``"radial"`` or ``"lateral"``.
    table : dict or None
        ``{section: {key: value}}`` from the campaign file (missing sections
        and keys take the defaults).
    where : str
        Prefix for error messages (file and key path).

    Returns
    -------
    dict
        The complete settings, ``{section: {key: value}}`` (JSON-ready).

    Raises
    ------
    InputError
        Unknown study, section or key, or a bad value (the message names it).
    """
    if study not in STUDIES:
        raise InputError(f"{where}: unknown study {study!r}; expected one of {sorted(STUDIES)}")
    table = {} if table is None else table
    if not isinstance(table, dict):
        raise InputError(f"{where}: expected a table of sections, got {table!r}")
    sections = STUDIES[study].sections
    unknown = sorted(set(table) - set(sections))
    if unknown:
        raise InputError(
            f"{where}: unknown section {unknown[0]!r}; expected one of {sorted(sections)}"
        )
    out: dict[str, dict[str, Any]] = {}
    for section in sections:
        given = table.get(section, {})
        if not isinstance(given, dict):
            raise InputError(f"{where}.{section}: expected a table, got {given!r}")
        given = dict(given)
        switch = getattr(_registry.STEPS[section], "switch", None)
        head: dict[str, Any] = {}
        if switch:
            on = given.pop(switch, True)
            if not isinstance(on, bool):
                raise InputError(f"{where}.{section}.{switch}: expected true or false, got {on!r}")
            head[switch] = on
        cls = _registry.settings_class(section)
        unknown = sorted(set(given) - set(knobs(cls)))
        if unknown:
            raise InputError(
                f"{where}.{section}: unknown key {unknown[0]!r}; "
                f"expected one of {sorted([*head, *knobs(cls)])}"
            )
        settings = cls.from_mapping(given, f"{where}.{section}")
        out[section] = {**head, **settings.to_dict()}
    return out


def settings_schema() -> dict[str, Any]:
    """The ``settings`` part of the campaign file's JSON schema, from the step classes.

    ``tyredamp/schemas/campaign.schema.json`` holds it as written by this
    function (a test compares them).
    """
    import inspect

    studies: dict[str, Any] = {}
    for study, chain in STUDIES.items():
        props: dict[str, Any] = {}
        for section in chain.sections:
            cls = _registry.settings_class(section)
            sec = cls.schema()
            switch = getattr(_registry.STEPS[section], "switch", None)
            if switch:
                on = {
                    "type": "boolean",
                    "default": True,
                    "description": f"false: the campaign does not run the {section} step.",
                }
                sec["properties"] = {switch: on, **sec["properties"]}
            text = " ".join((inspect.getdoc(cls) or "").split("\n\n")[0].split())
            props[section] = {"description": text, **sec}
        studies[study] = {"type": "object", "additionalProperties": False, "properties": props}
    return {"type": "object", "additionalProperties": False, "properties": studies}


def section_settings(section: str, table: Mapping[str, Any]) -> Any:
    """The typed settings of one validated section (its switch left out)."""
    switch = getattr(_registry.STEPS[section], "switch", None)
    cls = _registry.settings_class(section)
    return cls.from_mapping({k: v for k, v in table.items() if k != switch})


def step_settings(study: str, step: str, settings: Mapping[str, Any]) -> dict[str, Any]:
    """The part of a study's ``settings`` that ``step``'s result depends on (for its key)."""
    return {s: settings[s] for s in STUDIES[study].settings_of[step]}


def step_conditions(study: str, step: str, conditions: Mapping[str, Any]) -> dict[str, Any]:
    """The test conditions that ``step``'s result depends on (for its key)."""
    return {c: conditions.get(c) for c in STUDIES[study].conditions_of.get(step, ())}


def step_enabled(study: str, step: str, settings: Mapping[str, Any]) -> bool:
    """False when an optional step is switched off in ``settings``."""
    switch = getattr(_registry.STEPS[step], "switch", None)
    if not switch:
        return True
    return bool(settings[step].get(switch, True))


# ------------------------------------------------------------------ steps
def plain(doc: Any) -> Any:
    """``doc`` as it reads back from its strict JSON file (NaN as None, plain types).

    Every step document passes through this at once, so a result computed now
    and one read from the cache are the same objects, bit for bit.
    """
    from ..documents.jsonfile import json_text

    return json.loads(json_text(doc, indent=0))


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _check_dict(res: Any) -> dict[str, Any]:
    return {
        "name": str(res.name),
        "passed": bool(res.passed),
        "figure": float(res.figure),
        "threshold": float(res.threshold),
        "summary": str(res.summary),
        "figures": {k: float(v) for k, v in res.figures.items()},
        "notes": list(res.notes),
    }


def _radial_modal(
    path: Path, upstream: Mapping[str, Any], settings: Mapping[str, Any], conditions: Any
) -> dict[str, Any]:
    """``tyredamp frf`` (time data only), ``check quality`` and ``tyredamp modal``."""
    from ..frf import FRF
    from ..io import ChannelMap, read
    from ..signal.checks import dependent_forces
    from ..studies.steps import FrfStep, ModalStep, QualityStep

    obj = read(path, ChannelMap.from_dict((conditions or {}).get("channel_map") or {}))
    if not isinstance(obj, FRF):  # output-only data: said in one line, with what to do
        obj.require_force("the modal step (an FRF from time data)", path.name)
    if isinstance(obj, FRF):
        frf = obj
        source_kind = "frf"
    else:
        fs = section_settings("frf", settings["frf"])
        dep = dependent_forces(obj) if len(obj.force_indices) > 1 and not fs.reference else []
        if dep:  # every force channel is an input: refused as 'tyredamp frf' does
            k, r2, uses = dep[0]
            lab = obj.channels
            raise InputError(
                f"{path.name}: force {lab[k].label} is {100 * r2:.4g} % a linear combination "
                f"of {' and '.join(lab[i].label for i in uses)}: the forces are not "
                "independent excitations (one is a reaction); give the FRFs, or time data "
                "with the excitation forces only"
            )
        frf, _ = FrfStep.run(obj, fs, "settings.radial.frf.")
        source_kind = "time"
    quality = None
    if step_enabled("radial", "checks", settings):
        quality, _ = QualityStep.run(obj, section_settings("checks", settings["checks"]))
    res, verdicts = ModalStep.run(frf, section_settings("modal", settings["modal"]))
    doc = ModalStep.document(res, verdicts, source=path.name)
    doc["campaign"] = {
        "input": source_kind,
        "n_out": frf.n_out,
        "n_in": frf.n_in,
        "n_lines": int(res.frequency.size),
        "quality": None if quality is None else _check_dict(quality),
        "warnings": list(res.warnings),
    }
    return doc


def _radial_damping(
    path: Path, upstream: Mapping[str, Any], settings: Mapping[str, Any], conditions: Any
) -> dict[str, Any]:
    """``tyredamp damping`` on the modes document of the modal step."""
    from ..documents.modes import models_from_document
    from ..studies.steps import DampingStep

    ds = section_settings("damping", settings["damping"])
    skip = damping_skip_reason(upstream["modal"], ds.model)
    if skip is not None:
        raise skip
    models = models_from_document(dict(upstream["modal"]))
    if ds.model not in models:
        raise InputError(
            f"settings.radial.damping.model: the modes hold models {sorted(models)}, "
            f"not {ds.model!r}"
        )
    dm, _ = DampingStep.run(models, ds, meta={"source": path.name, "model": ds.model})
    return DampingStep.document(dm)


def _lateral_fit(
    path: Path, upstream: Mapping[str, Any], settings: Mapping[str, Any], conditions: Any
) -> dict[str, Any]:
    """``tyredamp lateral fit`` with the test's speed."""
    from ..io import read_frf
    from ..studies.steps import LateralFitStep

    frf = read_frf(path)
    speed_kmh = None if conditions is None else conditions.get("speed_kmh")
    result, _ = LateralFitStep.run(
        frf,
        section_settings("fit", settings["fit"]),
        speed_kmh=None if speed_kmh is None else float(speed_kmh),
        source=path.name,
    )
    return LateralFitStep.document(result, source=path.name, frf_kind=frf.kind)


#: The campaign's own recipes of the built-in steps (a registered step that is not
#: here runs with its ``run_file``).
_STEP_FUNCTIONS: dict[str, Callable[..., dict[str, Any]]] = {
    "modal": _radial_modal,
    "damping": _radial_damping,
    "fit": _lateral_fit,
}


def _step_function(step: str) -> Callable[..., dict[str, Any]]:
    fn = _STEP_FUNCTIONS.get(step)
    if fn is None:
        fn = _registry.STEPS[step].run_file
    return fn


def run_step(
    study: str,
    step: str,
    path: str | Path,
    upstream: Mapping[str, Any],
    settings: Mapping[str, Any],
    conditions: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Run one step of a study on one test file; returns its JSON-ready document.

    Parameters
    ----------
    study, step : str
        A study of :data:`STUDIES` and one of its steps.
    path : path
        The test file (read only).
    upstream : dict of str to dict
        Documents of the earlier steps of this test, by step name.
    settings : dict
        The study's complete settings (:func:`validate_settings`).
    conditions : dict, optional
        The test's conditions (the lateral fit uses ``speed_kmh``).

    Raises
    ------
    StepSkipped
        The step cannot run on this test's data (or a step before it was
        skipped): the reason in words.
    """
    skip = upstream_skip(STUDIES[study].steps, step, upstream)
    if skip is not None:
        raise skip
    fn = _step_function(step)
    return fn(Path(path), upstream, settings, conditions)


@dataclass(frozen=True)
class TestResult:
    """The documents of one test, by step name (``modal``, ``damping`` or ``fit``).

    ``skipped`` holds the skip document (:func:`skip_document`) of every step
    that could not run on the test's data, by step name.
    """

    __test__ = False  # not a pytest class

    study: str
    documents: dict[str, dict[str, Any]]
    skipped: dict[str, dict[str, Any]] = field(default_factory=dict)


def _process(
    study: str, path: str | Path, conditions: Mapping[str, Any] | None, settings: Any
) -> TestResult:
    full = validate_settings(study, settings, f"settings.{study}")
    docs: dict[str, dict[str, Any]] = {}
    for step in STUDIES[study].steps:
        if step_enabled(study, step, full):
            try:
                docs[step] = plain(run_step(study, step, path, docs, full, conditions))
            except StepSkipped as skip:
                docs[step] = skip_document(study, step, skip.why, skip.needs)
    return TestResult(
        study,
        {k: v for k, v in docs.items() if not is_skip(v)},
        {k: v for k, v in docs.items() if is_skip(v)},
    )


def process_radial_test(
    path: str | Path, conditions: Mapping[str, Any] | None = None, settings: Any = None
) -> TestResult:
    """Process one radial modal test (time data or FRFs) without any cache.

    ``settings`` is the radial settings table (``{section: {key: value}}``,
    defaults of :data:`DEFAULTS`). Returns the ``modal`` and ``damping``
    documents (the damping step skipped, with its reason, when the test's
    data cannot give a damping matrix).
    """
    return _process("radial", path, conditions, settings)


def process_lateral_test(
    path: str | Path, conditions: Mapping[str, Any] | None = None, settings: Any = None
) -> TestResult:
    """Process one lateral FRF test without any cache; returns the ``fit`` document."""
    return _process("lateral", path, conditions, settings)


def run_steps_from_bytes(
    study: str,
    name: str,
    data: bytes,
    steps: Sequence[str],
    upstream: Mapping[str, Any],
    settings: Mapping[str, Any],
    conditions: Mapping[str, Any] | None,
) -> tuple[dict[str, dict[str, Any]], tuple[str, str] | None]:
    """Run ``steps`` on a test given as its bytes (written to a private scratch copy).

    The file gets its original base name ``name`` so that readers which
    dispatch on the extension, and documents that record the source name,
    see the same thing wherever this runs (in-process or on any worker).

    Returns
    -------
    documents : dict of str to dict
        The documents of the steps that finished (as :func:`plain` gives them),
        a skip document (:func:`skip_document`) for a step that could not run.
    failure : (str, str) or None
        The step that failed and its one-line reason; the later steps are not run.
    """
    docs: dict[str, dict[str, Any]] = dict(upstream)
    new: dict[str, dict[str, Any]] = {}
    from .scratch import scratch_dir

    with scratch_dir() as scratch:
        tmp = str(scratch)
        path = scratch / Path(name).name
        path.write_bytes(data)
        for step in steps:
            try:
                doc = plain(run_step(study, step, path, docs, settings, conditions))
            except StepSkipped as skip:  # not a failure: recorded (and cached) as a skip
                doc = skip_document(study, step, skip.why, skip.needs)
            except Exception as exc:  # any failure of one test is that test's result
                # name the test file as the campaign knows it, not the temporary copy
                reason = _one_line(exc).replace(str(path), name).replace(tmp, "")
                return new, (step, reason)
            docs[step] = doc
            new[step] = doc
    return new, None


# ------------------------------------------------------------------ results as rows
def _complex_vec(rows: Any) -> NDArray:
    a = np.asarray(rows, dtype=float).reshape(-1, 2)
    return a[:, 0] + 1j * a[:, 1]


def mode_records(study: str, documents: Mapping[str, Any], model: str = "complex") -> list[dict]:
    """One record per identified mode of a test (for the tidy table and the tracking).

    Each record: ``mode`` (1-based), ``model``, ``frequency_hz``,
    ``frequency_std_hz``, ``damping_ratio``, ``damping_ratio_std``, ``mpc``,
    ``modal_damping`` and ``modal_damping_std`` (the diagonal ``C'_nn`` in 1/s
    and its standard error, from the damping step when there is one),
    ``points`` (output labels; input labels when the shapes are at the
    inputs, a roving-hammer test), ``angles_deg`` (the points' angular
    positions in deg, None where a channel has none), ``reference_deg`` (the
    first excitation's angle, 0 when unknown; the fixed response's angle for
    a roving-hammer test, the same point by reciprocity) and ``shape``
    (complex, one per point). A lateral test has no modes (empty list).
    """
    if study == "rolling":  # output-only: the fixed-frame modes, no MPC or damping matrix
        return _rolling_records(documents)
    if study != "radial" or "modal" not in documents or is_skip(documents["modal"]):
        return []
    models = documents["modal"]["models"]
    name = model if model in models else sorted(models)[0]
    m = models[name]
    # the shapes where they are: the inputs of a roving-hammer test (modes JSON "shapes_at")
    at_inputs = m.get("shapes_at") == "inputs"
    points = [
        str(o.get("name") or f"{o.get('node')}{o.get('direction', '')}")
        for o in m["inputs" if at_inputs else "outputs"]
    ]
    at = m["inputs" if at_inputs else "outputs"]
    angles = [None if o.get("angle_deg") is None else float(o["angle_deg"]) for o in at]
    fixed = m.get("outputs" if at_inputs else "inputs") or []
    refs = [float(c["angle_deg"]) for c in fixed if c.get("angle_deg") is not None]
    reference = refs[0] if refs else 0.0
    damp = documents.get("damping")
    if is_skip(damp):
        damp = None
    cdiag: list[float] | None = None
    cstd: list[float] | None = None
    if damp is not None and damp.get("meta", {}).get("model") == name:
        cp = np.asarray(damp["modal"], dtype=float)
        if cp.shape == (len(m["modes"]), len(m["modes"])):
            cdiag = np.diag(cp).tolist()
            std = damp.get("std", {}).get("modal")
            if std is not None:
                cstd = np.diag(np.asarray(std, dtype=float)).tolist()
    mpc = m.get("meta", {}).get("mpc") or [None] * len(m["modes"])
    out = []
    for i, md in enumerate(m["modes"]):
        std = md.get("std", {})
        out.append(
            {
                "mode": i + 1,
                "model": name,
                "frequency_hz": md["frequency_hz"],
                "frequency_std_hz": std.get("frequency_hz"),
                "damping_ratio": md["damping_ratio"],
                "damping_ratio_std": std.get("damping_ratio"),
                "mpc": mpc[i],
                "modal_damping": None if cdiag is None else cdiag[i],
                "modal_damping_std": None if cstd is None else cstd[i],
                "points": points,
                "angles_deg": angles,
                "reference_deg": reference,
                "shape": _complex_vec(md["participation" if at_inputs else "shape"]),
            }
        )
    return out


def _rolling_records(documents: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The fixed-frame modes of the ``rolling`` step as :func:`mode_records` records."""
    doc = documents.get("rolling")
    if doc is None or is_skip(doc):
        return []
    angles = [float(a) for a in doc.get("angles_deg", [])]
    return [
        {
            "mode": i + 1,
            "model": "output-only",
            "frequency_hz": md["frequency_hz"],
            "frequency_std_hz": md.get("std_frequency_hz"),
            "damping_ratio": md["damping_ratio"],
            "damping_ratio_std": md.get("std_damping_ratio"),
            "mpc": None,
            "modal_damping": None,
            "modal_damping_std": None,
            "points": list(doc.get("points", [])),
            "angles_deg": angles,
            "reference_deg": 0.0,
            "shape": _complex_vec(md["shape"]),
        }
        for i, md in enumerate(doc.get("modes", []))
    ]


def lateral_records(documents: Mapping[str, Any]) -> list[dict[str, Any]]:
    """One record per fitted lateral model of a test: rank, name, BIC/AIC, parameters."""
    doc = documents.get("fit")
    if doc is None or is_skip(doc):
        return []
    ranks = {row["model"]: row for row in doc["table"]}
    out = []
    for f in doc["fits"]:
        row = ranks.get(f["model"], {})
        out.append(
            {
                "model": f["model"],
                "rank": row.get("rank"),
                "aic": f.get("aic"),
                "bic": f.get("bic"),
                "amplitude_error": f.get("amplitude_error"),
                "params": dict(f.get("params", {})),
                "stderr": dict(f.get("stderr", {})),
                "units": dict(f.get("units", {})),
                "at_bound": list(f.get("at_bound", [])),
            }
        )
    return out


def failure_reason(exc: BaseException) -> str:
    """The one-line reason of a failed step."""
    return _one_line(exc)


NDArray = np.ndarray
