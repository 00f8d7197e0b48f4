"""pLSCF poles and the automatic selection rules."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, ShapeError
from tyredamp.modal.indicators import mac
from tyredamp.modal.lscf import plscf
from tyredamp.modal.selection import cluster_poles, stability_flags

from .helpers import chain_system

F = np.linspace(0.1, 40.0, 800)


def _nearest(found: np.ndarray, true: np.ndarray) -> np.ndarray:
    return np.array([found[np.argmin(np.abs(found - t))] for t in true])


def test_plscf_high_order_recovers_exact_poles() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, inputs=[0]).H
    ps = plscf(F, h, 24)
    idx = ps.at_order(24)
    got = _nearest(ps.poles[idx], cm.poles)
    # noise-free data; the z-domain model needs over-modelling, at order 24 the
    # poles agree to ~1e-7 relative
    assert_allclose(got, cm.poles, rtol=1e-6)
    assert set(np.unique(ps.order)) <= set(range(1, 25))


def test_plscf_band_not_starting_at_zero_and_two_inputs() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, inputs=[0, 3]).H
    ps = plscf(F, h, 14, band=(8.0, 40.0))  # normalised band: only modes 2..6 inside
    idx = ps.at_order(14)
    sel = cm.frequency_hz > 9.0
    got = _nearest(ps.poles[idx], cm.poles[sel])
    assert_allclose(got, cm.poles[sel], rtol=1e-4)  # over-modelled, noise-free
    # participation vectors are the mode shapes at the inputs (up to scale)
    j = [int(idx[np.argmin(np.abs(ps.poles[idx] - p))]) for p in cm.poles[sel]]
    m = mac(ps.participation[j].T, cm.psi[[0, 3]][:, sel])
    assert np.all(np.diag(m) > 0.999)


def test_selection_finds_each_mode_once_with_noise() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    rng = np.random.default_rng(5)
    h = sys_.frf(F, inputs=[0]).H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    h = h + 0.01 * rms * (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape))
    ps = plscf(F, h, 40)
    flags = stability_flags(ps)
    kept, rejected = cluster_poles(ps, flags)
    f_kept = np.array([c.frequency_hz for c in kept])
    assert f_kept.size == cm.poles.size
    assert_allclose(f_kept, cm.frequency_hz, rtol=1e-3)  # pLSCF medians, 40 dB noise
    assert all(c.fraction >= 0.3 for c in kept)
    assert all(c.fraction < 0.3 for c in rejected)
    # stable implies admissible: positive damping below 20 %
    st = flags.stable
    assert np.all((ps.damping_ratio[st] > 0) & (ps.damping_ratio[st] <= 0.2))


def test_plscf_input_checks() -> None:
    h = np.ones((2, 1, 10), complex)
    f = np.arange(1.0, 11.0)
    with pytest.raises(InputError, match="max_order"):
        plscf(f, h, 20)
    with pytest.raises(ShapeError, match="H"):
        plscf(f, h[:, :, :5], 2)
    with pytest.raises(InputError, match="band"):
        plscf(f, h, 2, band=(5.0, 2.0))
    with pytest.raises(InputError, match="min_fraction"):
        cluster_poles(
            plscf(F, chain_system().frf(F).H, 4),
            stability_flags(plscf(F, chain_system().frf(F).H, 4)),
            min_fraction=0.0,
        )
