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
from scipy.cluster.hierarchy import linkage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial.distance import squareform

from ..exceptions import InputError
from .lscf import PoleSet

_CHUNK = 200  # poles per complete-linkage call (groups split at gaps are joined up to it)

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


def _complete_linkage(
    p: NDArray[np.complex128],
    lv: NDArray[np.complex128],
    od: NDArray[np.int64],
    cut: float,
) -> NDArray[np.int64]:
    """Labels ``0..k-1`` of complete-linkage clusters cut at ``cut`` (rule 3)."""
    if p.size == 1:
        return np.zeros(1, np.int64)
    mag = np.maximum(np.abs(p)[:, None], np.abs(p)[None, :])
    d = np.abs(p[:, None] - p[None, :]) / mag
    if lv.shape[1] > 1:
        num = np.abs(lv.conj() @ lv.T) ** 2
        nn = np.sum(np.abs(lv) ** 2, axis=1)
        d = d + (1.0 - num / np.outer(nn, nn))
    big = 1e6
    d = np.where(od[:, None] == od[None, :], big, d)
    np.fill_diagonal(d, 0.0)
    d = np.clip(0.5 * (d + d.T), 0.0, big)
    z = linkage(squareform(d, checks=False), method="complete")
    # complete linkage is monotone: the merges up to the cut are the first rows
    # of z; the clusters are the connected components of those merges
    n = p.size
    k = int(np.searchsorted(z[:, 2], cut, side="right"))
    if k == 0:
        return np.arange(n, dtype=np.int64)
    a = z[:k, :2].astype(np.int64).ravel()
    b = np.repeat(n + np.arange(k), 2)
    g = coo_matrix((np.ones(2 * k), (a, b)), shape=(n + k, n + k))
    lab = connected_components(g, directed=False)[1][:n]
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
    labels = np.zeros(idx.size, np.int64)
    # complete linkage never joins poles farther apart than the cut, and the
    # distance is at least the relative gap of |p|: groups split at such gaps
    # cluster independently (same clusters, no n^2 matrix over all poles)
    order = np.argsort(np.abs(p), kind="stable")
    mag = np.abs(p)[order]
    gap = 1.0 - mag[:-1] / np.where(mag[1:] > 0, mag[1:], 1.0)
    cuts = np.flatnonzero(gap > cluster_distance) + 1
    # consecutive groups are joined up to _CHUNK poles (fewer, larger linkages)
    chunks: list[int] = []
    for cut in cuts.tolist():
        if cut - (chunks[-1] if chunks else 0) >= _CHUNK:
            chunks.append(cut)
    n_lab = 0
    for grp in np.split(order, chunks):
        sub = _complete_linkage(p[grp], lv[grp], od[grp], cluster_distance)
        labels[grp] = sub + n_lab
        n_lab += int(sub.max()) + 1
    # per-cluster medians, spread, persistence and representative, all at once
    n_orders = ps.orders.size
    n_cl = n_lab
    fn_all = np.abs(p) / (2 * np.pi)
    zz_all = -p.real / np.abs(p)
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
