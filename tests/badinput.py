"""The bad-input corpus generator (issue 15): inputs, hostile files and a runner.

Every case runs ``tyredamp.cli.main`` in-process in its own directory and checks
the promises of docs/reference/safety.md:

* the exit code;
* stderr is exactly one line ``tyredamp: error: ...`` naming the problem (no
  traceback, no warning before it);
* nothing is left behind (no temporary, no partial output) and no user file
  is removed: the directory tree after the run is the tree before it, entry
  by entry (type, bytes of every regular file, link targets);
* every input is byte-identical afterwards (same hashes).

:func:`make_library` writes small valid inputs (a 3-DOF FRF, time data, the
lateral rig's FRF, modes, damping and lateral-fit JSON) once per session;
:func:`hostile_npz` builds NPZ archives with crafted headers.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
import stat
import struct
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tyredamp.cli import main
from tyredamp.frf import Channel
from tyredamp.io import write_frf, write_timedata
from tyredamp.timedata import TimeData
from tyredamp.virtual.lateral_rig import VirtualLateralRig

from .helpers import chain_system

Setup = Callable[[Path], None]


@dataclass(frozen=True)
class Case:
    """One bad-input case.

    ``argv`` runs in the case directory (relative paths); ``files`` maps names
    in that directory to library file names (copied) or bytes; ``setup`` makes
    links, FIFOs, permissions. ``needle`` must appear (case-insensitive) in the
    one stderr line; ``code`` is the expected exit code.
    """

    id: str
    argv: list[str]
    code: int
    needle: str
    files: dict[str, str | bytes] = field(default_factory=dict)
    setup: Setup | None = None
    #: paths (relative) a successful run may create or change
    writes: tuple[str, ...] = ()
    #: a monkeypatch applied for this case: (target, name, value-factory)
    patch: Callable[[pytest.MonkeyPatch, Path], None] | None = None


def make_library(root: Path) -> Path:
    """Write the valid inputs every case starts from; returns the directory."""
    lib = root / "lib"
    lib.mkdir()
    sysm = chain_system(3, c_local=(5.0, 0.0, 2.0))
    f = np.linspace(0.5, 40.0, 300)
    frf = sysm.frf(f, outputs=[0, 1, 2], inputs=[0])
    write_frf(frf, lib / "frf.npz")
    write_frf(frf, lib / "frf.csv")
    write_frf(frf, lib / "frf.uff")
    rng = np.random.default_rng(1)
    fs = 256.0
    force = rng.standard_normal(2048)
    resp = np.convolve(force, np.exp(-np.arange(64) / 8.0) * np.cos(np.arange(64)), "same")
    td = TimeData(
        np.vstack([force, resp]),
        fs,
        [Channel(1, 3), Channel(2, 3)],
        ["force", "acceleration"],
    )
    write_timedata(td, lib / "time.npz")
    lat = VirtualLateralRig().measure(5.0, 1.7, "ground", 0)
    write_frf(lat.frf, lib / "lat.npz")
    for argv in (
        ["modal", "frf.npz", "-o", "modes.json"],
        ["damping", "modes.json", "-o", "damping.json", "--samples", "0"],
        ["lateral", "fit", "lat.npz", "-o", "lat.json"],
    ):
        cwd = os.getcwd()
        os.chdir(lib)
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                main(argv)
        except SystemExit as exc:  # pragma: no cover - the library must build
            raise AssertionError(f"{argv}: exit {exc.code}") from None
        finally:
            os.chdir(cwd)
    return lib


def npz_bytes(header: Any, arrays: dict[str, np.ndarray], raw_header: bool = False) -> bytes:
    """An NPZ archive with ``header`` (a dict as JSON text, or any array when ``raw_header``)."""
    buf = io.BytesIO()
    h = header if raw_header else np.array(json.dumps(header))
    np.savez(buf, header=h, **arrays)
    return buf.getvalue()


def frf_header(**over: Any) -> dict[str, Any]:
    head: dict[str, Any] = {
        "format": "tyredamp",
        "version": 1,
        "type": "frf",
        "kind": "receptance",
        "outputs": [{"node": 1, "direction": 3}],
        "inputs": [{"node": 1, "direction": 3}],
        "meta": {},
    }
    head.update(over)
    return head


def frf_npz(freq: np.ndarray | None = None, h: np.ndarray | None = None, **over: Any) -> bytes:
    """A 1x1 FRF archive (a single-DOF receptance unless given)."""
    f = np.linspace(1.0, 50.0, 64) if freq is None else freq
    w = 2 * np.pi * np.real(f)
    hh = 1.0 / (1e4 - w**2 + 2j * w) if h is None else h
    arrays = {"frequency": f, "H": np.asarray(hh).reshape(1, 1, -1)}
    arrays.update(over.pop("arrays", {}))
    return npz_bytes(frf_header(**over), arrays)


def huge_member_npz() -> bytes:
    """An NPZ whose 'H' member header claims 1e12 complex elements but holds none."""
    good = frf_npz()
    zin = zipfile.ZipFile(io.BytesIO(good))
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info)
            if info.filename == "H.npy":
                hdr = "{'descr': '<c16', 'fortran_order': False, 'shape': (1, 1, 1000000000000), }"
                hdr = hdr.ljust(118) + "\n"
                data = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(hdr)) + hdr.encode()
            zout.writestr(info.filename, data)
    return out.getvalue()


def nested_json(depth: int = 100_000) -> bytes:
    return ("[" * depth + "]" * depth).encode()


# ----------------------------------------------------------------------------- campaign
CAMPAIGN_TOML = b"""name = "bad-input corpus"
[[tests]]
files = "data/frf.npz"
tyre = "A"
pressure_bar = 7.5
"""


def _campaign_output(extra: dict[str, str]) -> Setup:
    """An earlier campaign output ``res/`` (its summary lists what it wrote) plus ``extra``."""

    def setup(d: Path) -> None:
        out = d / "res"
        (out / "tests" / "frf").mkdir(parents=True)
        (out / "modes.csv").write_text("test_id\n")
        (out / "tests" / "frf" / "modes.json").write_text("{}")
        doc = {
            "kind": "tyredamp-campaign",
            "version": 1,
            "written": ["campaign.json", "modes.csv", "tests/frf/modes.json"],
        }
        (out / "campaign.json").write_text(json.dumps(doc))
        for k, v in extra.items():
            (out / k).parent.mkdir(parents=True, exist_ok=True)
            (out / k).write_text(v)

    return setup


def campaign_cases() -> list[Case]:
    """``campaign`` and ``simulate campaign``: bad campaign files and refused output folders.

    The campaign writes into a new or empty folder, or one holding nothing but
    what earlier campaign runs wrote; ``simulate campaign`` likewise with an
    earlier virtual campaign. Everything is checked before any test runs.
    """
    files: dict[str, str | bytes] = {"c.toml": CAMPAIGN_TOML, "data/frf.npz": "frf.npz"}

    def argv(*rest: str) -> list[str]:
        return ["campaign", "c.toml", "--serial", *rest]

    def user_dir(name: str) -> Setup:
        return lambda d: ((d / name).mkdir(), (d / name / "notes.txt").write_text("my notes"))

    sim = ["simulate", "campaign", "--quick"]
    return [
        Case(
            "campaign-bad-toml",
            argv("-o", "res"),
            2,
            "not valid TOML",
            {**files, "c.toml": b"name = [unclosed\n"},
        ),
        Case(
            "campaign-bad-setting",
            argv("-o", "res"),
            2,
            "settings.radial.modal.model",
            {**files, "c.toml": CAMPAIGN_TOML + b'[settings.radial.modal]\nmodel = "x"\n'},
        ),
        Case("campaign-missing-file", ["campaign", "none.toml", "-o", "res"], 2, "not found"),
        Case(
            "campaign-missing-test-file",
            argv("-o", "res"),
            2,
            "data/frf.npz",
            {"c.toml": CAMPAIGN_TOML},
        ),
        Case(
            "campaign-out-is-campaign-file", argv("-o", "c.toml"), 2, "is or holds the input", files
        ),
        Case(
            "campaign-out-is-file",
            argv("-o", "f"),
            2,
            "not a directory",
            {**files, "f": b"a user's file"},
        ),
        Case("campaign-out-holds-input", argv("-o", "data"), 2, "holds the input file", files),
        Case(
            "campaign-dir-with-user-files",
            argv("-o", "res"),
            2,
            "not an earlier campaign output",
            files,
            user_dir("res"),
        ),
        Case(
            "campaign-earlier-output-with-user-file",
            argv("-o", "res"),
            2,
            "notes.txt",
            files,
            _campaign_output({"notes.txt": "my notes"}),
        ),
        Case(
            "campaign-foreign-file-in-cache",
            argv("-o", "res"),
            2,
            "cache/mine.json",
            files,
            _campaign_output({"cache/mine.json": "{}"}),
        ),
        Case("campaign-out-dot", argv("-o", "."), 2, "input file", files),
        Case(
            "simulate-campaign-dir-with-user-files",
            [*sim, "-o", "v"],
            2,
            "not an earlier virtual campaign",
            setup=user_dir("v"),
        ),
        Case(
            "simulate-campaign-out-is-file",
            [*sim, "-o", "f"],
            2,
            "not a directory",
            {"f": b"a user's file"},
        ),
        Case("simulate-campaign-missing-parent", [*sim, "-o", "nodir/v"], 2, "does not exist"),
    ]


# ----------------------------------------------------------------------------- runner
def snapshot(root: Path) -> dict[str, tuple[Any, ...]]:
    """Every entry under ``root`` (links not followed): type and content hash / target."""
    out: dict[str, tuple[Any, ...]] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in [*dirnames, *filenames]:
            p = Path(dirpath) / n
            rel = p.relative_to(root).as_posix()
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                out[rel] = ("link", os.readlink(p))
            elif stat.S_ISREG(st.st_mode):
                out[rel] = ("file", hashlib.sha256(p.read_bytes()).hexdigest(), st.st_ino)
            elif stat.S_ISDIR(st.st_mode):
                out[rel] = ("dir",)
            else:
                out[rel] = ("special", stat.S_IFMT(st.st_mode))
    return out


def prepare(case: Case, lib: Path, d: Path) -> None:
    d.mkdir(parents=True, exist_ok=True)
    for name, src in case.files.items():
        p = d / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(src, bytes):
            p.write_bytes(src)
        else:
            shutil.copyfile(lib / src, p)
    if case.setup is not None:
        case.setup(d)


def run_main(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out = capsys.readouterr()
    return code, out.out, out.err


def check_one_error_line(err: str, code: int, case_code: int, needle: str) -> str:
    assert "Traceback" not in err
    lines = err.strip("\n").splitlines()
    assert code == case_code, f"exit {code}, expected {case_code}; stderr: {err!r}"
    if case_code == 0:
        assert not [ln for ln in lines if ln.startswith("tyredamp: error")], err
        return ""
    assert len(lines) == 1, f"expected one stderr line, got {lines!r}"
    line = lines[0]
    assert line.startswith("tyredamp: error: "), line
    assert needle.lower() in line.lower(), f"{needle!r} not in {line!r}"
    assert ".tyredamp-" not in line, f"a temporary name reached the user: {line!r}"
    return line
