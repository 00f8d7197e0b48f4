"""Excitation detected from the data: periodic (period, start transient), random, impact."""

from __future__ import annotations

import gc
import warnings
from pathlib import Path

import numpy as np
import pytest
import pyuff
import scipy.signal
from numpy.testing import assert_allclose

from tyredamp import InputError
from tyredamp.cli import main
from tyredamp.io import read_frf
from tyredamp.signal import estimate_frf
from tyredamp.signal.periodicity import detect_excitation, repetition_error, transient_periods
from tyredamp.timedata import TimeData

from .excitation_records import (
    exact_frf,
    impact_record,
    periodic_record,
    random_record,
    respond,
)

FS = 1000.0  # Hz: 997 samples is 0.997 s, not a whole number of seconds


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        main(list(argv))
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def write_with_pyuff(path: Path, x: np.ndarray, y: np.ndarray, binary: bool) -> None:
    """Force and acceleration as plain UFF 58 time data, no tyredamp metadata at all."""
    sets = []
    for k, (sig, q) in enumerate(((x, "force"), (y, "acceleration"))):
        sets.append(
            pyuff.prepare_58(
                binary=int(binary),
                id1=f"DAQ channel {k + 1}",
                func_type=1,
                rsp_node=k + 1,
                rsp_dir=3,
                ref_node=0,
                ref_dir=0,
                data=sig,
                x=np.arange(sig.size) / FS,
                abscissa_spacing=1,
                abscissa_min=0.0,
                abscissa_inc=1.0 / FS,
                abscissa_spec_data_type=17,
                ordinate_spec_data_type=13 if q == "force" else 12,
                ordinate_axis_units_lab="N" if q == "force" else "m/s^2",
                orddenom_spec_data_type=0,
            )
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)  # pyuff leaves a handle to the GC
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
        gc.collect()


@pytest.mark.parametrize("kind", ["multisine", "chirp"])
@pytest.mark.parametrize("period", [1024, 997])
@pytest.mark.parametrize("transient", [False, True])
def test_pyuff_periodic_time_data_gives_the_exact_frf(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, kind: str, period: int, transient: bool
) -> None:
    rng = np.random.default_rng(period + transient)
    x, y, lines = periodic_record(kind, period, 10, rng, transient)
    binary = period % 2 == 0  # ASCII (12 digits) for the odd period, 58b for the other
    src = tmp_path / "daq.unv"
    write_with_pyuff(src, x, y, binary)
    out = tmp_path / "frf.npz"
    code, stdout, err = run(capsys, "frf", str(src), "--out", str(out))
    assert code == 0, err
    assert "method cyclic" in stdout
    assert f"detected periodic: the force repeats every {period} samples" in stdout
    assert ("start transient" in stdout) == transient
    frf = read_frf(out)
    k = np.round(frf.frequency * period / FS).astype(int)
    assert_allclose(frf.frequency, k * FS / period, rtol=1e-12)
    sel = np.isin(k, lines)
    assert sel.sum() == lines.size  # every excited line is kept
    h = exact_frf(k[sel], period)
    # noise-free: exact up to the storage (12 digits ASCII) and the transient left
    # below the 1e-9 storage floor of the settle detection
    rel = np.abs(frf.H[0, 0, sel] - h) / np.abs(h)
    assert rel.max() < 1e-6
    assert frf.meta["detection"]["period_samples"] == period
    assert (frf.meta["settle_samples"] > 0) == transient


def test_random_and_impact_records_are_never_periodic() -> None:
    """At least 100 generated records of each kind: none classified periodic."""
    rng = np.random.default_rng(2026)
    wrong = {"random": 0, "impact": 0}
    for _ in range(120):
        n = int(rng.integers(1500, 12000))
        x, y = random_record(n, rng)
        wrong["random"] += detect_excitation(x, y).kind != "random"
        x, y = impact_record(n, rng)
        wrong["impact"] += detect_excitation(x, y).kind != "impact"
    assert wrong == {"random": 0, "impact": 0}


def test_noisy_periodic_is_detected_and_reported() -> None:
    rng = np.random.default_rng(5)
    x, y, _ = periodic_record("multisine", 777, 8, rng, True)
    xn = x + 0.1 * rng.standard_normal(x.size)  # 20 dB
    yn = y + 0.1 * np.std(y) * rng.standard_normal(x.size)
    det = detect_excitation(xn, yn)
    assert det.kind == "periodic"
    assert det.period_samples == 777
    assert det.settle_samples % 777 == 0
    assert 0.97 < det.periodic_fraction < 1.0  # 1 / (1 + 0.01)
    assert det.p_value < 1e-12


def test_non_integer_period_in_samples_gives_the_whole_multiple() -> None:
    n = 20000
    x = np.sin(2 * np.pi * np.arange(n) / 441.5)  # period 441.5 samples
    det = detect_excitation(x, respond(x))
    assert det.kind == "periodic"
    assert det.period_samples == 883


def test_repetition_error_matches_its_definition() -> None:
    rng = np.random.default_rng(3)
    x = rng.standard_normal((2, 300))
    e = repetition_error(x, 100)
    for k in (1, 7, 100):
        d = np.sum((x[:, k:] - x[:, :-k]) ** 2)
        s = np.sum(x[:, k:] ** 2 + x[:, :-k] ** 2)
        assert e[k] == pytest.approx(d / s, rel=1e-12)
    periodic = np.tile(rng.standard_normal(50), 6)
    assert repetition_error(periodic, 150)[[50, 100, 150]] == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(InputError, match="max_lag"):
        repetition_error(x, 300)


def test_transient_periods_counts_the_periods_to_skip() -> None:
    rng = np.random.default_rng(4)
    x, y, _ = periodic_record("multisine", 500, 12, rng, True)
    s = transient_periods(np.vstack([x, y]), 500)
    # decay of the slowest mode: exp(-zeta w) per sample, 2 % at 0.06 fs
    decay = np.exp(-0.02 * 2 * np.pi * 0.06 * 500)
    assert decay ** (s - 1) > 1e-10  # the last skipped period still held a transient
    x2, y2, _ = periodic_record("multisine", 500, 12, rng, False)
    assert transient_periods(np.vstack([x2, y2]), 500) == 0
    with pytest.raises(InputError, match="two whole periods"):
        transient_periods(x2[:700], 500)


def test_detection_bad_input() -> None:
    with pytest.raises(InputError, match="alpha"):
        detect_excitation(np.ones(100), alpha=0.7)
    with pytest.raises(InputError, match="min_periods"):
        detect_excitation(np.ones(100), min_periods=2)
    with pytest.raises(InputError, match="responses"):
        detect_excitation(np.ones(100), np.ones(99))
    with pytest.raises(InputError, match="finite"):
        detect_excitation([1.0, np.nan, 2.0])


def test_period_and_settle_options(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    rng = np.random.default_rng(6)
    x, y, _ = periodic_record("chirp", 500, 8, rng, True)
    src = tmp_path / "daq.uff"
    write_with_pyuff(src, x, y, True)
    out = tmp_path / "frf.npz"
    code, _, err = run(
        capsys, "frf", str(src), "--out", str(out), "--period", "0.5s", "--settle", "3000"
    )
    assert code == 0, err
    frf = read_frf(out)
    assert frf.meta["segment_samples"] == 500
    assert frf.meta["settle_samples"] == 3000
    assert "detection" not in frf.meta
    # --period alone: the start transient is still found in the data
    out2 = tmp_path / "frf2.npz"
    code, _, err = run(capsys, "frf", str(src), "--out", str(out2), "--period", "500")
    assert code == 0, err
    assert read_frf(out2).meta["settle_samples"] > 0
    # --method cyclic without a period finds it
    out3 = tmp_path / "frf3.npz"
    code, _, err = run(capsys, "frf", str(src), "--out", str(out3), "--method", "cyclic")
    assert code == 0, err
    assert read_frf(out3).meta["segment_samples"] == 500
    for bad, word in (("0.5005s", "not a whole"), ("abc", "expected samples"), ("-3", "non-neg")):
        dst = tmp_path / "bad.npz"
        code, _, err = run(capsys, "frf", str(src), "--out", str(dst), "--period", bad)
        assert code == 2
        assert word in err
        assert err.startswith("tyredamp: error: --period")
        assert not dst.exists()


def test_cyclic_on_random_data_names_the_reason(tmp_path: Path) -> None:
    rng = np.random.default_rng(8)
    x, y = random_record(4000, rng)
    td = TimeData(np.vstack([x, y]), FS, [1, 2], ["force", "acceleration"])
    with pytest.raises(InputError, match="none found in the data"):
        estimate_frf(td, method="cyclic")
    assert estimate_frf(td).meta["detection"]["kind"] == "random"
    assert estimate_frf(td).meta["method"] == "welch"
    xi, yi = impact_record(4000, rng)
    td = TimeData(np.vstack([xi, yi]), FS, [1, 2], ["force", "acceleration"])
    frf = estimate_frf(td)
    assert frf.meta["method"] == "transient"
    assert frf.meta["detection"]["kind"] == "impact"


def test_narrow_band_random_is_not_periodic() -> None:
    """A lightly damped resonator driven by noise repeats itself over many cycles.

    Neighbouring "periods" are alike (correlation time ~3000 samples), which the
    F ratio alone would take for periodicity; the serial test of the residual
    rejects it.
    """
    rng = np.random.default_rng(12)
    w, z = 0.025, 0.0015
    r = np.exp(-z * 2 * np.pi * w)
    a = [1.0, -2 * r * np.cos(2 * np.pi * w), r * r]
    bad = 0
    for _ in range(20):
        x = scipy.signal.lfilter([1.0], a, rng.standard_normal(25000))[5000:]
        bad += detect_excitation(x).kind != "random"
    assert bad == 0


def test_period_is_not_a_fraction_of_the_true_one() -> None:
    """A narrow-band periodic chirp nearly repeats every half period: the full one is found."""
    from tyredamp.signal import periodic_chirp

    for p in (404, 384, 216, 202):
        e = periodic_chirp(1000.0, p, (50.0, 60.0), n_periods=30)
        det = detect_excitation(e.signal, respond(e.signal))
        assert det.kind == "periodic"
        assert det.period_samples == p


def test_burst_random_is_cut_into_its_records() -> None:
    from tyredamp.signal import burst_random

    e = burst_random(1000.0, 1000, (5.0, 300.0), n_records=12, rng=np.random.default_rng(3))
    det = detect_excitation(e.signal, respond(e.signal))
    assert det.kind == "impact"
    assert det.record_starts == tuple(range(0, 12000, 1000))
    assert det.record_samples == 1000


def test_quality_check_of_periodic_data_without_metadata_is_not_clipping() -> None:
    """Each period reaches the same extreme: not flat-topping once the period is detected."""
    from tyredamp.signal import quality_check

    x, y, _ = periodic_record("multisine", 500, 8, np.random.default_rng(0), False)
    td = TimeData(np.vstack([x, y]), FS, [1, 2], ["force", "acceleration"])
    res = quality_check(td)
    assert res.figures["clipped_channels"] == 0
    assert res.passed, res.report()
    clipped = np.minimum(y, 0.6 * y.max())  # a real overload is still found
    res = quality_check(TimeData(np.vstack([x, clipped]), FS, [1, 2], ["force", "acceleration"]))
    assert res.figures["clipped_channels"] == 1


def test_steady_data_with_noise_shared_by_channels_has_no_transient() -> None:
    """Force noise reaches every response: channels are correlated, periods still steady."""
    from tyredamp.signal import periodic_chirp

    rng = np.random.default_rng(0)
    x = periodic_chirp(1024.0, 3000, (1.0, 200.0), n_periods=40).signal
    xn = x + 0.01 * rng.standard_normal(x.size)
    y = np.tile(xn, (16, 1)) + 0.01 * rng.standard_normal((16, x.size))
    assert transient_periods(np.vstack([xn, y]), 3000) == 0
