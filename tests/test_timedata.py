"""TimeData and its typed acquisition record."""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp import InputError
from tyredamp.signal import estimate_frf, pseudo_random
from tyredamp.timedata import ACQUISITION_KEYS, Acquisition, TimeData


def _td(**kw) -> TimeData:
    rng = np.random.default_rng(0)
    return TimeData(rng.normal(size=(2, 1000)), 100.0, [1, 2], ["force", "acceleration"], **kw)


def test_acquisition_fields_validated() -> None:
    a = Acquisition(period_samples=np.int64(100), run_starts=[0, 400], band_hz=[1, 20])
    assert a.period_samples == 100
    assert isinstance(a.period_samples, int)
    assert a.run_starts == (0, 400)
    assert a.band_hz == (1.0, 20.0)
    assert Acquisition.from_dict(a.to_dict()) == a
    assert set(a.to_dict()) <= ACQUISITION_KEYS
    for kw, word in [
        ({"period_samples": 1}, "period_samples"),
        ({"period_samples": 2.5}, "period_samples"),
        ({"run_starts": (5, 10)}, "run_starts"),
        ({"run_starts": (0, 10, 10)}, "run_starts"),
        ({"run_starts": "0"}, "run_starts"),
        ({"settle_samples": -1}, "settle_samples"),
        ({"band_hz": (20.0, 1.0)}, "band_hz"),
        ({"band_hz": (0.0, float("nan"))}, "band_hz"),
        ({"n_averages": 0}, "n_averages"),
    ]:
        with pytest.raises(InputError, match=word):
            Acquisition(**kw)
    with pytest.raises(InputError, match="unknown field"):
        Acquisition.from_dict({"period_sample": 100})


def test_acquisition_must_fit_the_record() -> None:
    with pytest.raises(InputError, match="run_starts"):
        _td(acquisition=Acquisition(run_starts=(0, 1000)))
    with pytest.raises(InputError, match="period_samples"):
        _td(acquisition=Acquisition(period_samples=1001))
    with pytest.raises(InputError, match="acquisition"):
        _td(acquisition={"period_samples": 100})


def test_legacy_meta_keys_move_into_acquisition() -> None:
    td = _td(meta={"period_samples": 100, "n_periods": 10, "operator": "me"})
    assert td.acquisition == Acquisition(period_samples=100, n_averages=10)
    assert td.meta == {"operator": "me"}
    with pytest.raises(InputError, match="give them once"):
        _td(meta={"period_samples": 100}, acquisition=Acquisition(period_samples=100))


@pytest.mark.parametrize("key", ["period_sample", "settle_sample", "runstarts", "record_sample"])
def test_misspelt_acquisition_key_is_an_error_not_a_silent_method_change(key: str) -> None:
    with pytest.raises(InputError, match=key):
        _td(meta={key: 100})


def test_estimator_reads_acquisition_only() -> None:
    exc = pseudo_random(256.0, 256, (5.0, 60.0), rng=np.random.default_rng(1), n_periods=8)
    resp = np.roll(exc.signal, 3) * 2.0  # y = 2 x(t - 3 samples), exactly periodic
    data = np.vstack([exc.signal, resp])
    td = TimeData(data, 256.0, [1, 2], ["force", "displacement"], acquisition=exc.acquisition())
    frf = estimate_frf(td)
    assert frf.meta["method"] == "cyclic"
    assert frf.meta["segment_samples"] == 256
    notes = TimeData(data, 256.0, [1, 2], ["force", "displacement"], meta={"note": 1})
    assert estimate_frf(notes, detect=False).meta["method"] == "welch"  # notes are not read
    # a misspelt field is refused rather than left as a note
    with pytest.raises(InputError, match="period_sample"):
        TimeData(data, 256.0, [1, 2], ["force", "displacement"], meta={"period_sample": 256})
