"""Physical sources of non-proportional damping in the ring tyre and their decomposition.

The damping matrix of the virtual tyre is a sum of named physical sources
(:attr:`RingTyre.damping_sources`): the sidewall rubber on its radial and
tangential stiffness, the band rubber on bending and on membrane strain, a
tread splice, the air cavity, the tread in a loaded contact patch and the
drive-point attachment. Distributed sources that are uniform round the
circumference couple only modes of the same wave number; the in-band
off-diagonal terms of ``C' = Phi^T C Phi`` (radial spec eq. [14]) that make
the modes complex (eq. [16]) come from whatever breaks that symmetry or mixes
different losses inside one mode (band with air, radial with tangential).

:func:`damping_decomposition` splits the off-diagonal part of ``C'`` of the
in-band modes into the contribution of each source: since ``C = sum_s C_s``
and the modes ``Phi`` are the same, ``C'_off = sum_s Phi^T C_s Phi|_off``
exactly, and the share of source ``s`` is the projection

``share_s = <C'_off,s, C'_off> / ||C'_off||^2``  (Frobenius),

which sums to one over the sources (a source whose terms cancel those of
another has a negative share).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..exceptions import InputError

if TYPE_CHECKING:
    from .ring import RingTyre

__all__ = ["DampingDecomposition", "damping_decomposition", "tip_loss_damping"]


@dataclass(frozen=True)
class DampingDecomposition:
    """The off-diagonal part of ``C'`` of the in-band modes, source by source.

    Attributes
    ----------
    frequency_hz : ndarray, shape (m,)
        Undamped frequencies of the in-band modes.
    modal_damping : ndarray, shape (m, m)
        ``C' = Phi^T C Phi`` (1/s) with mass-normalised undamped modes.
    offdiagonal_share : float
        ``||C'_off|| / ||C'||`` (Frobenius): 0 for proportional damping.
    names : tuple of str
        The sources.
    share : ndarray, shape (k,)
        Projection share of each source in ``C'_off`` (sums to 1).
    norm_ratio : ndarray, shape (k,)
        ``||C'_off,s|| / ||C'_off||`` of each source alone.
    """

    frequency_hz: NDArray[np.float64]
    modal_damping: NDArray[np.float64]
    offdiagonal_share: float
    names: tuple[str, ...]
    share: NDArray[np.float64]
    norm_ratio: NDArray[np.float64]

    @property
    def coupling(self) -> NDArray[np.float64]:
        """First-order complexity ``|alpha_k^(n)| = omega_n |C'_kn| / |omega_n^2 - omega_k^2|``.

        Radial spec eq. [16] (Adhikari & Woodhouse, J. Sound Vib. 243(1), 2001):
        the imaginary part that mode ``k`` lends to the complex mode ``n``,
        relative to its real part; shape (m, m), column ``n``, zero diagonal.
        A double (``omega_k = omega_n``) that the damping couples gets ``inf``.
        """
        w = 2 * np.pi * self.frequency_hz
        gap = np.abs(w[None, :] ** 2 - w[:, None] ** 2)
        c = np.abs(self.modal_damping) * w[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(gap > 0, c / np.where(gap > 0, gap, 1.0), np.where(c > 0, np.inf, 0.0))
        np.fill_diagonal(a, 0.0)
        return np.asarray(a, dtype=np.float64)

    def largest_coupling(self) -> tuple[float, float, float]:
        """``(f_k, f_n, |alpha_k^(n)|)`` of the largest finite :attr:`coupling` (Hz, Hz, 1)."""
        a = self.coupling
        a = np.where(np.isfinite(a), a, 0.0)
        k, n = np.unravel_index(int(np.argmax(a)), a.shape)
        return float(self.frequency_hz[k]), float(self.frequency_hz[n]), float(a[k, n])

    def as_dict(self) -> dict[str, float]:
        """``{source: share}``."""
        return {n: float(s) for n, s in zip(self.names, self.share, strict=True)}

    def format(self) -> str:
        """A text table: source, share of the off-diagonal part, norm ratio."""
        lines = [
            f"in-band modes: {self.frequency_hz.size}; off-diagonal share of C': "
            f"{self.offdiagonal_share:.3f}",
            f"{'source':22s} {'share':>8s} {'alone':>8s}",
        ]
        for n, s, r in zip(self.names, self.share, self.norm_ratio, strict=True):
            lines.append(f"{n:22s} {100 * s:7.1f}% {100 * r:7.1f}%")
        return "\n".join(lines)


def tip_loss_damping(mass: float, stiffness: float, loss_factor: float, frequency: float) -> float:
    """Equivalent dashpot (N s/m) on the band of the tread loss under a shaker tip.

    With the force gauge at the tyre surface (ISO 7626-2:2015, sec. 6) the
    mass ``m`` below the gauge's sensing element (gauge base, stud, glued
    tip) rides on the tread under the tip, a spring ``k (1 + i eta)`` in
    series with the band: the tread is worked only by the relative motion of
    tip and band, not by the band's absolute motion. Eliminating the tip
    (``-omega^2 m y = -k* (y - x)`` in free vibration) leaves on the band
    the dynamic stiffness ``-omega^2 m k* / (k* - omega^2 m)``, whose
    imaginary part is the dashpot

    ``c(omega) = omega^3 m^2 k eta / ((k - omega^2 m)^2 + (k eta)^2)``

    (the loss of a Kelvin element carrying a mass; e.g. Harris & Piersol,
    *Shock and Vibration Handbook*, 5th ed., 2002, ch. 2, the single-DOF
    system with structural damping, here seen from its base). It grows as
    ``omega^3`` far below the tip resonance ``sqrt(k/m)``.

    Parameters
    ----------
    mass : float
        Mass below the sensing element, kg (>= 0).
    stiffness : float
        Tread stiffness under the tip, N/m (> 0).
    loss_factor : float
        Tread loss factor (>= 0).
    frequency : float
        Frequency in Hz (>= 0).

    Returns
    -------
    float
        ``c`` in N s/m.
    """
    for name, v, pos in (
        ("mass", mass, False),
        ("stiffness", stiffness, True),
        ("loss_factor", loss_factor, False),
        ("frequency", frequency, False),
    ):
        if not math.isfinite(v) or v < 0 or (pos and v == 0):
            bound = "> 0" if pos else ">= 0"
            raise InputError(f"{name}: expected a finite number {bound}, got {v}")
    w = 2 * math.pi * frequency
    k = stiffness
    return w**3 * mass**2 * k * loss_factor / ((k - w * w * mass) ** 2 + (k * loss_factor) ** 2)


def _offdiag(a: NDArray[np.float64]) -> NDArray[np.float64]:
    return a - np.diag(np.diag(a))


def damping_decomposition(
    tyre: RingTyre, band: tuple[float, float] = (0.0, 200.0)
) -> DampingDecomposition:
    """Split the off-diagonal in-band modal damping of ``tyre`` by physical source.

    The undamped modes of the physical system in ``band`` (Hz) are computed
    once; each source's damping matrix (:attr:`RingTyre.damping_sources`) is
    projected on them (radial spec eq. [14]); the off-diagonal parts add up
    to that of the whole ``C`` and are shared by projection (module
    docstring). The ``nonproportionality`` knob is not applied: this is the
    physical distribution.

    Parameters
    ----------
    tyre : RingTyre
    band : (float, float)
        Frequency band in Hz.

    Returns
    -------
    DampingDecomposition
    """
    um = tyre.physical_system.undamped_modes()
    f = um.frequency_hz
    sel = np.flatnonzero((f >= band[0]) & (f <= band[1]))
    if sel.size < 2:
        raise InputError(f"band: expected at least two modes in {band} Hz, found {sel.size}")
    phi = um.phi[:, sel]
    names = tuple(tyre.damping_sources)
    parts = [_offdiag(phi.T @ tyre.damping_sources[n] @ phi) for n in names]
    cfull = phi.T @ tyre.physical_system.C @ phi
    total = _offdiag(cfull)
    tn2 = float(np.sum(total**2))
    if tn2 == 0:
        share = np.zeros(len(names))
        ratio = np.zeros(len(names))
    else:
        share = np.array([float(np.sum(p * total)) / tn2 for p in parts])
        ratio = np.array([math.sqrt(float(np.sum(p**2)) / tn2) for p in parts])
    return DampingDecomposition(
        frequency_hz=f[sel],
        modal_damping=0.5 * (cfull + cfull.T),
        offdiagonal_share=math.sqrt(tn2) / float(np.linalg.norm(cfull)),
        names=names,
        share=share,
        norm_ratio=ratio,
    )
