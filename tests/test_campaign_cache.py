"""The content-addressed step cache (tyredamp.campaign.cache)."""

from __future__ import annotations

import hashlib
from pathlib import Path

from tyredamp.campaign.cache import ResultCache, file_digest, step_key


def test_file_digest_is_the_sha256_of_the_bytes(tmp_path: Path) -> None:
    p = tmp_path / "x.uff"
    data = bytes(range(256)) * 5000  # more than one read block
    p.write_bytes(data)
    assert file_digest(p) == hashlib.sha256(data).hexdigest()
    assert p.read_bytes() == data  # only read


def test_step_key_changes_with_each_ingredient() -> None:
    base = ("radial", "modal", "a" * 64, {"modal": {"band": None}}, {}, None, "0.1.0")
    k0 = step_key(*base)
    assert k0 == step_key(*base)  # deterministic
    assert len(k0) == 64
    variants = [
        ("lateral", *base[1:]),
        (base[0], "damping", *base[2:]),
        (*base[:2], "b" * 64, *base[3:]),
        (*base[:3], {"modal": {"band": [0.0, 100.0]}}, *base[4:]),
        (*base[:4], {"speed_kmh": 5.0}, *base[5:]),
        (*base[:5], "c" * 64, base[6]),
        (*base[:6], "0.2.0"),
    ]
    keys = {step_key(*v) for v in variants}
    assert len(keys) == len(variants)
    assert k0 not in keys
    # settings are keyed by content, not by the order of their keys
    a = step_key("radial", "modal", "a" * 64, {"x": 1, "y": 2}, {}, None, "v")
    b = step_key("radial", "modal", "a" * 64, {"y": 2, "x": 1}, {}, None, "v")
    assert a == b


def test_cache_round_trip_and_bad_entries(tmp_path: Path) -> None:
    cache = ResultCache(tmp_path / "cache")
    key = "d" * 64
    assert cache.get(key) is None
    doc = {"a": [1.5, None, "x"], "b": {"c": 2}}
    cache.put(key, doc, {"test": "t.uff", "step": "modal"})
    assert cache.get(key) == doc
    assert [p.name for p in (tmp_path / "cache").iterdir()] == [f"{key}.json"]  # no temp left
    # a truncated or foreign entry counts as missing (and is computed again)
    cache.path(key).write_text('{"key": "dd', encoding="utf-8")
    assert cache.get(key) is None
    cache.path(key).write_text('{"key": "other", "document": {}}', encoding="utf-8")
    assert cache.get(key) is None


def test_a_task_on_a_missing_or_changed_file_fails_with_its_reason(tmp_path: Path) -> None:
    from tyredamp.campaign.runner import Task, execute

    settings: dict[str, object] = {}
    missing = Task(
        "t", "radial", str(tmp_path / "x.uff"), "x.uff", "0" * 64, ("modal",), {}, settings, {}
    )
    out = execute(missing)
    assert out.failed_step == "modal"
    assert out.reason is not None
    assert out.reason.startswith("x.uff: cannot read")
    assert "shared file system" in out.reason
    (tmp_path / "x.uff").write_bytes(b"new bytes")
    out = execute(missing)  # the digest is not the one planned
    assert out.reason == "x.uff: the file changed during the campaign"
    assert out.documents == {}


def test_what_an_earlier_campaign_wrote_may_be_replaced_and_nothing_else(tmp_path: Path) -> None:
    import json

    import pytest

    from tyredamp.campaign.outputs import campaign_files, check_campaign_output
    from tyredamp.exceptions import InputError

    out = tmp_path / "res"
    assert campaign_files(out) is None  # nothing there
    (out / "cache").mkdir(parents=True)
    key = "ab" * 32
    (out / "cache" / f"{key}.json").write_text("{}")
    # an interrupted first run: only cache entries and a killed write's temporary
    (out / "cache" / f".{key}.json.tyredamp-123-0a1b2c3d.tmp").write_text("")
    assert check_campaign_output(out) == out.resolve()
    # the claim written before the tables: the files it is about to write are its own
    doc = {"kind": "tyredamp-campaign", "version": 1, "written": ["campaign.json", "modes.csv"]}
    (out / "campaign.json").write_text(json.dumps(doc))
    (out / "modes.csv").write_text("x\n")
    (out / ".modes.csv.tyredamp-99-deadbeef.tmp").write_text("")
    assert set(campaign_files(out) or []) >= {
        "campaign.json",
        "modes.csv",
        f"cache/{key}.json",
        ".modes.csv.tyredamp-99-deadbeef.tmp",
    }
    check_campaign_output(out)
    # a file the campaign did not write stops it, and stays
    (out / "modes.parquet.bak").write_text("mine")
    with pytest.raises(InputError, match=r"modes\.parquet\.bak"):
        check_campaign_output(out)
    assert (out / "modes.parquet.bak").read_text() == "mine"
    # a summary that is not ours makes the folder someone else's
    (out / "modes.parquet.bak").unlink()
    (out / "campaign.json").write_text(json.dumps({"kind": "other"}))
    (out / "cache" / f"{key}.json").unlink()
    (out / "cache" / f".{key}.json.tyredamp-123-0a1b2c3d.tmp").unlink()
    with pytest.raises(InputError, match="not an earlier campaign output"):
        check_campaign_output(out)
    # an output folder that holds an input is refused
    with pytest.raises(InputError, match="holds the input file"):
        check_campaign_output(tmp_path, [out / "modes.csv"])
