"""The named steps of the studies: the command line gives what the steps give."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.cli import main
from tyredamp.exceptions import InputError
from tyredamp.io import write_frf
from tyredamp.modal import ModalModel
from tyredamp.studies.lateral import fit_models, lateral_data
from tyredamp.studies.radial import check_reciprocity, damping_from_modes, modes_from_frf
from tyredamp.virtual import VirtualLateralRig

from .helpers import chain_system


def _run(args: list[str]) -> None:
    code: object = 0
    try:
        main(args)
    except SystemExit as exc:
        code = exc.code
    assert not code, code


def test_modal_command_is_the_modes_step(tmp_path: Path) -> None:
    system = chain_system()
    frf = system.frf(np.linspace(0.5, 40.0, 200), inputs=[0])
    path = write_frf(frf, tmp_path / "chain.npz")
    step = modes_from_frf(frf, model="complex")
    _run(["modal", str(path), "--out", str(tmp_path / "m.json"), "--model", "complex"])
    doc = json.loads((tmp_path / "m.json").read_text())
    poles = np.array([m["pole"] for m in doc["models"]["complex"]["modes"]])
    # the same computation on the same (losslessly stored) FRF: the same poles
    assert_allclose(poles[:, 0] + 1j * poles[:, 1], step.models["complex"].poles, rtol=1e-12)


def test_lateral_fit_command_is_the_fit_step(tmp_path: Path) -> None:
    frf = VirtualLateralRig().measure(5.0, 1.7, "ground", 0).frf
    path = write_frf(frf, tmp_path / "rig.npz")
    ranking = fit_models(lateral_data(frf), ["maxwell", "hysteretic"])
    out = tmp_path / "l.json"
    _run(["lateral", "fit", str(path), "--out", str(out), "--models", "maxwell,hysteretic"])
    doc = json.loads(out.read_text())
    assert doc["order"] == [f.name for f in ranking.fits]
    assert doc["table"][0]["bic"] == pytest.approx(ranking.fits[0].bic, rel=1e-12)


def test_steps_name_bad_input() -> None:
    cm = chain_system().complex_modes()
    with pytest.raises(InputError, match="not 'real'"):
        damping_from_modes({"complex": ModalModel(cm.poles, cm.psi, cm.psi[:1])}, model="real")
    with pytest.raises(InputError, match="one or more FRFs"):
        check_reciprocity([])
    frf = VirtualLateralRig().measure(5.0, 1.7, "ground", 0).frf
    with pytest.raises(InputError, match="speed"):
        lateral_data(frf, speed_kmh=-5.0)
