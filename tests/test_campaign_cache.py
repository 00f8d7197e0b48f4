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
