"""The air cavity of the virtual tyre against closed forms (virtual/cavity.py)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.mechanics import MCKSystem
from tyredamp.virtual import MeasurementLayout, RingTyre, RingTyreParameters, difference_symbol
from tyredamp.virtual.cavity import Cavity, cavity_blocks, cavity_dispersion, loaded_split_estimate
from tyredamp.virtual.contact import ContactPatch
from tyredamp.virtual.ring import _operators

BARE = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
N = 32


def _air_only(cav: Cavity, n: int = N, area_change: np.ndarray | None = None) -> MCKSystem:
    blk = cavity_blocks(
        cav, _operators(n, 4).D, pressure=7.5e5, band_width=0.24, area_change=area_change
    )
    return MCKSystem(blk.m_air, blk.c_air, blk.k_air)


def _ring_q(p: RingTyreParameters, s: float) -> np.ndarray:
    """The ring's 2x2 stiffness per unit length (Soedel; ring.py module docstring)."""
    r, ea, ei, t0 = p.radius, p.membrane_stiffness, p.bending_stiffness, p.hoop_tension
    qaa = (ea + t0) / r**2 + ei * s**4 / r**4 + t0 * (s**2 - 1) / r**2 + p.radial_stiffness
    qac = (ea + t0) * s / r**2 + ei * s**3 / r**4
    qcc = (ea + t0) * s**2 / r**2 + ei * s**2 / r**4 + p.tangential_stiffness
    return np.array([[qaa, qac], [qac, qcc]])


def test_rigid_walled_torus_modes_are_n_c_over_2_pi_rc() -> None:
    cav = Cavity()
    f = _air_only(cav).undamped_modes().frequency_hz
    n = np.arange(1, 6)
    s = difference_symbol(n, N, 4)
    exact = s * cav.sound_speed / (2 * np.pi * cav.mean_radius)
    # each n is a double; the discrete modes are exact harmonics (rounding 1e-10)
    assert_allclose(f[: 2 * n.size : 2], exact, rtol=1e-10)
    assert_allclose(f[1 : 2 * n.size : 2], exact, rtol=1e-10)
    # against the continuous n c / (2 pi R_c) = 140.0 n Hz: 4th-order differences, n h < 1
    assert_allclose(f[0], cav.first_mode_hz, rtol=1e-3)
    assert cav.first_mode_hz == pytest.approx(140.0, abs=0.1)  # c / (2 pi 0.39 m)


def test_acoustic_loss_factor_at_first_mode() -> None:
    cav = Cavity(loss_factor=0.02)
    cm = _air_only(cav).complex_modes()
    s1 = float(difference_symbol([1], N, 4)[0])
    # bulk-modulus loss eta K / omega_1: zeta = eta omega / (2 omega_1), omega = s(1) c / R_c
    assert_allclose(cm.damping_ratio[0], 0.02 * s1 / 2, rtol=1e-6)  # eigen-solver rounding


def test_coupled_ring_cavity_matches_closed_form_per_wave_number() -> None:
    p = RingTyreParameters()
    cav = Cavity()
    tyre = RingTyre(p, BARE, n_ring=N, cavity=cav)
    assert tyre.n_dof == 3 * N - 1
    f = tyre.physical_system.undamped_modes().frequency_hz
    for n in (1, 2, 3, 4):
        s = float(difference_symbol([n], N, tyre.fd_order)[0])
        closed = cavity_dispersion(
            _ring_q(p, s), s, mass_per_length=p.mass_per_length, radius=p.radius,
            cavity=cav, pressure=p.pressure, band_width=p.width,
        )  # fmt: skip
        for fc in closed:
            # every closed-form root is a double of the discrete system (rounding 1e-8)
            assert np.sort(np.abs(f - fc) / fc)[1] < 1e-8
    # the coupling moves the flexural n = 1 mode and the cavity mode apart
    bare = RingTyre(p, BARE, n_ring=N).ring_frequencies(1)[0, 0]
    s1 = float(difference_symbol([1], N, 4)[0])
    coupled = cavity_dispersion(
        _ring_q(p, s1), s1, mass_per_length=p.mass_per_length, radius=p.radius,
        cavity=cav, pressure=p.pressure, band_width=p.width,
    )  # fmt: skip
    assert coupled[0] < bare
    assert coupled[1] > s1 * cav.first_mode_hz


def test_without_band_coupling_closed_form_separates() -> None:
    p = RingTyreParameters()
    cav = Cavity()
    f = cavity_dispersion(
        _ring_q(p, 2.0), 2.0, mass_per_length=p.mass_per_length, radius=p.radius,
        cavity=cav, pressure=p.pressure, band_width=0.0,
    )  # fmt: skip
    from tyredamp.virtual import ring_dispersion

    ring = [ring_dispersion(p, [2])[0], ring_dispersion(p, [2], branch="extensional")[0]]
    # b = 0: the ring's two roots and the rigid-walled 2 c / (2 pi R_c) (rounding 1e-9)
    assert_allclose(np.sort(f), np.sort([*ring, 2 * cav.first_mode_hz]), rtol=1e-9)


def test_loaded_split_against_first_order_estimate() -> None:
    cav = Cavity()
    n = 64
    th = np.arange(n) * 2 * np.pi / n
    phi = np.angle(np.exp(1j * (th - np.pi)))
    # a flattened 0.30 m patch of a 0.5 m band, 20 mm deep, 0.24 m wide
    depth = np.clip(0.5 - 0.48 / np.cos(np.clip(phi, -0.3, 0.3)), 0.0, None)
    depth[np.abs(phi) > 0.3] = 0.0
    da = -0.24 * depth
    f = _air_only(cav, n, da).undamped_modes().frequency_hz
    f0, split = loaded_split_estimate(cav, da)
    # first-order perturbation of the horn equation; second order in dA/A ~ 0.1
    assert_allclose(f[1] - f[0], split, rtol=0.15)
    assert_allclose(0.5 * (f[0] + f[1]), f0, rtol=0.01)


def cavity_pair(tyre: RingTyre) -> np.ndarray:
    """Frequencies (Hz) of the two modes with the largest air share (the n = 1 cavity pair)."""
    um = tyre.physical_system.undamped_modes()
    air = np.sum(um.phi[tyre.cavity_dofs] ** 2, axis=0)  # M_air = I: kinetic-energy share
    air[(um.frequency_hz < 100) | (um.frequency_hz > 200)] = 0.0  # the n = 1 band
    return np.sort(um.frequency_hz[np.argsort(air)[-2:]])


def test_loaded_tyre_cavity_split_is_a_few_hz() -> None:
    free = cavity_pair(RingTyre(layout=BARE, n_ring=N, cavity=Cavity()))
    tyre = RingTyre(layout=BARE, n_ring=N, cavity=Cavity(), contact=ContactPatch(25e3))
    pair = cavity_pair(tyre)
    assert tyre.patch is not None
    assert free[1] - free[0] < 1e-6 * free[0]  # axisymmetric: an exact double
    from tyredamp.virtual.contact import patch_intrusion

    da = -0.24 * patch_intrusion(tyre.patch, tyre.contact, 0.5, N)  # type: ignore[arg-type]
    _, est = loaded_split_estimate(Cavity(), da)
    # the band's own n = 1 modes shift the pair; within a factor 2 of the rigid-walled estimate
    assert 0.5 * est < pair[1] - pair[0] < 2.0 * est
