"""Stabilisation flags and automatic selection of physical poles.

Rules (all thresholds are arguments with the defaults stated here):

1. *Admissible poles*: ``0 < zeta <= max_damping`` (default 0.2: negative
   damping and heavily damped computational poles are rejected) and damped
   frequency inside the analysis band.
2. *Stability*: a pole of order ``p`` is stable when the nearest pole of the
   previous computed order (``p - 1``, or ``p - order_step``) differs by at
   most ``tol_frequency`` (1 %) in natural frequency,
   ``tol_damping`` (5 %) relative in damping ratio and, with several inputs,
   has participation-vector MAC >= ``tol_mac`` (0.95).
3. *Clustering*: the stable poles are grouped by complete-linkage hierarchical
   clustering with the distance
   ``d_ij = |p_i - p_j| / max(|p_i|, |p_j|) + (1 - MAC(l_i, l_j))``
   (relative distance of the poles in the complex plane, which weighs a
   frequency difference ``df/f`` and a damping difference ``d zeta`` alike,
   plus the participation term with several inputs), cut at
   ``cluster_distance`` (0.01). Two poles of the same order never share a
   cluster, so two close modes that some orders resolve stay apart.
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
from scipy.spatial import cKDTree

from ..exceptions import InputError
from ..mechanics.modal_sum import pole_quantities
from .lscf import PoleSet

_SLACK = 1e-6  # relative widening of the candidate search (rounding of log|p|, arg p)

__all__ = ["Cluster", "StabilityFlags", "cluster_poles", "stability_flags"]


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
        Poles over model orders from :func:`~tyredamp.modal.lscf.plscf`.
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
            vstab[cur] = _mac_rows(ps.participation[cur], ps.participation[j]) >= tol_mac
        else:
            vstab[cur] = True
    return StabilityFlags(admissible=adm, frequency=fstab, damping=zstab, vector=vstab)


def _threshold_edges(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    od: NDArray[np.int64],
    cut: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Pairs of poles of different orders at rule-3 distance ``<= cut``.

    Returns ``(i, j, d)`` with ``i < j`` (each pair once) and ``d`` the distance
    of rule 3. Candidates come from a k-d tree: with ``m <= M`` the two moduli
    and ``theta`` the angle between the poles, ``|p_i - p_j| >= M - m`` and
    ``|p_i - p_j| >= M sin(theta)`` (``>= M`` for ``theta > pi/2``), so a pole
    distance ``<= cut < 1`` implies ``log M - log m <= -log(1 - cut)`` and
    ``theta <= arcsin(cut)``. In ``(log|p|, arg p)`` scaled by these two bounds
    every such pair lies within a unit max-norm ball (widened by ``_SLACK`` for
    rounding); the participation term ``1 - MAC >= 0`` only adds, so the
    candidates hold every pair within the cut. Their exact distance, element by
    element, then keeps the pairs ``<= cut``.
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
        ij = cKDTree(x).query_pairs(1.0 + _SLACK, p=np.inf, output_type="ndarray")
        i, j = ij[:, 0].astype(np.int64), ij[:, 1].astype(np.int64)  # i < j
        if wrap.size:
            keep = i < n  # two copies: the same pair as the two originals
            i, j = i[keep], np.concatenate([np.arange(n), wrap])[j[keep]]
            i, j = np.minimum(i, j), np.maximum(i, j)
    else:  # no bound: every pair is a candidate
        i, j = (np.asarray(k, np.int64) for k in np.triu_indices(n, 1))
    keep = od[i] != od[j]  # same order: never in one cluster
    i, j = i[keep], j[keep]
    d = np.abs(p[i] - p[j]) / np.maximum(mag[i], mag[j])
    if lv.shape[1] > 1:
        nn = np.sum(np.abs(lv) ** 2, axis=1)
        s = np.zeros(i.size, np.complex128)
        for k in range(lv.shape[1]):
            s += lv[i, k].conj() * lv[j, k]
        d = np.maximum(d + (1.0 - np.abs(s) ** 2 / (nn[i] * nn[j])), 0.0)
    keep = d <= cut
    return i[keep], j[keep], d[keep]


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
    # n^2 matrix: see _complete_linkage); poles numbered by increasing |p|, so
    # the clusters are numbered by their member of smallest |p|
    order = np.argsort(np.abs(p), kind="stable")
    labels = np.empty(idx.size, np.int64)
    labels[order] = _complete_linkage(
        idx.size, *_threshold_edges(p[order], lv[order], od[order], cluster_distance)
    )
    n_lab = int(labels.max()) + 1
    # per-cluster medians, spread, persistence and representative, all at once
    n_orders = ps.orders.size
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
    pairs = np.unique(labels * (int(od.max()) + 1) + od)
    frac = np.bincount(pairs // (int(od.max()) + 1), minlength=n_cl) / n_orders
    mean = np.bincount(labels, fn_all, n_cl) / count
    var = np.maximum(np.bincount(labels, (fn_all - mean[labels]) ** 2, n_cl) / count, 0.0)
    members = np.split(np.argsort(labels, kind="stable"), np.cumsum(count)[:-1])
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
