"""The campaign file (tyredamp.campaign.spec) and its JSON schema."""

from __future__ import annotations

import json
import tomllib
from importlib import resources
from pathlib import Path

import jsonschema
import pytest

from tyredamp.campaign.spec import CampaignFileError, load_campaign
from tyredamp.campaign.steps import DEFAULTS

SCHEMA = json.loads(
    resources.files("tyredamp").joinpath("schemas/campaign.schema.json").read_text("utf-8")
)


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    data = tmp_path / "data"
    data.mkdir()
    for name in ("A_6bar.uff", "A_7.5bar.uff", "B_6bar.uff", "lat_5kmh.npz"):
        (data / name).write_bytes(b"x")
    return tmp_path


GOOD = """
name = "sweep"
output = "results"

[defaults]
temperature_c = 21.5

[settings.radial.modal]
band = [30.0, 180.0]

[settings.radial.damping]
samples = 20

[settings.lateral.fit]
models = ["classic", "maxwell"]

[tracking]
model = "real"

[[tests]]
files = "data/A_*.uff"
tyre = "A"
pressure_bar = 6.0
load_n = 20000

[[tests]]
files = ["data/B_6bar.uff"]
tyre = 2
pressure_bar = 6
note = "second tyre"

[[tests]]
files = "data/lat_5kmh.npz"
study = "lateral"
speed_kmh = 5
"""


def write(folder: Path, text: str) -> Path:
    p = folder / "campaign.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_a_good_campaign_file(folder: Path) -> None:
    c = load_campaign(write(folder, GOOD))
    assert c.name == "sweep"
    assert c.output == folder / "results"
    assert [t.rel for t in c.tests] == [
        "data/A_6bar.uff",
        "data/A_7.5bar.uff",
        "data/B_6bar.uff",
        "data/lat_5kmh.npz",
    ]
    assert [t.study for t in c.tests] == ["radial"] * 3 + ["lateral"]
    assert c.tests[0].conditions == {
        "tyre": "A",
        "pressure_bar": 6.0,
        "load_n": 20000.0,
        "speed_kmh": None,
        "temperature_c": 21.5,
        "note": None,
    }
    assert c.tests[2].conditions["tyre"] == "2"
    assert len({t.test_id for t in c.tests}) == 4
    assert c.settings["radial"]["modal"]["band"] == [30.0, 180.0]
    assert c.settings["radial"]["damping"]["samples"] == 20
    assert c.settings["radial"]["damping"]["method"] == DEFAULTS["radial"]["damping"]["method"]
    assert c.settings["lateral"]["fit"]["models"] == ["classic", "maxwell"]
    assert c.tracking == {"model": "real"}
    # the same file satisfies the JSON schema
    jsonschema.validate(tomllib.loads(GOOD), SCHEMA)


@pytest.mark.parametrize(
    ("change", "key", "message"),
    [
        (("pressure_bar = 6.0", 'pressure_bar = "six"'), "tests[0].pressure_bar", "number"),
        (("pressure_bar = 6.0", "pressure_bar = -1.0"), "tests[0].pressure_bar", ">= 0"),
        (("load_n = 20000", "load_n = nan"), "tests[0].load_n", "finite"),
        (("temperature_c = 21.5", "temperature_c = -300.0"), "defaults.temperature_c", "-273"),
        (('files = "data/A_*.uff"', 'files = "data/C_*.uff"'), "tests[0].files", "no file"),
        (('files = "data/A_*.uff"', 'files = "data/none.uff"'), "tests[0].files", "not found"),
        (('files = "data/A_*.uff"', "files = 3"), "tests[0].files", "path"),
        (('study = "lateral"', 'study = "axial"'), "tests[2].study", "radial"),
        (('tyre = "A"', 'tyre = "A"\nspeed = 3'), "tests[0].speed", "unknown key"),
        (("band = [30.0, 180.0]", "band = [180.0, 30.0]"), "settings.radial.modal.band", "f_lo"),
        (("band = [30.0, 180.0]", "bands = [1, 2]"), "settings.radial.modal", "bands"),
        (("samples = 20", "samples = -2"), "settings.radial.damping.samples", ">= 0"),
        (("samples = 20", 'method = "best"'), "settings.radial.damping.method", "improved"),
        (('models = ["classic", "maxwell"]', 'models = ["nope"]'), "settings.lateral.fit", "nope"),
        (('model = "real"', 'model = "both"'), "tracking.model", "complex"),
        (('name = "sweep"', "name = 1"), "name", "text"),
        (('name = "sweep"', 'nmae = "sweep"'), "nmae", "unknown key"),
        (('output = "results"', 'output = ""'), "output", "folder"),
        (("[settings.radial.modal]", "[settings.axial.modal]"), "settings.axial", "study"),
    ],
)
def test_every_bad_field_is_one_line_naming_file_and_key(
    folder: Path, change: tuple[str, str], key: str, message: str
) -> None:
    assert change[0] in GOOD
    path = write(folder, GOOD.replace(change[0], change[1], 1))
    with pytest.raises(CampaignFileError) as err:
        load_campaign(path)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith(f"{path}: ")
    assert key in text
    assert message in text


def test_unreadable_campaign_files(folder: Path) -> None:
    with pytest.raises(CampaignFileError, match="not found"):
        load_campaign(folder / "missing.toml")
    with pytest.raises(CampaignFileError, match="not valid TOML"):
        load_campaign(write(folder, "tests = [\n"))
    with pytest.raises(CampaignFileError, match=r"tests: expected at least one"):
        load_campaign(write(folder, 'name = "x"\n'))
    p = folder / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(CampaignFileError, match="not a text"):
        load_campaign(p)


def test_a_file_listed_twice_is_refused(folder: Path) -> None:
    text = '[[tests]]\nfiles = "data/A_*.uff"\n[[tests]]\nfiles = "data/A_6bar.uff"\n'
    with pytest.raises(CampaignFileError, match=r"tests\[1\]\.files: data/A_6bar.uff is already"):
        load_campaign(write(folder, text))


def test_schema_rejects_what_the_reader_rejects() -> None:
    bad = tomllib.loads(GOOD.replace("pressure_bar = 6.0", "pressure_bar = -1.0"))
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)
    bad = tomllib.loads(GOOD.replace('tyre = "A"', 'tyre = "A"\nspeed = 3'))
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)


def test_schema_and_reader_know_the_same_settings() -> None:
    props = SCHEMA["properties"]["settings"]["properties"]
    assert set(props) == set(DEFAULTS)
    for study, sections in DEFAULTS.items():
        assert set(props[study]["properties"]) == set(sections)
        for section, keys in sections.items():
            assert set(props[study]["properties"][section]["properties"]) == set(keys)
    from tyredamp.campaign.spec import CONDITIONS

    test_props = SCHEMA["properties"]["tests"]["items"]["properties"]
    assert set(test_props) == {"files", "study", "channel_map", *CONDITIONS}
