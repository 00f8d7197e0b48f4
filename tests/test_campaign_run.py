"""The campaign end to end on the quick virtual campaign: serial, Dask, cache, faults.

One quick virtual campaign (``tyredamp simulate campaign --quick``: 2 tyres x
3 pressures at one load, 2 lateral speeds) is written once per module and
processed serially once; the other tests reuse it (through the cache where
they can) so the module stays fast. At most 2 Dask workers are started.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import tomllib
from collections.abc import Iterator
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from click.testing import CliRunner

from tyredamp.campaign import load_campaign
from tyredamp.campaign.families import mode_wave
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import run_tests
from tyredamp.campaign.virtual import compare_with_truth
from tyredamp.campaign.virtual_check import true_branches
from tyredamp.cli import cli
from tyredamp.report.campaign import write_campaign_report

pytestmark = pytest.mark.slow


def invoke(*args: str) -> Any:
    res = CliRunner().invoke(cli, list(args), catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return res


@pytest.fixture(scope="module")
def virtual(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("virtual")
    invoke("simulate", "campaign", "--out", str(root), "--quick")
    return root


@pytest.fixture(scope="module")
def serial(virtual: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("serial") / "out"
    campaign = load_campaign(virtual / "campaign.toml")
    runs = run_tests(campaign, out, mode="serial")
    results = write_outputs(campaign, runs, out)
    write_campaign_report(results, out)
    return {"out": out, "campaign": campaign, "runs": runs, "results": results}


@pytest.fixture(scope="module")
def cluster() -> Iterator[Any]:
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
    ) as c:
        yield c


def test_virtual_campaign_file_follows_the_schema(virtual: Path) -> None:
    schema = json.loads(
        resources.files("tyredamp").joinpath("schemas/campaign.schema.json").read_text("utf-8")
    )
    doc = tomllib.loads((virtual / "campaign.toml").read_text("utf-8"))
    jsonschema.validate(doc, schema)


def test_virtual_campaign_end_to_end(virtual: Path, serial: dict[str, Any]) -> None:
    runs, results = serial["runs"], serial["results"]
    assert all(r.ok for r in runs), [(r.spec.rel, r.reason) for r in runs if not r.ok]
    truth = json.loads((virtual / "truth.json").read_text("utf-8"))
    check = compare_with_truth(results, truth, runs)
    # every identified mode is a true mode, and every family is one wave number: no swap
    assert check["unmatched"] == []
    assert check["swaps"] == []
    for fam, by_tyre in check["families"].items():
        waves = set().union(*by_tyre.values())
        assert len(waves) == 1, (fam, by_tyre)  # the same mode for both tyres
    # every family is named by the true wave number of its modes (the cos member: one
    # shaker); where the loaded patch mixes harmonics so that no shape of the family is a
    # single one, its dominant harmonic, and the label says it is mixed
    names = {f["family"]: f for f in results.summary["families"]}
    branches = true_branches(truth)
    for fam, by_tyre in check["families"].items():
        (true_n,) = set().union(*by_tyre.values())
        mixed = names[fam]["wave_mixed"]
        assert mixed == (names[fam]["n_labelled"] == 0)
        if mixed:
            # the dominant harmonic of the family's true shapes at the 16 points
            true_n = _dominant_true_harmonic(
                truth, branches, set().union(*check["branches"][fam].values())
            )
        assert names[fam]["wave_number"] == true_n, (fam, names[fam])
        # families sharing a name are told apart by their frequency order: "(2nd)"
        expected = re.escape(f"n={true_n} mixed" if mixed else f"n={true_n} cos")
        assert re.fullmatch(expected + r"( \(\d+(nd|rd|th)\))?", names[fam]["label"]), names[fam]
    # every family seen at all three pressures of both tyres is tracked through all six tests
    n_tests = {f["family"]: f["n_tests"] for f in results.summary["families"]}
    assert sum(v == 6 for v in n_tests.values()) >= 4
    # trend of frequency against pressure at the held-out pressures (6.75, 8.25 bar)
    assert len(check["held_out"]) >= 2 * 2 * 4
    assert check["max_held_out_error"] < 0.005
    # the files
    out = serial["out"]
    for name in results.summary["files"]:
        assert (out / name).is_file(), name
    import pyarrow.parquet as pq

    table = pq.read_table(out / "modes.parquet")
    assert table.num_rows == len(results.modes) > 0
    assert {"family", "pressure_bar", "frequency_std_hz", "modal_damping"} <= set(
        table.column_names
    )
    for t in results.summary["tests"]:
        for p in t["documents"].values():
            assert json.loads((out / p).read_text("utf-8"))
    damping = pq.read_table(out / "damping.parquet").to_pylist()
    # one row per entry of each test's C' (5 or 6 modes), labelled by families
    assert len(damping) == sum(
        len(r.documents["damping"]["modal"]) ** 2 for r in runs if "damping" in r.documents
    )
    assert all(d["family_k"] and d["family_n"] for d in damping)
    html = (out / "report.html").read_text("utf-8")
    assert "Damping matrix across conditions" in html
    assert "data:image/png;base64," in html
    assert 'href="tests/' in html


def test_rerun_recomputes_only_what_changed(virtual: Path, serial: dict[str, Any]) -> None:
    campaign = serial["campaign"]
    out = serial["out"]
    runs = run_tests(campaign, out, mode="serial")
    assert sum(len(r.computed) for r in runs) == 0
    assert sum(len(r.reused) for r in runs) == 6 * 2 + 2
    # a changed damping setting renews the damping step only
    text = (virtual / "campaign.toml").read_text("utf-8").replace("samples = 50", "samples = 10")
    changed = virtual / "changed.toml"
    changed.write_text(text, encoding="utf-8")
    runs = run_tests(load_campaign(changed), out, mode="serial")
    assert sorted({s for r in runs for s in r.computed}) == ["damping"]
    assert sum(len(r.computed) for r in runs) == 6


def test_scheduler_and_one_worker_give_the_serial_results(
    virtual: Path, serial: dict[str, Any], cluster: Any, tmp_path: Path
) -> None:
    ref = (serial["out"] / "modes.csv").read_bytes()
    # a real LocalCluster with 2 worker processes, started separately, passed by address
    invoke(
        "campaign",
        str(virtual / "campaign.toml"),
        "--out",
        str(tmp_path / "two"),
        "--scheduler",
        cluster.scheduler_address,
        "--no-report",
    )
    assert (tmp_path / "two" / "modes.csv").read_bytes() == ref
    # the default local cluster with one worker
    invoke(
        "campaign",
        str(virtual / "campaign.toml"),
        "--out",
        str(tmp_path / "one"),
        "--workers",
        "1",
        "--no-report",
    )
    assert (tmp_path / "one" / "modes.csv").read_bytes() == ref
    for name in ("modes.csv", "damping.csv", "trends.csv", "lateral.csv"):
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes()
    s = json.loads((tmp_path / "two" / "campaign.json").read_text("utf-8"))
    assert s["steps_computed"] == 6 * 2 + 2


def test_a_killed_worker_is_retried_and_nothing_is_lost(
    virtual: Path, serial: dict[str, Any], cluster: Any, tmp_path: Path
) -> None:
    from distributed import Client

    # long Monte Carlo damping so that tasks are running when a worker is killed
    text = (virtual / "campaign.toml").read_text("utf-8").replace("samples = 50", "samples = 400")
    path = virtual / "slow.toml"
    path.write_text(text, encoding="utf-8")
    campaign = load_campaign(path)
    killed: list[int] = []
    with Client(cluster.scheduler_address) as client:

        def kill_a_busy_worker() -> None:
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and not killed:
                busy = [w for w, keys in client.processing().items() if keys]
                if busy:
                    pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)
                    return
                time.sleep(0.05)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        runs = run_tests(campaign, tmp_path / "out", client=client, mode="scheduler")
        killer.join()
    assert killed, "no worker was busy"
    assert all(r.ok for r in runs), [(r.spec.rel, r.reason) for r in runs if not r.ok]
    # the modal results are those of the serial run, bit for bit (same keys, same documents)
    ref = {r.spec.test_id: r.documents["modal"] for r in serial["runs"] if "modal" in r.documents}
    for r in runs:
        if r.spec.study == "radial":
            assert r.documents["modal"] == ref[r.spec.test_id]


def test_an_interrupted_command_resumes(virtual: Path, tmp_path: Path) -> None:
    text = (virtual / "campaign.toml").read_text("utf-8").replace("samples = 50", "samples = 300")
    path = virtual / "resume.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    cmd = [
        sys.executable,
        "-c",
        "from tyredamp.cli import main; main()",
        "campaign",
        str(path),
        "--out",
        str(out),
        "--serial",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            cache = out / "cache"
            if cache.is_dir() and len(list(cache.glob("*.json"))) >= 3:
                break
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    stored = {p.stem for p in (out / "cache").glob("*.json")}
    assert 3 <= len(stored) < 14  # interrupted mid-way, with finished steps on disk
    runs = run_tests(load_campaign(path), out, mode="serial")
    assert all(r.ok for r in runs)
    reused = {r.keys[s] for r in runs for s in r.reused}
    computed = {r.keys[s] for r in runs for s in r.computed}
    assert reused == stored  # everything that finished is read back, nothing recomputed
    assert not computed & stored
    assert len(reused) + len(computed) == 14


def test_a_corrupt_file_is_reported_and_the_others_complete(
    virtual: Path, serial: dict[str, Any], tmp_path: Path
) -> None:
    camp = tmp_path / "camp"
    shutil.copytree(virtual / "data", camp / "data")
    shutil.copy(virtual / "campaign.toml", camp / "campaign.toml")
    bad = camp / "data" / "T1_7.5bar_20000N.uff"
    bad.write_bytes(bad.read_bytes()[:1000])
    out = tmp_path / "out"
    shutil.copytree(serial["out"] / "cache", out / "cache")  # same files: reused
    res = CliRunner().invoke(
        cli, ["campaign", str(camp / "campaign.toml"), "--out", str(out), "--serial"]
    )
    assert res.exit_code == 1  # the campaign ran; a test failed
    assert "1 failed" in res.output
    failed = [line for line in res.output.splitlines() if line.startswith("failed: ")]
    assert len(failed) == 1
    assert failed[0].startswith("failed: data/T1_7.5bar_20000N.uff: ")
    assert "/tmp" not in failed[0].split(": ", 2)[2] or str(camp) not in failed[0]
    s = json.loads((out / "campaign.json").read_text("utf-8"))
    assert s["n_ok"] == 7
    assert s["n_failed"] == 1
    assert s["steps_computed"] == 0  # the other tests came from the cache
    assert "T1_7.5bar_20000N" in (out / "report.html").read_text("utf-8")


def test_output_folder_of_someone_else_is_refused(virtual: Path, tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine", encoding="utf-8")
    (tmp_path / "cache").mkdir()  # a folder named cache that is not ours
    (tmp_path / "cache" / "mine.json").write_text("{}", encoding="utf-8")
    res = CliRunner().invoke(
        cli, ["campaign", str(virtual / "campaign.toml"), "--out", str(tmp_path), "--serial"]
    )
    assert res.exit_code != 0
    assert "not an earlier campaign output" in str(res.exception)
    assert (tmp_path / "notes.txt").read_text("utf-8") == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache", "notes.txt"]
    assert [p.name for p in (tmp_path / "cache").iterdir()] == ["mine.json"]


def test_without_the_campaign_extra_the_command_says_what_to_install(
    virtual: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import importlib.util

    real = importlib.util.find_spec

    def find_spec(name: str, *a: Any, **k: Any) -> Any:
        return None if name in ("distributed", "dask") else real(name, *a, **k)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    from tyredamp.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["campaign", str(virtual / "campaign.toml"), "--out", str(tmp_path / "o"), "--dask"])
    assert exc.value.code == 2
    assert not (tmp_path / "o").exists()


def test_the_adapter_gives_the_documents_of_the_single_test_commands(
    virtual: Path, tmp_path: Path
) -> None:
    from tyredamp.campaign.steps import process_lateral_test, process_radial_test

    f = virtual / "data" / "T1_6bar_20000N.uff"
    invoke("modal", str(f), "--out", str(tmp_path / "m.json"), "--band", "30", "180")
    invoke(
        "damping", str(tmp_path / "m.json"), "--out", str(tmp_path / "d.json"), "--samples", "50"
    )
    res = process_radial_test(
        f, settings={"modal": {"band": [30.0, 180.0]}, "damping": {"samples": 50}}
    )
    modes = dict(res.documents["modal"])
    assert modes.pop("campaign")["input"] == "frf"
    assert modes == json.loads((tmp_path / "m.json").read_text("utf-8"))
    damping = dict(res.documents["damping"])
    cli_damping = json.loads((tmp_path / "d.json").read_text("utf-8"))
    assert damping["kind"] == cli_damping["kind"] == "damping"  # the documents' own layout
    assert damping.pop("meta")["model"] == cli_damping.pop("meta")["model"] == "complex"
    assert damping == cli_damping
    lat = virtual / "data" / "lateral_5kmh.npz"
    invoke("lateral", "fit", str(lat), "--out", str(tmp_path / "l.json"), "--speed", "5")
    doc = dict(process_lateral_test(lat, {"speed_kmh": 5.0}).documents["fit"])
    cli_doc = json.loads((tmp_path / "l.json").read_text("utf-8"))
    assert doc["kind"] == cli_doc["kind"] == "lateral-fit"
    assert doc.pop("input")["file"] == "lateral_5kmh.npz"
    assert cli_doc.pop("input")["file"] == str(lat)
    assert doc == cli_doc


def test_time_data_goes_through_the_frf_step_of_tyredamp_frf(tmp_path: Path) -> None:
    from tyredamp.campaign.steps import process_radial_test

    td = tmp_path / "t.uff"
    invoke("simulate", "radial", "--out", str(td), "--periods", "2", "--seed", "3")
    invoke("frf", str(td), "--out", str(tmp_path / "f.uff"))
    invoke("modal", str(tmp_path / "f.uff"), "--out", str(tmp_path / "m.json"))
    res = process_radial_test(td, settings={"damping": {"enabled": False}})
    assert set(res.documents) == {"modal"}  # damping switched off
    doc = res.documents["modal"]
    assert doc["campaign"]["input"] == "time"
    assert doc["campaign"]["quality"]["name"]  # the data-quality check of the time data
    cli_doc = json.loads((tmp_path / "m.json").read_text("utf-8"))
    assert doc["models"] == cli_doc["models"]  # the FRF file is lossless (binary UFF 58b)


def test_doubled_modes_are_tracked_as_pairs_without_swaps(tmp_path: Path) -> None:
    from tyredamp.campaign.virtual import VirtualCampaign, write_virtual_campaign

    # shakers at points 1 and 5 (90 deg apart) see both members of the doubled modes that
    # the contact patch splits: pairs with their members a (lower) and b
    spec = VirtualCampaign(1, (6.0, 7.5, 9.0), (20000.0,), (), 1.7, 4, 0, (1, 5))
    truth = write_virtual_campaign(tmp_path / "v", spec)
    campaign = load_campaign(tmp_path / "v" / "campaign.toml")
    runs = run_tests(campaign, tmp_path / "out", mode="serial")
    assert all(r.ok for r in runs)
    results = write_outputs(campaign, runs, tmp_path / "out", report=False)
    check = compare_with_truth(results, truth, runs)
    assert check["unmatched"] == []
    assert check["swaps"] == []
    assert check["slot_swaps"] == []
    # the true pairs: the tyre's modes followed through the pressures with their exact
    # shapes, doubled modes as pairs; those with both members visible at every pressure
    branches = true_branches(truth)
    files = [t["file"] for t in truth["tests"]]
    members: dict[str, dict[str, set[str]]] = {}
    for (key, _), (branch, slot, _) in branches.items():
        if key in files and slot:
            members.setdefault(branch, {}).setdefault(key, set()).add(slot)
    always = {b for b, at in members.items() if all(at.get(f) == {"a", "b"} for f in files)}
    assert always  # the patch splits doubled modes that both shakers see
    # every pair family holds both members of one true pair, each slot one member
    for f in check["pairs"]:
        (branch,) = check["branches"][f]["T1"]
        assert branch in members, (f, branch)
    # every true pair seen at all three pressures is one pair family through all three
    n_tests = {f["family"]: f["n_tests"] for f in results.summary["families"]}
    fams = {b: [f for f in check["pairs"] if check["branches"][f]["T1"] == {b}] for b in always}
    assert all(len(v) == 1 and n_tests[v[0]] == 3 for v in fams.values()), fams
    held = [h for h in check["held_out"] if h["slot"] and [h["family"]] in fams.values()]
    assert len(held) == len(always) * 2 * 2  # pairs x 2 members x 2 held-out pressures
    # the trend of the other pressures predicts a held-out one to 1 %: the loaded tyre's
    # f(p) is curved (sidewall stiffness 90 % from pressure, the patch shortens with
    # pressure) and the members of the n = 2 pair veer (split 2.4 Hz at 6 and 9 bar,
    # 0.2 Hz at 7.5 bar), so a slot's f(p) bends; 0.75 % at most here
    assert check["max_held_out_error"] < 0.01


def _dominant_true_harmonic(truth: dict[str, Any], branches: Any, wanted: set[str]) -> int:
    """The harmonic with the largest summed energy fraction over the true shapes of branches."""
    energy: dict[int, float] = {}
    angles = [22.5 * k for k in range(16)]
    for t in truth["tests"]:
        for q, m in enumerate(t.get("modes") or []):
            if branches.get((t["file"], q), ("",))[0] in wanted:
                w = mode_wave(angles, [complex(a, b) for a, b in m["shape"]])
                assert w is not None
                energy[w.n] = energy.get(w.n, 0.0) + w.fraction
    return max(sorted(energy), key=lambda n: energy[n])


def test_the_output_folder_can_come_from_the_campaign_file(
    virtual: Path, serial: dict[str, Any]
) -> None:
    text = 'output = "from_file"\n' + (virtual / "campaign.toml").read_text("utf-8")
    (virtual / "with_output.toml").write_text(text, encoding="utf-8")
    shutil.copytree(serial["out"] / "cache", virtual / "from_file" / "cache")
    invoke("campaign", str(virtual / "with_output.toml"), "--serial", "--no-report")
    s = json.loads((virtual / "from_file" / "campaign.json").read_text("utf-8"))
    assert s["n_ok"] == 8
    assert s["steps_computed"] == 0
