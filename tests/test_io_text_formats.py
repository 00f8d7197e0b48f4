"""Plain CSV, LVM, MATLAB and WAV readers; header text in legacy encodings (cp1252 / Latin-1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyuff
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import FRF, FileFormatError
from tyredamp.io import ChannelMap, read, read_frf, read_timedata, write_timedata
from tyredamp.io.plain_csv import split_column_name
from tyredamp.timedata import TimeData

from .test_io_roundtrip import sample_timedata
from .test_io_uff import foreign_frf_sets, write_foreign

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"

G = 9.80665


def _signals(n: int = 64) -> np.ndarray:
    rng = np.random.default_rng(3)
    return rng.normal(size=(3, n))


@pytest.mark.parametrize(
    ("text", "name", "unit"),
    [
        ("acc1_m/s2", "acc1", "m/s2"),
        ("acc1 [m/s^2]", "acc1", "m/s^2"),
        ("F (N)", "F", "N"),
        ("Kraft / kN", "Kraft", "kN"),
        ("time_s", "time", "s"),
        ("m_1", "m_1", ""),
        ("F", "F", ""),
        ("Beschleunigung (m/s²)", "Beschleunigung", "m/s²"),
        ("mic_Pa", "mic", "Pa"),
    ],
)
def test_column_names(text: str, name: str, unit: str) -> None:
    assert split_column_name(text) == (name, unit)


def _write(path: Path, lines: list[str], encoding: str = "utf-8") -> Path:
    path.write_bytes("\n".join(lines).encode(encoding) + b"\n")
    return path


@pytest.mark.parametrize(
    ("delim", "dec", "encoding"),
    [(",", ".", "utf-8"), (";", ",", "cp1252"), ("\t", ",", "utf-8"), ("\t", ".", "cp1252")],
)
def test_plain_csv_layouts(tmp_path: Path, delim: str, dec: str, encoding: str) -> None:
    x = _signals()
    fs = 512.0
    head = delim.join(["Zeit (s)", "Kraft [N]", "Beschleunigung (m/s²)", "acc2_g"])
    rows = [
        delim.join(f"{v:.9f}".replace(".", dec) for v in (k / fs, *x[:, k]))
        for k in range(x.shape[1])
    ]
    p = _write(tmp_path / "export.csv", ["Prüfstand 3, Messung 7", head, *rows], encoding)
    td = read_timedata(p)
    assert td.sample_rate == fs
    assert [c.name for c in td.channels] == ["Kraft", "Beschleunigung", "acc2"]
    assert td.quantities == ("force", "acceleration", "acceleration")
    # 9 decimals printed: equal to that precision; g converted to m/s^2
    assert_allclose(td.data, x * np.array([[1], [1], [G]]), rtol=0, atol=5e-9 * G)
    assert td.meta.get("preamble") == ["Prüfstand 3, Messung 7"]
    if encoding == "cp1252":
        assert td.meta["text_encoding"] == "cp1252"
    else:
        assert "text_encoding" not in td.meta


def test_aligned_text_table(tmp_path: Path) -> None:
    x = _signals(8).tolist()
    rows = [f"  {k / 100:10.4f}  {x[0][k]!r:>24}  {x[1][k]!r:>24}" for k in range(8)]
    td = read_timedata(_write(tmp_path / "t.txt", ["   t [s]     F [N]    a [m/s^2]", *rows]))
    assert td.sample_rate == 100.0
    assert_array_equal(td.data, [x[0], x[1]])


def test_plain_csv_problems(tmp_path: Path) -> None:
    x = _signals(8)
    rows = [f"{k / 100},{x[0, k]},{x[1, k]}" for k in range(8)]
    p = _write(tmp_path / "a.csv", ["time_s,F,acc", *rows])
    with pytest.raises(FileFormatError, match=r"'F', 'acc' measure.*--channel 'F=force:N'"):
        read_timedata(p)
    td = read_timedata(p, ChannelMap.parse(["F=force:N", "acc=acceleration:g"]))
    assert_allclose(td.data[1], x[1] * G, rtol=1e-15)  # g to m/s^2, exact product
    uneven = [f"{k / 100 + (0.003 if k == 5 else 0)},{x[0, k]},{x[1, k]}" for k in range(8)]
    with pytest.raises(FileFormatError, match="time column is not evenly spaced"):
        read_timedata(_write(tmp_path / "b.csv", ["time_s,F_N,acc_g", *uneven]))
    notime = [f"{x[0, k]},{x[1, k]}" for k in range(8)]
    with pytest.raises(FileFormatError, match=r"is not a time .* or a frequency"):
        read_timedata(_write(tmp_path / "c.csv", ["F_N,acc_g", *notime]))
    # a last row cut short by an interrupted export is left out, and said so
    cut = _write(tmp_path / "d.csv", ["time_s,F_N,acc_g", *rows, "0.08,1.0"])
    td = read_timedata(cut)
    assert td.n_samples == 8
    assert "last row is incomplete" in td.meta["read_notes"][0]


def test_plain_csv_with_a_units_row(tmp_path: Path) -> None:
    x = _signals(8)
    xs = x.tolist()
    rows = [f"{k / 100};{xs[0][k]!r};{xs[1][k]!r}".replace(".", ",") for k in range(8)]
    p = _write(tmp_path / "u.csv", ["Messung 7", "Zeit;Kraft;Beschl.", "[s];[kN];[g]", *rows])
    td = read_timedata(p)
    assert [c.name for c in td.channels] == ["Kraft", "Beschl."]
    assert_allclose(td.data, [x[0] * 1e3, x[1] * G], rtol=1e-15)  # kN and g to SI
    assert td.meta["preamble"] == ["Messung 7"]


@pytest.mark.parametrize(
    ("line", "fs"),
    [("Sample rate: 1024 Hz", 1024.0), ("Abtastrate;2,56;kHz", 2560.0), ("dt = 0.5 ms", 2000.0)],
)
def test_plain_csv_without_time_column_but_a_stated_rate(
    tmp_path: Path, line: str, fs: float
) -> None:
    x = _signals(8).tolist()
    rows = [f"{x[0][k]!r};{x[1][k]!r}" for k in range(8)]
    td = read_timedata(_write(tmp_path / "r.csv", [line, "F [N];a [g]", *rows]))
    assert td.sample_rate == fs
    assert_array_equal(td.data[0], x[0])
    assert any("sample rate" in n for n in td.meta["read_notes"])


def test_plain_csv_frf(tmp_path: Path) -> None:
    f = np.arange(1, 33) * 2.0
    h = (1 + 1j * f) / (100 - f**2 + 2j * f)
    rows = [
        f"{fk!r};{hk.real!r};{hk.imag!r};{abs(hk)!r};{float(np.degrees(np.angle(hk)))!r};0.99"
        for fk, hk in zip(f.tolist(), h.tolist(), strict=True)
    ]
    head = "Frequency [Hz];H1.re [g/N];H1.im [g/N];H2 mag [g/N];H2 phase [deg];coh H1"
    p = _write(tmp_path / "frf.csv", [head, *rows])
    with pytest.raises(FileFormatError, match="expected 2 coherence"):
        read_frf(p)
    rows = [r.rsplit(";", 1)[0] for r in rows]
    p = _write(tmp_path / "frf.csv", [head.rsplit(";", 1)[0], *rows])
    frf = read_frf(p)
    assert frf.kind == "accelerance"
    assert_array_equal(frf.frequency, f)
    assert_allclose(frf.H[0, 0], h * G, rtol=1e-15)  # re/im: exact up to the g factor
    assert_allclose(frf.H[1, 0], h * G, rtol=1e-12)  # magnitude/phase through degrees
    body = [f"{a!r},{b.real!r},{b.imag!r}" for a, b in zip(f.tolist(), h.tolist(), strict=True)]
    nounit = _write(tmp_path / "n.csv", ["f_Hz,H.re,H.im", *body])
    with pytest.raises(FileFormatError, match=r"--channel 'H=acceleration:m/s\^2/N'"):
        read_frf(nounit)
    assert read_frf(nounit, channel_map=ChannelMap.parse(["H=velocity:m/s/N"])).kind == "mobility"


def test_tyredamp_csv_still_reads(tmp_path: Path) -> None:
    td = sample_timedata(np.random.default_rng(0))
    back = read_timedata(write_timedata(td, tmp_path / "t.csv"))
    assert_array_equal(back.data, td.data)
    with pytest.raises(Exception, match="a channel map is not used"):
        read_timedata(tmp_path / "t.csv", ChannelMap.parse(["1=force"]))


def test_uff_header_in_cp1252(tmp_path: Path) -> None:
    fs, n = 1000.0, 32
    y = np.sin(np.arange(n))
    d = pyuff.prepare_58(
        binary=0,
        func_type=1,
        id1="Beschleunigung Ü",
        rsp_node=1,
        rsp_dir=3,
        ref_node=0,
        ref_dir=0,
        data=y,
        x=np.arange(n) / fs,
        abscissa_spacing=1,
        abscissa_spec_data_type=17,
        ordinate_spec_data_type=0,
        orddenom_spec_data_type=0,
        ordinate_axis_units_lab="m/s²",
    )
    p = tmp_path / "vendor.uff"
    write_foreign(p, [d])
    raw = p.read_bytes()
    # as Windows software writes it: cp1252, one byte per character (padded to keep columns)
    raw = raw.replace("m/s²".encode(), "m/s²".encode("cp1252") + b" ")
    raw = raw.replace("Ü".encode(), "Ü".encode("cp1252") + b" ")
    p.write_bytes(raw)
    assert b"\xc2" not in raw
    td = read_timedata(p)
    assert td.quantities == ("acceleration",)
    assert td.meta["text_encoding"] == "cp1252"
    assert td.meta["description"] == "Beschleunigung Ü"
    assert_allclose(td.data[0], y, rtol=1e-11)  # ASCII UFF: 12 significant digits


def test_lvm_written_here(tmp_path: Path) -> None:
    lines = [
        "LabVIEW Measurement\t",
        "Writer_Version\t2",
        "Reader_Version\t2",
        "Separator\tTab",
        "Decimal_Separator\t,",
        "Multi_Headings\tNo",
        "X_Columns\tNo",
        "Operator\tMüller",
        "***End_of_Header***\t",
        "\t",
        "Channels\t2\t",
        "Samples\t4\t4\t",
        "Y_Unit_Label\tV\tm/s²\t",
        "X_Dimension\tTime\tTime\t",
        "X0\t0,0E+0\t0,0E+0\t",
        "Delta_X\t0,001\t0,001\t",
        "***End_of_Header***\t\t",
        "X_Value\tHammer\tAcc\tComment",
        "\t0,5\t1,25",
        "\t-0,5\t2,5",
        "\t0,25\t-1,0",
        "\t0,0\t0,125",
    ]
    p = _write(tmp_path / "t.lvm", lines, "cp1252")
    td = read_timedata(p)
    assert td.quantities == ("voltage", "acceleration")
    assert td.meta["text_encoding"] == "cp1252"
    assert td.meta["operator"] == "Müller"
    assert td.sample_rate == 1000.0
    td = read_timedata(p, ChannelMap.parse([], ["Hammer=2 mV/N"]))
    assert_allclose(td.data[0], np.array([0.5, -0.5, 0.25, 0.0]) / 2e-3, rtol=1e-15)
    assert_array_equal(td.data[1], [1.25, 2.5, -1.0, 0.125])


def test_lvm_damaged_header_is_refused_in_one_line(tmp_path: Path) -> None:
    """A header line lost (the decimal separator's) turns lvm_read's fields into tuples."""
    src = REAL / "ladisk_lvm_read" / "data" / "short.lvm"
    if not src.is_file():
        pytest.skip("real-data gallery not found")
    lines = src.read_bytes().split(b"\n")
    assert lines[4].startswith(b"Decimal_Separator")
    lines[4] = b"1,2,3,4,5,6,7,8,9"
    p = tmp_path / "short.lvm"
    p.write_bytes(b"\n".join(lines))
    with pytest.raises(FileFormatError, match="segment 1: header or data not readable"):
        read_timedata(p)


def test_mat_variants(tmp_path: Path) -> None:
    from scipy.io import savemat

    x = _signals(100)
    p = tmp_path / "a.mat"
    savemat(p, {"fs": 200.0, "data": x.T, "title": "run 3", "freq": np.arange(7.0)})
    td = read_timedata(p, ChannelMap.parse(["data(:,1)=force:N", "data=acceleration:g"]))
    assert td.sample_rate == 200.0
    assert [c.name for c in td.channels] == ["data(:,1)", "data(:,2)", "data(:,3)"]
    assert td.quantities == ("force", "acceleration", "acceleration")
    assert_array_equal(td.data[0], x[0])
    assert_allclose(td.data[2], x[2] * G, rtol=1e-15)  # g to m/s^2
    assert any("freq" in n for n in td.meta["read_notes"])
    q = tmp_path / "b.mat"
    savemat(q, {"t": np.arange(100) / 50.0, "F": x[0], "a": x[1]})
    td = read_timedata(q, ChannelMap.parse(["F=force:kN", "a=velocity:mm/s"]))
    assert td.sample_rate == 50.0
    assert_allclose(td.data, [x[0] * 1e3, x[1] * 1e-3], rtol=1e-15)
    s = tmp_path / "s.mat"
    savemat(s, {"test": {"time": np.arange(100) / 20.0, "F": x[0], "acc": x[1], "id": "A"}})
    td = read_timedata(s, ChannelMap.parse(["F=force:N", "acc=acceleration:g"]))
    assert [c.name for c in td.channels] == ["test.F", "test.acc"]
    assert td.sample_rate == 20.0
    assert_allclose(td.data[1], x[1] * G, rtol=1e-15)  # g to m/s^2
    r = tmp_path / "c.mat"
    savemat(r, {"F": x[0], "a": x[1]})
    with pytest.raises(FileFormatError, match="no time base"):
        read_timedata(r)
    bad = tmp_path / "d.mat"
    bad.write_bytes(b"MATLAB 7.3 MAT-file" + b"\0" * 200)
    with pytest.raises(FileFormatError, match=r"d\.mat"):
        read(bad)


def test_wav(tmp_path: Path) -> None:
    from scipy.io import wavfile

    x = (np.sin(np.arange(400) / 7) * 16000).astype(np.int16)
    p = tmp_path / "r.wav"
    wavfile.write(p, 48000, np.stack([x, -x], axis=1))
    td = read_timedata(p)
    assert isinstance(td, TimeData)
    assert td.quantities == ("voltage", "voltage")
    assert_array_equal(td.data[0], x / 32768.0)
    td = read_timedata(p, ChannelMap.parse(["ch1=force"], ["1=10 mV/N", "2=100 mV/g"]))
    assert td.quantities == ("force", "acceleration")
    assert_allclose(td.data[0], x / 32768.0 / 10e-3, rtol=1e-15)
    assert not isinstance(td, FRF)


@pytest.mark.parametrize("binary", [0, 1])
def test_vendor_frf_label_in_cp1252(tmp_path: Path, binary: int) -> None:
    sets, truth = foreign_frf_sets(binary, ("(1/N)*(m/s²)", "NONE"))
    p = tmp_path / "vendor_frf.uff"
    write_foreign(p, sets)
    raw = p.read_bytes()
    assert "m/s²".encode() in raw
    # as the vendor's Windows software writes it: one byte 0xB2 (padded to keep the columns)
    p.write_bytes(raw.replace("m/s²".encode(), "m/s²".encode("cp1252") + b" "))
    frf = read_frf(p)
    assert frf.kind == "accelerance"
    assert frf.meta["text_encoding"] == "cp1252"
    assert_allclose(frf.frequency, truth["f"], rtol=1e-5)  # record 7 keeps 6 digits
    assert_allclose(frf.H[0, 0], truth["H"][11], rtol=1e-11)  # ASCII: 12 digits; binary exact


def test_a_column_of_complex_numbers_asks_for_its_frequency_axis(tmp_path: Path) -> None:
    # one Python complex per line, as numpy or a script writes an FRF without its axis
    p = tmp_path / "frf.txt"
    p.write_text("(-0.07+2.6e-08j)\n(-0.17-0.12j)\n(0.09+0.02j)\n", encoding="utf-8")
    with pytest.raises(
        FileFormatError, match=r"complex numbers.*without a frequency column.*freq_Hz"
    ):
        read(p)
    p.write_text("1.0\n2.0\nabc\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match="no rows of numbers"):
        read(p)


def test_unnamed_channels_beside_a_force_are_suggested_as_responses(tmp_path: Path) -> None:
    p = tmp_path / "hammer.csv"
    rows = "\n".join(f"{k / 100:.2f},{k % 3},{k % 5},{k % 7}" for k in range(20))
    p.write_text("time_s,F [N],a1,a2\n" + rows + "\n", encoding="utf-8")
    # the force is named by its unit: the example does not call a1 a force too
    with pytest.raises(FileFormatError, match=r"for example --channel 'a1=acceleration:m/s\^2'"):
        read_timedata(p)
