"""One FRF per record (``tyredamp.signal.records``): each hit of an impact test alone."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.signal import estimate_frf
from tyredamp.signal.records import estimate_record_frfs
from tyredamp.timedata import TimeData

from .excitation_records import respond

FS = 1000.0


def _hits(n: int = 9000, at: tuple[int, ...] = (200, 3100, 6900)) -> TimeData:
    rng = np.random.default_rng(5)
    x = np.zeros(n)
    for t0, h in zip(at, (1.0, 1.6, 0.7)[: len(at)], strict=True):
        x[t0 : t0 + 8] += h * np.sin(np.pi * np.arange(8) / 8)
    y = respond(x)
    x = x + 1e-4 * rng.standard_normal(n)
    y = y + 1e-4 * np.std(y) * rng.standard_normal(n)
    return TimeData(np.vstack([x, y]), FS, [1, 2], ["force", "acceleration"])


def test_each_record_is_its_hit_alone_and_they_average_to_the_estimate() -> None:
    td = _hits()
    frf, recs = estimate_record_frfs(td)
    assert frf.meta["method"] == "transient"
    assert len(recs) == 3
    assert_allclose(frf.H, estimate_frf(td).H, rtol=0, atol=0)  # the averaged estimate as is
    seg = int(frf.meta["segment_samples"])
    lines = np.rint(frf.frequency * seg / FS).astype(int)  # the DFT lines of one record
    num = np.zeros(lines.size, complex)
    den = np.zeros(lines.size)
    for r in recs:
        s = r.meta["record_start_sample"]
        xk = np.fft.rfft(td.data[0, s : s + seg])[lines]
        yk = np.fft.rfft(td.data[1, s : s + seg])[lines]
        # one record, rectangular windows: H = Y / X at each line (numpy's own DFT)
        assert_allclose(r.H[0, 0], yk / xk, rtol=1e-9)
        assert r.coherence is None
        assert r.variance is None
        num += yk * np.conj(xk)
        den += np.abs(xk) ** 2
    # H1 of the average = sum Y X* / sum |X|^2 over the records (Bendat & Piersol eq. 9.6)
    assert_allclose(frf.H[0, 0], num / den, rtol=1e-9)


def test_records_need_one_input_and_two_records() -> None:
    td = _hits()
    two = TimeData(
        np.vstack([td.data[0], td.data[0] * 0.5 + td.data[1], td.data[1]]),
        FS,
        [1, 3, 2],
        ["force", "force", "acceleration"],
    )
    with pytest.raises(InputError, match="force inputs"):
        estimate_record_frfs(two)
    with pytest.raises(InputError, match="no records"):
        estimate_record_frfs(td, method="lrm")
    one = _hits(4000, (200,))
    with pytest.raises(InputError, match="at least two"):
        estimate_record_frfs(one)
