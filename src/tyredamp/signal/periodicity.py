"""What kind of excitation a record holds, detected from the signals themselves.

Time data written by other programs rarely say that the excitation was
periodic, nor with which period. :func:`detect_excitation` decides it from the
force (and, for the start transient, from every channel), so that the FRF
estimator can use cyclic averaging over whole periods (leakage free) instead
of a windowed Welch average.

Method
------
1. **Candidate periods** from the repetition error of the force signals
   ``x`` (means removed, channels summed)::

       e(k) = sum_t (x[t + k] - x[t])^2 / sum_t (x[t]^2 + x[t + k]^2),
       t = 0 .. N - k - 1,

   computed for every lag ``k`` at once from the FFT autocorrelation
   (``e(k) = 1 - rho(k)`` with the normalised autocorrelation ``rho``). A
   signal with period ``P`` has ``e(P) = 0`` plus its noise share. Lags within
   the main lobe (before the autocorrelation first crosses zero) are skipped,
   because a smooth, oversampled signal repeats itself trivially at small
   lags. The deepest local minima of ``e`` over ``k <= N / 3`` (at least three
   periods) are the candidates; every divisor of a candidate is tried in
   increasing order, so the fundamental (smallest) period is found, not a
   multiple. The period is an integer number of samples by construction: a
   signal whose period is not a whole number of samples (a sine of 441.5
   samples) is periodic with the smallest whole multiple (883 samples).
2. **Verification against the noise** (per candidate ``P``): the record is
   cut into ``M = floor(N / P)`` periods (aligned at its end, away from a
   start transient) with spectra ``X_m(k)`` on the DFT lines of one period.
   With ``Xbar`` the period mean and ``s^2(k) = sum_m |X_m - Xbar|^2 / (M - 1)``
   the period-to-period variance, the ratio::

       F = sum_k M |Xbar(k)|^2 / sum_k s^2(k)

   is, for a stationary random signal without periodic part, approximately
   F-distributed with ``(nu, nu (M - 1))`` degrees of freedom, ``nu`` the
   Satterthwaite number ``2 (sum S)^2 / sum S^2`` of the line powers ``S``
   (two per complex line when the power is spread, few when it sits on few
   lines). ``P`` is accepted when the upper tail probability of ``F``
   is below ``alpha / n_lags`` (``alpha = 1e-4``, Bonferroni over every lag
   searched) and the periodic part carries most of the force power,
   ``phi = (sum |Xbar|^2 - sum s^2 / M) / mean_m sum |X_m|^2 > 1/2`` (an
   unbiased estimate; with a smaller periodic share cyclic averaging would
   throw most of the excitation away). The F ratio assumes independent
   periods, which a narrow-band random signal with a correlation time longer
   than ``P`` violates (neighbouring periods alike): the period-to-period
   variance is multiplied by the batch-means inflation
   ``tau = 1 + 2 sum_j (1 - j/M) rho_j`` of the residuals' serial
   correlation (and the denominator degrees of freedom divided by it), so
   such a signal is not significant, while a periodic force with slow drift
   (large ``tau`` but a tiny residual) still is.
   Finally, the candidate ``k`` whose divisor ``P`` is tried must not
   fit significantly better (nested F test on the lines of the ``k``-period
   that a ``P``-periodic signal leaves empty), so a period is never a
   fraction of the true one.
3. **Start transient** (every channel, periods aligned at the start): the
   later half of the periods gives the steady-state period ``m(t)`` and the
   noise variance ``sigma^2`` of each channel (floored at ``(1e-9 rms)^2``,
   the storage precision of 12-digit text files and below single precision).
   Period ``j`` is steady when, in every channel, ``T_j = sum_t (x_j(t) -
   m(t))^2 / (sigma^2 (1 + 1/R))`` (``R`` reference periods), scaled to
   ``nu / P``, stays below ``nu`` times the ``F(nu, nu (R - 1))`` quantile
   (``sigma^2`` is estimated from the ``R`` reference periods; the
   ``chi^2_nu`` quantile when ``sigma^2`` is the storage floor) at level
   ``alpha / (M n_channels)`` (Bonferroni: channels share noise through the
   structure); ``nu`` is the Satterthwaite number of degrees of freedom of
   the residual's line powers (``P`` for white noise, fewer for coloured
   noise). The leading periods up to the last one that is not steady are
   skipped (``settle_samples``), keeping at least two periods.
4. **Not periodic**: impact data if the force has samples beyond what a
   Gaussian signal of its robust scale (``1.4826`` times the median absolute
   deviation) reaches in ``N`` samples at level ``alpha`` (hammer hits, and
   bursts of random noise separated by silence). Exceedances closer than
   half the length of the run before them are one hit; a hit starts where
   its force rises above three robust scales; the record is cut at the hit
   starts into transient records (rectangular window). Otherwise random
   (Welch averaging).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError, ShapeError

__all__ = [
    "ExcitationDetection",
    "detect_excitation",
    "repetition_error",
    "transient_periods",
]

ExcitationKind = Literal["periodic", "random", "impact"]
#: Family-wise false-alarm level of every test in this module.
ALPHA = 1e-4
#: Relative noise floor of stored samples (12-digit text, float64 binary).
_STORAGE_FLOOR = 1e-9
_N_CANDIDATES = 6


@dataclass(frozen=True)
class ExcitationDetection:
    """What :func:`detect_excitation` found and why.

    Attributes
    ----------
    kind : {"periodic", "random", "impact"}
    period_samples : int or None
        Period in samples (periodic only).
    settle_samples : int
        Leading samples holding a start transient (whole periods; periodic only).
    n_periods : int
        Whole steady periods after the settle samples (periodic only, else 0).
    periodic_fraction : float
        Share of the force power in its periodic part at the best period
        (``phi``; about 0 for random data).
    f_statistic : float
        Period-mean to period-spread ratio ``F`` at the best period (inf for
        noise-free periodic data).
    p_value : float
        Upper tail probability of ``F`` under "no periodic component".
    record_starts : tuple of int
        First sample of each transient record (impact only).
    record_samples : int or None
        Length of the transient records (impact only).
    reason : str
        One sentence that says what was decided and why.
    """

    kind: ExcitationKind
    period_samples: int | None = None
    settle_samples: int = 0
    n_periods: int = 0
    periodic_fraction: float = 0.0
    f_statistic: float = 0.0
    p_value: float = 1.0
    record_starts: tuple[int, ...] = ()
    record_samples: int | None = None
    reason: str = field(default="")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite floats as strings, tuples as lists)."""
        out = asdict(self)
        out["record_starts"] = list(self.record_starts)
        for k in ("periodic_fraction", "f_statistic", "p_value"):
            v = float(out[k])
            out[k] = v if np.isfinite(v) else repr(v)
        return out


def repetition_error(x: ArrayLike, max_lag: int) -> NDArray[np.float64]:
    """Normalised repetition error ``e(k)`` for ``k = 0 .. max_lag`` (module docstring).

    Parameters
    ----------
    x : array_like, shape (n_channels, n_samples) or (n_samples,)
        Signals (their means should be removed).
    max_lag : int
        Largest lag, ``< n_samples``.

    Returns
    -------
    ndarray, shape (max_lag + 1,)
        ``e(k)`` in [0, 2]; 0 for a lag at which every channel repeats exactly.
    """
    a = as_finite(x, "x")
    a = a[None, :] if a.ndim == 1 else a
    n = a.shape[1]
    if not 0 < max_lag < n:
        raise InputError(f"max_lag: expected 1..{n - 1}, got {max_lag}")
    nfft = scipy.fft.next_fast_len(2 * n)
    spec = scipy.fft.rfft(a, nfft, axis=1)
    r = scipy.fft.irfft(np.sum(np.abs(spec) ** 2, axis=0), nfft)[: max_lag + 1]
    c = np.concatenate([[0.0], np.cumsum(np.sum(a * a, axis=0))])  # c[i] = sum_{t<i} x^2
    k = np.arange(max_lag + 1)
    head = c[n - k]  # sum_{t < n - k} x[t]^2
    tail = c[n] - c[k]  # sum_{t >= k} x[t]^2
    den = head + tail
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(den > 0, 1.0 - 2.0 * r / np.where(den > 0, den, 1.0), 1.0)
    return np.clip(e, 0.0, 2.0)


def _periods(x: NDArray[np.float64], p: int, align_end: bool) -> NDArray[np.float64]:
    """Whole periods of ``x`` (n_ch, n) as (n_ch, M, p)."""
    m = x.shape[1] // p
    start = x.shape[1] - m * p if align_end else 0
    return x[:, start : start + m * p].reshape(x.shape[0], m, p)


def _periodic_test(x: NDArray[np.float64], p: int) -> tuple[float, float, float, float]:
    """(phi, F, p-value, tau) of period ``p`` for the forces ``x`` (module step 2)."""
    import scipy.stats  # lazy (scipy.stats is slow to import)

    xp = _periods(x, p, align_end=True)
    m = xp.shape[1]
    spec = scipy.fft.rfft(xp, axis=2)[:, :, 1:]  # DC excluded (means removed)
    if p % 2 == 0:
        spec[:, :, -1] /= np.sqrt(2.0)  # the Nyquist line is real: half the degrees of freedom
    mean = spec.mean(axis=1)
    pm = np.abs(mean) ** 2  # (n_ch, L)
    resid = spec - mean[:, None, :]
    s2 = np.sum(np.abs(resid) ** 2, axis=1) / (m - 1)
    total = np.mean(np.sum(np.abs(spec) ** 2, axis=2), axis=1).sum()
    if total <= 0:
        return 0.0, 0.0, 1.0, 1.0
    phi = float((pm.sum() - s2.sum() / m) / total)
    line_power = np.mean(np.abs(spec) ** 2, axis=1).ravel()
    nu = 2.0 * line_power.sum() ** 2 / max(float(np.sum(line_power**2)), 1e-300)
    tau = _inflation(resid, total * m)
    den = float(s2.sum()) * tau
    num = float(m * pm.sum())
    if den <= 1e-30 * num:
        return phi, float("inf"), 0.0, tau
    f = num / den
    pval = float(scipy.stats.f.sf(f, nu, nu * (m - 1) / tau))
    return phi, f, pval, tau


def _inflation(resid: NDArray[np.complex128], energy: float) -> float:
    """Variance inflation ``tau`` of the period mean from serially correlated residuals.

    ``Var(Xbar) = s^2 / M * tau`` with ``tau = 1 + 2 sum_j (1 - j/M) rho_j``
    (the batch-means correction; 1 for independent periods), ``rho_j`` the
    lag-``j`` correlation of the residuals across periods pooled over lines
    and channels, summed while positive (Geyer's initial positive sequence).
    A narrow-band random signal, whose neighbouring periods are alike, gets a
    large ``tau``; so does slow drift, whose share is small beside a periodic
    force. Residuals at the storage floor (noise-free data) give 1.
    """
    m = resid.shape[1]
    r0 = float(np.sum(np.abs(resid) ** 2))
    if m < 3 or r0 <= (_STORAGE_FLOOR**2) * energy:
        return 1.0
    tau = 1.0
    for j in range(1, m - 1):
        rho = float(np.real(np.sum(resid[:, j:] * np.conj(resid[:, :-j])))) / r0
        rho += 1.0 / m  # the mean removed from M values biases every rho_j by -1/M
        if rho <= 0:
            break
        tau += 2.0 * (1.0 - j / m) * rho
    return max(tau, 1.0)


def _multiple_fits_better(x: NDArray[np.float64], d: int, k: int, level: float) -> bool:
    """True when period ``k`` (a multiple of ``d``) explains the forces significantly better.

    Nested models: with period ``k = q d`` the DFT lines of one ``k``-period
    that are not multiples of ``q`` hold what a ``d``-periodic signal cannot;
    under "period ``d``" their period means are noise, so
    ``F = sum M |Xbar|^2 / sum s^2`` over those lines is F-distributed with
    ``(nu, nu (M - 1))`` degrees of freedom (``nu`` the Satterthwaite number
    of their noise powers). Significant at ``level``: ``d`` is not the period.
    Means below the storage floor of the signal power count as zero.
    """
    import scipy.stats  # lazy (scipy.stats is slow to import)

    q = k // d
    if q < 2:
        return False
    xp = _periods(x, k, align_end=True)
    m = xp.shape[1]
    spec = scipy.fft.rfft(xp, axis=2)
    lines = np.arange(spec.shape[2])
    extra = lines % q != 0
    if not np.any(extra):
        return False
    se = spec[:, :, extra]
    mean = se.mean(axis=1)
    num = float(m * np.sum(np.abs(mean) ** 2))
    s2 = np.sum(np.abs(se - mean[:, None, :]) ** 2, axis=1) / (m - 1)
    total = float(np.mean(np.sum(np.abs(spec[:, :, 1:]) ** 2, axis=2), axis=1).sum())
    if num <= (_STORAGE_FLOOR**2) * total * m:
        return False
    den = float(s2.sum())
    if den <= 1e-30 * num:
        return True
    nu = 2.0 * den**2 / max(float(np.sum(s2**2)), 1e-300)
    return bool(scipy.stats.f.sf(num / den, nu, nu * (m - 1)) < level)


def _divisors(k: int) -> list[int]:
    small = [d for d in range(1, int(np.sqrt(k)) + 1) if k % d == 0]
    return sorted(set(small + [k // d for d in small]))


def transient_periods(signals: ArrayLike, period_samples: int, alpha: float = ALPHA) -> int:
    """Leading whole periods that differ from the steady state beyond the noise (step 3).

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples)
        Every channel of a periodic test (forces and responses).
    period_samples : int
        The period in samples (at least two whole periods in the record).
    alpha : float
        False-alarm probability of the test over all periods.

    Returns
    -------
    int
        Number of leading periods to skip (at most ``M - 2`` of ``M``).
    """
    import scipy.stats  # lazy (scipy.stats is slow to import)

    y = as_finite(signals, "signals")
    y = y[None, :] if y.ndim == 1 else y
    p = int(period_samples)
    if y.ndim != 2 or p < 2 or y.shape[1] < 2 * p:
        raise InputError(
            f"period_samples: expected at least two whole periods of {period_samples!r} "
            f"samples in signals of shape {y.shape}"
        )
    yp = _periods(y, p, align_end=False)  # (n_ch, M, p)
    n_ch, m, _ = yp.shape
    rms = np.sqrt(np.mean(y * y, axis=1))
    floor = (_STORAGE_FLOOR * rms) ** 2
    s = 0
    for _ in range(m):
        ref = yp[:, s + (m - s) // 2 :, :]
        r = ref.shape[1]
        mean = ref.mean(axis=1)
        resid = ref - mean[:, None, :]
        var = np.sum(resid**2, axis=(1, 2)) / ((r - 1) * p) if r > 1 else np.zeros(n_ch)
        # degrees of freedom of a period's sum of squares: p for white noise, fewer for
        # coloured noise (Satterthwaite from the residual's line powers)
        nu = np.full(n_ch, float(p))
        if r > 1:
            line = np.sum(np.abs(np.fft.fft(resid, axis=2)) ** 2, axis=1)  # (n_ch, p)
            ok = var > floor
            nu[ok] = line[ok].sum(axis=1) ** 2 / np.sum(line[ok] ** 2, axis=1)
        var = np.maximum(var, floor)
        var = np.where(var > 0, var, 1.0)
        lead = yp[:, : s + (m - s) // 2, :]
        # per channel (channels share noise through the structure: Bonferroni over them)
        t = np.sum((lead - mean[:, None, :]) ** 2, axis=2) / (var[:, None] * (1.0 + 1.0 / r))
        t = t * (nu / p)[:, None]  # ~ chi^2 with nu degrees of freedom
        level = alpha / (m * n_ch)
        # with sigma^2 estimated from R - 1 periods, T / nu is F(nu, nu (R - 1))
        # distributed; at the storage floor sigma^2 is known: chi^2
        estimated = (var > floor) & (r > 1)
        limit = np.where(
            estimated,
            nu * scipy.stats.f.isf(level, nu, nu * max(r - 1, 1)),
            scipy.stats.chi2.isf(level, nu),
        )[:, None]
        bad = np.flatnonzero(np.any(t > limit, axis=0))
        new = min(int(bad[-1]) + 1 if bad.size else 0, m - 2)
        if new <= s:
            break
        s = new
    return s


def _impact_records(x: NDArray[np.float64], alpha: float) -> tuple[int, ...] | None:
    """Starts of the hits when the force is impulsive (step 4), else None."""
    import scipy.special

    n = x.shape[1]
    dev = np.abs(x - np.median(x, axis=1, keepdims=True))
    scale = 1.4826 * np.median(dev, axis=1)
    # Gaussian level exceeded by one of n samples with probability alpha (two-sided)
    z = float(scipy.special.ndtri(1.0 - alpha / (2.0 * n)))
    hit = np.any(dev > z * scale[:, None], axis=0)
    if not np.any(hit):
        return None
    idx = np.flatnonzero(hit)
    gaps = np.flatnonzero(np.diff(idx) > 1)
    run_starts = np.concatenate([[idx[0]], idx[gaps + 1]])
    run_ends = np.concatenate([idx[gaps], [idx[-1]]])
    # a quiet gap shorter than half the exceedance run before it belongs to the same hit
    merged: list[list[int]] = [[int(run_starts[0]), int(run_ends[0])]]
    for a, b in zip(run_starts[1:], run_ends[1:], strict=True):
        last = merged[-1]
        if a - last[1] <= max(2, (last[1] - last[0] + 1) // 2):
            last[1] = int(b)
        else:
            merged.append([int(a), int(b)])
    # each hit starts where its signal rises out of the noise (3 robust scales)
    active = np.any(dev > 3.0 * scale[:, None], axis=0)
    starts = []
    prev_end = -1
    for a, b in merged:
        j = a
        while j - 1 > prev_end and active[j - 1]:
            j -= 1
        starts.append(max(j, prev_end + 1, 0))
        prev_end = b
    return tuple(starts)


def detect_excitation(
    forces: ArrayLike,
    responses: ArrayLike | None = None,
    *,
    alpha: float = ALPHA,
    min_periods: int = 3,
) -> ExcitationDetection:
    """Decide from the signals whether the excitation is periodic, random or impact.

    Parameters
    ----------
    forces : array_like, shape (n_in, n_samples) or (n_samples,)
        Force signals (any unit).
    responses : array_like, shape (n_out, n_samples), optional
        Response signals, used with the forces to find a start transient.
    alpha : float
        Family-wise false-alarm probability of each test, in (0, 0.5).
    min_periods : int
        Fewest whole periods in the record for a periodic verdict (>= 3; two
        repetitions cannot tell a periodic signal from two similar hits).

    Returns
    -------
    ExcitationDetection
        The verdict with its figures and a one-sentence reason.
    """

    x = as_finite(forces, "forces")
    x = x[None, :] if x.ndim == 1 else x
    if x.ndim != 2:
        raise ShapeError(f"forces: expected shape (n_in, n_samples), got {x.shape}")
    n = x.shape[1]
    if not 0.0 < float(alpha) < 0.5:
        raise InputError(f"alpha: expected a probability in (0, 0.5), got {alpha!r}")
    if isinstance(min_periods, bool) or not isinstance(min_periods, int) or min_periods < 3:
        raise InputError(f"min_periods: expected an integer >= 3, got {min_periods!r}")
    y = x
    if responses is not None:
        r = as_finite(responses, "responses")
        r = r[None, :] if r.ndim == 1 else r
        if r.ndim != 2 or r.shape[1] != n:
            raise ShapeError(f"responses: expected shape (n_out, {n}), got {r.shape}")
        y = np.vstack([x, r])
    xc = x - x.mean(axis=1, keepdims=True)
    best = (0.0, 0.0, 1.0, 0)  # phi, F, p, period
    max_lag = n // min_periods
    if max_lag >= 2 and np.any(xc):
        e = repetition_error(xc, max_lag)
        below = np.flatnonzero(e[1:] >= 1.0)
        k0 = int(below[0]) + 1 if below.size else max_lag + 1
        cands = _candidates(e, k0, max_lag)
        n_lags = max(1, max_lag - k0 + 1)
        level = float(alpha) / n_lags
        tried: set[int] = set()
        for k in cands:
            for d in _divisors(k):
                if d < max(k0, 2) or d in tried:
                    continue
                tried.add(d)
                if e[d] > 0.75:  # repetition error alone rules out phi > 1/2
                    continue
                phi, f, pval, tau = _periodic_test(xc, d)
                if phi > best[0]:
                    best = (phi, f, pval, d)
                if pval < level and phi > 0.5 and not _multiple_fits_better(xc, d, k, level):
                    settle = transient_periods(y, d, float(alpha)) * d
                    m = (n - settle) // d
                    why = (
                        f"periodic: the force repeats every {d} samples ({m} whole periods"
                        + (f" after a {settle}-sample start transient" if settle else "")
                        + f"); periodic share of the force power {phi:.4f}, period-mean to "
                        f"spread ratio F = {f:.3g} (p = {pval:.2g} < {level:.2g}"
                        + (f"; serial correlation inflation {tau:.3g}" if tau > 1 else "")
                        + ")"
                    )
                    return ExcitationDetection("periodic", d, settle, m, phi, f, pval, reason=why)
    phi, f, pval, d = best
    near = f" (closest period {d} samples: periodic share {phi:.3f})" if d else ""
    hits = _impact_records(xc, float(alpha))
    if hits is not None:
        ends = [*hits[1:], n]
        rec = int(min(b - a for a, b in zip(hits, ends, strict=True)))
        why = (
            f"impact (or burst): {len(hits)} hit(s) beyond the Gaussian level of the "
            f"force's robust scale; transient records of {rec} samples from each hit; not "
            f"periodic{near}"
        )
        return ExcitationDetection(
            "impact", None, 0, 0, phi, f, pval, hits, rec if rec >= 2 else None, why
        )
    why = f"random: no period repeats the force within its noise{near}"
    return ExcitationDetection("random", None, 0, 0, phi, f, pval, reason=why)


def _candidates(e: NDArray[np.float64], k0: int, max_lag: int) -> list[int]:
    """The deepest local minima of ``e`` in ``k0 .. max_lag`` (at most a few)."""
    if k0 > max_lag:
        return []
    seg = e[k0 : max_lag + 1]
    order = np.argsort(seg, kind="stable")
    out: list[int] = []
    for i in order:
        k = int(i) + k0
        if all(abs(k - c) > 2 for c in out):
            out.append(k)
        if len(out) >= _N_CANDIDATES:
            break
    return out
