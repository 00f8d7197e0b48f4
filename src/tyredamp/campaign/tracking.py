"""Mode families across the conditions of a campaign.

Tracking
--------
The identified modes of every test are matched into *families* (the same
physical mode seen at different pressures, loads, speeds, tyres):

1. Within each test, modes whose half-power bands overlap,
   ``|f_i - f_j| < zeta_i f_i + zeta_j f_j`` (modal overlap above one), form a
   *pair*: the doubled cos/sin modes of one wave number of a nearly
   axisymmetric tyre, whose individual shapes rotate freely inside their
   2-D subspace from test to test. Where three or more neighbours overlap
   in a row (a doubled mode beside a cavity resonance), every grouping of
   them into disjoint pairs and singles is tried
   (:func:`~tyredamp.campaign.pairing.pairings`) and the one whose units
   match the families already found at the least total cost (step 3; a mode
   starting a family, or left without a partner by a match of a pair with a
   single mode, costs more than any admissible match) is kept; the
   first test of a campaign is grouped closest neighbours first. A pair is
   matched as a whole by the
   subspace MAC, the mean squared cosine of the principal angles between the
   two mode-shape subspaces (for single modes this is the usual MAC,
   ``|u^H v|^2 / (|u|^2 |v|^2)``; Allemang 2003 for the MAC, Björck & Golub
   1973 for principal angles).
2. Tests are visited in order of tyre, then conditions. A test is matched
   against every family already found, each represented by its member in the
   already visited test nearest in conditions (distance: the sum over the
   numeric conditions of the difference over that condition's range in the
   campaign; another tyre counts as far away), so a mode is always compared
   with its closest observed state and a sweep cannot swap two modes.
3. The match is an assignment problem (:func:`scipy.optimize.linear_sum_assignment`,
   one-to-one) with cost ``(1 - MAC) + (Delta f / gap)^2``, where ``gap`` is
   the distance from the family's representative to the nearest other mode
   of its test with a *similar shape* (MAC >= 0.5 with it; modes of other
   shapes may cross freely). A match is admissible only when ``MAC >= 0.5``
   (the shapes share more than they do not) and ``Delta f < gap`` (the new
   mode is closer to this family than its look-alike neighbour was, which
   also keeps spatially aliased wave numbers apart); modes left over start
   new families. Shapes are compared at the points common to both tests.
   Where no mode of a similar shape stands beside the representative (no
   gap to bound the change) and the family's members give a trend over the
   conditions (:mod:`~tyredamp.campaign.family_trend`: a least-squares plane,
   its prediction ``f_t`` at the new test), ``(f - f_t)^2 / var`` must also
   stay below the ``1 - 1e-3`` quantile (:data:`FALLBACK_ALPHA`) of the squared
   Student t of the trend's residual degrees of freedom, ``var`` the trend's
   prediction variance plus the new mode's squared standard error (at least
   the representative's: a noise-free line does not pin it), so that a family
   cannot jump to an unrelated mode far from its own course.
4. Where the MAC cannot be formed (fewer than 2 points common to the two
   tests: one response point each, as with a single accelerometer or a
   roving hammer, or shapes at disjoint points), modes are matched by
   frequency and damping instead. The distance is

   ``z^2 = ln(f_u / f_r)^2 / s_f^2 + ln(zeta_u / zeta_r)^2 / s_zeta^2``,

   ``s_f^2 = (sigma_f,u / f_u)^2 + (sigma_f,r / f_r)^2 + tau_f^2`` (and the same
   for the damping ratio): the identification's standard errors of both modes
   plus ``tau``, the scatter of the same mode between tests. ``tau`` comes from
   the campaign's own data (:func:`mode_scatter`): for every test and the
   already visited test nearest to it in conditions, the modes that are each
   other's nearest neighbour in frequency, and nearer to each other than half
   the distance to any other mode of either test, are taken as the same
   mode; ``tau`` is the scatter of their log ratios, ``1.4826 median |ln ratio|``
   (the median absolute deviation about zero, robust to the occasional wrong
   pair). Under the hypothesis that two modes are one, ``z^2`` is
   chi-square with 2 degrees of freedom (1 without a positive damping ratio
   on both sides), and a match is admissible when ``z^2`` is below its
   ``1 - 1e-3`` quantile (:data:`FALLBACK_ALPHA`) *and* the frequencies are
   nearer than half the distance to any other mode of either test (a match
   must be unambiguous). The assignment then uses the cost ``z^2 / limit``
   (below 1, as the MAC cost of an admissible match). A mode matched this
   way has no match MAC (NaN) and its ``method`` is ``"frequency"``.

The trends of each family's quantities over the conditions are fitted by
:mod:`~tyredamp.campaign.series_trend`; the doubled modes a shaker layout
cannot drive both members of are found by :mod:`~tyredamp.campaign.excitation`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from ..exceptions import InputError
from .excitation import single_member_wave_numbers
from .family_trend import change_limit, family_trend, frequency_change_z2, reference_frequency
from .pairing import group_pairs, pairings
from .series_trend import TrendFit, fit_trend

__all__ = [
    "FALLBACK_ALPHA",
    "MAC_MIN",
    "ModeSet",
    "Tracking",
    "TrendFit",
    "fit_trend",
    "group_pairs",
    "mode_scatter",
    "single_member_wave_numbers",
    "subspace_mac",
    "track_modes",
]

#: Smallest (subspace) MAC of an admissible match: the shapes share more than they do not.
MAC_MIN = 0.5
#: Significance level of the frequency-and-damping match where the MAC cannot be formed.
FALLBACK_ALPHA = 1e-3
#: Fewest points common to two tests for their shapes to be compared by the MAC.
MIN_COMMON_POINTS = 2
_FAR = 1.0e6


@dataclass(frozen=True)
class ModeSet:
    """The identified modes of one test, for tracking.

    Attributes
    ----------
    test_id : str
        Test name.
    conditions : dict
        ``tyre`` and the numeric conditions (None when not given).
    frequency_hz, damping_ratio : ndarray, shape (m,)
        Natural frequencies (Hz) and damping ratios.
    shapes : ndarray, complex, shape (n_points, m)
        Mode shapes at the points (any scaling).
    points : tuple of str
        Point labels (rows of ``shapes``).
    frequency_std_hz, damping_ratio_std : ndarray, shape (m,), optional
        Standard errors of the frequencies (Hz) and damping ratios (NaN or
        None where unknown, taken as 0); used where shapes cannot be compared.
    """

    test_id: str
    conditions: Mapping[str, Any]
    frequency_hz: NDArray[np.float64]
    damping_ratio: NDArray[np.float64]
    shapes: NDArray[np.complex128]
    points: tuple[str, ...]
    frequency_std_hz: NDArray[np.float64] | None = None
    damping_ratio_std: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency_hz, dtype=float).reshape(-1)
        z = np.asarray(self.damping_ratio, dtype=float).reshape(-1)
        for name in ("frequency_std_hz", "damping_ratio_std"):
            v = getattr(self, name)
            v = np.full(f.size, np.nan) if v is None else np.asarray(v, dtype=float).reshape(-1)
            if v.size != f.size:
                raise InputError(
                    f"ModeSet {self.test_id}: expected {f.size} values of {name}, got {v.size}"
                )
            object.__setattr__(self, name, v)
        s = np.asarray(self.shapes, dtype=complex)
        if s.ndim != 2 or s.shape[1] != f.size or z.size != f.size:
            raise InputError(
                f"ModeSet {self.test_id}: expected shapes (n_points, {f.size}) and "
                f"{f.size} damping ratios, got {s.shape} and {z.size}"
            )
        if s.shape[0] != len(self.points):
            raise InputError(
                f"ModeSet {self.test_id}: {s.shape[0]} shape rows but {len(self.points)} points"
            )
        object.__setattr__(self, "frequency_hz", f)
        object.__setattr__(self, "damping_ratio", z)
        object.__setattr__(self, "shapes", s)
        object.__setattr__(self, "points", tuple(self.points))


def _basis(v: NDArray[np.complex128]) -> NDArray[np.complex128]:
    q, r = np.linalg.qr(v)
    keep = np.abs(np.diag(r)) > 1e-12 * max(float(np.abs(r).max()), 1e-300)
    return q[:, keep]


def subspace_mac(u: NDArray[np.complex128], v: NDArray[np.complex128]) -> float:
    """Subspace MAC of the column spaces of ``u`` (n, k1) and ``v`` (n, k2), in [0, 1].

    The mean of ``cos^2`` of the ``min(k1, k2)`` principal angles; for two
    vectors it is the MAC ``|u^H v|^2 / (|u|^2 |v|^2)``.
    """
    u = np.asarray(u, dtype=complex)
    v = np.asarray(v, dtype=complex)
    if u.ndim == 1:
        u = u[:, None]
    if v.ndim == 1:
        v = v[:, None]
    qu, qv = _basis(u), _basis(v)
    k = min(qu.shape[1], qv.shape[1])
    if k == 0:
        return 0.0
    s = np.linalg.svd(qu.conj().T @ qv, compute_uv=False)
    return float(min(1.0, np.sum(s[:k] ** 2) / k))


@dataclass
class _Unit:
    test: int
    modes: tuple[int, ...]
    frequency: float
    damping: float = math.nan
    frequency_std: float = 0.0
    damping_std: float = 0.0


def _units(s: ModeSet, i: int, grouping: Sequence[tuple[int, ...]] | None = None) -> list[_Unit]:
    """The matching units (pairs and singles) of one test, with their mean f and zeta.

    ``grouping`` (index tuples) defaults to :func:`group_pairs`.
    """
    out = []
    for u in group_pairs(s.frequency_hz, s.damping_ratio) if grouping is None else grouping:
        q = list(u)
        sf = np.nan_to_num(s.frequency_std_hz[q], nan=0.0)  # type: ignore[index]
        sz = np.nan_to_num(s.damping_ratio_std[q], nan=0.0)  # type: ignore[index]
        out.append(
            _Unit(
                i,
                u,
                float(np.mean(s.frequency_hz[q])),
                float(np.mean(s.damping_ratio[q])),
                float(np.sqrt(np.sum(sf**2)) / len(q)),  # standard error of the mean
                float(np.sqrt(np.sum(sz**2)) / len(q)),
            )
        )
    return out


def _log_ratio(a: float, b: float) -> float:
    return math.log(a / b) if a > 0 and b > 0 and math.isfinite(a / b) else math.nan


def _nearest_gap(unit: _Unit, others: Sequence[_Unit]) -> float:
    """Distance (Hz) from ``unit`` to the nearest other unit of its test (inf: none)."""
    gaps = [abs(unit.frequency - o.frequency) for o in others if o is not unit]
    return min(gaps, default=math.inf)


def mode_scatter(
    sets: Sequence[ModeSet], order: Sequence[int] | None = None
) -> tuple[float, float, int]:
    """Scatter of the same mode's ``ln f`` and ``ln zeta`` between neighbouring tests.

    For every test (in ``order``, default the tracking order) and the already
    visited test nearest to it in conditions, the units (modes, or pairs of
    overlapping modes) that are each other's nearest neighbour in frequency
    and nearer to each other than half the distance to any other unit of
    either test are taken as one mode (module docstring, step 4).

    Returns
    -------
    tau_f, tau_zeta : float
        ``1.4826 median |ln(f_u / f_r)|`` and the same for the damping ratios
        (0 when there is no such pair).
    n : int
        Number of pairs of modes the scatter is taken from.
    """
    names = _numeric_conditions(sets)
    dist = _distance_fn(sets)
    if order is None:
        order = sorted(range(len(sets)), key=lambda i: _sort_key(sets[i], names))
    units = {i: _units(sets[i], i) for i in order}
    rf: list[float] = []
    rz: list[float] = []
    visited: list[int] = []
    for i in order:
        if visited and units[i]:
            j = min(visited, key=lambda t: (dist(sets[i], sets[t]), t))
            rf_ij, rz_ij = _mutual_nearest(units[j], units[i])
            rf += rf_ij
            rz += rz_ij
        visited.append(i)
    k = 1.4826  # MAD -> standard deviation for normal scatter
    tau_f = k * float(np.median(np.abs(rf))) if rf else 0.0
    zs = [v for v in rz if math.isfinite(v)]
    tau_z = k * float(np.median(np.abs(zs))) if zs else 0.0
    return tau_f, tau_z, len(rf)


def _mutual_nearest(a: Sequence[_Unit], b: Sequence[_Unit]) -> tuple[list[float], list[float]]:
    """Log ratios (f, zeta) of the unambiguous mutual nearest neighbours of ``a`` and ``b``."""
    if not a or not b:
        return [], []
    fa = np.array([u.frequency for u in a])
    fb = np.array([u.frequency for u in b])
    d = np.abs(fa[:, None] - fb[None, :])
    rf, rz = [], []
    for x in range(len(a)):
        y = int(np.argmin(d[x]))
        if int(np.argmin(d[:, y])) != x:
            continue
        half = 0.5 * min(_nearest_gap(a[x], a), _nearest_gap(b[y], b))
        if d[x, y] < half:
            rf.append(_log_ratio(b[y].frequency, a[x].frequency))
            rz.append(_log_ratio(b[y].damping, a[x].damping))
    return rf, rz


def _fallback_z2(rep: _Unit, unit: _Unit, tau_f: float, tau_z: float) -> tuple[float, int]:
    """``z^2`` of two units by frequency and damping (module docstring, step 4), its dof."""
    r = _log_ratio(unit.frequency, rep.frequency)
    var = (rep.frequency_std / rep.frequency) ** 2 + (unit.frequency_std / unit.frequency) ** 2
    var += tau_f**2
    z2 = _ratio2(r, var)
    dof = 1
    rz = _log_ratio(unit.damping, rep.damping)
    if math.isfinite(rz):
        vz = (rep.damping_std / rep.damping) ** 2 + (unit.damping_std / unit.damping) ** 2
        z2 += _ratio2(rz, vz + tau_z**2)
        dof = 2
    return z2, dof


def _ratio2(r: float, var: float) -> float:
    if not math.isfinite(r):
        return math.inf
    if var > 0:
        return r * r / var
    return 0.0 if r == 0 else math.inf


@dataclass
class Tracking:
    """Result of :func:`track_modes`.

    Attributes
    ----------
    family : dict of (test_id, mode index) to str
        Family name (``F1``, ``F2``, ... by increasing median frequency) of
        every mode (0-based index within its test).
    slot : dict of (test_id, mode index) to str
        ``""`` for single modes, ``"a"``/``"b"`` for the lower/upper mode of a
        pair.
    mac : dict of (test_id, mode index) to float
        The (subspace) MAC of the match that put the mode in its family (NaN
        for the mode that started the family and for a match by frequency).
    method : dict of (test_id, mode index) to str
        How the mode joined its family: ``"shape"`` (MAC), ``"frequency"``
        (frequency and damping, where the MAC cannot be formed) or ``""`` (it
        started the family).
    distance : dict of (test_id, mode index) to float
        ``z`` of a match by frequency and damping (module docstring, step 4;
        NaN otherwise).
    pairs : set of str
        Families holding a pair in at least one test.
    scatter : dict
        ``tau_f``, ``tau_zeta`` and ``n`` of :func:`mode_scatter` (used by the
        matches by frequency).
    """

    family: dict[tuple[str, int], str] = field(default_factory=dict)
    slot: dict[tuple[str, int], str] = field(default_factory=dict)
    mac: dict[tuple[str, int], float] = field(default_factory=dict)
    method: dict[tuple[str, int], str] = field(default_factory=dict)
    distance: dict[tuple[str, int], float] = field(default_factory=dict)
    pairs: set[str] = field(default_factory=set)
    scatter: dict[str, float] = field(default_factory=dict)


def _numeric_conditions(sets: Sequence[ModeSet]) -> list[str]:
    names: list[str] = []
    for s in sets:
        for k, v in s.conditions.items():
            if k != "tyre" and isinstance(v, int | float) and k not in names:
                names.append(k)
    return names


def _spans(sets: Sequence[ModeSet]) -> dict[str, float]:
    """Range of each numeric condition over the campaign (1 where it does not vary)."""
    span = {}
    for c in _numeric_conditions(sets):
        vals = [float(s.conditions[c]) for s in sets if s.conditions.get(c) is not None]
        span[c] = (max(vals) - min(vals)) if vals and max(vals) > min(vals) else 1.0
    return span


def _distance_fn(sets: Sequence[ModeSet]) -> Any:
    names = _numeric_conditions(sets)
    span = _spans(sets)

    def dist(a: ModeSet, b: ModeSet) -> float:
        d = 0.0 if a.conditions.get("tyre") == b.conditions.get("tyre") else _FAR
        for c in names:
            x, y = a.conditions.get(c), b.conditions.get(c)
            if x is None and y is None:
                continue
            d += 1.0 if (x is None or y is None) else abs(float(x) - float(y)) / span[c]
        return d

    return dist


def _sort_key(s: ModeSet, names: Sequence[str]) -> tuple[Any, ...]:
    vals = tuple(
        (0, float(s.conditions[c])) if s.conditions.get(c) is not None else (1, 0.0) for c in names
    )
    return (str(s.conditions.get("tyre") or ""), *vals, s.test_id)


def _shapes_at(s: ModeSet, modes: tuple[int, ...], points: Sequence[str]) -> NDArray:
    idx = [s.points.index(p) for p in points]
    return s.shapes[np.ix_(idx, list(modes))]


#: Cost of a mode that starts a family of its own, or that a match leaves without a
#: partner (a pair matched to a single mode): above every admissible match, whose cost
#: ``(1 - MAC) + (Delta f / gap)^2`` stays below 1.5 (fallback: below 1).
_NEW = 1.5


def _match_units(
    reps: Sequence[_Unit],
    cur: Sequence[_Unit],
    s: ModeSet,
    sets: Sequence[ModeSet],
    units: Sequence[Sequence[_Unit]],
    stats: tuple[float, float, Mapping[int, float], Callable[[int], Any]],
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Costs of matching the units ``cur`` of test ``s`` to the families' ``reps``.

    Returns the total cost of the best assignment (admissible matches, plus
    :data:`_NEW` for each mode left to start a family) and the cost, MAC and
    ``z`` matrices, shape (len(reps), len(cur)) (module docstring, steps 3-4).
    A match between a pair and a single mode costs :data:`_NEW` more (one mode
    is left without a partner), so the grouping into pairs that matches the
    families' own grouping is preferred. ``stats`` holds ``tau_f``, ``tau_z``,
    the chi-square limits by degrees of freedom and a function giving family
    ``a``'s trend (:func:`~tyredamp.campaign.family_trend.family_trend`).
    """
    tau_f, tau_z, limit, trend_of = stats
    cost = np.full((len(reps), len(cur)), _FAR)
    macs = np.full((len(reps), len(cur)), np.nan)
    zs = np.full((len(reps), len(cur)), np.nan)
    for a, rep in enumerate(reps):
        rs = sets[rep.test]
        common = [p for p in rs.points if p in s.points]
        if len(common) < MIN_COMMON_POINTS:
            # no shapes to compare: frequency and damping (module docstring, step 4)
            gap_r = _nearest_gap(rep, units[rep.test])
            for b, unit in enumerate(cur):
                df = abs(unit.frequency - rep.frequency)
                z2, dof = _fallback_z2(rep, unit, tau_f, tau_z)
                zs[a, b] = math.sqrt(z2)
                if z2 < limit[dof] and 2 * df < min(gap_r, _nearest_gap(unit, cur)):
                    cost[a, b] = z2 / limit[dof]
            continue
        own = rs.shapes[:, list(rep.modes)]
        alike = [
            u.frequency
            for u in units[rep.test]
            if u is not rep and subspace_mac(own, rs.shapes[:, list(u.modes)]) >= MAC_MIN
        ]
        gap = min((abs(rep.frequency - f) for f in alike), default=math.inf)
        ur = _shapes_at(rs, rep.modes, common)
        # no look-alike beside it: the change is bounded by the family's own course
        f_ref, bound, t_dof = rep.frequency, None, math.inf
        if math.isinf(gap):
            f_ref, bound, t_dof = reference_frequency(
                rep.frequency, trend_of(a), rep.frequency_std**2
            )
        t_lim = math.inf if bound is None else change_limit(t_dof, FALLBACK_ALPHA)
        for b, unit in enumerate(cur):
            m = subspace_mac(ur, _shapes_at(s, unit.modes, common))
            df = abs(unit.frequency - rep.frequency)
            macs[a, b] = m
            free = bound is None or (
                frequency_change_z2(unit.frequency, f_ref, bound + unit.frequency_std**2) < t_lim
            )
            if m >= MAC_MIN and df < gap and free:
                rel = 0.0 if math.isinf(gap) else df / gap
                cost[a, b] = (1.0 - m) + rel**2
    for a, rep in enumerate(reps):
        for b, unit in enumerate(cur):
            if cost[a, b] < _FAR:
                cost[a, b] += _NEW * abs(len(unit.modes) - len(rep.modes))
    total = _NEW * sum(len(u.modes) for u in cur)
    if reps and cur:
        rows, cols = linear_sum_assignment(cost)
        for a, b in zip(rows, cols, strict=True):
            if cost[a, b] < _FAR:
                total += cost[a, b] - _NEW * len(cur[b].modes)
    return float(total), cost, macs, zs


def track_modes(sets: Sequence[ModeSet]) -> Tracking:
    """Match the modes of all tests into families (see the module docstring).

    Parameters
    ----------
    sets : sequence of ModeSet
        The identified modes of every test (tests without modes may be given).

    Returns
    -------
    Tracking
    """
    from scipy.stats import chi2

    names = _numeric_conditions(sets)
    dist = _distance_fn(sets)
    span = _spans(sets)
    order = sorted(range(len(sets)), key=lambda i: _sort_key(sets[i], names))
    units: list[list[_Unit]] = [_units(s, i) for i, s in enumerate(sets)]
    tau_f, tau_z, n_scatter = mode_scatter(sets, order)
    limit = {k: float(chi2.ppf(1.0 - FALLBACK_ALPHA, k)) for k in (1, 2)}
    members: list[dict[int, _Unit]] = []  # family -> {test index: unit}
    # how each unit joined its family: (method, MAC, z)
    how: dict[tuple[int, tuple[int, ...]], tuple[str, float, float]] = {}
    for i in order:
        s = sets[i]
        if not units[i]:
            continue
        reps = [fam[min(fam, key=lambda t: (dist(s, sets[t]), t))] for fam in members]
        trend_of = lru_cache(maxsize=None)(
            lambda a, s=s: family_trend([(sets[t].conditions, u.frequency)
                                         for t, u in members[a].items()], s.conditions, span)
        )  # fmt: skip
        # the grouping of overlapping modes into pairs whose units match the families best
        best: tuple[float, list[_Unit], Any] | None = None
        for grouping in pairings(s.frequency_hz, s.damping_ratio):
            cur = _units(s, i, grouping)
            match = _match_units(reps, cur, s, sets, units, (tau_f, tau_z, limit, trend_of))
            if best is None or match[0] < best[0] - 1e-9:
                best = (match[0], cur, match[1:])
            if not reps:
                break
        if best is None:  # pairings() yields at least the closest-first grouping
            continue
        _, cur, (cost, macs, zs) = best
        units[i] = cur
        taken: set[int] = set()
        if reps:
            rows, cols = linear_sum_assignment(cost)
            for a, b in zip(rows, cols, strict=True):
                if cost[a, b] < _FAR:
                    members[a][i] = cur[b]
                    by_shape = bool(np.isfinite(macs[a, b]))
                    how[(i, cur[b].modes)] = (
                        ("shape", float(macs[a, b]), math.nan)
                        if by_shape
                        else ("frequency", math.nan, float(zs[a, b]))
                    )
                    taken.add(int(b))
        for b, unit in enumerate(cur):
            if b not in taken:
                members.append({i: unit})
                how[(i, unit.modes)] = ("", math.nan, math.nan)
    # name families by increasing median frequency
    med = [float(np.median([u.frequency for u in fam.values()])) for fam in members]
    result = Tracking(scatter={"tau_f": tau_f, "tau_zeta": tau_z, "n": float(n_scatter)})
    for rank, k in enumerate(np.argsort(med, kind="stable")):
        name = f"F{rank + 1}"
        fam = members[int(k)]
        is_pair = any(len(u.modes) == 2 for u in fam.values())
        if is_pair:
            result.pairs.add(name)
        pair_means = _pair_slot_means(sets, fam)
        for t, unit in fam.items():
            tid = sets[t].test_id
            f = sets[t].frequency_hz
            ordered = sorted(unit.modes, key=lambda q: f[q])
            method, mac, z = how[(t, unit.modes)]
            for pos, q in enumerate(ordered):
                if len(ordered) == 2:
                    slot = "ab"[pos]
                elif is_pair:
                    slot = _nearest_slot(float(f[q]), pair_means)
                else:
                    slot = ""
                result.family[(tid, q)] = name
                result.slot[(tid, q)] = slot
                result.mac[(tid, q)] = mac
                result.method[(tid, q)] = method
                result.distance[(tid, q)] = z
    return result


def _pair_slot_means(sets: Sequence[ModeSet], fam: Mapping[int, _Unit]) -> tuple[float, float]:
    lo, hi = [], []
    for t, u in fam.items():
        if len(u.modes) == 2:
            fs = sorted(float(sets[t].frequency_hz[q]) for q in u.modes)
            lo.append(fs[0])
            hi.append(fs[1])
    if not lo:
        return (math.nan, math.nan)
    return (float(np.mean(lo)), float(np.mean(hi)))


def _nearest_slot(f: float, means: tuple[float, float]) -> str:
    return "a" if abs(f - means[0]) <= abs(f - means[1]) else "b"
