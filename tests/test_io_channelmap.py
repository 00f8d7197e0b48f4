"""Units vocabulary, sensitivities and the channel map (CLI strings and files)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import FileFormatError, InputError
from tyredamp.io import ChannelMap, ChannelSpec
from tyredamp.io._channels import timedata_from_channels
from tyredamp.io.units import parse_sensitivity, parse_unit, quantity_units

G, LBF, IN = 9.80665, 4.4482216152605, 0.0254


@pytest.mark.parametrize(
    ("label", "quantity", "factor"),
    [
        ("Pa", "pressure", 1.0),
        ("kPa", "pressure", 1e3),
        ("mbar", "pressure", 1e2),
        ("bar", "pressure", 1e5),
        ("psi", "pressure", LBF / IN**2),
        ("N/m^2", "pressure", 1.0),
        ("V", "voltage", 1.0),
        ("mV", "voltage", 1e-3),
        ("Volts", "voltage", 1.0),
        ("g", "acceleration", G),
        ("in/s", "velocity", IN),
        ("lbf", "force", LBF),
        ("Newtons", "force", 1.0),
        ("µm", "displacement", 1e-6),
        ("m/s^2", "acceleration", 1.0),
        ("m/s2", "acceleration", 1.0),
        ("m/s**2", "acceleration", 1.0),
        ("m/s²", "acceleration", 1.0),
    ],
)
def test_units_vocabulary(label: str, quantity: str, factor: float) -> None:
    q, f = quantity_units(label)  # type: ignore[misc]
    assert q == quantity
    assert f == pytest.approx(factor, rel=1e-15)  # exact products of the defined factors


def test_psd_labels_parse_but_are_not_a_signal() -> None:
    u = parse_unit("g²/Hz")
    assert u.dimensions == (2, -3, 0)  # (m/s^2)^2 / (1/s)
    assert u.factor == pytest.approx(G**2, rel=1e-15)
    with pytest.raises(InputError, match=r"'g\^2/Hz'.*not a displacement"):
        quantity_units("g^2/Hz")


@pytest.mark.parametrize(
    ("text", "quantity", "volts_per_si"),
    [
        ("2.25 mV/N", "force", 2.25e-3),
        ("100 mV/g", "acceleration", 0.1 / G),
        ("10.2mV/(m/s^2)", "acceleration", 10.2e-3),
        ("50 mV/Pa", "pressure", 50e-3),
        ("2,25 mV/N", "force", 2.25e-3),
        ("444.8 N/V", "force", 1 / 444.8),
        ("10 mV/lbf", "force", 10e-3 / LBF),
    ],
)
def test_sensitivities(text: str, quantity: str, volts_per_si: float) -> None:
    s = parse_sensitivity(text)
    assert s.quantity == quantity
    assert s.volts_per_si == pytest.approx(volts_per_si, rel=1e-14)  # float products


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("mV/N", "expected a number and a unit"),
        ("2 mV", "expected volts per physical unit"),
        ("2 N", "expected volts per physical unit"),
        ("-1 mV/N", "expected a positive number"),
        ("2 mV/furlong", "unknown unit 'furlong'"),
    ],
)
def test_bad_sensitivities(text: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        parse_sensitivity(text)


def test_channel_strings() -> None:
    cm = ChannelMap.parse(
        ["Kanal 3=force:N", "1=acceleration", "m_1=acceleration:g@2+Z", "T=ignore", "x=mV"],
        ["Kanal 3=2.25 mV/N"],
    )
    by_key = {s.key: s for s in cm.channels}
    assert by_key["Kanal 3"].role == "force"
    assert by_key["Kanal 3"].unit == "N"
    assert by_key["Kanal 3"].sensitivity is not None  # merged from --sensitivity
    assert by_key["1"] == ChannelSpec("1", "acceleration")
    assert (by_key["m_1"].unit, by_key["m_1"].node, by_key["m_1"].direction) == ("g", 2, 3)
    assert by_key["T"].role == "ignore"
    assert (by_key["x"].role, by_key["x"].unit) == (None, "mV")


@pytest.mark.parametrize(
    ("channel", "message"),
    [
        ("F", "expected CHANNEL=VALUE"),
        ("=force", "no channel name before '='"),
        ("F=", "nothing after '='"),
        ("F=forse:N", "role 'forse' is not one of"),
        ("F=force:furlong", "unknown unit 'furlong'"),
        ("F=ignore:N", "an ignored channel takes no unit"),
        ("F=force@x", "point 'x' is not a point number"),
    ],
)
def test_bad_channel_strings(channel: str, message: str) -> None:
    with pytest.raises(InputError, match=message) as info:
        ChannelMap.parse([channel])
    assert "\n" not in str(info.value)
    assert "--channel" in str(info.value)


def test_map_files_toml_and_json(tmp_path: Path) -> None:
    toml = tmp_path / "m.toml"
    toml.write_text(
        '[channels."Kanal 3"]\nrole = "force"\nunit = "V"\nsensitivity = "2.25 mV/N"\n'
        'node = 7\ndirection = "-Y"\n[channels]\nm_1 = "acceleration:g"\n',
        encoding="utf-8",
    )
    cm = ChannelMap.from_file(toml)
    js = tmp_path / "m.json"
    js.write_text(json.dumps(cm.to_dict()))
    assert ChannelMap.from_file(js).to_dict() == cm.to_dict()
    k3 = {s.key: s for s in cm.channels}["Kanal 3"]
    assert (k3.node, k3.direction, k3.unit) == (7, -2, "V")
    # the command line overrides the file, field by field
    both = ChannelMap.parse(["Kanal 3=force:mV"], file=toml)
    k3 = {s.key: s for s in both.channels}["Kanal 3"]
    assert (k3.unit, k3.node) == ("mV", 7)
    bad = tmp_path / "bad.toml"
    bad.write_text('[channels.F]\nrole = "force"\ngain = 2\n')
    with pytest.raises(InputError, match=r"bad.toml: channels.F: unknown key 'gain'"):
        ChannelMap.from_file(bad)
    bad.write_text("[channels\n")
    with pytest.raises(FileFormatError, match="not a valid TOML channel map"):
        ChannelMap.from_file(bad)
    with pytest.raises(InputError, match="channel-map file not found"):
        ChannelMap.from_file(tmp_path / "none.toml")
    bad.write_text('[sensors]\nF = "force"\n')
    with pytest.raises(InputError, match="unknown key 'sensors'; expected 'channels'"):
        ChannelMap.from_file(bad)


def _build(cm: ChannelMap, units: list[str], names: list[str] | None = None) -> object:
    names = names or [f"c{k}" for k in range(len(units))]
    arrays = [np.linspace(-1, 1, 8) * (k + 1) for k in range(len(units))]
    return timedata_from_channels(Path("f.dat"), names, units, arrays, 100.0, None, cm)


def test_map_applied_to_channels() -> None:
    td = _build(
        ChannelMap.parse(["c0=force", "c2=ignore"], ["c0=2 mV/N", "2=100 mV/g"]),
        ["mV", "V", "N"],
    )
    x = np.linspace(-1, 1, 8)
    assert td.quantities == ("force", "acceleration")  # type: ignore[attr-defined]
    assert_allclose(td.data[0], x * 1e-3 / 2e-3, rtol=1e-15)  # type: ignore[attr-defined]
    assert_allclose(td.data[1], 2 * x / (0.1 / G), rtol=1e-15)  # type: ignore[attr-defined]
    assert "left out as the channel map asks: c2" in td.meta["read_notes"]  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    ("channels", "sens", "units", "message"),
    [
        (["c0=force"], [], ["V"], r"stored in volts \('V'\); give its sensitivity"),
        (["c0=force"], [], ["g"], r"'g' means acceleration, but the channel map names it force"),
        ([], ["c0=2 mV/N"], ["N"], r"stored in 'N' \(force\), not volts"),
        (["c0=acceleration"], ["c0=2 mV/N"], ["V"], "is for a force sensor"),
        (["c9=force"], [], ["N"], r"names channel 'c9'.*its channels are 1: 'c0'"),
        ([], [], [""], r"no units label tells what it measures.*--channel 'c0=force:N'"),
    ],
)
def test_map_and_file_disagree(
    channels: list[str], sens: list[str], units: list[str], message: str
) -> None:
    with pytest.raises((InputError, FileFormatError), match=message) as info:
        _build(ChannelMap.parse(channels, sens), units)
    assert "\n" not in str(info.value)


def test_voltage_and_pressure_channels_are_kept_but_not_responses() -> None:
    td = _build(ChannelMap(), ["N", "Pa", "V", "m/s^2"])
    assert td.quantities == ("force", "pressure", "voltage", "acceleration")  # type: ignore[attr-defined]
    assert td.response_indices == [3]  # type: ignore[attr-defined]
    assert td.other_indices == [1, 2]  # type: ignore[attr-defined]
    assert td.units == ("N", "Pa", "V", "m/s^2")  # type: ignore[attr-defined]


def test_a_step_that_needs_a_response_says_which_channels_it_has() -> None:
    td = _build(ChannelMap(), ["N", "Pa", "V"], ["hammer", "mic", "acc"])
    with pytest.raises(InputError, match=r"f.dat: no response channel") as info:
        td.require_response("an FRF", "f.dat")  # type: ignore[attr-defined]
    msg = str(info.value)
    assert "mic (pressure, Pa), acc (voltage, V)" in msg
    assert "--sensitivity 'acc=100 mV/g'" in msg
    td.require_force()  # type: ignore[attr-defined]  # has a force: no error
