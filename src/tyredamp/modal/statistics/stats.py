"""Statistics that decide the mode count and judge a fit against the noise.

Mode test (:func:`mode_threshold`). Adding a mode to a model adds ``k``
parameters (complex modes: ``2 n_out`` residue coefficients, 2 for the pole
and ``2 (n_in - 1)`` for the participation; real modes ``n_out + 2 + (n_in -
1)``). With Gaussian noise of known variance the drop of the weighted cost
(negative log-likelihood times two) when the mode is added, ``T = (S_0 -
S_1) / s^2``, is chi-square with ``k`` degrees of freedom when the mode is
not there (Wilks 1938; with ``s^2`` estimated from ``n_obs - n_par``
residual degrees of freedom, ``T / k`` is ``F(k, n_obs - n_par)``, Seber &
Lee 2003, sec. 4.3). The pole of a mode that is not there is not defined,
so the largest ``T`` over the positions a search tries exceeds the
chi-square quantile more often than its level; the test therefore uses a
Bonferroni bound over the ``n_freq`` lines of the band (each line one
position where a candidate could sit): a mode is kept when ``T >
chi2_k^-1(1 - alpha / n_freq)``, so that a fit of pure noise keeps a noise
mode with probability at most ``alpha`` (the false-alarm rate, default 1 %).
With several inputs the residue of a complex mode is rank one, ``psi l^T``:
at a given pole the best one takes the largest squared singular value of the
noise's ``n_out x n_in`` block, ``T_0 = 2 lambda_max(Z^H Z)``, whose law
(Khatri 1964, :func:`rank_one_sf`) has a heavier tail than the chi-square of
its ``2 (n_out + n_in - 1)`` parameters (the factors are not identified when
the residue is zero, so Wilks' count does not hold): at ``1e-5`` the quantile
is 4.5 units beyond it for 4 outputs and 3 inputs, 10 for 8 and 4. The law of
``T`` is then taken as ``T_0 + B``, ``B ~ chi2_2`` the pole's share
(:func:`mode_null_sf`; exactly ``chi2_k`` with one input), and the threshold
as its quantile (:func:`mode_null_isf`); the corrections for estimated line
weights below scale with it. A real mode's residue is ``u l^T`` with real
``u`` and ``l`` on one complex column: ``T_0 = lambda_max(Z^T Z)`` with ``Z``
real, the largest eigenvalue of a real Wishart matrix (Chiani 2017,
``kind="real"``).
The threshold depends neither on the noise level nor on the scale of the
data; ``T`` is measured in units of the noise. ``T`` is divided by the
residual variance of the weighted fit itself (``s^2 = cost / dof`` over
every line, :class:`~tyredamp.modal.fit.fit.ModalFitter`), not by the per-line
variance estimates, so the inflation ``nu / (nu - 2)`` of the goodness of fit
(below) cancels to first order. What is left comes from the line weights
``w_f = 1 / g^_f`` being estimates (``nu_w`` degrees of freedom: ``nu n_out``,
the separable line factor averages the independent residual powers of the
outputs, :mod:`tyredamp.modal.problem.problem`): with ``b_f = g_f / g^_f`` the
projection onto a mode's weighted columns explains ``sum b_f^2 a_f / sum b_f
a_f`` noise units (``a_f`` the mode's share of line ``f``), between ``E b =
nu_w / (nu_w - 2)`` (one line) and ``E b^2 / E b = nu_w / (nu_w - 4)`` (many
lines), while ``s^2`` holds ``E b``. ``T`` is thus inflated by at most
``(nu_w - 2) / (nu_w - 4)`` (1.25 for 4 averages and 2 outputs, 1.08 for 8),
and the threshold is scaled by that bound when the weights are estimated
(``weight_dof``; 2 at most, its value at ``nu_w = 6``, where the bound
diverges). That bounds the mean; the tail of a mode whose few lines share
one estimated factor is that of ``k F(k, nu_w)``, and the threshold is the
larger of the two (:func:`mode_threshold`). ``nu_w`` is ``nu n_out`` for
outputs with independent noise, fewer when the noise is common to the
outputs (an H1 estimate's input noise): measured from the scatter of the
line factor between adjacent lines
(:func:`~tyredamp.modal.problem.problem.line_factor_dof`). Noise common to the
outputs also concentrates along the response, where a mode's shape lies; the
search raises each mode's threshold by what the residual shows there
(:func:`span_threshold`, :mod:`tyredamp.modal.search.span_noise`).

Goodness of fit (:func:`goodness_of_fit`): the weighted cost of the final
fit against its chi-square expectation ``n_obs - n_par`` when the noise is
known (given variance or coherence); otherwise against the noise estimated
from the second differences of adjacent lines (:func:`difference_noise`),
which a smooth FRF barely contains. The verdict is "the model explains the
data to the noise" when the upper tail probability of the cost is at least
the false-alarm rate.

Estimated variance. When the per-line variance ``V^_k`` is itself estimated
with ``nu`` real degrees of freedom (H1 from ``n`` independent averages and
``n_in`` inputs: the least-squares residual of ``Y_m = H X_m + E_m`` over the
averages has ``n - n_in`` complex, ``nu = 2 (n - n_in)`` real degrees of
freedom and is independent of ``H^``, Seber & Lee 2003, thm. 3.5), a term is
``2 |e_k|^2 / V^_k = (2 |e_k|^2 / V_k) / (V^_k / V_k) = chi2_2 / (chi2_nu / nu)
= 2 F(2, nu)``, with mean ``2 nu / (nu - 2)`` and variance
``4 nu^3 / ((nu - 2)^2 (nu - 4))`` (``nu > 4``): the cost of a correct model
is ``nu / (nu - 2)`` times its chi-square expectation (1.5 for 4 averages of
one input) and has a heavier tail. The cost, a sum of ``dof / 2`` such
complex terms, is then tested against the scaled chi-square ``c chi2_d`` of
the same mean and variance (Satterthwaite 1946; Box 1954):
``mean = dof nu / (nu - 2)``, ``var = 2 dof nu^3 / ((nu - 2)^2 (nu - 4))``,
``c = var / (2 mean)``, ``d = 2 mean^2 / var``; it tends to ``chi2_dof`` as
``nu -> inf``. With ``nu <= 4`` the variance of a term is infinite and the
test is not defined (the caller falls back to the difference noise).

Noise from second differences. Without a measured variance the cost is
formed against each FRF's noise from the median of its second differences
(:func:`difference_noise`), estimated from the very lines the cost sums: its
error does not average out against the cost's, and it is of the same order.
Per FRF of ``n`` lines and unit noise, with ``Y_f = |d_f|^2 / 6`` (unit
exponential) and ``m = ln 2`` its median, the estimate is ``1 + delta`` with
``n delta = sum_f psi(Y_f) / m``, ``psi(y) = 1 - 2 [y <= m]`` (Bahadur 1966:
the sample median's linear term, ``1 / (2 f(m))`` with the density ``f(m) =
1/2``), so that the FRF's cost ``2 S / (1 + delta)``, ``S = sum_f |e_f|^2``,
is ``2 n + 2 sum_f Z_f`` to first order with ``Z_f = (|e_f|^2 - 1) - psi(Y_f)
/ m``. Its variance over the chi-square's ``4 n`` is the inflation::

    kappa = sum_h Cov(Z_0, Z_h) = 1 - 2 + 4 (g_0 + 2 g_1 + 2 g_2) / m^2     (GoF-1)

* ``1``: the chi-square's own ``Var |e|^2``;
* ``-2``: the cost and the estimate share the noise. ``e_0`` is in ``d_-1, d_0,
  d_1`` with weights ``1, -2, 1``, i.e. complex correlation ``a / sqrt 6``; for
  two unit exponentials of complex Gaussians with ``|rho|^2 = r``, ``E[X | Y =
  y] = 1 - r + r y`` gives ``Cov(X, [Y <= m]) = -r m / 2``, and the three
  ``r = 1/6, 4/6, 1/6`` sum to 1: ``-2 sum_h Cov(|e_0|^2, psi(Y_h)) / m = -2``;
* ``g_h = P(Y_0 <= m, Y_h <= m) - 1/4`` (``g_0 = 1/4``): adjacent second
  differences are correlated (``rho = -2/3`` at lag 1, ``1/6`` at lag 2, none
  beyond), ``P`` the distribution of Kibble's bivariate exponential
  (Kibble 1941): ``(1 - r) sum_k r^k P(k + 1, m / (1 - r))^2`` with ``P`` the
  regularised lower incomplete gamma function and ``r = |rho|^2``.

``kappa = 2.2246`` (:data:`DIFFERENCE_INFLATION`). The cost of a correct model
against the difference noise has the chi-square's mean and ``kappa`` times its
variance, whatever the number of FRFs and lines; it is tested against the
scaled chi-square ``kappa chi2_{dof / kappa}`` of that mean and variance
(Satterthwaite 1946). Tested as if the noise were known, a correct model
failed at the 1 % level about 6 % of the time (``2.33 / sqrt 2.22`` standard
deviations), and the fit was judged to leave structure.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import special as sps_special

__all__ = [
    "DIFFERENCE_INFLATION",
    "GoodnessOfFit",
    "chi2_isf",
    "chi2_isf_each",
    "chi2_sf",
    "cost_reference",
    "difference_noise",
    "f_isf",
    "f_sf",
    "goodness_of_fit",
    "mode_null_isf",
    "mode_null_sf",
    "mode_parameters",
    "mode_threshold",
    "rank_one_available",
    "rank_one_sf",
    "span_threshold",
    "weight_factor",
]

#: default false-alarm rate of the mode test and of the goodness-of-fit test
FALSE_ALARM = 0.01
#: ``kappa`` of eq. (GoF-1) (module docstring): the variance of the cost of a correct
#: model against each FRF's noise from the median of its second differences
#: (:func:`difference_noise`), over that of ``chi2_dof``
DIFFERENCE_INFLATION = 2.2245545646384453
#: lines per block of :func:`difference_noise`
_DIFF_BLOCK = 16384


def chi2_sf(x: float, df: float) -> float:
    """``P(chi2_df > x)``: the regularised upper incomplete gamma function
    ``Q(df / 2, x / 2)`` (:func:`scipy.special.chdtrc`; the special functions
    behind ``scipy.stats.chi2``, without importing ``scipy.stats``)."""
    return float(sps_special.chdtrc(df, x))


def chi2_isf(q: float, df: float) -> float:
    """``chi2_df^-1(1 - q)``: the ``x`` with ``chi2_sf(x, df) = q``
    (:func:`scipy.special.chdtri`)."""
    return float(sps_special.chdtri(df, q))


def chi2_isf_each(q: float, df: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`chi2_isf` for each of the degrees of freedom ``df`` (any shape)."""
    return np.asarray(sps_special.chdtri(np.asarray(df, dtype=float), q), dtype=float)


@functools.lru_cache(maxsize=1024)
def _chi2_isf(q: float, df: float) -> float:
    """:func:`chi2_isf`, cached: an identification asks for the same few quantiles
    many times."""
    return chi2_isf(q, df)


def f_sf(x: float, dfn: float, dfd: float) -> float:
    """``P(F_(dfn, dfd) > x)`` (:func:`scipy.special.fdtrc`)."""
    return float(sps_special.fdtrc(dfn, dfd, x))


def f_isf(q: float, dfn: float, dfd: float) -> float:
    """``F_(dfn, dfd)^-1(1 - q)``. The upper tail of ``F`` is ``P(F > x) =
    I_y(dfd / 2, dfn / 2)`` with ``y = dfd / (dfd + dfn x)`` (Abramowitz & Stegun
    26.6.2), so ``x = dfd (1 - y) / (dfn y)`` with ``y`` the inverse regularised
    incomplete beta function of ``q`` (accurate for small ``q``, where ``1 - q``
    would round)."""
    y = float(sps_special.betaincinv(0.5 * dfd, 0.5 * dfn, q))
    return dfd * (1.0 - y) / (dfn * y)


@functools.lru_cache(maxsize=256)
def _f_isf(q: float, dfn: float, dfd: float) -> float:
    """:func:`f_isf`, cached as :func:`_chi2_isf`."""
    return f_isf(q, dfn, dfd)


#: the largest smaller dimension of the residue for which the exact law of its
#: largest eigenvalue is evaluated (the Hankel matrix of gammas has condition
#: 5e13 at 16); beyond (17 inputs and 17 outputs), the threshold stays the
#: parameter count's ``chi2_k`` (:func:`mode_threshold`): too low there
_RANK_ONE_MAX = 16


def _check_shape(n_out: int, n_in: int) -> tuple[int, int]:
    """``min`` and ``max`` of a residue block's dimensions, both at least 1."""
    if int(n_out) < 1 or int(n_in) < 1:
        raise ValueError(f"residue block: expected n_out, n_in >= 1, got {n_out} x {n_in}")
    return min(int(n_out), int(n_in)), max(int(n_out), int(n_in))


def rank_one_sf(x: float, n_out: int, n_in: int, kind: str = "complex") -> float:
    """``P(T_0 > x)`` for the statistic of a mode that is not there, at a given
    pole (module docstring). ``x`` in the units of the mode statistic ``T``: the
    noise variance of one real row.

    Complex modes: ``T_0 = 2 lambda_max(W)``, ``W`` the complex Wishart matrix
    ``Z^H Z`` of an ``n_out x n_in`` residue block ``Z`` of independent unit
    complex Gaussian entries. Khatri (1964), *Ann. Math. Statist.* 35,
    1807-1810: with ``m = min(n_out, n_in)``, ``n = max(n_out, n_in)``,
    ``P(lambda_max <= y) = det[gamma(n - m + i + j - 1, y)] / det[Gamma(n - m + i +
    j - 1)]`` (``i, j = 1..m``, ``gamma`` the lower incomplete gamma function; the
    denominator is ``prod Gamma(n - i + 1) Gamma(m - i + 1)``). The upper tail is
    taken as ``1 - det(I - G^-1 U)``, ``G`` and ``U`` the complete and upper
    incomplete gammas, from the eigenvalues of ``G^-1 U`` (``-expm1(sum
    log1p(-mu))``: no cancellation at small tails). With one input it is
    ``chi2_(2 n_out)``.

    Real modes (``kind="real"``): ``T_0 = lambda_max(Z^T Z)``, ``Z`` real with
    independent unit Gaussian entries (:func:`_real_rank_one_sf`, Chiani 2017);
    ``chi2_n`` with one input. Raises ValueError where the law is not evaluated
    (:func:`rank_one_available`).
    """
    m, n = _check_shape(n_out, n_in)
    _check_kind(kind)
    if not x > 0.0:
        return 1.0
    if kind == "real":
        if m == 1:
            return chi2_sf(x, n)
        return _real_rank_one_sf(float(x), m, n)
    if m > _RANK_ONE_MAX:
        raise ValueError(f"rank_one_sf: min(n_out, n_in) = {m} > {_RANK_ONE_MAX}")
    y = 0.5 * float(x)
    i = np.arange(1, m + 1)
    a = (n - m + i[:, None] + i[None, :] - 1).astype(float)
    lg = sps_special.gammaln(a)
    sc = np.exp(-0.5 * np.diag(lg))  # symmetric scaling: G's diagonal is 1
    g = np.exp(lg) * sc[:, None] * sc[None, :]
    cdf = float(np.linalg.det(np.linalg.solve(g, g * sps_special.gammainc(a, y))))
    if cdf < 0.5:  # the body: 1 - F directly
        return min(max(1.0 - cdf, 0.0), 1.0)
    mu = np.linalg.eigvals(np.linalg.solve(g, g * sps_special.gammaincc(a, y)))
    return float(min(max(-np.expm1(np.sum(np.log1p(-mu)).real), 0.0), 1.0))


def _check_kind(kind: str) -> None:
    if kind not in ("complex", "real"):
        raise ValueError(f"kind: expected 'complex' or 'real', got {kind!r}")


#: the largest condition number of the real law's skew-symmetric matrix at
#: infinity (:func:`_real_terms`) for which the law is evaluated: at 2e13 (16 x 16)
#: and 7e11 (8 x 64) it agrees with Monte Carlo samples, at 3e16 (16 x 40) it does
#: not; beyond, :func:`rank_one_available` is False and the threshold stays chi2_k
_REAL_MAX_COND = 5e13


@functools.lru_cache(maxsize=64)
def _real_terms(m: int, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """The constant parts of the real law (``2 <= m <= n``): the skew-symmetric
    matrix ``A(inf)`` (:func:`_real_rank_one_sf`), the coefficients ``c_ij =
    2^(1 - a_i - a_j) Gamma(a_i + a_j) / (Gamma(a_j + 1) Gamma(a_i))`` and the
    condition number of ``A(inf)``; ``a_i = (n - m - 1) / 2 + i``."""
    a = 0.5 * (n - m - 1) + np.arange(1, m + 1)
    aij = a[:, None] + a[None, :]
    lc = (1.0 - aij) * math.log(2.0) + sps_special.gammaln(aij)
    lc -= sps_special.gammaln(a[None, :] + 1.0) + sps_special.gammaln(a[:, None])
    c = np.exp(lc)
    a_inf = _skew(c, np.ones(m) if m % 2 else None)
    for arr in (a_inf, c):
        arr.flags.writeable = False
    return a_inf, c, float(np.linalg.cond(a_inf))


def _skew(terms: NDArray[np.float64], last: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """The skew-symmetric matrix of the real law: ``a_(i,j+1) = a_(i,j) +
    terms_(i,j)`` from ``a_ii = 0`` (``i < j``), and the column ``last`` appended
    (odd ``m``)."""
    m = terms.shape[0]
    size = m + (last is not None)
    top = np.zeros((size, size))
    for i in range(m - 1):
        top[i, i + 1 : m] = np.cumsum(terms[i, i : m - 1])
    if last is not None:
        top[:m, m] = last
    return np.asarray(top - top.T)


def rank_one_available(n_out: int, n_in: int, kind: str = "complex") -> bool:
    """Is the exact law of :func:`rank_one_sf` evaluated for this residue block?
    Complex modes: ``min(n_out, n_in) <= 16``; real modes: the condition number
    of the law's matrix at most ``_REAL_MAX_COND`` (all blocks up to 16 x 16)."""
    m, n = _check_shape(n_out, n_in)
    _check_kind(kind)
    if kind == "complex":
        return m <= _RANK_ONE_MAX
    return m == 1 or _real_terms(m, n)[2] <= _REAL_MAX_COND


def _real_rank_one_sf(x: float, m: int, n: int) -> float:
    """``P(lambda_max(W) > x)``, ``W`` real Wishart ``W_m(n, I)`` (``2 <= m <= n``).

    Chiani (2017), *IEEE Trans. Inf. Theory* 63, 4521-4531, Algorithm 1 with
    ``a = 0`` (the real case of Chiani 2014, *J. Multivariate Anal.* 129,
    69-81): ``P(lambda_max <= x) = K sqrt(det A(x))``, ``A`` skew-symmetric of
    size ``m`` (``m + 1`` for odd ``m``) with ``a_(i,j+1) = a_(i,j) + c_ij
    P(a_i + a_j, x) - P(a_i, x/2) (x/2)^a_j e^(-x/2) / Gamma(a_j + 1)`` (``P``
    the regularised lower incomplete gamma function, ``a_ii = 0``) and, for odd
    ``m``, ``a_(i,m+1) = P(a_i, x/2)``. Written as ``A(x) = A(inf) - D(x)``,
    whose terms ``c_ij Q(a_i + a_j, x) + P(a_i, x/2) (x/2)^a_j e^(-x/2) /
    Gamma(a_j + 1)`` and ``Q(a_i, x/2)`` (``Q = 1 - P``) are all positive, with
    ``K sqrt(det A(inf)) = 1``: the tail is ``1 - sqrt(det(I - A(inf)^-1 D))``,
    taken from the eigenvalues of ``A(inf)^-1 D`` as for the complex law.
    """
    a_inf, c, cond = _real_terms(m, n)
    if cond > _REAL_MAX_COND:
        raise ValueError(f"rank_one_sf: the real law of a {m} x {n} block is not evaluated")
    a = 0.5 * (n - m - 1) + np.arange(1, m + 1)
    y = 0.5 * x
    # P(a_i, y) y^a_j e^-y / Gamma(a_j + 1), the power in logs (no overflow)
    ey = np.exp(a * math.log(y) - y - sps_special.gammaln(a + 1.0))
    terms = sps_special.gammaincc(a[:, None] + a[None, :], x) * c
    terms += sps_special.gammainc(a, y)[:, None] * ey[None, :]
    d = _skew(terms, sps_special.gammaincc(a, y) if m % 2 else None)
    mm = np.linalg.solve(a_inf, d)
    cdf = math.sqrt(max(float(np.linalg.det(np.eye(mm.shape[0]) - mm)), 0.0))
    if cdf < 0.5:  # the body: 1 - F directly
        return min(max(1.0 - cdf, 0.0), 1.0)
    mu = np.linalg.eigvals(mm)
    return float(min(max(-np.expm1(0.5 * np.sum(np.log1p(-mu)).real), 0.0), 1.0))


def mode_null_sf(x: float, n_out: int, n_in: int, kind: str = "complex") -> float:
    """``P(T_0 + B > x)``: the statistic of a mode that is not there, ``T_0`` the
    rank-one residue's (:func:`rank_one_sf`, of ``kind``) and ``B ~ chi2_2`` its
    pole, independent (module docstring): ``e^(-x/2) + int_0^x e^(-b/2) / 2 P(T_0
    > x - b) db``. With one input it is the ``chi2_k`` of :func:`mode_parameters`
    (``k = 2 n_out + 2`` complex, ``n_out + 2`` real). ``x`` in the units of ``T``
    (:func:`rank_one_sf`)."""
    m, _ = _check_shape(n_out, n_in)
    _check_kind(kind)
    if not x > 0.0:
        return 1.0
    if m == 1:
        return chi2_sf(x, mode_parameters(n_out, n_in, kind))

    from scipy import integrate  # several inputs only: scipy.integrate is slow to import

    def f(b: float) -> float:
        return 0.5 * math.exp(-0.5 * b) * rank_one_sf(x - b, n_out, n_in, kind)

    # far in the tail (below ~1e-12) the round-off of P(T_0 > .) (~1e-16 absolute)
    # makes quad report slow convergence; the value is right to that round-off
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        val = integrate.quad(f, 0.0, float(x), epsabs=0.0, epsrel=1e-8, limit=200)[0]
    return float(math.exp(-0.5 * x) + val)


@functools.lru_cache(maxsize=256)
def mode_null_isf(level: float, n_out: int, n_in: int, kind: str = "complex") -> float:
    """The upper ``level`` quantile (a probability in (0, 1)) of :func:`mode_null_sf`,
    in the units of ``T`` (``chi2_k`` with one input)."""
    if not 0.0 < level < 1.0:
        raise ValueError(f"level: expected a probability in (0, 1), got {level}")
    m, _ = _check_shape(n_out, n_in)
    _check_kind(kind)
    k = mode_parameters(n_out, n_in, kind)
    if m == 1:
        return _chi2_isf(level, k)
    # the parameter count's quantile: the law lies beyond it
    lo = _chi2_isf(level, k)
    hi = 2.0 * lo + 10.0
    while mode_null_sf(hi, n_out, n_in, kind) > level:
        hi *= 2.0
    from scipy import optimize  # several inputs only: scipy.optimize is slow to import

    lv = math.log(level)
    return float(
        optimize.brentq(
            lambda x: math.log(max(mode_null_sf(x, n_out, n_in, kind), 1e-300)) - lv,
            lo * 0.9,
            hi,
            xtol=1e-6,
        )
    )


def mode_parameters(n_out: int, n_in: int, mode_kind: str) -> int:
    """Number of real parameters ``k`` one mode adds (module docstring)."""
    if mode_kind == "complex":
        return 2 * n_out + 2 + 2 * (n_in - 1)
    return n_out + 2 + (n_in - 1)


def mode_threshold(
    k: int,
    n_lines: int,
    false_alarm: float = FALSE_ALARM,
    weight_dof: float | None = None,
    shape: tuple[int, int] | None = None,
    kind: str = "complex",
) -> float:
    """Threshold of the mode statistic ``T``: ``chi2_k^-1(1 - alpha / n_lines)``, or
    with ``shape = (n_out, n_in)`` the same quantile of the rank-one law of
    ``kind`` modes (:func:`mode_null_isf`; equal to it with one input; ``k`` must
    then be :func:`mode_parameters` of that shape and kind).

    When the line weights are estimated with ``nu_w`` degrees of freedom, the
    larger of that times ``(nu_w - 2) / (nu_w - 4)`` (at most 2; the bound of
    the mean, module docstring) and ``k F^-1_(k, nu_w)(1 - alpha / n_lines)``:
    the tail of ``T`` for a mode whose few lines share one estimated factor,
    ``T / k = (chi2_k / k) / (chi2_nu_w / nu_w)`` (Seber & Lee 2003, sec. 4.3),
    the bound of the tail (a mode over many lines averages several factors).

    Parameters
    ----------
    k : int
        Parameters of one mode (:func:`mode_parameters`).
    n_lines : int
        Lines of the band (Bonferroni factor).
    false_alarm : float
        Probability ``alpha`` that a fit of pure noise keeps a noise mode.
    weight_dof : float, optional
        Degrees of freedom ``nu_w`` of estimated line weights; default None
        (known weights or none: no correction).
    """
    if not 0.0 < false_alarm < 1.0:
        raise ValueError(f"false_alarm: expected a probability in (0, 1), got {false_alarm}")
    level = false_alarm / max(int(n_lines), 1)
    thr = _chi2_isf(level, int(k))
    law = 1.0  # the rank-one law's quantile over the parameter count's
    if shape is not None:
        n_out, n_in = int(shape[0]), int(shape[1])
        if int(k) != mode_parameters(n_out, n_in, kind):
            raise ValueError(f"k = {k} is not the parameter count of {kind} modes of {shape}")
        if rank_one_available(n_out, n_in, kind):
            law = max(mode_null_isf(level, n_out, n_in, kind) / thr, 1.0)
    if weight_dof is None or not math.isfinite(weight_dof):
        return thr * law
    # the mean bound and the F tail of a mode whose lines share one estimated factor
    f_tail = int(k) * _f_isf(level, int(k), max(float(weight_dof), 1.0))
    return max(thr * weight_factor(weight_dof), f_tail) * law


def span_threshold(
    threshold: float,
    k: int,
    n_in: int,
    n_lines: int,
    span: tuple[float, float, int],
    false_alarm: float = FALSE_ALARM,
) -> float:
    """The mode threshold where the noise concentrates along the response.

    ``span = (lambda_in, lambda_out, n)``: the noise variance per complex
    direction in the span of ``H(f)`` and off it, in units of the fit's noise,
    summed over ``n`` lines (:mod:`tyredamp.modal.search.span_noise`). Of a mode's
    ``k`` parameters, ``a = min(4 n_in, k)`` can lie along the span (the
    ``n_in`` complex components of the residue's shape there, the
    participation and the pole, whose derivatives follow the shape), the
    others off it, so that the statistic of a mode that is not there is
    ``lambda_in chi2_a + lambda_out chi2_(k - a)`` instead of ``chi2_k``. Its
    upper quantile at the level ``alpha / n_lines`` of
    :func:`mode_threshold` is taken from the scaled chi-square of the same
    mean and variance (Satterthwaite 1946; Box 1954): ``c chi2_d^-1(1 -
    alpha / n_lines)``, ``c = var / (2 mean)``, ``d = 2 mean^2 / var``. The
    threshold is ``threshold`` times its ratio to ``chi2_k^-1(1 - alpha /
    n_lines)`` (the corrections for estimated weights carry over), never
    lower than ``threshold``; unchanged unless ``lambda_in`` exceeds
    ``max(lambda_out, 1)`` beyond its sampling scatter (its one-sided 95 %
    lower bound from ``2 n n_in^2`` real degrees of freedom).
    """
    lam_in, lam_out, n = span
    dof = 2.0 * max(int(n), 1) * int(n_in) ** 2
    lower = lam_in * dof / _chi2_isf(0.05, dof)
    if not lower > max(lam_out, 1.0) or not math.isfinite(lam_in):
        return float(threshold)
    level = false_alarm / max(int(n_lines), 1)
    a = float(min(4 * int(n_in), int(k)))
    b = float(k) - a
    mean = lam_in * a + lam_out * b
    var = 2.0 * (lam_in**2 * a + lam_out**2 * b)
    c, d = var / (2.0 * mean), 2.0 * mean * mean / var
    ratio = c * _chi2_isf(level, d) / _chi2_isf(level, int(k))
    return float(threshold) * max(ratio, 1.0)


def weight_factor(weight_dof: float | None) -> float:
    """Bound ``(nu_w - 2) / (nu_w - 4)`` of the inflation of ``T`` (1 for None, at most 2)."""
    if weight_dof is None or not math.isfinite(weight_dof):
        return 1.0
    nu = float(weight_dof)
    return 2.0 if nu <= 6.0 else (nu - 2.0) / (nu - 4.0)


def difference_noise(H: NDArray[np.complex128], per_input: bool = False) -> NDArray[np.float64]:
    """Noise variance per output (or per FRF) from second differences of adjacent lines.

    For white complex noise of variance ``s^2`` per line, ``d_f = H_{f+1} - 2
    H_f + H_{f-1}`` has ``E|d|^2 = 6 s^2`` and ``|d|^2`` is exponential, with
    median ``6 s^2 ln 2``; the median over lines and inputs ignores the few
    lines near sharp peaks where the FRF itself curves. Returns shape
    (n_out,), in the units of ``H`` squared (an upper bound of the noise when
    the FRF curves at most lines: few lines per half-power bandwidth).
    ``per_input``: shape (n_out, n_in), the median over each FRF's lines: the
    inputs of one output may carry different noise (a shaker per input, each
    with its own force level), and the median of a mixture of exponentials of
    different scales lies below ``ln 2`` times its mean (for scales 1 and 2,
    7 % below), so one median over the inputs would understate the noise.
    """
    if H.shape[-1] < 3:
        return np.full(H.shape[0], np.nan)
    n = H.shape[-1] - 2
    a2 = np.empty((*H.shape[:-1], n))
    for i in range(0, n, _DIFF_BLOCK):  # blocks of lines: no temporaries of H's size
        j = min(i + _DIFF_BLOCK, n)
        d = H[..., i + 2 : j + 2] - 2.0 * H[..., i + 1 : j + 1] + H[..., i:j]
        a2[..., i:j] = d.real**2 + d.imag**2
    if per_input:
        return np.asarray(np.median(a2, axis=-1, overwrite_input=True) / (6.0 * math.log(2.0)))
    a2 = a2.reshape(H.shape[0], -1)
    return np.asarray(np.median(a2, axis=1, overwrite_input=True) / (6.0 * math.log(2.0)))


@dataclass(frozen=True)
class GoodnessOfFit:
    """Cost of a fit against its chi-square expectation.

    Attributes
    ----------
    chi2 : float
        Weighted cost ``2 sum |H_model - H|^2 / Var H``.
    dof : int
        Residual degrees of freedom ``n_obs - n_par``.
    p_value : float
        ``P(chi2_dof >= chi2)``.
    noise : str
        Which noise the cost is measured against.
    passed : bool
        ``p_value >= false_alarm``.
    verdict : str
        One sentence for people.
    noise_dof : float or None
        Real degrees of freedom ``nu`` of an estimated per-line variance (the
        cost is then ``F``-corrected, module docstring); None for a known one.
    expected : float
        Expectation of ``chi2`` for a correct model (``dof``, or ``dof nu / (nu - 2)``).
    """

    chi2: float
    dof: int
    p_value: float
    noise: str
    passed: bool
    verdict: str
    noise_dof: float | None = None
    expected: float = float("nan")


def cost_reference(dof: int, noise_dof: float | None) -> tuple[float, float, float]:
    """Mean of the cost of a correct model and its scaled chi-square ``c chi2_d``.

    Parameters
    ----------
    dof : int
        Residual degrees of freedom ``n_obs - n_par``.
    noise_dof : float or None
        Real degrees of freedom ``nu > 4`` of the per-line variance estimate;
        None for a known variance (then ``c = 1``, ``d = dof``).

    Returns
    -------
    (float, float, float)
        ``mean``, ``c``, ``d`` (module docstring).
    """
    dof = max(int(dof), 1)
    if noise_dof is None or not math.isfinite(noise_dof):
        return float(dof), 1.0, float(dof)
    nu = float(noise_dof)
    if not nu > 4.0:
        raise ValueError(f"noise_dof: the F-corrected test needs nu > 4, got {nu:g}")
    mean = dof * nu / (nu - 2.0)
    var = 2.0 * dof * nu**3 / ((nu - 2.0) ** 2 * (nu - 4.0))
    return mean, var / (2.0 * mean), 2.0 * mean * mean / var


def goodness_of_fit(
    resid_ss: float,
    dof: int,
    noise: str,
    *,
    n_rejected: int = 0,
    false_alarm: float = FALSE_ALARM,
    noise_dof: float | None = None,
    inflation: float = 1.0,
) -> GoodnessOfFit:
    """Test a weighted residual sum of squares against its reference distribution.

    ``chi2(dof)`` for a known noise variance; the scaled chi-square of the
    ``F``-corrected cost when the variance is estimated with ``noise_dof``
    degrees of freedom; ``inflation chi2_{dof / inflation}`` (the chi-square's
    mean, ``inflation`` times its variance: eq. (GoF-1) for the noise from second
    differences, :data:`DIFFERENCE_INFLATION`) otherwise (module docstring).

    Parameters
    ----------
    resid_ss : float
        Residual sum of squares in units of the noise variance (``2 |e|^2 / V``
        summed: ``dof`` expected for a correct model and known variance).
    dof : int
        Residual degrees of freedom.
    noise : str
        Source of the noise level, for the verdict.
    n_rejected : int
        Candidate modes tried and rejected, for the verdict.
    false_alarm : float
        Level of the test.
    noise_dof : float, optional
        Real degrees of freedom ``nu > 4`` of an estimated per-line variance;
        default None (known variance: chi-square).
    inflation : float
        Variance of the cost of a correct model over that of ``chi2_dof`` when
        the noise was estimated from the same lines (at least 1; default 1: a
        known noise); not with ``noise_dof``.
    """
    dof = max(int(dof), 1)
    if not (math.isfinite(inflation) and inflation >= 1.0):
        raise ValueError(f"inflation: expected a finite number >= 1, got {inflation!r}")
    if noise_dof is not None and inflation != 1.0:
        raise ValueError("inflation: not with noise_dof (an estimated per-line variance)")
    mean, c, d = cost_reference(dof, noise_dof)
    if inflation != 1.0:
        c, d = inflation, dof / inflation
    chi2 = float(resid_ss)
    p = chi2_sf(chi2 / c, d) if np.isfinite(chi2) else 0.0
    passed = p >= false_alarm
    if noise_dof is None:
        stat = f"chi2/dof = {chi2 / dof:.3g}"
        if inflation != 1.0:
            stat += f", its variance {inflation:.3g} times the chi-square's"
    else:
        stat = f"cost/expectation = {chi2 / mean:.3g} (F-corrected, nu = {noise_dof:.3g})"
    if passed:
        verdict = f"the model explains the data to the noise ({stat}, p = {p:.2g}; noise {noise})"
    else:
        why = (
            f"{n_rejected} candidate mode(s) were tried and rejected"
            if n_rejected
            else "the model is incomplete"
        )
        verdict = f"structure is left: {stat} (p = {p:.2g}; noise {noise}); {why}"
    return GoodnessOfFit(
        chi2=chi2,
        dof=dof,
        p_value=p,
        noise=noise,
        passed=passed,
        verdict=verdict,
        noise_dof=noise_dof,
        expected=mean,
    )
