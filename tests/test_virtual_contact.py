"""The loaded contact patch of the virtual tyre (virtual/contact.py) against closed forms
and the vertical stiffness of a public truck-tyre property file."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, PhysicsError
from tyredamp.virtual import MeasurementLayout, RingTyre, RingTyreParameters
from tyredamp.virtual.contact import (
    ContactPatch,
    contact_half_length,
    hub_stiffness,
    patch_springs,
)

BARE = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
TIRES = (
    Path(__file__).resolve().parents[2]
    / "shared" / "real-data" / "projectchrono_chrono" / "data" / "vehicle" / "feda" / "tires"
)  # fmt: skip


def _tir_value(name: str, key: str) -> float:
    path = TIRES / name
    if not path.exists():
        pytest.skip(f"real-data gallery not found ({path})")
    m = re.search(rf"^{key}\s*=\s*([-+0-9.eE]+)", path.read_text(errors="replace"), re.M)
    assert m is not None
    return float(m.group(1))


def test_patch_follows_the_mf61_length_law() -> None:
    tyre = RingTyre(layout=BARE, contact=ContactPatch(25e3))
    st = tyre.patch
    assert st is not None
    r0 = tyre.params.radius + 0.02
    rho = st.deflection
    # rho = F / K_hub and a = R0 (0.733 rho/R0 + 0.671 sqrt(rho/R0)), Pacejka &
    # Besselink 2012 eq. (A3.7) written out here (bisection to 1e-12 of R)
    assert_allclose(rho, 25e3 / st.hub_stiffness, rtol=1e-12)
    closed = r0 * (0.733 * rho / r0 + 0.671 * math.sqrt(rho / r0))
    assert_allclose(st.half_length, closed, rtol=1e-6)
    # about half the geometric chord sqrt(2 R0 rho) of the deflected circle
    assert 0.4 < st.half_length / math.sqrt(2 * r0 * rho) < 0.6
    # the chord law is the special case q_ra1 = sqrt 2, q_ra2 = 0
    chord = ContactPatch(25e3, length_sqrt=math.sqrt(2), length_linear=0.0)
    assert_allclose(contact_half_length(chord, 0.5, 0.01), math.sqrt(2 * 0.52 * 0.01), rtol=1e-12)
    # the springs cover exactly the patch: total radial stiffness k_cr 2a (cells summed)
    assert_allclose(st.radial_springs.sum(), 1.75e7 * 2 * st.half_length, rtol=1e-9)


def test_hub_stiffness_rigid_ring_limit() -> None:
    p = RingTyreParameters()
    tyre = RingTyre(p, BARE, n_ring=64)
    patch = ContactPatch(25e3)
    rad, tan = patch_springs(patch, p.radius, 64, 0.1)
    kh = hub_stiffness(1e9 * tyre.K, rad, tan, patch)
    h = 2 * np.pi / 64
    th = np.arange(64) * h
    springs = np.sum(rad * np.cos(th - np.pi) ** 2) + np.sum(tan * np.sin(th + h / 2 - np.pi) ** 2)
    # a rigid band: the tread springs alone, in parallel (condensed part ~1e-9)
    assert_allclose(kh, springs, rtol=1e-6)


def _tir_point(name: str) -> tuple[float, float, float]:
    """(pressure in Pa, nominal load in N, vertical stiffness in N/m) of a .tir file."""
    m = re.search(r"_(\d+)psi", name)  # the files carry no pressure key: their names do
    assert m is not None
    psi = 6894.757  # Pa
    k = _tir_value(name, "VERTICAL_STIFFNESS")
    return float(m.group(1)) * psi, _tir_value(name, "FNOMIN"), k


def test_hub_stiffness_follows_the_tir_files() -> None:
    names = ("335_65R22_5_G275MSA_40psi.tir", "335_65R22_5_G275MSA_95psi.tir")
    pts = [_tir_point(n) for n in names]
    (p40, f40, k40), (p95, f95, k95) = pts
    assert_allclose([k40, k95], [406.52e3, 848.55e3], rtol=1e-4)  # the file's own values
    model = []
    for p, f in ((p40, f40), (p95, f95)):
        st = RingTyre(RingTyreParameters(pressure=p), BARE, contact=ContactPatch(f)).patch
        assert st is not None
        model.append(st.hub_stiffness)
    # another tyre (295/80 against 335/65) at the file's pressure and nominal load:
    # within 20 % of each file value (model: +14 % at 2.76 bar, +1 % at 6.55 bar)
    assert_allclose(model, [k40, k95], rtol=0.20)
    # and the pressure trend: the stiffness ratio between the two files (2.09)
    # within 15 % (model 1.85; the band's bending and the tread do not scale with p)
    assert_allclose(model[1] / model[0], k95 / k40, rtol=0.15)


def test_loaded_n1_against_rigid_ring_closed_form() -> None:
    p = RingTyreParameters()
    free = RingTyre(p, BARE).ring_frequencies(1)[0, 0]
    tyre = RingTyre(p, BARE, contact=ContactPatch(25e3))
    assert tyre.patch is not None
    um = tyre.physical_system.undamped_modes()
    n = tyre.n_ring
    th = np.arange(n) * 2 * np.pi / n
    vert = np.concatenate([-np.cos(th - np.pi), np.sin(th + np.pi / n - np.pi)])  # unit vertical
    share = (um.phi.T @ tyre.M @ vert) ** 2 / (vert @ tyre.M @ vert)
    f_vert = um.frequency_hz[int(np.argmax(share))]
    # a rigid ring of band mass on the sidewalls (pi R (k_r + k_t)) and the hub stiffness
    k_sw = np.pi * p.radius * (p.radial_stiffness + p.tangential_stiffness)
    closed = free * math.sqrt(1 + tyre.patch.hub_stiffness / k_sw)
    assert_allclose(f_vert, closed, rtol=0.03)  # the band bends a little under the patch
    assert f_vert > 1.05 * free


def test_load_splits_pairs_by_hertz() -> None:
    tyre = RingTyre(layout=BARE, n_ring=32, contact=ContactPatch(25e3))
    split = np.diff(tyre.ring_frequencies(6), axis=1)[:, 0]
    # every double is split (Hz): n = 2 by about 0.5 Hz (the 0.2 m patch is near a
    # node line of both members), n = 1 and n >= 3 by several Hz
    assert split[1] > 0.2
    assert np.all(split[[0, 2, 3, 4, 5]] > 3.0)


def test_contact_errors() -> None:
    with pytest.raises(PhysicsError, match="load"):
        ContactPatch(-1.0)
    with pytest.raises(InputError, match="angle_deg"):
        ContactPatch(1e3, angle_deg=float("nan"))
    with pytest.raises(PhysicsError, match="flattens"):
        RingTyre(layout=BARE, n_ring=32, contact=ContactPatch(5e7))
    with pytest.raises(InputError, match="contact"):
        RingTyre(n_ring=32, contact=25e3)  # type: ignore[arg-type]
