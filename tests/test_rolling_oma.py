"""Rolling-tyre modes output-only: the frame relation, the in-tyre resolution, end to end."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.oma.rolling import (
    RollingWave,
    compare_waves,
    resolve_in_tyre,
    rolling_modes,
    rotating_frequency,
    rotating_pole,
)
from tyredamp.virtual import RotatingRing, rolling_test
from tyredamp.virtual.rolling_truth import RollingTruth


@pytest.fixture(scope="module")
def truth80() -> RollingTruth:
    return RollingTruth.from_ring(RotatingRing(speed_kmh=80.0), (20.0, 250.0))


def test_rotating_frequency_matches_the_exact_ring(truth80: RollingTruth) -> None:
    # the truth comes from the state modes of the gyroscopic ring, independently of eq. (1)
    fw = truth80.rotation_hz
    for row in truth80.table():
        if row["wave_number"] == 0:
            continue
        f, d = rotating_frequency(row["fixed_hz"], row["wave_number"], row["fixed_direction"], fw)
        assert d == row["direction"]
        assert_allclose(f, row["rotating_hz"], rtol=1e-9)  # exact kinematics, rounding only


def _fixed_waves(truth: RollingTruth) -> list[RollingWave]:
    return [
        RollingWave("fixed", r["wave_number"], r["direction"], r["fixed_direction"],
                    r["fixed_hz"], r["rotating_hz"], r["fixed_damping_ratio"], 0.0, 0.0)
        for r in truth.table()
    ]  # fmt: skip


def test_in_tyre_peaks_resolved_by_the_fixed_frame_waves(truth80: RollingTruth) -> None:
    rows = [r for r in truth80.table() if r["wave_number"] > 0]
    # the in-tyre peaks 0.2 % off, as an identification would give them
    f_rot = np.array([r["rotating_hz"] for r in rows]) * 1.002
    got = resolve_in_tyre(f_rot, _fixed_waves(truth80), truth80.rotation_hz, n_max=12)
    for r, w in zip(rows, got, strict=True):
        assert (w.wave_number, w.direction) == (r["wave_number"], r["direction"])


def test_in_tyre_peak_alone_is_unresolved_with_its_candidates(truth80: RollingTruth) -> None:
    row = truth80.wave(3, "forward")
    (w,) = resolve_in_tyre([row["rotating_hz"]], [], truth80.rotation_hz, n_max=4)
    assert w.wave_number is None
    assert w.direction is None
    assert (3, "forward") in [(n, d) for n, d, _ in w.candidates]
    ff = {(n, d): f for n, d, f in w.candidates}[(3, "forward")]
    assert_allclose(ff, row["fixed_hz"], rtol=1e-9)  # eq. (1) gives the fixed frequency back


def test_wheel_speed_is_required() -> None:
    test = rolling_test(10.0, n_sensors=4, duration=0.5, sample_rate=512, band=(0, 200), seed=0)
    test.data.meta.pop("rotation_hz")
    with pytest.raises(InputError, match="wheel speed"):
        rolling_modes(test.data)


def test_rolling_modes_end_to_end_at_80_kmh() -> None:
    test = rolling_test(80.0, duration=12.0, sample_rate=512, band=(0, 200), seed=3)
    modes = rolling_modes(test.data, uncertainty=False)
    cmp = compare_waves(modes.fixed, test.truth.table(), "fixed")
    by = {(c["truth"]["wave_number"], c["truth"]["direction"]): c for c in cmp}
    # waves well apart from their neighbours (n = 2 forward and n = 3 backward lie 1.3 Hz
    # apart at 80 km/h, less than their half-power bandwidths: not asked of a 12 s record)
    for key in [(2, "backward"), (3, "forward"), (4, "backward"), (5, "backward")]:
        c = by[key]
        assert c["found"], key
        assert abs(c["f_error"]) < 0.015, (key, c)  # 1.5 %: one 12 s record scatters ~1 %
    rot = compare_waves(modes.rotating, test.truth.table(), "rotating")
    assert sum(c["found"] for c in rot) >= 4  # resolved through eq. (1)
    for c in rot:
        if c["found"]:
            assert abs(c["f_error"]) < 0.02, c  # 2 %: one sensor, pLSCF


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    from tyredamp.cli import main

    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_rolling_writes_the_waves(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from tyredamp.io import write_timedata

    test = rolling_test(80.0, duration=8.0, sample_rate=512, band=(0, 200), seed=4)
    src = tmp_path / "rolling.npz"
    write_timedata(test.data, src)
    out = tmp_path / "waves.json"
    code, text, err = _run(capsys, "rolling", str(src), "-o", str(out), "--no-uncertainty")
    assert code == 0, err
    assert "wrote" in text
    doc = json.loads(out.read_text())
    got = {(w["wave_number"], w["direction"]) for w in doc["waves"] if w["source"] == "fixed"}
    assert (3, "forward") in got
    code, _, err = _run(
        capsys, "rolling", str(src), "-o", str(tmp_path / "x.json"), "--in-tyre", "99"
    )
    assert code == 2
    assert err.startswith("tyredamp: error: --in-tyre")


@pytest.mark.parametrize(
    ("sign", "member"), [(-1, "forward"), (1, "backward"), (0, "cos")], ids=str
)
def test_family_member_of_travelling_and_standing_shapes(sign: int, member: str) -> None:
    from tyredamp.campaign.families import family_names, mode_wave

    ang = np.arange(16) * 22.5
    th = np.radians(ang)
    # e^{-i n theta} e^{i omega t} travels towards +theta; cos n theta stands
    shape = np.cos(3 * th) if sign == 0 else np.exp(1j * sign * 3 * th)
    w = mode_wave(ang.tolist(), shape.tolist())
    assert w is not None
    assert (w.n, w.member) == (3, member)
    assert family_names({"F1": [w, w]})["F1"].label == f"n=3 {member}"


def test_rotating_pole_moves_the_damped_frequency(truth80: RollingTruth) -> None:
    # fixed-frame natural frequency |lambda_f| / 2 pi and damping from the exact ring's
    # decay rate and fixed damped frequency; the rotating pole is the state mode itself
    fw = truth80.rotation_hz
    rows = [r for r in truth80.table() if r["wave_number"] > 0]
    for r, p in zip(truth80.table(), truth80.poles, strict=True):
        if r["wave_number"] == 0:
            continue
        f_nat = np.hypot(r["fixed_hz"], r["decay_rate"] / (2 * np.pi))
        f, z, d = rotating_pole(f_nat, r["fixed_damping_ratio"], r["wave_number"],
                                r["fixed_direction"], fw)  # fmt: skip
        assert d == r["direction"]
        assert_allclose(f, abs(p) / (2 * np.pi), rtol=1e-9)  # exact kinematics, rounding only
        assert_allclose(z, r["damping_ratio"], rtol=1e-9)  # the same decay rate, rounding only
    assert rows


def test_in_tyre_match_widens_to_three_standard_errors(truth80: RollingTruth) -> None:
    row = truth80.wave(3, "forward")
    fw = truth80.rotation_hz
    # the fixed-frame wave 1.5 % off: beyond the 1 % tolerance, within 3 x its 1 % error
    off = RollingWave("fixed", 3, "forward", row["fixed_direction"], 1.015 * row["fixed_hz"],
                      float("nan"), 0.02, 0.01 * row["fixed_hz"], 0.0)  # fmt: skip
    tight = dataclasses.replace(off, std_frequency_hz=0.001 * row["fixed_hz"])
    (w,) = resolve_in_tyre([row["rotating_hz"]], [off], fw, n_max=4)
    assert (w.wave_number, w.direction) == (3, "forward")
    (w,) = resolve_in_tyre([row["rotating_hz"]], [tight], fw, n_max=4)
    assert w.wave_number is None


def test_a_pole_whose_resonance_the_band_cuts_is_not_a_wave() -> None:
    from tyredamp.oma.rolling import _within_band

    def wave(f: float, z: float) -> RollingWave:
        return RollingWave("fixed", 5, "forward", "forward", f, f, z, np.nan, np.nan)

    # flanks f -+ 2 zeta f: 196 + 3.92 = 199.92 Hz inside 200 Hz, 198 + 3.96 beyond it,
    # 6 - 0.24 = 5.76 Hz below a band from 5.8 Hz
    waves = [wave(100.0, 0.02), wave(196.0, 0.01), wave(198.0, 0.01), wave(6.0, 0.02)]
    kept, notes = _within_band(waves, (5.8, 200.0))
    assert [w.fixed_hz for w in kept] == [100.0, 196.0]
    assert len(notes) == 2
    assert "198 Hz left out" in notes[0]
    kept, _ = _within_band(waves, (0.0, 200.0))  # no lower edge from 0 Hz
    assert [w.fixed_hz for w in kept] == [100.0, 196.0, 6.0]


def test_document_keeps_only_the_modes_that_gave_a_wave() -> None:
    from types import SimpleNamespace

    from tyredamp.oma.rolling import RollingModes
    from tyredamp.studies.steps.rolling import RollingStep

    # a general-route result with two modes, the second cut off by the band edge
    r = SimpleNamespace(
        n_modes=2,
        frequency_hz=np.array([100.0, 199.0]),
        damping_ratio=np.array([0.02, 0.01]),
        std_frequency_hz=np.array([0.1, 0.1]),
        std_damping_ratio=np.array([0.001, 0.001]),
        shapes=np.ones((4, 2), complex),
    )
    wave = RollingWave("fixed", 2, "forward", "forward", 100.0, 95.0, 0.02, 0.1, 0.001)
    res = RollingModes(
        1.0, [wave], [], r, None, [], (0.0, 90.0, 180.0, 270.0), ("A", "B", "C", "D")
    )  # type: ignore[arg-type]
    doc = RollingStep.document(res, "x.npz")
    assert [m["frequency_hz"] for m in doc["modes"]] == [100.0]
