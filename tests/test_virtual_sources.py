"""Physical damping sources of the virtual tyre and the decomposition of C'_off (sources.py)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError, PhysicsError
from tyredamp.virtual import MeasurementLayout, RingTyre, RingTyreParameters
from tyredamp.virtual.assembly import Splice
from tyredamp.virtual.cavity import Cavity
from tyredamp.virtual.contact import ContactPatch
from tyredamp.virtual.sources import damping_decomposition, tip_loss_damping

N = 32


def test_sources_sum_to_the_damping_matrix() -> None:
    p = RingTyreParameters(membrane_loss_factor=0.02)
    tyre = RingTyre(p, n_ring=N, splice=Splice(), cavity=Cavity(), contact=ContactPatch(25e3))
    total = sum(tyre.damping_sources.values())
    assert_allclose(tyre.physical_system.C, total, atol=1e-12 * np.abs(total).max())  # symmetric
    assert set(tyre.damping_sources) == {
        "sidewall radial", "sidewall tangential", "band bending", "band membrane",
        "splice", "attachment", "contact", "cavity",
    }  # fmt: skip


def test_decomposition_shares_sum_to_one_and_attachment_closed_form() -> None:
    lay = MeasurementLayout(attachment_mass=0.0, attachment_damping=30.0)
    tyre = RingTyre(layout=lay, n_ring=N)
    dd = damping_decomposition(tyre)
    assert_allclose(dd.share.sum(), 1.0, rtol=1e-10)  # projection shares, exact
    # axisymmetric ring: only the drive-point damper couples different modes, and
    # C'_kj = c phi_k(0) phi_j(0) (radial spec eq. [14]); the rest is rounding
    um = tyre.physical_system.undamped_modes()
    sel = um.frequency_hz <= 200
    phi0 = um.phi[0, sel]
    closed = 30.0 * np.outer(phi0, phi0)
    off = dd.modal_damping - np.diag(np.diag(dd.modal_damping))
    assert_allclose(off, closed - np.diag(np.diag(closed)), atol=1e-9 * np.abs(closed).max())
    assert dd.as_dict()["attachment"] == pytest.approx(1.0, abs=1e-6)


def test_splice_adds_its_mass_and_splits_pairs() -> None:
    p = RingTyreParameters()
    lay = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    sp = Splice(arc_length=0.04, mass_fraction=0.3)
    bare = RingTyre(p, lay, n_ring=64)
    spl = RingTyre(p, lay, n_ring=64, splice=sp)
    added = np.trace(spl.M) - np.trace(bare.M)
    # radial (node cells) and tangential (mid-point cells) each get rho A L f
    assert_allclose(added, 2 * p.mass_per_length * 0.04 * 0.3, rtol=1e-9)
    f = spl.ring_frequencies(4)
    assert np.all(f[:, 1] - f[:, 0] > 1e-3)  # a splice splits every double (Hz)


def test_loaded_tyre_non_proportionality_from_tyre_sources() -> None:
    tyre = RingTyre(n_ring=N, splice=Splice(), cavity=Cavity(), contact=ContactPatch(25e3))
    dd = damping_decomposition(tyre)
    share = dd.as_dict()
    # the tread in the patch dominates; the tip is below 10 % of C'_off
    assert abs(share["attachment"]) < 0.10
    assert share["contact"] > 0.5
    assert dd.offdiagonal_share > 0.2
    assert "attachment" in dd.format()


@pytest.mark.parametrize("f", [50.0, 150.0, 300.0])
def test_tip_loss_damping_against_the_tip_mass_on_the_tread(f: float) -> None:
    m, k, eta = 0.01, 4e4, 0.15
    w = 2 * np.pi * f
    # tip mass on the lossy tread spring, band held at x = 1 m: solve the tip's
    # equation -w^2 m y = -k* (y - x) and take the force on the band k* (y - x)
    ks = k * (1 + 1j * eta)
    y = ks / (ks - w * w * m)
    force = ks * (y - 1.0)
    # a dashpot c to ground gives force -i w c x: its part in quadrature
    assert_allclose(tip_loss_damping(m, k, eta, f), -force.imag / w, rtol=1e-12)  # rounding


def test_free_tyre_non_proportionality_from_tyre_sources() -> None:
    lay = MeasurementLayout()
    # the default tip loss: 10 g below the gauge on the 4e4 N/m tread under a 2 x 2 cm
    # tip (2 MPa over 20 mm), loss factor 0.15, at the 200 Hz top of the band
    assert_allclose(lay.attachment_damping, tip_loss_damping(0.01, 4e4, 0.15, 200.0), rtol=0.05)
    dd = damping_decomposition(RingTyre(n_ring=N, cavity=Cavity()))
    share = dd.as_dict()
    # the band-air modes carry the sidewall loss: the tip below 10 % of C'_off
    assert abs(share["attachment"]) < 0.10
    assert share["sidewall radial"] > 0.5
    assert 0.02 < dd.offdiagonal_share < 0.3


def test_errors() -> None:
    with pytest.raises(PhysicsError, match="arc_length"):
        Splice(arc_length=0.0)
    with pytest.raises(InputError, match="splice"):
        RingTyre(n_ring=N, splice=1.0)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="band"):
        damping_decomposition(RingTyre(n_ring=N), band=(300.0, 301.0))
    with pytest.raises(InputError, match="stiffness"):
        tip_loss_damping(0.01, 0.0, 0.15, 100.0)
