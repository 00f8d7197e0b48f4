"""The per-line variance of FRF estimates: the data object, files, and the estimators."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.signal
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp import InputError, ShapeError
from tyredamp.frf import FRF
from tyredamp.io import read_frf, write_frf
from tyredamp.signal import estimate_frf
from tyredamp.timedata import TimeData

B, A = [0.5, 0.3, -0.2, 0.1], [1.0, -0.5, 0.3]  # a digital test system


def _frf() -> FRF:
    rng = np.random.default_rng(0)
    f = np.arange(1.0, 11.0)
    h = rng.normal(size=(2, 1, 10)) + 1j * rng.normal(size=(2, 1, 10))
    return FRF(f, h, "receptance", variance=rng.random((2, 1, 10)))


def test_variance_is_validated_read_only_and_carried() -> None:
    frf = _frf()
    assert frf.variance is not None
    with pytest.raises(ValueError, match="read-only"):
        frf.variance[0, 0, 0] = 1.0
    with pytest.raises(ShapeError, match="variance"):
        FRF(frf.frequency, frf.H, variance=np.ones((2, 1, 9)))
    with pytest.raises(InputError, match="variance"):
        FRF(frf.frequency, frf.H, variance=-frf.variance)
    with pytest.raises(InputError, match="variance"):
        FRF(frf.frequency, frf.H, variance=np.full((2, 1, 10), np.nan))
    band = frf.band(3.0, 6.0)
    assert_array_equal(band.variance, frf.variance[:, :, 2:6])
    sub = frf.select(outputs=[1])
    assert_array_equal(sub.variance, frf.variance[1:2])
    # H -> (i omega)^2 H scales the variance by omega^4
    acc = frf.to("accelerance")
    assert_allclose(acc.variance, frf.variance * frf.omega**4, rtol=1e-14)
    assert_allclose(acc.to("receptance").variance, frf.variance, rtol=1e-13)
    assert frf.with_H(frf.H * 2).variance is None


@pytest.mark.parametrize("ext", [".npz", ".csv", ".uff"])
def test_variance_round_trips_through_files(tmp_path: Path, ext: str) -> None:
    frf = _frf()
    back = read_frf(write_frf(frf, tmp_path / f"v{ext}"))
    assert_array_equal(back.variance, frf.variance)  # NPZ, CSV (17 digits), UFF 58b: exact
    assert_array_equal(back.H, frf.H)
    plain = FRF(frf.frequency, frf.H)
    assert read_frf(write_frf(plain, tmp_path / f"p{ext}")).variance is None


def _monte_carlo(method: str, n_runs: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Predicted (mean of the estimator's variance) and empirical variance per line."""
    rng = np.random.default_rng(11)
    one = rng.standard_normal(128)  # the same periodic force in every run (cyclic)
    hs, vs = [], []
    for _ in range(n_runs):
        if method == "cyclic":
            x = np.tile(one, 10)
            y = scipy.signal.lfilter(B, A, np.tile(one, 20))[-x.size :]
            kw: dict = {"period_samples": 128}
        else:
            x = rng.standard_normal(128 * 10)
            y = scipy.signal.lfilter(B, A, x)
            kw = {"segment_samples": 128}
        y = y + 0.3 * rng.standard_normal(y.size)
        td = TimeData(np.vstack([x, y]), 1.0, [1, 2], ["force", "displacement"])
        frf = estimate_frf(td, method=method, min_relative_power=0.0, **kw)  # type: ignore[arg-type]
        assert frf.variance is not None
        hs.append(frf.H[0, 0])
        vs.append(frf.variance[0, 0])
    h, v = np.array(hs), np.array(vs)
    emp = np.mean(np.abs(h - h.mean(axis=0)) ** 2, axis=0) * n_runs / (n_runs - 1)
    return v.mean(axis=0)[3:-3], emp[3:-3]


@pytest.mark.parametrize("method", ["welch", "cyclic"])
def test_estimated_variance_predicts_the_scatter(method: str) -> None:
    """Mean predicted variance = empirical variance of H over 200 noisy runs.

    Each line's empirical variance has a relative standard error of about
    1/sqrt(200) = 7 %; the mean over ~60 lines about 1 %: 10 % tolerance.
    Welch uses Hann windows with 50 % overlap (the overlap correction matters:
    without it the prediction would be ~25 % low).
    """
    pred, emp = _monte_carlo(method)
    assert np.mean(pred / emp) == pytest.approx(1.0, abs=0.1)


def test_noise_free_cyclic_has_zero_variance() -> None:
    one = np.random.default_rng(2).standard_normal(64)
    x = np.tile(one, 6)
    y = scipy.signal.lfilter(B, A, np.tile(one, 30))[-x.size :]
    td = TimeData(np.vstack([x, y]), 1.0, [1, 2], ["force", "displacement"])
    frf = estimate_frf(td, method="cyclic", period_samples=64)
    assert frf.variance is not None
    # zero up to the rounding of 1 - coherence (a few eps)
    assert np.max(frf.variance / np.abs(frf.H) ** 2) < 1e-14
    one_period = estimate_frf(
        TimeData(np.vstack([x[:64], y[:64]]), 1.0, [1, 2], ["force", "displacement"]),
        method="cyclic",
        period_samples=64,
    )
    assert one_period.variance is None  # one average: no degree of freedom for the noise


def test_merge_inputs_keeps_the_variance_of_each_column() -> None:
    from tyredamp.signal import merge_inputs

    a = _frf().select(inputs=[0])
    b = FRF(a.frequency, 2 * a.H, "receptance", a.outputs, [7], variance=3 * a.variance)
    m = merge_inputs([a, b])
    assert m.variance is not None
    assert_array_equal(m.variance[:, 0], a.variance[:, 0])
    assert_array_equal(m.variance[:, 1], 3 * a.variance[:, 0])
    assert merge_inputs([a, FRF(a.frequency, a.H, "receptance", a.outputs, [7])]).variance is None
