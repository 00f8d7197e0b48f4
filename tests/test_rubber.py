"""Rubber laws of the virtual tyre (tyredamp.virtual.rubber) and their exact truth."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.dampmodels import DampedSystem, Exponential, Hysteretic
from tyredamp.exceptions import InputError, PhysicsError, ShapeError
from tyredamp.virtual import RingTyre
from tyredamp.virtual.rubber import (
    DEFAULT_TREAD,
    WLF,
    ConstantLoss,
    FractionalZener,
    ModulusLaw,
    PronySeries,
    fit_prony,
    modal_band_system,
    rubber_system,
)


@pytest.fixture(scope="module")
def ring() -> RingTyre:
    return RingTyre(n_ring=16)


def test_fractional_zener_limits_and_derivative() -> None:
    z = FractionalZener(e0=2e6, e_inf=2e8, tau=1e-4, alpha=0.5)
    # low and high frequency limits E0 and E_inf (Pritz 1996, eq. (1)), to O((w tau)^alpha)
    assert_allclose(z.modulus(1e-12j).real, 2e6, rtol=1e-6)
    assert_allclose(z.modulus(1e16j).real, 2e8, rtol=1e-4)
    s, h = 300j + 20, 1e-3
    fd = (z.modulus(s + h) - z.modulus(s - h)) / (2 * h)
    assert_allclose(z.dmodulus(s), fd, rtol=1e-7)  # central difference, O(h^2)


def test_standard_linear_solid_loss_peak() -> None:
    # one Maxwell arm: tan delta peaks at w = 1/(tau sqrt(1 + E1/E_inf)) with
    # tan delta_max = E1 / (2 sqrt(E_inf (E_inf + E1))) (Tschoegl 1989, sec. 3.4)
    e_inf, e1, tau = 1e6, 3e6, 1e-3
    law = PronySeries(e_inf, np.array([e1]), np.array([tau]))
    w_peak = 1 / (tau * np.sqrt(1 + e1 / e_inf))
    f = w_peak / (2 * np.pi) * np.array([0.99, 1.0, 1.01])
    td = law.loss_factor(f)
    assert td[1] > td[0]
    assert td[1] > td[2]
    assert_allclose(td[1], e1 / (2 * np.sqrt(e_inf * (e_inf + e1))), rtol=1e-12)


def test_wlf_closed_form() -> None:
    w = WLF(c1=17.44, c2=51.6, t_ref=-45.0)
    assert w.log_shift(-45.0) == 0.0
    # at T - T_r = C2: log10 a_T = -C1/2 exactly
    assert_allclose(w.log_shift(-45.0 + 51.6), -17.44 / 2, rtol=1e-14)
    hot = DEFAULT_TREAD.at_temperature(40.0)
    assert hot.loss_factor([100.0])[0] < DEFAULT_TREAD.loss_factor([100.0])[0]  # rubbery side
    with pytest.raises(PhysicsError, match="WLF"):
        w.log_shift(-120.0)


def test_prony_fit_reproduces_the_law() -> None:
    pr = fit_prony(DEFAULT_TREAD, 10.0, 300.0, per_decade=2)
    f = np.geomspace(10.0, 300.0, 30)
    e_ref = np.array([DEFAULT_TREAD.modulus(2j * np.pi * x) for x in f])
    e_fit = np.array([pr.modulus(2j * np.pi * x) for x in f])
    # a smooth master curve is fitted by 2 terms a decade to better than 0.5 %
    assert_allclose(e_fit, e_ref, rtol=5e-3)


def test_ring_with_prony_rubber_is_exact(ring: RingTyre) -> None:
    pr = fit_prony(DEFAULT_TREAD, 10.0, 300.0, per_decade=1)
    sys = rubber_system(ring, pr)
    assert isinstance(sys.law, Exponential)
    # FRF: the Prony state space against the modulus applied directly
    K_r = ring.K_sidewall + ring.K_band
    e_ref = pr.modulus(2j * np.pi * 100.0).real
    f = np.array([40.0, 100.0, 250.0])
    for fi, H in zip(f, np.moveaxis(sys.receptance(f), -1, 0), strict=True):
        s = 2j * np.pi * fi
        D = s * s * ring.M + ring.K + K_r * (pr.modulus(s) / e_ref - 1)
        assert_allclose(H, np.linalg.inv(D), rtol=0, atol=1e-9 * np.abs(H).max())  # rounding
    # modes: augmented state space against Newton on the same law (independent solvers)
    exact = sys.modes()
    newton = sys.modes(max_hz=150.0)
    near = exact.poles[np.abs(exact.poles) < 2 * np.pi * 150.0 * 0.95]
    assert near.size >= 3
    for p in near:
        assert np.min(np.abs(newton.poles - p)) < 1e-8 * abs(p)


def test_other_rubber_laws(ring: RingTyre) -> None:
    assert isinstance(rubber_system(ring, ConstantLoss(1e7, 0.1)).law, Hysteretic)
    sys = rubber_system(ring, DEFAULT_TREAD, parts=("sidewall",))
    assert isinstance(sys.law, ModulusLaw)
    md = sys.modes(max_hz=120.0)
    for j, p in enumerate(md.poles):  # Newton roots of the fractional-Zener ring
        r = sys.dynamic_stiffness(p) @ md.shapes[:, j]
        assert np.linalg.norm(r) < 1e-7 * np.linalg.norm(ring.K) * np.linalg.norm(md.shapes[:, j])
    with pytest.raises(InputError, match="parts"):
        rubber_system(ring, DEFAULT_TREAD, parts=("tread",))


def test_time_response_prony_and_not_hysteretic() -> None:
    # one mass, k = 1e4, one relaxation arm: steady sine response amplitude |H(i w)|
    one = np.ones((1, 1))
    sys = DampedSystem(one, 1e4 * one, Exponential(5.0 * one, np.array([200.0])))
    f0, dt = 12.0, 1e-3
    t = np.arange(0, 6.0, dt)
    x = sys.time_response(np.sin(2 * np.pi * f0 * t)[:, None], dt)[:, 0]
    amp = np.max(np.abs(x[t > 4.0]))  # transients decayed (zeta ~ 0.02, 4 s)
    H = sys.receptance([f0])[0, 0, 0]
    # zero-order hold of a 83-sample period: amplitude error ~ (w dt)^2 / 24 plus peak sampling
    assert_allclose(amp, abs(H), rtol=2e-3)
    with pytest.raises(ShapeError, match="finite state space"):
        DampedSystem(one, 1e4 * one, Hysteretic(100 * one)).time_response(np.zeros((3, 1)), dt)


def test_modal_band_is_the_fractional_law_to_first_order() -> None:
    band = modal_band_system(RingTyre(), (40.0, 110.0))
    m = band.omega.size
    assert m >= 2
    s = 2j * np.pi * 70.0
    D_red = band.system.dynamic_stiffness(s)
    e_ref = DEFAULT_TREAD.modulus(2j * np.pi * 100.0).real
    x = complex(s * DEFAULT_TREAD.tau) ** DEFAULT_TREAD.alpha
    z = DEFAULT_TREAD
    kr = band.c_fractional * e_ref / ((z.e_inf - z.e0) * z.tau**z.alpha)
    # D_red = s^2 I + diag(omega^2) + kr (E* - E_0)/E_ref (Pritz 1996, eq. (1)), to rounding
    e_star = (z.e0 + z.e_inf * x) / (1 + x)
    expect = s * s * np.eye(m) + np.diag(band.omega**2) + kr * (e_star - z.e0) / e_ref
    assert_allclose(D_red, expect, rtol=1e-10, atol=1e-10 * np.abs(expect).max())
    # the fractional law C' s^alpha is that damping to first order in |x| (< 1 % here)
    frac = band.c_fractional * complex(s) ** band.alpha
    assert abs(x) < 0.01
    assert_allclose(D_red - s * s * np.eye(m) - np.diag(band.omega**2), frac, rtol=2 * abs(x))


def test_fit_zener_recovers_a_master_curve() -> None:
    from tyredamp.virtual.rubber import fit_zener

    true = FractionalZener(e0=3e6, e_inf=1.5e9, tau=2e-7, alpha=0.45)
    f = np.logspace(-4, 10, 60)  # a master curve over the transition (loss peak near 1e6 Hz)
    e = np.array([true.modulus(2j * np.pi * fi) for fi in f])
    fit = fit_zener(f, e.real, e.imag / e.real)
    # exact data: the four parameters to the solver's tolerance
    assert_allclose(
        [fit.e0, fit.e_inf, fit.tau, fit.alpha],
        [true.e0, true.e_inf, true.tau, true.alpha],
        rtol=1e-5,
    )
    with pytest.raises(InputError, match="at least 4"):
        fit_zener(f[:3], e.real[:3], (e.imag / e.real)[:3])
