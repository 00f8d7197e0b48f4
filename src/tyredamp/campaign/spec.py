"""The campaign file: which tests, under which conditions, processed how, written where.

A campaign file is TOML (read with :mod:`tomllib`); the layout is described
by the JSON schema ``tyredamp/schemas/campaign.schema.json`` and in
``docs/campaign.md``::

    name = "truck tyres, pressure and load sweep"   # optional
    output = "results"                             # optional, --out overrides

    [defaults]                     # conditions every test starts from (optional)
    study = "radial"
    temperature_c = 20.0

    [settings.radial.modal]        # per study and step; defaults: the single-test commands
    band = [30.0, 200.0]

    [tracking]
    model = "complex"

    [[tests]]
    files = "data/A_*bar.uff"      # a path or glob (or a list), relative to this file
    channel_map = "channels.toml"  # optional (also in [defaults]): roles, units and
                                   # sensitivities of the channels (docs/file-formats.md)
    tyre = "A"
    pressure_bar = 7.5
    load_n = 20000.0

Every bad field raises :class:`CampaignFileError` with one line naming the
file and the key (``campaign.toml: tests[3].pressure_bar: expected ...``).
"""

from __future__ import annotations

import glob
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..exceptions import FileFormatError, InputError
from ..io._guard import load_toml
from . import steps

__all__ = [
    "CONDITIONS",
    "Campaign",
    "CampaignFileError",
    "TestSpec",
    "load_campaign",
    "parse_campaign",
]

#: Condition columns a test can carry: name -> (unit, kind).
CONDITIONS: dict[str, tuple[str, str]] = {
    "tyre": ("", "text"),
    "pressure_bar": ("bar", "nonneg"),
    "load_n": ("N", "nonneg"),
    "speed_kmh": ("km/h", "nonneg"),
    "temperature_c": ("degC", "temperature"),
    "note": ("", "text"),
}
#: The numeric conditions (the axes of the trends), in the order they are tried.
NUMERIC_CONDITIONS: tuple[str, ...] = ("pressure_bar", "load_n", "speed_kmh", "temperature_c")

_TOP_KEYS = ("name", "output", "defaults", "settings", "tracking", "tests")
_TEST_KEYS = ("files", "study", "channel_map", *CONDITIONS)
_TRACKING = {"model": ("complex", "real")}
_GLOB = re.compile(r"[*?\[]")


class CampaignFileError(InputError):
    """A campaign file that cannot be read or has a bad field (one line naming file and key)."""


@dataclass(frozen=True)
class TestSpec:
    """One test of a campaign.

    Attributes
    ----------
    test_id : str
        Unique name (from the file path and study), safe as a file name.
    path : Path
        The test file (absolute).
    rel : str
        The file relative to the campaign file's folder (POSIX), or absolute.
    study : str
        ``"radial"`` or ``"lateral"``.
    conditions : dict
        ``tyre`` (str), ``pressure_bar``, ``load_n``, ``speed_kmh``,
        ``temperature_c`` (float or None) and ``note`` (str or None).
    """

    __test__ = False  # not a pytest class

    test_id: str
    path: Path
    rel: str
    study: str
    conditions: dict[str, Any]


@dataclass(frozen=True)
class Campaign:
    """A parsed campaign file.

    Attributes
    ----------
    path : Path
        The campaign file.
    name : str
        Campaign name (default the file stem).
    tests : tuple of TestSpec
        Every test, in file order (glob matches sorted).
    settings : dict
        Complete processing settings per study (``{study: {section: {key: value}}}``).
    tracking : dict
        Mode tracking options (``model``: which identified model is tracked).
    output : Path or None
        Output folder from the file (relative to it), if given.
    """

    path: Path
    name: str
    tests: tuple[TestSpec, ...]
    settings: dict[str, dict[str, dict[str, Any]]]
    tracking: dict[str, Any] = field(default_factory=dict)
    output: Path | None = None


def _err(src: Path, key: str, message: str) -> CampaignFileError:
    return CampaignFileError(f"{src}: {key}: {message}")


def _condition(src: Path, key: str, name: str, value: Any) -> Any:
    kind = CONDITIONS[name][1]
    if kind == "text":
        if isinstance(value, bool) or not isinstance(value, str | int):
            raise _err(src, key, f"expected text, got {value!r}")
        return str(value)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _err(src, key, f"expected a number in {CONDITIONS[name][0]}, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise _err(src, key, f"expected a finite number, got {value!r}")
    if kind == "nonneg" and v < 0:
        raise _err(src, key, f"expected a value >= 0 {CONDITIONS[name][0]}, got {v:g}")
    if kind == "temperature" and v <= -273.15:
        raise _err(src, key, f"expected a temperature above -273.15 degC, got {v:g}")
    return v


def _channel_map(src: Path, base: Path, key: str, value: Any) -> dict[str, Any]:
    """A test's channel map: a TOML/JSON file (relative to the campaign file) or a table.

    Returned as its document (``ChannelMap.to_dict``), which travels with the
    test's conditions to the workers and into the step's cache key.
    """
    from ..io.channelmap import ChannelMap

    try:
        if isinstance(value, str):
            full = Path(value) if Path(value).is_absolute() else base / value
            if not full.is_file():
                raise _err(src, key, f"channel-map file not found: {value}")
            cmap = ChannelMap.from_file(full)
        elif isinstance(value, dict):
            cmap = ChannelMap.from_dict(value, key)
        else:
            raise _err(src, key, f"expected a channel-map file or a table, got {value!r}")
    except CampaignFileError:
        raise
    except InputError as exc:
        raise _err(src, key, str(exc)) from None
    return cmap.to_dict()


def _safe_id(text: str) -> str:
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._")
    return s or "test"


def _expand(src: Path, base: Path, key: str, value: Any) -> list[Path]:
    patterns = [value] if isinstance(value, str) else value
    if not isinstance(patterns, list) or not patterns:
        raise _err(src, key, f"expected a path, a glob or a list of them, got {value!r}")
    out: list[Path] = []
    for j, pat in enumerate(patterns):
        k = key if isinstance(value, str) else f"{key}[{j}]"
        if not isinstance(pat, str) or not pat.strip():
            raise _err(src, k, f"expected a path or glob, got {pat!r}")
        full = Path(pat) if Path(pat).is_absolute() else base / pat
        if _GLOB.search(pat):
            hits = sorted(Path(p) for p in glob.glob(str(full), recursive=True))
            hits = [h for h in hits if h.is_file()]
            if not hits:
                raise _err(src, k, f"no file matches {pat!r}")
            out += hits
        else:
            if not full.is_file():
                raise _err(src, k, f"file not found: {pat}")
            out.append(full)
    return out


def _rel(path: Path, base: Path) -> str:
    try:
        return path.resolve().relative_to(base.resolve()).as_posix()
    except ValueError:
        return path.resolve().as_posix()


def parse_campaign(doc: Any, src: Path) -> Campaign:
    """Validate a campaign document (the parsed TOML) read from ``src``.

    Raises
    ------
    CampaignFileError
        Naming the file and the key of the first bad field.
    """
    if not isinstance(doc, dict):
        raise CampaignFileError(f"{src}: expected a TOML table at the top")
    unknown = sorted(set(doc) - set(_TOP_KEYS))
    if unknown:
        raise _err(src, unknown[0], f"unknown key; expected one of {list(_TOP_KEYS)}")
    base = src.parent
    name = doc.get("name", src.stem)
    if not isinstance(name, str):
        raise _err(src, "name", f"expected text, got {name!r}")
    output = doc.get("output")
    if output is not None and (not isinstance(output, str) or not output.strip()):
        raise _err(src, "output", f"expected a folder path, got {output!r}")
    out_path = None if output is None else (base / output)

    settings_doc = doc.get("settings", {})
    if not isinstance(settings_doc, dict):
        raise _err(src, "settings", f"expected a table, got {settings_doc!r}")
    bad = sorted(set(settings_doc) - set(steps.STUDIES))
    if bad:
        raise _err(src, f"settings.{bad[0]}", f"unknown study; expected {sorted(steps.STUDIES)}")
    settings: dict[str, dict[str, dict[str, Any]]] = {}
    for study in steps.STUDIES:
        try:
            settings[study] = steps.validate_settings(
                study, settings_doc.get(study), f"settings.{study}"
            )
        except InputError as exc:
            raise CampaignFileError(f"{src}: {exc}") from None

    tracking_doc = doc.get("tracking", {})
    if not isinstance(tracking_doc, dict):
        raise _err(src, "tracking", f"expected a table, got {tracking_doc!r}")
    tracking: dict[str, Any] = {"model": "complex"}
    for k, v in tracking_doc.items():
        if k not in _TRACKING:
            raise _err(src, f"tracking.{k}", f"unknown key; expected one of {sorted(_TRACKING)}")
        if v not in _TRACKING[k]:
            raise _err(src, f"tracking.{k}", f"expected one of {list(_TRACKING[k])}, got {v!r}")
        tracking[k] = v

    defaults = doc.get("defaults", {})
    if not isinstance(defaults, dict):
        raise _err(src, "defaults", f"expected a table, got {defaults!r}")
    bad = sorted(set(defaults) - {"study", "channel_map", *CONDITIONS})
    if bad:
        raise _err(
            src,
            f"defaults.{bad[0]}",
            f"unknown key; expected study, channel_map or one of {list(CONDITIONS)}",
        )

    entries = doc.get("tests")
    if not isinstance(entries, list) or not entries:
        raise _err(src, "tests", "expected at least one [[tests]] entry")
    tests: list[TestSpec] = []
    seen: dict[tuple[str, Path], str] = {}
    ids: set[str] = set()
    for i, entry in enumerate(entries):
        where = f"tests[{i}]"
        if not isinstance(entry, dict):
            raise _err(src, where, f"expected a table, got {entry!r}")
        bad = sorted(set(entry) - set(_TEST_KEYS))
        if bad:
            raise _err(src, f"{where}.{bad[0]}", f"unknown key; expected one of {list(_TEST_KEYS)}")
        merged = {**defaults, **entry}
        if "files" not in merged:
            raise _err(src, f"{where}.files", "missing: the test file(s), a path or glob")
        study = merged.get("study", "radial")
        if study not in steps.STUDIES:
            raise _err(
                src, f"{where}.study", f"expected one of {sorted(steps.STUDIES)}, got {study!r}"
            )
        conditions: dict[str, Any] = {}
        for c in CONDITIONS:
            v = merged.get(c)
            k = f"{where}.{c}" if c in entry else f"defaults.{c}"
            conditions[c] = None if v is None else _condition(src, k, c, v)
        if merged.get("channel_map") is not None:
            k = f"{where}.channel_map" if "channel_map" in entry else "defaults.channel_map"
            conditions["channel_map"] = _channel_map(src, base, k, merged["channel_map"])
        for path in _expand(src, base, f"{where}.files", merged["files"]):
            rp = path.resolve()
            if (study, rp) in seen:
                raise _err(
                    src,
                    f"{where}.files",
                    f"{_rel(path, base)} is already a test of {seen[(study, rp)]}",
                )
            seen[(study, rp)] = where
            rel = _rel(path, base)
            tid = _safe_id(f"{study}-{rel.rsplit('.', 1)[0].replace('/', '-')}")
            k = 2
            while tid in ids:
                tid = _safe_id(f"{study}-{rel.replace('/', '-')}-{k}")
                k += 1
            ids.add(tid)
            tests.append(TestSpec(tid, rp, rel, study, dict(conditions)))
    return Campaign(src, name, tuple(tests), settings, tracking, out_path)


#: The largest campaign file read (bytes).
MAX_CAMPAIGN_BYTES = 16 << 20


def load_campaign(path: str | Path) -> Campaign:
    """Read and validate a campaign file (TOML).

    Raises
    ------
    CampaignFileError
        Missing or unreadable file, invalid TOML, or a bad field (one line
        naming the file and the key).
    """
    src = Path(path)
    if not src.is_file():
        raise CampaignFileError(f"{src}: campaign file not found")
    try:
        if src.stat().st_size > MAX_CAMPAIGN_BYTES:
            raise CampaignFileError(
                f"{src}: {src.stat().st_size} bytes; a campaign file is at most "
                f"{MAX_CAMPAIGN_BYTES >> 20} MiB (globs list many test files in one line)"
            )
        doc = load_toml(src.read_text(encoding="utf-8"), str(src))
    except UnicodeDecodeError:
        raise CampaignFileError(f"{src}: not a text (TOML) file") from None
    except FileFormatError as exc:
        raise CampaignFileError(str(exc)) from None
    except RecursionError:
        raise CampaignFileError(f"{src}: not valid TOML (nested too deeply)") from None
    except OSError as exc:
        raise CampaignFileError(f"{src}: cannot read ({exc.strerror})") from None
    return parse_campaign(doc, src)
