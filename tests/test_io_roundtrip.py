"""File round trips: FRF and TimeData through UFF 58b/58, CSV and NPZ lose nothing."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import Channel, FileFormatError, InputError
from tyredamp.frf import FRF
from tyredamp.io import read, read_frf, read_timedata, write_frf, write_timedata
from tyredamp.timedata import Acquisition, TimeData

LOSSLESS = ["uff58b", "csv", "npz"]
EXT = {"uff58b": ".uff", "uff58": ".unv", "csv": ".csv", "npz": ".npz"}


def assert_same_frf(a: FRF, b: FRF, rtol: float = 0.0) -> None:
    assert b.kind == a.kind
    assert b.outputs == a.outputs  # node, direction, angle, name
    assert b.inputs == a.inputs
    if rtol == 0.0:
        assert_array_equal(b.frequency, a.frequency)
        assert_array_equal(b.H, a.H)
    else:
        assert_allclose(b.frequency, a.frequency, rtol=1e-15)
        assert_allclose(b.H, a.H, rtol=rtol)
    if a.coherence is None:
        assert b.coherence is None
    else:
        assert b.coherence is not None
        assert_allclose(b.coherence, a.coherence, rtol=rtol, atol=0)


def assert_same_timedata(a: TimeData, b: TimeData, rtol: float = 0.0) -> None:
    assert b.sample_rate == a.sample_rate
    assert b.channels == a.channels
    assert b.quantities == a.quantities
    assert b.meta == a.meta
    assert b.acquisition == a.acquisition
    if rtol == 0.0:
        assert_array_equal(b.data, a.data)
    else:
        assert_allclose(b.data, a.data, rtol=rtol, atol=0)


def sample_frf(rng: np.random.Generator, n_out=3, n_in=2, n_freq=37, coherence=True) -> FRF:
    f = np.arange(3, 3 + n_freq) * (2048 / 3000)  # rfft-style lines k * fs / N
    h = rng.normal(size=(n_out, n_in, n_freq)) + 1j * rng.normal(size=(n_out, n_in, n_freq))
    outs = [Channel(i + 1, 3, 22.5 * i, f"acc{i + 1:02d}") for i in range(n_out)]
    ins = [Channel(100 + j, -3 if j else 3) for j in range(n_in)]
    coh = rng.random((n_out, n_freq)) if coherence else None
    meta = {"estimator": "H1", "n_averages": 8}
    return FRF(f, h, "accelerance", outs, ins, coh, meta)


def sample_timedata(rng: np.random.Generator) -> TimeData:
    chans = [Channel(1, 3, 0.0, "force"), Channel(1, 3, 0.0), Channel(2, 3, 22.5), Channel(9, 2)]
    data = rng.normal(size=(4, 1000)) * np.array([[10.0], [3.0], [1e-3], [5e4]])
    return TimeData(
        data,
        2048.0,
        chans,
        ["force", "acceleration", "velocity", "displacement"],
        meta={"operator": "io"},
        acquisition=Acquisition(
            period_samples=500,
            run_starts=(0, 500),
            settle_samples=0,
            band_hz=(2.0, 300.0),
            n_averages=1,
            excitation="pseudo_random",
        ),
    )


@pytest.mark.parametrize("fmt", LOSSLESS)
def test_frf_round_trip_exact(tmp_path: Path, fmt: str) -> None:
    frf = sample_frf(np.random.default_rng(1))
    p = write_frf(frf, tmp_path / f"frf{EXT[fmt]}", fmt)
    back = read_frf(p)
    assert_same_frf(frf, back)  # bit for bit
    assert back.meta == frf.meta


def test_frf_round_trip_ascii_uff(tmp_path: Path) -> None:
    frf = sample_frf(np.random.default_rng(2))
    back = read_frf(write_frf(frf, tmp_path / "frf.unv", "uff58"))
    # E20.12 fields hold 12 significant digits: relative error <= 5e-12; the
    # frequency axis is rebuilt exactly from ID line 2
    assert_same_frf(frf, back, rtol=1e-11)
    assert_array_equal(back.frequency, frf.frequency)
    with pytest.raises(InputError, match="uneven frequency axis"):
        write_frf(frf.select_lines([0, 1, 5]), tmp_path / "x.unv", "uff58")
    assert not (tmp_path / "x.unv").exists()
    # binary UFF keeps an uneven axis exactly
    uneven = frf.select_lines([0, 1, 5])
    assert_same_frf(uneven, read_frf(write_frf(uneven, tmp_path / "x.uff")))


@pytest.mark.parametrize("fmt", [*LOSSLESS, "uff58"])
def test_timedata_round_trip(tmp_path: Path, fmt: str) -> None:
    td = sample_timedata(np.random.default_rng(3))
    back = read_timedata(write_timedata(td, tmp_path / f"td{EXT[fmt]}", fmt))
    assert_same_timedata(td, back, rtol=1e-11 if fmt == "uff58" else 0.0)


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_out=st.integers(1, 4),
    n_in=st.integers(1, 3),
    n_freq=st.integers(1, 40),
    kind=st.sampled_from(["receptance", "mobility", "accelerance"]),
    fmt=st.sampled_from(LOSSLESS),
    name=st.text(alphabet="abcXYZ019_-+. ", max_size=12),
    coherence=st.booleans(),
)
def test_frf_round_trip_property(
    tmp_path, seed, n_out, n_in, n_freq, kind, fmt, name, coherence
) -> None:
    g = np.random.default_rng(seed)
    f = np.sort(g.choice(np.arange(1, 10_000), n_freq, replace=False)) * g.uniform(1e-3, 10)
    h = (
        g.normal(size=(n_out, n_in, n_freq)) + 1j * g.normal(size=(n_out, n_in, n_freq))
    ) * 10 ** g.uniform(-8, 4)
    outs = [
        Channel(
            int(g.integers(1, 10**6)) * 10 + i,
            int(g.choice([1, 2, 3, -3])),
            None if i % 2 else float(g.uniform(-360, 360)),
            name if i == 0 else "",
        )
        for i in range(n_out)
    ]
    ins = [Channel(7 + 10 * j, 3, None, f"F{j}") for j in range(n_in)]
    coh = g.random((n_out, n_freq)) if coherence else None
    frf = FRF(f, h, kind, outs, ins, coh, {"k": [1, 2.5, "x"]})
    back = read_frf(write_frf(frf, tmp_path / f"p{EXT[fmt]}", fmt))
    assert_same_frf(frf, back)


def test_read_dispatch_and_type_errors(tmp_path: Path) -> None:
    rng = np.random.default_rng(4)
    td, frf = sample_timedata(rng), sample_frf(rng)
    for fmt in LOSSLESS:
        pt = write_timedata(td, tmp_path / f"t{EXT[fmt]}", fmt)
        pf = write_frf(frf, tmp_path / f"f{EXT[fmt]}", fmt)
        assert isinstance(read(pt), TimeData)
        assert isinstance(read(pf), FRF)
        with pytest.raises(FileFormatError, match=r"not an FRF|no FRF"):
            read_frf(pt)
        with pytest.raises(FileFormatError, match=r"not time data|no time response"):
            read_timedata(pf)
    with pytest.raises(InputError, match="unknown file extension"):
        write_frf(frf, tmp_path / "x.xls")
    with pytest.raises(FileFormatError, match="unknown file extension"):
        read_frf(tmp_path / "x.xls")
    with pytest.raises(FileNotFoundError):
        read_frf(tmp_path / "missing.uff")
    with pytest.raises(InputError, match="format"):
        write_frf(frf, tmp_path / "x.uff", "xlsx")


def test_writes_are_atomic_and_inputs_untouched(tmp_path: Path, monkeypatch) -> None:
    rng = np.random.default_rng(5)
    frf = sample_frf(rng)
    src = write_frf(frf, tmp_path / "in.uff")
    digest = hashlib.sha256(src.read_bytes()).hexdigest()
    mtime = src.stat().st_mtime_ns
    for _ in range(2):
        read_frf(src)
    assert hashlib.sha256(src.read_bytes()).hexdigest() == digest  # reading never modifies
    assert src.stat().st_mtime_ns == mtime

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(np, "savetxt", boom)
    with pytest.raises(OSError, match="disk full"):
        write_frf(frf, tmp_path / "out.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.uff"]  # no partial file left
    # an existing target survives a failed write unchanged
    with pytest.raises(OSError, match="disk full"):
        write_frf(frf, src.with_suffix(".csv"))
    monkeypatch.undo()
    with pytest.raises(InputError, match="JSON-compatible"):
        write_frf(FRF(frf.frequency, frf.H, meta={"bad": object()}), tmp_path / "m.npz")
    assert not (tmp_path / "m.npz").exists()


@pytest.mark.parametrize("fmt", [*LOSSLESS, "uff58"])
def test_old_files_with_acquisition_in_meta_still_read(tmp_path: Path, fmt: str) -> None:
    """Files written before ``Acquisition`` kept its fields in ``meta``: they read the same."""
    td = sample_timedata(np.random.default_rng(4))
    legacy = {"period_samples": 500, "settle_samples": 100, "band_hz": [2.0, 300.0]}
    path = tmp_path / f"old{EXT[fmt]}"
    if fmt == "csv":
        write_timedata(TimeData(td.data, td.sample_rate, td.channels, td.quantities), path, fmt)
        text = path.read_text().replace(
            "# sample_rate", f"# meta: {json.dumps(legacy)}\n# sample_rate"
        )
        path.write_text(text)
    elif fmt == "npz":
        write_timedata(TimeData(td.data, td.sample_rate, td.channels, td.quantities), path, fmt)
        with np.load(path) as z:
            head = json.loads(str(z["header"][()]))
            data = z["data"]
        head.pop("acquisition", None)
        head["meta"] = legacy
        np.savez(path, header=np.array(json.dumps(head)), data=data)
    else:  # UFF always kept them as meta keys on an ID line
        write_timedata(td, path, fmt)
    back = read_timedata(path)
    if fmt.startswith("uff"):
        assert back.acquisition == td.acquisition
    else:
        assert back.acquisition == Acquisition(
            period_samples=500, settle_samples=100, band_hz=(2.0, 300.0)
        )
        assert back.meta == {}


def test_uff_keeps_many_runs_or_refuses(tmp_path: Path) -> None:
    """Evenly spaced runs fit an ID line as run_every; a field that cannot fit is an error."""
    rng = np.random.default_rng(5)
    d = rng.normal(size=(2, 3200))
    acq = Acquisition(period_samples=100, run_starts=tuple(range(0, 3200, 200)), settle_samples=100)
    td = TimeData(d, 1000.0, [1, 2], ["force", "acceleration"], acquisition=acq)
    back = read_timedata(write_timedata(td, tmp_path / "runs.uff"))
    assert back.acquisition == acq
    uneven = Acquisition(run_starts=(0, *(100 * k + k * k for k in range(1, 25))))
    td = TimeData(d, 1000.0, [1, 2], ["force", "acceleration"], acquisition=uneven)
    with pytest.raises(InputError, match="run_starts"):
        write_timedata(td, tmp_path / "uneven.uff")
    assert not (tmp_path / "uneven.uff").exists()
    assert read_timedata(write_timedata(td, tmp_path / "uneven.npz")).acquisition == uneven


@pytest.mark.parametrize("fmt", [*LOSSLESS, "uff58"])
def test_long_meta_round_trips_in_every_writer(tmp_path: Path, fmt: str) -> None:
    """Metadata longer than the UFF ID lines (a lateral rig's conditions and truth) survive."""
    rng = np.random.default_rng(4)
    meta = {
        "speed_m_s": 5 / 3.6,
        "speed_kmh": 5.0,
        "pressure_bar": 1.7,
        "force": "axle",
        "wheel_mass_kg": 100.0,
        "label": "  1.7 bar, 5 km/h  ",  # leading/trailing blanks kept
        "truth": {"params": {"C_alpha": 8e4, "sigma": 0.5932605191260101}, "units": ["N/rad"]},
        "description": "a description " * 12 + "ünïcode \\u0020 NONE",
        "estimator": "H1",
    }
    frf = sample_frf(rng, n_out=2, n_in=1)
    frf = FRF(frf.frequency, frf.H, frf.kind, frf.outputs, frf.inputs, frf.coherence, meta)
    back = read_frf(write_frf(frf, tmp_path / f"frf{EXT[fmt]}", fmt))
    assert back.meta == meta
    td = sample_timedata(rng)
    td = TimeData(
        td.data,
        td.sample_rate,
        td.channels,
        td.quantities,
        meta={**meta, "x": [1] * 99},
        acquisition=td.acquisition,
    )
    back_t = read_timedata(write_timedata(td, tmp_path / f"td{EXT[fmt]}", fmt))
    assert back_t.meta == td.meta
    assert back_t.acquisition == td.acquisition  # typed, beside the metadata record


def test_uff_meta_record_is_deterministic_and_readable_by_pyuff(tmp_path: Path) -> None:
    import pyuff

    rng = np.random.default_rng(5)
    frf = sample_frf(rng, n_out=1, n_in=1)
    frf.meta["truth"] = {"params": list(range(200))}
    a = write_frf(frf, tmp_path / "a.uff").read_bytes()
    b = write_frf(frf, tmp_path / "b.uff").read_bytes()
    assert a == b
    sets = pyuff.UFF(str(tmp_path / "a.uff")).read_sets()
    heads = [s for s in sets if s["type"] == 151]
    assert len(heads) >= 2
    assert heads[0]["model_name"].startswith("tyredamp1 meta 1 ")
    assert [s["func_type"] for s in sets if s["type"] == 58] == [4, 6]
    # a missing part is an error, not a silent loss
    raw = (tmp_path / "a.uff").read_bytes()
    first = raw.index(b"    -1\n   151")
    second = raw.index(b"    -1\n   151", first + 10)
    (tmp_path / "c.uff").write_bytes(raw[:first] + raw[second:])
    with pytest.raises(FileFormatError, match="incomplete tyredamp metadata record"):
        read_frf(tmp_path / "c.uff")
    # a damaged record is an error naming it, and the file is left as it was
    bad = raw.replace(b'{"estimator"', b'{"estimator"}}', 1)
    (tmp_path / "d.uff").write_bytes(bad)
    with pytest.raises(FileFormatError, match="metadata record"):
        read_frf(tmp_path / "d.uff")
    assert (tmp_path / "d.uff").read_bytes() == bad
