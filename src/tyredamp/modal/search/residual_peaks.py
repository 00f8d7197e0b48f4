"""Where a fit's residual holds structure a missed mode could explain.

The residual search (:func:`~tyredamp.modal.search.search.residual_search`) starts
trial modes at the peaks of the residual power per line, summed over the FRFs
in units of each output's noise variance (a mode indicator on the residual).
A missed mode of damping ratio ``zeta`` at ``f`` leaves its residual power
spread over its half-power band ``f +- zeta f``, which holds one line or a
hundred depending on the damping and the line spacing. So the excess over
the noise is summed over windows matched to half-power bands of several
damping ratios (a matched filter per scale, its width proportional to the
frequency), and a line is a candidate when one of these sums stands out of
the noise's own scatter and could hold a mode that passes the test: the cost
drop of a mode fitted there is at least the excess within its band (the mode
test's statistic ``T``, :mod:`tyredamp.modal.statistics.stats`).

The noise level of a line is the mean of the residual power under noise,
estimated robustly from its median: the residual power of a line is a sum of
``K`` squared complex residuals in units of their variance, about
``chi2(2K) / 2`` under noise, whose median lies below its mean (0.69 of it for
``K = 1``); the median is scaled by that ratio so that sums over wide windows
carry no bias.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...mechanics.modal_sum import pole_from_frequency_damping
from ..fit._basis import factors, residual_lines, residual_power
from ..fit.fit import FitResult, ModalFitter
from ..statistics.stats import chi2_isf

__all__ = [
    "ResidualPeaks",
    "ScanGrid",
    "coherent_scan",
    "local_ratio",
    "model_of",
    "power_of",
    "rank_one_statistic",
    "residual_peaks",
    "residual_view",
    "room",
    "scan_of",
]

#: damping ratios of the windows, relative to the typical damping of the modes
SCALES = (0.25, 0.5, 1.0, 2.0, 4.0)
#: narrowest window (lines either side of the centre)
MIN_HALF = 2
#: a window's excess must stand this many of its noise standard deviations out
Z_NOISE = 3.0
#: and be at least this share of the mode test's threshold (a mode fitted there
#: lowers the cost by more than the excess in its band, so a generous screen)
SHARE = 0.25


@dataclass(frozen=True)
class ResidualPeaks:
    """Candidate frequencies (Hz), best first, and the residual's excess over the
    noise per line (units of the noise variance) for :func:`room`."""

    freq: NDArray[np.float64]
    excess: NDArray[np.float64]


def noise_mean(pw: NDArray[np.float64], k_terms: int) -> float:
    """Mean residual power per line under noise from the median of ``pw``, whose
    lines are ``chi2(2 k_terms) / 2`` distributed (up to a scale) under noise."""
    k2 = 2 * max(int(k_terms), 1)
    ratio = k2 / chi2_isf(0.5, k2)
    return float(np.median(pw)) * ratio


def _window_sums(
    c: NDArray[np.float64], half: NDArray[np.intp], i0: int = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sums of the series whose cumulative sum (with a leading 0) is ``c`` over
    ``[i - half_i, i + half_i]`` (clipped to the lines) for the lines ``i = i0,
    i0 + 1, ...`` (one per entry of ``half``), and the window lengths."""
    n = c.size - 1
    i = np.arange(i0, i0 + half.size)
    a = np.clip(i - half, 0, n)
    b = np.clip(i + half + 1, 0, n)
    return c[b] - c[a], (b - a).astype(np.float64)


def _peaks(score: NDArray[np.float64]) -> NDArray[np.intp]:
    """Local maxima of ``score`` where it is finite, best first (a line is one when
    it exceeds its left neighbour and is not below its right one; the ends count
    their missing neighbour as ``-inf``)."""
    fin = np.isfinite(score)
    sc = np.where(fin, score, -1e300)
    peak = fin
    peak[1:] &= sc[1:] > sc[:-1]
    peak[:-1] &= sc[:-1] >= sc[1:]
    idx = np.flatnonzero(peak)
    return np.asarray(idx[np.argsort(-sc[idx])], dtype=np.intp)


#: lines per block of the matched-window score of :func:`residual_peaks` (its
#: temporaries do not grow with the lines)
PEAK_BLOCK = 1 << 16


def residual_peaks(
    f: NDArray[np.float64],
    pw: NDArray[np.float64],
    k_terms: int,
    zeta0: float,
    threshold: float,
    n_max: int,
) -> ResidualPeaks:
    """The lines where a missed mode could sit, best first (module docstring).

    ``f`` (n,) the lines (Hz, uniform or not), ``pw`` (n,) the residual power
    per line in units of the noise variance summed over ``k_terms`` FRFs,
    ``zeta0`` the typical damping ratio of the modes, ``threshold`` the mode
    test's. Two lists, taken in turn: the local maxima of the residual power
    over 5 lines whose excess over the median exceeds ``SHARE * threshold``
    (largest first; narrow structure), and the local maxima of the
    standardised excess over windows matched to half-power bands of
    ``SCALES`` times ``zeta0`` where that excess exceeds ``Z_NOISE`` noise
    standard deviations and ``SHARE * threshold`` (most significant first;
    broad structure). Peaks within 1 % of an earlier one are the same
    structure. At most ``n_max``. The excess returned (for :func:`room`) is
    over the median, a generous bound of the room a mode has.
    """
    f = np.asarray(f, dtype=np.float64)
    pw = np.asarray(pw, dtype=np.float64)
    if pw.size < 3:
        return ResidualPeaks(np.zeros(0), pw - np.median(pw) if pw.size else pw)
    # narrow: 5 lines over the median
    k = min(5, pw.size)
    sm = np.convolve(pw, np.ones(k) / k, mode="same")
    sm[~(k * (sm - np.median(sm)) > SHARE * threshold)] = -np.inf
    narrow = list(_peaks(sm))
    del sm
    # taken from the front (deques: a list's pop(0) moves the rest, quadratic in the
    # peaks of a long record)
    lists = [deque(narrow), deque(_peaks(_broad_score(f, pw, k_terms, zeta0, threshold)))]
    out: list[float] = []
    while (lists[0] or lists[1]) and len(out) < n_max:
        for lst in lists:
            while lst:
                fi = float(f[lst.popleft()])
                if all(abs(fi - g) > 0.01 * g for g in out):
                    out.append(fi)
                    break
    return ResidualPeaks(np.asarray(out[:n_max]), pw - np.median(pw))


def _broad_score(
    f: NDArray[np.float64],
    pw: NDArray[np.float64],
    k_terms: int,
    zeta0: float,
    threshold: float,
) -> NDArray[np.float64]:
    """The standardised excess over the matched windows of :func:`residual_peaks`
    (``-inf`` where it is not significant), (n,), in blocks of :data:`PEAK_BLOCK` lines."""
    # broad: matched windows, excess over the noise mean (no bias in wide sums)
    mu = noise_mean(pw, k_terms)
    # the noise variance of one line's power, robustly: var of chi2(2K)/2 scaled as mu
    var_line = mu**2 / max(int(k_terms), 1)
    n = pw.size
    c = np.empty(n + 1)
    c[0] = 0.0
    np.cumsum(pw - mu, out=c[1:])
    score = np.full(n, -np.inf)
    for a in range(0, n, PEAK_BLOCK):
        b = min(a + PEAK_BLOCK, n)
        # np.gradient of the block with its neighbours: the same differences as of all lines
        lo, hi = max(a - 1, 0), min(b + 1, n)
        fb = f[a:b]
        dfl = np.gradient(f[lo:hi])[a - lo : a - lo + b - a] if n > 1 else np.ones(1)
        sb = score[a:b]
        for s in SCALES:
            half = np.maximum(np.round(s * zeta0 * fb / np.maximum(dfl, 1e-300)), MIN_HALF)
            e, w = _window_sums(c, half.astype(np.intp), a)
            z = e / np.sqrt(w * var_line)
            np.maximum(sb, np.where((z > Z_NOISE) & (e > SHARE * threshold), z, -np.inf), out=sb)
    return score


def room(f: NDArray[np.float64], excess: NDArray[np.float64], p: complex) -> float:
    """Residual power above the noise (units of the noise variance) within the
    half-power band ``+-2 zeta f`` of a candidate pole ``p`` (at least 5 lines)."""
    fc = abs(p.imag) / (2 * np.pi)
    z = -p.real / max(abs(p), 1e-300)
    half = max(2 * z * fc, 2.5 * (f[-1] - f[0]) / max(f.size - 1, 1))
    sel = (f >= fc - half) & (f <= fc + half)
    return float(np.sum(excess[sel]))


#: damping ratios of the coherent scan's trial poles, relative to the modes' typical
SCAN_SCALES = (0.5, 2.0)
#: half-width of a trial pole's window, in half-power half-widths (``zeta f``):
#: 92 % of the energy of its resonance lies within it
SCAN_HALF = 8.0
#: a grid point is a candidate when its statistic reaches this share of the threshold
SCAN_SHARE = 0.8
#: residual entries held whole by the scan (more: formed chunk by chunk)
SCAN_ENTRIES = 1 << 22
#: grid points per chunk (a window spans 2 SCAN_HALF grid steps: a chunk's lines
#: are about twice a window's) and most lines per window (more: strided)
SCAN_CHUNK = 32
SCAN_LINES = 8192


def _scan_statistic(
    e: NDArray[np.complex128], a: NDArray[np.complex128], n_in: int
) -> NDArray[np.float64]:
    """Rank-one statistic of each window column ``a`` (G, L) against the
    residual ``e`` (n_out, n_in, L): the largest squared singular value of
    ``<a, e_jk> / ||a||`` over outputs x inputs."""
    nrm2 = np.sum(a.real**2 + a.imag**2, axis=1)
    m = e.reshape(-1, e.shape[-1]) @ a.conj().T  # (K, G)
    return rank_one_statistic(m, nrm2, e.shape[0], n_in)


def rank_one_statistic(
    m: NDArray[np.complex128], nrm2: NDArray[np.float64], n_out: int, n_in: int
) -> NDArray[np.float64]:
    """The rank-one statistic of :func:`_scan_statistic` from its inner products
    ``m`` (n_out n_in, G) = ``<a_g, e_jk>`` (rows output-major) and the columns'
    squared norms ``nrm2`` (G,): sums over blocks of lines give the same."""
    g = m.shape[1]
    mg = m.T.reshape(g, n_out, n_in)
    if n_in == 1:
        top = np.sum(mg.real**2 + mg.imag**2, axis=(1, 2))
    else:
        top = np.linalg.svd(mg, compute_uv=False)[:, 0] ** 2
    return np.asarray(top / np.maximum(nrm2, 1e-300))


def _off_fitted(
    a: NDArray[np.complex128],
    inside: NDArray[np.bool_],
    s: NDArray[np.complex128],
    kap: NDArray[np.complex128],
    near: NDArray[np.complex128],
) -> NDArray[np.complex128]:
    """Each window column ``a`` (G, L) less its least-squares projection on the
    columns ``kappa / (s - p)`` of those of the fitted poles ``near`` whose
    damped frequency lies within its window (``inside``, G x L), over the
    window: what a pole there adds to a model that refits the
    nearby modes' residues (the statistic of a weak mode beside a strong one;
    without it the strong mode's column takes the weak one's share)."""
    if near.size == 0:
        return a
    b, lo, hi, own = _fitted_in_windows(inside, s, kap, near)
    c = (a @ b.conj().T) * own  # (G, m): <b_n, a_g> over the window (a is 0 outside)
    gram = _solvable(_window_gram(b, lo, hi), own)  # (G, m, m)
    sol = np.linalg.solve(gram, c[:, :, None])[:, :, 0]
    return np.asarray(a - np.where(inside, sol @ b, 0.0))


def _fitted_in_windows(
    inside: NDArray[np.bool_],
    s: NDArray[np.complex128],
    kap: NDArray[np.complex128],
    near: NDArray[np.complex128],
) -> tuple[NDArray[np.complex128], NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
    """The fitted poles' columns ``kappa / (s - p)`` (m, L), each window's first and
    last line (G,) and which poles' damped frequencies lie within it (G, m)."""
    b = kap[None, :] / (s[None, :] - near[:, None])
    has = inside.any(axis=1)
    lo = np.where(has, np.argmax(inside, axis=1), 0)
    hi = np.where(has, inside.shape[1] - 1 - np.argmax(inside[:, ::-1], axis=1), 0)
    wn = np.abs(near.imag)
    own = (wn[None, :] >= np.abs(s[lo])[:, None]) & (wn[None, :] <= np.abs(s[hi])[:, None])
    return b, lo, hi, own


def _sums_over_windows(
    w: NDArray[np.complex128], lo: NDArray[np.intp], hi: NDArray[np.intp]
) -> NDArray[np.complex128]:
    """Sums of ``w`` (..., L) over each window's lines ``[lo, hi]``, windows first
    (G, ...), from prefix sums over the lines."""
    pre = np.zeros((*w.shape[:-1], w.shape[-1] + 1), complex)
    np.cumsum(w, axis=-1, out=pre[..., 1:])
    return np.moveaxis(pre[..., hi + 1] - pre[..., lo], -1, 0)


def _window_gram(
    b: NDArray[np.complex128], lo: NDArray[np.intp], hi: NDArray[np.intp]
) -> NDArray[np.complex128]:
    """``<b_n, b_k>`` over each window's lines ``[lo, hi]`` (G, m, m)."""
    return _sums_over_windows(b.conj()[:, None, :] * b[None, :, :], lo, hi)


def _solvable(gram: NDArray[np.complex128], own: NDArray[np.bool_]) -> NDArray[np.complex128]:
    """The windows' Gram matrices (G, m, m) restricted to the poles within each
    window ``own`` (G, m): the others get a unit diagonal (their coefficient is 0),
    and a tiny ridge keeps two nearly equal columns solvable."""
    both = own[:, :, None] & own[:, None, :]
    eye = np.eye(own.shape[1], dtype=bool)[None, :, :]
    scale = np.max(np.abs(gram), axis=(1, 2), keepdims=True)
    gram = np.where(both, gram, 0.0) + np.where(eye & ~both, 1.0, 0.0)
    return np.asarray(gram + eye * (1e-12 * np.maximum(scale, 1e-300)))


def _rank_one_off_fitted(
    e: NDArray[np.complex128],
    a: NDArray[np.complex128],
    inside: NDArray[np.bool_],
    s: NDArray[np.complex128],
    kap: NDArray[np.complex128],
    near: NDArray[np.complex128],
    l_near: NDArray[np.complex128],
) -> NDArray[np.float64]:
    """The scan's statistic of each window column ``a`` (G, L) against the residual
    ``e`` (n_out, n_in, L) with the fitted modes ``near`` within the window
    refitted as the model holds them: rank-one residues ``psi_n l_n^T`` with
    their participation ``l_near`` (m, n_in) held, ``psi_n`` refitted (several
    inputs; :func:`_off_fitted` frees every input's coefficient, right for one).

    Per output ``j`` the data are a vector over inputs x lines; a fitted mode's
    column is ``l_n (x) b_n``, the trial's ``l (x) a`` with ``l`` free. With
    ``G = [(l_n^H l_k) <b_n, b_k>]``, ``H = [<b_n, a> conj(l_nk)]`` and ``C =
    G^-1 H``, the trial column off the fitted ones is linear in ``l``; its
    projection on output ``j`` is ``l^H z_j``, ``z_j = <a, e_j.> - C^H y_j``
    (``y_jn = sum_k conj(l_nk) <b_n, e_jk>``), its squared norm ``l^H N l``,
    ``N = ||a||^2 I - H^H C``. The statistic ``max_l sum_j |l^H z_j|^2 / l^H N
    l`` is the largest squared singular value of ``L^-1 Z``, ``N = L L^H``
    (the extra sum of squares of a rank-one residue, as
    :func:`_scan_statistic` without fitted modes)."""
    g = a.shape[0]
    n_out, n_in = e.shape[0], e.shape[1]
    x = (e.reshape(-1, e.shape[-1]) @ a.conj().T).T.reshape(g, n_out, n_in)
    nrm2 = np.sum(a.real**2 + a.imag**2, axis=1)
    eye_in = np.eye(n_in)[None, :, :]
    if near.size == 0:
        nmat = nrm2[:, None, None] * eye_in
        z = x
    else:
        b, lo, hi, own = _fitted_in_windows(inside, s, kap, near)
        beta = (a @ b.conj().T) * own  # (G, m): <b_n, a> over the window
        ll = l_near.conj() @ l_near.T  # (m, m): l_n^H l_k
        gram = _solvable(_window_gram(b, lo, hi) * ll[None, :, :], own)
        hmat = beta[:, :, None] * l_near.conj()[None, :, :]  # (G, m, n_in)
        cmat = np.linalg.solve(gram, hmat)
        # y[g, j, n] = sum_k conj(l_nk) <b_n, e_jk> over window g (prefix sums)
        # (one matrix product over the inputs: einsum's loop was 8 times slower)
        w = (l_near.conj() @ e.transpose(1, 0, 2).reshape(n_in, -1)).reshape(-1, n_out, e.shape[-1])
        w *= b.conj()[:, None, :]
        y = _sums_over_windows(w, lo, hi) * own[:, :, None]  # (G, m, n_out)
        z = x - np.einsum("gnk,gnj->gjk", cmat.conj(), y)
        nmat = nrm2[:, None, None] * eye_in - np.einsum("gnk,gnl->gkl", hmat.conj(), cmat)
        nmat = 0.5 * (nmat + nmat.conj().transpose(0, 2, 1))
    ridge = 1e-12 * np.maximum(nrm2, 1e-300)[:, None, None] * eye_in
    try:
        low = np.linalg.cholesky(nmat + ridge)
    except np.linalg.LinAlgError:  # a trial column inside the fitted ones' span
        ev, vec = np.linalg.eigh(nmat)
        low = vec * np.sqrt(np.maximum(ev, 1e-12 * np.maximum(nrm2, 1e-300)[:, None]))[:, None]
    wz = np.linalg.solve(low, z.transpose(0, 2, 1))  # (G, n_in, n_out)
    return np.asarray(np.linalg.svd(wz, compute_uv=False)[:, 0] ** 2)


def _scan_scale(
    fit: ModalFitter,
    f: NDArray[np.float64],
    z: float,
    resid: Callable[[slice], NDArray[np.complex128]],
    fitted: NDArray[np.complex128],
    l_fitted: NDArray[np.complex128] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """The scan's statistic on the grid of one damping ratio ``z``
    (:func:`coherent_scan`) and the grid's poles; ``resid(lines)`` gives the
    residual in units of the noise, ``fitted`` the fit's poles and ``l_fitted``
    (m, n_in) their participation vectors (several inputs: the fitted modes'
    rank-one residues, :func:`_rank_one_off_fitted`)."""
    n = f.size
    df = float(np.min(np.diff(f)))
    n_g = int(np.log(f[-1] / f[0]) / np.log1p(z)) + 2
    fg = f[0] * (1 + z) ** np.arange(n_g)
    idx = np.unique(np.clip(np.searchsorted(f, fg[fg <= f[-1]]), 0, n - 1))
    fg = f[idx]
    pg = pole_from_frequency_damping(fg, z)
    half = np.maximum(SCAN_HALF * z * fg, 3 * df)
    ia = np.searchsorted(f, fg - half)
    ib = np.searchsorted(f, fg + half, side="right")
    stride = max(1, -(-int(np.max(ib - ia)) // SCAN_LINES))
    t = np.empty(fg.size)
    fn = np.abs(fitted) / (2 * np.pi)
    for c0 in range(0, fg.size, SCAN_CHUNK):
        g = slice(c0, c0 + SCAN_CHUNK)
        la, lb = int(ia[g].min()), int(ib[g].max())
        sl = slice(la, lb, stride)
        s, kap, _ = factors(fit, sl)
        li = np.arange(la, lb, stride)
        inside = (li[None, :] >= ia[g, None]) & (li[None, :] < ib[g, None])
        a = np.where(inside, kap[None, :] / (s[None, :] - pg[g, None]), 0.0)
        sel = (fn >= f[la]) & (fn <= f[lb - 1])
        if l_fitted is not None and int(fit.n_in) > 1:
            t[g] = _rank_one_off_fitted(resid(sl), a, inside, s, kap, fitted[sel], l_fitted[sel])
            continue
        a_off = _off_fitted(a, inside, s, kap, fitted[sel])
        t[g] = _scan_statistic(resid(sl), a_off, int(fit.n_in))
    return t, pg


@dataclass(frozen=True)
class ScanGrid:
    """The coherent scan's statistic on its grids (:func:`coherent_scan`): trial
    poles (N,), their statistic (N,) and whether each is a local maximum of its
    grid (N,)."""

    poles: NDArray[np.complex128]
    stat: NDArray[np.float64]
    is_max: NDArray[np.bool_]

    def candidates(self, level: float, n_max: int) -> list[tuple[complex, float]]:
        """Local maxima whose statistic reaches ``level``, with it, largest first,
        one per 1 % of frequency, at most ``n_max``."""
        sel = np.flatnonzero(self.is_max & (self.stat >= level))
        out: list[tuple[complex, float]] = []
        for i in sel[np.argsort(-self.stat[sel])]:
            p = complex(self.poles[i])
            if all(abs(abs(p) - abs(q)) > 0.01 * abs(q) for q, _ in out):
                out.append((p, float(self.stat[i])))
            if len(out) >= n_max:
                break
        return out

    def support(self, f_hz: float, zeta: float) -> float:
        """Largest statistic of the grid points within ``zeta f`` of ``f_hz``
        (0 when none): what a mode started there can explain, about."""
        fg = np.abs(self.poles) / (2 * np.pi)
        near = np.abs(fg - f_hz) <= max(zeta, 1e-6) * f_hz
        return float(np.max(self.stat[near])) if np.any(near) else 0.0


def coherent_scan(
    fitter: ModalFitter,
    model: tuple[
        NDArray[np.complex128],
        NDArray[np.complex128],
        tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    ],
    s2: NDArray[np.float64],
    zeta0: float,
    whole: NDArray[np.complex128] | None = None,
) -> ScanGrid:
    """Where the residual holds a resonance coherent across the FRFs.

    The residual power per line (:func:`residual_peaks`) sums every FRF's
    residual incoherently: a mode near the threshold spread over many lines
    does not stand out of it. This scan is the mode test's own statistic for a
    pole held at each point of a grid: for a trial pole ``p`` (damping ratio
    ``zeta``, each of ``SCAN_SCALES`` times ``zeta0``; grid step ``zeta f``,
    at least a line), the residual of every FRF in units of its output's noise
    (``s2``) is projected on the pole's column ``kappa / (s - p)`` within
    ``SCAN_HALF`` half-widths, and the statistic is the largest squared
    singular value of those projections over outputs x inputs (a rank-one
    residue ``psi l^T``, as a mode has), the column taken off the columns of
    the fitted modes within the window: the cost drop of a mode held at ``p``
    with only its dominant term, the nearby modes' residues refitted (with
    several inputs as the model holds them, rank-one with their participation
    held, :func:`_rank_one_off_fitted`: freeing every input's coefficient took up
    most of a weak mode's share between two strong ones). ``model`` is the
    fit's ``(poles, residues (n_out, n_in, m), (upper, lower))``; ``whole``: the
    residual of every line in units of the noise when the caller formed it
    (:func:`residual_view`).
    """
    fit = fitter
    f = np.asarray(fit.f, dtype=np.float64)
    empty = ScanGrid(np.zeros(0, complex), np.zeros(0), np.zeros(0, bool))
    if f.size < 3 or not f[0] > 0:
        return empty
    poles, residues, terms = model
    inv = 1.0 / np.sqrt(np.maximum(np.asarray(s2, dtype=np.float64), 1e-300))
    if whole is None and fit.n_out * fit.n_in * f.size <= SCAN_ENTRIES:
        whole = _whole(fit, model, inv)

    def resid(sl: slice) -> NDArray[np.complex128]:
        if whole is not None:
            return whole[:, :, sl]
        return residual_lines(fit, poles, residues, terms, sl) * inv[:, None, None]

    # each fitted mode's participation: the row space of its rank-one residue
    l_fit = None
    res3 = np.asarray(residues)
    if fit.n_in > 1 and res3.ndim == 3 and res3.shape[-1] == np.size(poles):
        # R = u l^T = s1 u1 v1^H: l is proportional to the first row of V^H
        l_fit = np.linalg.svd(res3.transpose(2, 0, 1))[2][:, 0, :]
    pp, tt, mm = [], [], []
    for sc in SCAN_SCALES:
        z = float(np.clip(sc * zeta0, 1e-4, 0.1))
        t, pg = _scan_scale(fit, f, z, resid, np.asarray(poles, complex), l_fit)
        left = np.concatenate([[-np.inf], t[:-1]])
        right = np.concatenate([t[1:], [-np.inf]])
        pp.append(pg)
        tt.append(t)
        mm.append((t > left) & (t >= right))
    return ScanGrid(np.concatenate(pp), np.concatenate(tt), np.concatenate(mm))


def scan_of(fitter: ModalFitter, res: FitResult, zeta0: float) -> ScanGrid:
    """The coherent scan of the fit's residual (:func:`coherent_scan`)."""
    poles, residues, terms, s2 = model_of(fitter, res)
    return coherent_scan(fitter, (poles, residues, terms), s2, zeta0)


def model_of(
    fitter: ModalFitter, res: FitResult
) -> tuple[
    NDArray[np.complex128],
    NDArray[np.complex128],
    tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    NDArray[np.float64],
]:
    """A fit's model for the residual functions of :mod:`~tyredamp.modal.fit._basis`: poles,
    residues ``R = u l`` (n_out, n_in, m; u unscaled without drive points, or scaled),
    residual terms, and each output's noise variance (at least the fitter's floor)."""
    residues = res.psi_out[:, None, :] * res.psi_in[None, :, :]
    s2 = np.maximum(res.sigma_out**2, np.maximum(fitter.noise_floor**2, 1e-300))
    return res.poles, residues, (res.upper, res.lower), s2


def power_of(fitter: ModalFitter, res: FitResult) -> NDArray[np.float64]:
    """A fit's residual power per line in units of each output's noise, summed over
    the FRFs and weighted as the fit weights the lines (block by block)."""
    poles, residues, terms, s2 = model_of(fitter, res)
    return residual_power(fitter, poles, residues, terms, s2)


#: half-width of the lines around a mode whose residual gives its local ratio, in
#: half-power half-widths ``zeta f`` (at least LOCAL_LINES lines either side)
LOCAL_HALF = 2.0
LOCAL_LINES = 3


def local_ratio(
    f: NDArray[np.float64], pw: NDArray[np.float64], poles: NDArray[np.complex128]
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """The mean residual power per line ``pw`` within ``LOCAL_HALF`` half-widths
    of each pole (at least ``LOCAL_LINES`` lines either side) over its mean over
    the lines ``f`` (Hz), and the lines of each window."""
    mean = float(np.mean(pw)) if pw.size else 0.0
    df = float(np.median(np.diff(f))) if f.size > 1 else 1.0
    fc = np.abs(poles) / (2 * np.pi)
    half = np.maximum(LOCAL_HALF * -poles.real / (2 * np.pi), LOCAL_LINES * df)
    c = np.concatenate([[0.0], np.cumsum(pw)])
    i0 = np.searchsorted(f, fc - half)
    i1 = np.searchsorted(f, fc + half, side="right")
    n = np.maximum(i1 - i0, 1)
    return np.asarray((c[i1] - c[i0]) / n / max(mean, 1e-300)), np.asarray(n, dtype=np.intp)


def residual_view(
    fitter: ModalFitter, res: FitResult, zeta0: float
) -> tuple[ScanGrid, NDArray[np.float64]]:
    """The coherent scan of a fit's residual (:func:`scan_of`) and its residual power
    per line (n_f,) in units of each output's noise (:func:`power_of`): what one
    round of the residual search reads, formed once per fit. When the scan holds
    the residual of every line (``SCAN_ENTRIES``), the power is summed from it
    (one pass of the model over the lines instead of two)."""
    if fitter.n_out * fitter.n_in * fitter.n_f > SCAN_ENTRIES:
        return scan_of(fitter, res, zeta0), power_of(fitter, res)
    poles, residues, terms, s2 = model_of(fitter, res)
    inv = 1.0 / np.sqrt(np.maximum(s2, 1e-300))
    whole = _whole(fitter, (poles, residues, terms), inv)
    grid = coherent_scan(fitter, (poles, residues, terms), s2, zeta0, whole)
    # |e|^2 summed over the FRFs from the interleaved parts: one array of the lines
    parts = whole.reshape(-1, fitter.n_f).view(np.float64).reshape(-1, fitter.n_f, 2)
    return grid, np.einsum("jfr,jfr->f", parts, parts)


def _whole(fitter: ModalFitter, model: Any, inv: NDArray[np.float64]) -> NDArray[np.complex128]:
    """The residual of every line in units of each output's noise (``inv = 1 /
    sigma``), (n_out, n_in, n_f)."""
    poles, residues, terms = model
    e = residual_lines(fitter, poles, residues, terms, slice(0, fitter.n_f))
    e *= inv[:, None, None]
    return e
