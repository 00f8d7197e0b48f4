"""FRF estimators (spec step 1): exactness, bias, coherence, MIMO, methods, errors."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import pytest
import scipy.signal
from numpy.testing import assert_allclose

from tyredamp import Channel, InputError
from tyredamp.mechanics import MCKSystem, time_response
from tyredamp.signal import (
    burst_random,
    cross_spectra,
    estimate_frf,
    exponential_window,
    force_window,
    multiple_coherence,
    ordinary_coherence,
    resolve_channels,
)
from tyredamp.timedata import TimeData

_KIND = {"displacement": "receptance", "velocity": "mobility", "acceleration": "accelerance"}


def periodic_record(
    system: MCKSystem,
    fs: float,
    period: int,
    lines: np.ndarray,
    in_dofs: Sequence[int],
    out_dofs: Sequence[int],
    n_periods: int,
    rng: np.random.Generator,
    quantity: str = "acceleration",
    new_phases_each_period: bool = False,
) -> TimeData:
    """Noise-free steady-state periodic test data, built in the frequency domain.

    The force of each input is a multisine on ``lines`` (random phases); the
    response of every period is ``irfft(H(f_k) F_k)``, which is exactly the
    sampled steady state of the continuous system under the band-limited
    periodic force. With ``new_phases_each_period`` each period is a new
    realisation (as if every period were measured after its own settling),
    as MIMO needs.
    """
    f = lines * fs / period
    h = system.frf(f, _KIND[quantity], outputs=list(out_dofs), inputs=list(in_dofs)).H
    n_in = len(in_dofs)
    phases = rng.random((n_in, lines.size))
    xs, ys = [], []
    for _ in range(n_periods):
        if new_phases_each_period:
            phases = rng.random((n_in, lines.size))
        fk = np.exp(2j * np.pi * phases)
        fspec = np.zeros((n_in, period // 2 + 1), dtype=complex)
        fspec[:, lines] = fk
        yspec = np.zeros((len(out_dofs), period // 2 + 1), dtype=complex)
        yspec[:, lines] = np.einsum("oil,il->ol", h, fk)
        xs.append(np.fft.irfft(fspec, period, axis=-1))
        ys.append(np.fft.irfft(yspec, period, axis=-1))
    data = np.vstack([np.hstack(xs), np.hstack(ys)])
    chans = [Channel(node=d + 1, direction=3, name=f"F{d + 1}") for d in in_dofs]
    chans += [Channel(node=d + 1, direction=3) for d in out_dofs]
    quants = ["force"] * n_in + [quantity] * len(out_dofs)
    return TimeData(data, fs, chans, quants, meta={"period_samples": period})


def exact(system: MCKSystem, frf, in_dofs, out_dofs) -> np.ndarray:
    return system.frf(frf.frequency, frf.kind, outputs=out_dofs, inputs=in_dofs).H


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20240611)


# ------------------------------------------------------------- exactness
@pytest.mark.parametrize("estimator", ["H1", "H2", "Hv"])
def test_cyclic_noise_free_equals_mck_frf(chain: MCKSystem, rng, estimator: str) -> None:
    lines = np.arange(5, 201)  # 1-40 Hz at 0.2 Hz spacing; modes at 3.8-31 Hz
    td = periodic_record(chain, 200.0, 1000, lines, [0], [0, 2, 5], 3, rng)
    frf = estimate_frf(td, estimator)
    assert frf.meta["method"] == "cyclic"  # chosen from meta["period_samples"]
    assert frf.kind == "accelerance"
    assert_allclose(frf.frequency, lines * 0.2, rtol=1e-15)  # exactly the excited lines
    # exact steady state, rectangular window on whole periods: only FFT round-off
    # (1e-16 of the largest line, divided by the smallest |H|) remains
    assert_allclose(frf.H, exact(chain, frf, [0], [0, 2, 5]), rtol=1e-10)
    # coherence of noise-free data is 1 to round-off
    assert_allclose(frf.coherence, 1.0, atol=1e-12)


def test_cyclic_mimo_exact_with_independent_realisations(chain: MCKSystem, rng) -> None:
    lines = np.arange(5, 151)
    ins, outs = [0, 3], [0, 1, 2, 3, 4, 5]
    td = periodic_record(
        chain, 200.0, 1000, lines, ins, outs, 6, rng, "displacement", new_phases_each_period=True
    )
    ref = chain.frf(lines * 0.2, "receptance", outputs=outs, inputs=ins).H
    for est in ("H1", "Hv"):
        frf = estimate_frf(td, est)
        assert frf.kind == "receptance"
        assert frf.H.shape == (6, 2, lines.size)
        # Gxx well conditioned (6 random realisations of 2 inputs): round-off only
        assert_allclose(frf.H, ref, rtol=1e-9, err_msg=est)
    assert_allclose(estimate_frf(td).coherence, 1.0, atol=1e-10)  # noise-free MIMO
    # square MIMO H2: outputs = the two drive points
    td_sq = periodic_record(
        chain, 200.0, 1000, lines, ins, ins, 6, rng, "displacement", new_phases_each_period=True
    )
    frf2 = estimate_frf(td_sq, "H2")
    assert_allclose(frf2.H, chain.frf(lines * 0.2, outputs=ins, inputs=ins).H, rtol=1e-9)


# ------------------------------------------------------------------ bias
def _noisy_siso(chain, rng, in_noise: float, out_noise: float) -> tuple[TimeData, np.ndarray]:
    lines = np.arange(3, 100)
    td = periodic_record(chain, 100.0, 256, lines, [0], [0], 400, rng, "displacement")
    d = td.data.copy()
    d[0] += in_noise * d[0].std() * rng.normal(size=d.shape[1])
    d[1] += out_noise * d[1].std() * rng.normal(size=d.shape[1])
    f = lines * 100.0 / 256
    ref = chain.frf(f, outputs=[0], inputs=[0]).H[0, 0]
    acq = replace(td.acquisition, band_hz=(f[0], f[-1]))  # noise excites every line: keep the band
    return TimeData(d, td.sample_rate, td.channels, td.quantities, td.meta, acq), ref


def test_input_noise_biases_h1_low_and_not_h2(chain: MCKSystem, rng) -> None:
    td, ref = _noisy_siso(chain, rng, in_noise=0.5, out_noise=0.0)
    r1 = np.abs(estimate_frf(td, "H1").H[0, 0] / ref)
    r2 = np.abs(estimate_frf(td, "H2").H[0, 0] / ref)
    # theory: E|H1| = |H| / (1 + Nxx/Gxx), Nxx/Gxx = 0.19 here (flat spectra), so
    # |H1/H| ~ 0.84; H2 has no bias from input noise. 400 averages: random error
    # ~ 1/sqrt(400) per line, the medians over 97 lines are far tighter.
    # per-line noise-to-signal ratio of the force: 2 (0.5)^2 n_lines / P
    nsr = 2 * 0.5**2 * 97 / 256
    assert np.median(r1) < 0.9
    assert np.median(r1) == pytest.approx(1 / (1 + nsr), abs=0.02)
    assert np.median(r2) == pytest.approx(1.0, abs=0.03)


def test_output_noise_biases_h2_high_and_not_h1(chain: MCKSystem, rng) -> None:
    td, ref = _noisy_siso(chain, rng, in_noise=0.0, out_noise=0.5)
    r1 = np.abs(estimate_frf(td, "H1").H[0, 0] / ref)
    r2 = np.abs(estimate_frf(td, "H2").H[0, 0] / ref)
    # output noise: H1 unbiased, H2 = H (1 + Nyy/Gyy) biased high (sign of the bias
    # is what theory predicts; its size depends on the per-line SNR)
    assert np.median(r1) == pytest.approx(1.0, abs=0.03)
    assert np.median(r2) > 1.05
    assert np.all(r2 > r1)


def test_h1_le_hv_le_h2_and_coherence(chain: MCKSystem, rng) -> None:
    td, _ = _noisy_siso(chain, rng, in_noise=0.3, out_noise=0.3)
    h1, hv, h2 = (np.abs(estimate_frf(td, e).H[0, 0]) for e in ("H1", "Hv", "H2"))
    # identities for one input: |H1| / |H2| = gamma^2 and Hv between them
    assert np.all(h1 <= hv * (1 + 1e-12))
    assert np.all(hv <= h2 * (1 + 1e-12))
    coh = estimate_frf(td).coherence[0]
    assert_allclose(h1 / h2, coh, rtol=1e-10)  # gamma^2 = |H1/H2| exactly
    assert np.all(coh < 1.0)


# ---------------------------------------------------------------- Welch
def test_welch_matches_scipy_csd_siso(rng) -> None:
    x = rng.normal(size=8192)
    y = np.convolve(x, [0.5, 0.3, -0.2], mode="same") + 0.1 * rng.normal(size=8192)
    td = TimeData(np.vstack([x, y]), 100.0, [Channel(1), Channel(2)], ["force", "velocity"])
    frf = estimate_frf(td, method="welch", segment_samples=512, overlap=0.5, band=(0.1, 50))
    f, pxy = scipy.signal.csd(x, y, fs=100.0, nperseg=512, noverlap=256, window="hann")
    _, pxx = scipy.signal.welch(x, fs=100.0, nperseg=512, noverlap=256, window="hann")
    _, cxy = scipy.signal.coherence(x, y, fs=100.0, nperseg=512, noverlap=256, window="hann")
    keep = f > 0  # the DC line (removed by the constant detrend) is outside the band
    assert_allclose(frf.frequency, f[keep], rtol=1e-14)
    # scipy's csd is E[conj(X) Y] = our Gyx for one input: same numbers to round-off
    assert_allclose(frf.H[0, 0], (pxy / pxx)[keep], rtol=1e-10)
    assert_allclose(frf.coherence[0], cxy[keep], rtol=1e-9, atol=1e-12)
    assert frf.kind == "mobility"
    assert frf.meta["n_averages"] == 31


def test_welch_refuses_a_record_too_short_for_its_default_segments(rng) -> None:
    x = rng.normal(size=(2, 100))  # 100 samples: default segments of 12 samples
    td = TimeData(x, 100.0, [Channel(1), Channel(2)], ["force", "velocity"])
    with pytest.raises(InputError, match=r"100 samples per channel are too few.*--segment"):
        estimate_frf(td, method="welch")
    frf = estimate_frf(td, method="welch", segment_samples=32)  # a stated segment is used
    assert frf.meta["segment_samples"] == 32
    td = TimeData(rng.normal(size=(2, 128)), 100.0, [Channel(1), Channel(2)], ["force", "velocity"])
    assert estimate_frf(td, method="welch").meta["segment_samples"] == 16  # the shortest default


def _band_limited_noise(g: np.random.Generator, n: int, fs: float, f_hi: float) -> np.ndarray:
    spec = np.zeros(n // 2 + 1, dtype=complex)
    k = np.arange(1, int(f_hi * n / fs))
    spec[k] = g.normal(size=k.size) + 1j * g.normal(size=k.size)
    return np.fft.irfft(spec, n) * np.sqrt(n)


def test_welch_random_excitation_close_to_exact() -> None:
    sys2 = MCKSystem(
        np.diag([1.0, 2.0]), [[8.0, -2.0], [-2.0, 4.0]], [[4.0e4, -1.5e4], [-1.5e4, 3.0e4]]
    )  # modes ~ 17 and 35 Hz, zeta 3-5 %
    fs, r = 512.0, 8
    n = 2**18
    force = _band_limited_noise(np.random.default_rng(5), n * r, fs * r, 120.0)
    resp = time_response(sys2, force, fs * r, inputs=[0], hold="foh")
    # band-limited force (< 120 Hz) simulated 8x faster than recorded, then every 8th
    # sample kept: decimation is exact for force and response, and the first-order
    # hold error is (pi f / fs_sim)^2 / 3 < 2e-4 below 60 Hz
    d = np.vstack([force[::r], resp.acceleration[:, ::r]])
    td = TimeData(
        d, fs, [Channel(1), Channel(1), Channel(2)], ["force", "acceleration", "acceleration"]
    )
    frf = estimate_frf(td, method="welch", segment_samples=4096, band=(5.0, 60.0))
    assert frf.meta["n_averages"] == 127
    ref = sys2.frf(frf.frequency, "accelerance", inputs=[0]).H
    # Hann leakage at df = 0.125 Hz against half-power bandwidths >= 1 Hz is 1-2 %
    # at the peaks; random error over 127 averages is ~ sqrt((1-g2)/(2 n g2)) < 1 %
    # except near anti-resonances, where the coherence drops (leakage noise)
    err = np.abs(frf.H - ref)[:, 0] / np.abs(ref)[:, 0]
    assert np.median(err) < 0.005  # measured 8e-4
    assert np.max(err[frf.coherence > 0.99]) < 0.03  # measured 1.7e-2 (leakage at peaks)


# ------------------------------------------------------------- transient
def test_transient_burst_random_leakage_free() -> None:
    sys2 = MCKSystem(
        np.diag([1.0, 1.0]), [[30.0, -5.0], [-5.0, 20.0]], [[2.0e4, -1.0e4], [-1.0e4, 2.0e4]]
    )  # well damped: decays in the record
    fs, rec = 2048.0, 8192
    exc = burst_random(fs, rec, (0.5, 60.0), rms=2.0, burst_fraction=0.4, n_records=6, rng=3)
    resp = time_response(sys2, exc.signal, fs, inputs=[0], hold="foh")
    meta = {**exc.meta(), "band_hz": [1.0, 40.0]}
    td = TimeData(
        np.vstack([exc.signal, resp.displacement]),
        fs,
        [Channel(1), Channel(1), Channel(2)],
        ["force", "displacement", "displacement"],
        meta=meta,
    )
    frf = estimate_frf(td)
    assert frf.meta["method"] == "transient"
    assert frf.meta["n_averages"] == 6
    assert frf.frequency[0] >= 1.0
    assert frf.frequency[-1] <= 40.0
    ref = sys2.frf(frf.frequency, inputs=[0]).H
    # the response has decayed by the end of each record (sigma >= 10 1/s, 2.4 s of
    # silence), so a rectangular window is leakage free; what remains is the
    # first-order-hold reading of the sampled force, (pi f / fs)^2 / 3 < 1.3e-3
    assert_allclose(frf.H, ref, rtol=2e-3)
    assert_allclose(frf.coherence, 1.0, atol=1e-6)


def test_transient_windows_recorded_in_meta() -> None:
    rec = 256
    g = np.random.default_rng(0)
    x = np.zeros(4 * rec)
    x[::rec] = 1.0  # one hit per record
    y = np.convolve(x, np.exp(-np.arange(200) / 30.0))[: x.size] + 1e-3 * g.normal(size=x.size)
    td = TimeData(np.vstack([x, y]), 1000.0, [Channel(1), Channel(1)], ["force", "displacement"])
    frf = estimate_frf(
        td, method="transient", segment_samples=rec, force_window_samples=8, exponential_end=0.1
    )
    _, tau = exponential_window(rec, 1000.0, 0.1)
    assert frf.meta["exponential_tau_s"] == pytest.approx(tau)
    assert tau == pytest.approx(0.255 / np.log(10.0))
    assert frf.meta["force_window_samples"] == 8
    w = force_window(16, 4, 2, start_samples=1)
    assert_allclose(w[:8], [0, 1, 1, 1, 1, 0.75, 0.25, 0])  # cosine taper of 2 samples


# ------------------------------------------------------------- channels
def test_kind_and_reference_selection(chain: MCKSystem, rng) -> None:
    lines = np.arange(5, 50)
    td = periodic_record(
        chain, 200.0, 400, lines, [0, 3], [1, 2], 4, rng, "velocity", new_phases_each_period=True
    )
    frf = estimate_frf(td, reference="F4")  # by name: the second force only
    assert frf.kind == "mobility"
    assert frf.n_in == 1
    assert frf.inputs[0].node == 4
    assert [c.node for c in frf.outputs] == [2, 3]
    assert resolve_channels(td.channels, ["1+Z", 4, "3"], "x") == [0, 1, 3]
    with pytest.raises(InputError, match="matches 2 channels"):
        resolve_channels([Channel(1, name="F1"), Channel(1, 1)], [1], "reference")
    with pytest.raises(InputError, match="no channel matches"):
        estimate_frf(td, reference="2+Z")  # a response channel is not a reference


def test_coherence_functions_agree_for_one_input(rng) -> None:
    x = rng.normal(size=4096)
    y = np.vstack([np.roll(x, 3) + rng.normal(size=4096), -x + 0.5 * rng.normal(size=4096)])
    sp = cross_spectra(x, y, 10.0, 256, step_samples=128)
    assert_allclose(multiple_coherence(sp), ordinary_coherence(sp)[:, 0, :], rtol=1e-10, atol=1e-14)


def test_run_starts_and_settle_per_run(chain: MCKSystem, rng) -> None:
    lines = np.arange(5, 60)
    a = periodic_record(chain, 200.0, 400, lines, [0], [0, 1], 3, rng)
    b = periodic_record(chain, 200.0, 400, lines, [0], [0, 1], 3, rng)
    junk = rng.normal(size=(3, 150))  # a transient at the start of each run
    d = np.hstack([junk, a.data, junk, b.data])
    meta = {"period_samples": 400, "settle_samples": 150, "run_starts": [0, 1350]}
    td = TimeData(d, 200.0, a.channels, a.quantities, meta)
    frf = estimate_frf(td)
    assert frf.meta["n_averages"] == 6
    assert_allclose(frf.H, exact(chain, frf, [0], [0, 1]), rtol=1e-10)  # junk never used


# ----------------------------------------------------------------- errors
def test_errors(chain: MCKSystem, rng) -> None:
    lines = np.arange(5, 60)
    td = periodic_record(chain, 200.0, 400, lines, [0, 3], [1, 2, 4], 3, rng)
    with pytest.raises(InputError, match="fully correlated"):
        estimate_frf(td)  # the same realisation in every period: Gxx singular
    td_ind = periodic_record(
        chain, 200.0, 400, lines, [0, 3], [1, 2, 4], 3, rng, new_phases_each_period=True
    )
    with pytest.raises(InputError, match="H2 with 2 inputs"):
        estimate_frf(td_ind, "H2")
    zero = td.data.copy()
    zero[0] = 0.0
    with pytest.raises(InputError, match="all zeros"):
        estimate_frf(TimeData(zero, 200.0, td.channels, td.quantities, td.meta, td.acquisition))
    with pytest.raises(InputError, match="no force channel"):
        estimate_frf(TimeData(td.data[2:], 200.0, td.channels[2:], td.quantities[2:]))
    mixed = TimeData(
        td.data, 200.0, td.channels, ["force", "force", "velocity", "acceleration", "acceleration"]
    )
    with pytest.raises(InputError, match="one response quantity"):
        estimate_frf(mixed, reference=["F1"])
    with pytest.raises(InputError, match="estimator"):
        estimate_frf(td, "H3")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="cyclic method uses whole periods"):
        estimate_frf(td, reference="F1", window="hann")
    with pytest.raises(InputError, match="no whole segment"):
        estimate_frf(td, reference="F1", period_samples=5000)
    with pytest.raises(InputError, match="no excited frequency line"):
        estimate_frf(td, reference="F1", band=(90.0, 95.0))
    with pytest.raises(InputError, match="run_starts"):
        estimate_frf(
            TimeData(
                td.data,
                200.0,
                td.channels,
                td.quantities,
                {"period_samples": 400, "run_starts": [5]},
            ),
            reference="F1",
        )
