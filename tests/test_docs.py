"""Every example in the README and the documentation runs as written.

Each page's code blocks run in order in one empty temporary folder, the way a
reader copies them: ``bash`` blocks in ``bash -e`` (the ``tyredamp`` command
of this checkout), ``python`` blocks executed in one namespace per page (so a
later block sees the names of an earlier one, as in an interactive session).
Other blocks (``toml``, ``json``, ``text``) are not run.

Markers, HTML comments on the line right before a block (invisible on the
rendered page):

* ``<!-- docs-test: skip REASON -->``: the block is not run (set-up commands
  that install the package, a benchmark of minutes). A reason is required.
* ``<!-- docs-test: real-data PATH ... -->``: copy these files of the shared
  real-data gallery (``../shared/real-data`` beside the repository, see its
  CATALOGUE.md) into the folder before the block runs, under their base
  names; the page is skipped when the gallery is absent.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REAL_DATA = Path(__file__).resolve().parents[2] / "shared" / "real-data"

#: The pages whose examples run: the README and every page of the site.
PAGES = sorted(
    [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")],
    key=lambda p: str(p.relative_to(ROOT)),
)

RUN_LANGUAGES = {"bash": "bash", "sh": "bash", "console": "bash", "python": "python"}
_FENCE = re.compile(r"^(?P<indent> *)(?P<fence>```+|~~~+)\s*(?P<lang>[\w+-]*)")
_MARKER = re.compile(r"^\s*<!--\s*docs-test:\s*(?P<what>[\w-]+)\s*(?P<args>.*?)\s*-->\s*$")


@dataclass
class Block:
    """One fenced code block of a page."""

    page: Path
    line: int  # 1-based line of the opening fence
    language: str
    code: str
    skip: str | None = None
    real_data: list[str] = field(default_factory=list)


def code_blocks(page: Path) -> list[Block]:
    """The fenced code blocks of ``page`` with the markers right before each."""
    lines = page.read_text(encoding="utf-8").splitlines()
    blocks: list[Block] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = len(m["indent"]), m["fence"], m["lang"].lower()
        body: list[str] = []
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith(fence):
            body.append(lines[j][indent:] if lines[j][:indent].strip() == "" else lines[j])
            j += 1
        block = Block(page, i + 1, lang, "\n".join(body) + "\n")
        k = i - 1
        while k >= 0 and (mk := _MARKER.match(lines[k])):
            if mk["what"] == "skip":
                if not mk["args"]:
                    raise AssertionError(f"{page}:{k + 1}: a skip marker needs a reason")
                block.skip = mk["args"]
            elif mk["what"] == "real-data":
                block.real_data.extend(mk["args"].split())
            else:
                raise AssertionError(f"{page}:{k + 1}: unknown docs-test marker {mk['what']!r}")
            k -= 1
        blocks.append(block)
        i = j + 1
    return blocks


def _page_id(page: Path) -> str:
    return str(page.relative_to(ROOT))


def _runnable(page: Path) -> list[Block]:
    return [b for b in code_blocks(page) if b.language in RUN_LANGUAGES]


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    src = str(ROOT / "src")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH", "")) if p)
    env["MPLBACKEND"] = "Agg"
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    # ``tyredamp`` of this checkout: the interpreter running the tests
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def _run_bash(block: Block, cwd: Path) -> None:
    proc = subprocess.run(
        ["bash", "-e", "-o", "pipefail", "-c", block.code],
        cwd=cwd,
        env=_environment(),
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    if proc.returncode != 0:
        pytest.fail(
            f"{_page_id(block.page)}:{block.line}: bash block exited {proc.returncode}\n"
            f"--- block ---\n{block.code}--- stdout ---\n{proc.stdout[-3000:]}\n"
            f"--- stderr ---\n{proc.stderr[-3000:]}"
        )


def _run_python(block: Block, namespace: dict[str, object]) -> None:
    code = compile(block.code, f"{_page_id(block.page)}:{block.line}", "exec")
    try:
        exec(code, namespace)
    except Exception as exc:  # report where in the docs it broke
        raise AssertionError(
            f"{_page_id(block.page)}:{block.line}: python block raised "
            f"{type(exc).__name__}: {exc}\n--- block ---\n{block.code}"
        ) from exc


def test_pages_found() -> None:
    """The README and the site's pages are collected, and some blocks run."""
    names = {_page_id(p) for p in PAGES}
    assert {"README.md", "docs/index.md", "docs/getting-started.md"} <= names
    assert sum(len(_runnable(p)) for p in PAGES) >= 10


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_skip_markers_are_rare(page: Path) -> None:
    """At most two skipped blocks a page, each with its reason (checked by the parser)."""
    assert sum(b.skip is not None for b in _runnable(page)) <= 2


@pytest.mark.slow
@pytest.mark.parametrize(
    "page", [p for p in PAGES if any(b.skip is None for b in _runnable(p))], ids=_page_id
)
def test_examples_run(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every bash and python block of the page runs, in order, in an empty folder."""
    blocks = [b for b in _runnable(page) if b.skip is None]
    if any(b.real_data for b in blocks) and not REAL_DATA.is_dir():
        pytest.skip(f"the real-data gallery is not at {REAL_DATA}")
    monkeypatch.chdir(tmp_path)
    for key, value in _environment().items():
        if key in ("MPLBACKEND", "OPENBLAS_NUM_THREADS"):
            monkeypatch.setenv(key, value)
    namespace: dict[str, object] = {"__name__": "__docs__"}
    for block in blocks:
        for rel in block.real_data:
            source = REAL_DATA / rel
            assert source.is_file(), f"{_page_id(page)}:{block.line}: no {source}"
            shutil.copyfile(source, tmp_path / source.name)
        if block.language == "python":
            _run_python(block, namespace)
        else:
            _run_bash(block, tmp_path)


def test_every_page_in_the_site_navigation() -> None:
    """Each page under docs/ is reachable from the site's navigation (mkdocs.yml)."""
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    listed = set(re.findall(r":\s*([\w./-]+\.md)\s*$", config, flags=re.MULTILINE))
    pages = {str(p.relative_to(ROOT / "docs")) for p in (ROOT / "docs").rglob("*.md")}
    assert pages - listed == set(), "pages missing from nav in mkdocs.yml"
    assert listed - pages == set(), "nav entries without a page"
