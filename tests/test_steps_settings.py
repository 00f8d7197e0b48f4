"""Every setting of every step: declared once, reachable from the CLI, a campaign and Python.

For each knob of each settings class of :data:`tyredamp.studies.registry.STEPS`
a value other than its default is given three ways: on the command line of
the step's command (parsed by click, turned into settings as the command
does), in a campaign file's settings table, and as a Python keyword; each
path must give the same typed value. The campaign schema, the docs and the
CLI help are checked against the same classes.
"""

from __future__ import annotations

import dataclasses
import json
from importlib import resources
from pathlib import Path
from typing import Any

import click
import jsonschema
import pytest

from tyredamp.campaign.steps import (
    DEFAULTS,
    section_settings,
    settings_schema,
    validate_settings,
)
from tyredamp.cli import cli
from tyredamp.cli._settings import option_param, settings_from_options
from tyredamp.exceptions import InputError
from tyredamp.modal.poles.estimators import ESTIMATORS
from tyredamp.modal.poles.lscf import plscf
from tyredamp.studies.registry import STEPS, STUDIES, settings_class
from tyredamp.studies.steps import (
    Band,
    Boolean,
    Choice,
    Integer,
    Length,
    Names,
    Number,
    Pair,
    Positives,
    Registered,
    StepSettings,
    knobs,
)
from tyredamp.studies.steps.damping import ModeNumbers

DOCS = Path(__file__).resolve().parents[1] / "docs"

#: The command of each step (the words after ``tyredamp``).
COMMANDS: dict[str, tuple[str, ...]] = {
    "frf": ("frf",),
    "checks": ("check", "quality"),
    "modal": ("modal",),
    "damping": ("damping",),
    "fit": ("lateral", "fit"),
    "rolling": ("rolling",),
}
#: Valid names for the list settings whose entries a registry checks.
NAMES: dict[str, list[str]] = {"models": ["maxwell", "classic"], "reference": ["1+Z", "F2"]}


def _command(step: str) -> click.Command:
    cmd: Any = cli
    for word in COMMANDS[step]:
        cmd = cmd.get_command(click.Context(cmd), word)
    return cmd  # type: ignore[no-any-return]


def _other_value(name: str, check: Any, default: Any, option: str) -> tuple[list[str], Any, Any]:
    """(CLI words, campaign value, expected typed value) of a value that is not the default."""
    if isinstance(check, Boolean):
        return [], not default, not default
    if isinstance(check, Choice | Registered):
        v = next(o for o in check.choices() if o != default)
        return [v], v, v
    if isinstance(check, Integer):
        v = check.minimum + 3 if default != check.minimum + 3 else check.minimum + 4
        return [str(v)], v, v
    if isinstance(check, Number):
        lo = 0.0 if check.minimum is None else check.minimum
        v = (lo + check.maximum) / 3 if check.maximum is not None else lo + 1.5
        v = v if v != default else v / 2
        return [repr(v)], v, v
    if isinstance(check, Band):
        return ["1.5", "20"], [1.5, 20.0], (1.5, 20.0)
    if isinstance(check, Pair):
        return ["2", "1"], [2, 1], (2, 1)
    if isinstance(check, Positives):
        return ["12.5,30"], [12.5, 30.0], (12.5, 30.0)
    if isinstance(check, ModeNumbers):
        return ["1,3-4"], [1, 3, 4], (1, 3, 4)
    if isinstance(check, Length):
        return ["0.5s"], "0.5s", "0.5s"
    if isinstance(check, Names):
        v = NAMES[name]
        if check.split:  # comma-separated
            return [",".join(v)], v, tuple(v)
        return [v[0], option, v[1]], v, tuple(v)  # the option repeated
    raise AssertionError(f"{name}: no example value for {type(check).__name__}")


def _cli_settings(step: str, cls: type[StepSettings], words: list[str]) -> StepSettings:
    cmd = _command(step)
    args = ["input.file", *words]
    if any(p.name == "out" for p in cmd.params):
        args += ["--out", "x.json"]
    ctx = cmd.make_context(" ".join(COMMANDS[step]), args)
    return settings_from_options(cls, dict(ctx.params))


def _knob_cases() -> list[tuple[str, str]]:
    return [(step, name) for step in STEPS for name in knobs(STEPS[step].Settings)]


@pytest.fixture
def two_estimators(monkeypatch: pytest.MonkeyPatch) -> None:
    """A second pole estimator: the estimator setting then has a value besides its default."""
    monkeypatch.setitem(ESTIMATORS, "plscf-twin", plscf)


@pytest.mark.usefixtures("two_estimators")
@pytest.mark.parametrize(("step", "name"), _knob_cases())
def test_every_setting_reaches_every_path(step: str, name: str) -> None:
    cls = STEPS[step].Settings
    k = knobs(cls)[name]
    default = {f.name: f.default for f in dataclasses.fields(cls)}[name]
    words, campaign_value, expected = _other_value(name, k.check, default, k.option)
    assert expected != default  # the test would not see a knob that went nowhere
    # the command line: the option as the user types it
    got = _cli_settings(step, cls, [k.option, *words])
    assert getattr(got, name) == expected
    assert getattr(_cli_settings(step, cls, []), name) == default
    # a campaign file: the key of the step's section of a study that runs it
    study = next(s for s, chain in STUDIES.items() if step in chain.sections)
    table = validate_settings(study, {step: {name: campaign_value}}, f"settings.{study}")
    assert getattr(section_settings(step, table[step]), name) == expected
    # the campaign schema accepts the same value
    doc = {"tests": [{"files": "a.uff"}], "settings": {study: {step: {name: campaign_value}}}}
    jsonschema.validate(doc, SCHEMA)
    # Python
    assert getattr(cls(**{name: campaign_value}), name) == expected


def test_every_step_is_reachable_from_a_campaign() -> None:
    sections = {s for chain in STUDIES.values() for s in chain.sections}
    assert set(STEPS) <= sections


@pytest.mark.parametrize("step", list(STEPS))
def test_settings_refuse_unknown_keys_and_name_the_key(step: str) -> None:
    cls = settings_class(step)
    with pytest.raises(InputError, match=rf"^settings\.x\.{step}: unknown key 'nope'"):
        cls.from_mapping({"nope": 1}, f"settings.x.{step}")
    with pytest.raises(TypeError):
        cls(nope=1)  # type: ignore[call-arg]
    study = next(s for s, chain in STUDIES.items() if step in chain.sections)
    with pytest.raises(InputError, match=rf"settings\.{study}\.{step}: unknown key 'nope'"):
        validate_settings(study, {step: {"nope": 1}}, f"settings.{study}")


@pytest.mark.parametrize(("step", "name"), _knob_cases())
def test_every_setting_is_documented(step: str, name: str) -> None:
    k = knobs(STEPS[step].Settings)[name]
    assert k.text.strip().endswith((".", ")"))
    assert len(k.text.split()) >= 3
    assert k.option.startswith("--")
    # the campaign guide names every key in its section's row
    row = next(
        line
        for line in (DOCS / "campaign.md").read_text("utf-8").splitlines()
        if line.startswith("| `settings.") and line.split("|")[1].strip().endswith(f".{step}`")
    )
    assert f"`{name}`" in row
    # the command's help shows the text of the option
    help_text = " ".join(_command(step).get_help(click.Context(_command(step))).split())
    assert " ".join(k.text.split())[:40] in help_text


SCHEMA = json.loads(
    resources.files("tyredamp").joinpath("schemas/campaign.schema.json").read_text("utf-8")
)


def test_the_schema_file_is_the_one_the_settings_classes_give() -> None:
    assert SCHEMA["properties"]["settings"] == json.loads(json.dumps(settings_schema()))


def test_defaults_are_the_settings_classes_defaults() -> None:
    for study, sections in DEFAULTS.items():
        for section, table in sections.items():
            switch = getattr(STEPS[section], "switch", None)
            own = {k: v for k, v in table.items() if k != switch}
            assert own == settings_class(section).defaults(), (study, section)


def test_the_cli_converts_switches_and_names_options_in_errors() -> None:
    from tyredamp.studies.steps import ModalSettings

    s = settings_from_options(ModalSettings, {"no_residuals": True, "no_search": False})
    assert (s.residuals, s.search) == (False, True)
    with pytest.raises(InputError, match=r"^--frequencies: expected numbers"):
        settings_from_options(ModalSettings, {"frequencies": "12,abc"})
    with pytest.raises(InputError, match=r"^--estimator: expected a pole estimator"):
        settings_from_options(ModalSettings, {"estimator": "nope"})
    assert option_param(knobs(ModalSettings)["n_modes"]) == "modes"


def test_settings_are_frozen_and_checked_when_built() -> None:
    from tyredamp.studies.steps import ModalSettings

    s = ModalSettings(order_step=3, band=[10, 50.0])  # type: ignore[arg-type]
    assert s.band == (10.0, 50.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.order_step = 4  # type: ignore[misc]
    with pytest.raises(InputError, match=r"^order_step: expected an integer >= 1, got 0"):
        ModalSettings(order_step=0)
    with pytest.raises(InputError, match=r"^false_alarm: expected a number in \(0, 1\)"):
        ModalSettings(false_alarm=1.0)
    assert s.replace(order_step=4).order_step == 4


def test_false_alarm_reaches_the_automatic_order(monkeypatch: pytest.MonkeyPatch) -> None:
    """``--false-alarm`` / ``false_alarm`` also sets the count of resonances the data show,
    which caps the automatic order (it used to stay at the default rate there)."""
    import numpy as np

    from tyredamp.modal.poles import order
    from tyredamp.studies.steps import ModalSettings, ModalStep

    from .helpers import chain_system

    seen: list[float] = []
    shown = order.modes_shown

    def spy(problem: Any, false_alarm: float = 0.01) -> int:
        seen.append(false_alarm)
        return shown(problem, false_alarm)

    monkeypatch.setattr(order, "modes_shown", spy)
    frf = chain_system().frf(np.linspace(0.5, 40.0, 200), kind="accelerance", inputs=[0])
    rng = np.random.default_rng(2)
    frf = frf.with_H(frf.H * (1 + 1e-3 * rng.normal(size=frf.H.shape)))
    ModalStep.run(frf, ModalSettings(false_alarm=0.001, search=False, model="complex"))
    assert seen
    assert set(seen) == {0.001}
