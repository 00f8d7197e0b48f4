"""Modes found again in replicates: independent measurements of the same FRFs.

A replicate is one independent record of the structure the modes were
identified from: one hit of an impact test, one measurement of a repeated
test, with the same channels. Identified alone, by its own search and its own
mode test over the lines of its band, a replicate finds the modes of the
structure again; noise, or a pole that the joint fit placed where the records
together happened to leave the most, is not found again in each. A mode found
in some replicates but not in others is undecidable from them: a weak mode that
only the replicates together resolve, or an artefact of the joint fit.

Each replicate is identified over the whole band first; a mode not found there
is looked for again over its own band ``f (1 +- 5 %)`` (at least its
half-power bandwidth on each side), where the misfit of strong modes elsewhere
does not widen the noise that a weak mode is tested against.

Matching. A replicate's mode of pole ``q`` can find the joint mode of pole
``p_r`` again when its damped frequency lies within the joint mode's half-power
band, ``|Im q - Im p_r| <= max(|Re p_r|, 2 pi df)``. The term ``1 / (j omega -
p_r)`` of the mode has half the power of its peak at ``omega = Im p_r +- |Re
p_r|`` (Ewins 2000, *Modal Testing: Theory, Practice and Application*, 2nd ed.,
sec. 2.3, the half-power bandwidth ``2 zeta_r omega_r``): two estimates of one
resonance lie within that band of each other. ``df``, the line spacing, is the
least resolution of a frequency. The damping is not compared: its estimate
from one record varies far more than the frequency's. Each replicate mode finds
one joint mode at most, and each joint mode is found by one replicate mode at
most: of the pairings with the most pairs, the one of least summed distance
``|Im q - Im p_r|`` (an assignment problem; Kuhn 1955, Naval Res. Logist. Q. 2,
the Hungarian method), so that a broad pole of the joint fit, whose band holds
its neighbour, does not take the replicate mode that lies nearer the neighbour.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .model import ModalModel

__all__ = ["ReplicateSupport", "kept_poles", "match_replicate", "replicate_support"]

#: A replicate's identification over a band (Hz): the poles (rad/s) of the
#: modes its mode test keeps.
Identify = Callable[[int, tuple[float, float]], NDArray[np.complex128]]


@dataclass(frozen=True)
class ReplicateSupport:
    """Where each replicate found one mode of the joint fit.

    Attributes
    ----------
    frequency_hz : float
        The joint fit's natural frequency, Hz.
    found_hz : tuple of (float or None)
        Per replicate, the natural frequency (Hz) of its mode that matches,
        None when it has none.
    """

    frequency_hz: float
    found_hz: tuple[float | None, ...]

    @property
    def n_found(self) -> int:
        """The number of replicates that found the mode again."""
        return sum(g is not None for g in self.found_hz)

    @property
    def confirmed(self) -> bool:
        """Found again in each replicate."""
        return self.n_found == len(self.found_hz)

    def text(self) -> str:
        """The finding in words."""
        n = len(self.found_hz)
        where = ", ".join("-" if g is None else f"{g:.6g}" for g in self.found_hz)
        if self.confirmed:
            return f"found again in each of the {n} replicates ({where} Hz)"
        return (
            f"undecidable: found again in {self.n_found} of the {n} replicates "
            f"({where} Hz): a weak mode that only the replicates together resolve, "
            "or an artefact of the joint fit"
        )

    def to_dict(self) -> dict[str, object]:
        """The JSON form (``meta.replicates`` of the modes document)."""
        return {
            "found_hz": list(self.found_hz),
            "confirmed": self.confirmed,
            "text": self.text(),
        }


def kept_poles(model: ModalModel) -> NDArray[np.complex128]:
    """The poles (rad/s) of the modes the mode test keeps (every mode when the
    model carries no test: modes asked for by number or frequency)."""
    p = np.asarray(model.poles, dtype=complex)
    q = model.quality
    if q is None or q.statistic.size != p.size:
        return p
    keep = np.asarray(q.statistic, dtype=float) > np.asarray(q.thresholds, dtype=float)
    return p[keep]


def match_replicate(
    poles: NDArray[np.complex128], found: NDArray[np.complex128], df: float
) -> list[complex | None]:
    """Which joint modes a replicate's modes find again.

    Parameters
    ----------
    poles : ndarray, shape (m,)
        The joint fit's poles, rad/s (upper half plane).
    found : ndarray, shape (k,)
        The poles (rad/s) of the modes the replicate's test keeps.
    df : float
        The line spacing, Hz: the least radius.

    Returns
    -------
    list of (complex or None), length m
        Per joint mode, the replicate pole paired with it, its damped frequency
        within the mode's half-power band, ``max(|Re p|, 2 pi df)`` either side
        (module docstring), else None.
    """
    from scipy.optimize import linear_sum_assignment

    p = np.asarray(poles, dtype=complex).ravel()
    p = p.real + 1j * np.abs(p.imag)
    q = np.asarray(found, dtype=complex).ravel()
    q = q.real + 1j * np.abs(q.imag)
    out: list[complex | None] = [None] * p.size
    if p.size == 0 or q.size == 0:
        return out
    radius = np.maximum(np.abs(p.real), 2 * np.pi * df)
    d = np.abs(q.imag[:, None] - p.imag[None, :])
    ok = d <= radius[None, :]
    # an infeasible pair costs more than any pairing of feasible ones: most pairs first
    cost = np.where(ok, d, 1.0 + d[ok].sum() if ok.any() else 1.0)
    for i, r in zip(*linear_sum_assignment(cost), strict=True):
        if ok[i, r]:
            out[int(r)] = complex(q[i])
    return out


def replicate_support(
    model: ModalModel,
    n_replicates: int,
    identify: Identify,
    *,
    band: tuple[float, float],
    df: float,
) -> list[ReplicateSupport]:
    """Find each mode of ``model`` again in each of ``n_replicates`` replicates.

    Parameters
    ----------
    model : ModalModel
        The joint fit.
    n_replicates : int
        How many replicates there are.
    identify : callable
        ``identify(k, band)``: the poles (rad/s) of the modes that replicate
        ``k``'s own identification keeps over ``band`` (Hz).
    band : (float, float)
        The joint fit's band, Hz: each replicate is identified over it first, and
        a mode's own band stays inside it.
    df : float
        The line spacing, Hz.

    Returns
    -------
    list of ReplicateSupport
        One per mode of ``model``, in its order.
    """
    poles = np.asarray(model.poles, dtype=complex)
    f = np.asarray(model.frequency_hz, dtype=float)
    half = np.maximum(0.05 * f, 2 * np.maximum(np.abs(poles.real) / (2 * np.pi), df))
    found = [match_replicate(poles, identify(k, band), df) for k in range(n_replicates)]
    for r in range(f.size):
        own = (float(max(band[0], f[r] - half[r])), float(min(band[1], f[r] + half[r])))
        for k in range(n_replicates):
            if found[k][r] is None:
                found[k][r] = match_replicate(poles, identify(k, own), df)[r]
    return [
        ReplicateSupport(
            float(f[r]),
            tuple(
                None if q is None else _hz(q) for q in (found[k][r] for k in range(n_replicates))
            ),
        )
        for r in range(f.size)
    ]


def _hz(pole: complex) -> float:
    """The natural frequency (Hz) of a pole (rad/s): ``|p| / 2 pi``."""
    return abs(pole) / (2 * np.pi)
