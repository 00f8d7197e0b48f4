"""What every command shares: --help with an example, --version, errors as one line + exit 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import click
import pytest

from tyredamp import __version__
from tyredamp.cli import COMMANDS as LAZY
from tyredamp.cli import cli, main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def _commands(group: click.Group, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    out: list[tuple[str, ...]] = []
    ctx = click.Context(group)
    for name in group.list_commands(ctx):  # imports the lazy subcommands
        cmd = group.get_command(ctx, name)
        assert cmd is not None
        out.append((*prefix, name))
        if isinstance(cmd, click.Group):
            out += _commands(cmd, (*prefix, name))
    return out


COMMANDS = _commands(cli)


def test_all_commands_are_there() -> None:
    names = {c[0] for c in COMMANDS}
    assert {"demo", "simulate", "frf", "check", "modal", "damping", "lateral", "report"} <= names
    assert ("simulate", "radial") in COMMANDS
    assert ("simulate", "lateral") in COMMANDS
    assert ("lateral", "fit") in COMMANDS


@pytest.mark.parametrize("command", [(), *COMMANDS], ids=lambda c: " ".join(c) or "tyredamp")
def test_help_has_an_example(capsys: pytest.CaptureFixture[str], command: tuple[str, ...]) -> None:
    code, out, _ = run(capsys, *command, "--help")
    assert code == 0
    assert "Example:" in out
    example = out.split("Example:")[1]
    assert "tyredamp " in example  # the example is a command line
    # every command that writes a file takes --out/-o
    cmd = cli
    for name in command:
        cmd = cmd.commands[name]  # type: ignore[attr-defined]
    if not isinstance(cmd, click.Group) and command not in {
        ("check", "linearity"),
        ("check", "reciprocity"),
        ("check", "quality"),
    }:
        opts = {o for p in cmd.params for o in getattr(p, "opts", [])}
        assert {"--out", "-o"} <= opts, command


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "--version")
    assert code == 0
    assert __version__ in out


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["demo", "--seed", "-1"], "--seed"),
        (["simulate", "radial"], "--out"),
        (["simulate", "lateral", "--out", "{tmp}/x.npz", "--speed", "abc"], "--speed"),
        (["simulate", "lateral", "--out", "{tmp}/x.npz", "--seed", "-1"], "--seed"),
        (["frf", "{tmp}/missing.uff", "--out", "{tmp}/f.uff"], "missing.uff"),
        (["check", "linearity", "{tmp}/one.uff"], "two or more"),
        (["modal", "{tmp}/missing.uff", "--out", "{tmp}/m.json"], "missing.uff"),
        (["damping", "{tmp}/notjson.json", "--out", "{tmp}/d.json"], "notjson.json"),
        (["lateral", "fit", "{tmp}/missing.npz", "--out", "{tmp}/l.json"], "missing.npz"),
        (["report", "--out", "{tmp}/r.html"], "RESULT_FILES"),
        (["report", "{tmp}/notjson.json", "--out", "{tmp}/r.html"], "notjson.json"),
        (["report", "{tmp}/other.json", "--out", "{tmp}/r.html"], "not a tyredamp result"),
        (["report", "{tmp}/data.xyz", "--out", "{tmp}/r.html"], "extension"),
        (["nosuchcommand"], "No such command"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, argv: list[str], needle: str
) -> None:
    (tmp_path / "notjson.json").write_text("{not json")
    (tmp_path / "other.json").write_text('{"kind": "something else"}')
    (tmp_path / "data.xyz").write_text("1 2 3")
    (tmp_path / "one.uff").write_text("x")
    before = sorted(p.name for p in tmp_path.iterdir())
    args = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    code, _out, err = run(capsys, *args)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("tyredamp: error: ")
    assert needle in lines[0]
    assert "Traceback" not in err
    # no output file, no temporary file
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_debug_shows_the_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # --debug adds the traceback; the exit code and the last line stay the same (issue 15)
    (tmp_path / "other.json").write_text('{"kind": "something else"}')
    argv = ["report", str(tmp_path / "other.json"), "--out", str(tmp_path / "r.html")]
    code, _, err = run(capsys, "--debug", *argv)
    assert code == 2
    assert "Traceback" in err
    assert "FileFormatError" in err
    assert err.strip().splitlines()[-1].startswith("tyredamp: error: ")
    code2, _, err2 = run(capsys, *argv)
    assert code2 == code
    assert err2.strip() == err.strip().splitlines()[-1]


def test_lazy_summaries_are_the_docstrings() -> None:
    # tyredamp --help prints LAZY's summaries without importing the commands
    ctx = click.Context(cli)
    for name, (_module, _attr, summary) in LAZY.items():
        cmd = cli.get_command(ctx, name)
        assert cmd is not None
        assert cmd.get_short_help_str(limit=1000) == summary


def test_start_imports_no_subcommand_and_modal_no_io() -> None:
    # a fresh interpreter: --help loads no subcommand (nor NumPy); the modal
    # package loads neither pyuff nor matplotlib
    code = (
        "import sys, contextlib, io\n"
        "from tyredamp.cli import main\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(['--help'])\n"
        "cmds = [m for m in sys.modules if m.startswith('tyredamp.cli.')]\n"
        "bad = [m for m in cmds if m != 'tyredamp.cli._common']\n"
        "assert not bad and 'numpy' not in sys.modules, (bad, 'numpy' in sys.modules)\n"
        "import tyredamp.modal\n"
        "assert 'pyuff' not in sys.modules and 'matplotlib' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("value", ["0", "nan", "25", "abc"])
@pytest.mark.parametrize(
    "command", [("simulate", "radial"), ("simulate", "lateral"), ("simulate", "rolling")]
)
def test_pressure_is_refused_in_bar_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: tuple[str, ...], value: str
) -> None:
    out = tmp_path / "never.uff"
    code, _, err = run(capsys, *command, "--out", str(out), "--pressure", value)
    assert code == 2
    line = err.strip()
    assert "\n" not in line
    assert "--pressure" in line
    assert "bar" in line
    assert "pressure_bar" not in line  # no Python name
    assert not out.exists()
