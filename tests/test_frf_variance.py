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
from tyredamp.signal.cyclic_variance import _line_average, cyclic_frf_variance, smoothing_lines
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


def _multisine(period: int, rng: np.random.Generator) -> np.ndarray:
    """One period of a flat-amplitude random-phase multisine on lines 1..period/2-1, RMS 1."""
    spec = np.zeros(period // 2 + 1, dtype=complex)
    spec[1:-1] = np.exp(2j * np.pi * rng.random(period // 2 - 1))
    x = np.fft.irfft(spec, period)
    return x / np.sqrt(np.mean(x**2))


def _cyclic_ratios(n_periods: int, noise: str, n_runs: int) -> tuple[np.ndarray, float]:
    """``|H1 - H_exact|^2 / variance`` over lines and runs, and the stated variance_dof.

    A digital system driven by a periodic multisine in steady state: the DFT of
    every period is exactly ``H(e^{i w}) X`` (``scipy.signal.freqz``), so the
    error of the estimate is the noise's alone.
    """
    period = 128
    rng = np.random.default_rng(5 + n_periods)
    one = _multisine(period, rng)
    y_clean = scipy.signal.lfilter(B, A, np.tile(one, n_periods + 20))[-period * n_periods :]
    x_clean = np.tile(one, n_periods)
    sx = 0.05 if noise in ("force", "both") else 0.0  # 26 dB below the force's RMS
    sy = 0.05 * np.std(y_clean) if noise in ("responses", "both") else 0.0
    ratios, dof = [], np.nan
    for _ in range(n_runs):
        x = x_clean + sx * rng.standard_normal(x_clean.size)
        y = y_clean + sy * rng.standard_normal(y_clean.size)
        td = TimeData(np.vstack([x, y]), 1.0, [1, 2], ["force", "displacement"])
        # the multisine's lines (without them, 0 Hz and Nyquist carry the force noise alone)
        band = (0.5 / period, (period // 2 - 0.5) / period)
        frf = estimate_frf(td, method="cyclic", period_samples=period, band=band)
        assert frf.variance is not None
        assert frf.frequency.size == period // 2 - 1
        _, h_exact = scipy.signal.freqz(B, A, worN=2 * np.pi * frf.frequency)
        ratios.append(np.abs(frf.H[0, 0] - h_exact) ** 2 / frf.variance[0, 0])
        dof = float(frf.meta["variance_dof"])
    return np.concatenate(ratios), dof


@pytest.mark.parametrize("noise", ["force", "responses", "both"])
@pytest.mark.parametrize("n_periods", [2, 4, 8, 16])
def test_cyclic_variance_is_calibrated_with_noise_anywhere(n_periods: int, noise: str) -> None:
    """The ratio of the squared error to the variance follows F(2, variance_dof).

    A variance estimated with ``d`` real degrees of freedom, independent of
    the error, makes ``|H - H_exact|^2 / variance`` an F(2, d) variable: mean
    ``d / (d - 2)``, median ``d (2^(2/d) - 1) / 2``; the errors-in-variables
    variance of :mod:`tyredamp.signal.cyclic_variance` holds for noise on the
    force, the response or both, and from 2 periods on states at least 20
    degrees of freedom. 30 runs x 63 lines (neighbouring lines share the
    line-averaged noise, so about 30 x 63 / L independent ratios): the mean's
    standard error is about 0.04 (2 periods) and less for more periods, the
    median's about 0.03: tolerances 0.15 and 0.1 (some 3.5 standard errors).
    """
    r, d = _cyclic_ratios(n_periods, noise, n_runs=30)
    assert d >= 20.0
    assert d == 2.0 * (n_periods - 1) * smoothing_lines(n_periods, 63)
    assert np.mean(r) == pytest.approx(d / (d - 2), abs=0.15)
    assert np.median(r) == pytest.approx(d * (2 ** (2 / d) - 1) / 2, abs=0.1)


def test_smoothing_lines_is_the_fewest_odd_count_for_the_target() -> None:
    # 2 (n - 1) L >= 20 with L odd: n = 2 -> 11, 3 -> 5, 4 -> 5, 6 -> 3, 11 -> 1
    got = [smoothing_lines(n, 1000) for n in (2, 3, 4, 6, 11, 40)]
    assert got == [11, 5, 5, 3, 1, 1]
    assert smoothing_lines(2, 8) == 7  # capped by the lines there are, kept odd
    assert smoothing_lines(2, 1) == 1


def test_cyclic_variance_matches_the_sample_covariance_of_the_periods() -> None:
    """The spectra-based algebra equals the first-order variance from np.cov of the periods.

    ``var(H) = [-H 1] C [-H 1]^H / (n |Xbar|^2)`` with ``C`` the sample
    covariance (``n - 1``) of ``[X_k, Y_k]``, computed here directly; 12
    periods give ``L = 1`` (no line averaging). Same arithmetic in another
    order: rtol 1e-10.
    """
    rng = np.random.default_rng(3)
    n, n_f, c = 12, 5, 0.37
    xk = 2.0 + 0.1 * (rng.normal(size=(n, n_f)) + 1j * rng.normal(size=(n, n_f)))
    yk = (1 - 2j) * xk + 0.2 * (rng.normal(size=(n, n_f)) + 1j * rng.normal(size=(n, n_f)))
    h = (np.mean(yk * xk.conj(), axis=0) / np.mean(np.abs(xk) ** 2, axis=0))[None, None, :]
    got = cyclic_frf_variance(
        c * np.mean(np.abs(xk) ** 2, axis=0),
        c * np.mean(yk * xk.conj(), axis=0)[:, None],
        c * np.mean(np.abs(yk) ** 2, axis=0)[:, None],
        (xk.mean(axis=0), yk.mean(axis=0)[:, None]),
        np.full(n_f, c),
        h,
        n,
    )
    assert got is not None
    var, dof = got
    assert dof == 2.0 * (n - 1)
    want = np.empty(n_f)
    for f in range(n_f):
        cov = np.cov(np.vstack([xk[:, f], yk[:, f]]))  # rows: variables; n - 1
        v = np.array([-h[0, 0, f], 1.0])
        want[f] = np.real(v.conj() @ cov.T @ v) / (n * abs(xk[:, f].mean()) ** 2)
    assert_allclose(var[0, 0], want, rtol=1e-10)


def test_line_average_is_a_moving_mean_shifted_inside_the_axis() -> None:
    a = np.arange(10.0) ** 2
    got = _line_average(a, 3)
    assert_allclose(got[1:-1], np.convolve(a, np.ones(3) / 3, mode="valid"), rtol=1e-14)
    assert got[0] == pytest.approx(np.mean(a[:3]), rel=1e-14)  # shifted, not shortened
    assert got[-1] == pytest.approx(np.mean(a[-3:]), rel=1e-14)
