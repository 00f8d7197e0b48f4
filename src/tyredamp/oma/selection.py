"""Stabilisation diagram and automatic mode selection from the poles themselves.

The selection follows the three-stage scheme of Reynders, Houbrechts & De Roeck,
"Fully automated (operational) modal analysis", Mech. Syst. Signal Process. 29
(2012) 228-250, with every cut taken from the data instead of a user threshold:

1. each admissible pole (``0 < zeta < zeta_max``, damped frequency in the band)
   gets the distance ``d = |f - f'| / f' + (1 - MAC)`` to its nearest pole of
   the previous order (their eq. 6, with the damping term left out: OMA damping
   scatters too much to judge a pole by it); physical poles recur with small
   ``d``, spurious ones do not. The two groups are split by Otsu's threshold on
   ``log10 d`` (two-means in one dimension, their step 1);
2. the consistent poles are grouped by hierarchical clustering (average
   linkage, the same distance) cut at that threshold (their step 2);
3. the cluster sizes (distinct orders) are split in two by Otsu again; the
   large clusters are the modes (their step 3).

The conventional stabilisation flags (frequency 1 %, damping 5 %, MAC 0.98
against the previous order) are kept only for the diagram.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.cluster.hierarchy import fcluster, linkage

from .ssi import OrderPoles

__all__ = ["ModeCluster", "Stabilisation", "otsu_threshold", "select_modes", "stabilisation"]


@dataclass(frozen=True)
class Stabilisation:
    """Per-pole facts of a stabilisation diagram.

    Attributes
    ----------
    admissible : ndarray of bool, shape (n_poles,)
        ``0 < zeta < zeta_max`` and the damped frequency inside the band.
    distance : ndarray, shape (n_poles,)
        ``|df| / f + (1 - MAC)`` to the nearest admissible pole of the previous
        order (inf for the first order or none).
    stable : ndarray of bool, shape (n_poles,)
        The conventional flag: frequency within 1 %, damping within 5 %, MAC > 0.98.
    """

    admissible: NDArray[np.bool_]
    distance: NDArray[np.float64]
    stable: NDArray[np.bool_]


@dataclass(frozen=True)
class ModeCluster:
    """One selected mode: the poles of its cluster and its representative.

    Attributes
    ----------
    members : ndarray of int
        Indices into the :class:`OrderPoles` (at most one per order).
    representative : int
        Index of the member nearest the cluster's median frequency.
    n_orders : int
        Number of distinct orders in the cluster.
    """

    members: NDArray[np.intp]
    representative: int
    n_orders: int


def _mac(a: NDArray[np.complex128], b: NDArray[np.complex128]) -> NDArray[np.float64]:
    """MAC of every row of ``a`` with every row of ``b`` (unit-norm rows)."""
    out: NDArray[np.float64] = np.abs(np.conj(a) @ b.T) ** 2
    return out


def stabilisation(
    op: OrderPoles, band: tuple[float, float], zeta_max: float = 0.2
) -> Stabilisation:
    """Classify the poles of ``op`` against the previous computed order.

    Parameters
    ----------
    op : OrderPoles
    band : (float, float)
        Hz; the damped frequency must lie inside.
    zeta_max : float
        Largest admissible damping ratio.
    """
    f = op.frequency_hz
    z = op.damping_ratio
    fd = op.poles.imag / (2 * np.pi)
    adm = (z > 0) & (z < zeta_max) & (fd >= band[0]) & (fd <= band[1])
    dist = np.full(f.size, np.inf)
    stable = np.zeros(f.size, bool)
    for a, b in zip(op.orders[:-1], op.orders[1:], strict=True):
        prev = np.flatnonzero((op.order == a) & adm)
        cur = np.flatnonzero((op.order == b) & adm)
        if prev.size == 0 or cur.size == 0:
            continue
        df = np.abs(f[cur][:, None] - f[prev][None, :]) / f[prev][None, :]
        d = df + 1 - _mac(op.shapes[cur], op.shapes[prev])
        j = np.argmin(d, axis=1)
        dist[cur] = d[np.arange(cur.size), j]
        dz = np.abs(z[cur] - z[prev][j]) / z[prev][j]
        mac = _mac(op.shapes[cur], op.shapes[prev])[np.arange(cur.size), j]
        stable[cur] = (df[np.arange(cur.size), j] < 0.01) & (dz < 0.05) & (mac > 0.98)
    return Stabilisation(adm, dist, stable)


def otsu_threshold(x: NDArray[np.float64]) -> float:
    """The cut that splits ``x`` into two groups of least within-group variance.

    Otsu, IEEE Trans. Syst. Man Cybern. 9(1) (1979) 62-66, eq. 18 (maximum
    between-class variance), over the sorted values (exact in one dimension).
    Returns the midpoint between the two groups; ``nan`` for fewer than 2 values.
    """
    v = np.sort(np.asarray(x, float))
    n = v.size
    if n < 2 or v[0] == v[-1]:
        return float("nan")
    c = np.cumsum(v)
    k = np.arange(1, n)
    m1 = c[:-1] / k
    m2 = (c[-1] - c[:-1]) / (n - k)
    between = k * (n - k) * (m1 - m2) ** 2
    between[v[1:] == v[:-1]] = -1.0  # no cut between equal values
    j = int(np.argmax(between))
    return float(0.5 * (v[j] + v[j + 1]))


def select_modes(op: OrderPoles, st: Stabilisation) -> tuple[list[ModeCluster], float]:
    """The persistent clusters of consistent poles (module docstring, steps 1-3).

    Returns
    -------
    clusters : list of ModeCluster
        Sorted by frequency.
    cut : float
        The data-driven distance cut of steps 1-2 (dimensionless).
    """
    cand = np.flatnonzero(st.admissible & np.isfinite(st.distance))
    if cand.size < 2:
        return [], float("nan")
    logd = np.log10(np.maximum(st.distance[cand], 1e-12))
    split = otsu_threshold(logd)
    low = logd[logd <= split] if np.isfinite(split) else logd
    # the consistent group's spread sets the cut (Reynders et al. 2012, sec. 3.2:
    # mean + 2 standard deviations of the distances of the likely physical poles)
    cut = float(10 ** (low.mean() + 2 * low.std())) if low.size > 1 else float(10**split)
    good = cand[st.distance[cand] <= cut]
    if good.size < 2:
        return [], cut
    f = op.frequency_hz[good]
    sh = op.shapes[good]
    D = np.abs(f[:, None] - f[None, :]) / np.minimum(f[:, None], f[None, :])
    D = D + 1 - _mac(sh, sh)
    np.fill_diagonal(D, 0.0)
    D = np.clip(0.5 * (D + D.T), 0.0, None)
    iu = np.triu_indices(good.size, 1)
    labels = fcluster(linkage(D[iu], "average"), t=cut, criterion="distance")
    groups = [good[labels == lab] for lab in np.unique(labels)]
    sizes = np.array([np.unique(op.order[g]).size for g in groups], float)
    size_cut = otsu_threshold(sizes)
    floor = max(3.0, 0.2 * op.orders.size)
    keep_at = max(floor, size_cut) if np.isfinite(size_cut) else floor
    out: list[ModeCluster] = []
    for g, n in zip(groups, sizes, strict=True):
        if n < keep_at:
            continue
        fm = np.median(op.frequency_hz[g])
        # one pole per order: the one nearest the median
        best: dict[int, int] = {}
        for idx in g:
            o = int(op.order[idx])
            if o not in best or abs(op.frequency_hz[idx] - fm) < abs(op.frequency_hz[best[o]] - fm):
                best[o] = int(idx)
        mem = np.array(sorted(best.values()), dtype=np.intp)
        rep = int(mem[np.argmin(np.abs(op.frequency_hz[mem] - fm))])
        out.append(ModeCluster(mem, rep, int(n)))
    out.sort(key=lambda c: float(op.frequency_hz[c.representative]))
    return out, cut
