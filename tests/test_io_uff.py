"""UFF 58 interoperability with pyuff and corrupt/truncated/garbage files."""

from __future__ import annotations

import gc
import warnings
from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import FileFormatError
from tyredamp.io import read, read_frf, read_timedata, write_frf, write_timedata

from .test_io_roundtrip import sample_frf, sample_timedata


def write_foreign(path: Path, sets: list[dict]) -> None:
    """Write data sets with pyuff directly, as another program would."""
    with warnings.catch_warnings():
        # pyuff's 58b writer leaves a file handle to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        uff = pyuff.UFF(str(path))
        for d in sets:
            uff._write_set(d, "add")
        gc.collect()


def foreign_frf_sets(binary: int, units: tuple[str, str] = ("m/s^2", "N")) -> tuple[list, dict]:
    f = np.arange(0, 201) * 0.5
    rng = np.random.default_rng(0)
    truth = {}
    sets = []
    for rsp in (11, 12):
        h = rng.normal(size=f.size) + 1j * rng.normal(size=f.size)
        truth[rsp] = h
        sets.append(
            pyuff.prepare_58(
                binary=binary,
                func_type=4,
                id1="Shaker test",
                rsp_node=rsp,
                rsp_dir=3,
                ref_node=1,
                ref_dir=3,
                rsp_ent_name="tyre",
                ref_ent_name="tyre",
                data=h,
                x=f,
                abscissa_spacing=1,
                abscissa_spec_data_type=18,
                ordinate_spec_data_type=12,
                orddenom_spec_data_type=13,
                ordinate_axis_units_lab=units[0],
                orddenom_axis_units_lab=units[1],
            )
        )
    return sets, {"f": f, "H": truth}


@pytest.mark.parametrize("binary", [0, 1])
def test_read_frf_written_by_pyuff(tmp_path: Path, binary: int) -> None:
    sets, truth = foreign_frf_sets(binary)
    write_foreign(tmp_path / "other.uff", sets)
    frf = read_frf(tmp_path / "other.uff")
    assert frf.kind == "accelerance"  # ordinate type 12 over denominator type 13
    assert [(c.node, c.direction) for c in frf.outputs] == [(11, 3), (12, 3)]
    assert [(c.node, c.direction) for c in frf.inputs] == [(1, 3)]
    # even abscissa from record 7 (E13.5: 0 and 0.5 are exact); values E20.12
    assert_array_equal(frf.frequency, truth["f"])
    rtol = 0.0 if binary else 1e-11
    assert_allclose(frf.H[0, 0], truth["H"][11], rtol=rtol)
    assert_allclose(frf.H[1, 0], truth["H"][12], rtol=rtol)
    assert frf.meta["description"] == "Shaker test"


def test_foreign_units_are_converted_to_si(tmp_path: Path) -> None:
    sets, truth = foreign_frf_sets(0, units=("g", "kN"))
    write_foreign(tmp_path / "g.uff", sets)
    frf = read_frf(tmp_path / "g.uff")
    # g/kN -> (m/s^2)/N: times 9.80665 / 1000
    assert_allclose(frf.H[0, 0], truth["H"][11] * 9.80665e-3, rtol=1e-11)
    sets, truth = foreign_frf_sets(0, units=("(m/s^2)/N", "NONE"))
    for d in sets:
        d["ordinate_spec_data_type"] = 0  # unknown type: the label tells the kind
    write_foreign(tmp_path / "lab.uff", sets)
    assert read_frf(tmp_path / "lab.uff").kind == "accelerance"
    sets, _ = foreign_frf_sets(0, units=("furlong", "N"))
    write_foreign(tmp_path / "bad.uff", sets)
    with pytest.raises(FileFormatError, match="units label 'furlong': unknown unit 'furlong'"):
        read_frf(tmp_path / "bad.uff")


def test_read_timedata_written_by_pyuff(tmp_path: Path) -> None:
    fs = 2048.0
    rng = np.random.default_rng(1)
    t = np.arange(4096) / fs
    sets, rows = [], []
    for node, sdt in ((1, 13), (2, 12), (3, 12)):
        y = rng.normal(size=t.size)
        rows.append(y)
        sets.append(
            pyuff.prepare_58(
                binary=0,
                func_type=1,
                rsp_node=node,
                rsp_dir=3,
                ref_node=0,
                ref_dir=0,
                data=y,
                x=t,
                abscissa_spacing=1,
                abscissa_spec_data_type=17,
                ordinate_spec_data_type=sdt,
                orddenom_spec_data_type=0,
            )
        )
    write_foreign(tmp_path / "time.uff", sets)
    td = read_timedata(tmp_path / "time.uff")
    # the increment 4.88281e-04 (E13.5) stands for 1/2048: snapped to the integer rate
    assert td.sample_rate == fs
    assert td.quantities == ("force", "acceleration", "acceleration")
    assert_allclose(td.data, np.array(rows), rtol=1e-11)


def test_our_files_read_back_in_pyuff(tmp_path: Path) -> None:
    rng = np.random.default_rng(2)
    frf = sample_frf(rng, n_out=2, n_in=1)
    for fmt, name in (("uff58b", "b.uff"), ("uff58", "a.unv")):
        sets = pyuff.UFF(str(write_frf(frf, tmp_path / name, fmt))).read_sets()
        h = [s for s in sets if s["func_type"] == 4]
        coh = [s for s in sets if s["func_type"] == 6]
        assert [(s["rsp_node"], s["rsp_dir"], s["ref_node"], s["ref_dir"]) for s in h] == [
            (1, 3, 100, 3),
            (2, 3, 100, 3),
        ]
        for s in h:
            assert s["ordinate_spec_data_type"] == 12  # acceleration
            assert s["orddenom_spec_data_type"] == 13  # excitation force
            assert s["abscissa_spec_data_type"] == 18  # frequency
            assert s["ordinate_axis_units_lab"] == "m/s^2"
        rtol = 0.0 if fmt == "uff58b" else 1e-11
        assert_allclose(h[1]["data"], frf.H[1, 0], rtol=rtol)
        assert_allclose(h[1]["x"], frf.frequency, rtol=1e-5)  # E13.5 abscissa for ASCII
        assert_allclose(coh[0]["data"], frf.coherence[0], rtol=rtol)
    td = sample_timedata(rng)
    sets = pyuff.UFF(str(write_timedata(td, tmp_path / "t.uff"))).read_sets()
    assert [s["ordinate_spec_data_type"] for s in sets] == [13, 12, 11, 8]
    assert_array_equal(sets[2]["data"], td.data[2])
    assert sets[0]["abscissa_inc"] == pytest.approx(1 / 2048.0, rel=1e-5)


# ----------------------------------------------------------- bad files
def test_empty_garbage_truncated_corrupt(tmp_path: Path) -> None:
    empty = tmp_path / "empty.uff"
    empty.write_bytes(b"")
    with pytest.raises(FileFormatError, match="empty file"):
        read_frf(empty)
    garbage = tmp_path / "garbage.uff"
    garbage.write_bytes(np.random.default_rng(0).bytes(5000))
    with pytest.raises(FileFormatError, match=r"garbage\.uff"):
        read(garbage)
    text = tmp_path / "text.uff"
    text.write_text("hello\nworld\n")
    with pytest.raises(FileFormatError, match="no UFF data set"):
        read(text)

    good = write_frf(sample_frf(np.random.default_rng(3)), tmp_path / "good.unv", "uff58")
    raw = good.read_bytes()
    cut = tmp_path / "cut.unv"
    cut.write_bytes(raw[: len(raw) - 500])
    with pytest.raises(FileFormatError, match=r"cut\.unv: truncated"):
        read_frf(cut)
    binary = write_frf(sample_frf(np.random.default_rng(3)), tmp_path / "good.uff")
    raw_b = binary.read_bytes()
    cut_b = tmp_path / "cut_b.uff"
    cut_b.write_bytes(raw_b[: len(raw_b) // 2])
    with pytest.raises(FileFormatError, match=r"cut_b\.uff"):
        read_frf(cut_b)
    # a data line removed in the middle: the count in record 7 no longer matches
    lines = raw.decode().splitlines(keepends=True)
    del lines[20]
    short = tmp_path / "short.unv"
    short.write_text("".join(lines))
    with pytest.raises(FileFormatError, match=r"short\.unv: data set #1 is corrupt or truncated"):
        read_frf(short)
    # a header line garbled
    lines = raw.decode().splitlines(keepends=True)
    lines[8] = "    XX   garbage in record seven" + " " * 48 + "\n"
    bad = tmp_path / "bad.unv"
    bad.write_text("".join(lines))
    with pytest.raises(FileFormatError, match=r"bad\.unv"):
        read_frf(bad)


def test_incomplete_matrix_and_unequal_channels(tmp_path: Path) -> None:
    sets, _ = foreign_frf_sets(0)
    sets[1]["ref_node"] = 2  # response 12 has a reference 2, response 11 reference 1
    write_foreign(tmp_path / "inc.uff", sets)
    with pytest.raises(FileFormatError, match="incomplete FRF matrix"):
        read_frf(tmp_path / "inc.uff")
    t = np.arange(100) / 100.0
    write_foreign(
        tmp_path / "uneq.uff",
        [
            pyuff.prepare_58(
                binary=0,
                func_type=1,
                rsp_node=1,
                rsp_dir=3,
                ref_node=0,
                ref_dir=0,
                data=np.ones(t.size),
                x=t,
                abscissa_spacing=1,
                abscissa_spec_data_type=17,
                ordinate_spec_data_type=13,
                orddenom_spec_data_type=0,
            ),
            pyuff.prepare_58(
                binary=0,
                func_type=1,
                rsp_node=2,
                rsp_dir=3,
                ref_node=0,
                ref_dir=0,
                data=np.ones(t.size - 10),
                x=t[:-10],
                abscissa_spacing=1,
                abscissa_spec_data_type=17,
                ordinate_spec_data_type=12,
                orddenom_spec_data_type=0,
            ),
        ],
    )
    with pytest.raises(FileFormatError, match="channels must have equal length"):
        read_timedata(tmp_path / "uneq.uff")


def test_non_increasing_frequency_and_nan_in_csv(tmp_path: Path) -> None:
    frf = sample_frf(np.random.default_rng(4))
    p = write_frf(frf, tmp_path / "f.csv")
    lines = p.read_text().splitlines()
    i = next(k for k, s in enumerate(lines) if s.startswith("frequency_Hz"))
    lines[i + 3], lines[i + 4] = lines[i + 4], lines[i + 3]  # two rows swapped
    (tmp_path / "swap.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(
        FileFormatError, match=r"swap\.csv: frequency: expected strictly increasing"
    ):
        read_frf(tmp_path / "swap.csv")
    td = sample_timedata(np.random.default_rng(5))
    p = write_timedata(td, tmp_path / "t.csv")
    lines = p.read_text().splitlines()
    lines[-3] = lines[-3].rsplit(",", 1)[0] + ",nan"
    (tmp_path / "nan.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError, match=r"nan\.csv: data: expected finite values"):
        read_timedata(tmp_path / "nan.csv")
    lines = p.read_text().splitlines()
    lines[-2] = lines[-2].rsplit(",", 1)[0]  # a row one value short
    (tmp_path / "short.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError, match=r"short\.csv: bad data row"):
        read_timedata(tmp_path / "short.csv")
    (tmp_path / "plain.csv").write_text("a,b\n1,2\n")
    with pytest.raises(FileFormatError, match="fewer than 2 data rows"):
        read(tmp_path / "plain.csv")
    npz = write_frf(frf, tmp_path / "f.npz")
    (tmp_path / "cut.npz").write_bytes(npz.read_bytes()[:200])
    with pytest.raises(FileFormatError, match=r"cut\.npz"):
        read(tmp_path / "cut.npz")


@pytest.mark.parametrize(
    ("num", "den", "factor"),
    [
        ("(1/N)*(m/s²)", "NONE", 1.0),
        ("m/s2", "N", 1.0),
        ("m/s²", "N", 1.0),
        ("(m/s^2)/N", "", 1.0),
        ("g/N", "NONE", 9.80665),
        ("m/s2/N", "NONE", 1.0),
        ("mm/s/N", "NONE", 1e-3),
    ],
)
@pytest.mark.parametrize("binary", [0, 1])
def test_vendor_units_labels(
    tmp_path: Path, num: str, den: str, factor: float, binary: int
) -> None:
    """FRF labels of real exports (superscripts, whole ratios) read to SI."""
    sets, truth = foreign_frf_sets(binary, units=(num, den))
    for d in sets:
        d["ordinate_spec_data_type"] = 0  # the label alone tells the kind
    write_foreign(tmp_path / "v.uff", sets)
    frf = read_frf(tmp_path / "v.uff")
    assert frf.kind == ("mobility" if num.startswith("mm/s/") else "accelerance")
    assert_allclose(frf.H[0, 0], truth["H"][11] * factor, rtol=1e-11)
