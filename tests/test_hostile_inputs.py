"""Hostile and damaged inputs through every reader: one error line, exit 2, nothing touched.

Each case of the corpus runs ``tyredamp`` in-process (``main([...])``) in a
folder of its own and checks the one rule of :mod:`tyredamp.io._guard`: exit
code 2, exactly one stderr line ``tyredamp: error: ...`` naming the problem,
no traceback and no library log line, every input byte-identical afterwards
(SHA-256 before and after) and no file left in the folder. The corpus:
truncated copies of every format, hostile units labels, axis units that are
not a frequency or a time, NPZ archives that would inflate far beyond their
size, deeply nested TOML, FRF values near the largest double, duplicate node
numbers, complex TDMS channels, a full disk. Axis units that can be converted
(rad/s, kHz, rpm, cpm, ms, us, min) must give the right answer instead.
"""

from __future__ import annotations

import hashlib
import math
import os
import tracemalloc
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.frf import FRF
from tyredamp.io import read_frf, read_timedata, write_frf
from tyredamp.io._guard import axis_scale, check_archive, load_toml, toml_depth
from tyredamp.io.npz import _check_members
from tyredamp.io.units import parse_unit

from . import hostile_corpus as hc
from .badinput import check_one_error_line, run_main, snapshot

pytest.importorskip("nptdms")
pytest.importorskip("asammdf")
pytest.importorskip("xarray")

Maker = Callable[[Path, Path], bytes]


@dataclass(frozen=True)
class Case:
    """One hostile input: ``files`` maps names to a maker ``(library, case dir) -> bytes``;
    ``argv`` runs in the case folder; ``needle`` must be in the error line."""

    id: str
    files: dict[str, Maker]
    argv: list[str]
    needle: str


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return hc.make_library(tmp_path_factory.mktemp("hostile-lib"))


def _copy(name: str, fraction: float | None = None) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        data = (lib / name).read_bytes()
        return data if fraction is None else hc.cut(data, fraction)

    return make


def _const(data: bytes) -> Maker:
    return lambda lib, d: data


def _sha(d: Path, names: list[str]) -> dict[str, str]:
    return {n: hashlib.sha256((d / n).read_bytes()).hexdigest() for n in names if (d / n).exists()}


def run_case(case: Case, lib: Path, d: Path, capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``case`` in ``d``; check the one rule; return the error line."""
    d.mkdir()
    for name, make in case.files.items():
        (d / name).write_bytes(make(lib, d))
    before, hashes = snapshot(d), _sha(d, list(case.files))
    cwd = os.getcwd()
    os.chdir(d)
    try:
        code, _, err = run_main(case.argv, capsys)
    finally:
        os.chdir(cwd)
    line = check_one_error_line(err, code, 2, case.needle)
    assert _sha(d, list(case.files)) == hashes  # inputs unchanged
    assert snapshot(d) == before  # nothing written, nothing removed
    return line


# ----------------------------------------------------------------------------- corpus
#: (library file, command reading it); the error names the cut copy.
_TRUNCATED = [
    ("frf.uff", "modal"),
    ("frf58a.uff", "modal"),
    ("frf.npz", "modal"),
    ("frf.nc", "modal"),
    ("frf.mat", "modal"),
    ("frf.csv", "modal"),
    ("time.uff", "frf"),
    ("time.npz", "frf"),
    ("time.csv", "frf"),
    ("time.tdms", "frf"),
    ("time.mf4", "frf"),
    ("time.mat", "frf"),
    ("time.wav", "frf"),
    ("modes.uff", "damping"),
    ("geometry.uff", "geometry"),
]


def _argv(cmd: str, name: str) -> list[str]:
    if cmd == "modal":
        return ["modal", name, "-o", "m.json"]
    if cmd == "frf":
        extra = ["--channel", "1=force:N", "--channel", "2=acceleration:g"]
        return ["frf", name, "-o", "f.npz", *(extra if name.endswith(".wav") else [])]
    if cmd == "damping":
        return ["damping", name, "-o", "d.json"]
    return ["modal", "frf.npz", "--geometry", name, "-o", "m.json"]


def truncation_cases() -> list[Case]:
    out = []
    for name, cmd in _TRUNCATED:
        for frac in (0.3, 0.6, 0.97):
            cut = f"cut{int(frac * 100)}_{name}"
            files = {cut: _copy(name, frac)}
            if cmd == "geometry":
                files["frf.npz"] = _copy("frf.npz")
            out.append(Case(f"truncated-{cut}", files, _argv(cmd, cut), cut))
    return out


#: Units labels no reader may crash on (parsed with bounded length, nesting and exponents).
HOSTILE_UNITS = [
    "((((((m))))))/s^2",
    "(" * 500 + "m" + ")" * 500,
    "m^99999/s^2",
    "m/s^-99999",
    "0/0",
    "m/0",
    "1e999 m/s^2",
    "(1e200 m)^2/s^4",
    "1e-400 m/s^2",
    "m/s" + "²" * 40,
    "m" * 300,
    "m^(2)/s",
    "m^^2",
    "m/s^2^2^2^2^2^2^2",
    "m/s^1e308",
]


def unit_cases() -> list[Case]:
    out = []
    for k, label in enumerate(HOSTILE_UNITS):
        data = hc.plain_csv(f"time_s,F [N],a [{label}]", hc.time_rows())
        out.append(
            Case(
                f"units-header-{k}",
                {"t.csv": _const(data)},
                ["frf", "t.csv", "-o", "f.npz"],
                "t.csv",
            )
        )
    for k, label in enumerate(HOSTILE_UNITS[:5]):
        argv = ["frf", "t.csv", "-o", "f.npz", "--channel", f"a=acceleration:{label}"]
        good = hc.plain_csv("time_s,F [N],a", hc.time_rows())
        out.append(Case(f"units-option-{k}", {"t.csv": _const(good)}, argv, "units label"))
    for k, text in enumerate(["1e999 mV/N", "0/0 mV/N", "2 mV/(((((N)))))", "1 mV/N^99999"]):
        argv = ["frf", "t.csv", "-o", "f.npz", "--sensitivity", f"F={text}"]
        good = hc.plain_csv("time_s,F [V],a [g]", hc.time_rows())
        out.append(Case(f"sensitivity-{k}", {"t.csv": _const(good)}, argv, "sensitivity"))
    return out


def _uff_axis(unit: str, time: bool) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        x = np.arange(hc.N_SAMPLES) / hc.FS if time else hc.F_HZ
        data = hc.time_channels()[1] if time else hc.accelerance(hc.F_HZ)
        return hc.uff58_bytes(d / ".tmp.uff", x, data, unit, time)

    return make


def _nc_axis(unit: str) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        import xarray as xr

        with xr.open_dataset(lib / "frf.nc", engine="scipy") as ds:
            ds = ds.load()
        ds["frequency"].attrs["units"] = unit
        tmp = d / ".tmp.nc"
        ds.to_netcdf(str(tmp), engine="scipy")
        data = tmp.read_bytes()
        tmp.unlink()
        return data

    return make


def _tdms(xunit: str | None = None, complex_channel: bool = False) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        import nptdms

        x, y = hc.time_channels()
        props = {"wf_increment": 1.0 / hc.FS}
        if xunit is not None:
            props["wf_xunit_string"] = xunit
        a = y + 1j * y if complex_channel else y
        tmp = d / ".tmp.tdms"
        with nptdms.TdmsWriter(str(tmp)) as w:
            w.write_segment(
                [
                    nptdms.ChannelObject("M", "F", x, properties={**props, "unit_string": "N"}),
                    nptdms.ChannelObject("M", "a", a, properties={**props, "unit_string": "g"}),
                ]
            )
        data = tmp.read_bytes()
        tmp.unlink()
        return data

    return make


def _mat(variables: dict[str, np.ndarray]) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        import scipy.io

        tmp = d / ".tmp.mat"
        scipy.io.savemat(tmp, variables)
        data = tmp.read_bytes()
        tmp.unlink()
        return data

    return make


def axis_refused_cases() -> list[Case]:
    h = hc.accelerance(hc.F_HZ)
    rows = hc.frf_rows()
    plain = {
        "freq-in-s": ("freq [s],H.re [m/s^2/N],H.im [m/s^2/N]", rows, "modal"),
        "freq-in-degC": ("freq [degC],H.re [m/s^2/N],H.im [m/s^2/N]", rows, "modal"),
        "freq-in-m": ("frequency (m),H.re [m/s^2/N],H.im [m/s^2/N]", rows, "modal"),
        "time-in-kg": ("time [kg],F [N],a [g]", hc.time_rows(), "frf"),
        "time-in-h": ("time [h],F [N],a [g]", hc.time_rows(), "frf"),
        "time-in-degC": ("t [degC],F [N],a [g]", hc.time_rows(), "frf"),
    }
    out = []
    for key, (head, r, cmd) in plain.items():
        argv = _argv(cmd, "x.csv")
        out.append(
            Case(f"axis-csv-{key}", {"x.csv": _const(hc.plain_csv(head, r))}, argv, "axis unit")
        )
    for unit in ("degC", "s", "m"):
        out.append(
            Case(
                f"axis-uff-frf-{unit}",
                {"x.uff": _uff_axis(unit, False)},
                _argv("modal", "x.uff"),
                "axis unit",
            )
        )
    for unit in ("Hz", "degC"):
        files = {"x.uff": _uff_axis(unit, True)}
        argv = ["frf", "x.uff", "-o", "f.npz", "--channel", "#1=acceleration:m/s^2"]
        out.append(Case(f"axis-uff-time-{unit}", files, argv, "axis unit"))
    out.append(Case("axis-nc-s", {"x.nc": _nc_axis("s")}, _argv("modal", "x.nc"), "axis unit"))
    out.append(Case("axis-tdms-Hz", {"x.tdms": _tdms("Hz")}, _argv("frf", "x.tdms"), "axis unit"))
    mat = {"freq_s": hc.F_HZ, "H": h}
    out.append(Case("axis-mat-freq_s", {"x.mat": _mat(mat)}, _argv("modal", "x.mat"), "axis unit"))
    out.append(
        Case(
            "complex-tdms-channel",
            {"x.tdms": _tdms(complex_channel=True)},
            _argv("frf", "x.tdms"),
            "complex",
        )
    )
    return out


def _zeros_member(n: int) -> bytes:
    return hc.npy_bytes(np.zeros(n // 8))


def npz_cases() -> list[Case]:
    def with_extra(name: str, data: bytes) -> Maker:
        def make(lib: Path, d: Path) -> bytes:
            src = zipfile.ZipFile(lib / "frf.npz")
            members = {i.filename: src.read(i) for i in src.infolist()}
            members[name] = data
            return hc.zip_bytes(members)

        return make

    bomb = _zeros_member(4 << 20)  # 4 MiB of zeros: deflates about 1000-fold
    object_array = b"\x93NUMPY\x01\x00" + (118).to_bytes(2, "little")
    object_array += b"{'descr': '|O', 'fortran_order': False, 'shape': (2,), }".ljust(117) + b"\n"
    cases = {
        "member-without-npy-suffix": (with_extra("notes", b"x" * 100), "not a NumPy array"),
        "hidden-deflate-bomb": (with_extra("junk", bomb), "inflates"),
        "npy-deflate-bomb": (with_extra("extra.npy", bomb), "inflates"),
        "object-array": (with_extra("obj.npy", object_array), "object arrays"),
        "only-a-bomb": (_const(hc.zip_bytes({"H.npy": bomb})), "inflates"),
    }
    return [
        Case(f"npz-{k}", {"x.npz": make}, _argv("modal", "x.npz"), needle)
        for k, (make, needle) in cases.items()
    ]


def _campaign(depth: int, kind: str) -> Maker:
    return _const(b"[campaign]\nname = 'x'\n" + hc.deep_toml(depth, kind))


def toml_cases() -> list[Case]:
    good = hc.plain_csv("time_s,F [N],a", hc.time_rows())
    out = []
    for depth, kind in ((40, "array"), (5000, "array"), (5000, "inline"), (200, "dotted")):
        files = {"t.csv": _const(good), "map.toml": _const(hc.deep_toml(depth, kind))}
        argv = ["frf", "t.csv", "-o", "f.npz", "--channel-map", "map.toml"]
        out.append(Case(f"toml-map-{kind}-{depth}", files, argv, "nested"))
        files = {"c.toml": _campaign(depth, kind)}
        out.append(
            Case(
                f"toml-campaign-{kind}-{depth}",
                files,
                ["campaign", "c.toml", "--out", "res"],
                "nested",
            )
        )
    big = b"# " + b"x" * (5 << 20) + b"\n"
    files = {"t.csv": _const(good), "map.toml": _const(big)}
    argv = ["frf", "t.csv", "-o", "f.npz", "--channel-map", "map.toml"]
    out.append(Case("toml-map-5MiB", files, argv, "MiB"))
    return out


def _noisy_npz(scale: float) -> Maker:
    def make(lib: Path, d: Path) -> bytes:
        from tyredamp.frf import FRF
        from tyredamp.io import write_frf

        rng = np.random.default_rng(1)
        h = hc.accelerance(hc.F_HZ)
        h = h / np.abs(h).max() * (1 + 0.01 * rng.standard_normal(h.size)) * scale
        write_frf(FRF(hc.F_HZ, h[None, None, :], kind="accelerance"), d / ".tmp.npz")
        data = (d / ".tmp.npz").read_bytes()
        (d / ".tmp.npz").unlink()
        return data

    return make


def other_cases() -> list[Case]:
    out = [
        Case(
            "overflow-frf-1e300",
            {"x.npz": _noisy_npz(1e300)},
            _argv("modal", "x.npz"),
            "double precision",
        ),
        Case(
            "overflow-frf-1.7e308",
            {"x.npz": _noisy_npz(1.7e308)},
            _argv("modal", "x.npz"),
            "double precision",
        ),
    ]

    def dup55(lib: Path, d: Path) -> bytes:
        hc.modes55_duplicate_node(d / ".tmp.uff")
        data = (d / ".tmp.uff").read_bytes()
        (d / ".tmp.uff").unlink()
        return data

    def dup15(lib: Path, d: Path) -> bytes:
        hc.geometry15(d / ".tmp.uff", [1, 2, 2, 3])
        data = (d / ".tmp.uff").read_bytes()
        (d / ".tmp.uff").unlink()
        return data

    out.append(Case("uff55-duplicate-node", {"m.uff": dup55}, _argv("damping", "m.uff"), "node 2"))
    files = {"g.uff": dup15, "frf.npz": _copy("frf.npz")}
    out.append(Case("uff15-duplicate-node", files, _argv("geometry", "g.uff"), "node 2"))
    return out


CASES = [
    *truncation_cases(),
    *unit_cases(),
    *axis_refused_cases(),
    *npz_cases(),
    *toml_cases(),
    *other_cases(),
]


def test_the_corpus_is_large() -> None:
    assert len(CASES) >= 100
    assert len({c.id for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_input(
    case: Case, lib: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = run_case(case, lib, tmp_path / "case", capsys)
    assert ".tmp." not in line  # names the user's file, never a temporary


def test_full_disk_names_the_target(
    lib: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ENOSPC (``/dev/full``) is reported with the file it was writing."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    (tmp_path / "time.npz").write_bytes((lib / "time.npz").read_bytes())
    before = snapshot(tmp_path)
    os.chdir(tmp_path)
    code, _, err = run_main(["frf", "time.npz", "--out", "/dev/full", "--format", "npz"], capsys)
    line = check_one_error_line(err, code, 2, "/dev/full")
    assert "space" in line.lower()
    assert snapshot(tmp_path) == before


# ----------------------------------------------------------------------------- right answers
#: Axis units that convert: (header of the frequency column, its values per Hz).
FREQUENCY_AXES = {
    "rad/s": ("freq [rad/s]", 2 * math.pi),
    "kHz": ("freq [kHz]", 1e-3),
    "rpm": ("frequency (rpm)", 60.0),
    "cpm": ("freq [cpm]", 60.0),
    "omega": ("omega [rad/s]", 2 * math.pi),
}


@pytest.mark.parametrize("unit", list(FREQUENCY_AXES))
def test_frequency_axis_units_converted(
    unit: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A CSV frequency axis in rad/s, kHz, rpm or cpm reads as the same FRF in Hz."""
    head, per_hz = FREQUENCY_AXES[unit]
    p = tmp_path / "x.csv"
    p.write_bytes(hc.plain_csv(f"{head},H.re [m/s^2/N],H.im [m/s^2/N]", hc.frf_rows(per_hz)))
    frf = read_frf(p)
    assert_allclose(frf.frequency, hc.F_HZ, rtol=1e-14)  # one multiplication: rounding only
    assert_allclose(frf.H[0, 0], hc.accelerance(hc.F_HZ), rtol=1e-15)  # values untouched
    assert any("converted to Hz" in n for n in frf.meta["read_notes"])
    os.chdir(tmp_path)
    code, out, err = run_main(["check", "quality", "x.csv"], capsys)
    assert code == 0, err
    assert "frequency axis in" in out
    assert "converted to Hz" in out


def test_rad_per_s_axis_gives_the_modes_in_hz(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The reported case: an FRF on a rad/s axis gives its mode at 47.9 Hz, not 301 Hz."""
    import json

    p = tmp_path / "x.csv"
    p.write_bytes(
        hc.plain_csv("freq [rad/s],H.re [m/s^2/N],H.im [m/s^2/N]", hc.frf_rows(2 * math.pi))
    )
    os.chdir(tmp_path)
    code, _, err = run_main(["modal", "x.csv", "-o", "m.json"], capsys)
    assert code == 0, err
    modes = json.loads((tmp_path / "m.json").read_text())["models"]["complex"]["modes"]
    f = np.array([m["frequency_hz"] for m in modes])
    assert_allclose(f[np.argmin(abs(f - hc.F0_HZ))], hc.F0_HZ, rtol=1e-6)  # noise-free 1-DOF


@pytest.mark.parametrize(("unit", "per_s"), [("ms", 1e-3), ("us", 1e-6), ("min", 60.0), ("s", 1.0)])
def test_time_axis_units_converted(unit: str, per_s: float, tmp_path: Path) -> None:
    """A CSV time column in ms, us or min gives the sample rate in Hz."""
    p = tmp_path / "x.csv"
    p.write_bytes(hc.plain_csv(f"time [{unit}],F [N],a [g]", hc.time_rows(per_s)))
    td = read_timedata(p)
    assert_allclose(td.sample_rate, hc.FS, rtol=1e-9)  # snapped to the integer rate


def test_uff58_axis_units(tmp_path: Path) -> None:
    """UFF 58 abscissa in rad/s (FRF) and ms (time) converted from record 8's label."""
    x_rad = hc.F_HZ * 2 * math.pi
    hc.uff58_bytes(tmp_path / "f.uff", x_rad, hc.accelerance(hc.F_HZ), "rad/s", False)
    frf = read_frf(tmp_path / "f.uff")
    assert_allclose(frf.frequency, hc.F_HZ, rtol=1e-5)  # pyuff writes the axis as E13.5
    t_ms = np.arange(hc.N_SAMPLES) / hc.FS * 1e3
    data = hc.time_channels()[1]
    hc.uff58_bytes(tmp_path / "t.uff", t_ms, data, "ms", True)
    from tyredamp.io import ChannelMap

    td = read_timedata(tmp_path / "t.uff", ChannelMap.parse(["#1=acceleration:m/s^2"]))
    assert_allclose(td.sample_rate, hc.FS, rtol=1e-9)  # 1/1024 s exactly in E13.5 (binary)


def test_netcdf_tdms_mat_axis_units(tmp_path: Path, lib: Path) -> None:
    """netCDF units rad/s, TDMS wf_xunit_string ms, MAT names omega and t_ms converted."""
    (tmp_path / "x.nc").write_bytes(_nc_axis("rad/s")(lib, tmp_path))
    assert_allclose(read_frf(tmp_path / "x.nc").frequency, hc.F_HZ / (2 * math.pi), rtol=1e-15)
    (tmp_path / "x.tdms").write_bytes(_tdms("ms")(lib, tmp_path))
    assert_allclose(read_timedata(tmp_path / "x.tdms").sample_rate, hc.FS * 1e3, rtol=1e-12)
    mat = {"omega": hc.F_HZ * 2 * math.pi, "H": hc.accelerance(hc.F_HZ)}
    (tmp_path / "f.mat").write_bytes(_mat(mat)(lib, tmp_path))
    from tyredamp.io import ChannelMap

    frf = read_frf(tmp_path / "f.mat", channel_map=ChannelMap.parse(["H=acceleration:m/s^2/N"]))
    assert_allclose(frf.frequency, hc.F_HZ, rtol=1e-14)  # one division: rounding only
    x, y = hc.time_channels()
    t_ms = np.arange(hc.N_SAMPLES) / hc.FS * 1e3
    (tmp_path / "t.mat").write_bytes(_mat({"t_ms": t_ms, "F": x, "a": y})(lib, tmp_path))
    cmap = ChannelMap.parse(["F=force:N", "a=acceleration:g"])
    assert_allclose(read_timedata(tmp_path / "t.mat", cmap).sample_rate, hc.FS, rtol=1e-9)


# ----------------------------------------------------------------------------- the helpers
def test_axis_scale_factors() -> None:
    """Closed forms: 1 Hz = 2 pi rad/s = 60 rpm = 60 cpm = 1e-3 kHz; 1 s = 1e3 ms = 1/60 min."""
    for label, per_hz in (
        ("rad/s", 2 * math.pi),
        ("RPM", 60),
        ("cpm", 60),
        ("kHz", 1e-3),
        ("Hz", 1),
    ):
        assert_allclose(axis_scale(label, "frequency", "f")[0] * per_hz, 1.0, rtol=1e-15)
    for label, per_s in (("ms", 1e3), ("us", 1e6), ("µs", 1e6), ("min", 1 / 60), ("s", 1)):
        assert_allclose(axis_scale(label, "time", "t")[0] * per_s, 1.0, rtol=1e-15)
    assert axis_scale("", "frequency", "f") == (1.0, None)
    assert axis_scale("NONE", "time", "t") == (1.0, None)
    with pytest.raises(FileFormatError, match=r"x\.csv: frequency axis unit 's'"):
        axis_scale("s", "frequency", "x.csv")


def test_units_labels_bounded() -> None:
    """Every hostile label is refused in words; sane labels keep their closed-form factors."""
    for label in HOSTILE_UNITS:
        with pytest.raises(InputError, match="units label"):
            parse_unit(label)
    assert_allclose(parse_unit("(1/N)*(m/s²)").factor, 1.0)
    assert_allclose(parse_unit("mm/s^2/N").factor, 1e-3)  # mm = 1e-3 m
    assert_allclose(parse_unit("g/lbf").factor, 9.80665 / 4.4482216152605)  # definitions
    assert parse_unit("m^12").dimensions == (12, 0, 0)


def test_toml_depth_matches_the_nesting() -> None:
    """The pre-parse scan finds the nesting tomllib would recurse into (strings skipped)."""
    assert toml_depth('a = [[1], {b = [2]}]\n[x.y.z]\nc = "[[[[ not nesting"\n') == 3
    assert toml_depth("a.b.c.d = 1\n") == 4
    assert toml_depth("# [[[[[[\nx = '''\n[[[[[[\n'''\n") == 1
    for depth in (3, 30):
        assert toml_depth(hc.deep_toml(depth, "array").decode()) == depth
    assert load_toml(hc.deep_toml(30, "array").decode(), "t.toml")["x"]
    with pytest.raises(FileFormatError, match=r"t\.toml: tables or arrays nested 33 deep"):
        load_toml(hc.deep_toml(33, "array").decode(), "t.toml")


def test_archive_refused_before_inflating(tmp_path: Path) -> None:
    """A deflate bomb is refused from the archive's directory: nothing near its declared
    size is allocated (traced), with the ratio check and with a low size limit."""
    declared = 8 << 20
    p = tmp_path / "b.npz"
    p.write_bytes(hc.zip_bytes({"H.npy": hc.npy_bytes(np.zeros(declared // 8))}))
    assert p.stat().st_size < declared / 100
    tracemalloc.start()
    try:
        with pytest.raises(FileFormatError, match="inflates"):
            _check_members(p)
        with zipfile.ZipFile(p) as zf, pytest.raises(FileFormatError, match="1000 bytes allowed"):
            check_archive(zf, str(p), max_bytes=1000, max_ratio=1e9)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < declared / 8  # the archive's directory only, never the members


def test_npz_member_header_that_does_not_parse(tmp_path: Path) -> None:
    """A header cut inside its dict (NumPy's parser raises tokenize's TokenError): one line."""
    good = hc.npy_bytes(np.zeros(4))
    cut = good.index(b"}")
    p = tmp_path / "h.npz"
    p.write_bytes(hc.zip_bytes({"H.npy": good[:cut].replace(b"{", b"{(") + good[cut:]}))
    with pytest.raises(FileFormatError, match=r"H\.npy: the array's header is not readable"):
        read_timedata(p)


def test_npz_needing_a_newer_zip_version(tmp_path: Path) -> None:
    """A member that says it needs zip version 9.1 (zipfile's NotImplementedError): one line."""
    good = tmp_path / "g.npz"
    write_frf(FRF(np.linspace(1.0, 10.0, 10), np.ones((1, 1, 10), complex)), good)
    raw = bytearray(good.read_bytes())
    for signature, offset in ((b"PK\x03\x04", 4), (b"PK\x01\x02", 6)):  # local, central
        at = raw.find(signature)
        raw[at + offset] = 91  # "version needed to extract"
    p = tmp_path / "v.npz"
    p.write_bytes(bytes(raw))
    with pytest.raises(FileFormatError, match=r"v\.npz: not a readable NPZ file \(zip file"):
        read_frf(p)
