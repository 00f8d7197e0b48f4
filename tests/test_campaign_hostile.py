"""Hostile input to ``tyredamp campaign``: every case one line, exit 2, nothing changed or left.

The corpus covers ``--scheduler`` (malformed addresses, unsupported schemes,
refused, silent, HTTP and lying servers, TLS options), the other options,
hostile campaign files (settings beyond what a method can use, bad TOML)
and outputs edited since the campaign wrote them. Every case asserts exit
code 2, exactly one line on stderr (``tyredamp: error: ...``) without a
traceback, the input files unchanged, and no file written (the output
folder untouched, no scratch copy left). Damaged cache entries, a test file
too large and scratch copies a killed run left are covered at the end.
"""

from __future__ import annotations

import contextlib
import hashlib
import http.server
import json
import multiprocessing.util
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import msgpack
import numpy as np
import pytest

from tyredamp.campaign import load_campaign
from tyredamp.campaign.runner import run_tests
from tyredamp.cli import main

from .helpers import chain_system

TINY = """name = "tiny"
[settings.radial.modal]
band = [0.0, 40.0]
search = false
[settings.radial.damping]
samples = 10
"""
TESTS = """[[tests]]
files = "chain1.npz"
tyre = "A"
pressure_bar = 6.0
[[tests]]
files = "chain2.npz"
tyre = "A"
pressure_bar = 7.0
"""


@pytest.fixture(autouse=True)
def _own_temporary_directory(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    # scratch copies are counted in the temporary directory: a test's own one, so that
    # campaigns run by other tests at the same time (pytest-xdist) are not counted. The
    # path is short (multiprocessing puts sockets in it), and multiprocessing's own
    # per-process directory (its fork server's socket) is made before the patch, so
    # that it outlives this test
    multiprocessing.util.get_temp_dir()
    d = tempfile.mkdtemp(prefix="td-")
    monkeypatch.setenv("TMPDIR", d)
    monkeypatch.setattr(tempfile, "tempdir", d)
    yield
    shutil.rmtree(d, ignore_errors=True)


def write_tiny_campaign(root: Path) -> Path:
    """Two noisy FRF files of the six-mode chain and a campaign file; returns the file."""
    from tyredamp.io import write_frf

    root.mkdir(parents=True, exist_ok=True)
    f = np.linspace(0.5, 40.0, 300)
    for k in (1, 2):
        frf = chain_system().frf(f, kind="accelerance", inputs=[0])
        rng = np.random.default_rng(k)
        rms = np.sqrt(np.mean(np.abs(frf.H) ** 2, axis=2, keepdims=True))
        write_frf(
            frf.with_H(frf.H + 1e-3 * rms * rng.normal(size=frf.H.shape)), root / f"chain{k}.npz"
        )
    path = root / "campaign.toml"
    path.write_text(TINY + TESTS, encoding="utf-8")
    return path


def tree(root: Path) -> dict[str, str]:
    """SHA-256 of every file under ``root`` (and the names of directories)."""
    out = {}
    for p in sorted(root.rglob("*")):
        out[p.relative_to(root).as_posix()] = (
            hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
        )
    return out


def scratch_dirs() -> set[str]:
    return {e for e in os.listdir(tempfile.gettempdir()) if e.startswith("tyredamp-campaign-")}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("tiny")
    write_tiny_campaign(root / "data")
    return root


@pytest.fixture(scope="module")
def done(tiny: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A completed campaign output (with its report) of the tiny campaign."""
    out = tmp_path_factory.mktemp("done") / "out"
    main(["campaign", str(tiny / "data" / "campaign.toml"), "--out", str(out), "--serial"])
    assert (out / "report.html").is_file()
    return out


# ----------------------------------------------------------------------------- servers
class Server:
    """A TCP server on 127.0.0.1 that answers every connection with ``reply(conn)``."""

    def __init__(self, reply: Callable[[socket.socket], None]) -> None:
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.reply = reply
        self.conns: list[socket.socket] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            with contextlib.suppress(OSError):
                self.reply(conn)

    def close(self) -> None:
        self.sock.close()
        for c in self.conns:
            c.close()


def _frames(payload: bytes) -> bytes:
    body = struct.pack("<QQ", 1, len(payload)) + payload
    return struct.pack("<Q", len(body)) + body


REPLIES: dict[str, Callable[[socket.socket], None]] = {
    "silent": lambda c: None,
    "closes": lambda c: c.close(),
    "huge-frame": lambda c: c.sendall(struct.pack("<Q", 3 << 60) + b"x" * 64),
    "zero-frame": lambda c: c.sendall(struct.pack("<Q", 0)),
    "text-banner": lambda c: c.sendall(b"SSH-2.0-OpenSSH_9.6\r\n" + b" " * 64),
    "bad-framing": lambda c: c.sendall(struct.pack("<QQ", 24, 1000) + b"\0" * 16),
    "not-msgpack": lambda c: c.sendall(_frames(b"\xc1\xc1\xc1\xc1")),
    "msgpack-list": lambda c: c.sendall(_frames(msgpack.packb([1, 2, 3]))),
    "msgpack-other-map": lambda c: c.sendall(_frames(msgpack.packb({"hello": "world"}))),
    "pickle-ext": lambda c: c.sendall(_frames(msgpack.packb(msgpack.ExtType(5, b"\x80\x04.")))),
}


@pytest.fixture(scope="module")
def servers() -> Iterator[dict[str, int]]:
    ports: dict[str, int] = {}
    made = []
    for name, reply in REPLIES.items():
        s = Server(reply)
        made.append(s)
        ports[name] = s.port
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    ports["http"] = httpd.server_address[1]
    free = socket.socket()
    free.bind(("127.0.0.1", 0))
    ports["refused"] = free.getsockname()[1]
    free.close()  # nothing listens there any more
    yield ports
    httpd.shutdown()
    httpd.server_close()
    for s in made:
        s.close()


# ----------------------------------------------------------------------------- the corpus
SCHEDULER_TEXT = {
    "empty": "",
    "blank": "   ",
    "no-scheme": "127.0.0.1:8786",
    "ucx": "ucx://127.0.0.1:8786",
    "inproc": "inproc://127.0.0.1/1/2",
    "ws": "ws://127.0.0.1:8786",
    "http-scheme": "http://127.0.0.1:8786",
    "no-host": "tcp://",
    "no-port": "tcp://127.0.0.1",
    "port-0": "tcp://127.0.0.1:0",
    "port-65536": "tcp://127.0.0.1:65536",
    "port-huge": "tcp://127.0.0.1:999999999999",
    "port-negative": "tcp://127.0.0.1:-1",
    "port-text": "tcp://127.0.0.1:abc",
    "space-in-host": "tcp://bad host:8786",
    "control-char": "tcp://a\x07b:8786",
    "ipv6-unclosed": "tcp://[::1:8786",
    "userinfo": "tcp://user@127.0.0.1:8786",
    "path": "tcp://127.0.0.1:8786/x",
    "query": "tcp://127.0.0.1:8786?x=1",
    "host-underscore": "tcp://bad_host:8786",
    "numeric-host": "tcp://999.1.1.1:8786",
    "tls-without-ca": "tls://127.0.0.1:8786",
}
SERVER_CASES = [*REPLIES, "http", "refused"]
OPTION_CASES: dict[str, list[str]] = {
    "serial-and-scheduler": ["--serial", "--scheduler", "tcp://127.0.0.1:8786"],
    "serial-and-dask": ["--serial", "--dask"],
    "dask-and-scheduler": ["--dask", "--scheduler", "tcp://127.0.0.1:8786"],
    "serial-and-workers": ["--serial", "--workers", "2"],
    "workers-0": ["--workers", "0"],
    "workers-huge": ["--workers", "100000000"],
    "connect-timeout-0": ["--scheduler", "tcp://127.0.0.1:8786", "--connect-timeout", "0"],
    "connect-timeout-nan": ["--scheduler", "tcp://127.0.0.1:8786", "--connect-timeout", "nan"],
    "worker-timeout-inf": ["--scheduler", "tcp://127.0.0.1:8786", "--worker-timeout", "inf"],
    "tls-ca-without-scheduler": ["--tls-ca", "ca.pem"],
    "tls-files-for-tcp": ["--scheduler", "tcp://127.0.0.1:8786", "--tls-ca", "campaign.toml"],
    "tls-ca-missing": [
        "--scheduler",
        "tls://127.0.0.1:8786",
        "--tls-ca",
        "nope.pem",
        "--tls-cert",
        "nope.pem",
    ],
    "tls-not-pem": [
        "--scheduler",
        "tls://127.0.0.1:8786",
        "--tls-ca",
        "chain1.npz",
        "--tls-cert",
        "chain2.npz",
    ],
    "out-empty": ["--out", ""],
    "out-is-input-dir": ["--out", "."],
}
SETTINGS_CASES = {
    "samples-1e9-float": "[settings.radial.damping]\nsamples = 1e9\n",
    "samples-1e9": "[settings.radial.damping]\nsamples = 1000000000\n",
    "samples-negative": "[settings.radial.damping]\nsamples = -1\n",
    "samples-text": '[settings.radial.damping]\nsamples = "many"\n',
    "samples-bool": "[settings.radial.damping]\nsamples = true\n",
    "modes-huge-range": '[settings.radial.damping]\nmodes = "1-100000000"\n',
    "modes-beyond-int64": '[settings.radial.damping]\nmodes = "1-99999999999999999999999"\n',
    "n-modes-huge": "[settings.radial.modal]\nn_modes = 100000000\n",
    "max-order-huge": "[settings.radial.modal]\nmax_order = 9223372036854775807\n",
    "order-step-0": "[settings.radial.modal]\norder_step = 0\n",
    "segment-huge": "[settings.radial.frf]\nsegment = 1099511627776\n",
    "frequencies-many": "[settings.radial.modal]\nfrequencies = ["
    + ", ".join(["10.0"] * 5000)
    + "]\n",
    "band-inf": "[settings.radial.modal]\nband = [0.0, inf]\n",
    "false-alarm-nan": "[settings.radial.modal]\nfalse_alarm = nan\n",
    "unknown-key": "[settings.radial.modal]\nbandd = [0.0, 40.0]\n",
    "unknown-section": "[settings.radial.nope]\nx = 1\n",
    "unknown-study": "[settings.orbital.modal]\nx = 1\n",
}
FILE_CASES = {
    "not-toml": b"this is [not toml\n",
    "binary": bytes(range(256)) * 4,
    "empty": b"",
    "no-tests": b'name = "x"\n',
    "nested-arrays": b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    "glob-matches-nothing": b'[[tests]]\nfiles = "nothing-*.npz"\n',
    "pressure-inf": b'[[tests]]\nfiles = "chain1.npz"\npressure_bar = inf\n',
    "pressure-text": b'[[tests]]\nfiles = "chain1.npz"\npressure_bar = "high"\n',
    "invalid-utf8": b'name = "\xff\xfe"\n',
}
EDIT_CASES = [
    "report.html",
    "modes.csv",
    "campaign.json",
    "steps.csv",
    "trend_fits.json",
    "tests/*/modes.json",
]


def _check_one_line_exit_2(run: Callable[[], None], capsys: pytest.CaptureFixture[str]) -> str:
    before = scratch_dirs()
    with pytest.raises(SystemExit) as exc:
        run()
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert exc.value.code == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith("tyredamp: error: "), err
    assert "Traceback" not in err
    assert scratch_dirs() <= before  # no scratch copy left
    return lines[0]


def _in_copy(tiny: Path, tmp_path: Path) -> Path:
    root = tmp_path / "data"
    shutil.copytree(tiny / "data", root)
    return root


@pytest.mark.parametrize("case", sorted(SCHEDULER_TEXT))
def test_a_bad_scheduler_address_is_refused_before_connecting(
    case: str,
    tiny: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    root = _in_copy(tiny, tmp_path)
    monkeypatch.chdir(root)
    before = tree(tmp_path)
    args = ["campaign", "campaign.toml", "--out", str(tmp_path / "out")]
    line = _check_one_line_exit_2(
        lambda: main([*args, "--scheduler", SCHEDULER_TEXT[case]]), capsys
    )
    assert "--scheduler" in line
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", SERVER_CASES)
def test_a_server_that_is_not_a_dask_scheduler_ends_in_one_line(
    case: str,
    servers: dict[str, int],
    tiny: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    root = _in_copy(tiny, tmp_path)
    before = tree(tmp_path)
    args = [
        "campaign",
        str(root / "campaign.toml"),
        "--out",
        str(tmp_path / "out"),
        "--scheduler",
        f"tcp://127.0.0.1:{servers[case]}",
        "--connect-timeout",
        "0.5",
    ]
    line = _check_one_line_exit_2(lambda: main(args), capsys)
    assert f"127.0.0.1:{servers[case]}" in line
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", sorted(OPTION_CASES))
def test_bad_options_end_in_one_line(
    case: str,
    tiny: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    root = _in_copy(tiny, tmp_path)
    monkeypatch.chdir(root)
    before = tree(tmp_path)
    opts = OPTION_CASES[case]
    out = [] if "--out" in opts else ["--out", str(tmp_path / "out")]
    _check_one_line_exit_2(lambda: main(["campaign", "campaign.toml", *out, *opts]), capsys)
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", sorted(SETTINGS_CASES))
def test_hostile_settings_are_refused_before_any_work(
    case: str, tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _in_copy(tiny, tmp_path)
    camp = root / "hostile.toml"
    camp.write_text('name = "hostile"\n' + SETTINGS_CASES[case] + TESTS, encoding="utf-8")
    before = tree(tmp_path)
    args = ["campaign", str(camp), "--out", str(tmp_path / "out"), "--serial"]
    line = _check_one_line_exit_2(lambda: main(args), capsys)
    assert "settings" in line
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", sorted(FILE_CASES))
def test_hostile_campaign_files_end_in_one_line(
    case: str, tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _in_copy(tiny, tmp_path)
    camp = root / "hostile.toml"
    camp.write_bytes(FILE_CASES[case])
    before = tree(tmp_path)
    args = ["campaign", str(camp), "--out", str(tmp_path / "out"), "--serial"]
    line = _check_one_line_exit_2(lambda: main(args), capsys)
    assert "hostile.toml" in line or "--out" in line
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", EDIT_CASES)
def test_an_edited_output_is_never_replaced(
    case: str, tiny: Path, done: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    shutil.copytree(done, out)
    target = sorted(out.glob(case))[0]
    target.write_bytes(target.read_bytes() + b"\nmy notes\n")
    before = tree(tmp_path)
    inputs = tree(tiny)
    args = ["campaign", str(tiny / "data" / "campaign.toml"), "--out", str(out), "--serial"]
    line = _check_one_line_exit_2(lambda: main(args), capsys)
    assert target.relative_to(out).as_posix() in line
    assert "changed since the campaign wrote it" in line
    assert tree(tmp_path) == before
    assert tree(tiny) == inputs


def test_a_rerun_with_nothing_changed_keeps_the_outputs(
    tiny: Path, done: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    shutil.copytree(done, out)
    stamps = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    camp = str(tiny / "data" / "campaign.toml")
    main(["campaign", camp, "--out", str(out)])
    assert "nothing changed since the last run" in capsys.readouterr().out
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == stamps
    # without the report the outputs are not those of the last run: written again
    main(["campaign", camp, "--out", str(out), "--no-report"])
    assert "wrote " in capsys.readouterr().out
    assert (out / "modes.csv").stat().st_mtime_ns != stamps[out / "modes.csv"]
    assert (out / "modes.csv").read_bytes() == (done / "modes.csv").read_bytes()


def test_the_corpus_has_at_least_fifty_cases() -> None:
    n = len(SCHEDULER_TEXT) + len(SERVER_CASES) + len(OPTION_CASES) + len(SETTINGS_CASES)
    assert n + len(FILE_CASES) + len(EDIT_CASES) >= 50


# ----------------------------------------------------------------------------- recovered
def _flip_a_digit(b: bytes) -> bytes:
    i = b.index(b'"document":')
    j = next(k for k in range(len(b) - 1, i, -1) if b[k : k + 1].isdigit())
    return b[:j] + (b"1" if b[j : j + 1] != b"1" else b"2") + b[j + 1 :]


CORRUPTIONS: dict[str, Callable[[bytes], bytes]] = {
    "truncated": lambda b: b[: len(b) // 2],
    "empty": lambda b: b"",
    "digit-changed": lambda b: _flip_a_digit(b),
    "not-json": lambda b: b"\x00garbage",
    "checksum-removed": lambda b: json.dumps({**json.loads(b), "sha256": None}).encode(),
}


@pytest.mark.parametrize("case", sorted(CORRUPTIONS))
def test_a_damaged_cache_entry_is_recomputed_with_a_warning(
    case: str, tiny: Path, done: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    shutil.copytree(done, out)
    entry = sorted((out / "cache").glob("*.json"))[0]
    good = entry.read_bytes()
    entry.write_bytes(CORRUPTIONS[case](good))
    args = ["campaign", str(tiny / "data" / "campaign.toml"), "--out", str(out), "--serial"]
    main(args)  # returns: exit code 0
    captured = capsys.readouterr()
    warnings = [x for x in captured.err.splitlines() if x]
    assert len(warnings) == 1, captured.err
    assert warnings[0].startswith("tyredamp: warning: ")
    assert entry.name in warnings[0]
    assert " 0 steps computed" not in captured.out  # the damaged step (and those after it) ran
    assert entry.read_bytes() == good  # computed again: the same document, bit for bit


def test_a_too_large_test_file_fails_that_test_only(tiny: Path, tmp_path: Path) -> None:
    root = _in_copy(tiny, tmp_path)
    big = root / "big.npz"
    with open(big, "wb") as fh:  # a sparse file: 3 GiB that take no disk space
        fh.truncate(3 << 30)
    camp = root / "big.toml"
    camp.write_text(TINY + TESTS + '[[tests]]\nfiles = "big.npz"\n', encoding="utf-8")
    runs = run_tests(load_campaign(camp), tmp_path / "out", mode="serial")
    assert [r.ok for r in runs] == [True, True, False]
    assert "big.npz: the file is 3.0 GiB, larger than the 2.0 GiB" in str(runs[2].reason)
    # a lower limit fails the others the same way, before they are read
    runs = run_tests(load_campaign(camp), tmp_path / "out2", mode="serial", max_file_bytes=1000)
    assert not any(r.ok for r in runs)


def test_scratch_copies_a_killed_run_left_are_swept_and_nothing_else(tmp_path: Path) -> None:
    from tyredamp.campaign.scratch import MARKER, sweep_scratch

    code = (
        "import os, signal, sys\n"
        "from tyredamp.campaign.scratch import scratch_dir\n"
        "cm = scratch_dir()\n"
        "d = cm.__enter__()\n"
        "(d / 'test.uff').write_bytes(b'x' * 1000)\n"
        "print(d, flush=True)\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert proc.returncode == -signal.SIGKILL
    left = Path(proc.stdout.strip())
    assert left.parent == tmp_path
    assert (left / "test.uff").is_file()
    # look-alikes that are not ours (or not dead) are kept
    alive = tmp_path / f"tyredamp-campaign-{os.getpid()}-abc"
    no_marker = tmp_path / "tyredamp-campaign-999999999-abc"
    other = tmp_path / "tyredamp-campaign-notapid"
    for d in (alive, no_marker, other):
        d.mkdir()
    (alive / MARKER).write_bytes(b"")
    (other / MARKER).write_bytes(b"")
    link = tmp_path / "tyredamp-campaign-999999998-lnk"
    link.symlink_to(alive)
    assert sweep_scratch(tmp_path) == [left]
    assert not left.exists()
    assert all(d.is_dir() for d in (alive, no_marker, other))
    assert link.is_symlink()


def _die_on_two(x: int) -> int:
    if x == 2:
        os._exit(9)  # a worker process killed (as by the out-of-memory killer)
    return x * 10


def test_a_worker_process_that_dies_fails_its_test_only() -> None:
    from tyredamp.campaign.pool import run_in_pool

    got = dict(run_in_pool(_die_on_two, [1, 2, 3, 4], 2, lambda x: -x))
    assert got == {1: 10, 2: -2, 3: 30, 4: 40}


def test_a_worker_result_is_plain_json_checked_on_arrival() -> None:
    import pickle

    from tyredamp.campaign.runner import Outcome, Task, outcome_from_json

    task = Task("t1", "radial", "/x", "x.uff", "0" * 64, ("modal", "damping"), {}, {}, {})

    def reason(data: Any) -> str | None:
        return outcome_from_json(data, task).reason

    bad = "the worker sent a malformed result"
    assert reason(pickle.dumps(Outcome("t1", {}))) == bad  # never unpickled
    assert reason(b"not json") == bad
    assert reason({"test_id": "t1"}) == bad  # not bytes
    ok = {"test_id": "t1", "documents": {"modal": {}}, "failed_step": None, "reason": None}
    ok |= {"seconds": 1.0, "cpu_seconds": 0.5}
    assert reason(json.dumps(ok).encode()) is None
    assert reason(json.dumps({**ok, "test_id": "t2"}).encode()) == bad
    assert reason(json.dumps({**ok, "documents": {"other": {}}}).encode()) == bad
    assert reason(json.dumps({**ok, "documents": {"modal": [1]}}).encode()) == bad
    assert reason(json.dumps({**ok, "seconds": "1"}).encode()) == bad
    assert reason(b"[" * 100000 + b"]" * 100000) == bad
