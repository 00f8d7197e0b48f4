"""Tests of a fit's residual against the noise: from the coherence, or from the data alone.

The statistics behind the fit verdicts of :mod:`tyredamp.studies.verdicts`
(whose module docstring derives them): :func:`noise_test` judges the
residual against a per-line noise variance (the one the FRF's coherence
implies, :func:`frf_noise_variance`), and without coherence
:func:`floor_test` judges it against the noise floor the data themselves
show (:func:`adjacent_line_variance`: differences of adjacent lines, a
running median) and the structure of the residual across lines
(:func:`residual_correlation`, outlying lines). :func:`noise_test_blocks`
and :func:`floor_test_blocks` are the same tests on a block of lines at a
time, for the verdicts of long FRFs: their memory beyond the data is a block's
and 8-16 bytes per line.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import special

from ..exceptions import InputError, ShapeError
from ..frf import FRF, KIND_POWER
from ..modal.statistics.stats import chi2_isf, chi2_sf, f_isf, f_sf

__all__ = [
    "ALPHA",
    "BLOCK_LINES",
    "NoiseTest",
    "adjacent_line_variance",
    "floor_test",
    "floor_test_blocks",
    "frf_noise_variance",
    "noise_test",
    "noise_test_blocks",
    "residual_correlation",
]

#: Significance level of the test against the noise.
ALPHA = 1e-3
#: Lines per block of the blocked tests (:func:`noise_test_blocks`,
#: :func:`floor_test_blocks`): their arrays are those of a block, and only the
#: excess residual of each line is kept for every line.
BLOCK_LINES = 65536
#: Share of the excess residual that defines the misfit region (central part).
_REGION = 0.8
#: Lines of the running median of the adjacent-line noise floor (odd).
_FLOOR_LINES = 21
#: Differences of the noise floor: fourth differences (binomial weights), which
#: cancel a cubic trend of the FRF over five lines, so that a smooth FRF between
#: few lines per half-power band adds little (the second differences of
#: :func:`tyredamp.modal.statistics.stats.difference_noise` cancel only a straight line)
_DIFF = np.array([1.0, -4.0, 6.0, -4.0, 1.0])
#: Fewest lines a fit is judged on without coherence.
_MIN_LINES = 8
#: Degrees of freedom of the adjacent-line floor per real residual degree of freedom:
#: a median of exponential variables has the efficiency ln(2)^2 of their mean, and
#: adjacent fourth differences are correlated (about a quarter as many independent)
_FLOOR_DOF = math.log(2.0) ** 2 / 4.0


@dataclass(frozen=True)
class NoiseTest:
    """Residual of a fit against the noise of its FRF (module docstring).

    Attributes
    ----------
    ratio : float
        ``q = sum |e|^2 / sum var(H)`` (1: only noise left).
    threshold : float
        Upper ``1 - alpha`` quantile of ``q`` when only noise is left.
    p_value : float
        Probability of a ``q`` at least this large from noise alone.
    relative_error : float
        ``sqrt(sum |e|^2 / sum |H|^2)``.
    noise_relative_error : float
        ``sqrt(sum var(H) / sum |H|^2)``: the relative error noise alone gives.
    dof : float
        Effective degrees of freedom of the residual.
    misfit_hz : (float, float) or None
        Lines holding the central 80 % of the excess residual, Hz; None when
        there is no excess.
    noise_from : str
        ``"coherence"`` (the FRF's coherence) or ``"adjacent lines"`` (the
        noise floor from second differences of adjacent lines, module
        docstring).
    correlation, correlation_z : float
        Correlation of the residual between adjacent lines and its ratio to
        the standard deviation white noise gives (NaN when not measured).
    """

    @property
    def structured(self) -> bool:
        """True when the residual is correlated across lines beyond what white noise
        gives (one-sided at the level ``ALPHA``): a misfit rather than noise."""
        return bool(self.correlation_z > -special.ndtri(ALPHA))

    ratio: float
    threshold: float
    p_value: float
    relative_error: float
    noise_relative_error: float
    dof: float
    misfit_hz: tuple[float, float] | None
    noise_from: str = "coherence"
    correlation: float = math.nan
    correlation_z: float = math.nan

    @property
    def passed(self) -> bool:
        """True when the residual is within the noise."""
        return bool(self.ratio <= self.threshold)


def frf_noise_variance(frf: FRF) -> tuple[NDArray[np.float64], float] | None:
    """Variance of each FRF value from the coherence, and the noise estimate's dof factor.

    Module docstring; uses ``frf.meta["n_averages"]`` and ``frf.meta["method"]``.

    Returns
    -------
    (ndarray, float) or None
        ``var`` of shape ``frf.H.shape`` (in the FRF's unit squared) and
        ``n_d - m`` for ``m`` inputs (``inf`` when the coherence is that of the estimate
        itself); None when the FRF has no coherence or no more averages than
        inputs.
    """
    if frf.coherence is None:
        return None
    nd = frf.meta.get("n_averages")
    g2 = np.clip(np.asarray(frf.coherence, dtype=float), 1e-12, 1.0)
    snr = (1.0 - g2) / g2  # (n_out, n_freq)
    n_in = frf.n_in
    if nd is None:
        scale, factor = 1.0, math.inf
    else:
        nd = int(nd)
        if nd <= n_in:  # coherence 1 by construction: no noise information
            return None
        factor = float(nd - n_in)
        # m inputs: mean inverse spectrum of random forces and coherence bias (docstring)
        scale = 1.0 / (nd - 1) if n_in == 1 else nd / (nd - n_in) ** 2
    # MIMO (multiple coherence per output): with uncorrelated inputs of equal power, the
    # noise of output o spreads evenly over its FRFs, var(H_oj) = (1 - g_o^2)/g_o^2 *
    # sum_j |H_oj|^2 / n_d, for every j; for one input this is the SISO formula
    power = np.sum(np.abs(frf.H) ** 2, axis=1, keepdims=True)
    var = np.broadcast_to(power * snr[:, None, :] * scale, frf.H.shape).copy()
    return var, factor


def noise_test(
    frequency: NDArray[np.float64],
    measured: NDArray[np.complex128],
    fitted: NDArray[np.complex128],
    variance: NDArray[np.float64],
    noise_dof_factor: float = math.inf,
    alpha: float = ALPHA,
) -> NoiseTest:
    """Test a fit's residual against the noise variance (module docstring).

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Hz.
    measured, fitted : ndarray, complex, shape (..., n_freq)
    variance : ndarray, shape (..., n_freq)
        Variance of each measured value.
    noise_dof_factor : float
        Degrees of freedom of the variance estimate per residual degree of
        freedom (``n_d - 1``; ``inf`` for a known variance).
    alpha : float
        Significance level.
    """
    f = np.asarray(frequency, dtype=float)
    h = np.asarray(measured, dtype=complex)
    m = np.asarray(fitted, dtype=complex)
    v = np.asarray(variance, dtype=float)
    if h.shape != m.shape or h.shape != v.shape or h.shape[-1] != f.size:
        raise ShapeError(
            f"measured, fitted, variance: expected equal shapes ending in {f.size} lines, got "
            f"{h.shape}, {m.shape}, {v.shape}"
        )
    if not 0 < alpha < 1:
        raise InputError(f"alpha: expected 0 < alpha < 1, got {alpha}")
    sums, excess = _sums(h, m, v)
    return _test_from_sums(f, sums, excess, noise_dof_factor, alpha)


def _sums(
    h: NDArray[Any], m: NDArray[Any], v: NDArray[Any]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The sums of :func:`noise_test` over some lines: ``sum |e|^2``, ``sum var``,
    ``sum |H|^2``, ``sum var^2``, and the excess ``(|e|^2 - var)+`` of each line
    summed over the FRFs, shape (n_lines,)."""
    e2 = np.abs(m - h) ** 2
    sums = np.array([e2.sum(), v.sum(), (np.abs(h) ** 2).sum(), (v**2).sum()])
    excess = np.clip(e2 - v, 0.0, None).reshape(-1, e2.shape[-1]).sum(axis=0)
    return sums, excess


def _test_from_sums(
    f: NDArray[np.float64],
    sums: NDArray[np.float64],
    excess: NDArray[np.float64],
    noise_dof_factor: float,
    alpha: float,
) -> NoiseTest:
    """:func:`noise_test` from the sums of :func:`_sums` over every line (module docstring)."""
    s_res, s_var, s_data, s_v2 = (float(x) for x in sums)
    if not (s_var > 0 and math.isfinite(s_var)):
        raise InputError("variance: expected a positive, finite noise variance")
    q = s_res / s_var
    nu = 2.0 * s_var**2 / s_v2
    if math.isinf(noise_dof_factor):
        thr = chi2_isf(alpha, nu) / nu
        p = chi2_sf(q * nu, nu)
    else:
        thr = f_isf(alpha, nu, noise_dof_factor * nu)
        p = f_sf(q, nu, noise_dof_factor * nu)
    return NoiseTest(
        ratio=q,
        threshold=thr,
        p_value=p,
        relative_error=math.sqrt(s_res / s_data) if s_data > 0 else math.nan,
        noise_relative_error=math.sqrt(s_var / s_data) if s_data > 0 else math.nan,
        dof=nu,
        misfit_hz=_misfit_region(f, excess),
    )


def _misfit_region(
    f: NDArray[np.float64], excess: NDArray[np.float64], block: int = 0
) -> tuple[float, float] | None:
    """Lines (Hz) holding the central ``_REGION`` of the excess residual per line
    (``excess``, shape (n_lines,), >= 0); None without excess. The cumulative sum
    is formed in blocks of ``block`` lines (0: :data:`BLOCK_LINES`), carried from
    block to block: the same additions in the same order as at once."""
    total = excess.sum()
    if not total > 0:
        return None
    n, step = f.size, block or BLOCK_LINES
    quantiles = ((1 - _REGION) / 2, 1 - (1 - _REGION) / 2)
    at = [n, n]
    carry = 0.0
    for a in range(0, n, step):
        c = np.cumsum(np.concatenate(([carry], excess[a : a + step])))[1:]
        carry = float(c[-1])
        c = c / total
        for j, qj in enumerate(quantiles):
            if at[j] == n and c[-1] >= qj:
                at[j] = a + int(np.searchsorted(c, qj))
        if max(at) < n:
            break
    return (float(f[min(at[0], n - 1)]), float(f[min(at[1], n - 1)]))


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def adjacent_line_variance(H: NDArray[np.complex128]) -> NDArray[np.float64]:
    """Noise variance of each FRF value from differences of adjacent lines.

    The running median over ``_FLOOR_LINES`` lines of ``|d|^2 / (70 ln 2)``,
    ``d`` the fourth difference of adjacent lines (second differences with fewer
    than 6 lines), for each FRF (module docstring): it follows noise that varies
    along the band and ignores the few lines where a sharp peak curves the FRF.

    Parameters
    ----------
    H : ndarray, complex, shape (..., n_freq)
        The FRFs, ``n_freq >= 3``.

    Returns
    -------
    ndarray, shape of ``H``
        Variance of each value (``H``'s unit squared); the end lines take that of
        their neighbours.
    """
    from scipy.ndimage import median_filter

    h = np.asarray(H, dtype=complex)
    n = h.shape[-1]
    c = _DIFF if n > len(_DIFF) else np.array([1.0, -2.0, 1.0])
    k = c.size
    if n < k:
        raise ShapeError(f"the FRF has {n} line(s): the noise floor needs at least 3")
    d = sum(c[j] * h[..., j : n - k + 1 + j] for j in range(k))
    a2 = (d.real**2 + d.imag**2) / (float(np.sum(c**2)) * math.log(2.0))
    size = [1] * (a2.ndim - 1) + [min(_FLOOR_LINES, a2.shape[-1])]
    med = median_filter(a2, size=size, mode="nearest")
    lo = (k - 1) // 2
    out = np.concatenate(
        [np.repeat(med[..., :1], lo, -1), med, np.repeat(med[..., -1:], k - 1 - lo, -1)], axis=-1
    )
    # a noise-free FRF (a simulation): the rounding of its values is the floor
    tiny = (1e-12 * np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))) ** 2
    return np.asarray(np.maximum(out, tiny + np.finfo(float).tiny))


def residual_correlation(
    residual: NDArray[np.complex128], variance: NDArray[np.float64]
) -> tuple[float, float]:
    """Correlation of a residual between adjacent lines, and its size against white noise.

    ``r = Re sum_f u_f conj(u_{f+1}) / sum_f |u_f|^2`` of the residual scaled by its
    noise, ``u = e / sqrt(var)``, over every FRF; white noise gives ``r`` about 0 with
    standard deviation ``1 / sqrt(2 N)`` over ``N`` pairs of lines.

    Returns
    -------
    (float, float)
        ``r`` and ``z = r sqrt(2 N)`` (NaN with fewer than 2 lines).
    """
    u = np.asarray(residual, dtype=complex) / np.sqrt(np.asarray(variance, dtype=float))
    u = u.reshape(-1, u.shape[-1])
    if u.shape[-1] < 2:
        return math.nan, math.nan
    num = float(np.sum((u[:, 1:] * np.conj(u[:, :-1])).real))
    den = float(np.sum(np.abs(u) ** 2))
    if not den > 0:
        return math.nan, math.nan
    r = num / den
    return r, r * math.sqrt(2.0 * u.shape[0] * (u.shape[-1] - 1))


def floor_test(
    frequency: NDArray[np.float64],
    measured: NDArray[np.complex128],
    fitted: NDArray[np.complex128],
    alpha: float = ALPHA,
) -> tuple[NoiseTest, NDArray[np.float64], list[str]]:
    """Test a fit without coherence against the noise floor of adjacent lines.

    The residual against :func:`adjacent_line_variance`, its correlation
    across lines (:func:`residual_correlation`) and its outlying lines
    (module docstring), on the data scaled to their largest value (the test
    is scale-free).

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Hz, adjacent lines.
    measured, fitted : ndarray, complex, shape (..., n_freq)
    alpha : float
        Significance level.

    Returns
    -------
    test : NoiseTest
        ``noise_from="adjacent lines"``; a white residual above the floor on no
        few lines passes (its threshold raised to its ratio) with a caution.
    excess : ndarray, shape of ``measured``
        ``|e|^2 - var`` of the scaled data.
    cautions : list of str
    """
    f = np.asarray(frequency, dtype=float)
    h0: NDArray[np.complex128] = np.asarray(measured, dtype=complex)
    big = float(np.max(np.abs(h0)))
    scale = big if math.isfinite(big) and big > 0 else 1.0
    h: NDArray[np.complex128] = h0 / scale
    e: NDArray[np.complex128] = (np.asarray(fitted, dtype=complex) - h0) / scale
    var = adjacent_line_variance(h)
    test = noise_test(f, h, h + e, var, _FLOOR_DOF, alpha)
    excess = np.abs(e) ** 2 - var
    r, z = residual_correlation(e, var)
    spikes = _outlying_lines(f, e, var, alpha)
    test, cautions = _floor_judgement(replace(test, noise_from="adjacent lines"), r, z, spikes)
    return test, excess, cautions


def _floor_judgement(
    test: NoiseTest, r: float, z: float, spikes: list[float]
) -> tuple[NoiseTest, list[str]]:
    """The test against the floor with the residual's correlation ``r``, ``z`` and
    its outlying lines ``spikes`` (Hz): a spike counts as structure, a white
    residual above the floor on no few lines passes with a caution (module docstring)."""
    test = replace(test, correlation=r, correlation_z=z)
    cautions: list[str] = []
    if spikes and not test.structured:
        # a mode sharper than the line spacing leaves a spike, not a correlation
        test = replace(test, correlation_z=math.inf)
        cautions.append(
            "the residual stands out of the noise floor at "
            + ", ".join(f"{x:.6g}" for x in spikes[:5])
            + " Hz"
            + (f" and {len(spikes) - 5} more line(s)" if len(spikes) > 5 else "")
        )
    if not test.passed and not test.structured:
        cautions.append(
            f"the residual is {math.sqrt(test.ratio):.3g}x the noise floor of adjacent "
            f"lines but white across lines (correlation of adjacent lines {r:.2f}, "
            f"{z:.2g} standard deviations of white noise) and on no few lines: noise "
            "larger than that floor rather than a misfit; judged within the noise"
        )
        test = replace(test, threshold=max(test.threshold, test.ratio))
    return test, cautions


def _outlying_lines(
    f: NDArray[np.float64],
    residual: NDArray[np.complex128],
    variance: NDArray[np.float64],
    alpha: float,
) -> list[float]:
    """Lines (Hz) where the residual stands out of the adjacent-line noise floor: its
    scaled power ``|e|^2 / var`` beyond the ``1 - alpha / N`` quantile of ``F(2, k)``
    over ``N`` values, ``k`` the floor's degrees of freedom over its running median."""
    u2 = (np.abs(residual) ** 2 / variance).reshape(-1, f.size)
    k = 2.0 * _FLOOR_DOF * _FLOOR_LINES
    limit = f_isf(alpha / u2.size, 2, k)
    return [float(x) for x in f[np.any(u2 > limit, axis=0)]]


# ------------------------------------------------------------------ in blocks of lines
#: Lines ``[a, b)`` of the FRFs (or of a fit, or of a variance), shape (..., b - a).
Lines = Callable[[int, int], NDArray[Any]]


def noise_test_blocks(
    frequency: NDArray[np.float64],
    lines: Callable[[int, int], tuple[NDArray[Any], NDArray[Any], NDArray[Any]]],
    noise_dof_factor: float = math.inf,
    alpha: float = ALPHA,
    block: int = BLOCK_LINES,
) -> tuple[NoiseTest, NDArray[np.float64]]:
    """:func:`noise_test` on ``block`` lines at a time.

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Hz.
    lines : callable
        ``lines(a, b)`` gives ``(measured, fitted, variance)`` of the lines of
        index ``a`` to ``b - 1``, each of shape (..., b - a), as :func:`noise_test`
        takes them.
    noise_dof_factor, alpha
        As :func:`noise_test`.
    block : int
        Lines per block.

    Returns
    -------
    test : NoiseTest
        The same test as :func:`noise_test` on every line at once (its sums
        taken block by block: equal to rounding).
    excess : ndarray, shape (n_freq,)
        ``(|e|^2 - var)+`` of each line summed over the FRFs.
    """
    f = np.asarray(frequency, dtype=float)
    if not 0 < alpha < 1:
        raise InputError(f"alpha: expected 0 < alpha < 1, got {alpha}")
    n, step = f.size, max(int(block), 1)
    sums = np.zeros(4)
    excess = np.empty(n)
    for a in range(0, n, step):
        b = min(a + step, n)
        h, m, v = (np.asarray(x) for x in lines(a, b))
        if h.shape != m.shape or h.shape != v.shape or h.shape[-1] != b - a:
            raise ShapeError(
                f"measured, fitted, variance: expected equal shapes ending in {b - a} lines, "
                f"got {h.shape}, {m.shape}, {v.shape}"
            )
        part, excess[a:b] = _sums(h, m, v)
        sums += part
    return _test_from_sums(f, sums, excess, noise_dof_factor, alpha), excess


def floor_test_blocks(
    frequency: NDArray[np.float64],
    measured: Lines,
    fitted: Lines,
    alpha: float = ALPHA,
    block: int = BLOCK_LINES,
) -> tuple[NoiseTest, NDArray[np.float64], list[str]]:
    """:func:`floor_test` on ``block`` lines at a time (module docstring).

    The noise floor of a block is the running median of its lines and of the
    lines of the median's window around them, so that it is that of
    :func:`adjacent_line_variance` on every line; the residual's correlation
    carries the last line of a block to the next.

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Hz, adjacent lines.
    measured, fitted : callable
        ``measured(a, b)``, ``fitted(a, b)``: the values of the lines of index
        ``a`` to ``b - 1``, complex, shape (..., b - a).
    alpha : float
        Significance level.
    block : int
        Lines per block.

    Returns
    -------
    test : NoiseTest
        As :func:`floor_test` (its sums taken block by block: equal to rounding).
    excess : ndarray, shape (n_freq,)
        ``(|e|^2 - var)+`` of each line of the scaled data summed over the FRFs
        (:func:`floor_test`'s ``excess`` clipped at 0 and summed over the FRFs).
    cautions : list of str
        As :func:`floor_test`.
    """
    f = np.asarray(frequency, dtype=float)
    if not 0 < alpha < 1:
        raise InputError(f"alpha: expected 0 < alpha < 1, got {alpha}")
    n, step = f.size, max(int(block), 1)
    spans = [(a, min(a + step, n)) for a in range(0, n, step)]
    big = float(np.max([np.max(np.abs(measured(a, b))) for a, b in spans]))
    scale = big if math.isfinite(big) and big > 0 else 1.0
    # the floor of a noise-free FRF: the mean power of each FRF (adjacent_line_variance)
    power = sum(
        np.sum(np.abs(np.asarray(measured(a, b), dtype=complex) / scale) ** 2, -1, keepdims=True)
        for a, b in spans
    )
    tiny = (1e-12 * np.sqrt(power / n)) ** 2 + np.finfo(float).tiny
    sums, corr = np.zeros(4), np.zeros(2)  # corr: sum Re u_f conj(u_f-1), sum |u|^2
    ex_test, excess = np.empty(n), np.empty(n)
    spikes: list[float] = []
    last: NDArray[np.complex128] | None = None
    rows = 0
    for a, b in spans:
        h0 = np.asarray(measured(a, b), dtype=complex)
        h = h0 / scale
        e = (np.asarray(fitted(a, b), dtype=complex) - h0) / scale
        var = _floor_lines(lambda i, j: np.asarray(measured(i, j), dtype=complex) / scale, n, a, b)
        var = np.maximum(var, tiny)
        part, ex_test[a:b] = _sums(h, h + e, var)
        sums += part
        excess[a:b] = np.clip(np.abs(e) ** 2 - var, 0.0, None).reshape(-1, b - a).sum(axis=0)
        u = (e / np.sqrt(var)).reshape(-1, b - a)
        rows = u.shape[0]
        w = u if last is None else np.concatenate([last, u], axis=-1)
        corr += (float(np.sum((w[:, 1:] * np.conj(w[:, :-1])).real)), float(np.sum(np.abs(u) ** 2)))
        last = u[:, -1:]
        spikes += _outlying_block(f[a:b], e, var, alpha / (rows * n))
    test = replace(
        _test_from_sums(f, sums, ex_test, _FLOOR_DOF, alpha), noise_from="adjacent lines"
    )
    r = z = math.nan
    if n >= 2 and corr[1] > 0:
        r = float(corr[0] / corr[1])
        z = r * math.sqrt(2.0 * rows * (n - 1))
    test, cautions = _floor_judgement(test, r, z, spikes)
    return test, excess, cautions


def _floor_lines(measured: Lines, n: int, a: int, b: int) -> NDArray[np.float64]:
    """:func:`adjacent_line_variance` of the lines ``[a, b)`` of ``n`` before its
    lower bound: the running median over the lines of the block and of its
    window around them (the median's ``nearest`` ends only at the ends of the
    lines), the same values as on every line at once. ``measured(i, j)``: the
    scaled FRFs of the lines ``[i, j)``."""
    from scipy.ndimage import median_filter

    c = _DIFF if n > len(_DIFF) else np.array([1.0, -2.0, 1.0])
    k = c.size
    if n < k:
        raise ShapeError(f"the FRF has {n} line(s): the noise floor needs at least 3")
    nd = n - k + 1  # fourth (second) differences
    size = min(_FLOOR_LINES, nd)
    lo = (k - 1) // 2
    m0 = min(max(a - lo, 0), nd - 1)
    m1 = min(max(b - 1 - lo, 0), nd - 1) + 1
    s0, s1 = max(m0 - size, 0), min(m1 + size, nd)
    h = measured(s0, s1 + k - 1)
    d = sum(c[j] * h[..., j : s1 - s0 + j] for j in range(k))
    a2 = (d.real**2 + d.imag**2) / (float(np.sum(c**2)) * math.log(2.0))
    med = median_filter(a2, size=[1] * (a2.ndim - 1) + [size], mode="nearest")
    at = np.clip(np.arange(a, b) - lo, 0, nd - 1) - s0
    return np.asarray(med[..., at])


def _outlying_block(
    f: NDArray[np.float64],
    residual: NDArray[np.complex128],
    variance: NDArray[np.float64],
    share: float,
) -> list[float]:
    """:func:`_outlying_lines` of some lines, ``share = alpha / N`` of every value."""
    u2 = (np.abs(residual) ** 2 / variance).reshape(-1, f.size)
    limit = f_isf(share, 2, 2.0 * _FLOOR_DOF * _FLOOR_LINES)
    return [float(x) for x in f[np.any(u2 > limit, axis=0)]]


def _fitted_span(frf: FRF, fitted: NDArray[np.float64], kind: str) -> slice | None:
    """The lines of ``frf`` that are the fitted lines ``fitted`` (Hz), as a slice, when
    they are a band of its lines, without the 0 Hz line that a conversion to ``kind``
    drops (:meth:`FRF.to`); None otherwise."""
    f = frf.frequency
    if fitted.size == 0:
        return None
    a = int(np.searchsorted(f, fitted[0]))
    b = a + fitted.size
    if b > f.size or not np.array_equal(f[a:b], fitted):
        return None
    if f[a] == 0.0 and KIND_POWER[kind] < KIND_POWER[frf.kind]:
        a += 1
    return slice(a, b) if b > a else None
