"""The lateral least-squares problem, reduced exactly and evaluated in blocks of lines.

The residual of a lateral fit (:mod:`.fit`, :mod:`.joint`) stacks, for each FRF
(a *segment*), the real and imaginary parts of ``r_k = w_k (A(f_k; p) - A_k)``
with the model parameters ``log p = T x + b`` of global log-parameters ``x``.
A Gauss-Newton trust-region method needs from ``r`` and its Jacobian ``J``
(``2N x P``) only ``J^T J``, ``J^T r`` and ``r^T r``, that is the
``(P+1) x (P+1)`` product ``G = [J r]^T [J r]``, a sum over the lines. It is
accumulated block by block (:meth:`Problem.gram`), so no ``2N x P`` array is
ever held: the work arrays are one block, whatever the number of lines.

:func:`scipy.optimize.least_squares` (method ``"trf"``) is run on a factor
``F`` of ``G`` (``F^T F = G``, Cholesky, or the symmetric square root when
``G`` is singular): with residual ``F[:, P]`` and Jacobian ``F[:, :P]`` the
cost, the gradient and the trust-region subproblem (which scipy solves through
the SVD of the scaled Jacobian) are those of the full problem, so the iterates
are the full problem's up to rounding. Two differences: forming ``G`` squares
the condition number of ``J`` (harmless for the well-posed fits; for a
parameter the data do not determine the iterates may wander differently along
the flat valley), and scipy's rank threshold ``eps * m * s_max`` sees
``m = P + 1`` rows instead of ``2N``.

The standard errors need the small singular values of ``J`` accurately, so at
the solution the triangular factor of ``[J r] = Q R_aug`` is computed by
Householder QR accumulated over the blocks (re-factorising ``[R_aug; J_blk
r_blk]``, the "tall-skinny QR" of Demmel et al., SIAM J. Sci. Comput. 34 (2012)
A206): ``J`` and ``R`` have the same singular values and right singular
vectors (Golub & Van Loan, *Matrix Computations*, 4th ed., sec. 5.3.3).

The Jacobian is analytic (each model's ``_mobility_gradient``) with the
axle-force chain rule ``d V_axle = d V / (1 + i omega M V)^2``; a model
without one gets central differences in the log-parameters.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..exceptions import InputError
from .models import LateralModel
from .response import ForceKind

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Lines per block: bounds the work arrays (a few MB) whatever the number of lines.
BLOCK = 1 << 14
#: Residual of a parameter vector the model rejects (as the former full residual did).
_BAD = 1e100
#: Log-parameter step of the central-difference fallback (scipy's 3-point step ~ eps^(1/3)).
_FD_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))


class Lines:
    """Fitted lines with the per-line factors every evaluation needs, computed once.

    The weighted residual is ``w (i omega V - A_meas) = (w i omega) V - w A_meas``
    with ``V`` the mobility at the force (module docstring).

    Parameters
    ----------
    frequency : ndarray, shape (N,)
        Hz (> 0).
    measured : ndarray, complex, shape (N,)
        Accelerance, m/(s^2 N).
    weights : ndarray, shape (N,)
        Residual weights.
    """

    def __init__(self, frequency: FloatArray, measured: ComplexArray, weights: FloatArray) -> None:
        self.frequency = frequency
        self.omega = 2.0 * np.pi * frequency
        self.w_iw = weights * (1j * self.omega)
        self.w_meas = weights * measured
        self.n = int(frequency.size)


@dataclass(frozen=True, eq=False)
class Segment:
    """One FRF's share of the residual ``w (A_model - A_meas)`` (module docstring).

    ``tmap`` (``P_model x P_global``) and ``offset`` give the model's
    log-parameters from the global ones; ``None`` means the identity and 0.
    """

    cls: type[LateralModel]
    cond: dict[str, float]
    lines: Lines
    force: ForceKind = "ground"
    wheel_mass: float = 0.0
    tmap: FloatArray | None = None
    offset: FloatArray | None = None

    @property
    def n_lines(self) -> int:
        return self.lines.n

    def log_params(self, x: FloatArray) -> FloatArray:
        """The model's log-parameters from the global ``x``."""
        lp = x if self.tmap is None else self.tmap @ x
        return lp if self.offset is None else lp + self.offset

    def model(self, logp: FloatArray) -> LateralModel | None:
        """The model at ``logp``; None when it rejects the values (as the residual's 1e100)."""
        try:
            with np.errstate(over="raise", invalid="raise"):
                return self.cls.from_vector(np.exp(logp), **self.cond)
        except (InputError, FloatingPointError, ZeroDivisionError):
            return None

    def _at_force(self, v: ComplexArray, w: FloatArray) -> tuple[ComplexArray, ComplexArray | None]:
        """The mobility at the force and ``dV_force/dV`` (None: 1), ``attach_mass``."""
        if self.force != "axle":
            return v, None
        den = 1.0 + 1j * w * self.wheel_mass * v
        return v / den, den**-2

    def residual(self, m: LateralModel, sl: slice) -> ComplexArray:
        """The weighted residual ``w (A - A_meas)`` on the lines ``sl``."""
        ln = self.lines
        w = ln.omega[sl]
        v, _ = self._at_force(np.asarray(m._mobility(w), dtype=complex), w)
        v *= ln.w_iw[sl]
        v -= ln.w_meas[sl]
        return v

    def residual_and_gradient(
        self, m: LateralModel, logp: FloatArray, sl: slice, out: ComplexArray
    ) -> bool:
        """``out[:P] = dr/d log p``, ``out[P] = r`` on the lines ``sl``; False: not finite."""
        ln = self.lines
        w = ln.omega[sl]
        p = logp.size
        both = m._mobility_gradient(w)
        if both is None:
            if not self._numerical_gradient(logp, sl, out[:p]):
                return False
            out[p] = self.residual(m, sl)
            return True
        v, dv = both
        v, dvf = self._at_force(np.asarray(v, dtype=complex), w)
        np.multiply(dv, ln.w_iw[sl] if dvf is None else ln.w_iw[sl] * dvf, out=out[:p])
        np.multiply(v, ln.w_iw[sl], out=out[p])
        out[p] -= ln.w_meas[sl]
        return True

    def _numerical_gradient(self, logp: FloatArray, sl: slice, out: ComplexArray) -> bool:
        for k in range(logp.size):
            e = np.zeros_like(logp)
            e[k] = _FD_STEP
            hi, lo = self.model(logp + e), self.model(logp - e)
            if hi is None or lo is None:
                return False
            out[k] = (self.residual(hi, sl) - self.residual(lo, sl)) / (2 * _FD_STEP)
        return True


@dataclass(eq=False)
class Problem:
    """The (joint) lateral least-squares problem over ``segments`` in ``n_params`` unknowns."""

    segments: Sequence[Segment]
    n_params: int
    _cache: tuple[FloatArray, FloatArray, float] | None = field(default=None, repr=False)

    @property
    def n_residuals(self) -> int:
        """Number of real residuals ``2 N`` (all segments)."""
        return 2 * sum(s.n_lines for s in self.segments)

    def _bad(self) -> tuple[FloatArray, float]:
        p = self.n_params
        r_aug = np.zeros((p + 1, p + 1))
        r_aug[p, p] = _BAD * np.sqrt(self.n_residuals)
        return r_aug, _BAD**2 * self.n_residuals

    def rss(self, x: FloatArray) -> float:
        """``r^T r`` at ``x`` (without the Jacobian)."""
        total = 0.0
        for seg in self.segments:
            m = seg.model(seg.log_params(x))
            if m is None:
                return self._bad()[1]
            for lo in range(0, seg.n_lines, BLOCK):
                d = seg.residual(m, slice(lo, lo + BLOCK))
                total += float(np.vdot(d, d).real)
        return total if np.isfinite(total) else self._bad()[1]

    def _blocks(self, x: FloatArray) -> Iterator[tuple[Segment, ComplexArray] | None]:
        """Per block ``[dr/d log p; r]`` (complex, ``(P_model + 1) x n``); None: not finite."""
        for seg in self.segments:
            logp = seg.log_params(x)
            m = seg.model(logp)
            if m is None:
                yield None
                return
            for lo in range(0, seg.n_lines, BLOCK):
                sl = slice(lo, lo + BLOCK)
                a = np.empty((logp.size + 1, min(BLOCK, seg.n_lines - lo)), dtype=complex)
                if not seg.residual_and_gradient(m, logp, sl, a):
                    yield None
                    return
                yield seg, a

    @staticmethod
    def _global(seg: Segment, local: FloatArray) -> FloatArray:
        """A segment's ``[J r]`` product in its own log-parameters mapped to the global ones."""
        if seg.tmap is None:
            return local
        p_l, p_g = seg.tmap.shape
        t = np.zeros((p_l + 1, p_g + 1))
        t[:p_l, :p_g] = seg.tmap
        t[p_l, p_g] = 1.0
        return np.asarray(t.T @ local @ t)

    def gram(self, x: FloatArray) -> tuple[FloatArray, float]:
        """``G = [J r]^T [J r]`` at ``x`` and ``r^T r``; cached for the last ``x``."""
        if self._cache is not None and np.array_equal(self._cache[0], x):
            return self._cache[1], self._cache[2]
        p = self.n_params
        gram = np.zeros((p + 1, p + 1))
        for item in self._blocks(np.asarray(x, dtype=float)):
            if item is None:
                gram = np.full((p + 1, p + 1), np.nan)
                break
            seg, a = item
            gram += self._global(seg, _products(a))
        rss = float(gram[p, p])
        if not np.all(np.isfinite(gram)):
            r_aug, rss = self._bad()
            gram = r_aug.T @ r_aug
        self._cache = (np.array(x, dtype=float), gram, rss)
        return gram, rss

    def reduced(self, x: FloatArray) -> FloatArray:
        """A factor ``F`` with ``F^T F = G`` (:meth:`gram`): scipy's residual and Jacobian."""
        gram, _ = self.gram(x)
        try:
            return np.asarray(np.linalg.cholesky(gram).T)
        except np.linalg.LinAlgError:  # singular: a symmetric square root instead
            lam, vec = np.linalg.eigh(gram)
            return np.asarray(np.sqrt(np.clip(lam, 0.0, None))[:, None] * vec.T)

    def qr(self, x: FloatArray) -> tuple[FloatArray, float]:
        """``R_aug`` of ``[J r]`` at ``x`` by blocked Householder QR (stable) and ``r^T r``."""
        p = self.n_params
        r_aug = np.zeros((0, p + 1))
        total = 0.0
        for item in self._blocks(np.asarray(x, dtype=float)):
            if item is None:
                return self._bad()
            seg, a = item
            if seg.tmap is not None:
                p_l = a.shape[0] - 1
                a = np.vstack([seg.tmap.T @ a[:p_l], a[p_l:]])
            top, n = r_aug.shape[0], a.shape[1]
            blk = np.empty((top + 2 * n, p + 1))
            blk[:top] = r_aug
            blk[top : top + n] = a.real.T
            blk[top + n :] = a.imag.T
            if not np.all(np.isfinite(blk)):
                return self._bad()
            total += float(np.vdot(a[p], a[p]).real)
            r_aug = np.asarray(np.linalg.qr(blk, mode="r"))
        if r_aug.shape[0] < p + 1:  # fewer residuals than unknowns + 1: pad with zeros
            r_aug = np.vstack([r_aug, np.zeros((p + 1 - r_aug.shape[0], p + 1))])
        return r_aug, total

    def solve(self, x0: FloatArray, span: float, max_nfev: int, **options: Any) -> Any:
        """scipy's ``least_squares`` (trf) on the reduced residual, bounds ``x0 +- span``."""
        p = self.n_params

        def fun(x: FloatArray) -> FloatArray:
            return np.array(self.reduced(x)[:, p])

        def jac(x: FloatArray) -> FloatArray:
            return np.array(self.reduced(x)[:, :p])

        return least_squares(
            fun,
            x0,
            jac=jac,
            bounds=(x0 - span, x0 + span),
            method="trf",
            xtol=1e-14,
            ftol=1e-14,
            gtol=1e-14,
            max_nfev=max_nfev,
            **options,
        )


def _products(a: ComplexArray) -> FloatArray:
    """``Re(a a^H)``: the products of the rows of ``a`` as stacked real vectors.

    Row by row with dot products of the float views (rows ``[Re, Im, Re, Im,
    ...]``): for a few long rows this is about 3x faster than one matrix product.
    """
    av = a.view(np.float64)
    q = av.shape[0]
    out = np.empty((q, q))
    for i in range(q):
        for j in range(i, q):
            out[i, j] = out[j, i] = av[i] @ av[j]
    return out
