"""The rolling tests of the virtual campaign: the tyre of ``tyredamp simulate rolling``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from tyredamp.campaign.virtual import VirtualCampaign, write_virtual_campaign
from tyredamp.campaign.virtual_rolling import ROLLING_TYRE, rolling_tyre
from tyredamp.cli import main
from tyredamp.exceptions import InputError
from tyredamp.virtual import Cavity, ContactPatch, RingTyre, RingTyreParameters, RotatingRing
from tyredamp.virtual.rolling_truth import RollingTruth


def test_campaign_rolling_tyre_is_the_tyre_of_simulate_rolling(tmp_path: Path) -> None:
    # the same settings (default tyre, 6 bar, 40 km/h) through `tyredamp simulate rolling`
    # and through the campaign's rolling tyre: the same waves, frequencies and damping
    out, truth = tmp_path / "r.npz", tmp_path / "t.json"
    args = ["simulate", "rolling", "--out", str(out), "--speed", "40", "--pressure", "6"]
    args += ["--duration", "0.5", "--sensors", "4", "--truth", str(truth)]
    main(args)
    cli_waves = json.loads(truth.read_text(encoding="utf-8"))["waves"]
    band = tuple(json.loads(truth.read_text(encoding="utf-8"))["band_hz"])
    ring = RotatingRing(rolling_tyre(RingTyreParameters(), 6.0), 40.0)
    ours = RollingTruth.from_modes(ring, ring.system.state_modes(), band).table()
    assert len(ours) == len(cli_waves) > 10
    for a, b in zip(ours, cli_waves, strict=True):
        assert (a["wave_number"], a["direction"]) == (b["wave_number"], b["direction"])
        for k in ("rotating_hz", "fixed_hz", "damping_ratio"):
            assert_allclose(a[k], b[k], rtol=1e-9)  # same matrices and eigensolver: rounding


def test_rolling_tyre_has_the_ring_losses_and_says_what_it_lacks() -> None:
    tyre = rolling_tyre(RingTyreParameters(), 7.5)
    assert tyre.nonproportionality == 1.0
    # the rubber losses of the radial tests' tyre, no shaker tips
    assert {"sidewall radial", "band bending"} <= set(tyre.damping_sources)
    assert "attachment" not in tyre.damping_sources
    assert tyre.cavity is None
    assert tyre.contact is None
    assert "not supported" in ROLLING_TYRE["cavity"]
    assert "not supported" in ROLLING_TYRE["contact"]


@pytest.mark.parametrize("part", ["cavity", "contact"])
def test_rotating_ring_refuses_what_it_does_not_model(part: str) -> None:
    # a cavity's air DOFs and a space-fixed patch are not in the rotating frame: refused
    # in words instead of a broadcasting error or a patch spinning with the tyre
    kw = {"cavity": Cavity()} if part == "cavity" else {"contact": ContactPatch(20000.0)}
    tyre = RingTyre(RingTyreParameters(), n_ring=32, **kw)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="rotating ring does not model"):
        RotatingRing(tyre, 40.0)


def test_truth_json_records_the_rolling_tyre(tmp_path: Path) -> None:
    spec = VirtualCampaign(1, (7.5,), (), (), 1.7, 2, 0, rolling_speeds_kmh=(0.0,))
    doc = write_virtual_campaign(tmp_path / "v", spec)
    saved = json.loads((tmp_path / "v" / "truth.json").read_text(encoding="utf-8"))
    assert saved["rolling_tyre"] == doc["rolling_tyre"] == ROLLING_TYRE
    (test,) = saved["tests"]
    ring = RotatingRing(rolling_tyre(_first_tyre(), 7.5), 0.0)
    exact = RollingTruth.from_modes(ring, ring.system.state_modes(), (0.0, 200.0)).table()
    got = sorted(t["fixed_hz"] for t in test["rolling_truth"])
    assert_allclose(got, sorted(t["fixed_hz"] for t in exact), rtol=1e-9)  # rounding only


def _first_tyre() -> RingTyreParameters:
    from tyredamp.campaign.virtual import tyre_parameters

    return tyre_parameters(0, 0)
