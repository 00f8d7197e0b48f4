"""A campaign on a measured beam: skipped steps, tracking by frequency, the report.

The measured beam of the real-data folder (one accelerometer, a roving
hammer: pyuff's ``meas_point_1..3.txt``) is a campaign of single-point tests:
its damping step cannot run (one response point for six modes; without a
drive point the shapes are not mass-normalised either). The modes and the
tracking still come out; the skips are cached like results. With one common
point the MAC cannot be formed, so the modes are matched by frequency and
damping: six families, one per physical mode.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner
from numpy.testing import assert_allclose

from tyredamp.campaign import load_campaign
from tyredamp.campaign.cache import ResultCache
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import run_tests
from tyredamp.campaign.steps import (
    StepSkipped,
    damping_skip_reason,
    is_skip,
    process_radial_test,
    run_step,
    skip_document,
    validate_settings,
)
from tyredamp.cli import cli
from tyredamp.frf import FRF, Channel
from tyredamp.io import write_frf
from tyredamp.report.campaign import campaign_report

#: The beam's six physical modes (Hz), approximate: the modal step's start frequencies.
BEAM_MODES = [51.5, 142.2, 278.7, 460.4, 687.2, 958.5]


def real_data() -> Path:
    """The shared real-data folder beside the repository (skip when it is absent)."""
    root = Path(__file__).resolve().parents[2] / "shared" / "real-data"
    if not root.is_dir():
        pytest.skip("the real-data folder ../shared/real-data is absent")
    return root


def write_beam(folder: Path) -> dict[str, Path]:
    """The three hammer points as UFF 58 files and all three as one roving-hammer FRF."""
    src = real_data() / "ladisk_pyuff" / "data"
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    files = {}
    for k in (1, 2, 3):
        h = np.genfromtxt(src / f"meas_point_{k}.txt", dtype=complex)
        f = np.arange(h.size, dtype=float)  # 0-1000 Hz at 1 Hz; line 0 (DC) is meaningless
        rows.append(h[1:])
        frf = FRF(
            f[1:],
            h[None, None, 1:],
            kind="accelerance",
            outputs=[Channel(1, 3)],
            inputs=[Channel(k, 3)],
        )
        files[f"point{k}"] = write_frf(frf, folder / f"point{k}.uff")
    roving = FRF(
        f[1:],
        np.stack(rows)[None],
        kind="accelerance",
        outputs=[Channel(1, 3)],
        inputs=[Channel(k, 3) for k in (1, 2, 3)],
    )
    files["roving"] = write_frf(roving, folder / "roving.uff")
    return files


def beam_campaign(folder: Path, extra: str = "") -> Path:
    write_beam(folder / "data")
    tests = "".join(
        f'\n[[tests]]\nfiles = "data/{name}.uff"\nnote = "{note}"\n'
        for name, note in (
            ("point1", "hammer at node 1"),
            ("point2", "hammer at node 2"),
            ("point3", "hammer at node 3"),
            ("roving", "roving hammer at nodes 1-3"),
        )
    )
    text = (
        'name = "measured beam"\n[settings.radial.modal]\n'
        f"frequencies = {BEAM_MODES}\n{extra}{tests}"
    )
    path = folder / "campaign.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def beam(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("beam")
    campaign = load_campaign(beam_campaign(root))
    out = root / "out"
    runs = run_tests(campaign, out, mode="serial")
    results = write_outputs(campaign, runs, out)
    return {"root": root, "campaign": campaign, "runs": runs, "results": results, "out": out}


def _modes_doc(outputs: list[tuple[int, int]], inputs: list[tuple[int, int]], n: int) -> dict:
    ch = [{"node": a, "direction": d} for a, d in outputs]
    ci = [{"node": a, "direction": d} for a, d in inputs]
    return {"models": {"complex": {"outputs": ch, "inputs": ci, "modes": [{}] * n}}}


def test_damping_skip_reason_from_the_channels_of_the_modes() -> None:
    # 16 points, a drive point (node 1, +z and -z are one direction), 6 modes: it runs
    ok = _modes_doc([(k, 3) for k in range(1, 17)], [(1, -3)], 6)
    assert damping_skip_reason(ok, "complex") is None
    # one response point for six modes, and a drive point
    one = damping_skip_reason(_modes_doc([(1, 3)], [(1, 3)], 6), "complex")
    assert isinstance(one, StepSkipped)
    assert "1 response point for 6 modes" in one.why
    assert "at least 6 response points" in one.needs
    assert "mass-normalised" not in one.why
    # enough points, but the response is never measured at the excitation point
    nod = damping_skip_reason(_modes_doc([(k, 3) for k in range(2, 9)], [(1, 3)], 6), "complex")
    assert isinstance(nod, StepSkipped)
    assert "not mass-normalised" in nod.why
    assert "excitation point" in nod.needs
    assert "response points as modes" not in nod.why
    # at the excitation node but in another direction: no drive point either
    other = _modes_doc([(k, 1) for k in range(1, 9)], [(1, 3)], 6)
    assert damping_skip_reason(other, "complex") is not None
    # a model the modes do not hold: not a skip (the step fails with the setting's message)
    assert damping_skip_reason(ok, "real") is None


def test_a_step_after_a_skipped_one_is_skipped_too(tmp_path: Path) -> None:
    settings = validate_settings("radial", None, "settings.radial")
    upstream = {"modal": skip_document("radial", "modal", "why", "the data it needs")}
    with pytest.raises(StepSkipped) as exc:
        run_step("radial", "damping", tmp_path / "none.uff", upstream, settings)
    assert "needs the modal step, which was skipped" in exc.value.why
    assert exc.value.needs == "the data it needs"


def test_one_accelerometer_skips_damping_and_keeps_the_modes(beam: dict[str, Any]) -> None:
    for run in beam["runs"]:
        assert run.ok, run.reason  # not a failed test
        assert run.reason is None
        assert "modal" in run.documents
        assert "damping" not in run.documents
        assert run.outcome("modal") == "ran"
        assert run.outcome("damping") == "skipped"
        reason = run.skipped["damping"]["reason"]
        assert reason.startswith("damping step skipped: ")
        assert "1 response point for 6 modes" in reason
    s = beam["results"].summary
    assert (s["n_ok"], s["n_partial"], s["n_failed"]) == (4, 4, 0)
    assert s["n_skipped_steps"] == 4
    by_id = {t["test_id"]: t for t in s["tests"]}
    assert {t["status"] for t in s["tests"]} == {"partial"}
    # hammer at node 2 or 3 and the response at node 1: no drive point, said as well
    assert "not mass-normalised" in by_id["radial-data-point2"]["skipped"]["damping"]
    assert "not mass-normalised" not in by_id["radial-data-point1"]["skipped"]["damping"]
    assert [st["outcome"] for st in by_id["radial-data-point1"]["steps"]] == ["ran", "skipped"]
    # the step table: one row per step, the skip with its reason, no verdict
    with open(beam["out"] / "steps.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 8
    damp = [r for r in rows if r["step"] == "damping"]
    assert {r["outcome"] for r in damp} == {"skipped"}
    assert all(r["reason"].startswith("damping step skipped: ") for r in damp)
    assert {r["outcome"] for r in rows if r["step"] == "modal"} == {"ran"}


def test_a_skip_is_cached_under_the_step_key(beam: dict[str, Any], tmp_path: Path) -> None:
    campaign = beam["campaign"]
    cache = ResultCache(beam["out"] / "cache")
    for run in beam["runs"]:
        assert run.computed == ["modal", "damping"]
        entry = cache.get(run.keys["damping"])
        assert is_skip(entry)
        assert entry == run.skipped["damping"]
    # a rerun reads the skip back: nothing is computed, the same skips
    again = run_tests(campaign, beam["out"], mode="serial")
    for a, b in zip(again, beam["runs"], strict=True):
        assert a.computed == []
        assert a.reused == ["modal", "damping"]
        assert a.skipped == b.skipped
    # a new damping setting is a new key: the skip is found again, the modes reused
    other = load_campaign(
        beam_campaign(tmp_path, extra="[settings.radial.damping]\nsamples = 10\n")
    )
    for name in ("point1", "point2", "point3", "roving"):  # same bytes: the same file keys
        assert (tmp_path / "data" / f"{name}.uff").read_bytes() == (
            beam["root"] / "data" / f"{name}.uff"
        ).read_bytes()
    runs = run_tests(other, beam["out"], mode="serial")
    for r in runs:
        assert r.reused == ["modal"]
        assert r.computed == ["damping"]
        assert "damping" in r.skipped


def test_process_radial_test_returns_the_skip(beam: dict[str, Any]) -> None:
    res = process_radial_test(
        beam["root"] / "data" / "point1.uff", settings={"modal": {"frequencies": BEAM_MODES}}
    )
    assert set(res.documents) == {"modal"}
    assert set(res.skipped) == {"damping"}
    assert is_skip(res.skipped["damping"])


def test_the_cli_lists_skips_and_exits_zero(beam: dict[str, Any], tmp_path: Path) -> None:
    out = tmp_path / "out"
    res = CliRunner().invoke(
        cli, ["campaign", str(beam["root"] / "campaign.toml"), "--out", str(out), "--serial"]
    )
    assert res.exit_code == 0, res.output  # a skip is not a failure
    assert "4 ok (4 with skipped steps), 0 failed" in res.output
    skipped = [line for line in res.output.splitlines() if line.startswith("skipped: ")]
    assert len(skipped) == 4
    assert skipped[0].startswith("skipped: data/point1.uff: damping step skipped: ")
    assert not [line for line in res.output.splitlines() if line.startswith("failed: ")]
    s = json.loads((out / "campaign.json").read_text("utf-8"))
    assert "steps.csv" in s["written"]
    html = (out / "report.html").read_text("utf-8")
    assert "Skipped steps" in html
    assert "None: every step" not in html


def test_the_report_lists_failed_checks_and_every_step(beam: dict[str, Any]) -> None:
    results = beam["results"]
    html = campaign_report(results)
    s = results.summary
    checks = [t for t in s["tests"] if t["checks"]["failed"]]
    if checks:  # a failed check is never reported as "None"
        assert "None: every" not in html
        assert "Failed quality checks" in html
        for t in checks:
            assert t["test_id"] in html
    # every test's damping step is shown with its reason; a figure per family
    assert html.count('<td class="l">skipped: the damping matrix in physical coordinates') == 4
    assert html.count("<figure") >= len(s["families"])


def test_the_beam_gives_one_family_per_physical_mode(beam: dict[str, Any]) -> None:
    rows = beam["results"].modes
    families: dict[str, list[dict[str, Any]]] = {}
    for r in rows:
        families.setdefault(r["family"], []).append(r)
    assert len(families) == len(BEAM_MODES)
    for fam in families.values():
        # one mode of each of the four tests, the same physical mode
        assert sorted(r["test_id"] for r in fam) == sorted(r.spec.test_id for r in beam["runs"])
        f = np.array([r["frequency_hz"] for r in fam])
        nearest = BEAM_MODES[int(np.argmin(np.abs(np.array(BEAM_MODES) - f.mean())))]
        # the listed frequencies are rounded to 0.1 Hz; the tests agree to 0.03 Hz
        assert np.all(np.abs(f - nearest) < 0.1), (nearest, f)
        # the first test starts the family; the others joined by frequency and damping
        assert sorted(r["match"] for r in fam) == ["", "frequency", "frequency", "frequency"]
        assert all(np.isnan(r["match_mac"]) for r in fam)
        assert all(r["match_z"] < 5 or r["match"] == "" for r in fam)
    assert {fam[0]["family"] for fam in families.values()} == {f"F{k}" for k in range(1, 7)}
    tr = beam["results"].summary["tracking"]
    assert tr["matched_by_frequency"] == 18
    assert tr["matched_by_shape"] == 0
    # the scatter of one mode between tests, from the data: tiny in frequency
    assert 0 < tr["scatter_ln_frequency"] < 1e-3


def test_plot_family_draws_into_the_given_axes(beam: dict[str, Any]) -> None:
    from matplotlib.figure import Figure

    from tyredamp.plot.campaign import plot_family

    rows = [r for r in beam["results"].modes if r["family"] == "F1"]
    fig = Figure()
    axes = fig.subplots(1, 2)
    out = plot_family(rows, axes=axes)
    assert out["axes"] == list(axes)
    assert out["x"].tolist() == list(range(len(rows)))  # the tests side by side
    (drawn,) = out["series"].values()  # one series (no tyre given), no slots
    y = drawn[0].lines[0].get_ydata()
    assert_allclose(y, [r["frequency_hz"] for r in rows], rtol=0)  # drawn as they are
    z = drawn[1].lines[0].get_ydata()
    assert_allclose(z, [100 * r["damping_ratio"] for r in rows], rtol=1e-15)  # in percent
    assert [t.get_text() for t in axes[0].get_xticklabels()] == [r["test_id"] for r in rows]
    # against a numeric condition, on a new figure
    num = [{**r, "pressure_bar": 6.0 + k} for k, r in enumerate(rows)]
    out = plot_family(num, "pressure_bar")
    assert out["x"].tolist() == [6.0, 7.0, 8.0, 9.0]
    assert out["axes"][0].figure is out["axes"][1].figure


def test_a_step_switched_off_is_neither_run_nor_skipped(
    beam: dict[str, Any], tmp_path: Path
) -> None:
    campaign = load_campaign(
        beam_campaign(tmp_path, extra="[settings.radial.damping]\nenabled = false\n")
    )
    runs = run_tests(campaign, tmp_path / "out", mode="serial")
    results = write_outputs(campaign, runs, tmp_path / "out")
    for r in runs:
        assert r.outcome("damping") == "off"
        assert r.skipped == {}
    assert {t["status"] for t in results.summary["tests"]} == {"ok"}
    assert {row["outcome"] for row in results.steps if row["step"] == "damping"} == {"off"}
    assert results.summary["n_partial"] == 0
