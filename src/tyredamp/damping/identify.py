"""Damping matrix from complex modes (spec step 7, eq. [14]-[18]).

After Adhikari & Woodhouse (J. Sound Vib. 243(1), 2001) as used by Popov &
Geng (2005). Notation (time dependence ``e^{st}``):

* identified poles ``p_n = -sigma_n + i Omega_n`` (rad/s), ``n = 1..m``;
* second-order complex shapes at the ``N`` measured points
  ``Psi^_n = psi_n sqrt(2 i Omega_n)`` (spec step 7), where ``psi_n`` is in the
  eq. [10] scaling. ``Re Psi^_n`` is then close to the mass-normalised
  undamped mode ``phi_n`` and ``Im Psi^_n`` comes from non-proportional damping;
* ``U = Re Psi^`` and ``V = Im Psi^`` (N x m), ``B = pinv(U) V`` (m x m), so that
  ``pinv(U) Psi^ = I + i B``: the complex modes written in the undamped modal
  coordinates of eq. [13], ``alpha_k^(n) = i B_kn``.

Three estimators of ``C'`` (eq. [14], damping in undamped modal coordinates,
1/s for mass-normalised modes) are provided:

``"first"`` (eq. [15], [16])
    ``C'_nn = -2 Re p_n`` and, inverting
    ``alpha_k^(n) = i omega_n C'_kn / (omega_n^2 - omega_k^2)`` with
    ``alpha_k^(n) = i B_kn``: ``C'_kn = (omega_n^2 - omega_k^2) B_kn / omega_n``,
    with ``omega_n = |p_n|``.

``"improved"`` (eq. [18])
    ``alpha_k^(n) = i lambda_n C'_kn / ((lambda_n - lambda_k)(lambda_n + conj lambda_k))``
    with ``lambda_n = p_n / i = Omega_n + i sigma_n`` (eq. [12]). Solving for
    ``C'_kn`` with ``alpha_k^(n) = i B_kn`` gives the complex number
    ``B_kn (lambda_n - lambda_k)(lambda_n + conj lambda_k) / lambda_n``; ``C'`` is
    real, so its real part is taken, which is also the real least-squares
    solution of ``i B_kn = C'_kn h_kn`` with ``h_kn = i lambda_n / (...)``:
    ``C'_kn = Re[B_kn (lambda_n - lambda_k)(lambda_n + conj lambda_k) / lambda_n]``.
    For real ``lambda`` this is eq. [16] again; the two differ by terms of order
    ``zeta^2`` for well separated modes and by much more for close modes,
    where ``(lambda_n - lambda_k)`` is dominated by the damping. (Measured on
    random systems, ``benchmarks/damping_accuracy.py``: the inverted [18] is
    not more accurate than [16]; both errors grow as ``zeta^2``.)

``"refined"`` (this package; not in the paper)
    Removes the bias of the first-order theory: the modes of the
    modal-coordinate system ``(I, S, diag w^2)`` are computed exactly (state
    space, eq. [4]-[10], same scaling and ``Psi^`` convention as the data), and
    the symmetric ``S`` and ``w`` are solved for so that eq. [16] applied to
    those exact modes gives the same (symmetrised) ``C'`` and ``|p|`` as
    applied to the data; the result is ``S`` plus the data's antisymmetric
    residual. A fixed-point iteration solves this for small damping, MINPACK's
    hybrid root finder when it stalls (close modes). With the complete modal
    set and exact modes this recovers ``C`` to rounding error; with a
    truncated set it is exact for the truncated modal system.

Normalisation. Adhikari & Woodhouse write each complex mode with unit
component on its own undamped mode (``alpha_n^(n) = 1``, eq. [13]). The
eq. [10] scaling used by the modal fit gives instead
``Psi^_n = Psi_n sqrt(2 i Omega_n / a_n)``, which differs from that by a
complex factor ``1 + O(zeta^2)``, and a fitted shape can carry a phase
error. For ``"first"`` and ``"improved"`` (with ``normalise=True``, the
default) each column of ``Psi^`` is rotated (phase only, magnitude kept) until
the diagonal of ``pinv(Re Psi^) Psi^`` is 1, so that ``diag(B) = 0`` as the
theory assumes; the removed phase is reported. Exact eq. [10] modes need no
rotation (to rounding); a phase error ``theta`` of a column would otherwise
shrink ``Re Psi^`` by ``cos theta`` and mix ``theta Im Psi^`` into it.
``"refined"`` uses the eq. [10] scaling of the data unchanged, because its
model modes are computed in the same scaling.

Physical coordinates: ``C = pinv(Phi)^T C' pinv(Phi)`` at the measured points,
with ``Phi = U`` (first, improved) or the real part of ``Psi^ G^-1`` where ``G``
are the model's second-order shapes in modal coordinates (refined). The
reduced mass and stiffness are ``M = pinv(Phi)^T pinv(Phi)`` and
``K = pinv(Phi)^T diag(omega^2) pinv(Phi)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment, root

from .._validate import as_finite
from ..exceptions import ConvergenceError, InputError, PhysicsError, ShapeError

__all__ = [
    "METHODS",
    "Method",
    "ModalDampingEstimate",
    "align_signs",
    "first_order_damping",
    "modal_damping_from_modes",
    "modal_system_shapes",
    "normalise_shapes",
    "physical_matrices",
]

Method = Literal["first", "improved", "refined"]
METHODS: tuple[Method, ...] = ("first", "improved", "refined")

#: Relative change of C' and omega at which the refinement stops (rounding floor ~1e-12).
_REFINE_TOL = 1e-10
#: Relative condition number of Re Psi^ above which the shapes count as dependent.
_RANK_RTOL = 1e-10
#: Largest |p| (rad/s) and shape norm (and smallest inverse) whose squares and
#: products stay inside double precision (1e150^2 = 1e300 < 1.8e308).
_MAX_SCALE = 1e150


@dataclass(frozen=True)
class ModalDampingEstimate:
    """Damping in modal coordinates identified from complex modes.

    Attributes
    ----------
    c_modal : ndarray, shape (m, m)
        ``C'`` (eq. [14]) in 1/s for mass-normalised modes; not symmetrised.
    omega : ndarray, shape (m,)
        Undamped natural frequencies used, rad/s (``|p_n|``, or the refined
        values for ``method="refined"``).
    basis : ndarray, shape (N, m)
        Real mass-normalised mode shapes at the points that define the modal
        coordinates (``U`` or the refined ``Phi``), in 1/sqrt(kg).
    shapes : ndarray, complex, shape (N, m)
        Second-order complex shapes ``Psi^`` after normalisation.
    B : ndarray, shape (m, m)
        ``pinv(U) V`` of the (normalised) shapes.
    method : {"first", "improved", "refined"}
    normalisation_phase : ndarray, shape (m,)
        Phase (rad) removed from each column by the normalisation; zeros when
        none was applied.
    iterations : int
        Iterations of the normalisation (first/improved) or refinement.
    basis_residual : float
        ``||Im(Psi^ G^-1)|| / ||Re(Psi^ G^-1)||`` for ``"refined"`` (how far the
        data are from the modes of a real basis times the truncated modal
        system); 0 otherwise.
    """

    c_modal: NDArray[np.float64]
    omega: NDArray[np.float64]
    basis: NDArray[np.float64]
    shapes: NDArray[np.complex128]
    B: NDArray[np.float64]
    method: Method
    normalisation_phase: NDArray[np.float64]
    iterations: int
    basis_residual: float


def _check_inputs(
    poles: ArrayLike, shapes: ArrayLike
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    p = as_finite(poles, "poles", ndim=1, dtype=complex)
    s = as_finite(shapes, "shapes", ndim=2, dtype=complex)
    if s.shape[1] != p.size:
        raise ShapeError(f"shapes: expected {p.size} columns (one per pole), got shape {s.shape}")
    if np.any(p.imag <= 0):
        raise InputError("poles: expected Im p > 0 (one member of each conjugate pair)")
    if np.any(p.real >= 0):
        raise PhysicsError("poles: expected Re p < 0 (damped, stable modes)")
    if s.shape[0] < p.size:
        raise ShapeError(
            f"the damping matrix needs at least as many measured points as modes "
            f"({s.shape[0]} points, {p.size} modes): choose fewer modes with --modes or "
            "--band (Python: fewer columns of shapes)"
        )
    # C, M and K at the points involve omega^2 and 1/|shape|^2: both must stay finite
    big = float(np.max(np.abs(p)))
    if big > _MAX_SCALE:
        raise InputError(
            f"poles: |p| up to {big:.3g} rad/s; its square overflows double precision "
            "(check the units of the modes file)"
        )
    amax = np.max(np.abs(s.real), axis=0)  # no squares: no overflow or underflow
    if np.any(amax == 0):
        k = int(np.argmin(amax))
        raise PhysicsError(
            f"the shape of mode {k + 1} has a zero real part at every measured point: its "
            "damping cannot be identified; leave that mode out (--modes or --band)"
        )
    if np.any(amax < 1 / _MAX_SCALE) or np.any(amax > _MAX_SCALE):
        raise InputError(
            f"shapes: largest entries from {amax.min():.3g} to {amax.max():.3g} 1/sqrt(kg) "
            "mean modal masses that overflow double precision (check the shape scaling)"
        )
    # the rank test does not depend on how each column is scaled
    sv = np.linalg.svd(s.real / amax, compute_uv=False)
    if sv[-1] <= _RANK_RTOL * sv[0]:
        raise PhysicsError(
            f"the real parts of the {p.size} mode shapes are linearly dependent at the "
            f"{s.shape[0]} measured points (condition number {sv[0] / max(sv[-1], 1e-300):.3g}); "
            "spatial aliasing or a repeated mode: measure more points or drop a mode"
        )
    return p, s


def align_signs(
    shapes: NDArray[np.complex128], reference: NDArray[np.floating] | NDArray[np.complexfloating]
) -> NDArray[np.complex128]:
    """Flip columns of ``shapes`` so that ``Re(shapes)^T Re(reference)`` has a positive diagonal.

    Parameters
    ----------
    shapes : ndarray, complex, shape (N, m)
    reference : ndarray, shape (N, m)
        Real or complex reference shapes (only the real part is used).
    """
    dots = np.einsum("in,in->n", shapes.real, np.real(reference))
    sign = np.where(dots < 0, -1.0, 1.0)
    return shapes * sign


def normalise_shapes(
    shapes: NDArray[np.complex128], max_iter: int = 100
) -> tuple[NDArray[np.complex128], NDArray[np.float64], int]:
    """Rotate each column so that ``diag(pinv(Re Psi^) Psi^) = 1`` (``alpha_n^(n) = 1``, eq. [13]).

    ``pinv(Re Psi^) Psi^ = I + i B`` always has a unit real diagonal; the
    condition ``B_nn = 0`` fixes the phase of each column. Only the phase is
    changed (the magnitude of ``Psi^`` carries the mass normalisation from the
    fitted residues); each step rotates column ``n`` by ``-arg(1 + i B_nn)``
    and recomputes ``Re Psi^``, which converges in a few steps for small
    damping.

    Parameters
    ----------
    shapes : ndarray, complex, shape (N, m)
        Second-order shapes ``Psi^``.
    max_iter : int
        Fixed-point iterations allowed (each changes ``Re Psi^`` by second-order
        terms, so two or three are usual).

    Returns
    -------
    shapes : ndarray, complex, shape (N, m)
    phase : ndarray, shape (m,)
        Total phase removed from each column, rad.
    iterations : int
    """
    s: NDArray[np.complex128] = np.array(shapes, dtype=complex)
    total = np.ones(s.shape[1], dtype=complex)
    for it in range(1, max_iter + 1):
        g = np.diag(np.linalg.pinv(s.real) @ s)  # 1 + i B_nn
        u = g / np.abs(g)  # phase only: |Psi^| carries the mass normalisation of the fit
        s = s / u
        total = total * u
        if np.max(np.abs(np.angle(g))) < 1e-14:
            return s, np.asarray(np.angle(total), dtype=float), it
    raise ConvergenceError(
        f"normalise_shapes: diag(pinv(Re Psi^) Psi^) did not converge to 1 in {max_iter} "
        f"iterations (last phase {np.max(np.abs(np.angle(g))):.3g} rad); the modes are far from "
        "the small-damping form"
    )


def first_order_damping(
    B: NDArray[np.float64],
    poles: NDArray[np.complex128],
    omega: NDArray[np.float64] | None = None,
    method: Literal["first", "improved"] = "first",
) -> NDArray[np.float64]:
    """``C'`` from ``B = pinv(U) V`` and the poles by eq. [15] with [16] or [18].

    Parameters
    ----------
    B : ndarray, shape (m, m)
        Imaginary part of the complex modes in undamped modal coordinates.
    poles : ndarray, complex, shape (m,)
        ``p_n`` in rad/s.
    omega : ndarray, shape (m,), optional
        Undamped natural frequencies (rad/s) for eq. [16]; default ``|p_n|``.
    method : {"first", "improved"}
        Eq. [16] or the inverted eq. [18] (see the module docstring).

    Returns
    -------
    ndarray, shape (m, m)
        ``C'`` in 1/s, diagonal ``-2 Re p_n`` (eq. [15]).
    """
    w = np.abs(poles) if omega is None else omega
    if method == "first":
        cp = (w[None, :] ** 2 - w[:, None] ** 2) * B / w[None, :]
    elif method == "improved":
        lam = -1j * poles  # eq. [12]: p_n = i lambda_n
        ln, lk = lam[None, :], lam[:, None]
        cp = np.real(B * (ln - lk) * (ln + np.conj(lk)) / ln)
    else:
        raise InputError(f"method: expected 'first' or 'improved', got {method!r}")
    np.fill_diagonal(cp, -2.0 * poles.real)
    return np.asarray(cp, dtype=float)


def modal_system_shapes(
    c_modal: NDArray[np.float64], omega: NDArray[np.float64]
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Exact complex modes of the modal-coordinate system ``(I, C', diag omega^2)``.

    Solves eq. [4]-[5] for ``q'' + C' q' + diag(omega^2) q = 0``, scales the
    modes as in eq. [10] and returns the second-order shapes
    ``G_n = psi_n sqrt(2 i Omega_n)`` in modal coordinates, column ``n``
    matched to modal coordinate ``n`` and with ``Re G_nn > 0``.

    Parameters
    ----------
    c_modal : ndarray, shape (m, m)
        Symmetric ``C'`` in 1/s.
    omega : ndarray, shape (m,)
        Undamped natural frequencies in rad/s.

    Returns
    -------
    poles : ndarray, complex, shape (m,)
    G : ndarray, complex, shape (m, m)

    Raises
    ------
    ConvergenceError
        If a mode of the modal system is overdamped (real pole).
    """
    m = omega.size
    a_state = np.block([[-c_modal, -np.diag(omega**2)], [np.eye(m), np.zeros((m, m))]])
    lam, vec = sla.eig(a_state)
    upper = lam.imag > 1e-12 * np.max(np.abs(lam))
    if np.count_nonzero(upper) != m:
        raise ConvergenceError(
            "modal_system_shapes: the modal system with the current C' has overdamped modes; "
            "the damping is too large for the refinement"
        )
    p = lam[upper]
    psi_u = vec[m:, upper]
    psi_u = psi_u / np.sqrt(np.einsum("in,in->n", psi_u, psi_u))
    a = np.einsum("in,ij,jn->n", psi_u, c_modal, psi_u) + 2 * p  # eq. [8], M = I
    g = psi_u / np.sqrt(a) * np.sqrt(2j * p.imag)
    # assign each model mode to the modal coordinate it is dominated by
    rows, cols = linear_sum_assignment(-np.abs(g))
    order = cols[np.argsort(rows)]
    p, g = p[order], g[:, order]
    sign = np.where(np.diag(g).real < 0, -1.0, 1.0)
    return p, g * sign


def _b_matrix(shapes: NDArray[np.complex128]) -> NDArray[np.float64]:
    return np.asarray(np.linalg.lstsq(shapes.real, shapes.imag, rcond=None)[0], dtype=float)


def _refine(
    p: NDArray[np.complex128], shapes: NDArray[np.complex128], max_iter: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128], int]:
    """Bias-corrected estimator ``C' = F(data) - (F(model(S, w)) - S)``.

    ``F`` is eq. [15]/[16] (``B`` and poles to ``C'``); ``model(S, w)`` the exact
    modes of the modal system ``(I, S, diag w^2)``. ``S`` (symmetric) and ``w``
    solve ``sym(F(data) - F(model(S, w))) = 0`` and ``|p_model| = |p_data|``,
    a square system of ``m(m+1)/2 + m`` equations. A fixed-point iteration
    (whose Jacobian is close to the identity for small damping) is tried first;
    if it stalls, as it can for close modes with overlapping resonances, the
    same equations are solved by MINPACK's hybrid method
    (:func:`scipy.optimize.root`). The returned ``C'`` is
    ``S + antisym(F(data) - F(model(S, w)))``: exact data give ``S`` itself;
    inconsistent data keep their asymmetry.
    """
    m = p.size
    iu = np.triu_indices(m)
    n_s = iu[0].size
    w_data = np.abs(p)
    c0 = first_order_damping(_b_matrix(shapes), p, w_data, "first")

    def model_map(
        s: NDArray[np.float64], w: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128]]:
        pm, g = modal_system_shapes(s, w)
        return first_order_damping(_b_matrix(g), pm, np.abs(pm), "first"), np.abs(pm), g

    def unpack(x: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        s = np.zeros((m, m))
        s[iu] = x[:n_s]
        return s + np.triu(s, 1).T, x[n_s:]

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        s, w = unpack(x)
        f_mod, w_mod, _ = model_map(s, w)
        r = c0 - f_mod
        return np.concatenate([(0.5 * (r + r.T))[iu], w_data - w_mod])

    scale = np.concatenate([np.full(n_s, max(float(np.max(np.abs(c0))), 1e-300)), w_data])
    x = np.concatenate([(0.5 * (c0 + c0.T))[iu], w_data])
    best, best_size = x, np.inf
    it = 0
    try:
        for it in range(1, min(max_iter, 60) + 1):
            r = residual(x)
            size = float(np.max(np.abs(r) / scale))
            if size < best_size:
                best, best_size = x, size
            elif it > 3:
                break  # stalled: at the rounding floor, or diverging
            if size < 1e-15:
                break
            x = x + r
    except ConvergenceError:
        pass
    x = best
    solved = best_size < _REFINE_TOL
    if not solved:
        x0 = np.concatenate([(0.5 * (c0 + c0.T))[iu], w_data])
        try:
            sol = root(
                lambda y: residual(y * scale) / scale,
                x0 / scale,
                method="hybr",
                options={"xtol": 1e-13, "maxfev": 200 * max_iter},
            )
        except ConvergenceError:
            sol = None
        if sol is None or float(np.max(np.abs(sol.fun))) > 1e3 * _REFINE_TOL:
            raise ConvergenceError(
                "refined damping estimate: the bias-correction equations have no solution "
                "near the first-order estimate (modes too strongly coupled or inconsistent); "
                "use the improved method (--method improved; method='improved' in Python) "
                "and read the diagnostics"
            ) from None
        x = sol.x * scale
        it += int(sol.nfev)
    s, w = unpack(x)
    f_mod, _, g = model_map(s, w)
    r = c0 - f_mod
    return s + 0.5 * (r - r.T), w, g, it


def modal_damping_from_modes(
    poles: ArrayLike,
    shapes: ArrayLike,
    method: Method = "improved",
    normalise: bool = True,
    max_iter: int = 200,
) -> ModalDampingEstimate:
    """Identify ``C'`` (eq. [14]) from poles and second-order complex shapes (spec step 7).

    Parameters
    ----------
    poles : array_like, complex, shape (m,)
        ``p_n`` in rad/s, ``Im p_n > 0``, ``Re p_n < 0``.
    shapes : array_like, complex, shape (N, m)
        ``Psi^_n = psi_n sqrt(2 i Omega_n)`` at ``N >= m`` points, 1/sqrt(kg)
        (e.g. :meth:`tyredamp.modal.ModalModel.second_order_shapes`).
    method : {"first", "improved", "refined"}
        Eq. [16], eq. [18], or the bias-corrected iteration (module docstring).
    normalise : bool
        Apply the ``alpha_n^(n) = 1`` normalisation before ``"first"`` and
        ``"improved"`` (ignored by ``"refined"``).
    max_iter : int
        Iteration limit of the normalisation / refinement.

    Returns
    -------
    ModalDampingEstimate

    Raises
    ------
    ShapeError
        Fewer points than modes, or mismatched sizes.
    PhysicsError
        Linearly dependent shapes, or unstable poles.
    ConvergenceError
        The normalisation or refinement did not converge.
    """
    if method not in METHODS:
        raise InputError(f"method: expected one of {METHODS}, got {method!r}")
    p, s = _check_inputs(poles, shapes)
    phase = np.zeros(p.size)
    if method == "refined":
        c, w, g, it = _refine(p, s, max_iter)
        phi_c = np.linalg.solve(g.T, s.T).T  # Psi^ G^-1
        basis = np.real(phi_c)
        resid = float(np.linalg.norm(phi_c.imag) / np.linalg.norm(phi_c.real))
        return ModalDampingEstimate(
            c_modal=c,
            omega=w,
            basis=basis,
            shapes=s,
            B=_b_matrix(s),
            method=method,
            normalisation_phase=phase,
            iterations=it,
            basis_residual=resid,
        )
    it = 0
    if normalise:
        s, phase, it = normalise_shapes(s, max_iter)
    b = _b_matrix(s)
    w = np.abs(p)
    c = first_order_damping(b, p, w, method)
    return ModalDampingEstimate(
        c_modal=c,
        omega=w,
        basis=np.array(s.real),
        shapes=s,
        B=b,
        method=method,
        normalisation_phase=phase,
        iterations=it,
        basis_residual=0.0,
    )


def physical_matrices(
    basis: NDArray[np.float64], c_modal: NDArray[np.float64], omega: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Reduced ``M``, ``C``, ``K`` at the points from modal quantities.

    ``P = pinv(Phi)``; ``M = P^T P``, ``C = P^T C' P``, ``K = P^T diag(omega^2) P``.
    With ``m < N`` modes all three have rank ``m``.

    Parameters
    ----------
    basis : ndarray, shape (N, m)
        Mass-normalised real shapes ``Phi`` at the points, 1/sqrt(kg).
    c_modal : ndarray, shape (m, m)
        ``C'`` in 1/s.
    omega : ndarray, shape (m,)
        rad/s.

    Returns
    -------
    M, C, K : ndarray, shape (N, N)
        kg, N s/m, N/m (for SI shapes).
    """
    pinv = np.linalg.pinv(basis)
    return pinv.T @ pinv, pinv.T @ c_modal @ pinv, (pinv.T * omega**2) @ pinv
