"""Random *physical* test structures for the speed benchmarks (``perf_common.physical_case``).

Not a benchmark itself. :func:`physical_system` draws a mass-spring network,
tunes its natural frequencies so that a given number of modes falls in the
band, damps it non-proportionally and picks the measured points; the FRFs
follow from ``M``, ``C``, ``K`` (``perf_common.physical_case``).

The system, in order of construction
------------------------------------
1. Network: ``n_dof`` random masses (0.5-2 kg) on a chain of random springs
   with random extra couplings and a few springs to ground. Its mass-normalised
   undamped modes ``Phi`` (``Phi^T M Phi = I``) give the mode shapes.
2. Tuning: the stiffness is replaced by ``K = M Phi diag(omega^2) Phi^T M``
   with designed ``omega`` (the same mass and mode shapes, other natural
   frequencies: the spectral form of a symmetric positive definite pencil,
   ``Phi^T K Phi = diag(omega^2)``). ``n_modes - 1`` in-band slots in
   0.04-0.92 ``f_hi``, roughly evenly spread but at least 6 % apart, one of
   them a close pair (below);
   the remaining modes above the band, from 1.1-1.3 ``f_hi`` up with the
   network's own frequency ratios (at most 8 ``f_hi``).
3. Measured points: ``n_out`` random DOFs (the others unmeasured); the
   ``n_in`` drive points among them, chosen so that every in-band mode but
   the weak one has a large amplitude at some drive point.
4. Damping: Rayleigh ``alpha M + beta K`` (0.4-1.2 % at the band's ends)
   plus ``2 + n_modes // 10`` localised dashpots (between two masses or to
   ground, none at a drive point) adding a mean 0.6-1.5 % (at most 4 %) to
   the in-band modes by the first-order estimate of eq. [15]
   (``zeta_n ~ C'_nn / (2 omega_n)``): ``C' = Phi^T C Phi`` (eq. [14]) is
   not diagonal and the complex modes are genuinely complex.
5. Weak mode: one in-band mode's shape is turned (within the span of itself
   and a few modes above the band, keeping ``Phi^T M Phi = I``) to ``eps``
   times its amplitude at every drive point and to rest at the dashpots'
   DOFs (placed where it moves least): a classical mode whose residues
   ``psi_j psi_k`` are small in every FRF.
6. Close pair: the upper mode of one slot sits 1-2 half-power bandwidths
   ``2 zeta f`` above the lower.
7. The pair's spacing and the weak mode's level (its largest accelerance
   peak 20-26 dB below the median of the other modes') are then corrected
   a few times on the complex modes of the assembled ``M, C, K``; the
   coupling through the dashpots leaves some pairs closer than one
   bandwidth (:func:`describe` reports what was reached).

References
----------
A. A. Popov, Z. Geng, "Modelling of vibration damping in pneumatic tyres",
Vehicle System Dynamics 43 (Suppl.), 2005, 145-155: eq. [1] (the system),
[4]-[10] (complex modes and their FRF), [14]-[15] (modal damping matrix and
the small-damping pole); restated in the project's spec ``radial-damping.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from tyredamp.mechanics import MCKSystem, rayleigh_coefficients
from tyredamp.modal.statistics.indicators import modal_phase_collinearity

#: smallest relative spacing of the in-band slots (natural frequency ratio)
MIN_RATIO = 1.06
#: lowest and highest in-band slot, fractions of the band's upper end
BAND_LO, BAND_HI = 0.04, 0.92


@dataclass(frozen=True)
class PhysicalSystem:
    """A damped MCK structure with its measured points and designed features.

    Attributes
    ----------
    system : MCKSystem
        ``M`` (kg), ``C`` (N s/m), ``K`` (N/m), each (n_dof, n_dof).
    outputs, inputs : ndarray of int, shape (n_out,), (n_in,)
        Measured DOFs (0-based, ascending) and the drive points (a subset).
    f_hi : float
        Upper end of the band in Hz; exactly ``n_modes`` modes lie below it.
    in_band : ndarray of int, shape (n_modes,)
        Indices of the in-band modes in ``system.complex_modes()`` (ascending).
    pair : (int, int)
        The close pair, positions in ``in_band``.
    weak : int
        The weak mode, position in ``in_band``.
    eps : float
        Its amplitude at the drive points relative to the untuned shape.
    info : dict
        Figures of the drawn system (:func:`describe`).
    """

    system: MCKSystem
    outputs: NDArray[np.intp]
    inputs: NDArray[np.intp]
    f_hi: float
    in_band: NDArray[np.intp]
    pair: tuple[int, int]
    weak: int
    eps: float
    info: dict[str, Any] = field(default_factory=dict)


def _network(n: int, rng: np.random.Generator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Masses (kg) and stiffness (N/m) of a random chain with extra couplings and ground springs."""
    m = rng.uniform(0.5, 2.0, n)
    k = np.zeros((n, n))

    def spring(i: int, j: int | None, s: float) -> None:
        k[i, i] += s
        if j is not None:
            k[j, j] += s
            k[i, j] -= s
            k[j, i] -= s

    for i in range(n - 1):
        spring(i, i + 1, rng.uniform(0.5, 2.0) * 1e5)
    for _ in range(max(1, n // 3)):
        i, j = rng.choice(n, 2, replace=False)
        spring(int(i), int(j), rng.uniform(0.1, 0.5) * 1e5)
    for i in rng.choice(n, max(2, n // 8), replace=False):
        spring(int(i), None, rng.uniform(0.05, 0.2) * 1e5)
    return m, k


def _slots(n_slots: int, f_hi: float, rng: np.random.Generator) -> NDArray[np.float64]:
    """``n_slots`` ascending frequencies (Hz) in ``[BAND_LO, BAND_HI] f_hi``, ratios >= MIN_RATIO.

    ``f_(i+1) = MIN_RATIO f_i + e_i`` from ``f_0`` in 1-1.5 ``BAND_LO f_hi`` to
    ``f_N`` in 0.92-1 ``BAND_HI f_hi``, the increments ``e_i >= 0`` in
    proportion to Dirichlet shares ``d_i``, scaled so that the last lands on
    ``f_N`` (``sum_i e_i MIN_RATIO^(N-1-i) = f_N - f_0 MIN_RATIO^N``): a
    roughly even density in frequency, as a one-dimensional structure has,
    and no two slots closer than the ratio.
    """
    n = n_slots - 1
    lo = BAND_LO * f_hi * rng.uniform(1.0, 1.5)
    hi = BAND_HI * f_hi * rng.uniform(0.92, 1.0)
    budget = hi - lo * MIN_RATIO**n
    if budget < 0:
        raise ValueError(f"n_modes: {n_slots + 1} modes do not fit in the band {MIN_RATIO} apart")
    d = rng.dirichlet(np.ones(n))
    e = budget * d / np.sum(d * MIN_RATIO ** (n - 1 - np.arange(n)))
    f = [lo]
    for step in e:
        f.append(MIN_RATIO * f[-1] + step)
    return np.asarray(f)


def _above(
    f_net: NDArray[np.float64], f_hi: float, rng: np.random.Generator
) -> NDArray[np.float64]:
    """The network's frequencies ``f_net`` (ascending, Hz) moved above the band, ratios kept.

    The lowest goes to 1.1-1.3 ``f_hi``; a ratio over 8 ``f_hi`` to the lowest is compressed
    (log-affine) so that the highest stays below 8 ``f_hi`` of it.
    """
    lo = rng.uniform(1.1, 1.3) * f_hi
    x = np.log(f_net / f_net[0])
    top = np.log(8.0)
    if x[-1] > top:
        x = x * top / x[-1]
    return np.asarray(lo * np.exp(x))


def _drive_points(
    phi: NDArray[np.float64], outputs: NDArray[np.intp], modes: NDArray[np.intp], n_in: int
) -> NDArray[np.intp]:
    """``n_in`` outputs chosen greedily to maximise the weakest mode's best drive amplitude.

    Amplitude of mode ``n`` at DOF ``k``: ``|phi_kn|`` over the RMS of ``phi_n`` over the outputs.
    """
    a = np.abs(phi[np.ix_(outputs, modes)])
    a = a / np.sqrt(np.mean(a**2, axis=0))
    chosen: list[int] = []
    best = np.zeros(modes.size)
    for _ in range(n_in):
        score = np.min(np.maximum(best[None, :], a), axis=1)
        score[chosen] = -1.0
        k = int(np.argmax(score))
        chosen.append(k)
        best = np.maximum(best, a[k])
    return np.sort(outputs[chosen])


def _weaken(
    q: NDArray[np.float64],
    m: NDArray[np.float64],
    w: int,
    partners: NDArray[np.intp],
    points: NDArray[np.intp],
    scale: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Orthonormal ``q = M^1/2 Phi`` with column ``w`` scaled by ``scale`` at ``points``.

    Within ``S = q[:, [w, *partners]]`` the new column ``S a`` (``|a| = 1``)
    meets ``phi_kw' = scale_k phi_kw`` at every point ``k`` and keeps the
    largest share ``a_0`` of the old shape; the partners become an
    orthonormal basis of the rest of ``span S``, so ``q`` stays orthonormal
    and every other column is unchanged. Needs ``len(partners) >= len(points)``.
    """
    cols = np.concatenate([[w], partners])
    s = q[:, cols]
    b = s[points] / np.sqrt(m[points])[:, None]  # phi at the points of each column
    a_p = np.linalg.lstsq(b, scale * b[:, 0], rcond=None)[0]  # minimum norm: a_p is in row(b)
    null = sla.null_space(b)
    rest = 1.0 - float(a_p @ a_p)
    if rest < 0:
        raise ValueError("_weaken: the drive amplitudes cannot be reached in this span")
    z = null[0] / np.linalg.norm(null[0])
    a = a_p + np.sqrt(rest) * null @ z
    basis = np.linalg.qr(np.column_stack([a, np.eye(cols.size)]))[0][:, : cols.size]
    basis[:, 0] = a  # qr's first column is +-a
    out = q.copy()
    out[:, cols] = s @ basis
    return out


def _dashpots(
    allowed: NDArray[np.intp], n_dash: int, rng: np.random.Generator
) -> list[tuple[int, int | None, float]]:
    """``n_dash`` dashpots (DOF, other DOF or ground, relative strength 0.3-1) among ``allowed``."""
    out: list[tuple[int, int | None, float]] = []
    for _ in range(n_dash):
        i, j = (int(x) for x in rng.choice(allowed, 2, replace=False))
        out.append((i, j if rng.random() < 0.5 else None, float(rng.uniform(0.3, 1.0))))
    return out


def _dashpot_matrix(n: int, pots: list[tuple[int, int | None, float]]) -> NDArray[np.float64]:
    c = np.zeros((n, n))
    for i, j, s in pots:
        c[i, i] += s
        if j is not None:
            c[j, j] += s
            c[i, j] -= s
            c[j, i] -= s
    return c


def _modal_diagonal(phi: NDArray[np.float64], c: NDArray[np.float64]) -> NDArray[np.float64]:
    """``C'_nn = phi_n^T C phi_n`` (Popov & Geng eq. [14]'s diagonal), shape (m,)."""
    return np.asarray(np.einsum("in,ij,jn->n", phi, c, phi))


def _partners(phi: NDArray[np.float64], points: NDArray[np.intp], n_band: int) -> NDArray[np.intp]:
    """Three modes above the band per point (while there are): the largest amplitudes there."""
    a = np.abs(phi[:, n_band:]) / np.sqrt(np.mean(phi[:, n_band:] ** 2, axis=0))
    out: list[int] = []
    for _ in range(3):
        for k in points:
            if len(out) == a.shape[1]:
                break
            row = a[k].copy()
            row[out] = -1.0
            out.append(int(np.argmax(row)))
    return np.asarray(out, dtype=np.intp) + n_band


def _weak_layout(
    m: NDArray[np.float64],
    phi0: NDArray[np.float64],
    outputs: NDArray[np.intp],
    n_modes: int,
    c: int,
    n_in: int,
    n_dash: int,
    rng: np.random.Generator,
) -> tuple[
    int, NDArray[np.intp], list[tuple[int, int | None, float]], NDArray[np.intp], NDArray[np.intp]
]:
    """The weak mode, the drive points, the dashpots and the turn's points and partners.

    The drive points excite every other in-band mode (:func:`_drive_points`);
    the dashpots sit where the weak mode moves least (its quietest third of
    DOFs, none at a drive point). The weak mode is then turned (:func:`_weaken`)
    to ``eps`` times its amplitude at the drive points and to rest at the
    dashpots' DOFs, so that ``C phi_w = (alpha M + beta K) phi_w``: a classical
    mode whose peaks scale with ``eps``. Candidates (not the pair ``c, c + 1``)
    are tried in random order until the turn is possible for every ``eps`` in
    [0, 1]; if none is, the last one is kept without the rest at the dashpots.
    Returns ``weak, inputs, dashpots, points, partners``.
    """
    band = np.arange(n_modes)
    q0 = np.sqrt(m)[:, None] * phi0
    n = m.size
    for weak in rng.permutation(band[(band != c) & (band != c + 1)]):
        inputs = _drive_points(phi0, outputs, band[band != weak], n_in)
        quiet = np.argsort(np.abs(phi0[:, weak]))[: max(n_in + 2, n // 3)]
        pots = _dashpots(np.setdiff1d(quiet, inputs), n_dash, rng)
        still = np.setdiff1d([d for i, j, _ in pots for d in (i, j) if d is not None], inputs)
        points = np.concatenate([inputs, still]).astype(np.intp)
        partners = _partners(phi0, points, n_modes)
        try:  # |a_p|^2 is a convex quadratic in eps: its ends decide
            for eps in (0.0, 1.0):
                scale = np.where(np.arange(points.size) < n_in, eps, 0.0)
                _weaken(q0, m, int(weak), partners, points, scale)
        except ValueError:
            continue
        return int(weak), inputs, pots, points, partners
    return int(weak), inputs, pots, inputs, _partners(phi0, inputs, n_modes)


def _tuned(
    m: NDArray[np.float64], phi: NDArray[np.float64], f_hz: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``K = M Phi diag(omega^2) Phi^T M`` (N/m): undamped modes ``Phi`` at ``f_hz``.

    With ``Phi^T M Phi = I`` this is the pencil with ``K Phi = M Phi diag(omega^2)``
    (Popov & Geng eq. [2]'s modes).
    """
    mp = m[:, None] * phi
    k = (mp * (2 * np.pi * f_hz) ** 2) @ mp.T
    return np.asarray(0.5 * (k + k.T))


def _pair_and_weak(
    system: MCKSystem,
    in_band: NDArray[np.intp],
    pair: tuple[int, int],
    weak: int,
    outputs: NDArray[np.intp],
    inputs: NDArray[np.intp],
) -> tuple[float, float]:
    """The pair's spacing in mean half-power bandwidths ``2 zeta f`` and the weak mode's
    largest accelerance peak below the median of the others' (dB), from the complex modes."""
    cm = system.complex_modes()
    f, z = cm.frequency_hz[in_band], cm.damping_ratio[in_band]
    i, j = pair
    bw = float((f[j] - f[i]) / np.mean(2 * z[[i, j]] * f[[i, j]]))
    p = cm.poles[in_band]
    psi_o, psi_i = cm.psi[np.ix_(outputs, in_band)], cm.psi[np.ix_(inputs, in_band)]
    db = mode_peak_snr_db(p, psi_o, psi_i, np.ones((outputs.size, inputs.size, 1)), 0.0)
    return bw, float(np.median(np.delete(db, weak)) - db[weak])


def physical_system(
    n_out: int, n_in: int, n_modes: int, seed: int = 0, f_hi: float = 200.0
) -> PhysicalSystem:
    """A random non-proportionally damped structure with ``n_modes`` modes below ``f_hi``.

    Construction in the module docstring: network, tuning, drive points,
    Rayleigh damping plus dashpots, a weak mode, a close pair, corrections.

    Parameters
    ----------
    n_out : int
        Measured DOFs (>= 1); the structure has ``max(n_out + max(2, n_out // 4),
        n_modes + n_in + 2 n_dash + 4)`` DOFs with ``n_dash = 2 + n_modes // 10``
        dashpots, the rest unmeasured.
    n_in : int
        Drive points, among the outputs (1 <= n_in <= n_out).
    n_modes : int
        Modes in ``(0, f_hi]``, 4 to 47 (the band's slots 6 % apart).
    seed : int
        Seed of everything drawn.
    f_hi : float
        Upper end of the band in Hz.

    Returns
    -------
    PhysicalSystem
    """
    if not 1 <= n_in <= n_out:
        raise ValueError(f"n_in: expected 1..n_out = {n_out} drive points, got {n_in}")
    if n_modes < 4:
        raise ValueError(f"n_modes: expected at least 4 modes in the band, got {n_modes}")
    rng = np.random.default_rng(seed)
    n_dash = 2 + n_modes // 10
    n = max(n_out + max(2, n_out // 4), n_modes + n_in + 2 * n_dash + 4)
    m, k0 = _network(n, rng)
    lam, phi0 = sla.eigh(k0, np.diag(m))
    slots = _slots(n_modes - 1, f_hi, rng)
    c = int(rng.integers(1, n_modes - 2))  # the pair's slot: neither the first nor the last
    f_design = np.concatenate(
        [
            slots[: c + 1],
            slots[c : c + 1],
            slots[c + 1 :],
            _above(np.sqrt(lam[n_modes:]), f_hi, rng),
        ]
    )
    outputs = np.sort(rng.choice(n, n_out, replace=False)).astype(np.intp)
    weak, inputs, pots, points, partners = _weak_layout(
        m, phi0, outputs, n_modes, c, n_in, n_dash, rng
    )
    # damping: Rayleigh at the band's ends plus dashpots scaled on the in-band modes (eq. [15])
    alpha, beta = rayleigh_coefficients(
        BAND_LO * f_hi, rng.uniform(0.004, 0.012), BAND_HI * f_hi, rng.uniform(0.004, 0.012)
    )
    cd = _dashpot_matrix(n, pots)
    w = 2 * np.pi * f_design[:n_modes]  # the pair's upper mode still at the lower one's slot
    z_d = np.delete(_modal_diagonal(phi0[:, :n_modes], cd) / (2 * w), weak)
    cd *= min(rng.uniform(0.006, 0.015) / np.mean(z_d), 0.04 / np.max(z_d))
    zeta_c = (alpha + beta * w[c] ** 2 + float(phi0[:, c] @ cd @ phi0[:, c])) / (2 * w[c])
    # goals on the complex modes, first guesses from eq. [15] and the untouched weak mode,
    # then a few multiplicative corrections (the pair's coupling moves its spacing)
    goal_bw, goal_db = rng.uniform(1.0, 2.0), rng.uniform(20.0, 26.0)
    delta_max = 0.5 * (f_design[c + 2] / f_design[c] - 1)
    delta, eps = min(goal_bw * 2 * zeta_c, delta_max), 1.0
    sm = np.sqrt(m)
    for _ in range(8):
        scale = np.where(np.arange(points.size) < inputs.size, eps, 0.0)
        phi = _weaken(sm[:, None] * phi0, m, weak, partners, points, scale) / sm[:, None]
        f_design[c + 1] = f_design[c] * (1 + delta)
        k = _tuned(m, phi, f_design)
        cmat = alpha * np.diag(m) + beta * k + cd
        system = MCKSystem(np.diag(m), 0.5 * (cmat + cmat.T), k)
        in_band = np.flatnonzero(system.complex_modes().frequency_hz <= f_hi).astype(np.intp)
        if in_band.size != n_modes:  # the margins of the design make this impossible
            raise RuntimeError(f"physical_system: {in_band.size} modes in the band, not {n_modes}")
        bw, below = _pair_and_weak(system, in_band, (c, c + 1), weak, outputs, inputs)
        if abs(bw / goal_bw - 1) < 0.05 and abs(below - goal_db) < 1.0:
            break
        delta = min(delta * goal_bw / max(bw, 0.1), delta_max)
        eps = min(1.0, eps * 10 ** ((below - goal_db) / 20))
    ps = PhysicalSystem(system, outputs, inputs, f_hi, in_band, (c, c + 1), weak, eps)
    ps.info.update(describe(ps))
    return ps


def describe(ps: PhysicalSystem) -> dict[str, Any]:
    """Figures of the drawn structure (in-band modes unless stated).

    Keys: ``n_dof``; ``zeta_min``, ``zeta_max`` (damping ratios); ``mpc_median``,
    ``mpc_min`` (modal phase collinearity of the shapes at the outputs: 1 for
    a real mode); ``offdiag_share`` (``||offdiag C'||_F / ||C'||_F`` of the
    modal damping matrix eq. [14] over the in-band undamped modes: 0 for
    proportional damping); ``pair_hz`` and ``pair_bandwidths`` (the close
    pair's natural frequencies and their spacing over the mean half-power
    bandwidth ``2 zeta f``); ``weak_hz``, ``weak_eps`` (the weak mode and its
    drive amplitude relative to the untuned shape), ``weak_below_median_db``
    (its largest accelerance peak below the median of the other modes', dB).
    """
    cm = ps.system.complex_modes()
    f, z = cm.frequency_hz[ps.in_band], cm.damping_ratio[ps.in_band]
    mpc = modal_phase_collinearity(cm.psi[np.ix_(ps.outputs, ps.in_band)])
    n_band = ps.in_band.size
    cp = ps.system.modal_damping()[:n_band, :n_band]  # undamped modes ascending: the band first
    off = cp - np.diag(np.diag(cp))
    bw, below = _pair_and_weak(ps.system, ps.in_band, ps.pair, ps.weak, ps.outputs, ps.inputs)
    return {
        "n_dof": ps.system.n_dof,
        "zeta_min": float(z.min()),
        "zeta_max": float(z.max()),
        "mpc_median": float(np.median(mpc)),
        "mpc_min": float(mpc.min()),
        "offdiag_share": float(np.linalg.norm(off) / np.linalg.norm(cp)),
        "pair_hz": [float(f[ps.pair[0]]), float(f[ps.pair[1]])],
        "pair_bandwidths": bw,
        "weak_hz": float(f[ps.weak]),
        "weak_eps": ps.eps,
        "weak_below_median_db": below,
    }


def mode_peak_snr_db(
    poles: NDArray[np.complex128],
    psi_out: NDArray[np.complex128],
    psi_in: NDArray[np.complex128],
    exact: NDArray[np.complex128],
    snr_db: float,
    kind: str = "accelerance",
) -> NDArray[np.float64]:
    """Each mode's largest resonance peak over the noise of its FRF, in dB, shape (m,).

    The term of mode ``n`` in FRF ``jk`` (Popov & Geng eq. [10]) at
    ``omega = Omega_n``: ``|psi_jn psi_kn| / sigma_n`` (receptance, the
    conjugate term left out), times ``Omega_n`` (mobility) or ``Omega_n^2``
    (accelerance); the noise's standard deviation of ``perf_common.add_noise``:
    ``rms_f |H_jk| 10^(-SNR/20)`` from the noise-free FRFs ``exact`` (n_out,
    n_in, n_freq). The largest ratio over the FRFs, in dB.
    """
    sigma, omega = -poles.real, poles.imag
    power = {"receptance": 0, "mobility": 1, "accelerance": 2}[kind]
    peak = np.abs(psi_out[:, None, :] * psi_in[None, :, :]) * (omega**power / sigma)
    noise = np.sqrt(np.mean(np.abs(exact) ** 2, axis=-1)) * 10 ** (-snr_db / 20)
    return np.asarray(20 * np.log10(np.max(peak / noise[:, :, None], axis=(0, 1))))
