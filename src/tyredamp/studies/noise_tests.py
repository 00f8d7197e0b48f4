"""Tests of a fit's residual against the noise: from the coherence, or from the data alone.

The statistics behind the fit verdicts of :mod:`tyredamp.studies.verdicts`
(whose module docstring derives them): :func:`noise_test` judges the
residual against a per-line noise variance (the one the FRF's coherence
implies, :func:`frf_noise_variance`), and without coherence
:func:`floor_test` judges it against the noise floor the data themselves
show (:func:`adjacent_line_variance`: differences of adjacent lines, a
running median) and the structure of the residual across lines
(:func:`residual_correlation`, outlying lines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy import special

from ..exceptions import InputError, ShapeError
from ..frf import FRF
from ..modal.statistics.stats import chi2_isf, chi2_sf, f_isf, f_sf

__all__ = [
    "ALPHA",
    "NoiseTest",
    "adjacent_line_variance",
    "floor_test",
    "frf_noise_variance",
    "noise_test",
    "residual_correlation",
]

#: Significance level of the test against the noise.
ALPHA = 1e-3
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
    e2 = np.abs(m - h) ** 2
    s_res, s_var = float(e2.sum()), float(v.sum())
    s_data = float((np.abs(h) ** 2).sum())
    if not (s_var > 0 and math.isfinite(s_var)):
        raise InputError("variance: expected a positive, finite noise variance")
    q = s_res / s_var
    nu = 2.0 * s_var**2 / float((v**2).sum())
    if math.isinf(noise_dof_factor):
        thr = chi2_isf(alpha, nu) / nu
        p = chi2_sf(q * nu, nu)
    else:
        thr = f_isf(alpha, nu, noise_dof_factor * nu)
        p = f_sf(q, nu, noise_dof_factor * nu)
    excess = np.clip(e2 - v, 0.0, None).reshape(-1, f.size).sum(axis=0)
    region = None
    if excess.sum() > 0:
        c = np.cumsum(excess) / excess.sum()
        lo = int(np.searchsorted(c, (1 - _REGION) / 2))
        hi = min(int(np.searchsorted(c, 1 - (1 - _REGION) / 2)), f.size - 1)
        region = (float(f[lo]), float(f[hi]))
    return NoiseTest(
        ratio=q,
        threshold=thr,
        p_value=p,
        relative_error=math.sqrt(s_res / s_data) if s_data > 0 else math.nan,
        noise_relative_error=math.sqrt(s_var / s_data) if s_data > 0 else math.nan,
        dof=nu,
        misfit_hz=region,
    )


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
    test = replace(test, noise_from="adjacent lines", correlation=r, correlation_z=z)
    cautions: list[str] = []
    spikes = _outlying_lines(f, e, var, alpha)
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
    return test, excess, cautions


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
