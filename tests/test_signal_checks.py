"""Linearity, reciprocity and data-quality checks (spec step 2)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import Channel, InputError, ShapeError
from tyredamp.frf import FRF
from tyredamp.mechanics import MCKSystem
from tyredamp.signal import (
    clipping,
    estimate_frf,
    linearity_check,
    merge_inputs,
    pseudo_random,
    quality_check,
    reciprocity_check,
)
from tyredamp.timedata import TimeData

from .test_signal_estimators import periodic_record

M2 = np.eye(2)
C2 = np.array([[8.0, -2.0], [-2.0, 4.0]])
K2 = np.array([[2.0e4, -1.0e4], [-1.0e4, 1.0e4]])  # modes ~ 9.8 and 25.8 Hz, zeta 2-4 %


def duffing_test(
    force_rms: float,
    k3: float,
    fs: float = 400.0,
    period: int = 400,
    settle: int = 8,
    record: int = 4,
) -> TimeData:
    """2-DOF chain with a cubic spring ``k3 x0^3`` from mass 0 to ground, driven at mass 0.

    Classical RK4 with step 1/fs; the periodic multisine force (2-40 Hz) is
    generated at 2 fs so its values at the half steps are exact. The first
    ``settle`` periods are dropped (free decay < 1e-6 by then).
    """
    n = (settle + record) * period
    f2 = pseudo_random(
        2 * fs, 2 * period, (2.0, 40.0), rms=force_rms, n_periods=settle + record, rng=11
    ).signal
    f2 = np.append(f2, f2[0])
    h = 1.0 / fs
    minv = np.linalg.inv(M2)

    def acc(x: np.ndarray, v: np.ndarray, f: float) -> np.ndarray:
        load = np.array([f - k3 * x[0] ** 3, 0.0])
        return minv @ (load - C2 @ v - K2 @ x)

    x, v = np.zeros(2), np.zeros(2)
    out = np.empty((3, n))
    for j in range(n):
        out[0, j], out[1:, j] = f2[2 * j], x
        fa, fb, fc = f2[2 * j], f2[2 * j + 1], f2[2 * j + 2]
        k1x, k1v = v, acc(x, v, fa)
        k2x, k2v = v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v, fb)
        k3x, k3v = v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v, fb)
        k4x, k4v = v + h * k3v, acc(x + h * k3x, v + h * k3v, fc)
        x = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    meta = {"period_samples": period, "settle_samples": settle * period, "band_hz": [2, 40]}
    return TimeData(
        out,
        fs,
        [Channel(1, name="F"), Channel(1), Channel(2)],
        ["force", "displacement", "displacement"],
        meta,
    )


# ------------------------------------------------------------- linearity
def test_linear_system_passes_cubic_spring_fails() -> None:
    lin = [estimate_frf(duffing_test(a, k3=0.0)) for a in (1.0, 30.0)]
    res = linearity_check(lin, threshold=0.01)
    # RK4 is linear in the force: the FRFs at the two levels agree to round-off
    assert res.passed
    assert res.figure < 1e-9
    assert "PASS" in res.summary
    assert res.threshold == 0.01
    nl = [estimate_frf(duffing_test(a, k3=3.0e6)) for a in (1.0, 30.0)]
    bad = linearity_check(nl, threshold=0.05)
    assert not bad.passed
    assert "FAIL" in bad.summary
    # the hardening spring moves the first resonance (9.8 Hz) up at 30 N: the
    # largest per-line deviation sits near it
    assert bad.figure > 0.1
    assert 8.0 <= bad.figures["max_line_frequency_hz"] <= 14.0
    assert bad.per_line is not None
    assert bad.per_line.shape == nl[0].frequency.shape


def test_linearity_input_errors(chain: MCKSystem) -> None:
    a = chain.frf(np.linspace(1, 10, 20), inputs=[0])
    with pytest.raises(InputError, match="two or more"):
        linearity_check([a])
    b = chain.frf(np.linspace(1, 11, 20), inputs=[0])
    with pytest.raises(ShapeError, match="same frequency lines"):
        linearity_check([a, b])
    c = chain.frf(np.linspace(1, 10, 20), inputs=[1])
    with pytest.raises(ShapeError, match="same output and input channels"):
        linearity_check([a, c])
    # a different kind is converted before comparing: still identical
    assert linearity_check([a, a.accelerance()]).figure < 1e-12


# ----------------------------------------------------------- reciprocity
def test_reciprocal_pair_passes_swapped_or_scaled_fails(chain: MCKSystem) -> None:
    rng = np.random.default_rng(3)
    lines = np.arange(5, 151)
    td = periodic_record(
        chain, 200.0, 1000, lines, [0, 3], [0, 1, 2, 3], 6, rng, new_phases_each_period=True
    )
    frf = estimate_frf(td)
    ok = reciprocity_check(frf)
    assert ok.passed
    assert ok.figures["n_pairs"] == 1
    assert ok.figure < 1e-9  # symmetric M, C, K: H_14 = H_41 to round-off
    # swapped output labels (cables of points 1 and 4 exchanged)
    outs = list(frf.outputs)
    outs[0], outs[3] = outs[3], outs[0]
    swapped = FRF(frf.frequency, frf.H, frf.kind, outs, frf.inputs)
    assert not reciprocity_check(swapped).passed
    # a wrong sensitivity (+10 %) on the accelerometer at point 4
    h = frf.H.copy()
    h[3] *= 1.1
    scaled = reciprocity_check(frf.with_H(h), threshold=0.05)
    assert not scaled.passed
    assert scaled.figure == pytest.approx(0.1 / np.sqrt((1 + 1.1**2) / 2), rel=1e-6)
    # two separate single-input tests joined by merge_inputs give the same answer
    parts = [frf.select(inputs=[0]), frf.select(inputs=[1])]
    assert reciprocity_check(merge_inputs(parts)).figure == pytest.approx(ok.figure, abs=1e-12)


def test_reciprocity_direction_signs_and_errors(chain: MCKSystem) -> None:
    frf = chain.frf(np.linspace(1, 30, 50), outputs=[0, 2], inputs=[0, 2])
    # an input given as -Z at node 3: the FRF column changes sign, reciprocity holds
    h = frf.H.copy()
    h[:, 1] *= -1
    flipped = FRF(
        frf.frequency, h, "receptance", frf.outputs, [frf.inputs[0], Channel(node=3, direction=-3)]
    )
    assert reciprocity_check(flipped).figure < 1e-12
    with pytest.raises(InputError, match="reciprocity needs two inputs"):
        reciprocity_check(frf.select(inputs=[0]))


# --------------------------------------------------------------- quality
def test_quality_clean_clipped_reversed_noisy(chain: MCKSystem) -> None:
    rng = np.random.default_rng(4)
    lines = np.arange(5, 151)
    td = periodic_record(chain, 200.0, 1000, lines, [0], [0, 2, 4], 4, rng)
    clean = quality_check(td)
    assert clean.passed, clean.report()
    assert clean.figures["clipped_channels"] == 0
    assert clean.figures["passivity_violations"] == 0
    assert clean.figures["low_coherence_fraction"] == 0.0
    banded = quality_check(td, band=(2.0, 10.0))  # judge only the lines of a band
    assert banded.frequency is not None
    assert banded.frequency.min() >= 2.0
    assert banded.frequency.max() <= 10.0

    d = td.data.copy()
    top = 0.7 * d[2].max()
    d[2] = np.minimum(d[2], top)  # overloaded amplifier on one accelerometer
    clipped = quality_check(TimeData(d, 200.0, td.channels, td.quantities, td.meta, td.acquisition))
    assert not clipped.passed
    assert clipped.figures["clipped_channels"] == 1
    assert "clipped" in clipped.summary

    d = td.data.copy()
    d[0] *= -1  # force transducer mounted the wrong way round
    rev = quality_check(TimeData(d, 200.0, td.channels, td.quantities, td.meta, td.acquisition))
    assert not rev.passed
    assert rev.figures["passivity_fraction"] > 0.5
    assert "not passive" in rev.summary

    d = td.data.copy()
    d[1:] += 3 * d[1:].std(axis=1, keepdims=True) * rng.normal(size=d[1:].shape)
    noisy = quality_check(TimeData(d, 200.0, td.channels, td.quantities, td.meta, td.acquisition))
    assert not noisy.passed
    assert noisy.figure > noisy.threshold
    assert noisy.frequency is not None
    assert noisy.per_line is not None


def test_quality_of_frf_and_dead_force(chain: MCKSystem) -> None:
    frf = chain.frf(np.linspace(0.5, 40, 200), "accelerance", outputs=[0, 1], inputs=[0])
    res = quality_check(frf)
    assert res.passed
    assert res.figures["min_drive_point_real_ratio"] >= 0.0  # passive to round-off
    assert any("no coherence" in n for n in res.notes)
    td = TimeData(
        np.vstack([np.zeros(64), np.ones(64)]),
        10.0,
        [Channel(1), Channel(2)],
        ["force", "acceleration"],
    )
    dead = quality_check(td)
    assert not dead.passed
    assert dead.figures["dead_channels"] == 1


def test_clipping_counter() -> None:
    x = np.sin(np.linspace(0, 20, 1000))
    assert clipping(x) == 0
    y = np.clip(x, -0.9, 0.8)
    n_top = int(np.sum(y == 0.8))
    n_bot = int(np.sum(y == -0.9))
    assert clipping(y) == n_top + n_bot
    assert clipping(np.zeros(10)) == 0
    assert_allclose(clipping(np.array([0.0, 1.0, 1.0, 0.0])), 0)  # a run of 2 is not clipping
    # a fast signal clipped at 70 %: isolated samples at the limit, no runs
    z = np.sin(2.4 * np.arange(2000))
    assert clipping(z) == 0
    zc = np.minimum(z, 0.7)
    assert clipping(zc) == int(np.sum(zc == 0.7))
    # periodic data repeats its maximum once per period: not clipping
    per = np.tile(z[:100], 5)
    assert clipping(per, repeats=5) == 0
    with pytest.raises(InputError, match="min_run"):
        clipping(x, 1)


def test_low_coherence_bands_print_single_lines_once() -> None:
    from tyredamp.signal.checks import _low_bands

    f = np.array([25.0, 25.5, 26.0, 26.5, 27.0])
    low = np.array([False, True, False, True, True])
    assert _low_bands(f, low) == ["25.5 Hz", "26.5-27 Hz"]


def test_dependent_forces_finds_a_reaction_force_not_a_second_shaker() -> None:
    from tyredamp.signal.checks import dependent_forces
    from tyredamp.timedata import TimeData

    rng = np.random.default_rng(0)
    n = 4000
    body = rng.standard_normal(n)
    acc = np.convolve(body, np.exp(-np.arange(50) / 8.0), "same") / 5.0  # a dynamic response
    ground = body - 2.0 * acc  # reaction under a driven 2 kg body
    chans = [Channel(1, 2, name="body force"), Channel(1, 2, name="acc"), Channel(2, 2, name="g")]

    def td(rows: list[np.ndarray]) -> TimeData:
        noisy = [r + 0.01 * r.std() * rng.standard_normal(n) for r in rows]
        return TimeData(np.array(noisy), 100.0, chans, ["force", "acceleration", "force"])

    dep = dependent_forces(td([body, acc, ground]))
    assert {k for k, _, _ in dep} == {0, 2}
    for _, r2, uses in dep:
        assert r2 > 0.99
        assert 1 in uses  # the response is part of the combination
    # two independent shakers and a response to both: no instantaneous relation
    other = rng.standard_normal(n)
    resp = np.convolve(body + other, np.exp(-np.arange(50) / 8.0), "same")
    assert dependent_forces(td([body, resp, other])) == []
    with pytest.raises(InputError, match="min_r2"):
        dependent_forces(td([body, acc, ground]), min_r2=1.5)


def test_quality_judges_coherence_where_the_response_is_strong(chain: MCKSystem) -> None:
    f = np.linspace(0.5, 40, 400)
    frf = chain.frf(f, "accelerance", outputs=[0, 2, 4], inputs=[0])
    power = np.abs(frf.H[:, 0, :]) ** 2
    # white output noise: gamma^2 = S / (S + N) (Bendat & Piersol, Random Data, output noise,
    # no input noise), N set so that the dips (antiresonances, nodal lines) fall below 0.9
    noise = 0.5 * np.quantile(power, 0.2, axis=1, keepdims=True)
    coh = power / (power + noise)
    base = FRF(f, frf.H, "accelerance", frf.outputs, frf.inputs, coherence=coh)
    weak_only = quality_check(base)
    assert weak_only.figures["low_coherence_fraction_all_lines"] > 0.1
    assert weak_only.passed, weak_only.report()
    assert weak_only.figure == 0.0
    assert any("response is weak" in n for n in weak_only.notes)
    # the same low coherence moved to the strongest lines (leakage or a non-linearity at
    # the resonances): the data fail
    strong = power >= np.quantile(power, 0.8, axis=1, keepdims=True)
    coh_bad = np.where(strong, 0.5, 1.0)
    bad = quality_check(FRF(f, frf.H, "accelerance", frf.outputs, frf.inputs, coherence=coh_bad))
    assert not bad.passed
    # 20 % of all lines are the top 40 % of the strong half: the verdict figure is 0.4
    assert bad.figure == pytest.approx(0.4, abs=0.01)
    assert "strong response" in bad.summary
