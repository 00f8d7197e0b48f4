"""TDMS (npTDMS) and MDF4 (asammdf) time data: exact read back, units, force, frf, bad files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from tyredamp import FileFormatError, InputError
from tyredamp.cli import main
from tyredamp.io import ChannelMap, read_frf, read_timedata
from tyredamp.io.mdf import read_mdf
from tyredamp.io.tdms import read_tdms

from .excitation_records import exact_frf, periodic_record

nptdms = pytest.importorskip("nptdms")
asammdf = pytest.importorskip("asammdf")

FS = 2000.0


def signals() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x, y, lines = periodic_record("multisine", 500, 6, np.random.default_rng(7), False)
    return x, y, lines


def write_tdms(path: Path, chans: list[tuple[str, np.ndarray, str]], fs: float = FS) -> None:
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment(
            [
                nptdms.ChannelObject(
                    "Measurement",
                    name,
                    data,
                    properties={"wf_increment": 1.0 / fs, "unit_string": u},
                )
                for name, data, u in chans
            ]
        )


def write_mdf(path: Path, chans: list[tuple[str, np.ndarray, str]], fs: float = FS) -> None:
    t = np.arange(chans[0][1].size) / fs
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(data, t, name=name, unit=u) for name, data, u in chans])
    m.save(str(path), overwrite=True)
    m.close()


WRITERS = {".tdms": write_tdms, ".mf4": write_mdf}


@pytest.mark.parametrize("ext", list(WRITERS))
def test_known_signals_read_back_exactly(tmp_path: Path, ext: str) -> None:
    x, y, _ = signals()
    path = tmp_path / f"test{ext}"
    WRITERS[ext](path, [("Hammer", x, "lbf"), ("Acc 1", y, "g"), ("Acc 2", 2 * y, "m/s²")])
    td = read_timedata(path)
    assert td.sample_rate == FS
    assert td.quantities == ("force", "acceleration", "acceleration")
    assert [c.name for c in td.channels] == ["Hammer", "Acc 1", "Acc 2"]
    assert_array_equal(td.data[0], x * 4.4482216152605)  # lbf -> N
    assert_array_equal(td.data[1], y * 9.80665)  # g -> m/s^2
    assert_array_equal(td.data[2], 2 * y)


@pytest.mark.parametrize("ext", list(WRITERS))
def test_frf_command_on_tdms_and_mdf(
    tmp_path: Path, ext: str, capsys: pytest.CaptureFixture[str]
) -> None:
    x, y, lines = signals()
    path = tmp_path / f"test{ext}"
    WRITERS[ext](path, [("Force", x, "N"), ("Response", y, "m/s^2")])
    out = tmp_path / "frf.npz"
    try:
        main(["frf", str(path), "--out", str(out)])
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "detected periodic" in captured.out
    frf = read_frf(out)
    k = np.round(frf.frequency * 500 / FS).astype(int)
    sel = np.isin(k, lines)
    h = exact_frf(k[sel], 500)
    assert np.max(np.abs(frf.H[0, 0, sel] - h) / np.abs(h)) < 1e-9  # float64 storage


def test_force_named_by_quantities_when_units_are_blank(tmp_path: Path) -> None:
    x, y, _ = signals()
    path = tmp_path / "blank.tdms"
    write_tdms(path, [("ch0", x, ""), ("ch1", y, "")])
    with pytest.raises(FileFormatError, match=r"'ch0', 'ch1' measure.*--channel 'ch0=force:N'"):
        read_tdms(path)
    td = read_tdms(path, quantities={"ch0": "force", "ch1": "velocity"})
    assert td.quantities == ("force", "velocity")
    with pytest.raises(InputError, match="names channel 'nope', which the file does not have"):
        read_tdms(path, quantities={"nope": "force"})
    mpath = tmp_path / "blank.mf4"
    write_mdf(mpath, [("ch0", x, ""), ("ch1", y, "")])
    assert read_mdf(mpath, quantities={"ch0": "force", "ch1": "acceleration"}).n_channels == 2


@pytest.mark.parametrize("ext", list(WRITERS))
def test_bad_files(tmp_path: Path, ext: str) -> None:
    x, y, _ = signals()
    garbage = tmp_path / f"garbage{ext}"
    garbage.write_bytes(b"\x00\x01not a real file" * 10)
    with pytest.raises(FileFormatError, match="not a readable"):
        read_timedata(garbage)
    empty = tmp_path / f"empty{ext}"
    empty.write_bytes(b"")
    with pytest.raises(FileFormatError, match="empty"):
        read_timedata(empty)
    noforce = tmp_path / f"noforce{ext}"
    WRITERS[ext](noforce, [("a", x, "m/s^2"), ("b", y, "m/s^2")])
    td = read_timedata(noforce)  # output-only data reads; the steps needing a force refuse it
    assert td.output_only
    with pytest.raises(InputError, match=r"output-only data \(no force channel\): channels a"):
        td.require_force()
    badunit = tmp_path / f"badunit{ext}"
    WRITERS[ext](badunit, [("F", x, "N"), ("b", y, "furlong")])
    if ext == ".mf4":  # a logger's other channels (degC, rpm ...) are left out, and said so
        td = read_timedata(badunit)
        assert td.n_channels == 1
        assert "b (unit 'furlong' is not a vibration quantity)" in td.meta["read_notes"][0]
    else:
        with pytest.raises(FileFormatError, match="units label 'furlong'"):
            read_timedata(badunit)
    nan = tmp_path / f"nan{ext}"
    WRITERS[ext](nan, [("F", np.where(np.arange(x.size) == 5, np.nan, x), "N"), ("b", y, "g")])
    with pytest.raises(FileFormatError, match="finite"):
        read_timedata(nan)
    with pytest.raises(FileFormatError, match="time data, not an FRF"):
        read_frf(nan)


def test_tdms_unequal_sampling(tmp_path: Path) -> None:
    x, y, _ = signals()
    path = tmp_path / "mixed.tdms"
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment(
            [
                nptdms.ChannelObject(
                    "g", "F", x, properties={"wf_increment": 1e-3, "unit_string": "N"}
                ),
                nptdms.ChannelObject(
                    "g", "A", y, properties={"wf_increment": 2e-3, "unit_string": "g"}
                ),
            ]
        )
    with pytest.raises(FileFormatError, match="sample intervals"):
        read_tdms(path)


def test_mdf_several_rates_text_and_value_table_channels(tmp_path: Path) -> None:
    x, y, _ = signals()
    t = np.arange(x.size) / FS
    slow = np.arange(0, x.size, 64) / FS
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(x, t, name="F", unit="N"), asammdf.Signal(y, t, name="a", unit="g")])
    m.append(
        [
            asammdf.Signal(np.full(slow.size, 21.5), slow, name="temp", unit="degC"),
            asammdf.Signal(np.array([b"run"] * slow.size), slow, name="state", encoding="utf-8"),
            asammdf.Signal(np.ones(slow.size), slow, name="x1", unit="m/s^2"),
            asammdf.Signal(np.ones(slow.size), slow, name="x2", unit="m/s^2"),
            asammdf.Signal(np.ones(slow.size), slow, name="x3", unit="m/s^2"),
        ]
    )
    # a value-table channel on the fast rate: strings after conversion
    vt = {"val_0": 0, "text_0": b"off", "val_1": 1, "text_1": b"on", "default": b""}
    m.append([asammdf.Signal(np.zeros(x.size, dtype=np.uint8), t, name="gear", conversion=vt)])
    path = tmp_path / "logger.mf4"
    m.save(str(path), overwrite=True)
    m.close()
    # the slow group has the most channels of vibration units: the map chooses the fast one
    td = read_mdf(path, channel_map=ChannelMap.parse(["F=force"]))
    assert [c.name for c in td.channels] == ["F", "a"]
    assert_array_equal(td.data[0], x)
    assert td.sample_rate == FS
    note = td.meta["read_notes"][0]
    for name in ("temp (another time base)", "state (not numeric", "gear (not numeric"):
        assert name in note
    slow_td = read_mdf(path)  # without a map: the rate of the most vibration channels
    assert [c.name for c in slow_td.channels] == ["x1", "x2", "x3"]
    assert "temp (unit 'degC' is not a vibration quantity)" in slow_td.meta["read_notes"][0]
    with pytest.raises(InputError, match="different time bases"):
        read_mdf(path, channel_map=ChannelMap.parse(["F=force", "x1=acceleration"]))


def test_tdms_time_channel_instead_of_wf_increment(tmp_path: Path) -> None:
    x, y, _ = signals()
    path = tmp_path / "script.tdms"
    t = np.arange(x.size) / FS
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment(
            [
                nptdms.ChannelObject("g", "Time", t),
                nptdms.ChannelObject("g", "F", x, properties={"unit_string": "N"}),
                nptdms.ChannelObject("g", "A", y),
            ]
        )
    td = read_tdms(path, channel_map=ChannelMap.parse(["g/A=acceleration:g"]))
    assert [c.name for c in td.channels] == ["F", "A"]
    assert td.sample_rate == FS  # 1 / mean step of the time channel, snapped
    assert_array_equal(td.data[0], x)
    assert "time channel 'Time'" in td.meta["read_notes"][0]
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment([nptdms.ChannelObject("g", "F", x, properties={"unit_string": "N"})])
    with pytest.raises(FileFormatError, match=r"no wf_increment .* no evenly spaced time channel"):
        read_tdms(path)
