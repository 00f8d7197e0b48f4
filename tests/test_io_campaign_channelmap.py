"""A campaign's channel map: parsed with the campaign file, applied when its tests are read."""

from __future__ import annotations

from pathlib import Path

import pytest

from tyredamp import InputError
from tyredamp.campaign import steps
from tyredamp.campaign.spec import CampaignFileError, load_campaign

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
CSV = REAL / "converted" / "impact_test_3ch.csv"


def _campaign(tmp_path: Path, extra: str) -> Path:
    p = tmp_path / "campaign.toml"
    p.write_text(
        f'[settings.radial.modal]\nband = [10.0, 200.0]\n\n[[tests]]\nfiles = "{CSV.as_posix()}"\n'
        f"pressure_bar = 2.0\n{extra}",
        encoding="utf-8",
    )
    return p


def test_campaign_channel_map_file_and_table(tmp_path: Path) -> None:
    if not CSV.is_file():
        pytest.skip("real-data gallery not found")
    (tmp_path / "channels.toml").write_text(
        '[channels]\nF = "force:N"\nm_1 = "acceleration:m/s^2"\nm_2 = "acceleration:m/s^2"\n'
    )
    by_file = load_campaign(_campaign(tmp_path, 'channel_map = "channels.toml"\n'))
    table = (
        'channel_map = { channels = { F = "force:N", 2 = "acceleration", 3 = "acceleration" } }\n'
    )
    by_table = load_campaign(_campaign(tmp_path, table))
    spec = by_file.tests[0]
    assert spec.conditions["channel_map"]["channels"]["F"] == {"role": "force", "unit": "N"}
    # the map is part of the modal step's cache key: another map, another key
    keys = [
        steps.step_conditions("radial", "modal", c.tests[0].conditions) for c in (by_file, by_table)
    ]
    assert keys[0] != keys[1]
    res = steps.process_radial_test(CSV, spec.conditions, by_file.settings["radial"])
    assert res.documents["modal"]  # the test was read and identified through the map
    with pytest.raises(Exception, match=r"'F', 'm_1', 'm_2' measure"):
        steps.process_radial_test(CSV, {}, by_file.settings["radial"])


def test_campaign_bad_channel_map(tmp_path: Path) -> None:
    if not CSV.is_file():
        pytest.skip("real-data gallery not found")
    with pytest.raises(
        CampaignFileError, match=r"tests\[0\].channel_map: channel-map file not found"
    ):
        load_campaign(_campaign(tmp_path, 'channel_map = "none.toml"\n'))
    with pytest.raises(CampaignFileError, match=r"tests\[0\].channel_map.*role 'forse'"):
        load_campaign(_campaign(tmp_path, 'channel_map = { channels = { F = "forse:N" } }\n'))


def test_campaign_modal_step_on_output_only_data(tmp_path: Path) -> None:
    mps = REAL / "ladisk_pyuff" / "data" / "MPSTD#Set001_2024_10_08_10_27_07.uff"
    if not mps.is_file():
        pytest.skip("real-data gallery not found")
    with pytest.raises(InputError, match=r"MPSTD.*output-only data \(no force channel\)") as info:
        steps.process_radial_test(mps)
    assert "with tyredamp oma (operational modal analysis)" in str(info.value)
    assert "\n" not in str(info.value)
