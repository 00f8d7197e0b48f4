"""Two poles the lines cannot tell apart: the resolution of the record.

An FRF of lines ``df`` apart (Hz) comes from records of ``T = 1 / df`` seconds,
and a record of ``T`` seconds resolves two sinusoids no closer than ``1 / T =
df`` (the Rayleigh limit of Fourier analysis; Harris, "On the use of windows for
harmonic analysis with the discrete Fourier transform", *Proc. IEEE* 66, 1978,
sec. II, the resolution bandwidth of a rectangular window being one bin). A mode
whose half-power bandwidth ``2 zeta f_n`` is below ``df`` rings longer than the
record (its decay time ``1 / (pi 2 zeta f_n)`` exceeds ``T / pi``): within the
record it is a sinusoid, and two such modes closer than ``df`` are two
sinusoids the record does not resolve. The lines of such a pair differ from
those of one pole only by a dipole term (the derivative of one resonance), which
is also what the truncation of a ringing response (leakage) puts beside a peak:
the data do not prove two modes there, nor where a pole of any width lies within
``df`` of such a ringing mode (the record does not tell their frequencies apart,
and the second pole then takes up the ringing mode's leakage).
:func:`unresolved_pair` finds such a pair
in a fit; :func:`~tyredamp.modal.final.final_complex` keeps its stronger pole
and refits. Modes wider than the lines, resolved close pairs among them, are
left alone however close (a parametric fit resolves them through their
half-power bands).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["unresolved_pair", "unresolved_pair_text"]


def unresolved_pair(
    poles: NDArray[np.complex128], statistic: NDArray[np.float64], df: float
) -> tuple[int, int] | None:
    """The weaker and the stronger pole of the closest pair the lines do not resolve.

    Parameters
    ----------
    poles : ndarray, complex, shape (m,)
        In-band poles (rad/s, upper half plane).
    statistic : ndarray, shape (m,)
        Each mode's test statistic ``T`` (its strength).
    df : float
        Line spacing (Hz).

    Returns
    -------
    (int, int) or None
        Indices ``(weaker, stronger)`` of the closest pair whose natural frequencies
        differ by less than ``df``, one of them with a half-power bandwidth ``-Re p / pi``
        (Hz) below ``df`` (module docstring); None when there is none.
    """
    p = np.asarray(poles, complex)
    t = np.asarray(statistic, float)
    if p.size < 2 or not df > 0:
        return None
    fn = np.abs(p) / (2.0 * np.pi)
    narrow = -p.real / np.pi < df  # half-power bandwidth 2 zeta f_n = -Re p / pi (Hz)
    best: tuple[float, int, int] | None = None
    for i in range(p.size):
        for j in range(i + 1, p.size):
            gap = abs(fn[i] - fn[j])
            if (narrow[i] or narrow[j]) and gap < df and (best is None or gap < best[0]):
                best = (gap, i, j)
    if best is None:
        return None
    _, i, j = best
    return (i, j) if t[i] < t[j] else (j, i)


def unresolved_pair_text(f_strong: float, df: float) -> str:
    """The reason a pole of an unresolved pair is dropped, for people."""
    return (
        f"within the line spacing {df:.3g} Hz of the stronger mode at {f_strong:.5g} Hz, a "
        f"pair with a mode narrower than the lines: records of {1.0 / df:.3g} s do not "
        "resolve two modes there (one resonance, its distortion fitted by a second pole)"
    )
