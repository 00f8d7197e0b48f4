"""Identified values merged into a complete ``.tir`` (``tyremodel.tirmerge.merge_tir``).

Bases: the public files of ``../shared/real-data`` (CATALOGUE.md sections 8, 9; see
test_tir_reader.py). The merged text must keep every base line but the identified ones,
read back in the package's reader, in a strict MFeval-style reader and under TyreDyn's
validation rules no worse than the base (tests/tir_readers.py).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.tyremodel import parse_tir
from tyredamp.tyremodel.tir import decode_tir
from tyredamp.tyremodel.tirmerge import TirValue, base_pressure, merge_tir

from .tir_readers import mfeval_required, mfeval_style_read, tyredyn_problems

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
BASES = {
    "chrono40": REAL / "projectchrono_chrono/data/vehicle/feda/tires/335_65R22_5_G275MSA_40psi.tir",
    "chrono95": REAL / "projectchrono_chrono/data/vehicle/feda/tires/335_65R22_5_G275MSA_95psi.tir",
    "mf62": REAL / "matheusft_MFeval_julia/test/fixtures/MagicFormula62_Parameters.tir",
}
VALUES = [
    TirValue("INERTIA", "BELT_MASS", 12.345, "+- 0.3 kg (test)"),
    TirValue("STRUCTURAL", "FREQ_LONG", 77.25, "+- 0.1 Hz"),
    TirValue("STRUCTURAL", "DAMP_LONG", 0.0321, "+- 0.004"),
    TirValue("OPERATING_CONDITIONS", "INFLPRES", 270000.0, "test pressure"),
]


def base(key: str) -> str:
    p = BASES[key]
    if not p.exists():
        pytest.skip(f"real-data file not found: {p}")
    return decode_tir(p.read_bytes(), p.name)


@pytest.mark.parametrize("key", list(BASES))
def test_merge_keeps_the_base_and_writes_the_values(key: str) -> None:
    text = base(key)
    merged = merge_tir(text, VALUES, header=["identified by a test"], name=key)
    old, new = text.splitlines(), merged.splitlines()
    # every base line is kept, in order, except the lines of the identified keys
    keys = {v.key for v in VALUES}
    kept = [ln for ln in old if ln.split("=")[0].strip() not in keys]
    it = iter(new)
    assert all(any(ln == m for m in it) for ln in kept)
    assert ("\r\n" in merged) == ("\r\n" in text)  # the base's line ends
    doc = parse_tir(merged)
    for v in VALUES:
        assert doc[v.section][v.key] == pytest.approx(v.value, rel=1e-6)  # written with 7 digits
    flat = mfeval_style_read(merged)
    assert flat["BELT_MASS"] == pytest.approx(12.345, rel=1e-6)  # 7 significant digits
    assert flat["FREQ_LONG"] == pytest.approx(77.25, rel=1e-6)
    # no new TyreDyn problem: the merge only adds what the base lacked
    assert tyredyn_problems(doc) <= tyredyn_problems(parse_tir(text))
    before = parse_tir(text)
    for v in VALUES:  # the old value in the comment
        old_v = before.get(v.section, {}).get(v.key)
        line = next(ln for ln in new if ln.split("=")[0].strip() == v.key)
        if old_v is not None:
            assert f"base value {old_v:.7g}" in line
        assert v.comment in line


def test_mf62_merged_passes_tyredyn_and_mfeval() -> None:
    text = base("mf62")
    assert tyredyn_problems(parse_tir(text)) == set()  # the base itself passes
    merged = merge_tir(text, VALUES, header=["h"], name="mf62")
    assert tyredyn_problems(parse_tir(merged)) == set()
    flat = mfeval_style_read(merged)
    assert mfeval_required(flat) == []
    assert flat["DAMP_LONG"] == pytest.approx(0.0321, rel=1e-6)
    assert flat["NOMPRES"] == 260000.0  # kept: the base's pressure coefficients refer to it


def test_chrono_base_fails_tyredyn_without_the_merge() -> None:
    # the MF-Tyre 5.0 truck file lacks [OPERATING_CONDITIONS], [INERTIA], [STRUCTURAL]: the
    # merge adds them, so those problems go away
    doc = parse_tir(base("chrono40"))
    probs = tyredyn_problems(doc)
    assert "[INERTIA] missing" in probs
    merged = parse_tir(merge_tir(base("chrono40"), VALUES, header=["h"]))
    assert "[INERTIA] missing" not in tyredyn_problems(merged)


def test_merge_adds_keys_and_sections_in_place() -> None:
    text = "[MDI_HEADER]\nFILE_TYPE = 'tir'\n[STRUCTURAL]\nFREQ_LAT = 40\n\n[MODEL]\nFITTYP = 62\n"
    merged = merge_tir(text, VALUES[:2], header=["line one", "line two"])
    assert merged.splitlines() == [
        "[MDI_HEADER]",
        "FILE_TYPE = 'tir'",
        "$ line one",
        "$ line two",
        "[STRUCTURAL]",
        "FREQ_LAT = 40",
        "FREQ_LONG                = 77.25          $ +- 0.1 Hz",
        "",
        "[MODEL]",
        "FITTYP = 62",
        "$------------------------------------------------inertia (tyredamp)",
        "[INERTIA]",
        "BELT_MASS                = 12.345         $ +- 0.3 kg (test)",
    ]


def test_merge_replaces_a_key_in_every_section_it_is_in() -> None:
    # a key in another section and a repeated section: a reader of keys alone must agree
    text = "[INERTIA]\nMASS = 9\n[STRUCTURAL]\nBELT_MASS = 7 $ misplaced\n[INERTIA]\nIXX = 1\n"
    merged = merge_tir(text, VALUES[:1], header=[])
    flat = mfeval_style_read(merged)
    assert flat["BELT_MASS"] == pytest.approx(12.345, rel=1e-6)
    assert parse_tir(merged)["STRUCTURAL"]["BELT_MASS"] == pytest.approx(12.345, rel=1e-6)


def test_merge_refusals() -> None:
    with pytest.raises(InputError, match="SI"):
        merge_tir("[UNITS]\nMASS = 'lbm'\n", VALUES, header=[], name="b.tir")
    with pytest.raises(InputError, match="finite"):
        merge_tir("[A]\nX = 1\n", [TirValue("A", "Y", float("nan"))], header=[])
    with pytest.raises(InputError, match="twice"):
        merge_tir("[A]\nX = 1\n", [VALUES[0], VALUES[0]], header=[])
    with pytest.raises(FileFormatError, match=r"b\.tir: \.tir line 2"):
        merge_tir("[A]\nnot a line\n", VALUES, header=[], name="b.tir")


def test_base_pressure_units() -> None:
    assert base_pressure({"OPERATING_CONDITIONS": {"NOMPRES": 220000.0}}) == 220000.0
    assert base_pressure({"GOODYEAR": {"INFLATION_PRESSURE": 2.7}}) == pytest.approx(2.7e5)
    assert base_pressure({"X": {"INFLATION_PRESSURE": 95.0}}) is None  # psi or kPa: ambiguous
    assert base_pressure({"TIRE_CONDITIONS": {"IP": "high"}}) is None
