"""The virtual campaign's physical tyre, its load and pressure and its scatter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.campaign.virtual import VirtualCampaign, campaign_tyre, tyre_parameters
from tyredamp.studies.radial import virtual_tyre
from tyredamp.virtual import RingTyreParameters
from tyredamp.virtual.sources import damping_decomposition


def test_campaign_tyre_is_the_tyre_of_simulate_radial() -> None:
    # without scatter, the campaign's tyre is the physical tyre of `tyredamp simulate radial`
    a = campaign_tyre(RingTyreParameters(), 7.5, 25000.0, (1, 5))
    b = virtual_tyre(7.5, (1, 5), load_n=25000.0)
    for x, y in zip(
        (a.system.M, a.system.C, a.system.K), (b.system.M, b.system.C, b.system.K), strict=True
    ):
        assert_allclose(x, y, rtol=1e-12, atol=0)  # the same assembly: rounding only
    assert a.nonproportionality == 1.0
    assert a.cavity is not None
    assert campaign_tyre(RingTyreParameters(), 7.5, 0.0).contact is None  # no load, no patch


def test_load_and_pressure_act_through_the_contact_patch() -> None:
    params = tyre_parameters(0)
    half = {}
    for p in (6.0, 9.0):
        for load in (10000.0, 30000.0):
            patch = campaign_tyre(params, p, load).patch
            assert patch is not None
            # deflection from the tyre's own vertical stiffness, rho = F / K_hub
            assert_allclose(patch.deflection, load / patch.hub_stiffness, rtol=1e-9)  # solver
            # MF-Tyre 6.1 contact length (Pacejka & Besselink 2012, eq. (A3.7)) with the
            # patch's defaults q_ra1 = 0.671, q_ra2 = 0.733, R_0 = R + 0.02 m
            r0 = params.radius + 0.02
            x = patch.deflection / r0
            # bisection on a stops within its tolerance of the law (contact.solve_patch)
            assert_allclose(patch.half_length, r0 * (0.733 * x + 0.671 * math.sqrt(x)), rtol=1e-4)
            half[(p, load)] = patch.half_length
    # a heavier load lengthens the patch; a higher pressure stiffens the tyre and shortens it
    assert half[(6.0, 30000.0)] > half[(6.0, 10000.0)] > half[(9.0, 10000.0)]
    assert half[(6.0, 30000.0)] > half[(9.0, 30000.0)] > half[(9.0, 10000.0)]


@pytest.mark.parametrize("drive_points", [(1,), (1, 5)])
def test_drive_point_attachment_is_a_small_part_of_the_nonproportionality(
    drive_points: tuple[int, ...],
) -> None:
    # the shaker tips (10 g, 2 N s/m) carry less than a tenth of the off-diagonal C'
    tyre = campaign_tyre(tyre_parameters(0), 6.0, 30000.0, drive_points)
    d = damping_decomposition(tyre)
    k = d.names.index("attachment")
    assert abs(d.share[k]) < 0.1
    assert d.norm_ratio[k] < 0.1
    assert "contact" in d.names
    assert "cavity" in d.names


def test_manufacturing_scatter_is_seeded_and_small() -> None:
    base = RingTyreParameters()
    a, b = tyre_parameters(0, seed=0), tyre_parameters(1, seed=0)
    assert a == tyre_parameters(0, seed=0)
    assert a != b
    for t in (a, b):
        assert abs(t.bending_stiffness / base.bending_stiffness - 1) < 0.15  # 5 sigma of 3 %
        assert abs(t.mass_per_length / base.mass_per_length - 1) < 0.05
    assert VirtualCampaign().held_out_bar == (6.375, 7.125, 7.875, 8.625)


def test_a_breathing_shape_with_standard_errors_gets_its_amplitude_error() -> None:
    # a loaded tyre's mixed shape can be best fitted by n = 0; its one-coefficient
    # covariance gives the amplitude error sqrt(sigma^2 / (2 J)) of a constant fitted to J
    # points of complex standard error sigma (half the complex variance in the real part)
    from tyredamp.tyremodel.wavenumber import _label_shape

    theta = np.arange(16) * 2 * np.pi / 16
    sigma = np.full(16, 0.1)
    label = _label_shape(theta, np.full(16, 2.0 + 0j), sigma, 7)
    assert label.n == 0
    assert label.amplitude_std is not None
    assert_allclose(label.amplitude_std, math.sqrt(0.1**2 / (2 * 16)), rtol=1e-12)  # rounding
