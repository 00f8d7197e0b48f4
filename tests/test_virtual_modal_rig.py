"""The virtual modal test rig: periodic chirp, steady state, noise, cyclic FRF vs truth."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import InputError, TyredampError
from tyredamp.mechanics import time_response
from tyredamp.signal import band_lines
from tyredamp.timedata import TimeData
from tyredamp.virtual import (
    MeasurementLayout,
    RingTyre,
    VirtualModalTest,
    hadamard_drive_matrix,
    periodic_initial_state,
    run_modal_test,
    schroeder_multisine,
)

#: A small, fast configuration: 64 DOFs, 1 s period at 512 Hz, 4x oversampling.
SMALL: dict[str, Any] = {"sample_rate": 512.0, "period": 1.0, "n_periods": 4, "oversample": 4}


@pytest.fixture(scope="module")
def small_tyre() -> RingTyre:
    return RingTyre(n_ring=32)


@pytest.fixture(scope="module")
def default_test() -> VirtualModalTest:
    return run_modal_test(seed=7)


def cyclic_frf(data: TimeData, run_starts: list[int] | None = None) -> np.ndarray:
    """H1 over whole periods: S_yf S_ff^-1 per line, shape (n_out, n_in, n_lines)."""
    p = int(data.acquisition.period_samples or 0)
    fi, ri = data.force_indices, data.response_indices
    x = data.data.reshape(data.n_channels, -1, p)  # every period is steady state
    spec = np.fft.rfft(x, axis=2)
    f, y = spec[fi], spec[ri]
    syf = np.einsum("jpk,ipk->jik", y, np.conj(f))
    sff = np.einsum("jpk,ipk->kji", f, np.conj(f))  # (line, j, i)
    lines = np.asarray(data.meta["lines"])
    h = np.empty((len(ri), len(fi), lines.size), dtype=complex)
    for n, k in enumerate(lines):
        h[:, :, n] = syf[:, :, k] @ np.linalg.inv(sff[k].T)
    return h


def exact_foh_accelerance(
    tyre: RingTyre, f: np.ndarray, fs_sim: float, m_max: int = 100
) -> np.ndarray:
    """``sum_m A(f + m fs_sim) sinc^2(f/fs_sim + m)``: what a first-order hold measures.

    The first-order hold turns the band-limited chirp into a piecewise-linear force
    whose line ``f + m fs_sim`` carries ``sinc^2`` of the sampled spectrum; sampling the
    response folds those lines back onto ``f``. ``A`` by the complete complex modal sum
    (eq. [10]); beyond ``m_max`` ``A`` is its limit ``M^-1``.
    """
    cm = tyre.system.complex_modes()
    psi_o = cm.psi[tyre.point_dofs]
    psi_i = cm.psi[tyre.drive_dofs]
    minv = np.linalg.inv(tyre.M)[np.ix_(tyre.point_dofs, tyre.drive_dofs)]
    total = np.zeros((psi_o.shape[0], psi_i.shape[0], f.size), dtype=complex)
    weight_sum = np.zeros(f.size)
    for m in range(-m_max, m_max + 1):
        fm = f + m * fs_sim
        s = 2j * np.pi * fm
        g = 1 / (s[None, :] - cm.poles[:, None])
        gc = 1 / (s[None, :] - np.conj(cm.poles)[:, None])
        h = np.einsum("jn,kn,nf->jkf", psi_o, psi_i, g)
        h += np.einsum("jn,kn,nf->jkf", np.conj(psi_o), np.conj(psi_i), gc)
        w = np.sinc(fm / fs_sim) ** 2
        total += h * s**2 * w
        weight_sum += w
    return total + minv[:, :, None] * (1 - weight_sum)  # sum_m sinc^2(x + m) = 1


# ----------------------------------------------------------------- excitation
def test_schroeder_multisine_spectrum() -> None:
    exc = schroeder_multisine(4096.0, 4096, (10.0, 200.0), rms=3.0, n_periods=2)
    x = exc.signal
    assert x.shape == (8192,)
    assert exc.period_samples == 4096
    assert np.sqrt(np.mean(x**2)) == pytest.approx(3.0, rel=1e-12)
    spec = np.abs(np.fft.rfft(x[:4096]))
    lines = band_lines(4096.0, 4096, (10.0, 200.0))
    assert lines[0] == 10
    assert lines[-1] == 200
    # flat on the band, nothing elsewhere (rounding 1e-9 of the line amplitude)
    assert_allclose(spec[lines], spec[lines][0], rtol=1e-9)
    others = np.delete(spec, lines)
    assert np.max(others) < 1e-9 * spec[lines][0]
    # generated 4x faster, every 4th sample is the same band-limited signal
    slow = schroeder_multisine(1024.0, 1024, (10.0, 200.0), rms=1.0).signal
    assert_allclose(x[:4096:4] / np.sqrt(np.mean(x[:4096:4] ** 2)), slow, atol=1e-12)


def test_hadamard_drive_matrix_orthogonal() -> None:
    for n in (1, 2, 3, 5):
        h = hadamard_drive_matrix(n)
        assert h.shape[1] == n
        assert_allclose(h.T @ h, h.shape[0] * np.eye(n))


# -------------------------------------------------------------- steady state
def test_periodic_initial_state_is_periodic(small_tyre: RingTyre) -> None:
    fs = 2048.0
    base = schroeder_multisine(fs, 512, (0.0, 200.0), rms=10.0).signal[None, :]
    x0, v0 = periodic_initial_state(small_tyre.system, base, fs, small_tyre.drive_dofs)
    resp = time_response(
        small_tyre.system, np.tile(base, 3), fs, small_tyre.drive_dofs.tolist(), x0=x0, v0=v0
    )
    d = resp.displacement
    # exact modal integration: periodic to rounding (1e-10 of the amplitude)
    assert_allclose(d[:, :512], d[:, 512:1024], atol=1e-10 * np.abs(d).max())
    assert_allclose(d[:, 1024], x0, atol=1e-10 * np.abs(d).max())
    assert_allclose(resp.velocity[:, 512], v0, atol=1e-10 * np.abs(resp.velocity).max())


def test_rest_start_settles_to_the_sampled_foh_response(small_tyre: RingTyre) -> None:
    opts = {**SMALL, "excitation": "multisine", "snr_db": None}
    # slowest mode sigma >= 1.36 1/s: after 10 s the transient is < 1.3e-6
    rest = run_modal_test(small_tyre, initial_state="rest", settle_periods=10, **opts)  # type: ignore[arg-type]
    h = cyclic_frf(rest.data)
    ref = exact_foh_accelerance(small_tyre, rest.frequency_lines, 512.0 * 4)
    # time stepping, sampling and decimation against the folded closed form: the
    # transient left and the truncated alias sum; measured 1.5e-10 of max |A|
    assert_allclose(h, ref, atol=1e-8 * np.abs(ref).max())
    # the periodic default measures A(f) itself: the two differ by the hold's folding
    # (measured 3 % of max |A| with 4x oversampling), far above that tolerance
    per = cyclic_frf(run_modal_test(small_tyre, **opts).data)  # type: ignore[arg-type]
    assert np.max(np.abs(per - ref)) > 1e-3 * np.abs(ref).max()
    kept = run_modal_test(
        small_tyre,
        snr_db=None,
        initial_state="rest",
        settle_periods=2,
        keep_settle=True,
        **SMALL,
    )
    assert kept.data.acquisition.settle_samples == 2 * 512
    assert kept.data.n_samples == 6 * 512
    # the settle periods hold the transient: they differ from the settled periods
    a = kept.data.data
    assert np.max(np.abs(a[1:, :512] - a[1:, -512:])) > 1e-3 * np.abs(a).max()


# ---------------------------------------------------------------- the test
def test_default_test_shapes_and_metadata(default_test: VirtualModalTest) -> None:
    d = default_test.data
    assert d.n_channels == 17
    assert d.sample_rate == 1024.0
    assert d.n_samples == 8 * 4096
    assert d.quantities == ("force",) + ("acceleration",) * 16
    assert d.force_indices == [0]
    assert [c.angle_deg for c in d.channels[1:]] == [22.5 * k for k in range(16)]
    assert d.channels[0].node == 1
    assert d.channels[0].name == "F1"
    m = default_test.meta
    assert m["period_samples"] == 4096
    assert m["settle_samples"] == 0
    assert m["n_runs"] == 1
    assert m["run_starts"] == [0]
    assert m["snr_db"] == 40.0
    assert m["seed"] == 7
    assert m["excitation"] == "periodic_chirp"
    assert m["lines"][0] == 1
    assert m["lines"][-1] == 800  # every DFT line in 0-200 Hz (DC excluded)
    assert m["excitation_band_hz"] == [0.25, 199.75]  # sweep edges on DFT lines
    assert default_test.frequency_lines[-1] == 200.0
    tr = default_test.truth
    assert tr.band == (0.0, 200.0)
    mm = tr.modal_model()
    assert mm.n_modes == 6
    assert mm.mode_kind == "complex"
    assert [c.angle_deg for c in mm.outputs] == [22.5 * k for k in range(16)]


def test_seed_reproducibility(small_tyre: RingTyre) -> None:
    a = run_modal_test(small_tyre, seed=11, **SMALL)
    b = run_modal_test(small_tyre, seed=11, **SMALL)
    c = run_modal_test(small_tyre, seed=12, **SMALL)
    g = run_modal_test(small_tyre, seed=np.random.default_rng(11), **SMALL)
    assert np.array_equal(a.data.data, b.data.data)
    assert np.array_equal(a.data.data, g.data.data)
    assert not np.array_equal(a.data.data, c.data.data)


@pytest.mark.parametrize("snr", [20.0, 40.0])
def test_noise_at_requested_snr(small_tyre: RingTyre, snr: float) -> None:
    clean = run_modal_test(small_tyre, snr_db=None, **SMALL).data.data
    noisy = run_modal_test(small_tyre, snr_db=snr, seed=3, **SMALL).data.data
    noise = noisy - clean
    rms = np.sqrt(np.mean(clean**2, axis=1))
    ratio = 20 * np.log10(rms / noise.std(axis=1))
    # 2048 samples per channel: the std estimate scatters by 1.6 %, i.e. 0.14 dB (4 sigma 0.6)
    assert_allclose(ratio, snr, atol=0.6)
    # independent channels: correlation of the noise between channels ~ 1/sqrt(2048)
    corr = np.corrcoef(noise)
    assert np.max(np.abs(corr - np.eye(corr.shape[0]))) < 0.12


@pytest.mark.parametrize(
    "options",
    [
        {"excitation": "multisine"},
        {"excitation": "chirp"},
        {"excitation": "chirp", "direction": "tangential", "band": (0.0, 100.0)},
    ],
)
def test_noise_free_cyclic_frf_is_the_exact_frf(
    small_tyre: RingTyre, options: dict[str, Any]
) -> None:
    """An ideal lab: continuous force and exact response, filtered alike, give ``A(f)``."""
    vt = run_modal_test(small_tyre, snr_db=None, **SMALL, **options)
    h = cyclic_frf(vt.data)
    true = vt.true_frf(vt.frequency_lines).H
    # the rig's receptance (balanced state-space eigenvalues) against the truth's direct
    # solve, then FFTs and the H1 division: measured 1.7e-10 of max |A| and 4e-10
    # relative where |A| is smallest (1.9e-9 on the default tyre)
    assert np.max(np.abs(h - true)) < 1e-9 * np.abs(true).max()
    assert_allclose(h, true, rtol=1e-8)


def test_default_cyclic_frf_equals_true_accelerance(default_test: VirtualModalTest) -> None:
    clean = run_modal_test(default_test.tyre, snr_db=None)
    h = cyclic_frf(clean.data)
    f = clean.frequency_lines
    true = clean.true_frf(f).H
    # exact to rounding (module docstring of tyredamp.virtual.modal_rig, "Sampling"):
    # measured relative 1.9e-9 where |A| is smallest
    assert_allclose(h, true, rtol=1e-8)
    # the noisy test (40 dB per channel, 8 averages): on lines with |A| > 0.1 max |A|
    # the error is noise, max over the lines 1.6-2.7 % for seeds 0-4; 4 % allowed
    hn = cyclic_frf(default_test.data)
    big = np.abs(true) > 0.1 * np.abs(true).max()
    assert_allclose(hn[big], true[big], rtol=4e-2)


@pytest.mark.parametrize("mode", ["sequential", "simultaneous"])
def test_multi_reference(mode: str) -> None:
    layout = MeasurementLayout(drive_points=(1, 4))
    tyre = RingTyre(layout=layout, n_ring=32)
    vt = run_modal_test(
        tyre,
        snr_db=None,
        drive_mode=mode,  # type: ignore[arg-type]
        excitation="multisine",
        **SMALL,
    )
    assert vt.data.n_channels == 18
    assert vt.n_runs == 2
    assert vt.meta["run_starts"] == [0, 4 * 512]
    if mode == "sequential":
        assert_allclose(vt.drive_matrix, np.eye(2))
        # force channel 2 is silent in run 0
        assert np.max(np.abs(vt.run_data(0).data[1])) == 0.0
    else:
        assert_allclose(np.abs(vt.drive_matrix), 1.0)
    h = cyclic_frf(vt.data)
    t = vt.true_frf(vt.frequency_lines).H
    # H1 over both runs separates the inputs exactly (noise-free): rounding, as above
    assert_allclose(h, t, rtol=1e-8)
    # reciprocity of the truth: H(point 4, drive 1) == H(point 1, drive 4)
    assert_allclose(t[3, 0], t[0, 1], rtol=1e-9)
    run1 = vt.run_data(1)
    assert run1.n_samples == 4 * 512
    assert run1.acquisition.run_starts == (0,)


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "word"),
    [
        ({"period": 1.0001}, "period"),
        ({"band": (0.0, 300.0), "sample_rate": 512.0, "period": 1.0}, "band"),
        ({"band": (150.0, 100.0)}, "band"),
        ({"band": "wide"}, "band"),
        ({"excitation": "noise"}, "excitation"),
        ({"n_periods": 0}, "n_periods"),
        ({"oversample": 0}, "oversample"),
        ({"settle_periods": -1}, "settle_periods"),
        ({"drive_mode": "random"}, "drive_mode"),
        ({"initial_state": "hot"}, "initial_state"),
        ({"snr_db": float("nan")}, "snr_db"),
        ({"force_rms": -1.0}, "force_rms"),
        ({"sample_rate": 0.0}, "sample_rate"),
    ],
)
def test_bad_test_options(small_tyre: RingTyre, kwargs: dict[str, Any], word: str) -> None:
    with pytest.raises(TyredampError, match=word):
        run_modal_test(small_tyre, **kwargs)


def test_bad_tyre_and_run_index(small_tyre: RingTyre) -> None:
    with pytest.raises(InputError, match="tyre"):
        run_modal_test("tyre")  # type: ignore[arg-type]
    vt = run_modal_test(small_tyre, snr_db=None, **SMALL)
    with pytest.raises(InputError, match="run"):
        vt.run_data(1)
    with pytest.raises(InputError, match="period_samples"):
        schroeder_multisine(100.0, 2, (0.0, 10.0))
    with pytest.raises(InputError, match="inputs"):
        periodic_initial_state(small_tyre.system, np.ones((1, 8)), 100.0, [small_tyre.n_dof])
