"""The one place where the campaign knows how a test is processed.

A *study* (``"radial"`` or ``"lateral"``) is a chain of named *steps*; each
step takes the test file, the documents of the steps before it and its own
settings, and returns one JSON-ready document. The rest of
:mod:`tyredamp.campaign` (spec, cache, runner, tracking, outputs) only sees
step names, settings dictionaries and documents, never the processing
itself, so pointing this module at :mod:`tyredamp.studies` changes nothing
else.

The steps are those of :mod:`tyredamp.studies`, called with the same
arguments and defaults as the single-test commands, and their documents are
those of :mod:`tyredamp.documents` (the files the commands write):

* radial ``modal``: :func:`tyredamp.io.read` (time data or FRFs); for time
  data :func:`tyredamp.studies.radial.frf_from_time` as ``tyredamp frf``;
  :func:`tyredamp.studies.radial.check_quality` as ``tyredamp check
  quality``; :func:`tyredamp.studies.radial.modes_from_frf`,
  :func:`tyredamp.studies.radial.label_wave_numbers` and
  :func:`tyredamp.studies.verdicts.modal_verdicts` as ``tyredamp modal``;
  the document is :func:`tyredamp.documents.modes.modes_document` (the modes
  JSON, ``docs/modes-json.md``) with a ``"campaign"`` entry holding the FRF
  summary and the quality check;
* radial ``damping``: :func:`tyredamp.studies.radial.damping_from_modes` on
  the models of that modes document
  (:func:`tyredamp.documents.modes.models_from_document`), as ``tyredamp
  damping``; the document is
  :func:`tyredamp.documents.damping.damping_document` (``docs/damping-json.md``);
* lateral ``fit``: :func:`tyredamp.studies.lateral.lateral_data` and
  :func:`tyredamp.studies.lateral.fit_models` as ``tyredamp lateral fit``
  (a test where no model fits fails with the reasons); the document is
  :func:`tyredamp.documents.lateral.lateral_fit_document`.

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
Each study's settings are a nested dictionary ``{step: {key: value}}`` with
the defaults of :data:`DEFAULTS` (the single-test commands' defaults); see
``docs/campaign.md``. :func:`validate_settings` checks a campaign file's
table against them.
"""

from __future__ import annotations

import json
import math
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import InputError
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

_ESTIMATORS = ("H1", "H2", "Hv")
_FRF_METHODS = ("auto", "cyclic", "welch", "transient", "lrm", "lpm")
_MODAL_MODELS = ("both", "real", "complex")
_DAMPING_METHODS = ("first", "improved", "refined")
_WEIGHTS = ("auto", "relative", "coherence", "uniform")

#: Default settings of each study (the defaults of the single-test commands).
DEFAULTS: dict[str, dict[str, dict[str, Any]]] = {
    "radial": {
        "frf": {"estimator": "H1", "method": "auto", "segment": None, "band": None},
        "checks": {"quality": True, "coherence_min": 0.9, "max_low_fraction": 0.1},
        "modal": {
            "band": None,
            "model": "both",
            "n_modes": None,
            "frequencies": None,
            "max_order": None,
            "order_step": 2,
            "residuals": True,
        },
        "damping": {
            "enabled": True,
            "method": "improved",
            "model": "complex",
            "samples": 200,
            "seed": 0,
            "normalise": True,
        },
    },
    "lateral": {
        "fit": {
            "models": None,
            "force": None,
            "wheel_mass_kg": None,
            "band": None,
            "weights": "auto",
            "criterion": "bic",
            "channel": None,
        },
    },
}


@dataclass(frozen=True)
class StudySteps:
    """The chain of steps of one study.

    Attributes
    ----------
    name : str
        ``"radial"`` or ``"lateral"``.
    steps : tuple of str
        Step names in order; a step's cache key includes the keys of the steps
        before it.
    settings_of : dict of str to tuple of str
        For each step, the settings sections (keys of the study's settings)
        its result depends on.
    optional : frozenset of str
        Steps that are skipped when their ``enabled`` setting is false.
    conditions_of : dict of str to tuple of str
        For each step, the test conditions its result depends on (part of its
        cache key; the lateral fit uses the speed).
    """

    name: str
    steps: tuple[str, ...]
    settings_of: dict[str, tuple[str, ...]]
    optional: frozenset[str] = field(default_factory=frozenset)
    conditions_of: dict[str, tuple[str, ...]] = field(default_factory=dict)


#: The studies a campaign test can belong to.
STUDIES: dict[str, StudySteps] = {
    "radial": StudySteps(
        "radial",
        ("modal", "damping"),
        {"modal": ("frf", "checks", "modal"), "damping": ("damping",)},
        frozenset({"damping"}),
        conditions_of={"modal": ("channel_map",)},  # the test's channel map (time data)
    ),
    "lateral": StudySteps(
        "lateral", ("fit",), {"fit": ("fit",)}, conditions_of={"fit": ("speed_kmh",)}
    ),
}


# ------------------------------------------------------------------ settings
def _band(value: Any, where: str) -> list[float] | None:
    if value is None:
        return None
    if (
        not isinstance(value, list | tuple)
        or len(value) != 2
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    ):
        raise InputError(f"{where}: expected [f_lo, f_hi] in Hz, got {value!r}")
    lo, hi = float(value[0]), float(value[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise InputError(f"{where}: expected 0 <= f_lo < f_hi, got {value!r}")
    return [lo, hi]


def _choice(options: Sequence[str]) -> Callable[[Any, str], Any]:
    def check(value: Any, where: str) -> Any:
        if value not in options:
            raise InputError(f"{where}: expected one of {list(options)}, got {value!r}")
        return value

    return check


def _boolean(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise InputError(f"{where}: expected true or false, got {value!r}")
    return value


def _int_min(lo: int, optional: bool = True) -> Callable[[Any, str], Any]:
    def check(value: Any, where: str) -> Any:
        if value is None and optional:
            return None
        if not isinstance(value, int) or isinstance(value, bool) or value < lo:
            raise InputError(f"{where}: expected an integer >= {lo}, got {value!r}")
        return value

    return check


def _fraction(value: Any, where: str) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool) or not 0 <= value <= 1:
        raise InputError(f"{where}: expected a number in [0, 1], got {value!r}")
    return float(value)


def _positive_list(value: Any, where: str) -> list[float] | None:
    if value is None:
        return None
    ok = isinstance(value, list) and len(value) > 0
    ok = ok and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    if not ok or not all(math.isfinite(v) and v > 0 for v in value):
        raise InputError(f"{where}: expected a non-empty list of frequencies > 0 Hz, got {value!r}")
    return [float(v) for v in value]


def _models(value: Any, where: str) -> list[str] | None:
    if value is None:
        return None
    from ..lateral.models import get_model_class

    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise InputError(f"{where}: expected a non-empty list of model names, got {value!r}")
    try:
        return [get_model_class(v).name for v in value]
    except (InputError, KeyError, ValueError) as exc:
        raise InputError(f"{where}: {exc}") from None


def _nonneg_or_none(value: Any, where: str) -> float | None:
    if value is None:
        return None
    if not isinstance(value, int | float) or isinstance(value, bool) or not value >= 0:
        raise InputError(f"{where}: expected a number >= 0, got {value!r}")
    return float(value)


def _channel(value: Any, where: str) -> list[int] | None:
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) != 2
        or not all(isinstance(v, int) and not isinstance(v, bool) and v >= 1 for v in value)
    ):
        raise InputError(
            f"{where}: expected [output, input] counted from 1 (as --channel), got {value!r}"
        )
    return [int(v) for v in value]


_CHECKS: dict[str, dict[str, dict[str, Callable[[Any, str], Any]]]] = {
    "radial": {
        "frf": {
            "estimator": _choice(_ESTIMATORS),
            "method": _choice(_FRF_METHODS),
            "segment": _int_min(2),
            "band": _band,
        },
        "checks": {
            "quality": _boolean,
            "coherence_min": _fraction,
            "max_low_fraction": _fraction,
        },
        "modal": {
            "band": _band,
            "model": _choice(_MODAL_MODELS),
            "n_modes": _int_min(1),
            "frequencies": _positive_list,
            "max_order": _int_min(2),
            "order_step": _int_min(1, optional=False),
            "residuals": _boolean,
        },
        "damping": {
            "enabled": _boolean,
            "method": _choice(_DAMPING_METHODS),
            "model": _choice(("complex", "real")),
            "samples": _int_min(0, optional=False),
            "seed": _int_min(0, optional=False),
            "normalise": _boolean,
        },
    },
    "lateral": {
        "fit": {
            "models": _models,
            "force": _choice(("ground", "axle", None)),  # type: ignore[arg-type]
            "wheel_mass_kg": _nonneg_or_none,
            "band": _band,
            "weights": _choice(_WEIGHTS),
            "criterion": _choice(("bic", "aic")),
            "channel": _channel,
        },
    },
}


def validate_settings(study: str, table: Any, where: str) -> dict[str, dict[str, Any]]:
    """Check one study's settings table and fill in the defaults.

    Parameters
    ----------
    study : str
        ``"radial"`` or ``"lateral"``.
    table : dict or None
        ``{section: {key: value}}`` from the campaign file (missing sections
        and keys take the defaults of :data:`DEFAULTS`).
    where : str
        Prefix for error messages (file and key path).

    Returns
    -------
    dict
        The complete settings, ``{section: {key: value}}``.

    Raises
    ------
    InputError
        Unknown study, section or key, or a bad value (the message names it).
    """
    if study not in DEFAULTS:
        raise InputError(f"{where}: unknown study {study!r}; expected one of {sorted(DEFAULTS)}")
    table = {} if table is None else table
    if not isinstance(table, dict):
        raise InputError(f"{where}: expected a table of sections, got {table!r}")
    out: dict[str, dict[str, Any]] = {}
    for section, defaults in DEFAULTS[study].items():
        given = table.get(section, {})
        if not isinstance(given, dict):
            raise InputError(f"{where}.{section}: expected a table, got {given!r}")
        unknown = sorted(set(given) - set(defaults))
        if unknown:
            raise InputError(
                f"{where}.{section}: unknown key {unknown[0]!r}; expected one of {sorted(defaults)}"
            )
        sec: dict[str, Any] = {}
        for key, default in defaults.items():
            value = given.get(key, default)
            sec[key] = _CHECKS[study][section][key](value, f"{where}.{section}.{key}")
        out[section] = sec
    unknown = sorted(set(table) - set(DEFAULTS[study]))
    if unknown:
        raise InputError(
            f"{where}: unknown section {unknown[0]!r}; expected one of {sorted(DEFAULTS[study])}"
        )
    return out


def step_settings(study: str, step: str, settings: Mapping[str, Any]) -> dict[str, Any]:
    """The part of a study's ``settings`` that ``step``'s result depends on (for its key)."""
    return {s: settings[s] for s in STUDIES[study].settings_of[step]}


def step_conditions(study: str, step: str, conditions: Mapping[str, Any]) -> dict[str, Any]:
    """The test conditions that ``step``'s result depends on (for its key)."""
    return {c: conditions.get(c) for c in STUDIES[study].conditions_of.get(step, ())}


def step_enabled(study: str, step: str, settings: Mapping[str, Any]) -> bool:
    """False when an optional step is switched off in ``settings``."""
    if step not in STUDIES[study].optional:
        return True
    return bool(settings[step].get("enabled", True))


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
    from ..documents.modes import modes_document
    from ..frf import FRF
    from ..io import ChannelMap, read
    from ..signal.checks import dependent_forces
    from ..studies.radial import check_quality, frf_from_time, label_wave_numbers, modes_from_frf
    from ..studies.verdicts import modal_verdicts

    fs, cs, ms = settings["frf"], settings["checks"], settings["modal"]
    obj = read(path, ChannelMap.from_dict((conditions or {}).get("channel_map") or {}))
    if not isinstance(obj, FRF):  # output-only data: said in one line, with what to do
        obj.require_force("the modal step (an FRF from time data)", path.name)
    if isinstance(obj, FRF):
        frf = obj
        source_kind = "frf"
    else:
        dep = dependent_forces(obj) if len(obj.force_indices) > 1 else []
        if dep:  # every force channel is an input: refused as 'tyredamp frf' does
            k, r2, uses = dep[0]
            lab = obj.channels
            raise InputError(
                f"{path.name}: force {lab[k].label} is {100 * r2:.4g} % a linear combination "
                f"of {' and '.join(lab[i].label for i in uses)}: the forces are not "
                "independent excitations (one is a reaction); give the FRFs, or time data "
                "with the excitation forces only"
            )
        frf = frf_from_time(
            obj,
            fs["estimator"],
            method=None if fs["method"] == "auto" else fs["method"],
            segment_samples=fs["segment"],
            band=None if fs["band"] is None else (fs["band"][0], fs["band"][1]),
        )
        source_kind = "time"
    quality = None
    if cs["quality"]:
        quality = check_quality(
            obj, coherence_min=cs["coherence_min"], max_low_fraction=cs["max_low_fraction"]
        )
    res = modes_from_frf(
        frf,
        band=None if ms["band"] is None else (ms["band"][0], ms["band"][1]),
        model=ms["model"],
        n_modes=ms["n_modes"],
        frequencies=ms["frequencies"],
        max_order=ms["max_order"],
        order_step=ms["order_step"],
        residuals=ms["residuals"],
    )
    for mdl in res.models.values():
        label_wave_numbers(mdl)
    for name, v in modal_verdicts(frf, res).items():  # meta.verdict, as 'tyredamp modal'
        res.models[name].meta["verdict"] = v.to_dict()
    doc = modes_document(res.models, source=path.name, band_hz=res.band_hz, frf_kind=res.frf_kind)
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
    from ..documents.damping import damping_document
    from ..documents.modes import models_from_document
    from ..studies.radial import damping_from_modes

    ds = settings["damping"]
    skip = damping_skip_reason(upstream["modal"], ds["model"])
    if skip is not None:
        raise skip
    models = models_from_document(dict(upstream["modal"]))
    if ds["model"] not in models:
        raise InputError(
            f"settings.radial.damping.model: the modes hold models {sorted(models)}, "
            f"not {ds['model']!r}"
        )
    dm = damping_from_modes(
        models,
        model=ds["model"],
        method=ds["method"],
        normalise=ds["normalise"],
        n_samples=ds["samples"],
        seed=ds["seed"],
        meta={"source": path.name, "model": ds["model"]},
    )
    return damping_document(dm)


def _lateral_fit(
    path: Path, upstream: Mapping[str, Any], settings: Mapping[str, Any], conditions: Any
) -> dict[str, Any]:
    """``tyredamp lateral fit`` with the test's speed."""
    from ..documents.lateral import lateral_fit_document
    from ..io import read_frf
    from ..lateral import DEFAULT_MODELS
    from ..lateral.models import get_model_class
    from ..studies.lateral import fit_models, lateral_data

    s = settings["fit"]
    frf = read_frf(path)
    channel = s["channel"]
    where = "settings.lateral.fit"
    if channel is not None and (channel[0] > frf.n_out or channel[1] > frf.n_in):
        raise InputError(
            f"{where}.channel: expected an output 1..{frf.n_out} and an input 1..{frf.n_in} "
            f"of {path.name}, got {channel}"
        )
    if channel is None and frf.n_out * frf.n_in != 1:
        raise InputError(
            f"{where}.channel: {path.name} holds {frf.n_out}x{frf.n_in} FRFs and a lateral "
            "fit takes one; choose it with channel = [OUT, IN] (counted from 1)"
        )
    speed_kmh = None if conditions is None else conditions.get("speed_kmh")
    data = lateral_data(
        frf,
        speed_kmh=None if speed_kmh is None else float(speed_kmh),
        force=s["force"],
        wheel_mass=s["wheel_mass_kg"],
    )
    names = s["models"] or list(DEFAULT_MODELS)
    if data.speed is None:
        need = [n for n in names if "speed" in get_model_class(n).condition_names]
        if need:
            raise InputError(
                f"speed_kmh: the {', '.join(need)} model(s) need the travel speed and "
                f"{path.name} does not store it; give the test's speed_kmh"
            )
    ranking = fit_models(
        data,
        names,
        criterion=s["criterion"],
        band=None if s["band"] is None else (s["band"][0], s["band"][1]),
        weights=s["weights"],
        channel=None if channel is None else (channel[0] - 1, channel[1] - 1),
    )
    ranking.check()  # no model fits: the test fails with the reasons, as the command does
    return lateral_fit_document(ranking, data, source=path.name, frf_kind=frf.kind)


_STEP_FUNCTIONS: dict[tuple[str, str], Callable[..., dict[str, Any]]] = {
    ("radial", "modal"): _radial_modal,
    ("radial", "damping"): _radial_damping,
    ("lateral", "fit"): _lateral_fit,
}


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
    fn = _STEP_FUNCTIONS[(study, step)]
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
    """Run ``steps`` on a test given as its bytes (written to a private temporary file).

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
    with tempfile.TemporaryDirectory(prefix="tyredamp-campaign-") as tmp:
        path = Path(tmp) / Path(name).name
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
    inputs, a roving-hammer test) and ``shape`` (complex, one per point). A
    lateral test has no modes (empty list).
    """
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
                "shape": _complex_vec(md["participation" if at_inputs else "shape"]),
            }
        )
    return out


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
            }
        )
    return out


def failure_reason(exc: BaseException) -> str:
    """The one-line reason of a failed step."""
    return _one_line(exc)


NDArray = np.ndarray
