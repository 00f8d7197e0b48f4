"""The ``.tir`` reader on public property files and on the format's corner cases.

Real files (``../shared/real-data``, CATALOGUE.md sections 8 and 9):

* ``projectchrono_chrono/data/vehicle/feda/tires/335_65R22_5_G275MSA_{40,95}psi.tir``
  -- Goodyear 335/65R22.5 truck tyre, MF-Tyre 5.0 (Project Chrono, BSD-3-Clause,
  commit 7689fbc0): ``!`` header, ``[SHAPE]`` rows without column names,
  ``{pen fz}`` curves, CRLF line ends;
* ``matheusft_MFeval_julia/test/fixtures/MagicFormula62_Parameters.tir`` -- MF 6.2
  (MIT).

Verbatim excerpts of other public files are in the tests below with their source.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tyredamp.exceptions import FileFormatError
from tyredamp.tyremodel import parse_tir
from tyredamp.tyremodel.tir import decode_tir, scan_tir
from tyredamp.tyremodel.tirmerge import base_pressure

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
CHRONO = REAL / "projectchrono_chrono" / "data" / "vehicle" / "feda" / "tires"
MF62 = REAL / "matheusft_MFeval_julia" / "test" / "fixtures" / "MagicFormula62_Parameters.tir"


def real(path: Path) -> str:
    if not path.exists():
        pytest.skip(f"real-data file not found: {path}")
    return decode_tir(path.read_bytes(), path.name)


@pytest.mark.parametrize(
    ("name", "stiffness", "fnomin", "bar"),
    [
        # CATALOGUE.md section 8: VERTICAL_STIFFNESS 406.5 / 848.6 kN/m, FNOMIN 16.9 / 29.9 kN
        ("335_65R22_5_G275MSA_40psi.tir", 4.0652e5, 16929.0, 2.7),
        ("335_65R22_5_G275MSA_95psi.tir", 8.4855e5, None, 6.5),
    ],
)
def test_chrono_truck_files(name: str, stiffness: float, fnomin: float | None, bar: float) -> None:
    doc = parse_tir(real(CHRONO / name))
    assert doc["VERTICAL"]["VERTICAL_STIFFNESS"] == stiffness
    if fnomin is not None:
        assert doc["VERTICAL"]["FNOMIN"] == fnomin
    assert doc["MODEL"]["PROPERTY_FILE_FORMAT"] == "MF_05"
    assert doc["DIMENSION"]["RIM_RADIUS"] == 0.2858
    # [SHAPE]: ten rows of (radial, width) without a {column} line; the last is 0.90 1.00
    assert len(doc["SHAPE"]["_rows"]) == 10
    assert doc["SHAPE"]["_rows"][-1] == [0.9, 1.0]
    assert "_columns" not in doc["SHAPE"]
    # {pen fz} curves: the bottoming curve's three rows, the deflection-load curve's columns
    assert doc["BOTTOMING_CURVE"] == {
        "_columns": ["pen", "fz"],
        "_rows": [[0.0, 0.0], [0.10546, 0.0], [0.30546, 563080.0]],
    }
    assert doc["DEFLECTION_LOAD_CURVE"]["_columns"] == ["pen", "fz"]
    assert doc["GOODYEAR"]["TEST_DEVICE"] == "CALSPAN"
    assert doc["GOODYEAR"]["TEST_NUMBER"] == ""  # an empty quoted string
    assert base_pressure(doc) == pytest.approx(bar * 1e5, rel=1e-12)  # [GOODYEAR], in bar


def test_mf62_file() -> None:
    doc = parse_tir(real(MF62))
    # CATALOGUE.md section 9: 21 sections; FREQ_LONG 80 Hz, DAMP_* 0.04, 2.6 bar
    assert len(doc) == 21
    assert doc["MODEL"]["FITTYP"] == 62.0
    assert doc["STRUCTURAL"]["FREQ_LONG"] == 80.0
    assert doc["STRUCTURAL"]["DAMP_LONG"] == 0.04
    assert doc["INERTIA"]["BELT_MASS"] == 7.0
    assert doc["VERTICAL"]["VERTICAL_STIFFNESS"] == 314931.2969
    assert base_pressure(doc) == 260000.0  # NOMPRES in Pa


# Verbatim excerpt of Project Chrono data/vehicle/citybus/tire/CityBus_Pac02Tire.tir
# (commit 7689fbc0, BSD-3-Clause): PAC2002 with the pressure in [TIRE_CONDITIONS].
CITYBUS = """$-------------------------------------------------------------------------info
! 315/80 R 22.5 ADAMS/Car example for a typical truck tire (Pacejka Book)
$-------------------------------------------------------------------------units
[UNITS]
LENGTH                     = 'meter'
FORCE                      = 'newton'
ANGLE                      = 'radian'
MASS                       = 'kg'
TIME                       = 'second'
PRESSURE                   = 'pascal'             $Chosen by TDFT. Please check if it is correct.
$-------------------------------------------------------------------------model
[MODEL]
PROPERTY_FILE_FORMAT       = 'PAC2002'            $Tire property type
USE_MODE                   = 4                    $Tyre use switch (IUSED)
$---------------------------------------------------------------tire_conditions
[TIRE_CONDITIONS]
IP                         = 800000               $Inflation Pressure
IP_NOM                     = 800000               $Nominal Inflation Pressure
"""

# Verbatim excerpt of Project Chrono data/vehicle/VW_microbus/json/mf_185_80R14.tir
# (commit 7689fbc0, BSD-3-Clause): "! : KEY : value" comment lines, no blank after "=".
MICROBUS = """[MDI_HEADER]
FILE_TYPE                ='tir'
FILE_VERSION             =3.0
FILE_FORMAT              ='ASCII'
! : TIRE_VERSION :      PAC2002
! : COMMENT :           Tire                    185/80 R14
! : COMMENT :           Infl. pressure    (Pa)  190000
"""


def test_public_excerpts() -> None:
    bus = parse_tir(CITYBUS)
    assert bus["MODEL"]["PROPERTY_FILE_FORMAT"] == "PAC2002"
    assert bus["UNITS"]["PRESSURE"] == "pascal"
    assert base_pressure(bus) == 800000.0  # IP_NOM
    bus_doc = parse_tir(MICROBUS)
    assert bus_doc == {
        "MDI_HEADER": {"FILE_TYPE": "tir", "FILE_VERSION": 3.0, "FILE_FORMAT": "ASCII"}
    }


def test_format_corner_cases() -> None:
    text = (
        "\ufeff[MDI_HEADER]\r\n"
        'FILE_TYPE = "tir"  ! a comment after a double-quoted string\r\n'
        "[ model ]\r\n"  # spaces inside the brackets, lower case
        "FITTYP = 62\r\n"
        "COMMENT = 'a $ and a ! inside quotes'  $ then a comment\r\n"
        "[STRUCTURAL]\r\n"
        "FREQ_LONG = 8.0D+01\r\n"  # a Fortran exponent
        "[MODEL]\r\n"  # the section again: read as one
        "USE_MODE = 124\r\n"
        "FITTYP = 62   $ repeated with the same value: read once\r\n"
        "[SHAPE]\r\n"
        "{radial width}\r\n"
        " 1.00 , 0.00\r\n"  # comma-separated row
    )
    doc = parse_tir(text)
    assert doc["MDI_HEADER"] == {"FILE_TYPE": "tir"}
    assert doc["MODEL"] == {
        "FITTYP": 62.0,
        "COMMENT": "a $ and a ! inside quotes",
        "USE_MODE": 124.0,
    }
    assert doc["STRUCTURAL"]["FREQ_LONG"] == 80.0
    assert doc["SHAPE"] == {"_columns": ["radial", "width"], "_rows": [[1.0, 0.0]]}
    kinds = [ln.kind for ln in scan_tir(text)]
    assert kinds.count("section") == 5
    assert kinds.count("row") == 1


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("[A]\nX = 1\nX = 2\n", "different value"),
        ("X = 1\n", "before any"),
        ("[A]\nthis is not a tir line\n", "line 2"),
        ("[A]\nX = 'open\n", "unterminated"),
        ("[A]\nX =\n", "without a value"),
        ("$ only a comment\n", "no \\[SECTION\\]"),
        ("1.0 2.0\n", "line 1"),
    ],
)
def test_reader_refuses(text: str, match: str) -> None:
    with pytest.raises(FileFormatError, match=match):
        parse_tir(text)


def test_decode() -> None:
    assert decode_tir("[A]\nX = 'é'\n".encode("latin-1")) == "[A]\nX = 'é'\n"
    assert decode_tir(b"\xef\xbb\xbf[A]\n") == "[A]\n"
    with pytest.raises(FileFormatError, match="NUL"):
        decode_tir(b"[A]\x00\n", "x.tir")
