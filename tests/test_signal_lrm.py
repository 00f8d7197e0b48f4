"""Local rational / polynomial FRF estimation against the exact FRF of a digital system."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from tyredamp import InputError
from tyredamp.modal.problem.problem import build_problem
from tyredamp.signal import estimate_frf
from tyredamp.signal.lrm import local_frf, local_variance_dof
from tyredamp.timedata import Acquisition, TimeData

# two lightly damped modes (0.5 % and 0.3 %): the exact FRF is B/A at exp(2 pi i f)
_POLES = []
for _f, _z in ((0.05, 0.005), (0.13, 0.003)):
    _w = 2 * np.pi * _f
    _POLES += [np.exp(-_z * _w + 1j * _w), np.exp(-_z * _w - 1j * _w)]
A = np.real(np.poly(_POLES))
B = np.array([0.3, 0.1, -0.2])


def exact(f: np.ndarray) -> np.ndarray:
    return scipy.signal.freqz(B, A, worN=2 * np.pi * f)[1]


def rel_error(h: np.ndarray, ht: np.ndarray) -> np.ndarray:
    """|h - ht| / |ht|, floored at 1e-4 of the peak (B has a zero at Nyquist)."""
    return np.abs(h - ht) / np.maximum(np.abs(ht), 1e-4 * np.abs(ht).max())


def test_lrm_removes_leakage_and_transient_noise_free() -> None:
    rng = np.random.default_rng(0)
    x = rng.standard_normal(4096)
    y = scipy.signal.lfilter(B, A, x)  # from rest: start transient and leakage
    f, h, var = local_frf(x, y, 1.0)
    ht = exact(f)
    # the local rational model fits a resonance inside the window: what is left
    # is its small model error (measured 8e-7 at the resonances, 4e-10 typical)
    assert np.max(rel_error(h[0, 0], ht)) < 1e-5
    assert np.median(rel_error(h[0, 0], ht)) < 1e-8
    assert var.shape == h.shape
    assert np.all(var >= 0)
    # the local polynomial method follows smooth parts but not a 0.3 % resonance
    _, hp, _ = local_frf(x, y, 1.0, rational=False)
    err = rel_error(hp[0, 0], ht)
    assert np.median(err) < 1e-5
    assert err.max() > 1e-2


def test_lrm_variance_predicts_the_scatter() -> None:
    """Mean predicted variance / empirical variance over 100 noisy records ~ 1.

    Per line the empirical variance has a relative standard error of ~10 %
    (100 complex samples); over ~250 lines the median is within a few %.
    """
    rng = np.random.default_rng(1)
    x = rng.standard_normal(512)  # the same force, new noise each time
    y0 = scipy.signal.lfilter(B, A, x)
    hs, vs = [], []
    for _ in range(100):
        y = y0 + 0.05 * rng.standard_normal(x.size)
        _, h, v = local_frf(x, y, 1.0)
        hs.append(h[0, 0])
        vs.append(v[0, 0])
    hs_a, vs_a = np.array(hs), np.array(vs)
    emp = np.var(hs_a, axis=0) * 100 / 99
    ratio = np.median(vs_a.mean(axis=0)[10:-10] / emp[10:-10])
    assert ratio == pytest.approx(1.0, abs=0.15)


def test_estimate_frf_lrm_method() -> None:
    rng = np.random.default_rng(2)
    x = rng.standard_normal(2048)
    y = scipy.signal.lfilter(B, A, x)
    td = TimeData(np.vstack([x, y]), 100.0, [1, 2], ["force", "displacement"])
    frf = estimate_frf(td, method="lrm")
    assert frf.meta["method"] == "lrm"
    assert frf.frequency[0] > 0  # 0 Hz left out
    assert np.max(rel_error(frf.H[0, 0], exact(frf.frequency / 100.0))) < 1e-5
    assert frf.variance is not None
    banded = estimate_frf(td, method="lpm", band=(2.0, 10.0))
    assert banded.frequency.min() >= 2.0
    assert banded.frequency.max() <= 10.0


def test_lrm_bad_input() -> None:
    x = np.random.default_rng(3).standard_normal(256)
    with pytest.raises(InputError, match="half_width"):
        local_frf(x, x, 1.0, half_width=3)
    with pytest.raises(InputError, match="order"):
        local_frf(x, x, 1.0, order=-1)
    with pytest.raises(InputError, match="inputs, outputs"):
        local_frf(x, x[:100], 1.0)
    with pytest.raises(InputError, match="fewer than the local method's window"):
        local_frf(x[:8], x[:8], 1.0)
    td = TimeData(np.vstack([x, x]), 1.0, [1, 2], ["force", "displacement"])
    with pytest.raises(InputError, match="least-squares"):
        estimate_frf(td, "H2", method="lrm")
    with pytest.raises(InputError, match="whole record"):
        estimate_frf(td, method="lrm", segment_samples=64)
    runs = TimeData(
        np.vstack([x, x]),
        1.0,
        [1, 2],
        ["force", "displacement"],
        None,
        Acquisition(run_starts=(0, 128)),
    )
    with pytest.raises(InputError, match="2 runs"):
        estimate_frf(runs, method="lrm")


def test_lrm_two_inputs() -> None:
    """MISO: two independent random forces through two systems, both FRFs recovered."""
    rng = np.random.default_rng(4)
    x = rng.standard_normal((2, 4096))
    b2, a2 = [0.2, -0.1], [1.0, -1.2, 0.72]  # a second, well damped system
    y = scipy.signal.lfilter(B, A, x[0]) + scipy.signal.lfilter(b2, a2, x[1])
    f, h, _ = local_frf(x, y[None, :], 1.0)
    assert h.shape == (1, 2, f.size)
    h2 = scipy.signal.freqz(b2, a2, worN=2 * np.pi * f)[1]
    assert np.median(rel_error(h[0, 0], exact(f))) < 1e-6
    assert np.median(rel_error(h[0, 1], h2)) < 1e-6
    assert np.max(rel_error(h[0, 0], exact(f))) < 1e-3


@pytest.mark.parametrize("rational", [True, False])
def test_local_variance_dof_matches_the_scatter_of_the_variance(rational: bool) -> None:
    """The stated dof ``nu`` of the local variance: ``V^ / V ~ chi2_nu / nu`` has
    relative variance ``2 / nu`` (Seber & Lee 2003, thm. 3.5), measured over
    200 records of the same force with new noise (the relative variance of a
    line's variance estimate, median over lines; its standard error ~10 %)."""
    nu = local_variance_dof(1, rational=rational)
    # one input, order 2: n_par = 6 (+ 2 rational), window 2 ceil((n_par + 3) / 2) + 1
    # = 11 (13) lines: 5 complex degrees of freedom either way
    assert nu == 10.0
    rng = np.random.default_rng(3)
    x = rng.standard_normal(512)
    y0 = scipy.signal.lfilter(B, A, x)
    vs = np.array(
        [
            local_frf(x, y0 + 0.05 * rng.standard_normal(x.size), 1.0, rational=rational)[2][0, 0]
            for _ in range(200)
        ]
    )[:, 10:-10]
    rel_var = np.median(np.var(vs, axis=0) / np.mean(vs, axis=0) ** 2)
    assert rel_var == pytest.approx(2.0 / nu, rel=0.2)


def test_estimate_frf_local_methods_state_the_variance_dof() -> None:
    rng = np.random.default_rng(4)
    x = rng.standard_normal(2048)
    y = scipy.signal.lfilter(B, A, x) + 0.01 * rng.standard_normal(x.size)
    td = TimeData(np.vstack([x, y]), 100.0, [1, 2], ["force", "displacement"])
    for method, rational in (("lrm", True), ("lpm", False)):
        frf = estimate_frf(td, method=method)
        assert frf.meta["variance_dof"] == local_variance_dof(1, rational=rational)
        # the fit problem takes the stated dof for the goodness of fit
        assert build_problem(frf).noise_dof == frf.meta["variance_dof"]
