"""What importing the command line, its subcommands and the modal package loads (start-up).

Each check runs in a fresh interpreter and lists ``sys.modules`` after the
import: a heavy import added back at module level (SciPy's optimisers,
plotting, the parallel and file-format back-ends) fails here, not only in
``benchmarks/startup.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[1] / "src")

#: top-level packages that no command may load before it runs
HEAVY = ("matplotlib", "scipy", "distributed", "dask", "asammdf", "nptdms")


def _loaded(statement: str) -> list[str]:
    """Modules in ``sys.modules`` after ``statement`` in a fresh interpreter."""
    code = f"import json, sys\n{statement}\nprint(json.dumps(sorted(sys.modules)))"
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    out = subprocess.run(
        [sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env
    )
    return list(json.loads(out.stdout.splitlines()[-1]))


def _heavy(mods: list[str], names: tuple[str, ...] = HEAVY) -> list[str]:
    return [m for m in mods if m.split(".")[0] in names]


@pytest.mark.parametrize("statement", ["import tyredamp", "import tyredamp.cli"])
def test_command_line_loads_no_heavy_package(statement: str) -> None:
    assert _heavy(_loaded(statement)) == []


def _commands() -> list[str]:
    cli = Path(SRC) / "tyredamp" / "cli"
    return sorted(p.stem for p in cli.glob("*.py") if not p.stem.startswith("_"))


@pytest.mark.parametrize("command", _commands())
def test_every_command_module_loads_no_heavy_package(command: str) -> None:
    # a subcommand's module is imported for its --help and before its inputs are
    # checked: the numerical packages wait until the command runs
    assert _heavy(_loaded(f"import tyredamp.cli.{command}")) == []


def test_step_settings_name_what_the_registries_hold() -> None:
    # the settings carry the registries' names so that they load without SciPy
    from tyredamp.damping import METHODS
    from tyredamp.lateral.models import MODELS
    from tyredamp.modal.poles.estimators import DEFAULT_ESTIMATOR
    from tyredamp.modal.statistics.stats import FALSE_ALARM
    from tyredamp.signal.estimators import ESTIMATORS
    from tyredamp.studies.steps import damping, frf, lateral_fit, modal

    assert tuple(METHODS) == damping.DAMPING_METHODS
    assert tuple(ESTIMATORS) == frf.FRF_ESTIMATORS
    assert tuple(sorted(MODELS)) == lateral_fit.LATERAL_MODELS
    assert modal.FALSE_ALARM == FALSE_ALARM
    assert modal.DEFAULT_ESTIMATOR == DEFAULT_ESTIMATOR


def test_documents_registry_is_built_on_first_use() -> None:
    mods = _loaded("import tyredamp.documents.jsonfile")
    assert _heavy(mods) == []
    assert "tyredamp.documents.modes" not in mods
    from tyredamp.documents import DOCUMENTS

    assert sorted(DOCUMENTS) == ["damping", "lateral-fit", "modes", "tyredamp-demo-results"]


def test_modal_package_is_lazy() -> None:
    # the names of tyredamp.modal are loaded on first access (PEP 562)
    mods = _loaded("import tyredamp.modal")
    assert _heavy(mods) == []
    assert [m for m in mods if m.startswith("tyredamp.modal.")] == []
    mods = _loaded("from tyredamp.modal import ModalModel")
    assert "scipy.optimize" not in mods
    assert "tyredamp.modal.identify" not in mods
    assert _heavy(mods, ("matplotlib", "distributed", "dask", "asammdf", "nptdms")) == []


def test_modal_package_names_resolve() -> None:
    import tyredamp.modal as modal

    for name in modal.__all__:
        assert getattr(modal, name) is not None, name
    assert set(modal.__all__) <= set(dir(modal))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        modal.nothing


def test_a_refused_file_loads_no_linear_algebra(tmp_path: Path) -> None:
    # `tyredamp modal` checks its settings (the estimator's name among them) and
    # reads the file before anything of the identification is imported
    bad = tmp_path / "bad.uff"
    bad.write_text("not a universal file\n")
    statement = (
        "from tyredamp.cli import main\n"
        "try:\n"
        f"    main(['modal', {str(bad)!r}, '-o', {str(tmp_path / 'm.json')!r}])\n"
        "except SystemExit:\n"
        "    pass"
    )
    mods = _loaded(statement)
    assert "tyredamp.modal.poles.lscf" not in mods
    assert _heavy(mods) == []
    assert not (tmp_path / "m.json").exists()


def test_a_modal_run_loads_only_what_it_needs(tmp_path: Path) -> None:
    # the identification and its verdicts take their distributions from
    # scipy.special; scipy.stats and scipy.signal cost half a second to import
    import numpy as np

    from tyredamp.frf import FRF
    from tyredamp.io import write_frf

    f = np.linspace(1.0, 200.0, 200)
    s = 2j * np.pi * f
    p = -0.02 * 2 * np.pi * 60 + 2j * np.pi * 60
    h = (1 / (s - p) + 1 / (s - np.conj(p)))[None, None, :] * np.ones((2, 1, 1))
    h = h + 1e-4 * np.random.default_rng(0).normal(size=h.shape)
    npz = tmp_path / "small.npz"
    write_frf(FRF(f, h, kind="receptance"), npz)
    statement = (
        "from tyredamp.cli import main\n"
        "try:\n"
        f"    main(['modal', {str(npz)!r}, '-o', {str(tmp_path / 'm.json')!r}])\n"
        "except SystemExit as e:\n"
        "    assert not e.code, e.code"
    )
    mods = _loaded(statement)
    assert (tmp_path / "m.json").is_file()
    assert "scipy.stats" not in mods
    assert "scipy.signal" not in mods
    # nor what only several inputs, a model error or the damping step need
    for heavy in ("scipy.optimize", "scipy.integrate", "scipy.spatial", "scipy.sparse.csgraph"):
        assert heavy not in mods, heavy
    assert "tyredamp.damping.estimate" not in mods
