"""A mode family's own frequency trend (tyredamp.campaign.family_trend)."""

from __future__ import annotations

import math

import numpy as np
from numpy.testing import assert_allclose
from scipy import stats

from tyredamp.campaign.family_trend import change_limit, family_trend, reference_frequency


def test_straight_line_prediction_and_its_variance_are_the_closed_form() -> None:
    # one condition: the plane is the least-squares line and the variance of a new
    # observation s^2 (1 + 1/n + (x0 - xbar)^2 / Sxx) (simple linear regression)
    rng = np.random.default_rng(3)
    x = np.array([6.0, 6.5, 7.0, 7.5, 8.0])
    f = 140.0 + 3.0 * x + 0.2 * rng.standard_normal(x.size)
    members = [
        ({"tyre": "A", "pressure_bar": float(a)}, float(b)) for a, b in zip(x, f, strict=True)
    ]
    got = family_trend(members, {"tyre": "A", "pressure_bar": 9.0}, {"pressure_bar": 3.0})
    assert got is not None
    slope, icpt = np.polyfit(x, f, 1)
    s2 = float(np.sum((f - (icpt + slope * x)) ** 2)) / (x.size - 2)
    sxx = float(np.sum((x - x.mean()) ** 2))
    var = s2 * (1 + 1 / x.size + (9.0 - x.mean()) ** 2 / sxx)
    assert_allclose(got[0], icpt + slope * 9.0, rtol=1e-12)  # two solvers: rounding
    assert_allclose(got[1], var, rtol=1e-9)  # rounding of the normal equations
    assert got[2] == x.size - 2


def test_too_few_members_of_the_tyre_use_all_members_or_none() -> None:
    span = {"pressure_bar": 3.0}
    mine = [
        ({"tyre": "A", "pressure_bar": 6.0}, 140.0),
        ({"tyre": "A", "pressure_bar": 7.0}, 143.0),
    ]
    other = [({"tyre": "B", "pressure_bar": p}, 141.0 + 3 * (p - 6)) for p in (6.0, 7.0, 8.0)]
    target = {"tyre": "A", "pressure_bar": 8.0}
    assert family_trend(mine, target, span) is None  # 2 members, 2 coefficients: no scale
    pooled = family_trend(mine + other, target, span)
    assert pooled is not None
    assert pooled[2] == 3  # 5 members, 2 coefficients
    # without a trend the change is not bounded; with one, never below the member variance
    assert reference_frequency(150.0, None, 0.01) == (150.0, None, math.inf)
    assert reference_frequency(150.0, (149.0, 0.0, 3.0), 0.01) == (149.0, 0.01, 3.0)


def test_change_limit_is_the_squared_student_t_quantile() -> None:
    for dof in (2.0, 5.0, 40.0):
        t = stats.t.ppf(1 - 1e-3 / 2, dof)  # two-sided Student t
        assert_allclose(change_limit(dof, 1e-3), t**2, rtol=1e-8)  # quantile solvers
    assert_allclose(change_limit(math.inf, 1e-3), stats.norm.ppf(1 - 1e-3 / 2) ** 2, rtol=1e-8)
