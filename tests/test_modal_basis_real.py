"""The real-mode basis (modal.fit._basis.basis_real): its derivative columns against
finite differences."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.modal.fit import _basis
from tyredamp.modal.fit.fit import ModalFitter


@pytest.mark.parametrize("n_in", [1, 3])
def test_real_basis_derivatives_match_finite_differences(n_in: int) -> None:
    # D's first two columns per mode are d Phi / d x1 and d Phi / d x2 with
    # sigma = w_ref exp(x1), Omega = w_ref x2 (modal.fit.fit's parameters); the others
    # are Phi's column of the mode at each free input (participation entries)
    rng = np.random.default_rng(1)
    f = np.linspace(1.0, 200.0, 300)
    h = rng.normal(size=(2, n_in, f.size)) + 0j
    fit = ModalFitter(f, h, 2, "real", [(0, 0)])
    poles = np.array([-3.0 + 400.0j, -8.0 + 900.0j])
    part = rng.normal(size=(2, n_in)) + 0j
    ref = np.array([0, n_in - 1])
    phi, D = _basis.basis_real(fit, poles, part, ref, True)
    npm = 2 + (n_in - 1)
    assert D.shape == (phi.shape[0], 2 * npm)
    eps = 1e-6
    for n in range(2):
        sig, om = -poles[n].real, poles[n].imag
        for j in range(2):
            cols = []
            for e in (eps, -eps):  # central differences in x1 = log(sigma / w_ref), x2
                moved = poles.copy()
                moved[n] = (
                    -sig * np.exp(e) + 1j * om if j == 0 else -sig + 1j * (om + fit.w_ref * e)
                )
                cols.append(_basis.basis_real(fit, moved, part, ref, False)[0][:, n])
            fd = (cols[0] - cols[1]) / (2 * eps)
            # central difference: error ~ eps^2 times the third derivative's scale
            # ((w_ref eps / sigma)^2 ~ 2e-7 of the largest entry here, round-off ~1e-10)
            assert_allclose(D[:, n * npm + j], fd, rtol=0, atol=1e-6 * np.abs(fd).max())
        free = [k for k in range(n_in) if k != ref[n]]
        for j, k in enumerate(free):
            col = D[:, n * npm + 2 + j].view(complex).reshape(n_in, -1)
            base = phi[:, n].view(complex).reshape(n_in, -1)[ref[n]] / part[n, ref[n]].real
            # the mode's column at input k alone: the same numbers, round-off only
            assert_allclose(col[k], base, rtol=1e-12)
            assert not np.any(np.delete(col, k, axis=0))
