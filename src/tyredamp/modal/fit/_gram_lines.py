"""The Gram blocks of the modal basis with several inputs, from per-line sums.

The real basis ``B = [Phi | E]`` of :func:`~tyredamp.modal.fit._basis.basis_ek`
(complex modes, spec eq. [10], the model in the docstring of
:mod:`~tyredamp.modal.fit.fit`; ``n_in >= 2``) has ``2 n_in n_f`` rows: every
column is, at input ``k``, a complex function of the line times real numbers.
With the per-line functions ("atoms") of mode ``n`` (``t = s + sigma_n``, ``d =
(s - p_n)(s - conj p_n) = t^2 + Omega_n^2``, ``g = kappa / (s - p_n)``, ``gb =
kappa / (s - conj p_n)``)::

    u_n  = g + gb                      = 2 t kappa / d
    v_n  = i (g - gb)                  = -2 Omega_n kappa / d
    u'_n = g / (s - p_n) + gb / (s - conj p_n)   = 2 (t^2 - Omega_n^2) kappa / d^2
    v'_n = i (g / (s - p_n) - gb / (s - conj p_n)) = -4 Omega_n t kappa / d^2

plus ``kappa`` and ``kappa_low`` (the residual terms), the column ``A + B = l g +
conj(l) gb`` of mode ``n`` at input ``k`` (``l = l_kn``) is ``Re(l) u_n + Im(l)
v_n``, ``i (A - B) = Re(l) v_n - Im(l) u_n``, likewise ``S = Re(l) u'_n + Im(l)
v'_n`` and ``i T = Re(l) v'_n - Im(l) u'_n``; a participation column ``[g + gb]``
(``[i (g - gb)]``) is ``u_n`` (``v_n``) at its input and 0 elsewhere, a residual
column ``kappa`` (``kappa_low``) at its input. So with the atoms of the lines
as the columns of ``F`` (n_f, n_phi) and, per input ``k``, the real
coefficients ``M_k`` (n_phi, n_cols) of every column (at most two non-zero
per column), ``B`` restricted to the rows of input ``k`` is ``[F M_k]`` (a
complex column as real rows) -- a Kronecker-structured basis -- and, as the
real inner product of two such columns is ``Re(conj(a)^T b)``::

    B^T B = sum_k M_k^T Re(F^H F) M_k,     B^T Y = sum_k M_k^T Re(F^H Y_k)

with ``Y_k`` (n_f, n_out) the complex data of input ``k`` (times the line
weights, as :func:`~tyredamp.modal.fit._basis.ydata`). ``Re(F^H F)`` is one
real symmetric rank-k update of the atoms as real rows and ``Re(F^H Y_k)`` one
real product with the data viewed as real numbers, summed over the same
blocks of lines as the basis (:func:`~tyredamp.modal.fit._basis.blocks`): the
cost per line is ``O(n_phi^2 + n_in n_phi n_out)`` (``n_phi = 4 m + 2``) instead
of ``O(n_in (q + n_e) (q + n_e + n_out))`` (``q + n_e = 2 m (n_in + 1) + 2
n_in``), and the basis itself is not formed. The Gram blocks feed the
variable projection of :meth:`~tyredamp.modal.fit.fit.ModalFitter._solve`
(Golub & Pereyra, *SIAM J. Numer. Anal.* 10, 1973; Kaufman, *BIT* 15, 1975)
exactly as ``B^T B`` and ``B^T Y`` do, equal to them up to rounding.

The real-mode basis (spec eq. [2]; :func:`~tyredamp.modal.fit._basis.real_rows`)
has the same structure with one atom per column and input: ``kappa / d`` of each
mode and its derivatives by the two pole parameters (:func:`real_atoms`), the
participation ``L_kn`` as the coefficients (:func:`real_coefficients`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from . import _basis
from ._state import FitterState

#: take the route of this module in ``ModalFitter._solve`` (complex modes, several
#: inputs); False forms the basis as before (for comparisons)
USE = True


def applies(fitter: FitterState) -> bool:
    """Does :func:`gram` apply to this fitter (complex or real modes, several inputs)?"""
    return bool(USE and fitter.kind in ("complex", "real") and fitter.n_in >= 2)


def coefficients(
    fitter: FitterState,
    part: NDArray[np.complex128],
    ref: NDArray[np.intp],
    derivatives: bool,
    residual: bool = True,
) -> tuple[NDArray[np.intp], NDArray[np.float64], int]:
    """The real coefficients of every column of ``B = [Phi | E]`` on the atoms.

    Parameters
    ----------
    fitter : FitterState
        A complex-mode fitter with ``n_in >= 2`` inputs.
    part : ndarray, complex, shape (m, n_in)
        Participation ``l_kn`` (one entry per mode is 1, at ``ref``).
    ref : ndarray of int, shape (m,)
        Input of each mode's fixed participation entry.
    derivatives : bool
        Include the columns ``E`` (and the atoms ``u'``, ``v'``).
    residual : bool
        Include the residual terms the fitter uses (False: none, as the added
        mode's columns of ``fit_added``).

    Returns
    -------
    idx : ndarray of int, shape (n_in, n_cols, 2)
        The (at most) two atoms of column ``c`` at input ``k`` (module docstring;
        atom ``a n + j`` is ``u_n, v_n, u'_n, v'_n`` for ``j = 0 .. a - 1``, ``a``
        4 with derivatives, else 2; then ``kappa`` and ``kappa_low`` when the
        fitter uses the upper and lower residual terms).
    val : ndarray, shape (n_in, n_cols, 2)
        Their coefficients (0 where a column has fewer atoms at that input).
    n_phi : int
        Number of atoms.
    """
    m, nin = part.shape
    na = 4 if derivatives else 2
    terms = (fitter.use_upper, fitter.use_lower) if residual else (False, False)
    q = 2 * m + nin * sum(terms)
    nc = q + (2 * nin * m if derivatives else 0)
    idx = np.zeros((nin, nc, 2), np.intp)
    val = np.zeros((nin, nc, 2))
    lr, li = part.real.T, part.imag.T  # (n_in, m)
    a0 = na * np.arange(m)
    for c, j in ((0, 0), (q, 2)) if derivatives else ((0, 0),):
        # A + B (S): Re l u + Im l v;  i (A - B) (i T): Re l v - Im l u
        stride = 2 if c == 0 else 2 * nin
        cols = c + stride * np.arange(m)
        idx[:, cols, 0], idx[:, cols, 1] = a0 + j, a0 + j + 1
        val[:, cols, 0], val[:, cols, 1] = lr, li
        idx[:, cols + 1, 0], idx[:, cols + 1, 1] = a0 + j + 1, a0 + j
        val[:, cols + 1, 0], val[:, cols + 1, 1] = lr, -li
    n_phi = _term_columns((idx, val), terms, 2 * m, na * m)
    if derivatives:
        # participation pairs [g + gb] = u, [i (g - gb)] = v at input k != ref[n]
        for n in range(m):
            oth = [k for k in range(nin) if k != ref[n]]
            for j, k in enumerate(oth):
                col = q + 2 * nin * n + 2 + 2 * j
                idx[k, col, 0], idx[k, col + 1, 0] = a0[n], a0[n] + 1
                val[k, col, 0] = val[k, col + 1, 0] = 1.0
    return idx, val, n_phi


def atoms(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    derivatives: bool,
    fac: tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]],
    residual: bool = True,
) -> NDArray[np.complex128]:
    """The atoms of the lines as rows (n_phi, lines), complex (module docstring).

    ``fac``: :func:`~tyredamp.modal.fit._basis.factors` of the lines (``s``,
    ``kappa``, ``kappa_low``, line weights included); ``residual``: with the
    residual terms' atoms the fitter uses. Each mode's ``u``, ``v`` (and ``u'``,
    ``v'``) are :func:`~tyredamp.modal.fit._basis.mode_atoms`.
    """
    s, kap, kap_low = fac
    m, nf = poles.size, s.size
    na = 4 if derivatives else 2
    terms = (fitter.use_upper, fitter.use_lower) if residual else (False, False)
    n_phi = na * m + sum(terms)
    ft = np.empty((n_phi, nf), complex)
    if m:
        rows = [ft[j : na * m : na] for j in range(na)]
        _basis.mode_atoms(
            s, kap, poles, (rows[0], rows[1]), (rows[2], rows[3]) if derivatives else None
        )
    _term_atoms(ft, na * m, terms, (kap, kap_low))
    return ft


def _term_columns(
    table: tuple[NDArray[np.intp], NDArray[np.float64]],
    terms: tuple[bool, bool],
    c0: int,
    n_phi: int,
) -> int:
    """Write the residual terms' columns into the coefficient tables ``table`` (idx,
    val; :func:`coefficients`): from column ``c0`` on, ``kappa`` (then
    ``kappa_low``) at each input in turn, on the atom after the ``n_phi`` modes'
    (:func:`_term_atoms`), coefficient 1. Returns the number of atoms with them."""
    idx, val = table
    ins = np.arange(idx.shape[0])
    for use in terms:
        if use:
            idx[ins, c0 + ins, 0] = n_phi
            val[ins, c0 + ins, 0] = 1.0
            c0 += ins.size
            n_phi += 1
    return n_phi


def _term_atoms(
    ft: NDArray[np.complex128],
    c: int,
    terms: tuple[bool, bool],
    kk: tuple[NDArray[np.complex128], NDArray[np.complex128]],
) -> None:
    """Write the residual terms' atoms ``kappa``, ``kappa_low`` (``kk``) that ``terms``
    use into the rows of ``ft`` from row ``c`` on (:func:`_term_columns`)."""
    for use, k in zip(terms, kk, strict=True):
        if use:
            ft[c] = k
            c += 1


def real_coefficients(
    fitter: FitterState,
    part: NDArray[np.complex128],
    ref: NDArray[np.intp],
    derivatives: bool,
) -> tuple[NDArray[np.intp], NDArray[np.float64], int]:
    """The real coefficients of every column of the real-mode basis ``[Phi | D]``
    on the atoms of :func:`real_atoms` (tables as :func:`coefficients`).

    The columns of :func:`~tyredamp.modal.fit._basis.real_rows` (mode ``n``
    with real participation ``L_kn``, spec eq. [2]): ``Phi`` column ``n`` is
    ``L_kn kappa / d`` at input ``k``, a residual column ``kappa`` (``kappa_low``)
    at its input; the derivative columns of mode ``n`` are ``L_kn`` times the
    atoms ``-2 sigma t kappa / d^2`` and ``-2 w_ref Omega kappa / d^2``, then
    ``kappa / d`` at input ``k`` alone for each free participation entry (``k !=
    ref[n]``). One atom per column and input: the second entry of every pair
    is 0.
    """
    m, nin = part.shape
    na = 3 if derivatives else 1
    q = fitter.n_cols(m)
    npm = nin + 1
    nc = q + (npm * m if derivatives else 0)
    idx = np.zeros((nin, nc, 2), np.intp)
    val = np.zeros((nin, nc, 2))
    lr = part.real.T  # (n_in, m)
    a0 = na * np.arange(m)
    idx[:, :m, 0], val[:, :m, 0] = a0, lr
    n_phi = _term_columns((idx, val), (fitter.use_upper, fitter.use_lower), m, na * m)
    if derivatives:
        base = q + npm * np.arange(m)
        for j in (1, 2):  # d / d x1, d / d x2: the atoms a0 + 1, a0 + 2 times L
            idx[:, base + j - 1, 0], val[:, base + j - 1, 0] = a0 + j, lr
        for n in range(m):
            oth = [k for k in range(nin) if k != ref[n]]
            for j, k in enumerate(oth):
                idx[k, base[n] + 2 + j, 0], val[k, base[n] + 2 + j, 0] = a0[n], 1.0
    return idx, val, n_phi


def real_atoms(
    fitter: FitterState,
    poles: NDArray[np.complex128],
    derivatives: bool,
    fac: tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]],
) -> NDArray[np.complex128]:
    """The atoms of the real-mode basis over the lines as rows (n_phi, lines), complex:
    per mode ``kappa / d`` (``t = s + sigma_n``, ``d = t^2 + Omega_n^2``) and, with
    ``derivatives``, ``-2 sigma_n t kappa / d^2`` and ``-2 w_ref Omega_n kappa / d^2``
    (the derivatives by ``x1``, ``sigma = w_ref e^x1``, and ``x2``, ``Omega = w_ref
    x2``); then ``kappa`` and ``kappa_low`` of the residual terms the fitter uses
    (:func:`real_coefficients`; the same products as
    :func:`~tyredamp.modal.fit._basis.real_rows`). ``fac``:
    :func:`~tyredamp.modal.fit._basis.factors` of the lines."""
    s, kap, kap_low = fac
    m, nf = poles.size, s.size
    na = 3 if derivatives else 1
    terms = (fitter.use_upper, fitter.use_lower)
    ft = np.empty((na * m + sum(terms), nf), complex)
    if m:
        sig, om = (-poles.real)[:, None], poles.imag[:, None]
        t = s[None, :] + sig
        r = np.multiply(t, t)
        r += om * om  # d
        np.reciprocal(r, out=r)
        base = ft[0 : na * m : na]
        np.multiply(kap[None, :], r, out=base)  # kappa / d
        if derivatives:
            u = base * r  # kappa / d^2
            t *= u
            np.multiply(t, -2.0 * sig, out=ft[1 : na * m : na])
            np.multiply(u, -2.0 * fitter.w_ref * om, out=ft[2 : na * m : na])
    _term_atoms(ft, na * m, terms, (kap, kap_low))
    return ft


def gram(
    fitter: FitterState,
    pp: tuple[NDArray[np.complex128], NDArray[np.complex128]],
    ref: NDArray[np.intp],
    derivatives: bool,
    parts: list[slice],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``B^T B`` and ``B^T Y`` of the modal basis with several inputs.

    Parameters
    ----------
    fitter : FitterState
        A fitter with ``n_in >= 2`` (:func:`applies`): complex modes, or real
        modes (:func:`real_coefficients`, :func:`real_atoms`).
    pp : (ndarray, ndarray)
        Poles (m,) in rad/s and participation (m, n_in) (``fitter.unpack``).
    ref : ndarray of int, shape (m,)
        Input of each mode's fixed participation entry.
    derivatives : bool
        Include the distinct derivative columns ``E``.
    parts : list of slice
        Blocks of lines to sum over (:func:`~tyredamp.modal.fit._basis.blocks`).

    Returns
    -------
    G : ndarray, shape (n_cols, n_cols)
        ``B^T B`` of ``B = [Phi | E]`` (the columns of
        :func:`~tyredamp.modal.fit._basis.basis_ek`), exactly symmetric.
    P : ndarray, shape (n_cols, n_out)
        ``B^T Y`` with the data rows of
        :func:`~tyredamp.modal.fit._basis.ydata` (line weights, no output weights).

    Notes
    -----
    ``G = sum_k M_k^T Re(F^H F) M_k`` and ``P = sum_k M_k^T Re(F^H Y_k)`` (module
    docstring): the atoms ``F`` of a block as real rows (real and imaginary part
    interleaved) give ``Re(F^H F)`` as one symmetric product and ``Re(F^H Y_k)``
    of every input as one product with the block of the data viewed as real
    numbers (line weights once more on the atoms: ``Y`` carries them too);
    ``M_k`` has at most two entries per column, so its products are gathers.
    """
    poles, part = pp
    real = fitter.kind == "real"
    table = (real_coefficients if real else coefficients)(fitter, part, ref, derivatives)
    form = real_atoms if real else atoms

    def block_atoms(sl: slice) -> NDArray[np.complex128]:
        return form(fitter, poles, derivatives, _basis.factors(fitter, sl))

    return gram_of(fitter, block_atoms, table, parts)


def gram_of(
    fitter: FitterState,
    block_atoms: Callable[[slice], NDArray[np.complex128]],
    table: tuple[NDArray[np.intp], NDArray[np.float64], int],
    parts: Sequence[slice],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`gram` of the atoms ``block_atoms(sl)`` (n_phi, lines) of each block of
    lines and the coefficient tables ``table`` (:func:`coefficients`)."""
    idx, val, n_phi = table
    gam = np.zeros((n_phi, n_phi))
    z = np.zeros((fitter.n_out * fitter.n_in, n_phi))
    for sl in parts:
        ft = block_atoms(sl)
        fr = ft.view(np.float64)  # (n_phi, 2 lines): the atoms as real rows
        gam += fr @ fr.T
        z += data_rows(fitter, sl) @ _weighted(fitter, ft, sl).T
    G = products(gam, (idx, val), (idx, val))
    G += G.T
    G *= 0.5
    return G, data_products(z, (idx, val))


def added_sums(
    fitter: FitterState,
    pp1: tuple[NDArray[np.complex128], NDArray[np.complex128]],
    ref1: NDArray[np.intp],
    fixed: tuple[NDArray[np.complex128], tuple[NDArray[np.intp], NDArray[np.float64]]],
    parts: tuple[slice, ...],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``Phi_f^T B1``, ``B1^T B1`` and ``B1^T Y`` of one added mode against fixed modes.

    Parameters
    ----------
    fitter : FitterState
        The fitter (complex modes, ``n_in >= 2``; :func:`applies`).
    pp1 : (ndarray, ndarray)
        Pole (1,) in rad/s and participation (1, n_in) of the added mode, whose
        columns ``B1 = [Phi_1 | E_1]`` have no residual terms.
    ref1 : ndarray of int, shape (1,)
        Input of its fixed participation entry.
    fixed : (ndarray, (ndarray, ndarray))
        The atoms of the fixed basis ``Phi_f`` (fixed modes and residual terms, no
        derivatives) as rows (n_phi_f, n_f) of every line (:func:`atoms`), and
        its coefficient tables (:func:`coefficients`).
    parts : tuple of slice
        Blocks of lines to sum over.

    Returns
    -------
    cross : ndarray, shape (q_f, n_1)
        ``Phi_f^T B1 = sum_k M_fk^T Re(F_f^H F_1) M_1k`` (module docstring).
    g0 : ndarray, shape (n_1, n_1)
        ``B1^T B1``, exactly symmetric.
    p0 : ndarray, shape (n_1, n_out)
        ``B1^T Y`` (line weights, no output weights).
    """
    ff, tab_f = fixed
    idx1, val1, n1 = coefficients(fitter, pp1[1], ref1, True, residual=False)
    one = (idx1, val1)
    g11 = np.zeros((n1, n1))
    gf1 = np.zeros((ff.shape[0], n1))
    z = np.zeros((fitter.n_out * fitter.n_in, n1))
    for sl in parts:
        f1 = atoms(fitter, pp1[0], True, _basis.factors(fitter, sl), residual=False)
        fr = f1.view(np.float64)
        g11 += fr @ fr.T
        gf1 += ff[:, sl].view(np.float64) @ fr.T
        z += data_rows(fitter, sl) @ _weighted(fitter, f1, sl).T
    g0 = products(g11, one, one)
    g0 += g0.T
    g0 *= 0.5
    return products(gf1, tab_f, one), g0, data_products(z, one)


def data_rows(fitter: FitterState, sl: slice) -> NDArray[np.float64]:
    """The data of the lines ``sl`` as real rows (n_out n_in, 2 lines), rows ``(j, k)``
    (real and imaginary part interleaved; a view of ``fitter.H`` when it allows)."""
    hb = np.asarray(fitter.H[:, :, sl], np.complex128).reshape(fitter.n_out * fitter.n_in, -1)
    if hb.strides[-1] != hb.itemsize:
        hb = np.ascontiguousarray(hb)
    return hb.view(np.float64)


def _weighted(fitter: FitterState, ft: NDArray[np.complex128], sl: slice) -> NDArray[np.float64]:
    """Atoms of the lines ``sl`` (rows) times the line weights, as real rows: their
    product with :func:`data_rows` is ``Re(F^H Y_k)`` (``Y`` carries the weights too)."""
    lw = fitter.line_weights
    return (ft if lw is None else ft * lw[sl][None, :]).view(np.float64)


def products(
    gam: NDArray[np.float64],
    left: tuple[NDArray[np.intp], NDArray[np.float64]],
    right: tuple[NDArray[np.intp], NDArray[np.float64]],
) -> NDArray[np.float64]:
    """``sum_k L_k^T gam R_k`` of the coefficient tables ``left`` and ``right``
    (:func:`coefficients`; at most two entries per column: gathers, no products
    with the zeros)."""
    (il, vl), (ir, vr) = left, right
    out = np.zeros((il.shape[1], ir.shape[1]))
    for k in range(il.shape[0]):
        gm = gam[:, ir[k, :, 0]] * vr[k, :, 0] + gam[:, ir[k, :, 1]] * vr[k, :, 1]  # gam R_k
        out += vl[k, :, 0, None] * gm[il[k, :, 0]] + vl[k, :, 1, None] * gm[il[k, :, 1]]
    return out


def data_products(
    z: NDArray[np.float64], table: tuple[NDArray[np.intp], NDArray[np.float64]]
) -> NDArray[np.float64]:
    """``sum_k M_k^T Re(F^H Y_k)`` (n_cols, n_out) from ``z`` (n_out n_in, n_phi), the
    products of :func:`data_rows` with the weighted atoms (rows ``(j, k)``)."""
    idx, val = table
    nin = idx.shape[0]
    zk = z.reshape(-1, nin, z.shape[1])
    out = np.zeros((idx.shape[1], zk.shape[0]))
    for k in range(nin):
        zt = zk[:, k, :].T  # Re(F^H Y_k), (n_phi, n_out)
        out += val[k, :, 0, None] * zt[idx[k, :, 0]] + val[k, :, 1, None] * zt[idx[k, :, 1]]
    return out
