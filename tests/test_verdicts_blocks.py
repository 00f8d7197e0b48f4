"""The fit verdicts' statistics in blocks of lines (tyredamp.studies.noise_tests) against
the same statistics on every line at once.

The blocked tests form their arrays per block (the running median of the noise
floor with its window's overlap) and sum across blocks: each value per line is
the same to the bit, the sums over the lines differ by their order only.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import identify_modes
from tyredamp.modal.model import ModalModel
from tyredamp.studies.noise_tests import (
    floor_test,
    floor_test_blocks,
    noise_test,
    noise_test_blocks,
)
from tyredamp.studies.verdicts import modal_fit_verdict, modal_verdicts

#: Sums over the lines in another order: a few roundings of a sum of up to 3000 terms
SUM_RTOL = 1e-13
FIELDS = ("ratio", "threshold", "p_value", "relative_error", "noise_relative_error", "dof")


def same_test(a: object, b: object) -> None:
    """Two NoiseTests: the same region and source, the same numbers but for rounding."""
    assert a is not None
    assert b is not None
    assert a.misfit_hz == b.misfit_hz  # type: ignore[attr-defined]
    assert a.noise_from == b.noise_from  # type: ignore[attr-defined]
    for k in (*FIELDS, "correlation", "correlation_z"):
        x, y = getattr(a, k), getattr(b, k)
        if np.isnan(x) or np.isinf(x):
            assert np.isnan(y) if np.isnan(x) else x == y, k
        else:
            if k == "p_value" and x > 0:
                # a far tail's p multiplies the statistic's rounding by its log: compared
                # on the log, to the sums' rounding (SUM_RTOL)
                x, y = np.log(x), np.log(y)
            # the sums in another order (SUM_RTOL)
            np.testing.assert_allclose(y, x, rtol=SUM_RTOL, atol=0, err_msg=k)


def data(n: int, shape: tuple[int, int], seed: int) -> tuple[np.ndarray, ...]:
    """Lines, a measured FRF (a peak, white noise) and a fit off by a smooth misfit
    and one sharp spike."""
    rng = np.random.default_rng(seed)
    f = 10.0 + 0.5 * np.arange(n)
    peak = 5.0 / (1.0 + ((f - f.mean()) / 2.0) ** 2)
    noise = rng.normal(size=(*shape, n)) + 1j * rng.normal(size=(*shape, n))
    h = peak + 0.05 * noise
    m = h + 0.04 * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    m = m + 0.02 * np.sin(f / 3.0)
    m[..., n // 3] += 1.0  # a spike: a mode sharper than the line spacing
    return f, h, m


@pytest.mark.parametrize("n", [3, 5, 6, 7, 40, 300])
@pytest.mark.parametrize("shape", [(1, 1), (2, 3)])
def test_floor_test_in_blocks_is_the_test_on_every_line(n: int, shape: tuple[int, int]) -> None:
    f, h, m = data(n, shape, seed=n)
    whole, ex_whole, notes_whole = floor_test(f, h, m)
    # the per-line excess the blocked test keeps: clipped, summed over the FRFs
    per_line = np.clip(ex_whole, 0.0, None).reshape(-1, n).sum(axis=0)
    for block in (1, 2, 7, 25, n + 5):
        test, excess, notes = floor_test_blocks(
            f, lambda a, b: h[..., a:b], lambda a, b: m[..., a:b], block=block
        )
        same_test(whole, test)
        assert np.array_equal(excess, per_line)  # per line: the same operations
        assert notes == notes_whole


def test_floor_test_in_blocks_judges_a_structured_misfit_the_same() -> None:
    f, h, _ = data(400, (1, 1), seed=3)
    m = h * 1.3  # a misfit at the peak: correlated across lines
    whole, _, notes_whole = floor_test(f, h, m)
    test, _, notes = floor_test_blocks(
        f, lambda a, b: h[..., a:b], lambda a, b: m[..., a:b], block=9
    )
    assert not whole.passed
    assert whole.structured
    same_test(whole, test)
    assert notes == notes_whole


@pytest.mark.parametrize("block", [1, 4, 33, 1000])
def test_noise_test_in_blocks_is_the_test_on_every_line(block: int) -> None:
    f, h, m = data(200, (2, 1), seed=5)
    v = np.random.default_rng(6).uniform(1e-3, 4e-3, size=h.shape)
    whole = noise_test(f, h, m, v)
    test, excess = noise_test_blocks(
        f, lambda a, b: (h[..., a:b], m[..., a:b], v[..., a:b]), block=block
    )
    same_test(whole, test)
    e2 = np.abs(m - h) ** 2  # the excess per line, formed independently
    assert np.array_equal(excess, np.clip(e2 - v, 0.0, None).reshape(-1, 200).sum(axis=0))


def modes(kind: str = "complex") -> ModalModel:
    wn = 2 * np.pi * np.array([30.0, 70.0])
    z = np.array([0.02, 0.03])
    poles = -z * wn + 1j * wn * np.sqrt(1 - z**2)
    psi = np.array([[1.0 + 0.2j, 0.5 - 0.1j]]) / np.sqrt(2j * poles.imag)
    return ModalModel(poles, psi, psi[:, :].copy(), mode_kind=kind, meta={"band_hz": [20, 90]})


def test_modal_verdicts_in_blocks_with_coherence_and_a_conversion() -> None:
    """A band from 0 Hz of an accelerance judged as a receptance fit: the blocked
    verdict converts per block and drops the 0 Hz line as the conversion does."""
    rng = np.random.default_rng(7)
    f = np.linspace(0.0, 100.0, 501)
    true = modes()
    h = true.frf(f[1:], "accelerance").H
    h = np.concatenate([np.zeros((1, 1, 1)), h], axis=-1)
    h = h + 1e-3 * np.abs(h).max() * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    coh = rng.uniform(0.9, 0.999, size=(1, f.size))
    frf = FRF(f, h, "accelerance", coherence=coh, meta={"n_averages": 8})
    off = ModalModel(true.poles * 1.01, true.psi_out, true.psi_in, meta=true.meta)
    band = f[f <= 90.0]
    res = SimpleNamespace(
        frequency=band, frf_kind="receptance", models={"complex": true, "real": off}
    )
    # the unblocked reference: a copy of the band, converted at once
    meas = frf.select_lines(np.flatnonzero(np.isin(f, band))).to("receptance")
    ref = {"complex": modal_fit_verdict(true, meas, subject="complex-mode fit", block=10**9)}
    ref["real"] = modal_fit_verdict(
        off, meas, subject="real-mode fit", better=ref["complex"], block=10**9
    )
    assert ref["real"].status == "failed"  # the case the comparison is about
    for block in (3, 64, 10**9):
        got = modal_verdicts(frf, res, block=block)  # type: ignore[arg-type]
        for k in ("complex", "real"):
            assert got[k].reasons == ref[k].reasons
            assert got[k].cautions == ref[k].cautions
            same_test(ref[k].test, got[k].test)


def test_modal_verdicts_in_blocks_without_coherence() -> None:
    """An identification of an FRF without coherence (the floor of adjacent lines):
    the verdicts in blocks of 17 lines are those in one block."""
    rng = np.random.default_rng(8)
    f = np.linspace(0.0, 200.0, 3001)[1:]
    true = modes()
    h = true.frf(f, "accelerance").H
    h = h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * rng.normal(size=h.shape)
    frf = FRF(f, h, "accelerance")
    res = identify_modes(frf, band=(10.0, 120.0), model="both")
    one = modal_verdicts(frf, res, block=10**9)
    got = modal_verdicts(frf, res, block=17)
    assert one["complex"].test is not None
    assert one["complex"].test.noise_from == "adjacent lines"
    for k in one:
        assert (got[k].status, got[k].reasons, got[k].cautions) == (
            one[k].status,
            one[k].reasons,
            one[k].cautions,
        )
        same_test(one[k].test, got[k].test)


def test_select_lines_by_slice_is_by_index() -> None:
    f = np.linspace(1.0, 10.0, 10)
    frf = FRF(f, np.arange(20.0).reshape(2, 1, 10) + 1j, coherence=np.full((2, 10), 0.5))
    for sl in (slice(2, 7), slice(None, 3), slice(8, None), slice(1, 9, 3)):
        a, b = frf.select_lines(sl), frf.select_lines(np.arange(10)[sl])
        assert np.array_equal(a.frequency, b.frequency)
        assert np.array_equal(a.H, b.H)
        assert np.array_equal(a.coherence, b.coherence)  # type: ignore[arg-type]
    with pytest.raises(Exception, match="holds no frequency line"):
        frf.select_lines(slice(5, 5))
