"""Stabilisation flags and automatic selection of physical poles.

Rules (all thresholds are arguments with the defaults stated here):

1. *Admissible poles*: ``0 < zeta <= max_damping`` (default 0.2: negative
   damping and heavily damped computational poles are rejected) and damped
   frequency inside the analysis band.
2. *Stability*: a pole of order ``p`` is stable when the nearest pole of the
   previous computed order (``p - 1``, or ``p - order_step``) differs by at
   most ``tol_frequency`` (1 %) in natural frequency,
   ``tol_damping`` (5 %) relative in damping ratio and, with several inputs,
   has participation-vector MAC >= ``tol_mac`` (0.95); where several poles of the
   previous order lie at one place with it (within half a half-power
   half-width: a repeated root, whose vectors turn within the space they
   share), the MAC is the share of its vector in the space theirs span.
3. *Clustering*: the stable poles are grouped by complete-linkage hierarchical
   clustering with the distance
   ``d_ij = |p_i - p_j| / max(|p_i|, |p_j|) + (1 - MAC(l_i, l_j))``
   (relative distance of the poles in the complex plane, which weighs a
   frequency difference ``df/f`` and a damping difference ``d zeta`` alike,
   plus the participation term with several inputs), cut at
   ``cluster_distance`` (0.01). Two poles of the same order never share a
   cluster, so two close modes that some orders resolve stay apart. With
   several inputs, the poles of the clusters that do not persist (rule 4) are
   clustered again as repeated roots: the participation term of a pole with
   twins (poles of its order at one place) is its partner's share in the space
   the twins span, and the clusters at one place are regrouped one per
   multiplicity.
4. *Persistence*: a cluster is a mode when it holds poles of at least
   ``min_fraction`` (0.3) of the computed orders.
5. Each kept cluster gives the median of its frequencies and damping ratios
   and the participation vector of its member closest to that median.

Poles that pass these rules can still be rejected later by the residue fit
(small contribution to the FRF; see :mod:`tyredamp.modal.identify`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InputError
from ...mechanics.modal_sum import pole_quantities
from .lscf import PoleSet

_SLACK = 1e-6  # relative widening of the candidate search (rounding of log|p|, arg p)

__all__ = [
    "Cluster",
    "StabilityFlags",
    "cluster_poles",
    "same_place_distinct",
    "stability_flags",
]


@dataclass(frozen=True)
class StabilityFlags:
    """Per-pole flags of a :class:`PoleSet` (all arrays of shape (n,)).

    ``admissible``: passes the damping and band rules; ``frequency``,
    ``damping``, ``vector``: stable against the previous computed order; ``stable``:
    admissible and all three.
    """

    admissible: NDArray[np.bool_]
    frequency: NDArray[np.bool_]
    damping: NDArray[np.bool_]
    vector: NDArray[np.bool_]

    @property
    def stable(self) -> NDArray[np.bool_]:
        """Admissible and stable in frequency, damping and vector."""
        return self.admissible & self.frequency & self.damping & self.vector


@dataclass(frozen=True)
class Cluster:
    """One group of stable poles (a candidate mode).

    Attributes
    ----------
    pole : complex
        Representative pole (median frequency and damping), rad/s.
    participation : ndarray, complex, shape (n_in,)
        Participation vector of the member closest to the median.
    members : ndarray of int
        Indices into the :class:`PoleSet`.
    fraction : float
        Fraction of the computed orders that contribute a member.
    spread_frequency : float
        Relative spread (std / mean) of the member frequencies.
    """

    pole: complex
    participation: NDArray[np.complex128]
    members: NDArray[np.intp]
    fraction: float
    spread_frequency: float

    @property
    def frequency_hz(self) -> float:
        """Natural frequency in Hz."""
        return float(abs(self.pole) / (2 * np.pi))

    @property
    def damping_ratio(self) -> float:
        """Damping ratio."""
        return float(-self.pole.real / abs(self.pole))


def _mac_rows(a: NDArray[np.complex128], b: NDArray[np.complex128]) -> NDArray[np.float64]:
    num = np.abs(np.sum(a.conj() * b, axis=-1)) ** 2
    den = np.sum(np.abs(a) ** 2, axis=-1) * np.sum(np.abs(b) ** 2, axis=-1)
    return np.asarray(num / np.where(den > 0, den, 1.0))


#: poles closer than this share of the smaller half-power half-width ``|Re p|`` are at
#: one place: a repeated root (several inputs), whose poles no line can tell apart
TWIN = 0.5


def _same_place(a: NDArray[np.complex128], b: NDArray[np.complex128]) -> NDArray[np.bool_]:
    """Whether poles ``a`` and ``b`` (broadcast) lie within ``TWIN`` half-widths."""
    return np.asarray(np.abs(a - b) <= TWIN * np.minimum(np.abs(a.real), np.abs(b.real)))


#: participation MAC below which two modes at one place are a repeated root (their
#: residues together have rank two) rather than one mode held twice
REPEATED_MAC = 0.99


def same_place_distinct(part: NDArray[np.complex128]) -> NDArray[np.bool_]:
    """Pairs of modes (m, m) whose participation vectors (m, n_in) are not parallel
    (MAC below ``REPEATED_MAC``): at one pole they are a repeated root."""
    g = part.conj() @ part.T
    nn = np.real(np.diag(g))
    mac = np.abs(g) ** 2 / np.maximum(nn[:, None] * nn[None, :], 1e-300)
    return np.asarray(mac < REPEATED_MAC)


#: singular values of a set of participation vectors below this share of the largest
#: span no direction of it (two estimates of one vector are not a plane)
SPAN_TOL = 0.1


def _span(vecs: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """Orthonormal basis (n_in, r) of the space the participation vectors ``vecs``
    (k, n_in) span: the left singular vectors of ``vecs^T`` whose singular value is at
    least ``SPAN_TOL`` of the largest."""
    u, sv, _ = np.linalg.svd(np.asarray(vecs).T, full_matrices=False)
    return np.asarray(u[:, sv >= SPAN_TOL * sv[0]]) if sv.size and sv[0] > 0 else u[:, :0]


def _share_in(v: NDArray[np.complex128], basis: NDArray[np.complex128]) -> float:
    """Share of ``||v||^2`` in the span of the orthonormal columns ``basis``: the MAC of
    ``v`` with that space (the MAC of two vectors when it is one vector's line)."""
    nv = float(np.sum(np.abs(v) ** 2))
    return float(np.sum(np.abs(basis.conj().T @ v) ** 2) / nv) if nv > 0 else 0.0


def stability_flags(
    ps: PoleSet,
    *,
    band: tuple[float, float] | None = None,
    max_damping: float = 0.2,
    tol_frequency: float = 0.01,
    tol_damping: float = 0.05,
    tol_mac: float = 0.95,
) -> StabilityFlags:
    """Classify every pole of ``ps`` (rules 1 and 2 of the module docstring).

    Parameters
    ----------
    ps : PoleSet
        Poles over model orders from :func:`~tyredamp.modal.poles.lscf.plscf`.
    band : (float, float), optional
        Band (Hz) for the damped frequency; default ``ps.band_hz``.
    max_damping : float
        Largest admissible damping ratio.
    tol_frequency, tol_damping : float
        Relative tolerances against the previous order.
    tol_mac : float
        Smallest participation MAC against the previous order (several inputs).
    """
    lo, hi = ps.band_hz if band is None else band
    fd = ps.poles.imag / (2 * np.pi)
    z = ps.damping_ratio
    fn = ps.frequency_hz
    adm = (z > 0) & (z <= max_damping) & (fd >= lo) & (fd <= hi)
    n = ps.poles.size
    fstab = np.zeros(n, bool)
    zstab = np.zeros(n, bool)
    vstab = np.zeros(n, bool)
    multi = ps.participation.shape[1] > 1
    for p_prev, p in zip(ps.orders[:-1], ps.orders[1:], strict=True):
        cur = ps.at_order(int(p))
        prev = ps.at_order(int(p_prev))
        prev = prev[adm[prev]]
        if cur.size == 0 or prev.size == 0:
            continue
        dist = np.abs(ps.poles[cur][:, None] - ps.poles[prev][None, :])
        j = prev[np.argmin(dist, axis=1)]
        fstab[cur] = np.abs(fn[cur] - fn[j]) <= tol_frequency * fn[cur]
        zstab[cur] = np.abs(z[cur] - z[j]) <= tol_damping * np.abs(z[cur])
        if multi:
            mac = _mac_rows(ps.participation[cur], ps.participation[j])
            # a repeated root: the previous order's poles at the same place span the
            # participation space of this pole, any vector of which it may take
            near = _same_place(ps.poles[cur][:, None], ps.poles[prev][None, :])
            for r in np.flatnonzero(np.count_nonzero(near, axis=1) > 1):
                span = _span(ps.participation[prev[near[r]]])
                mac[r] = _share_in(ps.participation[cur[r]], span)
            vstab[cur] = mac >= tol_mac
        else:
            vstab[cur] = True
    return StabilityFlags(admissible=adm, frequency=fstab, damping=zstab, vector=vstab)


def _threshold_edges(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    od: NDArray[np.int64],
    cut: float,
    repeated: bool = False,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Pairs of poles of different orders at rule-3 distance ``<= cut``.

    Returns ``(i, j, d)`` with ``i < j`` (each pair once) and ``d`` the distance
    of rule 3. Candidates come from :func:`_pairs_within`: with ``m <= M`` the two moduli
    and ``theta`` the angle between the poles, ``|p_i - p_j| >= M - m`` and
    ``|p_i - p_j| >= M sin(theta)`` (``>= M`` for ``theta > pi/2``), so a pole
    distance ``<= cut < 1`` implies ``log M - log m <= -log(1 - cut)`` and
    ``theta <= arcsin(cut)``. In ``(log|p|, arg p)`` scaled by these two bounds
    every such pair lies within a unit max-norm ball (widened by ``_SLACK`` for
    rounding); the participation term ``1 - MAC >= 0`` only adds, so the
    candidates hold every pair within the cut. Their exact distance, element by
    element, then keeps the pairs ``<= cut``. ``repeated``: the participation term
    of repeated roots (:func:`_repeated_roots`).
    """
    n = p.size
    mag = np.abs(p)
    if cut < 1:
        ang = np.angle(p)
        r_ang = float(np.arcsin(cut))
        x = np.column_stack(
            [np.log(np.maximum(mag, np.finfo(float).tiny)) / -np.log1p(-cut), ang / r_ang]
        )
        # arg p wraps at -pi/pi: poles within the bound above -pi get a copy past pi
        wrap = np.flatnonzero(ang < -np.pi + r_ang)
        x = np.vstack([x, x[wrap] + [0.0, 2 * np.pi / r_ang]])
        i, j = _pairs_within(x, 1.0 + _SLACK)  # i < j
        if wrap.size:
            keep = i < n  # two copies: the same pair as the two originals
            i, j = i[keep], np.concatenate([np.arange(n), wrap])[j[keep]]
            i, j = np.minimum(i, j), np.maximum(i, j)
    else:  # no bound: every pair is a candidate
        i, j = (np.asarray(k, np.int64) for k in np.triu_indices(n, 1))
    keep = od[i] != od[j]  # same order: never in one cluster
    twins = (i[~keep], j[~keep])
    i, j = i[keep], j[keep]
    d = np.abs(p[i] - p[j]) / np.maximum(mag[i], mag[j])
    if lv.shape[1] > 1:
        nn = np.sum(np.abs(lv) ** 2, axis=1)
        s = np.zeros(i.size, np.complex128)
        for k in range(lv.shape[1]):
            s += lv[i, k].conj() * lv[j, k]
        mac = np.abs(s) ** 2 / (nn[i] * nn[j])
        if repeated:
            _repeated_roots(p, lv, twins, cut, (i, j, mac))
        d = np.maximum(d + (1.0 - mac), 0.0)
    keep = d <= cut
    return i[keep], j[keep], d[keep]


def _pairs_within(x: NDArray[np.float64], r: float) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Every pair ``i < j`` of rows of ``x`` (n, 2) within max-norm distance ``r``.

    A sweep along the first coordinate: after sorting by it, the rows within
    ``r`` of row ``k`` there are the next ones up to a binary-searched end;
    those candidates keep the pairs whose second coordinates are within ``r``
    too. Pairs come sorted by ``(i, j)``.
    """
    n = x.shape[0]
    order = np.argsort(x[:, 0], kind="stable")
    xs = x[order]
    end = np.searchsorted(xs[:, 0], xs[:, 0] + r, side="right")
    count = np.maximum(end - np.arange(n) - 1, 0)
    a = np.repeat(np.arange(n), count)
    b = a + 1 + np.arange(a.size) - np.repeat(np.cumsum(count) - count, count)
    keep = (xs[b, 0] - xs[a, 0] <= r) & (np.abs(xs[b, 1] - xs[a, 1]) <= r)
    i, j = order[a[keep]], order[b[keep]]
    i, j = np.minimum(i, j).astype(np.int64), np.maximum(i, j).astype(np.int64)
    srt = np.lexsort((j, i))
    return i[srt], j[srt]


def _components(adjacent: NDArray[np.bool_]) -> NDArray[np.intp]:
    """Connected components of the undirected graph of a symmetric boolean
    matrix: each node labelled by the smallest node index of its component
    (labels spread as running minima over the edges until none changes)."""
    n = adjacent.shape[0]
    comp = np.arange(n)
    while True:
        new = np.minimum(comp, np.min(np.where(adjacent, comp[None, :], n), axis=1))
        if np.array_equal(new, comp):
            return comp
        comp = new


def _repeated_roots(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    twins: tuple[NDArray[np.int64], NDArray[np.int64]],
    cut: float,
    edges: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]],
) -> None:
    """The participation term of a repeated root (several inputs), in place.

    A root of multiplicity ``r`` gives ``r`` poles of one order at the same place
    whose participation vectors are any basis of an ``r``-dimensional space: from
    order to order they turn within it, and their pairwise MAC says nothing. For a
    pole with such twins (poles of its own order at one place with it,
    :func:`_same_place`, and within ``cut``: among the candidate pairs
    ``twins``), the MAC of an edge ``(i, j, mac)`` becomes the larger share of
    either pole's participation in the space its partner and the partner's twins
    span (:func:`_span`); for poles without twins it is their MAC.
    """
    a, b = twins
    if not a.size:
        return
    big = np.maximum(np.abs(p[a]), np.abs(p[b]))
    close = _same_place(p[a], p[b]) & (np.abs(p[a] - p[b]) <= cut * big)
    a, b = a[close], b[close]
    if not a.size:
        return
    group: dict[int, list[int]] = {}
    for x, y in zip(a.tolist(), b.tolist(), strict=True):
        group.setdefault(x, [x]).append(y)
        group.setdefault(y, [y]).append(x)
    basis = {k: _span(lv[v]) for k, v in group.items()}
    i, j, mac = edges
    for e in np.flatnonzero(np.isin(i, a) | np.isin(i, b) | np.isin(j, a) | np.isin(j, b)):
        x, y = int(i[e]), int(j[e])
        in_y = _share_in(lv[x], basis[y]) if y in basis else 0.0
        in_x = _share_in(lv[y], basis[x]) if x in basis else 0.0
        mac[e] = max(mac[e], in_y, in_x)


def _complete_linkage(
    n: int, i: NDArray[np.int64], j: NDArray[np.int64], d: NDArray[np.float64]
) -> NDArray[np.int64]:
    """Labels ``0..k-1`` of the complete-linkage clusters (rule 3) of ``n`` poles.

    ``(i, j, d)`` are the pole pairs at distance ``<= cut``
    (:func:`_threshold_edges`). The complete-linkage distance of two clusters is
    the largest distance of their member pairs: it is ``<= cut`` exactly when
    every member pair is an edge, and it then is the largest of those edges.
    Larger distances never lead to a merge below the cut, so the edges alone
    give every merge up to the cut (a cluster is a clique of the graph; poles in
    different connected components are never merged). Complete linkage is
    reducible (a merged cluster is at least as far from any other as the nearer
    of its two parts), so pairs of reciprocal nearest neighbours stay reciprocal
    when other pairs merge: merging all of them at once gives the same
    dendrogram as one merge at a time. The rounds below repeat this on the
    cluster graph (per cluster pair: count of member pairs within the cut and
    their largest distance) until no cluster pair has all its member pairs
    within the cut. Each round costs O(edges), and the edges shrink fast (a pair
    with a member pair missing is dropped for good). The result is the clusters
    of :func:`scipy.cluster.hierarchy.linkage` (``"complete"``) cut at ``cut``,
    the order of exactly tied merges aside; no n^2 matrix is formed. A cluster
    keeps its smallest pole index as label, so the labels are numbered in the
    order of the smallest members.
    """
    lab = np.arange(n)
    size = np.ones(n, np.int64)
    a, b, dist, cnt = i, j, d, np.ones(i.size, np.int64)
    while a.size:
        near = np.full(n, np.inf)
        np.minimum.at(near, a, dist)
        np.minimum.at(near, b, dist)
        nn = np.full(n, n)  # nearest neighbour, the smallest label among ties
        m = dist == near[a]
        np.minimum.at(nn, a[m], b[m])
        m = dist == near[b]
        np.minimum.at(nn, b[m], a[m])
        c = np.flatnonzero(nn < n)
        c = c[(nn[nn[c]] == c) & (c < nn[c])]  # reciprocal pairs (c, nn[c]) merge into c
        if c.size == 0:  # cannot happen (the closest pair is reciprocal); never loop
            break
        new = np.arange(n)
        new[nn[c]] = c
        size[c] += size[nn[c]]
        lab = new[lab]
        a, b = new[a], new[b]
        keep = a != b
        a, b, dist, cnt = a[keep], b[keep], dist[keep], cnt[keep]
        key = np.minimum(a, b) * n + np.maximum(a, b)
        o = np.argsort(key, kind="stable")  # after round 1: sorted runs, cheap
        key, dist, cnt = key[o], dist[o], cnt[o]
        if key.size == 0:
            break
        first = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
        cnt = np.add.reduceat(cnt, first)
        dist = np.maximum.reduceat(dist, first)
        a, b = key[first] // n, key[first] % n
        keep = cnt == size[a] * size[b]  # some member pair beyond the cut: never merges
        a, b, dist, cnt = a[keep], b[keep], dist[keep], cnt[keep]
    return np.asarray(np.unique(lab, return_inverse=True)[1], np.int64)


def _linkage(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    od: NDArray[np.int64],
    cut: float,
    repeated: bool = False,
) -> NDArray[np.int64]:
    """Complete-linkage labels of the poles (rule 3; ``repeated``: with the
    participation term of repeated roots, :func:`_repeated_roots`)."""
    # poles numbered by increasing |p|, so the clusters are numbered by their member
    # of smallest |p|
    order = np.argsort(np.abs(p), kind="stable")
    labels = np.empty(p.size, np.int64)
    labels[order] = _complete_linkage(
        p.size, *_threshold_edges(p[order], lv[order], od[order], cut, repeated)
    )
    return labels


def _orders_of(labels: NDArray[np.int64], od: NDArray[np.int64], n_lab: int) -> NDArray[np.intp]:
    """How many distinct orders ``od`` each of the ``n_lab`` clusters ``labels`` holds."""
    pairs = np.unique(labels * (int(od.max()) + 1) + od)
    return np.asarray(np.bincount(pairs // (int(od.max()) + 1), minlength=n_lab))


def _second_pass(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    od: NDArray[np.int64],
    labels: NDArray[np.int64],
    cut: float,
    min_orders: float,
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """The poles of the clusters that do not persist, clustered again as repeated
    roots (several inputs); the new labels and which poles were clustered again.

    Rule 3 keeps the clusters of distinct modes apart by their participation
    vectors; the poles of a repeated root, whose vectors turn from order to order
    within the space they share, it scatters into clusters too sparse to persist
    (fewer than ``min_orders`` orders). Those poles alone are linked again with the
    participation term of repeated roots (:func:`_repeated_roots`) and their
    clusters regrouped one per multiplicity (:func:`_repeated_slots`); the
    persistent clusters of the first pass are kept as they are.
    """
    n_lab = int(labels.max()) + 1
    again = _orders_of(labels, od, n_lab)[labels] < min_orders
    rest = np.flatnonzero(again)
    if rest.size < 2:
        return labels, np.zeros(p.size, bool)
    sub = _repeated_slots(p[rest], od[rest], _linkage(p[rest], lv[rest], od[rest], cut, True))
    out = labels.copy()
    out[rest] = n_lab + sub
    return np.asarray(np.unique(out, return_inverse=True)[1], np.int64), again


def _repeated_slots(
    p: NDArray[np.complex128], od: NDArray[np.int64], labels: NDArray[np.int64]
) -> NDArray[np.int64]:
    """Clusters of a repeated root, one per multiplicity (several inputs).

    The poles of a root of multiplicity ``r`` lie at one place, up to ``r`` per
    order; no pole distance or participation vector tells which of them belongs
    with which of the next order, and complete linkage under the rule that two
    poles of one order never share a cluster can split them into more than ``r``
    clusters, each too sparse to persist. Clusters whose mean poles lie at one
    place (:func:`_same_place`, joined transitively) are pooled, ``r`` is the
    most poles of one order among them, and the ``k``-th of each order's poles
    (by damped frequency) goes to the ``k``-th cluster: ``r`` clusters, the
    ``k``-th holding the orders with at least ``k`` poles there (a group that
    linkage split into ``r`` clusters already is left as it is). Labels are
    renumbered ``0..`` keeping their order.
    """
    n_lab = int(labels.max()) + 1
    count = np.bincount(labels, minlength=n_lab)
    mean = (
        np.bincount(labels, p.real, n_lab) / count + 1j * np.bincount(labels, p.imag, n_lab) / count
    )
    comp = _components(_same_place(mean[:, None], mean[None, :]))
    out = labels.copy()
    for c in np.unique(comp):
        group = np.flatnonzero(comp == c)
        if group.size < 2:
            continue
        mem = np.flatnonzero(np.isin(labels, group))
        mem = mem[np.lexsort((p.imag[mem], od[mem]))]  # by order, then damped frequency
        first = np.concatenate([[True], od[mem][1:] != od[mem][:-1]])
        start = np.flatnonzero(first)
        slot = np.arange(mem.size) - np.repeat(start, np.diff(np.append(start, mem.size)))
        if int(slot.max()) + 1 < group.size:  # more clusters than the multiplicity
            out[mem] = group[slot]  # each slot keeps one of the labels
    return np.asarray(np.unique(out, return_inverse=True)[1], np.int64)


def _spanning_representatives(
    poles: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    dist: NDArray[np.float64],
    members: list[NDArray[np.intp]],
    best: NDArray[np.intp],
    again: NDArray[np.bool_],
) -> NDArray[np.intp]:
    """Representatives of clusters at one place (a repeated root, several inputs)
    whose participation vectors span the space their members share.

    The clusters of a repeated root hold its poles order by order with
    participation vectors that turn within one space (:func:`_repeated_roots`):
    the members closest to their medians may carry nearly the same vector, and a
    fit started from them would hold one vector twice. Within a group of
    clusters of repeated roots (``again``: from :func:`_second_pass`) whose
    representative poles lie at one place (:func:`_same_place`), the
    most populous keeps its representative; each other takes, among the half of
    its members closest to its pole, the one with the least share in the space
    the representatives chosen so far span.
    """
    best = best.copy()
    close = _same_place(poles[:, None], poles[None, :]) & again[:, None] & again[None, :]
    done = np.zeros(poles.size, bool)
    for c in np.argsort([-m.size for m in members], kind="stable"):
        if done[c] or np.count_nonzero(close[c]) < 2:
            continue
        group = np.flatnonzero(close[c] & ~done)
        group = group[np.argsort([-members[g].size for g in group], kind="stable")]
        done[group] = True
        chosen = [int(best[group[0]])]
        for g in group[1:]:
            mem = members[g][np.argsort(dist[members[g]], kind="stable")]
            mem = mem[: max(1, (mem.size + 1) // 2)]
            basis = _span(lv[chosen])
            share = [_share_in(lv[k], basis) for k in mem]
            best[g] = mem[int(np.argmin(share))]
            chosen.append(int(best[g]))
    return best


def cluster_poles(
    ps: PoleSet,
    flags: StabilityFlags,
    *,
    cluster_distance: float = 0.01,
    min_fraction: float = 0.3,
) -> tuple[list[Cluster], list[Cluster]]:
    """Cluster the stable poles and keep the persistent clusters (rules 3-5).

    Parameters
    ----------
    ps : PoleSet
        Poles over orders.
    flags : StabilityFlags
        From :func:`stability_flags`.
    cluster_distance : float
        Cut height of the complete-linkage dendrogram (dimensionless).
    min_fraction : float
        Smallest fraction of the computed orders a kept cluster must span.

    Returns
    -------
    kept : list of Cluster
        Clusters that pass the persistence rule, sorted by frequency.
    rejected : list of Cluster
        The other clusters (for reporting), sorted by frequency.
    """
    if not 0 < min_fraction <= 1:
        raise InputError(f"min_fraction: expected a value in (0, 1], got {min_fraction}")
    if not cluster_distance > 0:
        raise InputError(f"cluster_distance: expected a value > 0, got {cluster_distance}")
    idx = np.flatnonzero(flags.stable)
    if idx.size == 0:
        return [], []
    p = ps.poles[idx]
    lv = ps.participation[idx]
    od = ps.order[idx]
    # complete linkage on the graph of the pole pairs within the cut (exact, no
    # n^2 matrix: see _complete_linkage)
    labels = _linkage(p, lv, od, cluster_distance)
    n_orders = ps.orders.size
    second = np.zeros(p.size, bool)  # poles clustered as repeated roots
    if lv.shape[1] > 1:
        labels, second = _second_pass(p, lv, od, labels, cluster_distance, min_fraction * n_orders)
    n_lab = int(labels.max()) + 1
    # per-cluster medians, spread, persistence and representative, all at once
    n_cl = n_lab
    fn_all, zz_all = pole_quantities(p)
    count = np.bincount(labels, minlength=n_cl)
    start = np.concatenate([[0], np.cumsum(count)[:-1]])
    lo_i, hi_i = start + (count - 1) // 2, start + count // 2
    fs = fn_all[np.lexsort((fn_all, labels))]
    zs = zz_all[np.lexsort((zz_all, labels))]
    f_med = 0.5 * (fs[lo_i] + fs[hi_i])
    z_med = 0.5 * (zs[lo_i] + zs[hi_i])
    w = 2 * np.pi * f_med
    poles = -z_med * w + 1j * w * np.sqrt(np.maximum(1 - z_med**2, 0.0))
    dist = np.abs(p - poles[labels])
    by_dist = np.lexsort((np.arange(idx.size), dist, labels))
    best = by_dist[start]
    frac = _orders_of(labels, od, n_cl) / n_orders
    mean = np.bincount(labels, fn_all, n_cl) / count
    var = np.maximum(np.bincount(labels, (fn_all - mean[labels]) ** 2, n_cl) / count, 0.0)
    members = np.split(np.argsort(labels, kind="stable"), np.cumsum(count)[:-1])
    if lv.shape[1] > 1:
        again = np.bincount(labels, second, n_cl) > 0
        best = _spanning_representatives(poles, lv, dist, members, best, again)
    kept: list[Cluster] = []
    rejected: list[Cluster] = []
    for c in range(n_cl):
        cl = Cluster(
            pole=complex(poles[c]),
            participation=lv[best[c]],
            members=idx[members[c]],
            fraction=float(frac[c]),
            spread_frequency=float(np.sqrt(var[c]) / f_med[c]),
        )
        (kept if frac[c] >= min_fraction else rejected).append(cl)
    kept.sort(key=lambda c: c.frequency_hz)
    rejected.sort(key=lambda c: c.frequency_hz)
    return kept, rejected
