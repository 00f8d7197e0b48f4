"""The virtual campaign's load model and scatter (tyredamp.campaign.virtual)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.campaign.virtual import (
    CONTACT_STIFFNESS,
    VirtualCampaign,
    contact_patch,
    tyre_parameters,
)
from tyredamp.exceptions import InputError
from tyredamp.virtual import RingTyreParameters


@pytest.mark.parametrize("load", [5000.0, 20000.0, 30000.0])
def test_contact_patch_springs_add_up_to_the_patch_stiffness(load: float) -> None:
    p = RingTyreParameters(pressure=7.5e5)
    springs = contact_patch(p, load)
    # patch length 2a = F / (p b); total stiffness k_c 2a, centred on 180 deg
    length = load / (p.pressure * p.width)
    total = sum(s.stiffness for s in springs)
    assert_allclose(total, CONTACT_STIFFNESS * length, rtol=1e-12)
    angles = np.array([s.angle_deg for s in springs])
    weights = np.array([s.stiffness for s in springs])
    assert_allclose(np.sum(angles * weights) / total, 180.0, atol=1e-9)
    # every spring sits on a ring node (the imperfection is applied at the nearest node)
    assert_allclose(angles / (360 / 64), np.round(angles / (360 / 64)), atol=1e-9)


def test_contact_patch_is_smooth_in_load_and_empty_without_load() -> None:
    p = RingTyreParameters(pressure=6e5)
    assert contact_patch(p, 0.0) == ()
    a = sum(s.stiffness for s in contact_patch(p, 20000.0))
    b = sum(s.stiffness for s in contact_patch(p, 20000.0 * (1 + 1e-6)))
    assert math.isclose(b / a, 1 + 1e-6, rel_tol=1e-9)  # linear, no jump at node cells
    with pytest.raises(InputError, match="load_n"):
        contact_patch(p, -1.0)
    with pytest.raises(InputError, match="inflation"):
        contact_patch(RingTyreParameters(pressure=0.0), 1000.0)


def test_manufacturing_scatter_is_seeded_and_small() -> None:
    base = RingTyreParameters()
    a, b = tyre_parameters(0, seed=0), tyre_parameters(1, seed=0)
    assert a == tyre_parameters(0, seed=0)
    assert a != b
    for t in (a, b):
        assert abs(t.bending_stiffness / base.bending_stiffness - 1) < 0.15  # 5 sigma of 3 %
        assert abs(t.mass_per_length / base.mass_per_length - 1) < 0.05
    assert VirtualCampaign().held_out_bar == (6.375, 7.125, 7.875, 8.625)
