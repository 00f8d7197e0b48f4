"""Time response of an MCK system to a sampled force history.

The response is computed in complex modal coordinates (spec eq. [4]-[10]):
with ``psi_n`` scaled as in eq. [10], each mode obeys the scalar equation
``q_n' = p_n q_n + psi_n^T f(t)`` and the displacement is
``x = 2 Re sum_n psi_n q_n``. Between samples the force is held constant
(``hold="zoh"``) or interpolated linearly (``hold="foh"``, default), and each
modal equation is integrated exactly over a step: no ODE solver and no
time-step error beyond the interpretation of the sampled force.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite, check_positive
from ..exceptions import ShapeError
from .system import MCKSystem, _dofs

__all__ = [
    "TimeResponse",
    "continuous_periodic_lines",
    "foh_fourier_lines",
    "periodic_response_lines",
    "step_coefficients",
    "time_response",
]

#: Modes handled at once when accumulating the physical response.
_MODE_CHUNK = 64


@dataclass(frozen=True)
class TimeResponse:
    """Sampled response of an MCK system.

    Attributes
    ----------
    time : ndarray, shape (n_samples,)
        Time in s, starting at 0.
    displacement, velocity, acceleration : ndarray, shape (n_out, n_samples)
        At the requested output DOFs, in m, m/s and m/s^2.
    """

    time: NDArray[np.float64]
    displacement: NDArray[np.float64]
    velocity: NDArray[np.float64]
    acceleration: NDArray[np.float64]


def step_coefficients(
    poles: NDArray[np.complex128], h: float
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Exact one-step coefficients of ``q' = p q + g`` for a linear-in-time ``g``.

    Returns ``(Phi, E0, E1)`` with ``Phi = e^{p h}``,
    ``E0 = (e^{p h} - 1) / p`` and ``E1 = (e^{p h} - 1)/(p^2 h) - 1/p`` so that
    ``q_{k+1} = Phi q_k + (E0 - E1) g_k + E1 g_{k+1}``. Series are used where
    ``|p h|`` is small to avoid cancellation.
    """
    z = poles * h
    phi = np.exp(z)
    em1 = np.expm1(z)
    small = np.abs(z) < 1e-2
    zs = np.where(small, 1.0, z)  # safe divisor where the series is used
    e0 = np.where(small, h * (1 + z / 2 + z**2 / 6 + z**3 / 24 + z**4 / 120), em1 / zs * h)
    e1 = np.where(
        small,
        h * (0.5 + z / 6 + z**2 / 24 + z**3 / 120 + z**4 / 720),
        h * (em1 - zs) / zs**2,
    )
    return phi, e0, e1


def _minv_block(
    system: MCKSystem, inputs: NDArray[np.intp], outputs: NDArray[np.intp]
) -> NDArray[np.float64]:
    """The (outputs x inputs) block of ``M^-1``: the direct term of the acceleration
    (``sum_n p_n psi_n psi_n^T + c.c. = M^-1``), without forming the whole inverse."""
    unit = np.zeros((system.n_dof, inputs.size))
    unit[inputs, np.arange(inputs.size)] = 1.0
    return np.asarray(sla.cho_solve(sla.cho_factor(system.M), unit)[outputs], np.float64)


def time_response(
    system: MCKSystem,
    force: ArrayLike,
    sample_rate: float,
    inputs: Sequence[int],
    outputs: Sequence[int] | None = None,
    x0: ArrayLike | None = None,
    v0: ArrayLike | None = None,
    hold: Literal["foh", "zoh"] = "foh",
) -> TimeResponse:
    """Response to forces sampled at ``sample_rate`` applied at DOFs ``inputs``.

    Parameters
    ----------
    system : MCKSystem
        An underdamped system (all modes oscillatory).
    force : array_like, shape (n_in, n_samples) or (n_samples,)
        Force histories in N, one row per input DOF.
    sample_rate : float
        Samples per second (Hz).
    inputs : sequence of int
        DOF indices (0-based) where the forces act.
    outputs : sequence of int, optional
        DOF indices of the returned responses; default all.
    x0, v0 : array_like, shape (n_dof,), optional
        Initial displacement (m) and velocity (m/s); default at rest.
    hold : {"foh", "zoh"}
        Force between samples: linear (first-order hold) or constant.

    Returns
    -------
    TimeResponse
    """
    fs = check_positive(sample_rate, "sample_rate")
    f = as_finite(force, "force")
    if f.ndim == 1:
        f = f[None, :]
    if f.ndim != 2:
        raise ShapeError(f"force: expected shape (n_in, n_samples), got {f.shape}")
    ii = _dofs(inputs, system.n_dof, "inputs")
    if f.shape[0] != ii.size:
        raise ShapeError(f"force: expected {ii.size} rows (one per input DOF), got {f.shape[0]}")
    if hold not in ("foh", "zoh"):
        raise ShapeError(f"hold: expected 'foh' or 'zoh', got {hold!r}")
    oi = _dofs(outputs, system.n_dof, "outputs")
    n = system.n_dof
    x0a = np.zeros(n) if x0 is None else as_finite(x0, "x0", ndim=1)
    v0a = np.zeros(n) if v0 is None else as_finite(v0, "v0", ndim=1)
    if x0a.size != n or v0a.size != n:
        raise ShapeError(f"x0, v0: expected {n} entries each, got {x0a.size} and {v0a.size}")

    from scipy.signal import lfilter  # imported here: scipy.signal is slow to import

    cm = system.complex_modes()
    p, psi = cm.poles, cm.psi
    h = 1.0 / fs
    ns = f.shape[1]
    phi_step, e0, e1 = step_coefficients(p, h)
    # modal initial conditions q_n(0) = theta_n^T A z0 (eq. [4] orthogonality)
    mx0, mv0, cx0 = system.M @ x0a, system.M @ v0a, system.C @ x0a
    q0 = p * (psi.T @ mx0) + psi.T @ (mv0 + cx0)

    disp = np.zeros((oi.size, ns))
    vel = np.zeros((oi.size, ns))
    acc = np.zeros((oi.size, ns))
    psi_in = psi[ii]  # (n_in, m)
    psi_out = psi[oi]
    for start in range(0, p.size, _MODE_CHUNK):
        sl = slice(start, start + _MODE_CHUNK)
        g = psi_in[:, sl].T @ f  # (chunk, ns) modal forces
        q = np.empty_like(g)
        coeffs = zip(phi_step[sl], e0[sl], e1[sl], q0[sl], strict=True)
        for j, (pj, a1, b0, b1) in enumerate(coeffs):
            if hold == "foh":
                b = np.array([b0, a1 - b0])
                zi = np.array([b1 - b0 * g[j, 0]])
            else:
                b = np.array([0.0, a1])
                zi = np.array([b1])
            q[j], _ = lfilter(b, np.array([1.0, -pj]), g[j], zi=zi)
        ps = psi_out[:, sl]
        pp = p[sl]
        disp += 2 * np.real(ps @ q)
        vel += 2 * np.real((ps * pp) @ q)
        acc += 2 * np.real((ps * pp**2) @ q)
    acc += _minv_block(system, ii, oi) @ f
    return TimeResponse(
        time=np.arange(ns, dtype=float) * h, displacement=disp, velocity=vel, acceleration=acc
    )


def periodic_response_lines(
    system: MCKSystem,
    force_period: ArrayLike,
    sample_rate: float,
    inputs: Sequence[int],
    outputs: Sequence[int],
    n_lines: int,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """First DFT lines of the periodic steady-state response to a periodic force.

    The force repeats with period ``N / sample_rate`` (``N`` samples, first-order
    hold between samples as in :func:`time_response`). In the periodic steady
    state each complex mode's sequence ``q_k`` of :func:`time_response`,
    ``q_{k+1} = Phi q_k + (E0 - E1) g_k + E1 g_{k+1}`` with ``g = psi^T f``
    (spec eq. [10], coefficients of :func:`step_coefficients`), is periodic, so
    its DFT over one period obeys ``z Q = Phi Q + (E0 - E1) G + E1 z G`` with
    ``z = exp(2 pi i l / N)`` at line ``l``:

    ``Q_l = (E0 - E1 + E1 z) / (z - Phi) G_l``.

    The physical response is ``x = 2 Re sum psi q`` and
    ``a = 2 Re sum p^2 psi q + M^-1 f`` (the direct term of the acceleration);
    the DFT of ``conj(psi q)`` at line ``l`` is that of the mode with conjugate
    pole, shape and coefficients, so the conjugate modes enter as modes of
    their own. The result equals the DFT of the sampled response of
    :func:`time_response` started from the periodic state, to rounding, without
    stepping through the ``N`` samples of every mode.

    Parameters
    ----------
    system : MCKSystem
        An underdamped system.
    force_period : array_like, shape (n_in, N)
        One period of the forces in N (the sample after the last is the first).
    sample_rate : float
        Samples per second (Hz).
    inputs, outputs : sequence of int
        DOF indices of the forces and of the responses.
    n_lines : int
        Number of DFT lines returned, ``0 <= l < n_lines <= N // 2 + 1``.

    Returns
    -------
    displacement, acceleration : ndarray, shape (n_out, n_lines), complex
        The unnormalised DFT (``numpy.fft.rfft`` convention) of one period of
        the displacement (m) and the acceleration (m/s^2) at ``outputs``.
    """
    fs = check_positive(sample_rate, "sample_rate")
    f = as_finite(force_period, "force_period")
    if f.ndim == 1:
        f = f[None, :]
    ii = _dofs(inputs, system.n_dof, "inputs")
    oi = _dofs(outputs, system.n_dof, "outputs")
    if f.ndim != 2 or f.shape[0] != ii.size:
        raise ShapeError(
            f"force_period: expected shape ({ii.size}, n_samples), one row per input, got {f.shape}"
        )
    n = f.shape[1]
    if not 0 < int(n_lines) <= n // 2 + 1:
        raise ShapeError(f"n_lines: expected 1..{n // 2 + 1} for {n} samples, got {n_lines}")
    lines = int(n_lines)
    cm = system.complex_modes()
    phi, e0, e1 = step_coefficients(cm.poles, 1.0 / fs)
    # each conjugate pair as two modes: (p, psi, coefficients) and their conjugates
    p = np.concatenate([cm.poles, cm.poles.conj()])
    psi = np.concatenate([cm.psi, cm.psi.conj()], axis=1)
    phi, e0, e1 = (np.concatenate([c, c.conj()]) for c in (phi, e0, e1))
    force = np.fft.rfft(f, axis=1)[:, :lines]  # (n_in, lines)
    z = np.exp(2j * np.pi * np.arange(lines) / n)
    transfer = ((e0 - e1)[:, None] + e1[:, None] * z) / (z - phi[:, None])
    q = transfer * (psi[ii].T @ force)  # (2m, lines)
    disp = psi[oi] @ q
    acc = (psi[oi] * p**2) @ q + _minv_block(system, ii, oi) @ force
    return disp, acc


def foh_fourier_lines(force_period: ArrayLike, n_lines: int) -> NDArray[np.complex128]:
    """Fourier coefficients of a periodic first-order-hold signal, times ``N``.

    The piecewise-linear interpolant of ``N`` samples ``f_k`` per period
    ``T = N h`` is ``f(t) = sum_k f_k Lambda(t / h - k)`` (``Lambda`` the unit
    triangle, period extended). Since the Fourier transform of ``Lambda`` is
    ``h sinc^2(omega h / 2)`` (``sinc x = sin x / x``), its Fourier
    coefficient at ``omega_l = 2 pi l / T`` is

    ``c_l = (1/T) int_0^T f(t) e^{-i omega_l t} dt = X_l sinc^2(pi l / N) / N``

    with ``X_l`` the DFT of the samples (the triangle's transform: Bracewell,
    *The Fourier Transform and Its Applications*, 3rd ed., 2000, pictorial
    dictionary, ``Lambda(x) <-> sinc^2(s)``; the periodic sum gives ``X_l``;
    checked against a dense Fourier integral in the tests). The function returns
    ``N c_l = X_l sinc^2(pi l / N)``, in the ``numpy.fft.rfft`` convention of
    the samples.

    Parameters
    ----------
    force_period : array_like, shape (n_in, N) or (N,)
        One period of the samples (the sample after the last is the first).
    n_lines : int
        Number of lines returned, ``1 <= n_lines <= N // 2 + 1``.

    Returns
    -------
    ndarray, complex, shape (n_in, n_lines)
        ``N c_l`` for ``l = 0 .. n_lines - 1``, in the units of the samples.
    """
    f = as_finite(force_period, "force_period")
    if f.ndim == 1:
        f = f[None, :]
    if f.ndim != 2:
        raise ShapeError(f"force_period: expected shape (n_in, n_samples), got {f.shape}")
    n = f.shape[1]
    if not 0 < int(n_lines) <= n // 2 + 1:
        raise ShapeError(f"n_lines: expected 1..{n // 2 + 1} for {n} samples, got {n_lines}")
    lines = np.arange(int(n_lines))
    return np.fft.rfft(f, axis=1)[:, : lines.size] * np.sinc(lines / n) ** 2


def continuous_periodic_lines(
    system: MCKSystem,
    force_period: ArrayLike,
    sample_rate: float,
    inputs: Sequence[int],
    outputs: Sequence[int],
    n_lines: int,
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Harmonics of a periodic first-order-hold force and of the continuous steady state.

    What an ideal laboratory measures of the system driven by the
    piecewise-linear force of :func:`time_response`: the force gauge sees
    the continuous force, whose harmonics are :func:`foh_fourier_lines`, and
    the response in the periodic steady state is, harmonic by harmonic, the
    receptance times the force (spec eq. [1]; from the eigenvalues of the
    balanced first-order form, ``_receptance_balanced``, equal to the direct
    solution at each line to about 1e-10 of its largest value):

    ``X_l = H(omega_l) F_l``, ``A_l = -omega_l^2 X_l``,
    ``omega_l = 2 pi l sample_rate / N``.

    No line of the response folds onto another: a band-limited acquisition of
    these signals has exactly ``A_l / F_l = A(omega_l)``, unlike the samples of
    :func:`periodic_response_lines` (the response sampled at ``sample_rate``,
    whose harmonics above ``sample_rate / 2`` fold back).

    Parameters
    ----------
    system : MCKSystem
        An underdamped system.
    force_period : array_like, shape (n_in, N) or (n_runs, n_in, N)
        One period of the force samples in N (first-order hold between
        them); with three axes, several forcings of the same system (the
        receptance is computed once).
    sample_rate : float
        Samples per second (Hz).
    inputs, outputs : sequence of int
        DOF indices of the forces and of the responses.
    n_lines : int
        Number of lines returned, ``1 <= n_lines <= N // 2 + 1``.

    Returns
    -------
    force, displacement, acceleration : ndarray, complex
        Shapes (n_in, n_lines), (n_out, n_lines), (n_out, n_lines) (with a
        leading ``n_runs`` axis for a 3-D ``force_period``): ``N``
        times the Fourier coefficients of the continuous force (N),
        displacement (m) and acceleration (m/s^2) over one period (the
        ``numpy.fft.rfft`` scaling of ``N`` samples of a band-limited signal).
    """
    fs = check_positive(sample_rate, "sample_rate")
    ii = _dofs(inputs, system.n_dof, "inputs")
    oi = _dofs(outputs, system.n_dof, "outputs")
    f = as_finite(force_period, "force_period")
    runs = f.reshape(-1, *f.shape[-2:]) if f.ndim >= 2 else f[None, None, :]
    if f.ndim > 3 or runs.shape[1] != ii.size:
        raise ShapeError(
            f"force_period: expected shape ({ii.size}, n_samples), one row per input, got {f.shape}"
        )
    n = runs.shape[2]
    force = foh_fourier_lines(runs.reshape(-1, n), n_lines).reshape(runs.shape[0], ii.size, -1)
    freq = np.arange(force.shape[2]) * fs / n
    h = _receptance_balanced(system, freq, oi, ii)  # (n_out, n_in, lines)
    disp = np.einsum("oil,ril->rol", h, force)
    acc = -((2 * np.pi * freq) ** 2) * disp
    if f.ndim < 3:
        return force[0], disp[0], acc[0]
    return force, disp, acc


def _receptance_balanced(
    system: MCKSystem, freq: NDArray[np.float64], oi: NDArray[np.intp], ii: NDArray[np.intp]
) -> NDArray[np.complex128]:
    """Receptance ``(K - omega^2 M + i omega C)^-1`` at many lines, shape (n_out, n_in, n_freq).

    In the mass-normalised undamped modes (``Phi^T M Phi = I``,
    ``Phi^T K Phi = Omega^2``, ``C' = Phi^T C Phi``; spec eq. [11]-[14]) the
    equation of motion (spec eq. [1]) ``q'' + C' q' + Omega^2 q = Phi^T f`` has
    the first-order form ``z' = A z + B f`` with the state ``z = (Omega q, q')``,

    ``A = [[0, Omega], [-Omega, -C']]``, ``B = [0; Phi^T]``, ``x = Phi Omega^-1 z_1``

    (a linearisation of the quadratic eigenvalue problem, Tisseur & Meerbergen,
    SIAM Review 43(2), 2001, sec. 3.4, here scaled by ``Omega`` so that both
    blocks of ``A`` are of the size of the frequencies). ``A = V diag(l) V^-1``
    once, then ``H(omega) = C_x V diag(1 / (i omega - l)) V^-1 B`` at every
    line: a sum over the ``2 n`` eigenvalues instead of a solve per line. The
    balanced ``A`` is nearly normal for light damping, so ``V`` is well
    conditioned (checked against the direct solution in the tests). A system
    with a rigid-body mode (``Omega = 0``) is solved directly at each line.
    """
    w2, phi = sla.eigh(system.K, system.M)
    om = np.sqrt(np.clip(w2, 0.0, None))
    if om.size == 0 or om.min() <= 1e-8 * om.max():
        return system.receptance_direct(freq, oi, ii)
    n = om.size
    a = np.block([[np.zeros((n, n)), np.diag(om)], [-np.diag(om), -(phi.T @ system.C @ phi)]])
    lam, v = np.linalg.eig(a)
    vb = np.linalg.solve(v, np.vstack([np.zeros((n, ii.size)), phi[ii].T]))  # (2n, n_in)
    cv = (phi[oi] / om) @ v[:n]  # (n_out, 2n)
    g = 1.0 / (2j * np.pi * freq[None, :] - lam[:, None])  # (2n, n_freq)
    return np.einsum("on,ni,nf->oif", cv, vb, g)
