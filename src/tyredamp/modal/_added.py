"""The projection of :meth:`~tyredamp.modal.fit.ModalFitter.fit_added`: one added
mode refined with the other modes held fixed.

The fixed basis ``Phi_f`` (the fixed modes and the residual terms) is projected
out of the data once (:func:`fixed_part`: the range map of
:func:`~tyredamp.modal._linalg._fixed_range`); an evaluation at the added
mode's parameters (:func:`added_solver`) then needs only the Gram blocks of the
added columns ``B1 = [Phi_1 | E_1]`` against ``Phi_f``, themselves and the data
(Frisch-Waugh-Lovell theorem, e.g. Seber & Lee, *Linear Regression Analysis*,
2003, sec. 3.7; equations in the docstring of ``fit_added``).

The residual search tries many candidates against the same fixed modes: the
fitter keeps the fixed part of its latest fixed modes (``_fixed_memo``, keyed
by their parameters and the blocks of lines), so a candidate against the same
modes does not form their basis and range again. It is a pure cache: the
fixed part is a function of that key and of the fitter's data. Held between
calls are the range map and, when the data fit one block
(:func:`~tyredamp.modal._basis.one_block`), that block's fixed basis and
weighted data rows (no more than one block of a blocked fit).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _basis
from ._linalg import _PROJ_TOL, _fixed_range, _vp_solve


@dataclass
class FixedPart:
    """The fixed basis's part of :meth:`ModalFitter.fit_added` (module docstring).

    ``cols``: fixed basis ``Phi_f`` of the blocks kept (block index to rows);
    ``keep``: whether a block's basis is kept once formed; ``yw``: the weighted
    data rows of the one block (None with several blocks); ``tmap``, ``qty``,
    ``yyp``: the range map ``T``, ``Q_r^T Y`` and ``||P_f Y||^2``
    (:func:`_fixed_range`); ``qr``: ``Q_r = Phi_f T`` of the one block, formed
    when the QR route needs it.
    """

    th: NDArray[np.float64]
    m: int
    ref: NDArray[np.intp]
    parts: list[slice]
    cols: dict[int, NDArray[np.float64]]
    keep: bool
    yw: NDArray[np.float64] | None
    tmap: NDArray[np.float64]
    qty: NDArray[np.float64]
    yyp: NDArray[np.float64]
    qr: NDArray[np.float64] | None = None

    def basis(self, fitter: Any, i: int) -> NDArray[np.float64]:
        """``Phi_f`` of block ``i`` (kept when ``keep``)."""
        phi = self.cols.get(i)
        if phi is None:
            phi = fitter._basis_ek(self.th, self.m, self.ref, False, self.parts[i])[0]
            if self.keep:
                self.cols[i] = phi
        return phi

    def data(self, fitter: Any, i: int, w: NDArray[np.float64]) -> NDArray[np.float64]:
        """Weighted data rows of block ``i``."""
        if self.yw is not None:
            return self.yw
        return np.asarray(fitter._ydata(self.parts[i]) * w)

    def q_range(self, fitter: Any, i: int) -> NDArray[np.float64]:
        """``Q_r`` rows of block ``i`` (``Phi_f T``; kept for the one block)."""
        if self.yw is None:
            return np.asarray(self.basis(fitter, i) @ self.tmap)
        if self.qr is None:
            self.qr = np.asarray(self.basis(fitter, i) @ self.tmap)
        return self.qr


def fixed_part(
    fitter: Any, th_f: NDArray[np.float64], m: int, ref: NDArray[np.intp], parts: list[slice]
) -> FixedPart:
    """The fixed part of the modes ``th_f`` (``m``, ``ref``) on the blocks ``parts``:
    the fitter's ``_fixed_memo`` when it holds these, else formed (and, with one
    block, kept there; module docstring)."""
    key = (m, th_f.tobytes(), ref.tobytes(), tuple(sl.indices(fitter.n_f) for sl in parts))
    memo = fitter._fixed_memo
    if memo is not None and memo[0] == key:
        held: FixedPart = memo[1]
        # several blocks: the range map is held, the bases are formed in this call
        return held if held.yw is not None else dataclasses.replace(held, cols={})
    w = fitter._w1
    qf = fitter.n_cols(m)
    one = len(parts) == 1
    # the fixed basis is kept when it is no larger than the data (many outputs) or
    # fits one block; otherwise it is formed again block by block when needed
    fx = FixedPart(
        th=th_f,
        m=m,
        ref=ref,
        parts=parts,
        cols={},
        keep=one or qf <= fitter.n_out,
        yw=np.asarray(fitter._ydata(parts[0]) * w) if one else None,
        tmap=np.zeros((qf, 0)),
        qty=np.zeros((0, fitter.n_out)),
        yyp=np.zeros(fitter.n_out),
    )
    # Q_r^T X = T^T Phi_f^T X on an orthonormal basis Q_r of the range of Phi_f,
    # Q_r^T Y and ||P_f Y||^2 once (_fixed_range)
    fx.tmap, fx.qty, fx.yyp = _fixed_range(
        lambda: ((fx.basis(fitter, i), fx.data(fitter, i, w)) for i in range(len(parts))),
        qf,
        fitter._yss * w**2,
        (fx.basis(fitter, 0), fx.data(fitter, 0, w)) if one else None,
    )
    # several blocks: only the range map is held between calls
    fitter._fixed_memo = (key, fx if one else dataclasses.replace(fx, cols={}))
    return fx


def added_solver(fitter: Any, one: Any, fx: FixedPart, ref1: NDArray[np.intp], lay1: Any) -> Any:
    """The projection at the added mode's parameters (``solve(th)`` of
    :meth:`ModalFitter._refine`); ``one``: the fitter of the added mode alone (no
    residual terms), ``lay1`` its derivative layout."""
    w = fitter._w1
    q1 = one.n_cols(1)
    n1 = q1 + int(lay1.ecol.max()) + 1
    qf = fx.tmap.shape[0]
    yy = fitter._yss * w**2
    nb = len(fx.parts)

    def solve(th: NDArray[np.float64]) -> dict[str, Any]:
        # Gram blocks of the added mode's [Phi_1 | E_1] projected on the complement
        # of Phi_f: B1^T B1 - (Q_r^T B1)^T Q_r^T B1 and B1^T Y - (Q_r^T B1)^T Q_r^T Y
        pp1 = one.unpack(th, 1, ref1)
        b1s: list[NDArray[np.float64]] = []
        if nb == 1:  # one block: the products themselves (no sums)
            b1 = one._basis_ek(th, 1, ref1, True, fx.parts[0], (None, pp1))[0]
            b1s.append(b1)
            cross, g0, p0 = fx.basis(fitter, 0).T @ b1, b1.T @ b1, b1.T @ fx.data(fitter, 0, w)
        else:
            cross = np.zeros((qf, n1))
            g0 = np.zeros((n1, n1))
            p0 = np.zeros((n1, fitter.n_out))
            for i, sl in enumerate(fx.parts):
                b1 = one._basis_ek(th, 1, ref1, True, sl, (None, pp1))[0]
                cross += fx.basis(fitter, i).T @ b1
                g0 += b1.T @ b1
                p0 += _basis.rows_t_data(fitter, sl, b1) * w  # no data rows formed
        qb = fx.tmap.T @ cross
        G = g0 - qb.T @ qb
        P = p0 - qb.T @ fx.qty

        def projected() -> Any:
            for i, sl in enumerate(fx.parts):
                b1 = b1s[i] if b1s else one._basis_ek(th, 1, ref1, True, sl, (None, pp1))[0]
                pt = fx.q_range(fitter, i)
                yield b1 - pt @ qb, fx.data(fitter, i, w) - pt @ fx.qty

        # columns mostly in span(Phi_f): the QR route of the projected rows
        force = bool(np.any(np.diag(G) < _PROJ_TOL * np.diag(g0)))
        sol = _vp_solve(G, P, q1, fx.yyp, projected, residual=force, gradient=True, cancel=yy)
        sol["lay"] = lay1
        sol["coef"] = one._coef(lay1, pp1[0])
        return sol

    return solve
