"""The real basis of the modal fits and its derivative columns.

Functions of a :class:`~tyredamp.modal.fit.fit.ModalFitter` (its methods
``_basis_ek``, ``_basis_real``, ``_layout``, ``_coef``); the layout of the
columns is stated in the docstring of :mod:`tyredamp.modal.fit.fit`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._state import FitterState

#: derivative-column layouts (layout) per (kind, m, n_in, q, w_ref)
LAYOUTS: dict[tuple[str, int, int, int, float], Layout] = {}


def layout(fitter: FitterState, m: int) -> Layout:
    """Derivative columns of ``m`` modes: ``D = E[:, ecol] * coef`` (cached, read-only).

    Complex modes: per mode ``n`` the columns of ``E`` are ``[S]``, ``[i T]``
    (see :meth:`_basis_ek`), then ``[g]``, ``[i g']`` of each free
    participation entry (inputs ``k != ref[n]`` in increasing ``k``); the
    derivative columns, in the order of :meth:`basis`, are ``(-sigma [S], x1,
    col 2n)``, ``(-sigma [i T], x1, 2n+1)``, ``(w_ref [i T], x2, 2n)``, ``(-w_ref
    [S], x2, 2n+1)`` and per free entry ``([g], Re l, 2n)``, ``([i g'], Re l,
    2n+1)``, ``([i g'], Im l, 2n)``, ``(-[g], Im l, 2n+1)`` -- (column of ``E``
    and factor, parameter, basis column). Real modes: ``E = D`` (no repeated
    columns).
    """
    q = fitter.n_cols(m)
    key = (fitter.kind, m, fitter.n_in, q, fitter.w_ref)
    lay = LAYOUTS.get(key)
    if lay is not None:
        return lay
    nin = fitter.n_in
    ar = np.arange(m)
    if fitter.kind == "complex":
        n_par = 2 * m + 2 * (nin - 1) * m
        npp, ne_m = 4 * nin, 2 * nin
        e_m = [0, 1, 1, 0]
        for j in range(nin - 1):
            e_m += [2 + 2 * j, 3 + 2 * j, 3 + 2 * j, 2 + 2 * j]
        sign_m = [-1.0, -1.0, fitter.w_ref, -fitter.w_ref] + [1.0, 1.0, 1.0, -1.0] * (nin - 1)
        pp = 2 * m + 2 * (nin - 1) * ar[:, None] + 2 * np.arange(nin - 1)[None, :]
        part = (pp[:, :, None] + np.array([0, 0, 1, 1])[None, None, :]).reshape(m, -1)
        pole = 2 * ar[:, None] + np.array([0, 0, 1, 1])[None, :]
        dpar = np.concatenate([pole, part], axis=1).ravel()
        dcol = 2 * np.repeat(ar, npp) + np.tile([0, 1, 0, 1], m * nin)
        nsig = 2
    else:
        n_par = 2 * m + (nin - 1) * m
        npp = ne_m = 2 + (nin - 1)
        e_m = list(range(npp))
        sign_m = [1.0] * npp
        part = 2 * m + (nin - 1) * ar[:, None] + np.arange(nin - 1)[None, :]
        dpar = np.concatenate([2 * ar[:, None] + np.array([0, 1])[None, :], part], 1).ravel()
        dcol = np.repeat(ar, npp)
        nsig = 0
    ecol = (ne_m * ar[:, None] + np.array(e_m, np.intp)[None, :]).ravel()
    nd, ne = ecol.size, ne_m * m
    A = np.zeros((nd, n_par))
    A[np.arange(nd), dpar] = 1.0
    lay = Layout(
        ecol=ecol.astype(np.intp),
        sign=np.tile(np.array(sign_m), m),
        nsig=nsig,
        dpar=dpar.astype(np.intp),
        dcol=dcol.astype(np.intp),
        A=A,
        ee=(ecol[:, None] * ne + ecol[None, :]).astype(np.intp),
        dd=(dcol[:, None] * q + dcol[None, :]).astype(np.intp),
        eq=(ecol * q + dcol).astype(np.intp),
    )
    for arr in (lay.ecol, lay.sign, lay.dpar, lay.dcol, lay.A, lay.ee, lay.dd, lay.eq):
        arr.flags.writeable = False
    if len(LAYOUTS) >= 64:
        LAYOUTS.clear()
    LAYOUTS[key] = lay
    return lay


def coef(lay: Layout, poles: NDArray[np.complex128]) -> NDArray[np.float64]:
    """Factors ``coef`` (n_d,) of ``D = E[:, ecol] * coef`` at the poles."""
    coef = lay.sign.copy()
    if lay.nsig:
        cm = coef.reshape(poles.size, -1)
        cm[:, : lay.nsig] *= (-poles.real)[:, None]  # d p / d x1 = -sigma
    return coef


#: bytes of one block of rows of the fits (basis, derivative and data columns):
#: the Gram blocks, the QR route and the fitted FRFs are accumulated over blocks
#: of lines of this size, so that no array of the fits grows with the lines
#: beyond the data (:func:`blocks`). 8 MB: on 16 outputs x 2 inputs x 3000 lines
#: one block instead of several made the residual search 2x faster with the same
#: modes (``benchmarks/modal_blocks.py``); the cap is a constant, not per line
BLOCK_BYTES = 8_000_000
#: most bytes of data rows a fitter keeps for its life (:func:`one_block`)
KEEP_BYTES = 1_000_000
#: fewest lines of a block (fewer make the per-block overhead dominate)
MIN_BLOCK_LINES = 256


def blocks(fitter: FitterState, n_col: int) -> list[slice]:
    """Blocks of lines for arrays of ``n_col`` real columns (``2 n_in`` rows per line).

    One block when the lines fit in :data:`BLOCK_BYTES`; otherwise blocks of
    ``BLOCK_BYTES / (16 n_in (n_col + n_out))`` lines (at least
    :data:`MIN_BLOCK_LINES`).
    """
    n_f = fitter.n_f
    per_line = 16 * fitter.n_in * (n_col + fitter.n_out)
    nb = max(MIN_BLOCK_LINES, int(BLOCK_BYTES // max(per_line, 1)))
    if n_f <= nb:
        return [slice(0, n_f)]
    return [slice(a, min(a + nb, n_f)) for a in range(0, n_f, nb)]


def one_block(fitter: FitterState) -> bool:
    """Do the data rows of every line fit in :data:`KEEP_BYTES` (and one block,
    :data:`BLOCK_BYTES`)? The fitter then keeps them (no more memory than one block
    of a blocked fit)."""
    return bool(16 * fitter.n_in * fitter.n_f * fitter.n_out <= min(KEEP_BYTES, BLOCK_BYTES))


def factors(
    fitter: FitterState, lines: slice | None = None
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """``s = i w``, ``kappa = (i w)^power`` and ``kappa_low = (i w)^(power - 2)`` of the
    lines (times the line weights when the fitter has them), computed when needed
    (slices of the fitter's ``_factors`` of every line when it holds them)."""
    full = getattr(fitter, "_factors", None)
    if full is not None:
        return full if lines is None else (full[0][lines], full[1][lines], full[2][lines])
    f = fitter.f if lines is None else fitter.f[lines]
    w = 2 * np.pi * f
    s = 1j * w
    # (i w)^p = i^p w^p: a real power and one exact complex factor (a complex power
    # of every line costs several times more)
    p = fitter.power
    wp = w**p
    wl = w ** float(p - 2)
    lw = fitter.line_weights
    if lw is not None:
        lw = lw if lines is None else lw[lines]
        wp = wp * lw
        wl = wl * lw
    kappa = _I_POWER[p % 4] * wp
    kappa_low = _I_POWER[(p - 2) % 4] * wl
    c128 = np.complex128  # the dtypes already are complex128 (no copy): typed for mypy
    return np.asarray(s, c128), np.asarray(kappa, c128), np.asarray(kappa_low, c128)


#: ``i^k`` for ``k = 0 .. 3`` (exact)
_I_POWER = (1.0 + 0j, 1j, -1.0 + 0j, -1j)


def ydata(fitter: FitterState, lines: slice | None = None) -> NDArray[np.float64]:
    """Data rows of the lines (``(k, f)``, real and imaginary part interleaved), (rows, n_out).

    Weighted by the line weights when the fitter has them; row ``2 i`` is the
    real, ``2 i + 1`` the imaginary part of entry ``i``, as the basis rows.
    The fitter's ``_y`` (the rows of every line, read-only) when it holds them
    (data of at most one block, :func:`one_block`) and ``lines`` covers them all.
    """
    full = getattr(fitter, "_y", None)
    if full is not None and (lines is None or lines.indices(fitter.n_f) == (0, fitter.n_f, 1)):
        return full
    h = fitter.H if lines is None else fitter.H[:, :, lines]
    lw = fitter.line_weights
    if lw is not None:
        h = h * (lw if lines is None else lw[lines])[None, None, :]
    n_out, n_in, nb = h.shape
    hc = h.transpose(1, 2, 0).reshape(n_in * nb, n_out)
    Y = np.empty((2 * n_in * nb, n_out))
    Y[0::2] = hc.real
    Y[1::2] = hc.imag
    return Y


def rows_t_data(fitter: FitterState, lines: slice, b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``b^T Y`` (c, n_out) of basis rows ``b`` (rows of ``lines``, c columns) and the
    data rows of those lines, without forming ``Y``.

    ``b`` holds complex columns as real rows (real and imaginary part of each
    entry ``(k, f)`` interleaved, as :func:`basis_ek` returns them), and so does
    ``Y``: the real inner product of two such columns is ``Re(conj(a)^T y) =
    a_re^T y_re + a_im^T y_im``, the real product of the two arrays of
    interleaved parts, so ``b^T Y`` is one real matrix product of ``b^T`` with
    the block of ``fitter.H`` (times the line weights) viewed as real numbers
    (half the operations of the complex product ``conj(b_c)^T H_c``, of which
    only the real part counts). Falls back to ``b.T @ ydata(...)`` when ``b``
    is not laid out that way.
    """
    bt = b.T
    if not (bt.flags.c_contiguous and bt.shape[1] % 2 == 0):
        return np.asarray(bt @ ydata(fitter, lines))
    n_out = fitter.n_out
    h = fitter.H[:, :, lines]
    lw = fitter.line_weights
    h = h * lw[lines] if lw is not None else np.ascontiguousarray(h)
    hr = h.reshape(n_out, -1).view(np.float64)  # (n_out, 2 n_in nb), parts interleaved
    return np.asarray(bt @ hr.T)


def synth(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    coef: NDArray[np.float64],
) -> NDArray[np.complex128]:
    """Fitted FRFs ``Phi coef`` (unweighted), complex, (n_out, n_in, n_f), block by block.

    ``coef`` (q, n_out): the linear coefficients of the unweighted outputs.
    """
    out = np.empty((fitter.n_out, fitter.n_in, fitter.n_f), complex)
    lw = fitter.line_weights
    for sl in blocks(fitter, fitter.n_cols(m)):
        phi = basis_ek(fitter, th, m, ref, False, sl)[0]
        hw = np.ascontiguousarray(coef.T @ phi.T)  # (n_out, rows)
        blk = hw.view(np.complex128).reshape(fitter.n_out, fitter.n_in, -1)
        if lw is not None:
            blk = blk / lw[sl][None, None, :]
        out[:, :, sl] = blk
    return out


def residual_power(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    residues: NDArray[np.complex128],
    terms: tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    s2: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Residual power per line ``sum_jk |H_jk - H^_jk|^2 / s2_j`` (weighted as the fit
    weights the lines), (n_f,), block by block.

    ``residues`` (n_out, n_in, m): ``R_jkn`` of the model ``sum_n R / (s - p_n) +
    conj(R) / (s - conj p_n)`` in the data's kind; ``terms``: upper and lower
    residual terms (n_out, n_in) or None; ``s2`` (n_out,) the noise variances.
    """
    out = np.empty(fitter.n_f)
    for sl, e in residual_blocks(fitter, poles, residues, terms):
        out[sl] = np.einsum("jkf,j->f", e.real**2 + e.imag**2, 1.0 / s2)
    return out


def residual_blocks(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    residues: NDArray[np.complex128],
    terms: tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    n_col: int = 0,
) -> Iterator[tuple[slice, NDArray[np.complex128]]]:
    """The weighted residual ``H - H^`` (line weights applied), (n_out, n_in, lines),
    block by block with its lines (arguments as :func:`residual_power`); ``n_col``:
    the real columns per line the caller forms with each block, when more than
    the model's (:func:`blocks`)."""
    for sl in blocks(fitter, max(2 * poles.size + 2 * fitter.n_in, n_col)):
        yield sl, residual_lines(fitter, poles, residues, terms, sl)


def residual_lines(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    residues: NDArray[np.complex128],
    terms: tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    sl: slice,
) -> NDArray[np.complex128]:
    """The weighted residual ``H - H^`` of the lines ``sl`` (arguments as
    :func:`residual_power`), (n_out, n_in, lines).

    Only the result grows with the lines: the model's columns are formed for
    blocks of at most :func:`blocks` lines (each line's value is the same
    product of the same numbers whatever the block).
    """
    n_out, n_in, m = residues.shape
    upper, lower = terms
    # the model of every FRF as one real product: R a + conj(R) b = Re R (a + b) +
    # Im R i (a - b) with a = kappa / (s - p_n), b = kappa / (s - conj p_n), so
    # [Re R_n, Im R_n, upper, lower] (n_out n_in, n_t) times the complex columns
    # a + b, i (a - b), kappa, kappa_low as real rows (n_t, 2 lines): half the
    # operations of the complex product, no pass per residual term
    coef = [np.stack([residues.real, residues.imag], axis=3).reshape(n_out * n_in, 2 * m)]
    coef += [np.asarray(t, np.float64).reshape(-1, 1) for t in (upper, lower) if t is not None]
    rr = np.concatenate(coef, axis=1)
    idx = range(*sl.indices(fitter.n_f))
    e = np.empty((n_out, n_in, len(idx)), complex)
    nb = blocks(fitter, rr.shape[1])[0].stop
    for k in range(0, len(idx), nb):
        part = idx[k : k + nb]
        sb = slice(part.start, part.stop, part.step)
        eb = e[:, :, k : k + len(part)]
        h = fitter.H[:, :, sb]
        if fitter.line_weights is not None:
            np.multiply(h, fitter.line_weights[sb], out=eb)
        else:
            eb[...] = h
        if rr.shape[1]:
            eb -= _model_block(fitter, poles, rr, terms, sb).reshape(eb.shape)
    return e


def mode_atoms(
    s: NDArray[np.complex128],
    kap: NDArray[np.complex128],
    poles: NDArray[np.complex128],
    out: tuple[NDArray[np.complex128], NDArray[np.complex128]],
    derivative: tuple[NDArray[np.complex128], NDArray[np.complex128]] | None = None,
) -> None:
    """The columns of complex modes with unit participation over the lines, written
    into ``out = (u, v)`` and ``derivative = (u', v')`` (each (m, lines)).

    ``u = a + b`` and ``v = i (a - b)`` with ``a = kappa / (s - p_n)`` and ``b =
    kappa / (s - conj p_n)`` (spec eq. [10]): ``u = 2 t kappa / d``, ``v = -2 Omega_n
    kappa / d`` with ``t = s + sigma_n`` and ``d = (s - p_n)(s - conj p_n) = t^2 +
    Omega_n^2`` (one complex reciprocal per line and mode instead of two divisions);
    their derivatives ``u' = a' + b'``, ``v' = i (a' - b')`` (``a' = a / (s - p_n)``,
    ``d a / d p = a'``) are ``2 (t^2 - Omega_n^2) kappa / d^2`` and ``-4 Omega_n t
    kappa / d^2``. ``s``, ``kap``: (lines,) of :func:`factors`; ``poles``: (m,)."""
    om = poles.imag[:, None]
    t = s[None, :] + (-poles.real)[:, None]
    d = np.multiply(t, t)
    d += om * om
    r = np.reciprocal(d)
    h = r * (2.0 * kap[None, :])  # 2 kappa / d
    np.multiply(t, h, out=out[0])
    np.multiply(h, -om, out=out[1])
    if derivative is not None:
        h *= r  # 2 kappa / d^2
        d -= 2.0 * om * om  # t^2 - Omega^2
        du, dv = derivative
        np.multiply(d, h, out=du)
        np.multiply(t, h, out=dv)
        dv *= -2.0 * om


def _model_block(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    rr: NDArray[np.float64],
    terms: tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    sb: slice,
) -> NDArray[np.complex128]:
    """The weighted model ``rr`` times the columns of the lines ``sb`` (one block),
    (n_out n_in, lines) complex (:func:`residual_lines`).

    The columns ``a + b`` and ``i (a - b)`` of mode ``n`` (``a = kappa / (s - p_n)``,
    ``b = kappa / (s - conj p_n)``) are ``2 t kappa / d`` and ``-2 Omega_n kappa / d``
    with ``t = s + sigma_n`` and ``d = (s - p_n)(s - conj p_n) = t^2 + Omega_n^2``, as
    in :func:`basis_ek`: one complex reciprocal per line and mode instead of two
    divisions."""
    m = poles.size
    s, kap, kap_low = factors(fitter, sb)
    cols = np.empty((rr.shape[1], s.size), complex)
    if m:
        mode_atoms(s, kap, poles, (cols[0 : 2 * m : 2], cols[1 : 2 * m : 2]))
    c = 2 * m
    for t_, kk in zip(terms, (kap, kap_low), strict=True):
        if t_ is not None:
            cols[c] = kk
            c += 1
    return (rr @ cols.view(np.float64)).view(np.complex128)


def basis_ek(
    fitter: FitterState,
    th: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    derivatives: bool = True,
    lines: slice | None = None,
    given: tuple[Any, Any] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """``B = [Phi | E]`` (n_rows, q + n_e), Fortran-ordered, and the poles.

    ``lines``: the rows of these lines only (:func:`blocks`; default all).
    ``given``: ``(factors(fitter, lines), unpack(th, m, ref))`` when the caller
    has them already (either may be None).

    Complex modes, all at once: columns ``2n, 2n+1`` of mode ``n`` are ``A + B``
    and ``i (A - B)`` with ``A_k = l_kn kappa / (s - p_n)`` and ``B_k =
    conj(l_kn) kappa / (s - conj p_n)`` (real and imaginary part of the output
    coefficient ``u_jn``). The distinct derivative columns ``E`` (``n_e = 2
    n_in m``) of mode ``n`` are ``[S]`` and ``[i T]`` with ``S = A' + B'``, ``T =
    A' - B'`` (``A' = A / (s - p_n)``, ``B' = B / (s - conj p_n)``: ``d A / d p =
    A'``), then ``[g]`` and ``[i g']`` at input ``k`` only (``g = kappa / (s -
    p_n) + kappa / (s - conj p_n)``, ``g'`` the difference) for each free
    participation entry; ``[.]`` is a complex column as real rows (real and
    imaginary part of each line interleaved, as the data ``Y``). With one
    input (``l = 1``), ``t = s + sigma_n`` and ``d = (s - p_n)(s - conj p_n) =
    t^2 + Omega_n^2``: ``A + B = 2 t kappa / d``,
    ``i (A - B) = -2 Omega_n kappa / d``, ``S = 2 (t^2 - Omega_n^2) kappa / d^2``
    and ``i T = -4 Omega_n t kappa / d^2`` (one complex division per line and
    mode). Each column is written in place (transposed, contiguous). Real
    modes: ``E`` holds the derivative columns of :meth:`_basis_real`.
    ``derivatives=False``: ``B = Phi``.
    """
    fac, pp = (None, None) if given is None else given
    poles, part = fitter.unpack(th, m, ref) if pp is None else pp
    q = fitter.n_cols(m)
    s1, kap1, kap_low = factors(fitter, lines) if fac is None else fac
    if fitter.kind == "real":
        rt = real_rows(fitter, poles, part, ref, derivatives, (s1, kap1, kap_low))
        return rt.reshape(rt.shape[0], -1).view(np.float64).T, poles
    nin, nf = fitter.n_in, s1.size
    ne = 2 * nin * m if derivatives else 0
    # rows: columns of B, complex (real and imaginary part interleaved as in Y)
    bt = np.empty((q + ne, nin, nf), complex)
    s, kap = s1[None, :], kap1[None, :]
    if nin == 1:
        sig = (-poles.real)[:, None] + 0j  # complex factors: no casts in the loops
        mom = -poles.imag[:, None] + 0j
        den = s - poles[:, None]
        den *= s - np.conj(poles)[:, None]  # d = (s - p)(s - conj p)
        r = np.reciprocal(den)
        h = 2.0 * kap * r  # 2 kappa / d
        t = s + sig
        np.multiply(t, h, out=bt[0 : 2 * m : 2, 0])
        np.multiply(h, mom, out=bt[1 : 2 * m : 2, 0])
        if derivatives:
            h *= r  # 2 kappa / d^2
            den -= 2.0 * mom * mom  # t^2 - Omega^2
            np.multiply(den, h, out=bt[q::2, 0])
            o = bt[q + 1 :: 2, 0]
            np.multiply(t, h, out=o)
            o *= 2.0 * mom
    else:
        e = 1.0 / (s - poles[:, None])  # (m, nf)
        eb = 1.0 / (s - np.conj(poles)[:, None])
        g = kap * e
        gb = kap * eb
        lc = part[:, :, None]  # (m, nin, 1)
        A = lc * g[:, None, :]  # (m, nin, nf)
        B_ = np.conj(lc) * gb[:, None, :]
        put_pair(bt, 0, 2, A, B_)
        if derivatives:
            A *= e[:, None, :]
            B_ *= eb[:, None, :]
            put_pair(bt, q, 2 * nin, A, B_)
            # participation columns: zero but at input k
            oth = np.array([[k for k in range(nin) if k != ref[n]] for n in range(m)])
            rows = q + 2 * nin * np.arange(m)
            pairs = bt[q:].reshape(m, nin, 2, nin, nf)[:, 1:]  # (m, nin - 1, 2, nin, nf)
            pairs[...] = 0.0
            gp = g + gb
            gm = 1j * (g - gb)
            for j in range(nin - 1):
                kk_ = oth[:, j]
                bt[rows + 2 + 2 * j, kk_] = gp
                bt[rows + 3 + 2 * j, kk_] = gm
    c0 = 2 * m
    for use, kk in ((fitter.use_upper, kap1), (fitter.use_lower, kap_low)):
        if use:
            bt[c0 : c0 + nin] = 0.0
            for k in range(nin):
                bt[c0 + k, k] = kk
            c0 += nin
    return bt.reshape(q + ne, nin * nf).view(np.float64).T, poles


def basis_real(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    ref: NDArray[np.intp],
    derivatives: bool,
    lines: slice | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``Phi`` and ``D`` of the real-mode model (columns of :meth:`_layout`)."""
    bt = real_rows(fitter, poles, part, ref, derivatives, factors(fitter, lines))
    q = fitter.n_cols(poles.size)
    rows = bt.reshape(bt.shape[0], -1).view(np.float64).T
    return rows[:, :q], rows[:, q:]


def real_rows(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    ref: NDArray[np.intp],
    derivatives: bool,
    fac: tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]],
) -> NDArray[np.complex128]:
    """The columns ``[Phi | D]`` of the real-mode model as complex rows (q + n_d, n_in,
    lines) (:func:`basis_real`; ``fac``: :func:`factors` of the lines).

    Mode ``n`` (``sigma``, ``Omega``, participation ``L``), ``t = s + sigma`` and ``d =
    t^2 + Omega^2 = (s - p_n)(s - conj p_n)`` (the denominator of spec eq. [2]):
    ``Phi`` column ``L kappa / d``; derivative columns ``L sigma (-2 t kappa / d^2)``
    (``x1``, ``sigma = w_ref e^x1``: ``d d / d sigma = 2 t``), ``L w_ref (-2 Omega
    kappa / d^2)`` (``x2``, ``Omega = w_ref x2``: ``d d / d Omega = 2 Omega``) and
    ``kappa / d`` at input ``k`` for each free participation entry (``k !=
    ref[n]``). Every mode at once: ``1 / d = conj(d) / |d|^2`` from the real and
    imaginary parts of ``d`` (``Re d = (Re t^2 + Omega^2) - Im t^2``, the positive
    terms summed first), then ``kappa / d`` and ``kappa / d^2`` by two complex
    products (no complex division); written in place into one array.
    """
    s, kap, kap_low = fac
    nin, nf = fitter.n_in, s.size
    m = poles.size
    q = fitter.n_cols(m)
    npm = 2 + (nin - 1)
    bt = np.zeros((q + (npm * m if derivatives else 0), nin, nf), complex)
    if m:
        _real_mode_rows(fitter, bt, poles, part, ref, derivatives, s, kap)
    c0 = m
    for use, kk in ((fitter.use_upper, kap), (fitter.use_lower, kap_low)):
        if use:
            for k in range(nin):
                bt[c0, k] = kk
                c0 += 1
    return bt


def _real_mode_rows(
    fitter: FitterState,
    bt: NDArray[np.complex128],
    poles: NDArray[np.complex128],
    part: NDArray[np.complex128],
    ref: NDArray[np.intp],
    derivatives: bool,
    s: NDArray[np.complex128],
    kap: NDArray[np.complex128],
) -> None:
    """The modes' rows of :func:`real_rows`, written into ``bt`` (zeros there).

    Mode by mode (arrays of one mode's lines stay in cache): ``t = s + sigma``, ``d = t
    t + Omega^2``, one complex reciprocal ``r = 1 / d``, then ``kappa r`` and ``kappa
    r^2`` by products (the columns of three complex divisions before)."""
    nin, m = fitter.n_in, poles.size
    q, npm = fitter.n_cols(m), 2 + (nin - 1)
    nf = s.size
    t, r, base, u = (np.empty(nf, complex) for _ in range(4))
    rows = bt[q:].reshape(m, npm, nin, nf) if derivatives else None
    for n in range(m):
        sig, om = -poles[n].real, poles[n].imag
        lr = part[n].real[:, None]
        one = nin == 1 and lr[0, 0] == 1.0  # L = 1: the columns themselves
        np.add(s, sig, out=t)
        np.multiply(t, t, out=r)
        r += om * om  # d = t^2 + Omega^2
        np.reciprocal(r, out=r)
        np.multiply(kap, r, out=base)  # kappa / d
        if one:
            bt[n, 0] = base
        else:
            np.multiply(lr, base[None, :], out=bt[n])
        if rows is None:
            continue
        np.multiply(base, r, out=u)  # kappa / d^2
        t *= u
        t *= -2.0 * sig  # sigma (-2 t kappa / d^2)
        u *= -2.0 * fitter.w_ref * om  # w_ref (-2 Omega kappa / d^2)
        for j, col in enumerate((t, u)):
            if one:
                rows[n, j, 0] = col
            else:
                np.multiply(lr, col[None, :], out=rows[n, j])
        for j, k in enumerate(k for k in range(nin) if k != ref[n]):
            rows[n, 2 + j, k] = base


# ---------------------------------------------------- variable projection


@dataclass(frozen=True)
class Layout:
    """Derivative columns ``D = E[:, ecol] * coef`` of one basis layout.

    ``coef = sign`` with the first ``nsig`` entries of every mode's block times
    ``sigma_n`` (:meth:`ModalFitter._coef`); ``dpar``, ``dcol``: parameter and
    basis column of each derivative column; ``A`` (n_d, n_par): 0/1 map of
    derivative columns to parameters; ``ee``, ``dd``, ``eq``: flat indices of
    ``(ecol_d, ecol_d')`` in ``E^T P E``, ``(dcol_d, dcol_d')`` in ``C C^T`` and
    ``(ecol_d, dcol_d)`` in ``E^T r C^T``.
    """

    ecol: NDArray[np.intp]
    sign: NDArray[np.float64]
    nsig: int
    dpar: NDArray[np.intp]
    dcol: NDArray[np.intp]
    A: NDArray[np.float64]
    ee: NDArray[np.intp]
    dd: NDArray[np.intp]
    eq: NDArray[np.intp]


def put_pair(
    out: NDArray[np.complex128],
    c: int,
    stride: int,
    a: NDArray[np.complex128],
    b: NDArray[np.complex128],
) -> None:
    """Write the columns ``a + b`` and ``i (a - b)`` of every mode.

    ``a``, ``b``: (m, nin, nf) complex; ``out`` of shape (rows, nin, nf); mode
    ``n`` goes to rows ``c + stride n, c + stride n + 1``.
    """
    m = a.shape[0]
    o1, o2 = out[c : c + stride * m : stride], out[c + 1 : c + stride * m : stride]
    np.add(a, b, out=o1)
    np.subtract(a, b, out=o2)
    o2 *= 1j
