"""The damping bound of the residual search's trials (modal.search.search.sigma_bound and
ModalFitter.fit_added(sigma_max=...))."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose

from tyredamp.mechanics.modal_sum import pole_from_frequency_damping
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.search.search import sigma_bound

from .helpers import chain_system

F = np.linspace(0.5, 40.0, 400)


def test_sigma_bound_is_the_decay_rate_of_the_damping_ratio() -> None:
    # closed form: the pole of damping ratio zeta and damped frequency omega has
    # -Re p = sigma_bound(zeta, omega) (independently: from f_n and zeta)
    for zeta in (0.01, 0.2, 0.6):
        p = pole_from_frequency_damping(np.array([7.0]), np.array([zeta]))[0]
        # two routes to the same number: round-off only
        assert_allclose(sigma_bound(zeta, p.imag), -p.real, rtol=1e-12)


def test_a_bounded_trial_stays_below_the_bound_and_finds_a_mode_within_it() -> None:
    sys_ = chain_system()
    cm = sys_.complex_modes()
    h = sys_.frf(F, kind="accelerance", inputs=[0]).H
    fit = ModalFitter(F, h, 2, "complex", [(0, 0)], upper=False, lower=False)
    part = cm.psi[[0]].T
    k = int(np.argsort(cm.poles.imag)[2])
    keep = np.delete(np.arange(cm.poles.size), k)
    lo, hi = 0.8 * cm.poles[k].imag, 1.2 * cm.poles[k].imag
    zeta_k = -cm.poles[k].real / abs(cm.poles[k])
    args = (cm.poles[keep], part[keep], cm.poles[k] * (1.02 + 0.01j), part[k])
    # a bound above the mode's damping: the mode itself (noise-free: solver tolerance)
    p, _, _ = fit.fit_added(*args, omega_bounds=(lo, hi), sigma_max=sigma_bound(0.2, hi))
    assert_allclose(p, cm.poles[k], rtol=1e-8)
    # a bound below it: the trial stops at the bound (the iteration's projection
    # onto the box is exact up to its 1e-9 margin in log(sigma))
    cap = sigma_bound(0.5 * zeta_k, hi)
    p, _, _ = fit.fit_added(*args, omega_bounds=(lo, hi), sigma_max=cap)
    assert -p.real <= cap * (1 + 1e-8)
    assert -p.real >= cap * (1 - 1e-3)
