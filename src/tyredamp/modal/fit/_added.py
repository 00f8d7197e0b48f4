"""The projection of :meth:`~tyredamp.modal.fit.fit.ModalFitter.fit_added`: one added
mode refined with the other modes held fixed.

The fixed basis ``Phi_f`` (the fixed modes and the residual terms) is projected
out of the data once (:func:`fixed_part`: the range map of
:func:`~tyredamp.modal.fit._linalg._fixed_range`); an evaluation at the added
mode's parameters (:func:`added_solver`) then needs only the Gram blocks of the
added columns ``B1 = [Phi_1 | E_1]`` against ``Phi_f``, themselves and the data
(Frisch-Waugh-Lovell theorem, e.g. Seber & Lee, *Linear Regression Analysis*,
2003, sec. 3.7; equations in the docstring of ``fit_added``).

The residual search tries many candidates against the same fixed modes: the
fixed part (:class:`FixedPart`, from :meth:`ModalFitter.fixed_part
<tyredamp.modal.fit.fit.ModalFitter.fixed_part>`) is an immutable value that the
caller forms once per fixed mode set and passes to each ``fit_added``; the
fitter keeps nothing between calls. It holds the range map and, when the data
fit one block (:func:`~tyredamp.modal.fit._basis.one_block`), that block's fixed
basis, weighted data rows and the rows of ``[Q_r | P_f Y]`` (an orthonormal
basis of the range of ``Phi_f`` and the data with it projected out: an
evaluation is then one product ``B1^T [Q_r | P_f Y]`` and ``B1^T B1``); with
several blocks, the rows of ``Q_r`` of every line when the fixed basis is no
larger than the data or than one block of the fits (an evaluation then forms
the added columns of every line at once when they are no larger than the data
or one block either: one basis and three products instead of a fixed and an
added basis and three products per block).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _basis, _gram_lines, _pseudo
from ._linalg import _PROJ_TOL, _fixed_range, _vp_solve
from ._state import FitterState


@dataclass(frozen=True)
class FixedPart:
    """The fixed basis's part of :meth:`ModalFitter.fit_added` (module docstring).

    An immutable value of the fixed modes ``th`` (``m``, ``ref``) on the blocks
    of lines ``parts``: ``phi0`` the fixed basis ``Phi_f`` and ``yw`` the
    weighted data rows of the one block (None with several blocks, where they
    are formed block by block when needed); ``tmap``, ``qty``, ``yyp``: the
    range map ``T``, ``Q_r^T Y`` and ``||P_f Y||^2`` (:func:`_fixed_range`);
    ``keep``: whether a call keeps a block's basis once formed (several blocks);
    ``qy``: the rows of ``[Q_r | P_f Y]`` of the one block (``Q_r = Phi_f T``, ``P_f
    Y = Y - Q_r Q_r^T Y`` the data with the fixed basis projected out; None with
    several blocks), so that an evaluation needs one product ``B1^T [Q_r | P_f Y]``;
    ``src``: the poles and participation it was formed from, when given; ``qr``:
    with several blocks and ``keep``, the rows of ``Q_r`` of every line (no larger
    than the data), so that an evaluation needs no fixed basis; ``pseudo``: with
    several blocks, neither kept, and a long record, the pseudo-lines of the fixed
    basis and the data (:mod:`._pseudo`), so that an evaluation's cost does not
    grow with the lines; ``atoms``: with complex modes, several inputs and several
    blocks (no pseudo-lines), the atoms of ``Phi_f`` of every line and their
    coefficient tables (:mod:`._gram_lines`; no larger than the data or one
    block), so that an evaluation sums the Gram blocks of the added columns from
    per-line sums without forming them.
    """

    th: NDArray[np.float64]
    m: int
    ref: NDArray[np.intp]
    parts: tuple[slice, ...]
    keep: bool
    phi0: NDArray[np.float64] | None
    yw: NDArray[np.float64] | None
    tmap: NDArray[np.float64]
    qty: NDArray[np.float64]
    yyp: NDArray[np.float64]
    qy: NDArray[np.float64] | None = None
    src: tuple[NDArray[np.complex128], NDArray[np.complex128]] | None = None
    qr: NDArray[np.float64] | None = None
    pseudo: _pseudo.PseudoLines | None = None
    atoms: tuple[NDArray[np.complex128], tuple[NDArray[np.intp], NDArray[np.float64]]] | None = None

    def matches(self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp]) -> bool:
        """Is this the fixed part of the modes ``th`` (``m``, ``ref``)?"""
        return self.m == m and np.array_equal(self.th, th) and np.array_equal(self.ref, ref)

    def made_from(self, poles: NDArray[np.complex128], part: NDArray[np.complex128]) -> bool:
        """Was this formed from these poles and participation (``src``)? Then it is
        their fixed part (a pure function of them and the fitter)."""
        src = self.src
        return src is not None and np.array_equal(src[0], poles) and np.array_equal(src[1], part)


class _Rows:
    """The fixed basis and data rows of the blocks, within one call (nothing is
    kept between calls but what the :class:`FixedPart` holds)."""

    def __init__(self, fitter: FitterState, fx: FixedPart | None, parts: Any, keep: bool) -> None:
        self.fitter, self.fx, self.parts, self.keep = fitter, fx, parts, keep
        self.cols: dict[int, NDArray[np.float64]] = {}

    def basis(self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp], i: int) -> Any:
        """``Phi_f`` of block ``i`` (kept within the call when ``keep``)."""
        if self.fx is not None and self.fx.phi0 is not None:
            return self.fx.phi0
        phi = self.cols.get(i)
        if phi is None:
            phi = self.fitter._basis_ek(th, m, ref, False, self.parts[i])[0]
            if self.keep:
                self.cols[i] = phi
        return phi

    def data(self, yw: NDArray[np.float64] | None, i: int, w: NDArray[np.float64]) -> Any:
        """Weighted data rows of block ``i``."""
        if yw is not None:
            return yw
        return np.asarray(self.fitter._ydata(self.parts[i]) * w)


def fixed_part(
    fitter: FitterState,
    th_f: NDArray[np.float64],
    m: int,
    ref: NDArray[np.intp],
    parts: list[slice],
    src: tuple[NDArray[np.complex128], NDArray[np.complex128]] | None = None,
) -> FixedPart:
    """The fixed part of the modes ``th_f`` (``m``, ``ref``) on the blocks ``parts``
    (module docstring); a pure function of these and of the fitter's data. ``src``:
    the poles and participation ``th_f`` comes from (kept, copied)."""
    w = fitter._w1
    qf = fitter.n_cols(m)
    one = len(parts) == 1
    # the fixed basis is kept when it is no larger than the data (many outputs) or
    # than one block of the fits (a constant, _basis.BLOCK_BYTES); otherwise it is
    # formed again block by block when needed
    keep = one or _no_larger(fitter, qf)
    rows = _Rows(fitter, None, parts, keep)
    yw = np.asarray(fitter._ydata(parts[0]) * w) if one else None
    phi0 = rows.basis(th_f, m, ref, 0) if one else None
    pseudo = sums = None
    if phi0 is None and not keep and _pseudo.applies(fitter):
        # a long record: the pseudo-lines of the fixed basis, and its Gram blocks
        # summed in the same pass over the lines
        base = fitter._pseudo_lines()
        assert base is not None
        at_zero = [0j] if fitter.use_lower and fitter.power < 2 else []
        pseudo, gf, pf = _pseudo.fixed_far(
            fitter,
            base,
            lambda sl: fitter._basis_ek(th_f, m, ref, False, sl)[0],
            lambda fac: fitter._basis_ek(th_f, m, ref, False, None, (fac, None))[0],
            np.concatenate([fitter.unpack(th_f, m, ref)[0], at_zero]),
        )
        sums = (gf, pf * w)
    atoms = None if one or pseudo is not None else _fixed_atoms(fitter, th_f, m, ref, parts)
    if atoms is not None:  # the Gram blocks of the fixed basis from its atoms
        ff = atoms[0]
        gf, pf = _gram_lines.gram_of(fitter, lambda sl: ff[:, sl], (*atoms[1], ff.shape[0]), parts)
        sums = (gf, pf * w)
    # Q_r^T X = T^T Phi_f^T X on an orthonormal basis Q_r of the range of Phi_f,
    # Q_r^T Y and ||P_f Y||^2 once (_fixed_range)
    tmap, qty, yyp = _fixed_range(
        lambda: ((rows.basis(th_f, m, ref, i), rows.data(yw, i, w)) for i in range(len(parts))),
        qf,
        fitter._yss * w**2,
        (phi0, yw) if phi0 is not None and yw is not None else None,
        fitter.n_rows,
        sums,
    )
    qy = qr = None
    r = tmap.shape[1]
    if phi0 is not None and yw is not None:
        qy = np.empty((yw.shape[0], r + yw.shape[1]), order="F")
        np.subtract(yw, np.matmul(phi0, tmap, out=qy[:, :r]) @ qty, out=qy[:, r:])
    elif keep:  # several blocks, the fixed basis no larger than the data: Q_r of every line
        qr = np.empty((fitter.n_rows, r), order="F")
        for i, sl in enumerate(parts):
            qr[line_rows(fitter, sl)] = rows.basis(th_f, m, ref, i) @ tmap
    if src is not None:
        src = (np.array(src[0], complex), np.array(src[1], complex))
    extra = () if atoms is None else (atoms[0], *atoms[1])
    for a in (th_f, ref, phi0, yw, tmap, qty, yyp, qy, qr, *(src or ()), *extra):
        if a is not None:
            a.flags.writeable = False
    return FixedPart(
        th_f, m, ref, tuple(parts), keep, phi0, yw, tmap, qty, yyp, qy, src, qr, pseudo, atoms
    )


def _fixed_atoms(
    fitter: FitterState, th_f: NDArray[np.float64], m: int, ref: NDArray[np.intp], parts: Any
) -> tuple[NDArray[np.complex128], tuple[NDArray[np.intp], NDArray[np.float64]]] | None:
    """The atoms of the fixed basis of every line (n_phi_f, n_f) and its coefficient
    tables (:mod:`._gram_lines`), when they apply (complex modes, several inputs)
    and are no larger than the data or one block of the fits; else None."""
    if fitter.kind != "complex" or not _gram_lines.applies(fitter):
        return None
    poles, part = fitter.unpack(th_f, m, ref)
    idx, val, n_phi = _gram_lines.coefficients(fitter, part, ref, False)
    size = 16 * n_phi * fitter.n_f
    if n_phi > fitter.n_out * fitter.n_in and size > _basis.BLOCK_BYTES:
        return None
    ff = np.empty((n_phi, fitter.n_f), complex)
    for sl in parts:
        ff[:, sl] = _gram_lines.atoms(fitter, poles, False, _basis.factors(fitter, sl))
    return ff, (idx, val)


def _no_larger(fitter: FitterState, n_col: int) -> bool:
    """Are ``n_col`` real columns of every line no larger than the data rows or than
    one block of the fits (:data:`~tyredamp.modal.fit._basis.BLOCK_BYTES`)?"""
    return n_col <= fitter.n_out or 8 * fitter.n_rows * n_col <= _basis.BLOCK_BYTES


def line_rows(fitter: FitterState, sl: slice) -> slice | NDArray[np.intp]:
    """The rows of the lines ``sl`` among the rows of every line (``(k, f)``, real and
    imaginary part interleaved, :func:`~tyredamp.modal.fit._basis.ydata`): a slice for one
    input, else the indices in the order of the rows of a block."""
    n_f, n_in = fitter.n_f, fitter.n_in
    start, stop, _ = sl.indices(n_f)
    if n_in == 1:
        return slice(2 * start, 2 * stop)
    e = (np.arange(n_in)[:, None] * n_f + np.arange(start, stop)[None, :]).ravel()
    return np.stack([2 * e, 2 * e + 1], axis=1).ravel()


def added_solver(
    fitter: FitterState,
    one: FitterState,
    fx: FixedPart,
    ref1: NDArray[np.intp],
    lay1: _basis.Layout,
) -> Any:
    """The projection at the added mode's parameters (``solve(th)`` of
    :meth:`ModalFitter._refine`); ``one``: the fitter of the added mode alone (no
    residual terms), ``lay1`` its derivative layout."""
    w = fitter._w1
    rows = _Rows(fitter, fx, fx.parts, fx.keep)  # this call's fixed basis (several blocks)
    th_f, m_f, ref_f = fx.th, fx.m, fx.ref
    q1 = one.n_cols(1)
    n1 = q1 + int(lay1.ecol.max()) + 1
    qf, r = fx.tmap.shape
    yy = fitter._yss * w**2

    def solution(g0: Any, G: Any, P: Any, projected: Any, pp1: Any) -> dict[str, Any]:
        # columns mostly in span(Phi_f): the QR route of the projected rows
        force = bool((G.diagonal() < _PROJ_TOL * g0.diagonal()).any())
        sol = _vp_solve(
            G,
            P,
            q1,
            fx.yyp,
            projected,
            residual=force,
            gradient=True,
            cancel=yy,
            n_rows=fitter.n_rows,
        )
        sol["lay"] = lay1
        sol["coef"] = _basis.coef(lay1, pp1[0])  # ModalFitter._coef
        return sol

    def solve_one(th: NDArray[np.float64]) -> dict[str, Any]:
        # one block: B1^T [Q_r | P_f Y] in one product (FixedPart.qy); G = B1^T B1 -
        # (Q_r^T B1)^T Q_r^T B1 and P = B1^T P_f Y (= B1^T Y - (Q_r^T B1)^T Q_r^T Y)
        qy = fx.qy
        assert qy is not None
        pp1 = one.unpack(th, 1, ref1)
        b1 = one._basis_ek(th, 1, ref1, True, fx.parts[0], (None, pp1))[0]
        z = b1.T @ qy
        qbt = z[:, :r]  # (Q_r^T B1)^T
        g0 = b1.T @ b1
        G = g0 - qbt @ qbt.T

        def projected() -> Any:
            yield b1 - qy[:, :r] @ qbt.T, qy[:, r:]

        return solution(g0, G, np.array(z[:, r:]), projected, pp1)

    def solve_blocks(th: NDArray[np.float64]) -> dict[str, Any]:
        # the same, the Gram blocks of the added columns summed over blocks of lines
        # (or over the pseudo-lines of a long record, _pseudo)
        pp1 = one.unpack(th, 1, ref1)
        if fx.pseudo is not None:
            cross, g0, p0 = _pseudo.gram_blocks(
                fitter,
                fx.pseudo,
                lambda fac, sl: one._basis_ek(th, 1, ref1, True, sl, (fac, pp1))[0],
                lambda sl: fitter._basis_ek(th_f, m_f, ref_f, False, sl)[0],
                complex(pp1[0][0]),
            )
            p0 = p0 * w
        else:
            cross = np.zeros((qf, n1))
            g0 = np.zeros((n1, n1))
            p0 = np.zeros((n1, fitter.n_out))
            for i, sl in enumerate(fx.parts):
                b1 = one._basis_ek(th, 1, ref1, True, sl, (None, pp1))[0]
                cross += rows.basis(th_f, m_f, ref_f, i).T @ b1
                g0 += b1.T @ b1
                p0 += _basis.rows_t_data(fitter, sl, b1) * w  # no data rows formed
        qb = fx.tmap.T @ cross
        G = g0 - qb.T @ qb
        P = p0 - qb.T @ fx.qty

        def projected() -> Any:
            for i, sl in enumerate(fx.parts):
                b1 = one._basis_ek(th, 1, ref1, True, sl, (None, pp1))[0]
                pt = rows.basis(th_f, m_f, ref_f, i) @ fx.tmap  # Q_r rows
                yield b1 - pt @ qb, rows.data(fx.yw, i, w) - pt @ fx.qty

        return solution(g0, G, P, projected, pp1)

    fac_all = _basis.factors(fitter) if fx.qr is not None and _no_larger(fitter, n1) else None

    def solve_all(th: NDArray[np.float64]) -> dict[str, Any]:
        # several blocks, Q_r of every line kept (FixedPart.qr): the added columns of
        # every line at once (n1 columns, no larger than the data or one block)
        qr = fx.qr
        assert qr is not None
        pp1 = one.unpack(th, 1, ref1)
        b1 = one._basis_ek(th, 1, ref1, True, None, (fac_all, pp1))[0]
        qbt = b1.T @ qr  # (Q_r^T B1)^T
        g0 = b1.T @ b1
        G = g0 - qbt @ qbt.T
        P = _basis.rows_t_data(fitter, slice(0, fitter.n_f), b1) * w - qbt @ fx.qty

        def projected() -> Any:
            for sl in fx.parts:
                rr = line_rows(fitter, sl)
                pt = qr[rr]
                yield b1[rr] - pt @ qbt.T, fitter._ydata(sl) * w - pt @ fx.qty

        return solution(g0, G, P, projected, pp1)

    if fx.qy is not None:
        return solve_one
    if fx.atoms is not None and _gram_lines.USE:
        return _atoms_solver(fitter, one, fx, ref1, solution)
    return solve_all if fac_all is not None else solve_blocks


def _atoms_solver(
    fitter: FitterState, one: FitterState, fx: FixedPart, ref1: NDArray[np.intp], solution: Any
) -> Any:
    """The projection at the added mode's parameters with the Gram blocks of the added
    columns from per-line sums (:func:`~tyredamp.modal.fit._gram_lines.added_sums`,
    ``fx.atoms``); the QR route's rows as :func:`added_solver`'s."""
    w = fitter._w1
    rows = _Rows(fitter, fx, fx.parts, fx.keep)
    assert fx.atoms is not None

    def solve_atoms(th: NDArray[np.float64]) -> dict[str, Any]:
        pp1 = one.unpack(th, 1, ref1)
        assert fx.atoms is not None
        cross, g0, p0 = _gram_lines.added_sums(fitter, pp1, ref1, fx.atoms, fx.parts)
        qb = fx.tmap.T @ cross  # Q_r^T B1
        G = g0 - qb.T @ qb
        P = p0 * w - qb.T @ fx.qty

        def projected() -> Any:
            for i, sl in enumerate(fx.parts):
                b1 = one._basis_ek(th, 1, ref1, True, sl, (None, pp1))[0]
                if fx.qr is not None:
                    pt = fx.qr[line_rows(fitter, sl)]
                else:
                    pt = rows.basis(fx.th, fx.m, fx.ref, i) @ fx.tmap  # Q_r rows
                yield b1 - pt @ qb, rows.data(fx.yw, i, w) - pt @ fx.qty

        return solution(g0, G, P, projected, pp1)

    return solve_atoms
