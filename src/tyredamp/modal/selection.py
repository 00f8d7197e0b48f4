"""Stabilisation flags and automatic selection of physical poles.

Rules (all thresholds are arguments with the defaults stated here):

1. *Admissible poles*: ``0 < zeta <= max_damping`` (default 0.2: negative
   damping and heavily damped computational poles are rejected) and damped
   frequency inside the analysis band.
2. *Stability*: a pole of order ``p`` is stable when the nearest pole of order
   ``p - 1`` differs by at most ``tol_frequency`` (1 %) in natural frequency,
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
from scipy.cluster.hierarchy import fcluster, linkage
from scipy.spatial.distance import squareform

from ..exceptions import InputError
from .lscf import PoleSet

__all__ = ["Cluster", "StabilityFlags", "cluster_poles", "stability_flags"]


@dataclass(frozen=True)
class StabilityFlags:
    """Per-pole flags of a :class:`PoleSet` (all arrays of shape (n,)).

    ``admissible``: passes the damping and band rules; ``frequency``,
    ``damping``, ``vector``: stable against the previous order; ``stable``:
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
    for p in ps.orders[1:]:
        cur = ps.at_order(int(p))
        prev = ps.at_order(int(p) - 1)
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
    if idx.size == 1:
        labels = np.array([1])
    else:
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
        labels = fcluster(z, t=cluster_distance, criterion="distance")
    n_orders = ps.orders.size
    kept: list[Cluster] = []
    rejected: list[Cluster] = []
    for lab in np.unique(labels):
        mem = np.flatnonzero(labels == lab)
        fn = np.abs(p[mem]) / (2 * np.pi)
        zz = -p[mem].real / np.abs(p[mem])
        f_med = float(np.median(fn))
        z_med = float(np.median(zz))
        w = 2 * np.pi * f_med
        pole = complex(-z_med * w, w * np.sqrt(max(1 - z_med**2, 0.0)))
        best = int(np.argmin(np.abs(p[mem] - pole)))
        frac = np.unique(od[mem]).size / n_orders
        cl = Cluster(
            pole=pole,
            participation=lv[mem[best]],
            members=idx[mem],
            fraction=float(frac),
            spread_frequency=float(np.std(fn) / f_med),
        )
        (kept if frac >= min_fraction else rejected).append(cl)
    kept.sort(key=lambda c: c.frequency_hz)
    rejected.sort(key=lambda c: c.frequency_hz)
    return kept, rejected
