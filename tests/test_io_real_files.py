"""Files that real labs and other programs wrote (the shared gallery), read through the public API.

Every value is checked against the file's own content read independently
(npTDMS, asammdf, lvm_read, scipy.io, numpy text parsing), not against
numbers written here. The gallery lives beside the repository
(``../shared/real-data``, see its CATALOGUE.md); these tests are skipped
when it is absent.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import FileFormatError, InputError
from tyredamp.cli import main as _main
from tyredamp.io import ChannelMap, read, read_frf, read_timedata

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
if not REAL.is_dir():  # pragma: no cover - the gallery is beside the repository in CI
    pytest.skip(f"real-data gallery not found at {REAL}", allow_module_level=True)

IMPACT = REAL / "converted" / "impact_test_3ch"
LVM_LONG = REAL / "ladisk_lvm_read" / "data" / "long_single_header_multi_ch.lvm"
LVM_SHORT = REAL / "ladisk_lvm_read" / "data" / "short.lvm"
CASE1 = REAL / "vibrationtoolbox_vibration_toolbox" / "vibration_toolbox" / "data" / "case1.mat"
UFF = REAL / "ladisk_pyuff" / "data"


def main(argv: list[str]) -> int:
    """Run the command line; its exit code."""
    try:
        _main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


IMPACT_MAP = ["F=force:N", "m_1=acceleration:m/s^2", "m_2=acceleration:m/s^2"]


def _csv_table() -> tuple[list[str], np.ndarray]:
    """The plain CSV read with numpy alone: header names and the table."""
    p = IMPACT.with_suffix(".csv")
    header = p.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(p, delimiter=",", skiprows=1)


@pytest.mark.parametrize("ext", [".csv", ".tdms", ".mf4", ".lvm"])
def test_impact_test_in_every_format_reads_the_same_samples(ext: str) -> None:
    path = LVM_LONG if ext == ".lvm" else IMPACT.with_suffix(ext)
    td = read_timedata(path, ChannelMap.parse(IMPACT_MAP))
    header, table = _csv_table()
    assert [c.name for c in td.channels] == header[1:]
    assert td.quantities == ("force", "acceleration", "acceleration")
    assert td.n_samples == table.shape[0]
    # the CSV stores 6 significant digits (the LVM 6 decimals): equal to print precision
    assert_allclose(td.data, table[:, 1:].T, rtol=5e-6, atol=5e-7)
    dt = 0.000977  # the sample interval every source states (LVM Delta_X)
    assert_allclose(td.sample_rate, 1 / dt, rtol=1e-6)  # CSV rate from its 6-decimal times


def test_tdms_against_nptdms() -> None:
    nptdms = pytest.importorskip("nptdms")
    f = nptdms.TdmsFile.read(str(IMPACT.with_suffix(".tdms")))
    group = f.groups()[0]
    td = read_timedata(IMPACT.with_suffix(".tdms"), ChannelMap.parse(IMPACT_MAP))
    for k, ch in enumerate(group.channels()):
        assert_array_equal(td.data[k], ch[:])  # SI in the file: read bit for bit
        assert td.sample_rate == pytest.approx(1 / ch.properties["wf_increment"], rel=1e-12)


def test_mdf_reads_one_rate_and_says_what_it_left_out() -> None:
    asammdf = pytest.importorskip("asammdf")
    path = IMPACT.with_suffix(".mf4")
    with asammdf.MDF(str(path)) as m:
        ref = {s.name: s for s in m.iter_channels()}
    td = read_timedata(path, ChannelMap.parse(IMPACT_MAP))
    assert [c.name for c in td.channels] == ["F", "m_1", "m_2"]
    for k, c in enumerate(td.channels):
        assert_array_equal(td.data[k], ref[c.name].samples)
    t = ref["F"].timestamps
    assert td.sample_rate == pytest.approx((t.size - 1) / (t[-1] - t[0]), rel=1e-12)
    assert "temperature (another time base)" in td.meta["read_notes"][0]
    # without a map: one line naming the channel without a unit, and how to name it
    with pytest.raises(FileFormatError, match=r"channel 'F': no units label.*--channel 'F=force"):
        read_timedata(path)


def test_lvm_files_against_lvm_read() -> None:
    lvm_read = pytest.importorskip("lvm_read")
    for path, names in (
        (LVM_LONG, ["F", "m_1", "m_2"]),
        (LVM_SHORT, ["Excitation (Trigger)", "Response (Trigger)"]),
    ):
        ref = lvm_read.read(str(path), read_from_pickle=False, dump_file=False)
        td = read_timedata(path, ChannelMap.parse([f"{names[0]}=force:N"]))
        assert [c.name for c in td.channels] == names
        assert_array_equal(td.data, ref[0]["data"].T)  # units N and m/s^2: no scaling
        assert td.sample_rate == pytest.approx(1 / ref[0]["Delta_X"][0], rel=1e-12)
    # short.lvm states its units (Newtons, m/s^2) and a decimal comma: reads without a map
    td = read_timedata(LVM_SHORT)
    assert td.quantities == ("force", "acceleration")
    # the long file labels the hammer "g": without a map it reads as the file says
    td = read_timedata(LVM_LONG)
    assert td.output_only
    ref = lvm_read.read(str(LVM_LONG), read_from_pickle=False, dump_file=False)
    assert_allclose(td.data[0], ref[0]["data"][:, 0] * 9.80665, rtol=1e-15)  # g to m/s^2


def test_case1_mat_time_data_and_frf_against_scipy() -> None:
    from scipy.io import loadmat

    m = loadmat(str(CASE1))
    cmap = ChannelMap.parse(
        ["Time_chan_1=force:V", "Time_chan_2=acceleration"], ["Time_chan_1=2 mV/N"]
    )
    td = read_timedata(CASE1, cmap)
    assert td.sample_rate == float(m["Time_Sample_Rate"].item())
    volts = m["Time_chan_1"].ravel().astype(float)
    assert_allclose(td.data[0], volts / 2e-3, rtol=1e-14)  # V / (V/N), float64 rounding
    assert_array_equal(td.data[1], m["Time_chan_2"].ravel())
    assert any("Freq_domain" in n for n in td.meta["read_notes"])
    frf = read_frf(CASE1, channel_map=ChannelMap.parse(["Hf_chan_2=acceleration:g/N"]))
    assert frf.kind == "accelerance"
    assert_array_equal(frf.frequency, m["Freq_domain"].ravel().astype(float))
    assert_allclose(frf.H[0, 0], m["Hf_chan_2"].ravel() * 9.80665, rtol=1e-15)  # g -> m/s^2
    assert frf.coherence is not None
    # the analyser stored a few lines above 1: clipped, and said so
    stored = m["Hf_coh_chan_2"].ravel().astype(float)
    assert_array_equal(frf.coherence[0], np.clip(stored, 0, 1))
    assert any(f"at {np.sum(stored > 1)} line(s)" in n for n in frf.meta["read_notes"])
    with pytest.raises(FileFormatError, match=r"Hf_chan_2.*--channel 'Hf_chan_2=acceleration"):
        read_frf(CASE1)


def test_uff_gallery_reads_or_says_what_the_file_is() -> None:
    import pyuff

    mps = read(UFF / "MPSTD#Set001_2024_10_08_10_27_07.uff")
    ref = pyuff.UFF(str(UFF / "MPSTD#Set001_2024_10_08_10_27_07.uff")).read_sets()
    assert isinstance(mps, type(read_timedata(UFF / "time-history-not-all-columns-filled.uff")))
    assert mps.output_only
    assert mps.n_channels == len(ref)
    assert_array_equal(mps.data[2], np.asarray(ref[2]["data"], dtype=float))
    with pytest.raises(InputError, match=r"output-only data \(no force channel\)"):
        mps.require_force()
    mic = read_timedata(UFF / "Sample_UFF58b_bin.uff")
    assert mic.quantities == ("pressure",)
    assert mic.units == ("Pa",)
    hbm = read_timedata(UFF / "time-history-not-all-columns-filled.uff")
    assert hbm.quantities == ("acceleration",)
    lines = {
        "sample_dataset58_psd.uff": (
            r"holds a PSD \(function type 9\), not time data or an FRF; export the time data"
        ),
        "dataset_milestone_in_header.uff": r"header declares 2508876 values, the file stores 42",
        "TestLab 161 164 18 15 82.uff": r"holds geometry only",
        "mesh_Oros-modal_uff15_uff2412.uff": r"holds geometry only",
        "Artemis export - Geometry RPBC_setup_05_14102016_105117.uff": r"holds geometry only",
        "uff55 sample_test record10.uff": r"holds mode shapes",
    }
    for name, msg in lines.items():
        with pytest.raises(FileFormatError, match=msg):
            read(UFF / name)


def test_psd_units_label_in_latin1_is_decoded() -> None:
    from tyredamp.io._uff_load import load_sets

    raw = (UFF / "sample_dataset58_psd.uff").read_bytes()
    assert b"g\xb2/Hz" in raw  # the file stores the label in Latin-1
    s = load_sets(UFF / "sample_dataset58_psd.uff")[0]
    assert s["ordinate_axis_units_lab"] == "g²/Hz"


@pytest.mark.parametrize("ext", [".csv", ".tdms", ".mf4", ".lvm", ".mat"])
def test_cli_frf_on_real_files(tmp_path: Path, ext: str, capsys: pytest.CaptureFixture) -> None:
    if ext == ".mat":
        path, chans, sens = CASE1, ["Time_chan_1=force:V", "2=acceleration:m/s^2"], ["1=1 V/N"]
    else:
        path = LVM_LONG if ext == ".lvm" else IMPACT.with_suffix(ext)
        chans, sens = IMPACT_MAP, []
    opts = [x for c in chans for x in ("--channel", c)]
    opts += [x for c in sens for x in ("--sensitivity", c)]
    out = tmp_path / "frf.uff"
    assert main(["frf", str(path), *opts, "-o", str(out)]) == 0
    frf = read_frf(out)
    td = read_timedata(path, ChannelMap.parse(chans, sens))
    assert frf.kind == "accelerance"
    assert frf.n_out == len(td.response_indices)
    assert frf.frequency[-1] == pytest.approx(td.sample_rate / 2, rel=1e-9)


def test_cli_output_only_and_bad_maps(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "x.uff"
    assert main(["frf", str(UFF / "MPSTD#Set001_2024_10_08_10_27_07.uff"), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "output-only data (no force channel)" in err
    assert "with tyredamp oma (operational modal analysis)" in err
    assert not out.exists()
    csv = str(IMPACT.with_suffix(".csv"))
    for opts, msg in (
        (["--channel", "Kraft=force:N"], "names channel 'Kraft', which the file does not have"),
        (["--channel", "F=forse:N"], "role 'forse' is not one of"),
        (["--channel", "F=forse"], "expected ROLE[:UNIT] with ROLE one of force"),
        (["--channel", "F"], "expected CHANNEL=VALUE"),
        (["--sensitivity", "F=2 mV"], "expected volts per physical unit"),
        (["--channel", "F=force:furlong"], "unknown unit 'furlong'"),
    ):
        assert main(["frf", csv, *opts, "-o", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert msg in err
        assert err.count("\n") == 0
    # a map file gives the same FRF as the options
    by_options = tmp_path / "a.uff"
    opts = [x for c in IMPACT_MAP for x in ("--channel", c)]
    assert main(["frf", csv, *opts, "-o", str(by_options)]) == 0
    mp = tmp_path / "map.toml"
    mp.write_text('[channels]\nF = "force:N"\n2 = { role = "acceleration" }\n')
    opts = ["--channel-map", str(mp), "--channel", "3=acceleration"]
    assert main(["frf", csv, *opts, "-o", str(out)]) == 0
    assert_array_equal(read_frf(out).H, read_frf(by_options).H)
    # check quality reads output-only data and says so
    assert main(["check", "quality", str(UFF / "time-history-not-all-columns-filled.uff")]) == 0
    assert "output-only data" in capsys.readouterr().out


def test_uff_frf_refuses_a_channel_map(tmp_path: Path) -> None:
    out = tmp_path / "frf.uff"
    assert main(["frf", str(IMPACT.with_suffix(".csv")), *_opts(IMPACT_MAP), "-o", str(out)]) == 0
    with pytest.raises(InputError, match=r"holds FRFs.*applies to time data"):
        read(out, ChannelMap.parse(["1=force"]))


def _opts(chans: list[str]) -> list[str]:
    return [x for c in chans for x in ("--channel", c)]


def test_uff_time_data_takes_a_channel_map() -> None:
    import pyuff

    path = UFF / "time-history-not-all-columns-filled.uff"
    stored = np.asarray(pyuff.UFF(str(path)).read_sets(0)["data"], dtype=float)
    plain = read_timedata(path)
    assert_array_equal(plain.data[0], stored)  # m/s² as labelled: SI already
    # the map overrides the label (here: the sensor was in g) and sets the point
    td = read_timedata(path, ChannelMap.parse(["1=acceleration:g@4-Y"]))
    assert_allclose(td.data[0], stored * 9.80665, rtol=1e-15)  # g to m/s^2
    assert (td.channels[0].node, td.channels[0].direction) == (4, -2)
    mic = read_timedata(UFF / "Sample_UFF58b_bin.uff", ChannelMap.parse(["Mic 01=pressure:Pa"]))
    assert mic.channels[0].name == "Mic 01"
    with pytest.raises(
        InputError, match=r"'Pa' means pressure, but the channel map names it force"
    ):
        read_timedata(UFF / "Sample_UFF58b_bin.uff", ChannelMap.parse(["Mic 01=force"]))
