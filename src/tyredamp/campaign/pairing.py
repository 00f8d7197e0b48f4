"""Which modes of one test form the doubled pairs that the tracking matches as wholes.

Two modes ``i``, ``j`` of one test can be the two members of a doubled mode
when their half-power bands overlap, ``|f_i - f_j| < zeta_i f_i + zeta_j f_j``
(modal overlap above one; :mod:`.tracking`, step 1). Three or more modes in a
row can overlap (a doubled mode beside a cavity resonance, a pair whose
members cross another mode), and then the overlap alone does not say which
two belong together. :func:`group_pairs` takes the closest neighbours first;
:func:`pairings` lists every grouping of the overlapping neighbours, so that
the tracking can keep the one whose units match the families already found
best (:func:`~tyredamp.campaign.tracking.track_modes`).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["group_pairs", "overlapping_neighbours", "pairings"]

#: Most groupings of one test that :func:`pairings` lists (beyond: the closest-first one only).
MAX_PAIRINGS = 256


def overlapping_neighbours(
    frequency_hz: Sequence[float] | NDArray[np.float64],
    damping_ratio: Sequence[float] | NDArray[np.float64],
) -> tuple[NDArray[np.intp], list[tuple[float, int, int]]]:
    """Modes in order of frequency and the neighbours in it whose half-power bands overlap.

    Returns the order (indices by increasing frequency) and one
    ``(|f_a - f_b|, a, b)`` per overlapping pair of neighbours in that order
    (``a`` below ``b``).
    """
    f = np.asarray(frequency_hz, dtype=float)
    z = np.abs(np.asarray(damping_ratio, dtype=float))
    order = np.argsort(f, kind="stable")
    cand = []
    for a, b in itertools.pairwise(order):
        d = abs(f[b] - f[a])
        if d < z[a] * f[a] + z[b] * f[b]:
            cand.append((float(d), int(a), int(b)))
    return order, cand


def _units(order: NDArray[np.intp], chosen: Sequence[tuple[int, int]]) -> list[tuple[int, ...]]:
    pairs = {a: (a, b) for a, b in chosen}
    used = {m for p in chosen for m in p}
    units: list[tuple[int, ...]] = []
    for i in order:
        i = int(i)
        if i in pairs:
            units.append(pairs[i])
        elif i not in used:
            units.append((i,))
    return units


def group_pairs(
    frequency_hz: Sequence[float] | NDArray[np.float64],
    damping_ratio: Sequence[float] | NDArray[np.float64],
) -> list[tuple[int, ...]]:
    """Group modes into units: pairs with overlapping half-power bands, else singles.

    Two modes ``i``, ``j`` form a pair when ``|f_i - f_j| < zeta_i f_i + zeta_j f_j``;
    the closest qualifying neighbours are paired first and a mode belongs to at
    most one pair. Returns index tuples in increasing frequency.
    """
    order, cand = overlapping_neighbours(frequency_hz, damping_ratio)
    used: set[int] = set()
    chosen = []
    for _, a, b in sorted(cand):
        if a not in used and b not in used:
            used |= {a, b}
            chosen.append((a, b))
    return _units(order, chosen)


def pairings(
    frequency_hz: Sequence[float] | NDArray[np.float64],
    damping_ratio: Sequence[float] | NDArray[np.float64],
) -> Iterator[list[tuple[int, ...]]]:
    """Every grouping of one test's modes into pairs of overlapping neighbours and singles.

    The first is :func:`group_pairs` (closest first). The others are every
    other set of disjoint overlapping neighbours, singles included (a
    matching of the chains of overlapping neighbours; a chain of ``k`` links
    has ``F(k + 2)`` of them, ``F`` the Fibonacci numbers), as long as the
    count stays within :data:`MAX_PAIRINGS`; beyond, only the first.

    Yields
    ------
    list of tuple of int
        Units (index tuples of one or two modes) in increasing frequency.
    """
    first = group_pairs(frequency_hz, damping_ratio)
    yield first
    order, cand = overlapping_neighbours(frequency_hz, damping_ratio)
    chains: list[list[tuple[int, int]]] = []
    for _, a, b in cand:  # in frequency order: a link continues a chain when it shares a mode
        if chains and chains[-1][-1][1] == a:
            chains[-1].append((a, b))
        else:
            chains.append([(a, b)])
    options = [list(_matchings(c)) for c in chains]
    if int(np.prod([len(o) for o in options], dtype=float)) > MAX_PAIRINGS:
        return
    for combo in itertools.product(*options):
        units = _units(order, [p for part in combo for p in part])
        if units != first:
            yield units


def _matchings(chain: Sequence[tuple[int, int]]) -> Iterator[list[tuple[int, int]]]:
    """Every set of links of a chain with no two links sharing a mode (the empty one too)."""
    if not chain:
        yield []
        return
    yield from _matchings(chain[1:])  # the first link unused
    for rest in _matchings(chain[2:]):  # the first link used: the next one is not
        yield [chain[0], *rest]
