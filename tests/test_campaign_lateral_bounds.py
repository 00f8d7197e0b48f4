"""Lateral parameters a fit left on the bound of its search stay out of campaign trends."""

from __future__ import annotations

from tyredamp.campaign.tables import lateral_trend_rows


def _row(test: str, speed: float, value: float, at_bound: int) -> dict[str, object]:
    return {
        "test_id": test,
        "model": "classic",
        "speed_kmh": speed,
        "parameter": "C_r",
        "value": value,
        "stderr": 1.0,
        "at_bound": at_bound,
    }


def test_at_bound_values_are_not_trend_observations() -> None:
    rows = [_row("a", 5.0, 10.0, 0), _row("b", 10.0, 5.0, 0), _row("c", 15.0, 1e6, 1)]
    obs, quantities = lateral_trend_rows(rows)
    assert quantities == [("C_r", "C_r_std")]
    by_test = {o["test_id"]: o for o in obs}
    assert by_test["a"]["C_r"] == 10.0
    assert by_test["c"]["C_r"] is None  # the bound, not an estimate
