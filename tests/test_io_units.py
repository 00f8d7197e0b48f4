"""Units labels of real exports parsed to SI (factor, quantity, FRF kind)."""

from __future__ import annotations

import pytest

from tyredamp import InputError
from tyredamp.io.units import frf_units, parse_unit, quantity_units

G, LBF, IN = 9.80665, 4.4482216152605, 0.0254

# label, quantity, factor to SI (labels seen in UFF exports of test software)
SIGNALS = [
    ("m/s^2", "acceleration", 1.0),
    ("m/s2", "acceleration", 1.0),
    ("m/s²", "acceleration", 1.0),
    ("m/s**2", "acceleration", 1.0),
    ("ms^-2", "acceleration", 1.0),
    ("ms-2", "acceleration", 1.0),
    ("m s^-2", "acceleration", 1.0),
    ("m.s-2", "acceleration", 1.0),
    ("m·s⁻²", "acceleration", 1.0),
    ("(m/s^2)", "acceleration", 1.0),
    ("M/S^2", "acceleration", 1.0),
    ("mm/s^2", "acceleration", 1e-3),
    ("g", "acceleration", G),
    ("G", "acceleration", G),
    ("in/s^2", "acceleration", IN),
    ("m/s", "velocity", 1.0),
    ("mm/s", "velocity", 1e-3),
    ("in/s", "velocity", IN),
    ("ips", "velocity", IN),
    ("ms^-1", "velocity", 1.0),
    ("m", "displacement", 1.0),
    ("mm", "displacement", 1e-3),
    ("µm", "displacement", 1e-6),
    ("μm", "displacement", 1e-6),
    ("um", "displacement", 1e-6),
    ("micron", "displacement", 1e-6),
    ("in", "displacement", IN),
    ("mil", "displacement", IN * 1e-3),
    ("N", "force", 1.0),
    ("kN", "force", 1e3),
    ("lbf", "force", LBF),
    ("LBF", "force", LBF),
    ("kgf", "force", G),
]

# label, FRF kind, factor to SI
FRFS = [
    ("(1/N)*(m/s²)", "accelerance", 1.0),
    ("(m/s^2)/N", "accelerance", 1.0),
    ("m/s^2/N", "accelerance", 1.0),
    ("m/s2/N", "accelerance", 1.0),
    ("m/(s^2 N)", "accelerance", 1.0),
    ("m/s²/N", "accelerance", 1.0),
    ("g/N", "accelerance", G),
    ("g/lbf", "accelerance", G / LBF),
    ("g/lb", "accelerance", G / LBF),
    ("(m/s2)/kN", "accelerance", 1e-3),
    ("mm/s/N", "mobility", 1e-3),
    ("m/s/N", "mobility", 1.0),
    ("m/(s N)", "mobility", 1.0),
    ("(in/s)/lbf", "mobility", IN / LBF),
    ("m/N", "receptance", 1.0),
    ("mm/N", "receptance", 1e-3),
    ("µm/N", "receptance", 1e-6),
    ("in/lbf", "receptance", IN / LBF),
    ("m N^-1", "receptance", 1.0),
    ("m/s^2", "accelerance", 1.0),  # no force stated: per newton
]


@pytest.mark.parametrize(("label", "quantity", "factor"), SIGNALS)
def test_signal_labels(label: str, quantity: str, factor: float) -> None:
    q, f = quantity_units(label)  # type: ignore[misc]
    assert q == quantity
    assert f == pytest.approx(factor, rel=1e-15)


@pytest.mark.parametrize(("label", "kind", "factor"), FRFS)
def test_frf_labels(label: str, kind: str, factor: float) -> None:
    k, f = frf_units(label)  # type: ignore[misc]
    assert k == kind
    assert f == pytest.approx(factor, rel=1e-15)


def test_frf_label_with_uff_denominator() -> None:
    assert frf_units("g", "lbf") == ("accelerance", pytest.approx(G / LBF))
    assert frf_units("m/s^2", "N") == ("accelerance", 1.0)
    assert frf_units("NONE", "NONE") is None
    assert frf_units("", "lbf") == (None, pytest.approx(1 / LBF))
    with pytest.raises(InputError, match="must be a force"):
        frf_units("m/s^2", "m")
    assert quantity_units("") is None
    assert quantity_units("NONE") is None


def test_parse_unit_dimensions() -> None:
    u = parse_unit("(1/N)*(m/s²)")
    assert u.dimensions == (1, -2, -1)
    assert u.frf_kind == "accelerance"
    assert parse_unit("kg").dimensions == (-1, 2, 1)  # N s^2 / m


@pytest.mark.parametrize(
    ("label", "word"),
    [
        ("furlong/fortnight", "furlong"),
        ("m/s^", "exponent"),
        ("(m/s^2", "parenthesis"),
        ("m/s^2)", "unexpected"),
        ("m$", "unexpected character"),
        ("Hz", "Hz"),
        ("MN", "MN"),
        ("N/(m/s^2)", "not a displacement, velocity or acceleration per force"),
        ("N", "per force"),
        ("N/N", "per force"),
    ],
)
def test_unreadable_labels_are_refused_by_name(label: str, word: str) -> None:
    with pytest.raises(InputError, match=r"units label") as info:
        frf_units(label)
    assert label in str(info.value)
    assert word in str(info.value)


def test_signal_label_of_wrong_dimension() -> None:
    with pytest.raises(InputError, match="'m/N'"):
        quantity_units("m/N")
    with pytest.raises(InputError, match="'s'"):
        quantity_units("s")
