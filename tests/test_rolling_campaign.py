"""Rolling tests in a campaign: written by the virtual campaign, run by the rolling study."""

from __future__ import annotations

from pathlib import Path

from tyredamp.campaign import steps
from tyredamp.campaign.families import mode_wave
from tyredamp.campaign.virtual import tyre_parameters
from tyredamp.campaign.virtual_rolling import write_rolling_tests


def test_rolling_tests_run_through_the_rolling_study(tmp_path: Path) -> None:
    entries = write_rolling_tests(tmp_path, tyre_parameters(0), (80.0,), (7.5,), seed=1,
                                  duration=8.0)  # fmt: skip
    (e,) = entries
    assert e["study"] == "rolling"
    assert e["speed_kmh"] == 80.0
    truth = e["rolling_truth"]
    settings = steps.validate_settings("rolling", {"rolling": {"uncertainty": False}}, "s")
    doc = steps.run_step("rolling", "rolling", tmp_path / Path(e["file"]).name, {}, settings)
    recs = steps.mode_records("rolling", {"rolling": doc})
    assert len(recs) == len(doc["modes"]) > 0
    # the family members of the tracked modes: the direction seen from the fixed sensors
    named = {}
    for r in recs:
        w = mode_wave(r["angles_deg"], r["shape"])
        if w is not None and w.member in ("forward", "backward"):
            named[(w.n, w.member)] = r["frequency_hz"]
    exact = {(t["wave_number"], t["fixed_direction"]): t["fixed_hz"] for t in truth}
    for key in [(3, "forward"), (4, "backward")]:
        assert key in named, key
        assert abs(named[key] / exact[key] - 1) < 0.015, key  # 1.5 %: one 8 s record
