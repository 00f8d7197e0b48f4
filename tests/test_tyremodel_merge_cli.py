"""``tyredamp tyre-model --merge-into``: complete property files, and hostile inputs.

The virtual tyre's modes at 2.7 and 6.5 bar (the pressures of the public Chrono truck
files, ``../shared/real-data``, CATALOGUE.md section 8) are merged into both truck files
and into the MF 6.2 file (section 9; another tyre, so with --force); every result must
read back with the identified values in the package's reader, a strict MFeval-style
reader and TyreDyn's rules (tests/tir_readers.py). Then a corpus of hostile inputs: each
exits 2 with one line and leaves no file.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tyredamp.documents.modes import write_modes_json
from tyredamp.tyremodel import parse_tir
from tyredamp.tyremodel.tir import decode_tir
from tyredamp.virtual import RingTyre, RingTyreParameters

from .badinput import check_one_error_line, run_main, snapshot
from .tir_readers import mfeval_required, mfeval_style_read, tyredyn_problems

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
CHRONO = REAL / "projectchrono_chrono" / "data" / "vehicle" / "feda" / "tires"
MF62 = REAL / "matheusft_MFeval_julia" / "test" / "fixtures" / "MagicFormula62_Parameters.tir"
PRESSURES = (2.7, 6.5)


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("tyre_lib")
    for p in PRESSURES:
        truth = RingTyre(RingTyreParameters(pressure=p * 1e5)).truth((0.0, 110.0))
        write_modes_json(d / f"m{p:g}.json", {"complex": truth.modal_model("visible")})
    return d


def need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"real-data file not found: {path}")
    return path


def test_merge_into_public_files(
    lib: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bases = [need(CHRONO / "335_65R22_5_G275MSA_40psi.tir")]
    bases += [need(CHRONO / "335_65R22_5_G275MSA_95psi.tir"), need(MF62)]
    before = {b: b.read_bytes() for b in bases}
    argv = ["tyre-model", str(lib / "m2.7.json"), str(lib / "m6.5.json"), "--pressure", "2.7,6.5"]
    argv += ["--radius", "0.5", "--attachment-mass", "0.1", "--attachment-damping", "350"]
    argv += ["--out", str(tmp_path / "out"), "--force"]
    for b in bases:
        argv += ["--merge-into", str(b)]
    code, _, err = run_main(argv, capsys)
    assert code == 0, err
    assert {b: b.read_bytes() for b in bases} == before  # the bases untouched
    rig = json.loads((tmp_path / "out" / "rigid_ring.json").read_text())["rigid_ring"]
    by_p = {round(r["pressure_bar"], 3): r for r in rig}
    for b, p in zip(bases, (2.7, 6.5, 2.7), strict=True):  # MF 6.2 base: 2.6 bar, nearest 2.7
        text = decode_tir((tmp_path / "out" / f"{b.stem}_tyredamp.tir").read_bytes())
        doc, flat = parse_tir(text), mfeval_style_read(text)
        r = by_p[p]
        for key in ("BELT_MASS", "FREQ_LONG", "DAMP_LONG"):
            # written with 7 significant digits
            assert flat[key] == pytest.approx(r[key]["value"], rel=1e-6)
            budget = r["uncertainty_budget"]
            assert budget["total"][key] >= r[key]["stderr"]  # the budget contains the noise
        assert doc["OPERATING_CONDITIONS"]["INFLPRES"] == pytest.approx(p * 1e5)
        assert mfeval_required(flat) == []  # nothing left to defaults
        base_doc = parse_tir(decode_tir(before[b]))
        assert tyredyn_problems(doc) <= tyredyn_problems(base_doc)
        assert f"m{p:g}.json at {p:g} bar" in text.splitlines()[0] + text[:4000]
        assert "assumes" in next(ln for ln in text.splitlines() if ln.startswith("DAMP_LONG"))
    mf = parse_tir((tmp_path / "out" / "MagicFormula62_Parameters_tyredamp.tir").read_text())
    assert tyredyn_problems(mf) == set()
    assert mf["OPERATING_CONDITIONS"]["NOMPRES"] == 260000.0  # the base's reference, kept
    truck = (tmp_path / "out" / "335_65R22_5_G275MSA_95psi_tyredamp.tir").read_text()
    assert parse_tir(truck)["OPERATING_CONDITIONS"]["NOMPRES"] == pytest.approx(6.5e5)
    assert "WARNING" in (tmp_path / "out" / "MagicFormula62_Parameters_tyredamp.tir").read_text()
    frag = (tmp_path / "out" / "tyre_inplane_2.7bar.tir").read_text()
    assert "FRAGMENT" in frag
    assert "[MODEL] missing" in tyredyn_problems(parse_tir(frag))


# ----------------------------------------------------------------------- hostile corpus
def _edit_modes(src: Path, dst: Path, edit: Callable[[dict[str, Any]], None]) -> None:
    doc = json.loads(src.read_text())
    edit(doc)
    dst.write_text(json.dumps(doc))


def _negative_damping(doc: dict[str, Any]) -> None:
    m = doc["models"]["complex"]["modes"][2]
    m["pole"][0] = abs(m["pole"][0])
    m["damping_ratio"] = -abs(m["damping_ratio"])


def _zero_damping(doc: dict[str, Any]) -> None:
    m = doc["models"]["complex"]["modes"][0]
    m["pole"][0] = 0.0
    m["damping_ratio"] = 0.0


def _meta(value: Any) -> Callable[[dict[str, Any]], None]:
    def edit(doc: dict[str, Any]) -> None:
        doc["pressure_bar"] = value

    return edit


BASE_OK = "[UNITS]\nMASS = 'kg'\n[DIMENSION]\nUNLOADED_RADIUS = 0.52\nRIM_RADIUS = 0.29\n"
TWO = ["a.json", "b.json", "--pressure", "2.7,6.5", "--radius", "0.5"]
CASES: list[tuple[str, list[str], dict[str, Any], str]] = [
    ("radius huge", [*TWO[:4], "--radius", "1e300"], {}, "radius"),
    ("radius zero", [*TWO[:4], "--radius", "0"], {}, "radius"),
    ("radius nan", [*TWO[:4], "--radius", "nan"], {}, "--radius: expected a finite"),
    ("radius negative", [*TWO[:4], "--radius=-1"], {}, "radius"),
    ("radius text", [*TWO[:4], "--radius", "big"], {}, "radius"),
    ("pressure text", ["a.json", "b.json", "--pressure", "x,y", "--radius", "0.5"], {}, "pressure"),
    ("pressure count", ["a.json", "b.json", "--pressure", "2.7", "--radius", "0.5"], {}, "one"),
    (
        "pressure zero",
        ["a.json", "b.json", "--pressure", "0,6.5", "--radius", "0.5"],
        {},
        "above 0",
    ),
    ("pressure huge", ["a.json", "b.json", "--pressure", "2.7,1e300", "--radius", "0.5"], {}, "20"),
    ("same pressure", ["a.json", "b.json", "--pressure", "2.7,2.7", "--radius", "0.5"], {}, "same"),
    (
        "same file three times",
        ["a.json", "a.json", "a.json", "--pressure", "2.7,4.5,6.5", "--radius", "0.5"],
        {},
        "same modes",
    ),
    ("meta pressure text", ["c.json", "--radius", "0.5"], {"c.json": _meta("7 bar")}, "number"),
    ("meta pressure list", ["c.json", "--radius", "0.5"], {"c.json": _meta([7, 8])}, "number"),
    ("meta pressure bool", ["c.json", "--radius", "0.5"], {"c.json": _meta(True)}, "number"),
    ("meta pressure huge", ["c.json", "--radius", "0.5"], {"c.json": _meta(1e300)}, "pressure"),
    ("meta pressure negative", ["c.json", "--radius", "0.5"], {"c.json": _meta(-3)}, "pressure"),
    (
        "unstable pole",
        ["c.json", "--pressure", "2.7", "--radius", "0.5"],
        {"c.json": _negative_damping},
        "unstable",
    ),
    (
        "undamped pole",
        ["c.json", "--pressure", "2.7", "--radius", "0.5"],
        {"c.json": _zero_damping},
        "undamped",
    ),
    ("attachment mass huge", [*TWO, "--attachment-mass", "1e9"], {}, "attachment-mass"),
    ("attachment mass negative", [*TWO, "--attachment-mass=-1"], {}, "attachment-mass"),
    ("attachment damping huge", [*TWO, "--attachment-damping", "1e300"], {}, "attachment-damping"),
    ("attachment damper too large", [*TWO, "--attachment-damping", "1e5"], {}, "exceeds"),
    ("mass per length zero", [*TWO, "--mass-per-length", "0"], {}, "mass-per-length"),
    ("predict huge", [*TWO, "--predict", "1e300"], {}, "predict"),
    ("predict negative", [*TWO, "--predict=-3"], {}, "predict"),
    ("force sensitivity", [*TWO, "--force-sensitivity-error", "80"], {}, "force-sensitivity"),
    (
        "accel sensitivity nan",
        [*TWO, "--acceleration-sensitivity-error", "nan"],
        {},
        "acceleration",
    ),
    ("attachment damping error", [*TWO, "--attachment-damping-error", "200"], {}, "damping-error"),
    ("lateral pressure huge", [*TWO, "--lateral-pressure", "1e300"], {}, "lateral-pressure"),
    ("merge missing base", [*TWO, "--merge-into", "nope.tir"], {}, "cannot read"),
    ("merge junk base", [*TWO, "--merge-into", "j.tir"], {"j.tir": "hello world\n"}, "line 1"),
    ("merge binary base", [*TWO, "--merge-into", "z.tir"], {"z.tir": b"[A]\x00\x01"}, "NUL"),
    (
        "merge conflicting keys",
        [*TWO, "--merge-into", "k.tir"],
        {"k.tir": "[A]\nX = 1\nX = 2\n"},
        "different",
    ),
    (
        "merge non-SI base",
        [*TWO, "--merge-into", "u.tir"],
        {"u.tir": "[UNITS]\nMASS = 'lbm'\n[OPERATING_CONDITIONS]\nNOMPRES = 270000\n"},
        "SI",
    ),
    (
        "merge base of another pressure",
        [*TWO, "--merge-into", "p.tir"],
        {"p.tir": BASE_OK + "[OPERATING_CONDITIONS]\nNOMPRES = 900000\n"},
        "--force",
    ),
    (
        "merge base of another tyre",
        [*TWO, "--merge-into", "t.tir"],
        {"t.tir": "[DIMENSION]\nUNLOADED_RADIUS = 0.3\n[OPERATING_CONDITIONS]\nNOMPRES = 270000\n"},
        "another tyre",
    ),
    (
        "merge base without pressure",
        [*TWO, "--merge-into", "n.tir"],
        {"n.tir": BASE_OK},
        "pressure",
    ),
    (
        "modes not json",
        ["x.json", "--pressure", "2.7", "--radius", "0.5"],
        {"x.json": "{not json"},
        "x.json",
    ),
]


@pytest.mark.parametrize(("name", "argv", "files", "needle"), CASES, ids=[c[0] for c in CASES])
def test_hostile_inputs(
    name: str,
    argv: list[str],
    files: dict[str, Any],
    needle: str,
    lib: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    shutil.copy(lib / "m2.7.json", tmp_path / "a.json")
    shutil.copy(lib / "m6.5.json", tmp_path / "b.json")
    for fname, content in files.items():
        if callable(content):
            _edit_modes(lib / "m2.7.json", tmp_path / fname, content)
        elif isinstance(content, bytes):
            (tmp_path / fname).write_bytes(content)
        else:
            (tmp_path / fname).write_text(content)
    monkeypatch.chdir(tmp_path)
    before = snapshot(tmp_path)
    code, _, err = run_main(["tyre-model", *argv, "--out", "out"], capsys)
    check_one_error_line(err, code, 2, needle)
    assert snapshot(tmp_path) == before  # no file written, none changed


def test_corpus_size() -> None:
    assert len(CASES) >= 25
