"""The rolling study's count of false waves (``studies.rolling._false``)."""

from types import SimpleNamespace

from tyredamp.studies.rolling import _false

TRUTH = [
    {"wave_number": 8, "direction": "backward", "fixed_hz": 180.0},
    {"wave_number": 3, "direction": "forward", "fixed_hz": 95.0},
]


def _wave(n: int, direction: str | None, hz: float) -> SimpleNamespace:
    return SimpleNamespace(wave_number=n, direction=direction, fixed_hz=hz)


def test_a_wave_of_unresolved_direction_matches_either_direction() -> None:
    # the Nyquist wave of 16 sensors without an in-tyre sensor: no direction
    assert _false([_wave(8, None, 180.3)], TRUTH) == 0


def test_a_wrong_direction_or_number_or_frequency_is_false() -> None:
    waves = [_wave(8, "forward", 180.0), _wave(4, None, 180.0), _wave(3, "forward", 99.0)]
    assert _false(waves, TRUTH) == 3
