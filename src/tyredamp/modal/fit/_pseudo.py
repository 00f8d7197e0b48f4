"""Pseudo-lines: the Gram blocks of the fits on a long record, with a cost per
evaluation that does not grow with the lines.

An evaluation of :meth:`~tyredamp.modal.fit.fit.ModalFitter.fit_added`
(:mod:`._added`) needs three sums over the lines ``w_k`` of products of the added
mode's columns ``b(w)`` (a rational function of ``w`` with its poles at ``w =
Omega + i sigma`` and ``w = -Omega + i sigma`` for the pole ``p = -sigma + i
Omega``) with things that do not change between evaluations: the fixed basis
``Phi_f``, the data ``Y`` and ``b`` itself,

    ``Phi_f^T B1 = sum_k Phi_f(w_k)^T b(w_k)``, ``B1^T Y = sum_k b(w_k)^T y_k``,
    ``B1^T B1 = sum_k b(w_k)^T b(w_k)``.

The lines are cut into bins of :data:`BIN_LINES` lines. On a bin ``[c - h, c +
h]`` whose Bernstein ellipse of parameter :data:`RHO_MIN` holds no pole of ``b``,
``b`` is replaced by its interpolant at :data:`NODES` Chebyshev points ``x_j``
(``b(w) = sum_j l_j(w) b(x_j)``, ``l_j`` the Lagrange polynomials, barycentric
form: Berrut & Trefethen, *Barycentric Lagrange interpolation*, SIAM Review 46
(2004), eqs. (4.2) and (5.3)), so that the sums become sums over the nodes:

    ``sum_k Phi_f(w_k)^T b(w_k) = sum_j Phit_j^T b(x_j)`` with ``Phit_j = sum_k
    l_j(w_k) Phi_f(w_k)`` (and ``Yt_j`` likewise), and ``sum_k f(w_k) = sum_j W_j
    f(x_j)`` with ``W_j = sum_k l_j(w_k)`` for ``f = b^T b`` (the real product of
    two complex columns, ``Re(conj(a) b)``, is on the real axis the analytic
    function ``(a(w) b~(w) + a~(w) b(w)) / 2``, ``b~(w) = conj(b(conj w))``,
    whose poles are those of ``b`` and their mirror images, as far from the bin).

``Yt`` and ``W`` are formed once per fitter (:meth:`ModalFitter._pseudo_lines
<tyredamp.modal.fit.fit.ModalFitter._pseudo_lines>`), ``Phit`` once per fixed part
(:func:`fixed_far`: on the far bins from ``Phi_f`` at the nodes, ``Phit = M
Phi_f(x)`` with ``M = L L^T``, ``L`` the bin's Lagrange rows, since ``Phi_f`` too
is smooth away from its poles; the near bins from their lines); an evaluation
forms ``b`` at the nodes of the far bins and on the lines of the near ones only
(:func:`gram_blocks`). The same sums give the Gram blocks of a full fit
(:func:`gram_full`: every mode's columns, the bins far from every pole) and the
inner products of a scan of the residual against trial columns
(:func:`scan_sums`). The error of the interpolant of a function analytic
inside the ellipse ``E_rho`` with ``|f| <= M`` there is at most ``4 M rho^-n /
(rho - 1)`` on the bin (Trefethen, *Approximation Theory and Approximation
Practice*, 2013, Theorem 8.2, stated for Chebyshev points of the second kind;
its aliasing argument, chapter 4 there, bounds the interpolant in points of the
first kind alike): with ``n = 32`` nodes and the poles outside ``E_6`` (double
poles and the factor ``(i w)^power`` of ``b^T b`` included) the sums agree with
those over the lines to rounding (``tests/test_modal_pseudo.py`` checks them
against the sums over the lines and a sum of ``1 / (i w_k - p)`` against its
closed form by the digamma function).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _basis
from ._state import FitterState

#: Chebyshev nodes per bin
NODES = 32
#: lines per bin (the last bin may be shorter)
BIN_LINES = 2048
#: a bin is far from a pole outside its Bernstein ellipse of this parameter
RHO_MIN = 6.0
#: fewest bins for pseudo-lines to pay (fewer: the sums over the lines)
MIN_BINS = 8
#: most far bins whose nodes are formed at once (the columns at the nodes of this many
#: bins take about the memory of one bin of lines: no array grows with the record)
FAR_BINS = 64


def _cached(memo: dict[int, Any], ell: NDArray[np.float64], fn: Any) -> Any:
    """``fn(ell)``, computed once per array ``ell`` (bins of uniformly spaced lines
    share theirs, :func:`_bin_lagrange`)."""
    key = id(ell)
    if key not in memo:
        memo[key] = fn(ell)
    return memo[key]


def _chunks(idx: NDArray[np.intp]) -> list[NDArray[np.intp]]:
    """``idx`` in pieces of at most :data:`FAR_BINS`."""
    return [idx[a : a + FAR_BINS] for a in range(0, idx.size, FAR_BINS)]


@dataclass(frozen=True)
class PseudoLines:
    """The pseudo-lines of a fixed part (module docstring).

    ``bins``: the lines of each bin; ``centre``, ``half`` (n_bins,): centre and
    half-width of each bin in rad/s; ``nodes`` (n_bins, NODES): the Chebyshev
    nodes in rad/s; ``weights`` (n_bins, NODES): ``W_j``; ``phi`` (n_in, n_bins,
    NODES, 2, q_f) and ``y`` (n_in, n_bins, NODES, 2, n_out): ``Phit`` and ``Yt``
    (unweighted data), real and imaginary part as the rows of the basis; ``ells``:
    each bin's Lagrange rows (:func:`_bin_lagrange`) when kept (the functions here
    form them again when needed: a few milliseconds, and no memory held between
    the fits).
    """

    bins: tuple[slice, ...]
    centre: NDArray[np.float64]
    half: NDArray[np.float64]
    nodes: NDArray[np.float64]
    weights: NDArray[np.float64]
    phi: NDArray[np.float64]
    y: NDArray[np.float64]
    ells: tuple[NDArray[np.float64], ...] = ()


def applies(fitter: FitterState) -> bool:
    """Do pseudo-lines apply to this fitter's trials? Complex modes, no line weights,
    a non-negative power of ``i w``, at least :data:`MIN_BINS` bins."""
    return (
        fitter.kind == "complex"
        and fitter.line_weights is None
        and fitter.power >= 0
        and fitter.n_f >= MIN_BINS * BIN_LINES
    )


def _cheb_nodes(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The ``n`` Chebyshev points of the first kind on [-1, 1], ``x_j = cos((2j + 1) pi /
    2n)``, and their barycentric weights ``(-1)^j sin((2j + 1) pi / 2n)`` (Berrut &
    Trefethen 2004, eq. (5.3), common factors dropped)."""
    t = (2 * np.arange(n) + 1) * np.pi / (2 * n)
    return np.asarray(np.cos(t), np.float64), np.asarray((-1.0) ** np.arange(n) * np.sin(t))


def lagrange(x: NDArray[np.float64], n: int = NODES) -> NDArray[np.float64]:
    """``l_j(x_k)`` (n, x.size) of the Chebyshev points of :func:`_cheb_nodes`
    (second barycentric formula, Berrut & Trefethen 2004, eq. (4.2)); a point
    that falls on a node gets that node's unit row."""
    xj, wj = _cheb_nodes(n)
    d = x[None, :] - xj[:, None]
    hit = d == 0.0
    d[hit] = 1.0
    q = wj[:, None] / d
    out = q / q.sum(axis=0, keepdims=True)
    cols = np.flatnonzero(hit.any(axis=0))
    if cols.size:
        out[:, cols] = hit[:, cols].astype(float)
    return out


def bernstein_rho(z0: NDArray[np.complex128]) -> NDArray[np.float64]:
    """Parameter ``rho = |z + sqrt(z - 1) sqrt(z + 1)|`` (the larger root) of the
    Bernstein ellipse through ``z0`` (points of the plane of [-1, 1])."""
    r = np.sqrt(z0 - 1.0) * np.sqrt(z0 + 1.0)
    return np.maximum(np.abs(z0 + r), np.abs(z0 - r))


def pseudo_lines(
    fitter: FitterState, phi_rows: Any = None, base: PseudoLines | None = None
) -> PseudoLines:
    """The pseudo-lines of the data and, with ``phi_rows``, of a fixed basis (module
    docstring; ``phi`` has no column without it). ``phi_rows(sl)`` returns the fixed
    basis's rows of the lines ``sl`` (``(k, f)`` rows, real and imaginary part
    interleaved, as :func:`~tyredamp.modal.fit._basis.basis_ek`); ``base``: the
    fitter's pseudo-lines of the data, whose bins, weights and ``Yt`` are reused."""
    return fixed_lines(fitter, phi_rows, base)[0]


def fixed_lines(
    fitter: FitterState, phi_rows: Any = None, base: PseudoLines | None = None
) -> tuple[PseudoLines, NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """:func:`pseudo_lines`, and the Gram blocks ``Phi_f^T Phi_f`` and ``Phi_f^T Y``
    (unweighted data) of the fixed basis summed over the lines in the same pass
    (None without ``phi_rows``). Groups of bins of equal length share one product
    with their Lagrange rows, which bins of uniformly spaced lines share
    (:func:`_bin_lagrange`)."""
    n_f, n_in, n_out = fitter.n_f, fitter.n_in, fitter.n_out
    if base is None:
        bins = tuple(slice(a, min(a + BIN_LINES, n_f)) for a in range(0, n_f, BIN_LINES))
        w0 = 2 * np.pi * fitter.f
        lo = np.array([w0[b.start] for b in bins])
        hi = np.array([w0[b.stop - 1] for b in bins])
        centre, half = (hi + lo) / 2, np.maximum((hi - lo) / 2, 1e-12 * np.maximum(hi, 1.0))
        nodes = centre[:, None] + half[:, None] * _cheb_nodes(NODES)[0][None, :]
    else:
        bins, centre, half, nodes = base.bins, base.centre, base.half, base.nodes
    ells = _bin_lagrange(2 * np.pi * fitter.f, bins, centre, half)
    sums: dict[int, NDArray[np.float64]] = {}
    weights = np.stack([_cached(sums, e, lambda e: e.sum(axis=1)) for e in ells])
    phi = y = gf = pf = None
    if base is not None:
        y = base.y
    for i0, i1 in _groups(bins, ells, 16 * n_in * (n_out + 64)):
        sl = slice(bins[i0].start, bins[i1 - 1].stop)
        if phi_rows is not None:
            rows = np.asarray(phi_rows(sl))
            g1, p1 = rows.T @ rows, _basis.rows_t_data(fitter, sl, rows)
            gf, pf = (g1, p1) if gf is None or pf is None else (gf + g1, pf + p1)
            if phi is None:
                phi = np.empty((n_in, len(bins), NODES, 2, rows.shape[1]))
            phi[:, i0:i1] = _moments(ells[i0], rows, n_in, i1 - i0)
        if base is None:
            if y is None:
                y = np.empty((n_in, len(bins), NODES, 2, n_out))
            y[:, i0:i1] = _moments(ells[i0], _basis.ydata(fitter, sl), n_in, i1 - i0)
    if phi is None:
        phi = np.zeros((n_in, len(bins), NODES, 2, 0))
    assert y is not None
    for a in (centre, half, nodes, weights, phi, y):
        a.flags.writeable = False
    got = PseudoLines(bins, centre, half, nodes, weights, phi, y)  # ells formed again
    return got, gf, pf


def fixed_far(
    fitter: FitterState,
    base: PseudoLines,
    phi_rows: Any,
    phi_at: Any,
    poles: NDArray[np.complex128],
) -> tuple[PseudoLines, NDArray[np.float64], NDArray[np.float64]]:
    """:func:`fixed_lines` of a fixed basis whose columns are smooth away from
    ``poles`` (rad/s; 0 for a column in negative powers of ``i w``), on the
    fitter's pseudo-lines of the data ``base``: on the bins far from every pole
    the basis too is its interpolant at the nodes, so that ``Phit_j = sum_i M_ji
    Phi_f(x_i)`` with ``M = L L^T`` (``L`` the bin's Lagrange rows), ``Phi_f^T Phi_f
    = sum_i W_i Phi_f(x_i)^T Phi_f(x_i)`` and ``Phi_f^T Y = sum_i Phi_f(x_i)^T Yt_i``
    (module docstring); the near bins from their lines. ``phi_rows(sl)``: the basis
    on the lines ``sl``; ``phi_at(fac)``: at the factors ``fac``
    (:func:`factors_at`)."""
    n_in, n_out = fitter.n_in, fitter.n_out
    near = np.zeros(base.centre.size, bool)
    for p in np.asarray(poles, complex).ravel():
        near |= near_bins(base, complex(p))
    ells = base.ells or tuple(
        _bin_lagrange(2 * np.pi * fitter.f, base.bins, base.centre, base.half)
    )
    mass: dict[int, NDArray[np.float64]] = {}
    phi = gf = pf = None
    for far in _chunks(np.flatnonzero(~near)):
        pn = np.asarray(phi_at(factors_at(fitter, base.nodes[far].ravel())))
        qf = pn.shape[1]
        mm = np.stack([_cached(mass, ells[i], lambda e: e @ e.T) for i in far])
        if phi is None:
            phi = np.empty((n_in, base.centre.size, NODES, 2, qf))
        x = pn.reshape(n_in, far.size, NODES, 2 * qf)
        phi[:, far] = np.matmul(mm[None], x).reshape(n_in, far.size, NODES, 2, qf)
        wr = np.broadcast_to(base.weights[far][None, :, :, None], (n_in, far.size, NODES, 2))
        g1, p1 = (pn * wr.reshape(-1, 1)).T @ pn, pn.T @ base.y[:, far].reshape(-1, n_out)
        gf, pf = (g1, p1) if gf is None or pf is None else (gf + g1, pf + p1)
    for i in np.flatnonzero(near):
        sl = base.bins[i]
        rows = np.asarray(phi_rows(sl))
        g1, p1 = rows.T @ rows, _basis.rows_t_data(fitter, sl, rows)
        gf, pf = (g1, p1) if gf is None or pf is None else (gf + g1, pf + p1)
        if phi is None:
            phi = np.empty((n_in, base.centre.size, NODES, 2, rows.shape[1]))
        phi[:, i : i + 1] = _moments(ells[i], rows, n_in, 1)
    assert phi is not None
    assert gf is not None
    assert pf is not None
    phi.flags.writeable = False
    got = PseudoLines(base.bins, base.centre, base.half, base.nodes, base.weights, phi, base.y)
    return got, gf, pf


def _moments(
    ell: NDArray[np.float64], rows: NDArray[np.float64], n_in: int, n_bins: int
) -> NDArray[np.float64]:
    """``sum_k l_j(w_k) x_k`` of the rows (``(k, f)``, parts interleaved) of ``n_bins``
    bins of equal length that share the Lagrange rows ``ell`` (NODES, nb), as
    (n_in, n_bins, NODES, 2, c)."""
    nb = ell.shape[1]
    c = rows.shape[1]
    x = rows.reshape(n_in, n_bins, nb, 2 * c)
    return np.matmul(ell, x).reshape(n_in, n_bins, NODES, 2, c)


def _bin_lagrange(
    w: NDArray[np.float64],
    bins: tuple[slice, ...],
    centre: NDArray[np.float64],
    half: NDArray[np.float64],
) -> list[NDArray[np.float64]]:
    """The Lagrange rows (NODES, nb) of each bin: one array shared by the bins whose
    lines lie, to rounding, at the same relative places (uniformly spaced lines:
    ``(w_k - c) / h`` equal to ``-1 + 2 k / (nb - 1)`` to 64 ulp of ``max(|c| / h,
    1)``, the rounding of the lines themselves), else the bin's own."""
    shared: dict[int, NDArray[np.float64]] = {}
    out = []
    for i, sl in enumerate(bins):
        x = (w[sl] - centre[i]) / half[i]
        nb = x.size
        grid = np.linspace(-1.0, 1.0, nb) if nb > 1 else np.zeros(1)
        tol = 64 * np.finfo(float).eps * max(abs(centre[i]) / half[i], 1.0)
        if np.max(np.abs(x - grid)) <= tol:
            if nb not in shared:
                shared[nb] = lagrange(grid)
            out.append(shared[nb])
        else:
            out.append(lagrange(x))
    return out


def _groups(
    bins: tuple[slice, ...], ells: list[NDArray[np.float64]], bytes_per_line: int
) -> list[tuple[int, int]]:
    """Runs ``[i0, i1)`` of consecutive bins that share their Lagrange rows, of at most
    :data:`~tyredamp.modal.fit._basis.BLOCK_BYTES` of rows (at least one bin)."""
    most = max(1, _basis.BLOCK_BYTES // max(bytes_per_line * BIN_LINES, 1))
    out = []
    i0 = 0
    for i in range(1, len(bins) + 1):
        if i == len(bins) or ells[i] is not ells[i0] or i - i0 >= most:
            out.append((i0, i))
            i0 = i
    return out


def near_bins(pl: PseudoLines, pole: complex) -> NDArray[np.bool_]:
    """Bins (n_bins,) whose ellipse ``E_RHO_MIN`` holds a pole of the added columns:
    ``w = Omega + i sigma`` or ``-Omega + i sigma`` for ``p = -sigma + i Omega``."""
    near = np.zeros(pl.centre.size, bool)
    for wp in (complex(pole.imag, -pole.real), complex(-pole.imag, -pole.real)):
        near |= bernstein_rho(np.asarray((wp - pl.centre) / pl.half, np.complex128)) < RHO_MIN
    return near


def factors_at(fitter: FitterState, w: NDArray[np.float64]) -> tuple[Any, Any, Any]:
    """``s = i w``, ``kappa = (i w)^power`` and ``kappa_low`` at the frequencies ``w``
    (rad/s), as :func:`~tyredamp.modal.fit._basis.factors` (no line weights)."""
    p = fitter.power
    i_pow = (1.0 + 0j, 1j, -1.0 + 0j, -1j)
    s = 1j * w
    kappa = i_pow[p % 4] * w**p
    kappa_low = i_pow[(p - 2) % 4] * w ** float(p - 2)
    return s, kappa, kappa_low


def gram_full(
    fitter: FitterState,
    pl: PseudoLines,
    cols: Any,
    poles: NDArray[np.complex128],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``B^T B`` and ``B^T Y`` (data unweighted) of the columns ``B`` of a full fit
    (every mode and the residual terms), from the pseudo-lines of the bins far from
    every pole in ``poles`` (rad/s; include 0 for a column in negative powers of
    ``i w``) and the lines of the others (module docstring; ``cols`` as in
    :func:`gram_blocks`)."""
    near = np.zeros(pl.centre.size, bool)
    for p in np.asarray(poles, complex).ravel():
        near |= near_bins(pl, complex(p))
    got = _sums(fitter, pl, cols, near, None)
    return got[1], got[2]


def _sums(
    fitter: FitterState, pl: PseudoLines, cols: Any, near: NDArray[np.bool_], fixed_rows: Any
) -> tuple[Any, NDArray[np.float64], NDArray[np.float64]]:
    """``Phi_f^T B`` (None without ``fixed_rows``), ``B^T B`` and ``B^T Y`` over the
    pseudo-lines of the bins not ``near`` and the lines of the others."""
    n_in = fitter.n_in
    sums: list[tuple[Any, Any, Any]] = []
    for far in _chunks(np.flatnonzero(~near)):
        wn = pl.nodes[far].ravel()
        b = np.asarray(cols(factors_at(fitter, wn), None))  # (2 n_in n_nodes, n1)
        n1 = b.shape[1]
        wf = pl.weights[far][None, :, :, None, None]
        yt = pl.y[:, far].reshape(-1, pl.y.shape[-1])
        cross = None
        if fixed_rows is not None:
            cross = pl.phi[:, far].reshape(-1, pl.phi.shape[-1]).T @ b
        if np.all(wf > 0):  # B^T W B as X^T X, X = W^1/2 B: one symmetric product
            bw = (b.reshape(n_in, far.size, NODES, 2, n1) * np.sqrt(wf)).reshape(-1, n1)
            g1 = bw.T @ bw
        else:
            g1 = (b.reshape(n_in, far.size, NODES, 2, n1) * wf).reshape(-1, n1).T @ b
        sums.append((cross, g1, b.T @ yt))
    for i in np.flatnonzero(near):
        sl = pl.bins[i]
        b = np.asarray(cols(None, sl))
        cross = None if fixed_rows is None else fixed_rows(sl).T @ b
        sums.append((cross, b.T @ b, _basis.rows_t_data(fitter, sl, b)))
    g0 = sum(x[1] for x in sums[1:]) + sums[0][1]
    p0 = sum(x[2] for x in sums[1:]) + sums[0][2]
    cross = None if fixed_rows is None else sum(x[0] for x in sums[1:]) + sums[0][0]
    return cross, g0, p0


def gram_blocks(
    fitter: FitterState,
    pl: PseudoLines,
    cols: Any,
    fixed_rows: Any,
    pole: complex,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``Phi_f^T B1`` (q_f, n1), ``B1^T B1`` (n1, n1) and ``B1^T Y`` (n1, n_out, data
    unweighted) of the added columns, from the pseudo-lines of the far bins and the
    lines of the near ones (module docstring). ``cols(fac, sl)``: the added columns
    at the factors ``fac`` (:func:`factors_at`) or, with ``fac`` None, on the lines
    ``sl``; ``fixed_rows(sl)``: the fixed basis on the lines ``sl``; ``pole``: the
    added mode's pole (rad/s)."""
    cross, g0, p0 = _sums(fitter, pl, cols, near_bins(pl, pole), fixed_rows)
    return cross, g0, p0


def scan_sums(
    fitter: FitterState,
    pl: PseudoLines,
    vals: Any,
    cols: Any,
    poles: NDArray[np.complex128],
    chunk: int = 64,
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """``sum_k v_k conj(c_g(w_k))`` (r, G) and ``sum_k |c_g(w_k)|^2`` (G,) of complex
    values ``v`` and the columns ``c_g`` of the trial poles ``poles`` (G,): the inner
    products of a scan of a residual, from the pseudo-lines of the bins far from
    every trial pole (module docstring: ``v`` by its moments ``sum_k l_j(w_k) v_k``,
    ``|c|^2`` by the weights ``W_j``) and the lines of the others.

    ``vals(sl)``: the values (r, lines) of the lines ``sl`` (called once per line);
    ``cols(s, kappa, p)``: the columns (len(p), n) of the poles ``p`` at ``s = i w``
    and ``kappa`` (:func:`factors_at`), formed for ``chunk`` poles at a time."""
    near = np.zeros((pl.centre.size, poles.size), bool)
    for k, p in enumerate(np.asarray(poles, complex).ravel()):
        near[:, k] = near_bins(pl, complex(p))
    ells = pl.ells or tuple(_bin_lagrange(2 * np.pi * fitter.f, pl.bins, pl.centre, pl.half))
    m = np.zeros((0, poles.size), complex)
    nrm2 = np.zeros(poles.size)
    vt = []
    for i0, i1 in _groups(pl.bins, list(ells), 16 * (fitter.n_out * fitter.n_in + 2)):
        sl = slice(pl.bins[i0].start, pl.bins[i1 - 1].stop)
        v = np.asarray(vals(sl))
        if not m.size:
            m = np.zeros((v.shape[0], poles.size), complex)
        nb = ells[i0].shape[1]
        vt.append(np.matmul(v.reshape(v.shape[0], i1 - i0, nb), ells[i0].T))
        for i in range(i0, i1):
            gn = np.flatnonzero(near[i])
            if gn.size:  # the lines of a bin near some of the poles, for those
                b = pl.bins[i]
                s_, k_, _ = _basis.factors(fitter, b)
                c = np.asarray(cols(s_, k_, poles[gn]))
                m[:, gn] += v[:, b.start - sl.start : b.stop - sl.start] @ c.conj().T
                nrm2[gn] += np.sum(c.real**2 + c.imag**2, axis=1)
    v_all = np.concatenate(vt, axis=1)  # (r, n_bins, NODES)
    for c0 in range(0, poles.size, chunk):
        g = np.arange(c0, min(c0 + chunk, poles.size))
        far = np.flatnonzero(~near[:, g].any(axis=1))  # far from every pole of the chunk
        part = near[:, g].any(axis=1) & ~near[:, g].all(axis=1)
        for ib in np.flatnonzero(part):  # near some poles of the chunk: the others here
            gi = g[~near[ib, g]]
            s_, k_, _ = factors_at(fitter, pl.nodes[ib])
            c = np.asarray(cols(s_, k_, poles[gi]))
            m[:, gi] += v_all[:, ib] @ c.conj().T
            nrm2[gi] += (c.real**2 + c.imag**2) @ pl.weights[ib]
        for fc in _chunks(far):
            s_, k_, _ = factors_at(fitter, pl.nodes[fc].ravel())
            c = np.asarray(cols(s_, k_, poles[g]))
            m[:, g] += v_all[:, fc].reshape(v_all.shape[0], -1) @ c.conj().T
            nrm2[g] += (c.real**2 + c.imag**2) @ pl.weights[fc].ravel()
    return m, nrm2
