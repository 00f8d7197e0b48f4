"""The bad-input corpus of issue 15: every command, malformed, hostile, huge, interrupted
and file-system edge cases; each asserts the exit code, one stderr line naming the
problem, nothing left behind, inputs byte-identical and no user file removed.

Run it alone with ``pytest tests/test_badinput.py tests/test_badinput_modal.py -q``.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import tyredamp.io._safety as safety

from .badinput import (
    Case,
    campaign_cases,
    check_one_error_line,
    frf_header,
    frf_npz,
    huge_member_npz,
    make_library,
    nested_json,
    npz_bytes,
    prepare,
    run_main,
    snapshot,
)

EXIT_INPUT, EXIT_RUNTIME = 2, 3


@pytest.fixture(scope="session")
def lib() -> Path:
    return _Library.path()


# ------------------------------------------------------------------ commands that write
#: name: (argv with {out}, input files, output name)
WRITERS: dict[str, tuple[list[str], dict[str, str], str]] = {
    "frf": (["frf", "time.npz", "-o", "{out}"], {"time.npz": "time.npz"}, "f.npz"),
    "modal": (["modal", "frf.npz", "-o", "{out}"], {"frf.npz": "frf.npz"}, "m.json"),
    "damping": (
        ["damping", "modes.json", "-o", "{out}", "--samples", "0"],
        {"modes.json": "modes.json"},
        "d.json",
    ),
    "report": (
        ["report", "damping.json", "-o", "{out}"],
        {"damping.json": "damping.json"},
        "r.html",
    ),
    "lateral-fit": (["lateral", "fit", "lat.npz", "-o", "{out}"], {"lat.npz": "lat.npz"}, "l.json"),
    "lateral-simulate": (["lateral", "simulate", "-o", "{out}"], {}, "s.npz"),
    "simulate-lateral": (["simulate", "lateral", "-o", "{out}"], {}, "s.npz"),
    "simulate-radial": (["simulate", "radial", "--periods", "1", "-o", "{out}"], {}, "s.npz"),
}
READERS = {k: v for k, v in WRITERS.items() if v[1]}


def _argv(name: str, out: str) -> list[str]:
    return [a.replace("{out}", out) for a in WRITERS[name][0]]


def _mkfifo(name: str) -> Any:
    return lambda d: os.mkfifo(d / name)


def _readonly_file(name: str) -> Any:
    def setup(d: Path) -> None:
        (d / name).write_bytes(b"the user's earlier result\n")
        os.chmod(d / name, 0o444)

    return setup


def _readonly_dir(d: Path) -> None:
    (d / "ro").mkdir()
    os.chmod(d / "ro", 0o555)


def _dir(name: str) -> Any:
    return lambda d: (d / name).mkdir()


def _symlink(link: str, target: str) -> Any:
    return lambda d: os.symlink(target, d / link)


def _hardlink(link: str, target: str) -> Any:
    return lambda d: os.link(d / target, d / link)


def _subdir(d: Path) -> None:
    (d / "sub").mkdir()


def output_cases() -> list[Case]:
    cases: list[Case] = []
    for name, (_, files, out) in WRITERS.items():
        cases += [
            Case(f"{name}-out-empty", _argv(name, ""), EXIT_INPUT, "empty path", files),
            Case(
                f"{name}-out-missing-parent",
                _argv(name, f"nodir/{out}"),
                EXIT_INPUT,
                "does not exist",
                files,
            ),
            Case(
                f"{name}-out-is-dir",
                _argv(name, out),
                EXIT_INPUT,
                "is a directory",
                files,
                _dir(out),
            ),
            Case(f"{name}-out-fifo", _argv(name, out), EXIT_INPUT, "FIFO", files, _mkfifo(out)),
            Case(
                f"{name}-out-readonly-file",
                _argv(name, out),
                EXIT_INPUT,
                "read-only",
                files,
                _readonly_file(out),
            ),
            Case(
                f"{name}-out-readonly-dir",
                _argv(name, f"ro/{out}"),
                EXIT_INPUT,
                "not writable",
                files,
                _readonly_dir,
            ),
        ]
    for name, (_, files, _out) in READERS.items():
        inp = next(iter(files))
        cases += [
            Case(f"{name}-out-is-input", _argv(name, inp), EXIT_INPUT, "is the input file", files),
            Case(
                f"{name}-out-is-input-dotdot",
                _argv(name, f"./sub/../{inp}"),
                EXIT_INPUT,
                "is the input file",
                files,
                _subdir,
            ),
            Case(
                f"{name}-out-symlink-to-input",
                _argv(name, "link" + Path(inp).suffix),
                EXIT_INPUT,
                "is the input file",
                files,
                _symlink("link" + Path(inp).suffix, inp),
            ),
            Case(
                f"{name}-out-hardlink-to-input",
                _argv(name, "hard" + Path(inp).suffix),
                EXIT_INPUT,
                "is the input file",
                files,
                _hardlink("hard" + Path(inp).suffix, inp),
            ),
        ]
    # two outputs
    radial = ["simulate", "radial", "--periods", "1"]
    cases += [
        Case(
            "simulate-radial-truth-is-out",
            [*radial, "-o", "s.npz", "--truth", "s.npz"],
            EXIT_INPUT,
            "--truth",
        ),
        Case(
            "simulate-radial-truth-missing-parent",
            [*radial, "-o", "s.npz", "--truth", "nodir/t.json"],
            EXIT_INPUT,
            "does not exist",
            {"s.npz": b"user's own file\n"},
        ),
        Case(
            "simulate-radial-truth-empty",
            [*radial, "-o", "s.npz", "--truth", ""],
            EXIT_INPUT,
            "empty path",
        ),
        Case(
            "report-out-is-second-input",
            ["report", "damping.json", "lat.json", "-o", "lat.json"],
            EXIT_INPUT,
            "is the input file",
            {"damping.json": "damping.json", "lat.json": "lat.json"},
        ),
    ]
    return cases


# ----------------------------------------------------------------------------- demo
def _demo_dir(extra: dict[str, str], marker: bool = True, edited: bool = False) -> Any:
    """An earlier demo output (its files, results.json and the manifest written with them),
    then ``extra`` files of the user's; ``edited``: the user changed report.html."""

    def setup(d: Path) -> None:
        out = d / "demo"
        (out / "figures").mkdir(parents=True)
        (out / "figures" / "a.png").write_bytes(b"png")
        (out / "report.html").write_text("<html></html>")
        if marker:
            doc = {
                "kind": "tyredamp-demo-results",
                "files": ["figures/a.png", "report.html", "results.json", safety.MANIFEST_NAME],
            }
            (out / "results.json").write_text(json.dumps(doc))
            safety._write_manifest(out)
        if edited:
            (out / "report.html").write_text("<html><p>my notes</p></html>")
        for k, v in extra.items():
            (out / k).parent.mkdir(parents=True, exist_ok=True)
            (out / k).write_text(v)

    return setup


def demo_cases() -> list[Case]:
    def inside(d: Path) -> None:
        _demo_dir({})(d)

    return [
        Case(
            "demo-user-files-beside-results",
            ["demo", "--quick", "-o", "demo"],
            EXIT_INPUT,
            "notes.txt",
            setup=_demo_dir({"notes.txt": "my notes"}),
        ),
        Case(
            "demo-user-edited-its-report",
            ["demo", "--quick", "-o", "demo"],
            EXIT_INPUT,
            "changed since tyredamp wrote it",
            setup=_demo_dir({}, edited=True),
        ),
        Case(
            "demo-user-file-in-subdir",
            ["demo", "--quick", "-o", "demo"],
            EXIT_INPUT,
            "figures/mine.png",
            setup=_demo_dir({"figures/mine.png": "my figure"}),
        ),
        Case(
            "demo-foreign-dir",
            ["demo", "--quick", "-o", "demo"],
            EXIT_INPUT,
            "not an earlier tyredamp demo output",
            setup=_demo_dir({}, marker=False),
        ),
        Case(
            "demo-link-to-dir-with-user-files",
            ["demo", "--quick", "-o", "link"],
            EXIT_INPUT,
            "notes.txt",
            setup=lambda d: (_demo_dir({"notes.txt": "x"})(d), os.symlink("demo", d / "link")),
        ),
        Case("demo-out-empty", ["demo", "--quick", "-o", ""], EXIT_INPUT, "empty path"),
        Case("demo-out-dot", ["demo", "--quick", "-o", "."], EXIT_INPUT, "current directory"),
        Case(
            "demo-out-parent-of-cwd",
            ["demo", "--quick", "-o", ".."],
            EXIT_INPUT,
            "current directory",
        ),
        Case(
            "demo-out-is-file",
            ["demo", "--quick", "-o", "f"],
            EXIT_INPUT,
            "not a directory",
            {"f": b"a user's file"},
        ),
        Case(
            "demo-missing-parent",
            ["demo", "--quick", "-o", "nodir/demo"],
            EXIT_INPUT,
            "does not exist",
        ),
        Case("demo-bad-seed", ["demo", "--seed", "-1"], EXIT_INPUT, "--seed"),
    ]


# ----------------------------------------------------------------------------- tyre-model
def tyremodel_cases() -> list[Case]:
    """tyre-model writes a new or empty directory only, checked before any work."""

    def argv(out: str) -> list[str]:
        return ["tyre-model", "m.json", "--pressure", "7", "--radius", "0.5", "-o", out]

    def full_dir(d: Path) -> None:
        (d / "model").mkdir()
        (d / "model" / "notes.txt").write_text("my notes")

    files = {"m.json": "modes.json"}
    return [
        Case("tyre-model-dir-not-empty", argv("model"), EXIT_INPUT, "not empty", files, full_dir),
        Case(
            "tyre-model-link-to-dir-not-empty",
            argv("link"),
            EXIT_INPUT,
            "not empty",
            files,
            lambda d: (full_dir(d), os.symlink("model", d / "link")),
        ),
        Case("tyre-model-out-empty", argv(""), EXIT_INPUT, "empty path", files),
        Case("tyre-model-out-dot", argv("."), EXIT_INPUT, "current directory", files),
        Case(
            "tyre-model-out-is-file",
            argv("f"),
            EXIT_INPUT,
            "is a file",
            {**files, "f": b"a user's file"},
        ),
        Case("tyre-model-missing-parent", argv("nodir/model"), EXIT_INPUT, "does not exist", files),
    ]


# ------------------------------------------------------------------------ bad inputs
#: (command argv with {in}, input name, valid library file for the other slots)
SLOTS: dict[str, tuple[list[str], str, dict[str, str]]] = {
    "frf": (["frf", "{in}", "-o", "out.npz"], "time", {}),
    "modal": (["modal", "{in}", "-o", "out.json"], "frf", {}),
    "lateral-fit": (["lateral", "fit", "{in}", "-o", "out.json"], "frf", {}),
    "check-quality": (["check", "quality", "{in}"], "any", {}),
    "check-reciprocity": (["check", "reciprocity", "{in}"], "frf", {}),
    "check-linearity": (["check", "linearity", "frf.npz", "{in}"], "frf", {"frf.npz": "frf.npz"}),
    "report-data": (["report", "{in}", "-o", "out.html"], "any", {}),
}

MALFORMED: dict[str, tuple[str, bytes | None, str]] = {
    # name: (file name, content (None: not created), needle)
    "missing": ("x.npz", None, "no such file"),
    "empty": ("x.npz", b"", "empty"),
    "garbage-npz": ("x.npz", b"\x00\x01not a zip archive at all" * 10, "x.npz"),
    "truncated-npz": ("x.npz", b"", "x.npz"),  # filled from the library (half the bytes)
    "garbage-uff": ("x.uff", b"    -1\n    58\nthis is not a data set\n    -1\n", "x.uff"),
    "garbage-csv": ("x.csv", b"a,b,c\n1,2\nx,y,z\n", "x.csv"),
    "unknown-ext": ("x.xyz", b"1 2 3\n", "extension"),
    "binary-uff": ("x.uff", bytes(range(256)) * 8, "x.uff"),
}


def malformed_cases(lib_files: dict[str, bytes]) -> list[Case]:
    cases: list[Case] = []
    for slot, (argv, _kind, others) in SLOTS.items():
        for bad, (fname, content, needle) in MALFORMED.items():
            if bad == "truncated-npz":
                content = lib_files["frf.npz"][: len(lib_files["frf.npz"]) // 2]
            files: dict[str, str | bytes] = dict(others)
            if content is not None:
                files[fname] = content
            cases.append(
                Case(
                    f"{slot}-{bad}",
                    [a.replace("{in}", fname) for a in argv],
                    EXIT_INPUT,
                    needle,
                    files,
                )
            )
        cases.append(
            Case(
                f"{slot}-input-is-dir",
                [a.replace("{in}", "x.npz") for a in argv],
                EXIT_INPUT,
                "x.npz",
                dict(others),
                _dir("x.npz"),
            )
        )
    # wrong content for the command
    cases += [
        Case(
            "frf-given-an-frf",
            ["frf", "frf.npz", "-o", "o.npz"],
            2,
            "not time data",
            {"frf.npz": "frf.npz"},
        ),
        Case(
            "modal-given-time",
            ["modal", "time.npz", "-o", "o.json"],
            2,
            "time data",
            {"time.npz": "time.npz"},
        ),
    ]
    return cases


def _modes_variant(doc: dict[str, Any], how: str) -> dict[str, Any]:
    d = json.loads(json.dumps(doc))
    m = d["models"]["complex"]
    if how == "pole-strings":
        for md in m["modes"]:
            md["pole"] = ["a", "b"]
    elif how == "shape-huge":
        m["modes"][0]["shape"] = [[1e300, 1e300]] * len(m["modes"][0]["shape"])
    elif how == "shape-tiny":
        for md in m["modes"]:
            md["shape"] = [[1e-300, 1e-300]] * len(md["shape"])
    elif how == "pole-huge":
        m["modes"][0]["pole"] = [-1e300, 1e300]
    elif how == "modes-not-list":
        m["modes"] = 5
    elif how == "wrong-kind":
        d["kind"] = "lateral"
    elif how == "no-models":
        d["models"] = {}
    return d


def json_cases(lib_files: dict[str, bytes]) -> list[Case]:
    modes = json.loads(lib_files["modes.json"])
    lat = json.loads(lib_files["lat.json"])
    bad: dict[str, tuple[bytes, str]] = {
        "invalid": (b'{"kind": "modes", ', "not valid JSON"),
        "array": (b"[1, 2, 3]", "x.json"),
        "nested-100000": (nested_json(), "nested too deeply"),
        "not-utf8": (b"\xff\xfe\x00\x01" * 20, "x.json"),
        "empty-object": (b"{}", "x.json"),
        "whitespace": (b"   \n\n", "empty"),
        "nan-literal": (b'{"kind": "modes", "models": NaN}', "x.json"),
        "int-of-5000-digits": (b'{"kind": "modes", "models": ' + b"9" * 5000 + b"}", "x.json"),
    }
    for how in ("pole-strings", "modes-not-list", "wrong-kind", "no-models"):
        bad[f"modes-{how}"] = (json.dumps(_modes_variant(modes, how)).encode(), "x.json")
    cases: list[Case] = [
        Case(
            "damping-json-modes-shape-huge",
            ["damping", "x.json", "-o", "d.json", "--samples", "0"],
            EXIT_INPUT,
            "shapes",
            {"x.json": json.dumps(_modes_variant(modes, "shape-huge")).encode()},
        ),
        Case(
            "damping-json-modes-shape-tiny",
            ["damping", "x.json", "-o", "d.json", "--samples", "0"],
            EXIT_INPUT,
            "modal masses",
            {"x.json": json.dumps(_modes_variant(modes, "shape-tiny")).encode()},
        ),
        Case(
            "damping-json-modes-pole-huge",
            ["damping", "x.json", "-o", "d.json", "--samples", "0"],
            EXIT_INPUT,
            "poles",
            {"x.json": json.dumps(_modes_variant(modes, "pole-huge")).encode()},
        ),
    ]
    for name, (content, needle) in bad.items():
        cases.append(
            Case(
                f"damping-json-{name}",
                ["damping", "x.json", "-o", "d.json", "--samples", "0"],
                EXIT_INPUT,
                needle,
                {"x.json": content},
            )
        )
        cases.append(
            Case(
                f"report-json-{name}",
                ["report", "x.json", "-o", "r.html"],
                EXIT_INPUT,
                needle if name != "modes-wrong-kind" else "not a tyredamp result",
                {"x.json": content},
            )
        )

    def lat_variant(fn: Any) -> bytes:
        d = json.loads(json.dumps(lat))
        fn(d)
        return json.dumps(d).encode()

    def strings_in_table(d: dict[str, Any]) -> None:
        for r in d["table"]:
            for k in r:
                r[k] = str(r[k])

    def strings_in_params(d: dict[str, Any]) -> None:
        for f in d["fits"]:
            f["params"] = {k: str(v) for k, v in f["params"].items()}

    variants = {
        "table-strings": strings_in_table,
        "param-strings": strings_in_params,
        "conditions-string": lambda d: d.__setitem__("conditions", "x"),
        "fits-int": lambda d: d.__setitem__("fits", 5),
        "wheel-mass-string": lambda d: d["conditions"].__setitem__("wheel_mass_kg", "heavy"),
        "no-table": lambda d: d.pop("table"),
    }
    for name, fn in variants.items():
        cases.append(
            Case(
                f"report-lateral-{name}",
                ["report", "lat.json", "-o", "r.html"],
                EXIT_INPUT,
                "lat.json",
                {"lat.json": lat_variant(fn)},
            )
        )
    return cases


def hostile_cases() -> list[Case]:
    f = np.linspace(1.0, 50.0, 64)
    w = 2 * np.pi * f
    h = 1.0 / (1e4 - w**2 + 2j * w)
    td_head = {
        "format": "tyredamp",
        "version": 1,
        "type": "timedata",
        "sample_rate": 256.0,
        "channels": [
            {"node": 1, "direction": 3, "quantity": "force"},
            {"node": 2, "direction": 3, "quantity": "acceleration"},
        ],
        "meta": {},
    }
    rng = np.random.default_rng(0)
    data = rng.standard_normal((2, 512))
    npz: dict[str, tuple[bytes, str]] = {
        "meta-list": (frf_npz(meta=[1, 2]), "meta"),
        "outputs-int": (frf_npz(outputs=3), "outputs"),
        "inputs-strings": (frf_npz(inputs=["a"]), "inputs"),
        "kind-int": (frf_npz(kind=3), "kind"),
        "header-bytes": (
            npz_bytes(np.frombuffer(b"raw header bytes", dtype=np.uint8), {}, raw_header=True),
            "header",
        ),
        "header-not-json": (npz_bytes(np.array("{not json"), {}, raw_header=True), "JSON"),
        "header-nested": (
            npz_bytes(np.array(nested_json(50_000).decode()), {}, raw_header=True),
            "nested",
        ),
        "huge-member": (huge_member_npz(), "claims"),
        "complex-frequency": (frf_npz(freq=f + 1j, h=h), "frequency"),
        "complex-coherence": (
            frf_npz(arrays={"coherence": np.ones((1, 64)) * (0.5 + 0.5j)}),
            "coherence",
        ),
        "coherence-wrong-shape": (frf_npz(arrays={"coherence": np.ones(7)}), "coherence"),
        "nan-in-H": (frf_npz(h=np.where(f > 20, np.nan, h)), "finite"),
        "inf-frequency": (frf_npz(freq=np.where(f > 40, np.inf, f), h=h), "finite"),
        "decreasing-frequency": (frf_npz(freq=f[::-1].copy()), "increasing"),
        "negative-frequency": (frf_npz(freq=f - 10), "non-negative"),
        "H-wrong-shape": (frf_npz(h=np.ones((2, 3))), "H"),
        "missing-H": (npz_bytes(frf_header(), {"frequency": f}), "'H'"),
        "object-member": (
            npz_bytes(frf_header(), {"frequency": f, "H": np.array([{}, 1], dtype=object)}),
            "object",
        ),
        "format-other": (frf_npz(format="other"), "format"),
        "version-99": (frf_npz(version=99), "version"),
        "type-unknown": (frf_npz(type="spectrum"), "type"),
    }
    cases: list[Case] = []
    for name, (content, needle) in npz.items():
        cases.append(
            Case(
                f"modal-npz-{name}",
                ["modal", "x.npz", "-o", "m.json"],
                EXIT_INPUT,
                needle,
                {"x.npz": content},
            )
        )
    td: dict[str, tuple[bytes, str]] = {
        "complex-samples": (npz_bytes(td_head, {"data": data * (1 + 1j)}), "complex"),
        "sample-rate-string": (
            npz_bytes({**td_head, "sample_rate": "fast"}, {"data": data}),
            "sample_rate",
        ),
        "sample-rate-zero": (
            npz_bytes({**td_head, "sample_rate": 0}, {"data": data}),
            "sample_rate",
        ),
        "channels-not-records": (
            npz_bytes({**td_head, "channels": [1, 2]}, {"data": data}),
            "channel",
        ),
        "quantity-unknown": (
            npz_bytes(
                {
                    **td_head,
                    "channels": [{"node": 1, "quantity": "force"}, {"node": 2, "quantity": "heat"}],
                },
                {"data": data},
            ),
            "channel quantity 'heat'",
        ),
        "nan-sample": (npz_bytes(td_head, {"data": np.where(data > 2, np.nan, data)}), "finite"),
        "one-sample": (npz_bytes(td_head, {"data": data[:, :1]}), "samples"),
    }
    for name, (content, needle) in td.items():
        cases.append(
            Case(
                f"frf-npz-{name}",
                ["frf", "x.npz", "-o", "f.npz"],
                EXIT_INPUT,
                needle,
                {"x.npz": content},
            )
        )
    # lateral: metadata of the wrong type, a multi-channel FRF, data no model fits
    lat_f = np.linspace(0.25, 9.0, 120)
    mass_only = (
        -np.ones_like(lat_f)
        / 100.0
        * (1 + 0.03 * np.random.default_rng(2).standard_normal(lat_f.size))
    )
    noise = 1e-3 * (rng.standard_normal(lat_f.size) + 1j * rng.standard_normal(lat_f.size))
    lat: dict[str, tuple[bytes, int, str, list[str]]] = {
        "speed-string": (frf_npz(meta={"speed_m_s": "fast"}), 2, "speed_m_s", []),
        "wheel-mass-null": (frf_npz(meta={"wheel_mass_kg": None}), 2, "wheel_mass_kg", []),
        "force-int": (frf_npz(meta={"force": 7}), 2, "force", []),
        "three-outputs": (b"", 2, "--channel", []),
        "channel-out-of-range": (frf_npz(), 2, "channel", ["--channel", "3", "0"]),
        "pure-mass": (frf_npz(freq=lat_f, h=mass_only, kind="accelerance"), 3, "no model fits", []),
        "noise-only": (frf_npz(freq=lat_f, h=noise, kind="accelerance"), 3, "no model fits", []),
        "speed-negative": (b"", 2, "--speed", ["--speed", "-5"]),
    }
    for name, (content, code, needle, extra) in lat.items():
        files: dict[str, str | bytes] = (
            {"x.npz": "frf.npz"} if name == "three-outputs" else {"x.npz": content or "lat.npz"}
        )
        cases.append(
            Case(
                f"lateral-fit-{name}",
                ["lateral", "fit", "x.npz", "-o", "l.json", *extra],
                code,
                needle,
                files,
            )
        )
    # options beyond what the model or the data support
    cases += [
        Case(
            "lateral-simulate-speed-1e300",
            ["lateral", "simulate", "-o", "s.npz", "--speed", "1e300"],
            2,
            "speed",
        ),
        Case(
            "lateral-simulate-speed-nan",
            ["lateral", "simulate", "-o", "s.npz", "--speed", "nan"],
            2,
            "speed",
        ),
        Case(
            "lateral-simulate-noise-1e300",
            ["lateral", "simulate", "-o", "s.npz", "--noise", "1e300"],
            2,
            "noise",
        ),
        Case(
            "lateral-simulate-pressure-1e300",
            ["lateral", "simulate", "-o", "s.npz", "--pressure", "1e300"],
            2,
            "pressure",
        ),
        Case(
            "simulate-lateral-ext-unknown", ["simulate", "lateral", "-o", "s.xyz"], 2, "extension"
        ),
        Case(
            "simulate-radial-snr-minus-inf",
            ["simulate", "radial", "-o", "s.npz", "--snr", "-inf"],
            2,
            "snr",
        ),
        Case(
            "simulate-radial-snr-nan",
            ["simulate", "radial", "-o", "s.npz", "--snr", "nan"],
            2,
            "snr",
        ),
        Case(
            "simulate-radial-drive-point-17",
            ["simulate", "radial", "-o", "s.npz", "--drive-points", "17"],
            2,
            "drive",
        ),
        Case(
            "check-linearity-one-file",
            ["check", "linearity", "frf.npz"],
            2,
            "two or more",
            {"frf.npz": "frf.npz"},
        ),
        Case(
            "damping-model-missing",
            ["damping", "modes.json", "-o", "d.json", "--model", "other"],
            2,
            "--model",
            {"modes.json": "modes.json"},
        ),
        Case("report-no-files", ["report", "-o", "r.html"], 2, "at least one"),
        Case(
            "frf-segment-too-long",
            ["frf", "time.npz", "-o", "f.npz", "--method", "welch", "--segment", "100000"],
            2,
            "segment",
            {"time.npz": "time.npz"},
        ),
    ]
    return cases


class _Library:
    """The valid inputs, built once per session before the cases are generated."""

    _path: Path | None = None

    @classmethod
    def path(cls) -> Path:
        if cls._path is None:
            import atexit
            import shutil
            import tempfile

            root = Path(tempfile.mkdtemp(prefix="tyredamp-badinput-"))
            atexit.register(shutil.rmtree, root, ignore_errors=True)
            cls._path = make_library(root)
        return cls._path


def _build_cases() -> list[Case]:
    lib_files = {p.name: p.read_bytes() for p in _Library.path().iterdir()}
    return [
        *output_cases(),
        *demo_cases(),
        *tyremodel_cases(),
        *campaign_cases(),
        *malformed_cases(lib_files),
        *json_cases(lib_files),
        *hostile_cases(),
    ]


CASES = _build_cases()


def _emulate_permissions(monkeypatch: pytest.MonkeyPatch) -> None:
    """As root every file is writable; emulate a user's permission bits for the checks."""
    if os.geteuid() != 0:
        return
    real = os.access

    def access(path: Any, mode: int, **kw: Any) -> bool:
        try:
            st = os.stat(path)
        except OSError:
            return real(path, mode, **kw)
        if mode & os.W_OK and not st.st_mode & stat.S_IWUSR:
            return False
        return real(path, mode, **kw)

    monkeypatch.setattr(os, "access", access)


def test_corpus_size() -> None:
    assert len(CASES) >= 80
    assert len({c.id for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(
    case: Case,
    lib: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    d = tmp_path / "case"
    prepare(case, lib, d)
    _emulate_permissions(monkeypatch)
    before = snapshot(d)
    monkeypatch.chdir(d)
    code, _, err = run_main(case.argv, capsys)
    try:
        check_one_error_line(err, code, case.code, case.needle)
        assert snapshot(d) == before, "the directory changed"
    finally:
        for p in d.rglob("*"):  # let tmp_path cleanup remove read-only entries
            if p.is_dir() and not p.is_symlink():
                os.chmod(p, 0o755)


# ------------------------------------------------------------------ successes and faults
def test_dev_null_is_written_directly(
    lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    before = os.stat("/dev/null")
    code, _, err = run_main(["lateral", "simulate", "-o", "/dev/null", "--format", "npz"], capsys)
    assert code == 0, err
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode)
    assert (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert list(Path("/dev").glob(".null.*")) == []
    assert list(tmp_path.iterdir()) == []


def test_symlinked_output_is_followed(
    lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "real").mkdir()
    (tmp_path / "real" / "s.npz").write_bytes(b"old")
    os.symlink("real/s.npz", "link.npz")
    code, _, err = run_main(["lateral", "simulate", "-o", "link.npz"], capsys)
    assert code == 0, err
    assert os.path.islink("link.npz")
    assert (tmp_path / "real" / "s.npz").read_bytes()[:2] == b"PK"
    assert sorted(p.name for p in (tmp_path / "real").iterdir()) == ["s.npz"]


def test_full_disk_names_the_users_file(
    lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "frf.npz").write_bytes((lib / "frf.npz").read_bytes())
    (tmp_path / "m.json").write_text("the user's earlier result")
    before = snapshot(tmp_path)

    def full(p: Path) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(p))

    monkeypatch.setattr(safety, "_fsync_file", full)
    code, _, err = run_main(["modal", "frf.npz", "-o", "m.json"], capsys)
    line = check_one_error_line(err, code, EXIT_INPUT, "No space left on device")
    assert "m.json" in line
    assert snapshot(tmp_path) == before


def test_second_of_two_files_fails(
    lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """simulate radial --out X --truth Y: Y fails after X was replaced; X is put back."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.npz").write_bytes(b"the user's earlier data")
    before = snapshot(tmp_path)
    real_replace = os.replace

    def replace(src: Any, dst: Any, **kw: Any) -> None:
        if str(dst).endswith("t.json"):
            raise OSError(errno.ENOSPC, "No space left on device", str(src))
        real_replace(src, dst, **kw)

    monkeypatch.setattr(os, "replace", replace)
    argv = ["simulate", "radial", "--periods", "1", "-o", "s.npz", "--truth", "t.json"]
    code, _, err = run_main(argv, capsys)
    line = check_one_error_line(err, code, EXIT_INPUT, "No space left on device")
    assert "t.json" in line
    assert snapshot(tmp_path) == before


def test_stale_temporaries_are_swept(
    lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    old = safety.PROCESS_START - 3600
    dead = 2**22 + 12345  # above the default pid_max: no such process
    stale = [
        f".s.npz.tyredamp-{dead}-0badcafe.tmp",
        ".s.npz.abcd_123.tmp",  # the naming of earlier releases (mkstemp)
    ]
    keep = [
        f".s.npz.tyredamp-{os.getpid()}-0badcafe.tmp",  # a running process
        ".s.npz.notes",  # not our pattern
        f".other.npz.tyredamp-{dead}-0badcafe.tmp",  # another target
        "s.npz.tyredamp-1-00000000.tmp",  # not hidden: not ours
    ]
    for n in [*stale, *keep]:
        (tmp_path / n).write_text("x")
        os.utime(tmp_path / n, (old, old))
    fresh = f".s.npz.tyredamp-{dead}-0000beef.tmp"  # newer than this process: kept
    (tmp_path / fresh).write_text("x")
    os.mkdir(tmp_path / f".s.npz.tyredamp-{dead}-0dd0dd00.tmp")  # a stale directory
    os.utime(tmp_path / f".s.npz.tyredamp-{dead}-0dd0dd00.tmp", (old, old))
    code, _, err = run_main(["lateral", "simulate", "-o", "s.npz"], capsys)
    assert code == 0, err
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted([*keep, fresh, "s.npz"])


def test_warnings_never_precede_the_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import warnings

    import tyredamp.io as tio

    def noisy(*a: Any, **k: Any) -> Any:
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        raise tio.FileFormatError("x.npz: broken")

    monkeypatch.setattr("tyredamp.io.read_frf", noisy)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    check_one_error_line(err, code, EXIT_INPUT, "broken")


def test_last_resort_handler(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def bug(*a: Any, **k: Any) -> Any:
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr("tyredamp.io.read_frf", bug)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    line = check_one_error_line(err, code, 70, "internal error (ZeroDivisionError: division")
    assert line.endswith("rerun with --debug")
    code2, _, err2 = run_main(["--debug", "modal", "x.npz", "-o", "m.json"], capsys)
    assert code2 == 70  # --debug does not change the exit code
    assert "Traceback" in err2
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------- interrupted
_SLOW_WRITE = """
import sys, time, pathlib
marker = pathlib.Path(sys.argv[1])
import tyredamp.io._safety as s
def slow(*a, **k):
    marker.write_text("writing")
    time.sleep(60)
s._fsync_file = slow
import tyredamp.studies.demo as demo
import tyredamp.report.plots as figs
demo.run_demo = lambda *a, **k: None
figs.demo_figures = slow
from tyredamp.cli import main
main(sys.argv[2:])
"""


def _interrupt(tmp_path: Path, argv: list[str], sig: int) -> tuple[int, str]:
    marker = tmp_path.parent / f"{tmp_path.name}.marker"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONWARNINGS": ""}
    proc = subprocess.Popen(
        [sys.executable, "-c", _SLOW_WRITE, str(marker), *argv],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    t0 = time.monotonic()
    while not marker.exists():
        if proc.poll() is not None or time.monotonic() - t0 > 60:
            proc.kill()
            raise AssertionError(
                f"never reached the write: {proc.stderr.read() if proc.stderr else ''}"
            )
        time.sleep(0.02)
    proc.send_signal(sig)
    # generous: the cleanup and exit of a process on a loaded machine (seen above 30 s)
    _, err = proc.communicate(timeout=120)
    marker.unlink()
    return proc.returncode, err


_TERM, _INT = (signal.SIGTERM, 143), (signal.SIGINT, 130)


@pytest.mark.parametrize(
    ("argv", "existing", "sig"),
    [
        (["lateral", "simulate", "-o", "s.npz"], {"s.npz": b"the user's earlier data"}, _TERM),
        (["lateral", "simulate", "-o", "s.npz"], {"s.npz": b"the user's earlier data"}, _INT),
        (
            ["simulate", "radial", "--periods", "1", "-o", "s.npz", "--truth", "t.json"],
            {"t.json": b"the user's truth"},
            _TERM,
        ),
        (["demo", "--quick", "-o", "demo"], {}, _TERM),
    ],
    ids=["one-file-SIGTERM", "one-file-SIGINT", "two-files-SIGTERM", "demo-dir-SIGTERM"],
)
def test_interrupted(
    tmp_path: Path, argv: list[str], existing: dict[str, bytes], sig: tuple[int, int]
) -> None:
    """A real subprocess gets the signal while it writes: temporaries removed, one line,
    128 + signal number, every earlier file as it was (the demo replaces an earlier output)."""
    signum, code = sig
    if "demo" in argv:
        _demo_dir({})(tmp_path)
    for k, v in existing.items():
        (tmp_path / k).write_bytes(v)
    before = snapshot(tmp_path)
    rc, err = _interrupt(tmp_path, argv, signum)
    check_one_error_line(err, rc, code, f"interrupted by {signal.Signals(signum).name}")
    assert snapshot(tmp_path) == before


def test_docs_state_the_exit_codes() -> None:
    """The exit-code table of docs/reference/safety.md is the one cli.main uses."""
    from tyredamp.cli import _common as c

    page = Path(__file__).parents[1] / "docs" / "reference" / "safety.md"
    section = page.read_text(encoding="utf-8")
    codes = {
        int(x)
        for row in section.splitlines()
        if row.startswith("| ") and row[2].isdigit()
        for x in row.split("|")[1].replace("/", " ").split()
    }
    expected = {0, 1, c.EXIT_INPUT, c.EXIT_RUNTIME, c.EXIT_INTERNAL, c.EXIT_SIGINT, c.EXIT_SIGTERM}
    assert codes == expected
    for promise in ("--out", "symbolic link", "hard link", "/dev/null", "SIGTERM", "--debug"):
        assert promise in section


def test_replaced_file_keeps_its_permissions(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A private earlier result stays private; a new file gets the usual mode (umask)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.npz").write_bytes(b"old")
    os.chmod(tmp_path / "s.npz", 0o600)
    code, _, err = run_main(["lateral", "simulate", "-o", "s.npz"], capsys)
    assert code == 0, err
    assert stat.S_IMODE(os.stat(tmp_path / "s.npz").st_mode) == 0o600
    umask = os.umask(0)
    os.umask(umask)
    code, _, err = run_main(["lateral", "simulate", "-o", "new.npz"], capsys)
    assert code == 0, err
    assert stat.S_IMODE(os.stat(tmp_path / "new.npz").st_mode) == 0o666 & ~umask


def test_npz_larger_than_memory_is_refused_before_unpacking(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A compressed NPZ that unpacks beyond the memory available (a zip bomb) is refused."""
    import tyredamp.io.npz as npz_mod

    monkeypatch.chdir(tmp_path)
    (tmp_path / "x.npz").write_bytes(frf_npz())
    before = snapshot(tmp_path)
    monkeypatch.setattr(npz_mod, "_available_memory", lambda: 1000)  # bytes
    code, _, err = run_main(["modal", "x.npz", "-o", "m.json"], capsys)
    check_one_error_line(err, code, EXIT_INPUT, "memory available")
    assert snapshot(tmp_path) == before


def test_matplotlib_config_is_private(monkeypatch: pytest.MonkeyPatch) -> None:
    """demo and report point MPLCONFIGDIR at a temporary directory (not the user's home)
    when it is unset and matplotlib is not loaded yet; a user's own setting is kept."""
    monkeypatch.delenv("MPLCONFIGDIR", raising=False)
    monkeypatch.delitem(sys.modules, "matplotlib", raising=False)
    with safety.private_matplotlib_config():
        d = os.environ["MPLCONFIGDIR"]
        assert Path(d).is_dir()
        assert not Path(d).is_relative_to(Path.home())
    assert "MPLCONFIGDIR" not in os.environ
    assert not Path(d).exists()
    monkeypatch.setenv("MPLCONFIGDIR", "/somewhere/of/mine")
    with safety.private_matplotlib_config():
        assert os.environ["MPLCONFIGDIR"] == "/somewhere/of/mine"


def test_fsync_before_rename(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The temporary is flushed to disk before it is renamed onto the target."""
    events: list[tuple[str, str]] = []
    real_fsync, real_replace = safety._fsync_file, os.replace

    def fsync(p: Path) -> None:
        events.append(("fsync", str(p)))
        real_fsync(p)

    def replace(src: Any, dst: Any, **kw: Any) -> None:
        events.append(("replace", str(src)))
        real_replace(src, dst, **kw)

    monkeypatch.setattr(safety, "_fsync_file", fsync)
    monkeypatch.setattr(os, "replace", replace)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_main(["lateral", "simulate", "-o", "s.npz"], capsys)
    assert code == 0, err
    renamed = [p for e, p in events if e == "replace" and ".s.npz.tyredamp-" in p]
    assert renamed
    for p in renamed:
        assert events.index(("fsync", p)) < events.index(("replace", p))


def test_an_output_changed_since_it_was_written_is_not_replaced(tmp_path: Path) -> None:
    """A file of an earlier output that the user edited (notes in report.html) counts as
    the user's: the manifest written with the output tells it apart (issue 15)."""
    from tyredamp.exceptions import InputError
    from tyredamp.io._safety import MANIFEST_NAME, atomic_dir, check_output_dir

    out = tmp_path / "out"
    with atomic_dir(out) as tmp:
        (tmp / "report.html").write_text("<p>result</p>", encoding="utf-8")
        (tmp / "data").mkdir()
        (tmp / "data" / "a.uff").write_bytes(b"\x00\x01")
    assert (out / MANIFEST_NAME).is_file()
    owned = ["report.html", "data/a.uff"]
    # unchanged: an earlier output may be replaced
    assert check_output_dir(out, lambda _root: owned) == out.resolve()
    # edited by the user: refused, naming the file, and nothing is touched
    (out / "report.html").write_text("<p>result</p><p>my notes</p>", encoding="utf-8")
    with pytest.raises(InputError, match=r"report\.html changed since tyredamp wrote it"):
        check_output_dir(out, lambda _root: owned)
    assert "my notes" in (out / "report.html").read_text(encoding="utf-8")
    # without a readable manifest nothing proves the files are ours
    (out / "report.html").write_text("<p>result</p>", encoding="utf-8")
    (out / MANIFEST_NAME).write_text("{", encoding="utf-8")
    with pytest.raises(InputError, match="changed since tyredamp wrote it"):
        check_output_dir(out, lambda _root: owned)
