"""The package's import layering (developer guide "Package layout", /shared/DESIGN.md).

The import graph is parsed from the source with :mod:`ast` (nothing is
imported), counting every import: at module level, inside functions (lazy)
and under ``if TYPE_CHECKING:``. Three rules:

* every package sits on a floor and imports only from floors below it
  (packages on the same floor are independent of each other); the one
  allowed upward edge is the ``.plot()`` convenience of a data object, a
  lazy import of :mod:`tyredamp.plot` inside a method or function named
  ``plot...``;
* no import circle between modules (within a package, a module's import of
  its own package ``__init__`` counts; the implicit parent import that
  Python performs does not, it would make every package a circle);
* no function longer than 120 lines, no module longer than 800 lines.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "tyredamp"

#: Floors from the ground up; a package imports only from lower floors.
FLOORS: tuple[tuple[str, ...], ...] = (
    ("__init__", "exceptions", "_validate", "_blas", "_lazy", "frf", "timedata", "geometry"),
    ("mechanics",),
    ("signal",),
    ("modal", "lateral"),
    ("damping", "oma"),
    ("dampmodels",),
    ("virtual",),
    ("tyremodel",),
    ("io",),
    ("documents",),
    ("studies",),
    ("campaign",),
    ("plot",),
    ("report",),
    ("cli",),
)
FLOOR = {name: i for i, names in enumerate(FLOORS) for name in names}
#: The ground floor's modules form one unit (they import each other freely, without circles).
GROUND = "ground"

#: Groups of :mod:`tyredamp.modal` from the ground up (the map in its docstring):
#: a group imports only from lower floors; groups on one floor are independent.
MODAL_FLOORS: tuple[tuple[str, ...], ...] = (
    ("statistics",),
    ("model",),
    ("problem",),
    ("poles", "fit"),
    ("search",),
    ("pipeline",),
)
MODAL_FLOOR = {name: i for i, names in enumerate(MODAL_FLOORS) for name in names}
#: Modules at the top of :mod:`tyredamp.modal` and their group (the package itself,
#: ``tyredamp.modal``, is the pipeline's: it names the public API of every group).
MODAL_TOP = {
    "model": "model",
    "identify": "pipeline",
    "starts": "pipeline",
    "mode_count": "pipeline",
    "final": "pipeline",
    "assemble": "pipeline",
    "sandwich": "pipeline",
    "replicates": "pipeline",
}

MAX_FUNCTION_LINES = 120
MAX_MODULE_LINES = 800
#: Subpackages exempt from the size limits (none at present).
SIZE_EXEMPT: tuple[str, ...] = ()
#: Long functions waiting to be split (none at present).
LONG_PENDING: set[tuple[str, str]] = set()


@dataclass(frozen=True)
class Edge:
    """One import: ``source`` module imports ``target`` module at ``line``."""

    source: str
    target: str
    line: int
    function: str | None  # innermost enclosing function, None at module level


def _module_name(path: Path) -> str:
    parts = ["tyredamp", *path.relative_to(SRC).with_suffix("").parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(SRC.rglob("*.py"))}


def _resolve(module: str, is_pkg: bool, node: ast.ImportFrom, known: dict[str, Path]) -> list[str]:
    """Targets of ``from X import a, b``: submodules where ``a`` is one, else ``X``."""
    if node.level:
        base = module.split(".") if is_pkg else module.split(".")[:-1]
        base = base[: len(base) - (node.level - 1)]
        prefix = ".".join(base)
        mod = f"{prefix}.{node.module}" if node.module else prefix
    else:
        mod = node.module or ""
    if not mod.startswith("tyredamp"):
        return []
    out = []
    for alias in node.names:
        sub = f"{mod}.{alias.name}"
        out.append(sub if sub in known else mod)
    return out


def _edges(module: str, path: Path, known: dict[str, Path]) -> Iterator[Edge]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_pkg = path.name == "__init__.py"

    def visit(node: ast.AST, func: str | None) -> Iterator[Edge]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                yield from visit(child, child.name)
                continue
            if isinstance(child, ast.Import):
                for alias in child.names:
                    if alias.name.startswith("tyredamp"):
                        yield Edge(module, alias.name, child.lineno, func)
            elif isinstance(child, ast.ImportFrom):
                for target in _resolve(module, is_pkg, child, known):
                    yield Edge(module, target, child.lineno, func)
            yield from visit(child, func)

    yield from visit(tree, None)


def _graph() -> list[Edge]:
    known = _modules()
    return [e for m, p in known.items() for e in _edges(m, p, known) if e.target != m]


def _unit(module: str) -> str:
    """The layering unit of a module: its top-level package, or ``ground``."""
    parts = module.split(".")
    if len(parts) == 1 or parts[1] in FLOORS[0]:
        return GROUND
    return parts[1]


def _floor(unit: str) -> int:
    return 0 if unit == GROUND else FLOOR[unit]


def _plot_convenience(edge: Edge) -> bool:
    return (
        edge.function is not None
        and edge.function.startswith("plot")
        and (edge.target == "tyredamp.plot" or edge.target.startswith("tyredamp.plot."))
    )


def test_every_package_has_a_floor() -> None:
    units = {_unit(m) for m in _modules()}
    missing = sorted(u for u in units if u != GROUND and u not in FLOOR)
    assert not missing, f"packages without a floor in FLOORS: {missing}"


def test_no_import_from_a_higher_floor() -> None:
    bad = []
    for e in _graph():
        su, tu = _unit(e.source), _unit(e.target)
        if su == tu or _plot_convenience(e):
            continue
        if _floor(tu) >= _floor(su):
            bad.append(
                f"{e.source}:{e.line} ({su}, floor {_floor(su)}) imports {e.target} "
                f"({tu}, floor {_floor(tu)})"
            )
    assert not bad, "imports that go up or sideways:\n" + "\n".join(bad)


def _modal_group(module: str) -> str | None:
    """The group of a module of :mod:`tyredamp.modal` (None outside it): its
    subpackage, or ``MODAL_TOP``'s entry for a module at the top."""
    parts = module.split(".")
    if parts[:2] != ["tyredamp", "modal"]:
        return None
    if len(parts) == 2:
        return "pipeline"
    return MODAL_TOP.get(parts[2], parts[2])


def test_every_modal_module_has_a_group_with_a_floor() -> None:
    modal = [m for m in _modules() if _modal_group(m) is not None]
    assert "tyredamp.modal.fit.fit" in modal  # the walk sees the subpackages
    missing = sorted(m for m in modal if _modal_group(m) not in MODAL_FLOOR)
    assert not missing, f"modal modules without a group in MODAL_FLOORS/MODAL_TOP: {missing}"


def test_modal_groups_import_only_from_lower_floors() -> None:
    bad = []
    for e in _graph():
        sg, tg = _modal_group(e.source), _modal_group(e.target)
        if sg is None or tg is None or sg == tg:
            continue
        if MODAL_FLOOR[tg] >= MODAL_FLOOR[sg]:
            bad.append(f"{e.source}:{e.line} ({sg}) imports {e.target} ({tg})")
    assert not bad, "modal imports that go up or sideways:\n" + "\n".join(bad)


def test_modal_group_of_a_module() -> None:
    # the checker itself: subpackage, a top module and the package
    assert _modal_group("tyredamp.modal.search.narrow") == "search"
    assert _modal_group("tyredamp.modal.model") == "model"
    assert _modal_group("tyredamp.modal.identify") == "pipeline"
    assert _modal_group("tyredamp.modal") == "pipeline"
    assert _modal_group("tyredamp.lateral.models") is None


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one node (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return out


def test_no_import_circles() -> None:
    modules: dict[str, set[str]] = {}
    units: dict[str, set[str]] = {}
    for e in _graph():
        if _plot_convenience(e):
            continue  # the allowed upward edge closes a loop by design (plot imports the object)
        modules.setdefault(e.source, set()).add(e.target)
        su, tu = _unit(e.source), _unit(e.target)
        if su != tu:
            units.setdefault(su, set()).add(tu)
    assert _cycles(modules) == []
    assert _cycles(units) == []


def test_cycle_finder_finds_a_circle() -> None:
    # the checker itself: a three-module circle and a self-contained chain
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"e"}}
    assert _cycles(graph) == [["a", "b", "c"]]


@pytest.mark.parametrize(
    ("module", "is_pkg", "source", "expected"),
    [
        ("tyredamp.modal.fit.fit", False, "from ...frf import FRF", ["tyredamp.frf"]),
        ("tyredamp.modal", True, "from .fit.fit import X", ["tyredamp.modal.fit.fit"]),
        ("tyredamp.cli.demo", False, "from .. import __version__", ["tyredamp"]),
        ("tyredamp.io", True, "from . import uff", ["tyredamp.io.uff"]),
    ],
)
def test_relative_imports_resolve(
    module: str, is_pkg: bool, source: str, expected: list[str]
) -> None:
    node = ast.parse(source).body[0]
    assert isinstance(node, ast.ImportFrom)
    assert _resolve(module, is_pkg, node, _modules()) == expected


def _exempt(path: Path) -> bool:
    return path.relative_to(SRC).parts[0] in SIZE_EXEMPT


def test_no_long_functions() -> None:
    long = []
    for path in sorted(SRC.rglob("*.py")):
        if _exempt(path):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = (node.end_lineno or node.lineno) - node.lineno + 1  # def to end
                pending = (path.relative_to(SRC).as_posix(), node.name) in LONG_PENDING
                if n > MAX_FUNCTION_LINES and not pending:
                    long.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name}: {n} lines")
    assert not long, "functions over 120 lines:\n" + "\n".join(long)


def test_no_long_modules() -> None:
    long = []
    for path in sorted(SRC.rglob("*.py")):
        n = len(path.read_text(encoding="utf-8").splitlines())
        if not _exempt(path) and n > MAX_MODULE_LINES:
            long.append(f"{path.relative_to(SRC)}: {n} lines")
    assert not long, "modules over 800 lines:\n" + "\n".join(long)
