"""Fit of each damping model's exact FRF to measured FRFs, with standard errors.

The model is written in the undamped modal coordinates of the ``m`` modes of
the band (A-W part 1, eq. (13)-(14); part 2, eq. (20)): mass ``I``, stiffness
``diag(omega^2)``, real mode shapes ``Phi`` (N x m, 1/sqrt(kg)) at the
responses, and the damping ``Z(s) = g(s) C'`` of one law with a symmetric
``m x m`` matrix ``C'``:

``H(i w) = Phi_out (diag(omega^2) - w^2 I + g(i w) C')^-1 Phi_in^T``

with ``g(s) = s`` (viscous; ``C'`` diagonal for proportional damping),
``g = i`` (hysteretic), ``g(s) = s mu/(s + mu)`` (exponential, A-W part 2
eq. (4)) and ``g(s) = s^alpha`` (fractional, Bagley & Torvik 1983). The
inputs must be among the responses (a drive point per input), so that
``Phi_in`` is rows of ``Phi`` (reciprocity) and the scale of ``Phi`` is fixed.

The parameters are found by weighted least squares (the maximum-likelihood
estimate for independent complex Gaussian noise of known standard deviation
``sigma`` per line), started from the modal model (part 1 viscous estimate),
and their standard errors are the square roots of the diagonal of
``(J^T J)^-1`` (Gauss-Newton covariance; Bard, *Nonlinear Parameter
Estimation*, 1974, eq. (7-5-3)), ``J`` the Jacobian of the weighted
residuals. No residual terms are fitted: the band must hold the modes that
matter (out-of-band modes bias every model alike).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.special import expit

from .._validate import as_finite, as_frequency
from ..damping import modal_damping_from_modes
from ..exceptions import InputError, ShapeError
from .laws import DampingLaw, Exponential, Fractional, Hysteretic, Viscous

__all__ = ["MODELS", "ModelFit", "fit_model", "start_from_modes"]

#: The models, simplest first.
MODELS: tuple[str, ...] = ("proportional", "viscous", "hysteretic", "exponential", "fractional")
#: Starting relaxation parameters, as multiples of the largest natural frequency.
_MU_STARTS = (0.1, 0.3, 1.0, 3.0, 30.0)
#: Bound on ``|ln mu|`` (mu in 1/s): beyond it the kernel is viscous (or a stiffness) to rounding.
_LN_MU_MAX = 60.0
#: Function evaluations of the short run from each start (the best one is then run on).
_SCOUT_NFEV = 12
#: Starting derivative orders of the fractional model.
_ALPHA_STARTS = (0.3, 0.6, 1.0, 1.4)


@dataclass(frozen=True)
class ModalStart:
    """Start values from a modal model: ``omega`` (m,), ``Phi`` (N, m), ``C'`` (m, m)."""

    omega: NDArray[np.float64]
    shapes: NDArray[np.float64]
    c_modal: NDArray[np.float64]


def start_from_modes(poles: ArrayLike, shapes: ArrayLike) -> ModalStart:
    """Viscous start values from complex modes (A-W part 1, eq. (15)-(16)).

    Parameters
    ----------
    poles : array_like, complex, shape (m,)
        ``p_n`` (rad/s, ``Im p > 0``).
    shapes : array_like, complex, shape (N, m)
        Second-order shapes ``Psi^_n`` at the responses (1/sqrt(kg)).
    """
    est = modal_damping_from_modes(poles, shapes, method="first")
    c = 0.5 * (est.c_modal + est.c_modal.T)
    return ModalStart(est.omega.copy(), est.basis.copy(), c)


@dataclass(frozen=True)
class ModelFit:
    """One damping model fitted to FRFs (module docstring).

    Attributes
    ----------
    model : str
        One of :data:`MODELS`.
    omega : ndarray, shape (m,)
        Undamped natural frequencies, rad/s.
    shapes : ndarray, shape (N, m)
        Real mass-normalised mode shapes at the responses, 1/sqrt(kg).
    c_modal : ndarray, shape (m, m)
        ``C'`` of the law (units per law: 1/s viscous, 1/s^2 hysteretic,
        1/s exponential, 1/s^(2-alpha) fractional).
    extra : dict
        ``{"mu": ...}`` (1/s) or ``{"alpha": ...}``; empty otherwise.
    params, std : ndarray, shape (k,)
        All fitted parameters and their standard errors (``names`` says which).
    names : tuple of str
    chi2 : float
        Sum of squared weighted residuals (``-2 log L`` up to a constant).
    n_data : int
        Number of real data (2 per complex FRF value).
    """

    model: str
    omega: NDArray[np.float64]
    shapes: NDArray[np.float64]
    c_modal: NDArray[np.float64]
    extra: dict[str, float]
    params: NDArray[np.float64]
    std: NDArray[np.float64]
    names: tuple[str, ...]
    chi2: float
    n_data: int
    meta: dict[str, object] = field(default_factory=dict)

    @property
    def n_params(self) -> int:
        """Number of fitted parameters."""
        return int(self.params.size)

    @property
    def aic(self) -> float:
        """Akaike's criterion ``chi2 + 2 k`` (Akaike, IEEE TAC 19(6) 1974, eq. (1))."""
        return self.chi2 + 2 * self.n_params

    @property
    def bic(self) -> float:
        """Schwarz's criterion ``chi2 + k ln n`` (Schwarz, Ann. Stat. 6(2) 1978)."""
        return self.chi2 + self.n_params * float(np.log(self.n_data))

    def law(self) -> DampingLaw:
        """The law in modal coordinates (mass ``I``, stiffness ``diag(omega^2)``)."""
        c = self.c_modal
        if self.model in ("proportional", "viscous"):
            return Viscous(c)
        if self.model == "hysteretic":
            return Hysteretic(c)
        if self.model == "exponential":
            return Exponential(c, np.array([self.extra["mu"]]))
        return Fractional(c, self.extra["alpha"])

    def receptance(self, frequency: ArrayLike, inputs: ArrayLike) -> NDArray[np.complex128]:
        """Model FRF at ``frequency`` (Hz), inputs at rows ``inputs``, (N, n_in, n_f), m/N."""
        f = as_frequency(frequency, "frequency")
        extra = self.extra.get("mu", self.extra.get("alpha", 0.0))
        return _receptance(self.model, f, self.omega, self.shapes, self.c_modal, extra, inputs)


def _g(model: str, w: NDArray[np.float64], extra: float) -> NDArray[np.complex128]:
    """The scalar ``g(i w)`` of each law (module docstring)."""
    s = 1j * w
    if model in ("proportional", "viscous"):
        return np.asarray(s, dtype=complex)
    if model == "hysteretic":
        return np.full(w.shape, 1j)
    if model == "exponential":
        return np.asarray(s * extra / (s + extra), dtype=complex)
    return np.asarray(s**extra, dtype=complex)


def _receptance(
    model: str,
    f: NDArray[np.float64],
    omega: NDArray[np.float64],
    phi: NDArray[np.float64],
    c: NDArray[np.float64],
    extra: float,
    inputs: ArrayLike,
) -> NDArray[np.complex128]:
    q = _solve(model, 2 * np.pi * f, omega, c, extra)
    rows = np.asarray(inputs)
    return np.asarray(np.einsum("im,fmn,jn->ijf", phi, q, phi[rows]), dtype=complex)


def _solve(
    model: str,
    w: NDArray[np.float64],
    omega: NDArray[np.float64],
    c: NDArray[np.float64],
    extra: float,
) -> NDArray[np.complex128]:
    """``Q = (diag(omega^2) - w^2 I + g C')^-1`` at each line, shape (n_f, m, m)."""
    m = omega.size
    D = (np.diag(omega**2) - w[:, None, None] ** 2 * np.eye(m)) + _g(model, w, extra)[
        :, None, None
    ] * c
    return np.asarray(np.linalg.inv(D), dtype=complex)


def _jacobian(
    model: str,
    w: NDArray[np.float64],
    x: NDArray[np.float64],
    n: int,
    m: int,
    rows: NDArray[np.intp],
) -> NDArray[np.complex128]:
    """``dH/dx`` in closed form, shape (N, n_in, n_f, k): ``dQ = -Q dD Q``."""
    omega, phi, c, extra = _unpack(model, x, m, n)
    q = _solve(model, w, omega, c, extra)
    A = np.einsum("im,fmn->fin", phi, q)  # Phi Q, (nf, N, m)
    B = np.einsum("fmn,jn->fmj", q, phi[rows])  # Q Phi_in^T, (nf, m, n_in)
    g = _g(model, w, extra)
    cols = []
    for j in range(m):  # omega_j: dD = 2 omega_j e_j e_j^T
        cols.append(-2 * omega[j] * np.einsum("fi,fj->ijf", A[:, :, j], B[:, j, :]))
    for i in range(n):  # Phi[i, j] enters from the left and, at drive points, the right
        for j in range(m):
            d = np.zeros((n, rows.size, w.size), dtype=complex)
            d[i] += B[:, j, :].T
            for r in np.flatnonzero(rows == i):
                d[:, r, :] += A[:, :, j].T
            cols.append(d)
    for a, b in zip(*_sym_index(m, model == "proportional"), strict=True):
        d = np.einsum("fi,fj->ijf", A[:, :, a], B[:, b, :])
        if a != b:
            d = d + np.einsum("fi,fj->ijf", A[:, :, b], B[:, a, :])
        cols.append(-g * d)
    if model in ("exponential", "fractional"):
        s = 1j * w
        if model == "exponential":  # d g / d ln mu
            dg = extra * s**2 / (s + extra) ** 2
        else:  # d g / d u with alpha = 2/(1 + e^-u)
            dg = np.log(s) * s**extra * extra * (1 - extra / 2)
        cols.append(-dg * np.einsum("fim,mn,fnj->ijf", A, c, B))
    return np.stack(cols, axis=-1)


def _sym_index(m: int, diagonal: bool) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    return (np.arange(m), np.arange(m)) if diagonal else np.triu_indices(m)


def _unpack(
    model: str, x: NDArray[np.float64], m: int, n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float]:
    omega = x[:m]
    phi = x[m : m + n * m].reshape(n, m)
    iu = _sym_index(m, model == "proportional")
    k = iu[0].size
    c = np.zeros((m, m))
    c[iu] = x[m + n * m : m + n * m + k]
    c = c + np.triu(c, 1).T
    extra = 0.0
    if model == "exponential":
        extra = float(np.exp(np.clip(x[-1], -_LN_MU_MAX, _LN_MU_MAX)))
    elif model == "fractional":
        extra = _alpha(float(x[-1]))
    return omega, phi, c, extra


def _alpha(u: float) -> float:
    """Derivative order ``alpha = 2 / (1 + e^-u)`` in (0, 2) from the free parameter ``u``."""
    return 2.0 * float(expit(u))


def _alpha_u(alpha: float) -> float:
    """Inverse of :func:`_alpha`."""
    return float(np.log(alpha / (2.0 - alpha)))


def _names(model: str, m: int, n: int) -> tuple[str, ...]:
    iu = _sym_index(m, model == "proportional")
    names = [f"omega[{j + 1}]" for j in range(m)]
    names += [f"phi[{i + 1},{j + 1}]" for i in range(n) for j in range(m)]
    names += [f"C[{a + 1},{b + 1}]" for a, b in zip(*iu, strict=True)]
    names += {"exponential": ["ln mu"], "fractional": ["alpha"]}.get(model, [])
    return tuple(names)


def _starts(model: str, start: ModalStart) -> list[NDArray[np.float64]]:
    """Starting vectors from the viscous modal estimate (module docstring)."""
    om, phi, c = start.omega, start.shapes, start.c_modal
    iu = _sym_index(om.size, model == "proportional")
    head = np.concatenate([om, phi.ravel()])
    if model in ("proportional", "viscous"):
        return [np.concatenate([head, c[iu]])]
    if model == "hysteretic":
        return [np.concatenate([head, (c * np.sqrt(np.outer(om, om)))[iu]])]
    wm = float(np.sqrt(om.min() * om.max()))
    out = []
    if model == "exponential":
        for r in _MU_STARTS:
            mu = r * om.max()
            out.append(np.concatenate([head, (c * (1 + wm**2 / mu**2))[iu], [np.log(mu)]]))
        return out
    for a in _ALPHA_STARTS:
        scale = wm / (wm**a * np.sin(a * np.pi / 2))
        out.append(np.concatenate([head, (c * scale)[iu], [_alpha_u(a)]]))
    return out


def _warm_start(model: str, warm: ModelFit) -> NDArray[np.float64]:
    """Start vector at a fitted viscous model (``mu = 1000 omega_max``, ``alpha = 1``)."""
    om, c = warm.omega, warm.c_modal
    iu = np.triu_indices(om.size)
    head = np.concatenate([om, warm.shapes.ravel()])
    if model == "hysteretic":
        return np.concatenate([head, (c * np.sqrt(np.outer(om, om)))[iu]])
    if model == "exponential":
        return np.concatenate([head, c[iu], [np.log(1e3 * om.max())]])
    return np.concatenate([head, c[iu], [_alpha_u(1.0)]])


def fit_model(
    model: str,
    frequency: ArrayLike,
    H: ArrayLike,
    noise_std: ArrayLike,
    inputs: ArrayLike,
    start: ModalStart,
    warm: ModelFit | None = None,
) -> ModelFit:
    """Fit one damping model's FRF to measured receptances (module docstring).

    Parameters
    ----------
    model : str
        One of :data:`MODELS`.
    frequency : array_like, shape (n_f,)
        Frequency lines, Hz.
    H : array_like, complex, shape (N, n_in, n_f)
        Measured receptances, m/N.
    noise_std : array_like, shape broadcastable to (N, n_in, n_f)
        Standard deviation of the complex noise of each value (of its real and
        of its imaginary part each), m/N.
    inputs : array_like of int, shape (n_in,)
        Row of the response at each input's point (drive points).
    start : ModalStart
        Start values (:func:`start_from_modes`).
    warm : ModelFit, optional
        A fitted viscous model: one more start at its solution (``mu`` far
        above the band, ``alpha = 1``), so that a model nesting the viscous one
        fits at least as well.

    Returns
    -------
    ModelFit
    """
    if model not in MODELS:
        raise InputError(f"model: expected one of {', '.join(MODELS)}, got {model!r}")
    f = as_frequency(frequency, "frequency")
    h = as_finite(H, "H", dtype=complex)
    rows = np.asarray(inputs, dtype=int).ravel()
    if h.ndim != 3 or h.shape[2] != f.size or h.shape[1] != rows.size:
        raise ShapeError(f"H: expected shape (N, {rows.size}, {f.size}), got {h.shape}")
    sig = np.broadcast_to(as_finite(noise_std, "noise_std"), h.shape)
    if np.any(sig <= 0):
        raise InputError("noise_std: expected standard deviations > 0")
    n, m = start.shapes.shape
    if n != h.shape[0]:
        raise ShapeError(f"start: shapes at {n} points, the FRFs have {h.shape[0]} responses")

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        om, phi, c, extra = _unpack(model, x, m, n)
        r = (_receptance(model, f, om, phi, c, extra, rows) - h) / sig
        return np.concatenate([r.real.ravel(), r.imag.ravel()])

    def jac(x: NDArray[np.float64]) -> NDArray[np.float64]:
        d = _jacobian(model, 2 * np.pi * f, x, n, m, rows) / sig[..., None]
        d = d.reshape(-1, x.size)
        return np.concatenate([d.real, d.imag])

    best = None
    starts = _starts(model, start)
    if warm is not None and warm.model == "viscous" and model not in ("proportional", "viscous"):
        starts.append(_warm_start(model, warm))
    if len(starts) > 1:  # a short run from each start, then the best one to convergence
        for x0 in starts:
            sol = least_squares(
                resid, x0, jac=jac, method="lm", x_scale="jac", max_nfev=_SCOUT_NFEV
            )
            if best is None or sol.cost < best.cost:
                best = sol
        assert best is not None
        starts = [best.x]
    for x0 in starts:
        sol = least_squares(resid, x0, jac=jac, method="lm", x_scale="jac", max_nfev=200)
        if best is None or sol.cost <= best.cost:
            best = sol
    assert best is not None
    J = best.jac
    cov = np.linalg.pinv(J.T @ J)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    om, phi, c, extra = _unpack(model, best.x, m, n)
    params = best.x.copy()
    params[:m] = np.abs(params[:m])  # omega enters squared
    if model == "fractional":  # report alpha and its standard error (delta method)
        params[-1] = extra
        std[-1] *= extra * (1 - extra / 2)
    key = {"exponential": "mu", "fractional": "alpha"}.get(model)
    return ModelFit(
        model=model,
        omega=om,
        shapes=phi,
        c_modal=c,
        extra={key: extra} if key else {},
        params=params,
        std=std,
        names=_names(model, m, n),
        chi2=float(2 * best.cost),
        n_data=int(2 * h.size),
        meta={"nfev": int(best.nfev), "status": int(best.status)},
    )
