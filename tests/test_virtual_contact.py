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
from tyredamp.virtual.contact import ContactPatch, hub_stiffness, patch_springs

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


def test_patch_is_the_chord_of_the_deflected_tyre() -> None:
    tyre = RingTyre(layout=BARE, contact=ContactPatch(25e3))
    st = tyre.patch
    assert st is not None
    r = tyre.params.radius
    # d = F / K_hub and a = sqrt(2 R d - d^2) (bisection to 1e-12 of R)
    assert_allclose(st.deflection, 25e3 / st.hub_stiffness, rtol=1e-12)
    assert_allclose(st.half_length, math.sqrt(2 * r * st.deflection - st.deflection**2), rtol=1e-6)
    # the springs cover exactly the patch: total radial stiffness k_cr 2a (cells summed)
    assert_allclose(st.radial_springs.sum(), 2.5e7 * 2 * st.half_length, rtol=1e-9)


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


@pytest.mark.parametrize("load", [20e3, 30e3])
def test_hub_stiffness_in_published_truck_range(load: float) -> None:
    k95 = _tir_value("335_65R22_5_G275MSA_95psi.tir", "VERTICAL_STIFFNESS")
    k40 = _tir_value("335_65R22_5_G275MSA_40psi.tir", "VERTICAL_STIFFNESS")
    assert_allclose([k40, k95], [406.52e3, 848.55e3], rtol=1e-4)  # the file's own values
    st = RingTyre(layout=BARE, contact=ContactPatch(load)).patch
    assert st is not None
    # 7.5 bar (above the 6.5 bar file) and a taller 80-series section: between the
    # 0.85 MN/m file value and 1.5 times it (PAC2002 315/80R22.5 at 8 bar: 1.0 MN/m)
    assert k95 < st.hub_stiffness < 1.5 * k95
    # softer at the 2.7 bar of the 40 psi file, as the file is (pressure part of k_r, T0)
    soft = RingTyre(RingTyreParameters(pressure=2.76e5), BARE, contact=ContactPatch(load)).patch
    assert soft is not None
    assert soft.hub_stiffness < st.hub_stiffness


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
    f = tyre.physical_system.undamped_modes().frequency_hz
    f = f[(f > 60) & (f < 200)]
    # no two in-band modes closer than 1 Hz: every n >= 2 double is split
    assert np.min(np.diff(np.sort(f))) > 1.0


def test_contact_errors() -> None:
    with pytest.raises(PhysicsError, match="load"):
        ContactPatch(-1.0)
    with pytest.raises(InputError, match="angle_deg"):
        ContactPatch(1e3, angle_deg=float("nan"))
    with pytest.raises(PhysicsError, match="flattens"):
        RingTyre(layout=BARE, n_ring=32, contact=ContactPatch(5e7))
    with pytest.raises(InputError, match="contact"):
        RingTyre(n_ring=32, contact=25e3)  # type: ignore[arg-type]
