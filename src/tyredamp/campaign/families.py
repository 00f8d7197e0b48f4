"""Names of the campaign's mode families: circumferential wave number and pair member.

The tracking (:mod:`.tracking`) groups the modes of all tests into families
``F1, F2, ...`` by shape and frequency. A ring tyre's modes have a meaning
that a number does not carry: the circumferential wave number ``n`` (the
number of full waves around the tyre) and, for the doubled modes of every
``n >= 1``, the member of the pair (``cos``: antinode at the drive point,
``sin``: node there). This module names each family from its modes' shapes.

Per mode
--------
Where the shape is known at points with an angular position (the outputs'
``angle_deg``, or the inputs' for a roving-hammer test), every wave number
the angles resolve (:func:`~tyredamp.tyremodel.harmonics.resolved_wave_numbers`)
is fitted as a single harmonic ``a cos n theta + b sin n theta``
(:func:`~tyredamp.tyremodel.harmonics.harmonic_fit`, complex ``a``, ``b``);
the mode's wave number is the one with the largest energy fraction, and it
counts as a single harmonic when that fraction is at least
:data:`MIN_FRACTION` (the labelling criterion of
:func:`~tyredamp.tyremodel.wavenumber.wave_number_analysis`). The member
follows from the antinode angle ``theta_0`` of the shape (rotated to its
principal phase): ``cos`` when the antinode is nearer the reference (the first
input's angle) than the node, i.e. ``|n (theta_0 - theta_ref)| < 45 deg``
modulo 180 deg, else ``sin``.

A rolling tyre's modes are travelling waves, not standing pairs: with
``a cos n theta + b sin n theta = (a - i b)/2 e^{i n theta} + (a + i b)/2
e^{-i n theta}`` and the time dependence ``e^{i omega t}``, the second term
travels towards ``+theta`` (Huang & Soedel, J. Sound Vib. 115(2) (1987)
253-274: the split of a rotating ring's modes into two waves; the
decomposition is the spatial Fourier series of the shape). A shape whose
share ``|a + i b|^2 / (|a - i b|^2 + |a + i b|^2)`` is at least 3/4 is the
member ``forward`` (travelling towards increasing angle: with the rotation
when the angles run that way), at most 1/4 ``backward``; in between it is a
standing wave and named ``cos``/``sin`` as above.

Per family
----------
The family's wave number is the one that most of its single-harmonic modes
carry, provided they are a majority of the family's labelled modes
(``agreement`` is that share). A loaded tyre's contact patch mixes wave
numbers (a patch at one angle couples harmonic ``n`` with ``n +- 1``,
``n +- 2``, ...), and a mode near the air cavity's resonance shares its
motion with the cavity's, so a family's shapes can all be mixtures, none a
single harmonic. Such a family takes the *dominant* harmonic: the one with the largest summed energy
fraction over its modes' best harmonics; it is marked ``mixed`` and its label
says so (``n=1 mixed``), with ``agreement`` the share of its modes whose best
harmonic that is and ``fraction`` their mean energy fraction. A family
whose single-harmonic modes do not agree (no majority: modes of different
wave numbers tracked together) or that has no shape to analyse has no wave
number and says so. Its member is the majority member of
its modes (``pair`` for a family tracked as a pair, whose slots ``a``/``b``
are the lower and upper member). The label reads ``n=2``, ``n=2 cos`` or,
when two families share one wave number and member, ``n=2 cos (2nd)``.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..tyremodel.harmonics import harmonic_fit, resolved_wave_numbers

__all__ = [
    "MIN_FRACTION",
    "FamilyName",
    "ModeWave",
    "family_names",
    "mode_wave",
    "travelling_share",
]

#: Energy fraction of one harmonic above which a shape counts as that harmonic.
MIN_FRACTION = 0.8


@dataclass(frozen=True)
class ModeWave:
    """Wave number and member of one mode shape.

    Attributes
    ----------
    n : int
        Best single harmonic (0 for a breathing shape).
    fraction : float
        Share of the shape's energy that this harmonic explains, in [0, 1].
    member : str or None
        ``"cos"`` or ``"sin"`` relative to the reference angle, ``"forward"``
        or ``"backward"`` for a travelling wave (None for ``n = 0`` or a shape
        that is not a single harmonic).
    """

    n: int
    fraction: float
    member: str | None

    @property
    def single(self) -> bool:
        """Whether the shape is a single harmonic (fraction >= :data:`MIN_FRACTION`)."""
        return self.fraction >= MIN_FRACTION


def mode_wave(
    angles_deg: Sequence[float | None], shape: Sequence[complex], reference_deg: float = 0.0
) -> ModeWave | None:
    """Wave number, energy fraction and member of one shape (module docstring).

    Parameters
    ----------
    angles_deg : sequence of float or None
        Angular position of each point in deg (None where unknown: the point
        is left out).
    shape : sequence of complex
        The mode shape at the same points (any scaling).
    reference_deg : float
        Angle of the ``cos`` member's antinode (the drive point), deg.

    Returns
    -------
    ModeWave or None
        None when fewer than three points carry an angle or the shape is zero
        there.
    """
    known = [(i, float(a)) for i, a in enumerate(angles_deg) if a is not None]
    keep = [i for i, a in known if math.isfinite(a)]
    if len(keep) < 3:
        return None
    ang = np.array([a for _, a in known if math.isfinite(a)])
    if np.unique(np.round(np.mod(ang, 360.0), 6)).size < 3:
        return None
    x = np.asarray(shape, dtype=complex)[keep]
    if not np.all(np.isfinite(x)) or not np.any(x):
        return None
    n_res, cos_next = resolved_wave_numbers(ang)
    n_top = n_res + 1 if cos_next else n_res
    theta = np.radians(ang)
    fits = [harmonic_fit(theta, x, n) for n in range(n_top + 1)]
    best = max(fits, key=lambda f: f.fraction)
    member = None
    if best.n > 0 and best.fraction >= MIN_FRACTION:
        member = _member(best.coefficients, best.n, reference_deg)
    return ModeWave(n=int(best.n), fraction=float(best.fraction), member=member)


def travelling_share(coef: NDArray[np.complex128]) -> float:
    """Share of ``a cos n t + b sin n t`` travelling towards ``+t``.

    ``|a+ib|^2 / (|a-ib|^2 + |a+ib|^2)``: the spatial Fourier split of the module
    docstring (0.5 for a standing wave).
    """
    fwd = abs(coef[0] + 1j * coef[1]) ** 2
    bwd = abs(coef[0] - 1j * coef[1]) ** 2
    return float(fwd / (fwd + bwd)) if fwd + bwd > 0 else 0.5


def _member(coef: NDArray[np.complex128], n: int, reference_deg: float) -> str:
    """``forward``/``backward`` for a travelling wave, else ``cos`` when the antinode of
    ``a cos n t + b sin n t`` is nearer the reference."""
    share = travelling_share(coef)
    if share >= 0.75:
        return "forward"
    if share <= 0.25:
        return "backward"
    # principal phase of the complex pair (a, b), then real coefficients
    alpha = 0.5 * np.angle(coef[0] ** 2 + coef[1] ** 2)
    a, b = (coef * np.exp(-1j * alpha)).real
    if math.hypot(a, b) == 0.0:
        a, b = (coef * np.exp(-1j * (alpha + np.pi / 2))).real
    # antinode: n theta_0 = atan2(b, a); phase of the reference within the wave
    phase = math.degrees(math.atan2(b, a)) - n * reference_deg
    off = abs((phase + 90.0) % 180.0 - 90.0)  # distance to the nearest antinode, deg of n theta
    return "cos" if off < 45.0 else "sin"


@dataclass(frozen=True)
class FamilyName:
    """The name of one mode family.

    Attributes
    ----------
    family : str
        The tracking's name (``F1``, ...).
    wave_number : int or None
        The family's wave number (None: its single-harmonic modes do not
        agree on one, or no mode shape could be analysed).
    agreement : float
        Share of the family's single-harmonic modes that carry
        ``wave_number``; for a ``mixed`` family, the share of its analysed
        modes whose best harmonic it is (NaN without any).
    member : str or None
        ``"cos"``, ``"sin"``, ``"forward"``, ``"backward"``, ``"pair"``
        (tracked as a pair) or None.
    label : str
        ``n=2``, ``n=2 cos``, ``n=2 forward``, ``n=2 cos (2nd)``, or the tracking's name when
        there is no wave number.
    n_labelled : int
        How many of its modes are single harmonics.
    mixed : bool
        The wave number is the dominant harmonic of mixed shapes (module
        docstring), not that of single-harmonic modes.
    fraction : float
        Mean energy fraction of ``wave_number`` in the modes whose best
        harmonic it is (NaN without any).
    """

    family: str
    wave_number: int | None
    agreement: float
    member: str | None
    label: str
    n_labelled: int
    mixed: bool = False
    fraction: float = math.nan

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        return {
            "family": self.family,
            "wave_number": self.wave_number,
            "wave_agreement": None if math.isnan(self.agreement) else self.agreement,
            "member": self.member,
            "label": self.label,
            "n_labelled": self.n_labelled,
            "wave_mixed": self.mixed,
            "wave_fraction": None if math.isnan(self.fraction) else self.fraction,
        }


def family_names(
    families: Mapping[str, Sequence[ModeWave | None]], pairs: Sequence[str] = ()
) -> dict[str, FamilyName]:
    """Name every family from the waves of its modes (module docstring).

    Parameters
    ----------
    families : mapping of str to sequence of ModeWave or None
        The tracking's family names, in order of frequency, with the wave of
        each of its modes (None where the shape could not be labelled).
    pairs : sequence of str
        Families tracked as pairs (their modes sit in slots ``a`` and ``b``).

    Returns
    -------
    dict of str to FamilyName
    """
    out: dict[str, FamilyName] = {}
    for fam, waves in families.items():
        out[fam] = _family_wave(fam, waves, fam in pairs)
    # labels; families sharing one wave number and member are told apart by frequency order
    seen: dict[tuple[int, str | None, bool], int] = defaultdict(int)
    for fam, name in out.items():
        if name.wave_number is None:
            continue
        key = (name.wave_number, name.member, name.mixed)
        seen[key] += 1
        text = f"n={name.wave_number}"
        if name.member in ("cos", "sin", "forward", "backward"):
            text += f" {name.member}"
        if name.mixed:
            text += " mixed"
        if seen[key] > 1:
            text += f" ({_ordinal(seen[key])})"
        out[fam] = replace(name, label=text)
    return out


def _family_wave(fam: str, waves: Sequence[ModeWave | None], pair: bool) -> FamilyName:
    """Wave number and member of one family from its modes' waves (module docstring)."""
    labelled = [w for w in waves if w is not None and w.single]
    if labelled:
        (n_best, count), *_ = Counter(w.n for w in labelled).most_common(1)
        agreement = count / len(labelled)
        if agreement > 0.5:
            n = int(n_best)
            member = None
            if pair:
                member = "pair"
            elif n > 0:
                members = Counter(w.member for w in labelled if w.n == n and w.member)
                if members:
                    (m_best, m_count), *_ = members.most_common(1)
                    member = m_best if m_count / sum(members.values()) > 0.5 else None
            frac = float(np.mean([w.fraction for w in labelled if w.n == n]))
            return FamilyName(fam, n, agreement, member, fam, len(labelled), False, frac)
        # single harmonics that disagree: modes of different wave numbers in one family
        return FamilyName(fam, None, agreement, None, fam, len(labelled))
    known = [w for w in waves if w is not None]
    if not known:
        return FamilyName(fam, None, math.nan, None, fam, len(labelled))
    # mixed shapes: the harmonic with the largest summed energy fraction
    energy: dict[int, float] = defaultdict(float)
    for w in known:
        energy[w.n] += w.fraction
    n = max(sorted(energy), key=lambda k: energy[k])
    mine = [w.fraction for w in known if w.n == n]
    member = "pair" if pair else None
    return FamilyName(
        fam, n, len(mine) / len(known), member, fam, len(labelled), True, float(np.mean(mine))
    )


def _ordinal(k: int) -> str:
    return {2: "2nd", 3: "3rd"}.get(k, f"{k}th")
