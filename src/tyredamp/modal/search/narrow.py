"""A pole narrower than the lines: a resonance, or a spike or a step?

A mode whose half-power bandwidth ``2 zeta f_n`` is below the line spacing
``df`` (a lightly damped structure measured with coarse lines, e.g. a free beam
at 0.02 % damping and 1 Hz lines) is a real mode whose frequency the lines fix
and whose damping they only bound (:func:`unresolved_damping`).
A pole that narrow can also fit what is not a resonance: one outlying line (a
spike) or a level change between two lines (a step, e.g. where the records of an
impact test were joined). The two differ away from the pole: a resonance of any
width below ``df`` keeps its tail over many lines, the partial-fraction term
``kappa R / (s - p)`` falling off as ``1 / (f - f_n)``: at ``k`` lines from it
the term is ``1 / k`` of its value half a line away, so over the lines beyond
the two nearest a resonance still holds about a fifth of its power (the sum
of ``1 / (k + 1/2)^2`` over ``k >= 1`` against the two nearest lines' ``2 x 4``).
A spike holds nothing there and a step is flat.

:func:`narrow_evidence` makes that a likelihood-ratio test: the residual of a
fit without the pole, in units of each output's noise, over a window of lines
around it, is explained by the null model (free values at the two lines
nearest the pole, a step at the pole's frequency and a constant, and for a pole
narrower than the lines the terms of the fit's modes in the window with their
derivatives, each FRF with its own complex coefficients) and by the null model
plus the pole (its residue free per FRF); the drop in the residual sum of
squares, below and above the pole, is its evidence beyond what these explain,
compared by :func:`narrow_refusal` with the mode test's threshold. With
Gaussian noise of unit variance per real part the drop is chi-squared with two
degrees of freedom per FRF when the pole is absent (Wilks' theorem for a fixed
pole; the mode test's threshold covers the pole's search), so a noise spike or
a step does not pass, and a resonance narrower than the lines does.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..fit._basis import factors, residual_lines
from ..fit.fit import FitResult, ModalFitter
from .residual_peaks import model_of
from .resolution import unresolved_pair_text

__all__ = [
    "EDGE_LINES",
    "STEP_LINES",
    "WINDOW_LINES",
    "at_the_end",
    "narrow_evidence",
    "narrow_refusal",
    "too_narrow",
    "unresolved_damping",
]

#: lines either side of a narrow pole over which its evidence is weighed (its tail
#: at 32 lines is 1/64 of its value half a line away: beyond, nothing to add)
WINDOW_LINES = 32


#: half-power bandwidths (in lines) below which a pole competes with a step or a
#: spike at its lines (:func:`narrow_refusal`)
STEP_LINES = 3.0

#: fewest lines either side of a narrow pole for its tails to be weighed: nearer the
#: end of the lines, the few lines there (the erratic low end of an impact test, a
#: band edge) cannot tell a resonance from a spike
EDGE_LINES = 8


def at_the_end(f: NDArray[np.float64], pole: complex) -> bool:
    """Whether fewer than ``EDGE_LINES`` lines ``f`` (Hz) lie on either side of ``pole``."""
    j = int(np.searchsorted(f, pole.imag / (2 * np.pi)))
    return j < EDGE_LINES or f.size - j < EDGE_LINES


def too_narrow(pole: complex, df: float) -> bool:
    """Whether the half-power bandwidth ``-Re p / pi`` (Hz) of ``pole`` (rad/s) is below
    the line spacing ``df`` (Hz)."""
    return bool(df > 0 and -pole.real / np.pi < df)


def _real_columns(cols: list[NDArray[np.complex128]], free: list[bool]) -> NDArray[np.float64]:
    """Real design matrix (2 L, q) of complex columns ``cols`` (each (L,)): a column with
    a complex coefficient (``free``) gives two real columns ``c`` and ``i c``, one with
    a real coefficient gives ``c``; rows are the real parts, then the imaginary parts."""
    out = []
    for c, cplx in zip(cols, free, strict=True):
        out.append(np.concatenate([c.real, c.imag]))
        if cplx:
            out.append(np.concatenate([-c.imag, c.real]))
    return np.stack(out, axis=1)


def _fit(a: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """The residual of the least-squares fit of every column of ``y`` by ``a``."""
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    return np.asarray(y - a @ coef)


def narrow_evidence(
    fitter: ModalFitter,
    res: FitResult,
    pole: complex,
    drop: int | None = None,
    half_lines: int = WINDOW_LINES,
    neighbours: bool = True,
) -> tuple[float, float]:
    """A pole's evidence beyond a spike and a step at its lines, per side (module docstring).

    Parameters
    ----------
    fitter : ModalFitter
        The fitter of the data.
    res : FitResult
        A fit; its residual (without the pole ``drop`` when given) is what the pole
        must explain, in units of each output's noise ``res.sigma_out``.
    pole : complex
        The pole (rad/s, upper half plane).
    drop : int, optional
        Index of ``pole``'s own mode in ``res`` (a joint fit that holds it): left out of
        the model whose residual is tested.
    half_lines : int
        Lines either side of the pole in the window.
    neighbours : bool
        Whether the terms of the fit's modes in the window, with their derivatives,
        are in the null model (what the flank of a mode's misfit holds; also what a
        close second mode wider than the lines looks like, which a parametric fit
        resolves through its half-power band: left out for such poles).

    Returns
    -------
    (float, float)
        The drop of the residual sum of squares when the pole, its residue free per
        FRF, is added to the null model (free values at the two lines nearest it, a
        step at its frequency, a constant, and the terms of the fit's modes in the
        window with their derivatives), summed over the lines below the pole and
        over those above it, in units of the window's noise level (the noise, or
        the residual variance of the fit with the pole when that is larger: the
        model error the window holds). A resonance holds evidence on both sides
        (its tail falls off as ``1 / |f - f_n|`` either way); a pole that takes up
        the one-sided flank of another mode's misfit holds it on one. (0, 0) when
        the window holds fewer than 8 lines.
    """
    f = fitter.f
    f0 = pole.imag / (2 * np.pi)
    j = int(np.searchsorted(f, f0))
    sl = slice(max(j - half_lines, 0), min(j + half_lines, f.size))
    n = sl.stop - sl.start
    if n < 8:
        return 0.0, 0.0
    poles, residues, terms, s2 = model_of(fitter, res)
    if drop is not None:
        poles = np.delete(poles, drop)
        residues = np.delete(residues, drop, axis=2)
    e = residual_lines(fitter, poles, residues, terms, sl) / np.sqrt(s2)[:, None, None]
    y = e.reshape(-1, n).T  # (L, n_frf)
    y2 = np.concatenate([y.real, y.imag])
    s, kap, _ = factors(fitter, sl)
    lw = fitter.line_weights[sl] if fitter.line_weights is not None else np.ones(n)
    fl = f[sl]
    near = np.zeros((2, n))
    below = int(np.searchsorted(fl, f0)) - 1
    for r, i in enumerate((below, below + 1)):
        if 0 <= i < n:
            near[r, i] = lw[i]
    null = [near[0].astype(complex), near[1].astype(complex)]
    null += [(lw * (fl > f0)).astype(complex), lw.astype(complex)]
    # the modes of the fit within the window: their terms and derivatives (a mode
    # whose pole or residue is a little off leaves that dipole in the residual)
    near_modes = np.abs(poles.imag / (2 * np.pi) - f0) <= half_lines * (fl[-1] - fl[0]) / n
    for q in poles[near_modes] if neighbours else []:
        if abs(q - pole) > 1e-9 * abs(pole):
            null += [kap / (s - q), kap / (s - q) ** 2]
    a_p = kap / (s - pole)
    b_p = kap / (s - np.conj(pole))
    cols = [*null, a_p + b_p, 1j * (a_p - b_p)]
    kinds = [True] * len(null) + [False, False]
    a0 = _real_columns(null, [True] * len(null))
    a1 = _real_columns(cols, kinds)
    r0 = _fit(a0, y2)
    r1 = _fit(a1, y2)
    dof = max(r1.size - a1.shape[1] * y.shape[1], 1)
    scale = max(float(np.sum(r1 * r1)) / dof, 1.0)
    d = np.sum(r0 * r0 - r1 * r1, axis=1)
    d = d[:n] + d[n:]  # per line
    return float(np.sum(d[fl < f0])) / scale, float(np.sum(d[fl > f0])) / scale


def narrow_refusal(
    fitter: ModalFitter,
    res: FitResult,
    pole: complex,
    threshold: float,
    drop: int | None = None,
    others: NDArray[np.complex128] | None = None,
) -> str:
    """Why a ``pole`` a few lines wide or narrower is refused ('' when it is a resonance,
    and for wider poles).

    A pole narrower than the lines (:func:`too_narrow`) is a resonance when it lies
    away from the ends of the lines (``EDGE_LINES``), no mode lies within a line
    spacing of it (the record does not resolve the two:
    :mod:`~tyredamp.modal.search.resolution`; ``others``: the modes to compare with, when
    not those of ``res`` without its mode ``drop``), and its evidence beyond a spike
    at its two nearest lines, a step there and the terms of the modes beside it
    (:func:`narrow_evidence` on the residual of ``res`` without ``drop``) passes half
    the ``threshold`` on each side of it (a resonance's tails are alike on both
    sides, so together they pass the threshold). A pole up to ``STEP_LINES`` lines
    wide, which a step or a spike at its lines can also take for a peak, is a
    resonance when its evidence beyond a spike and a step alone (a close second
    mode of that width is resolved by its half-power band) passes half the
    ``threshold`` on each side.
    """
    df = float(fitter.f[1] - fitter.f[0]) if fitter.f.size > 1 else 0.0
    bw = -pole.real / np.pi  # half-power bandwidth 2 zeta f_n (Hz)
    if not too_narrow(pole, STEP_LINES * df):
        return ""
    if not too_narrow(pole, df):
        lo, hi = narrow_evidence(fitter, res, pole, drop, neighbours=False)
        if min(lo, hi) > 0.5 * threshold:
            return ""
        return (
            f"half-power bandwidth {bw:.3g} Hz, {bw / df:.2g} lines: beyond a spike at its "
            f"two nearest lines and a step there, T = {lo:.3g} below "
            f"and {hi:.3g} above it, not both above half the threshold {threshold:.3g} (a "
            "step or an outlying line, not a resonance)"
        )
    why = f"half-power bandwidth {bw:.3g} Hz below the line spacing {df:.3g} Hz"
    if at_the_end(fitter.f, pole):
        return f"{why}, within {EDGE_LINES} lines of the end of the lines"
    if others is None:
        others = np.delete(res.poles, drop) if drop is not None else res.poles
    near = np.abs(np.abs(others) - abs(pole)) / (2 * np.pi) < df
    if np.any(near):
        # the lines do not resolve it from that mode (resolution.py)
        f_near = float(np.abs(others[near][0]) / (2 * np.pi))
        return f"{why}: {unresolved_pair_text(f_near, df)}"
    lo, hi = narrow_evidence(fitter, res, pole, drop)
    if min(lo, hi) > 0.5 * threshold:
        return ""
    return (
        f"{why}: beyond a spike at its two nearest lines, a step there and the modes "
        f"beside it, T = {lo:.3g} below and {hi:.3g} above it, not both above half the "
        f"threshold {threshold:.3g}"
    )


def unresolved_damping(frequency_hz: float, damping_ratio: float, df: float) -> str:
    """The statement for a mode whose half-power band is narrower than the lines ('' if not).

    The half-power bandwidth ``2 zeta f_n`` (Hz) of such a mode lies between two
    lines ``df`` apart: the lines fix its frequency, but any damping with a
    bandwidth below ``df`` fits them alike, so the data bound the damping ratio,
    ``zeta < df / (2 f_n)``, and do not measure it.
    """
    if not (df > 0 and frequency_hz > 0) or 2.0 * damping_ratio * frequency_hz >= df:
        return ""
    return (
        f"mode at {frequency_hz:.5g} Hz: half-power bandwidth "
        f"{2.0 * damping_ratio * frequency_hz:.2g} Hz below the line spacing {df:.3g} Hz: "
        f"its damping is not resolved by the lines (zeta < {df / (2.0 * frequency_hz):.2%}, "
        "an upper bound; measure with finer lines for a value)"
    )
