"""``tyredamp damping``: modes JSON in, damping JSON out; errors as one line + exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.cli import main
from tyredamp.damping import DampingModel, identify_damping
from tyredamp.mechanics import MCKSystem
from tyredamp.modal import ModalModel

from .test_damping_identify import exact_model, mck

#: JSON schema of the damping file (docs/damping-json.md), checked on the CLI output.
MATRIX = {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}
SCHEMA = {
    "type": "object",
    "required": [
        "kind",
        "version",
        "method",
        "normalised",
        "modes",
        "points",
        "modal",
        "modal_symmetric",
        "physical",
        "physical_symmetric",
        "mass",
        "stiffness",
        "basis",
        "lancaster_physical",
        "std",
        "uncertainty",
        "diagnostics",
        "proportional",
        "findings",
        "meta",
    ],
    "properties": {
        "kind": {"const": "damping"},
        "version": {"const": 1},
        "method": {"enum": ["first", "improved", "refined"]},
        "normalised": {"type": "boolean"},
        "modes": {
            "type": "object",
            "required": ["frequency_hz", "damping_ratio", "poles"],
            "properties": {
                "frequency_hz": {"type": "array", "items": {"type": "number"}},
                "damping_ratio": {"type": "array", "items": {"type": "number"}},
                "poles": {
                    "type": "array",
                    "items": {
                        "type": "array",
                        "items": {"type": "number"},
                        "minItems": 2,
                        "maxItems": 2,
                    },
                },
            },
        },
        "points": {
            "type": "array",
            "items": {"type": "object", "required": ["node", "direction", "angle_deg", "name"]},
        },
        "modal": MATRIX,
        "modal_symmetric": MATRIX,
        "physical": MATRIX,
        "physical_symmetric": MATRIX,
        "mass": MATRIX,
        "stiffness": MATRIX,
        "basis": MATRIX,
        "lancaster_physical": {"anyOf": [MATRIX, {"type": "null"}]},
        "std": {"type": "object", "properties": {"modal": MATRIX, "physical": MATRIX}},
        "uncertainty": {"type": "object"},
        "diagnostics": {"type": "object", "required": ["symmetry_modal", "definiteness_modal"]},
        "proportional": {"type": "object", "required": ["rayleigh_alpha", "rayleigh_beta"]},
        "findings": {"type": "array", "items": {"type": "string"}},
        "meta": {"type": "object"},
    },
}


def modes_file(path: Path, models: dict[str, ModalModel]) -> Path:
    doc = {
        "kind": "modes",
        "models": {
            name: {**m.to_dict(), "rmsd": 1e-4, "relative_error": 0.01}
            for name, m in models.items()
        },
    }
    path.write_text(json.dumps(doc))
    return path


def truncated(s: MCKSystem, m: int) -> ModalModel:
    base = exact_model(s, slice(0, m))
    return ModalModel(
        base.poles,
        base.psi_out,
        base.psi_out[:1],
        outputs=base.outputs,
        inputs=base.outputs[:1],
        std={
            "frequency_hz": 1e-3 * base.frequency_hz,
            "damping_ratio": 1e-2 * base.damping_ratio,
            "psi_out": 1e-3 * np.abs(base.psi_out),
        },
    )


def test_cli_writes_valid_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    s = mck(4, n=8, zeta_max=0.01, rank=8)
    src = modes_file(tmp_path / "modes.json", {"complex": truncated(s, 5)})
    before = src.read_bytes()
    out = tmp_path / "damp.json"
    main(["damping", str(src), "--out", str(out), "--samples", "30"])
    text = capsys.readouterr().out
    assert "damping (improved): 5 modes at 8 points" in text
    assert "power leakage" in text
    assert src.read_bytes() == before  # input untouched
    doc = json.loads(out.read_text())
    jsonschema.validate(doc, SCHEMA)
    assert doc["meta"]["model"] == "complex"
    assert doc["uncertainty"]["n_samples"] == 30
    # the file holds exactly what the API computes
    api = identify_damping(truncated(s, 5), "improved", n_samples=30, seed=0)
    back = DampingModel.from_dict(doc)
    assert_allclose(back.modal, api.modal, rtol=1e-14)
    assert_allclose(back.std["physical"], api.std["physical"], rtol=1e-12)
    assert len(doc["points"]) == 8


def test_cli_method_and_model_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    s = mck(4, n=6, zeta_max=0.01, rank=6)
    cm = s.complex_modes()
    um = s.undamped_modes()
    real = ModalModel.from_real_modes(cm.frequency_hz, cm.damping_ratio, um.phi, um.phi)
    src = modes_file(tmp_path / "m.json", {"complex": exact_model(s), "real": real})
    out = tmp_path / "d.json"
    main(["damping", str(src), "-o", str(out), "--method", "refined", "--samples", "0"])
    doc = json.loads(out.read_text())
    assert doc["method"] == "refined"
    # complete exact modes: refined = exact C (rounding)
    assert_allclose(np.array(doc["physical"]), s.C, atol=1e-9 * np.abs(s.C).max())
    assert doc["std"] == {}
    main(["damping", str(src), "-o", str(out), "--model", "real", "--samples", "0"])
    assert "cannot be identified from real modes" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("not json", "not valid JSON"),
        ('{"kind": "frf"}', "expected a modes document"),
        ('{"kind": "modes", "models": {}}', "non-empty"),
        ('{"kind": "modes", "models": {"complex": {"modes": []}}}', "missing key"),
        ("", "empty"),
    ],
)
def test_cli_bad_input_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str, message: str
) -> None:
    src = tmp_path / "bad.json"
    src.write_text(content)
    out = tmp_path / "d.json"
    with pytest.raises(SystemExit) as exc:
        main(["damping", str(src), "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1
    assert not out.exists()


def test_cli_missing_model_and_same_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    s = mck(4, n=6, zeta_max=0.01)
    src = modes_file(tmp_path / "m.json", {"complex": exact_model(s)})
    with pytest.raises(SystemExit) as exc:
        main(["damping", str(src), "--out", str(tmp_path / "d.json"), "--model", "real"])
    assert exc.value.code == 2
    assert "holds models ['complex']" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["damping", str(src), "--out", str(src)])
    assert "is the input file" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["damping", str(tmp_path / "nope.json"), "--out", str(tmp_path / "d.json")])
    assert exc.value.code == 2


def test_cli_too_few_points_leaves_no_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    s = mck(4, n=6, zeta_max=0.01)
    cm = s.complex_modes()
    few = ModalModel(cm.poles, cm.psi[:3], cm.psi[:1])
    src = modes_file(tmp_path / "m.json", {"complex": few})
    out = tmp_path / "d.json"
    with pytest.raises(SystemExit) as exc:
        main(["damping", str(src), "--out", str(out)])
    assert exc.value.code == 2
    assert "at least as many points as modes" in capsys.readouterr().err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [src]  # no temporary file left behind


def _with_nan_std(model: ModalModel, where: dict[str, list[tuple[int, ...]]]) -> ModalModel:
    """``model`` with its standard errors set to NaN at the given (mode) / (point, mode) entries."""
    std = {k: np.array(v, dtype=float) for k, v in model.std.items()}
    for key, entries in where.items():
        for e in entries:
            std[key][e] = np.nan
    return ModalModel(
        model.poles,
        model.psi_out,
        model.psi_in,
        outputs=model.outputs,
        inputs=model.inputs,
        std=std,
    )


def test_some_nan_standard_errors_are_named_and_skip_the_monte_carlo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Some NaN standard errors: C' and C written without standard errors, exit 0, and one
    warning line naming exactly the modes and quantities (as the all-NaN case, which says
    "every mode")."""
    from tyredamp.documents.modes import write_modes_json

    s = mck(4, n=8, zeta_max=0.01, rank=8)
    base = truncated(s, 5)
    f = base.frequency_hz
    lab = [c.label for c in base.outputs]
    bad = _with_nan_std(base, {"frequency_hz": [(1,)], "psi_out": [(2, 3), (5, 3)]})
    src = write_modes_json(tmp_path / "modes.json", {"complex": bad})
    before = src.read_bytes()
    out = tmp_path / "d.json"
    main(["damping", str(src), "-o", str(out), "--samples", "30"])
    cap = capsys.readouterr()
    expected = (
        f"mode 2 ({f[1]:.4g} Hz): frequency; mode 4 ({f[3]:.4g} Hz): shape at points "
        f"{lab[2]}, {lab[5]}"
    )
    err = cap.err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("tyredamp: warning: No standard errors"), err
    assert expected in err[0]
    assert expected in cap.out  # the same finding in the printed summary
    assert "nan %" not in cap.out.lower()
    doc = json.loads(out.read_text())
    assert doc["std"] == {}
    assert doc["uncertainty"] == {}
    assert any(expected in s for s in doc["findings"])
    assert src.read_bytes() == before
    # The damping matrix itself is that of the modes without their standard errors.
    assert_allclose(doc["modal"], identify_damping(base, n_samples=0).modal, rtol=1e-13)

    # Every standard error NaN: the same rule, named as "every mode".
    all_nan = _with_nan_std(base, {k: [np.index_exp[...]] for k in base.std})
    write_modes_json(src, {"complex": all_nan})
    main(["damping", str(src), "-o", str(out), "--samples", "30"])
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "for every mode;" in err[0], err
    # Without Monte Carlo samples there is nothing to warn about.
    main(["damping", str(src), "-o", str(out), "--samples", "0"])
    assert capsys.readouterr().err == ""


def test_missing_std_names_each_gap() -> None:
    from tyredamp.damping import missing_std

    f = np.array([10.0, 20.0, 30.0])
    ok = {"frequency_hz": np.ones(3), "damping_ratio": np.ones(3), "psi_out": np.ones((2, 3))}
    assert missing_std(ok, f) == ""
    some = {**ok, "damping_ratio": np.array([1.0, -1.0, np.inf])}
    assert missing_std(some, f) == "mode 2 (20 Hz): damping ratio; mode 3 (30 Hz): damping ratio"
    shp = {**ok, "psi_out": np.array([[1.0, np.nan, np.nan], [1.0, 1.0, np.nan]])}
    assert missing_std(shp, f, ["1+Z", "2+Z"]) == (
        "mode 2 (20 Hz): shape at point 1+Z; mode 3 (30 Hz): shape at every point"
    )
    nan = {k: np.full_like(v, np.nan) for k, v in ok.items()}
    assert missing_std(nan, f) == "every mode"
    assert missing_std({}, f) == ""
