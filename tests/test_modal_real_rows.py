"""The real-mode basis (modal.fit._basis.real_rows) against the direct computation of
its columns (complex divisions, mode by mode) and the real-mode fit's path."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.modal.fit import _basis
from tyredamp.modal.fit.fit import ModalFitter


def _direct_rows(
    fitter: ModalFitter,
    poles: np.ndarray,
    part: np.ndarray,
    ref: np.ndarray,
    derivatives: bool,
) -> np.ndarray:
    """The columns of real_rows, one mode at a time by their formulas (spec eq. [2]):
    ``L kappa / d``, ``L sigma (-kappa (2 s + 2 sigma) / d^2)``, ``L w_ref (-kappa 2
    Omega / d^2)`` and ``kappa / d`` at each free input, the residual terms after the
    modes."""
    s, kap, kap_low = _basis.factors(fitter)
    nin, m = fitter.n_in, poles.size
    q, npm = fitter.n_cols(m), 2 + (nin - 1)
    bt = np.zeros((q + (npm * m if derivatives else 0), nin, s.size), complex)
    for n in range(m):
        sig, om = -poles[n].real, poles[n].imag
        lr = part[n].real[:, None]
        d = s**2 + 2 * sig * s + sig**2 + om**2
        bt[n] = lr * (kap / d)
        if derivatives:
            r = q + npm * n
            bt[r] = lr * (sig * (-kap * (2 * s + 2 * sig) / d**2))
            bt[r + 1] = lr * (fitter.w_ref * (-kap * 2 * om / d**2))
            for j, k in enumerate(k for k in range(nin) if k != ref[n]):
                bt[r + 2 + j, k] = kap / d
    c0 = m
    for use, kk in ((fitter.use_upper, kap), (fitter.use_lower, kap_low)):
        if use:
            for k in range(nin):
                bt[c0, k] = kk
                c0 += 1
    return bt


@pytest.mark.parametrize(
    ("n_in", "power", "weights", "derivatives"),
    [(1, 2, False, True), (1, 0, True, True), (3, 1, False, True), (2, 2, True, False)],
)
def test_real_rows_match_direct_columns(
    n_in: int, power: int, weights: bool, derivatives: bool
) -> None:
    rng = np.random.default_rng(3)
    f = np.linspace(0.5, 200.0, 701)
    h = rng.normal(size=(2, n_in, f.size)) + 0j
    lw = rng.uniform(0.5, 2.0, f.size) if weights else None
    fit = ModalFitter(f, h, power, "real", [(0, 0)], line_weights=lw)
    # light (zeta 5e-4, on a line's neighbourhood) to heavy damping, one near 0 Hz
    fn = np.array([0.01, 20.0, 99.9, 150.0])
    zeta = np.array([0.3, 5e-4, 0.02, 0.2])
    w = 2 * np.pi * fn
    poles = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)
    part = np.ones((4, n_in), complex)
    if n_in > 1:
        part[:, 1:] = rng.normal(size=(4, n_in - 1))
    ref = np.zeros(4, np.intp)
    new = _basis.real_rows(fit, poles, part, ref, derivatives, _basis.factors(fit))
    old = _direct_rows(fit, poles, part, ref, derivatives)
    assert new.shape == old.shape
    for c in range(new.shape[0]):
        # both round 1 / d differently: relative error ~ eps |d| / |Im d| near a
        # resonance (~1e-13 at zeta 5e-4), far below 1e-12 of the column's largest entry
        scale = max(float(np.abs(old[c]).max()), 1e-300)
        assert_allclose(new[c], old[c], rtol=0, atol=1e-12 * scale)
    # the zeros stay zeros (participation columns at the other inputs)
    assert np.array_equal(new == 0, old == 0)
