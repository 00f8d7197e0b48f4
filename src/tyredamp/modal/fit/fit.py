"""Residues (LSFD) and non-linear pole-residue refinement for real and complex modes.

Both models of the paper are fitted to the FRFs in their own kind
(receptance, mobility or accelerance, through the factor ``(i w)^q``):

* complex modes (general viscous damping, spec eq. [10])::

      H_jk(s) = sum_n u_jn l_kn / (s - p_n) + conj(u_jn l_kn) / (s - conj p_n)

  with complex output coefficients ``u_jn`` and participation ``l_kn``
  (rank-one residues ``R_jkn = u_jn l_kn``, one ``l_kn = 1`` per mode);
* real modes (proportional damping, spec eq. [2]/[3])::

      H_jk(s) = sum_n u_jn l_kn / (s^2 + 2 sigma_n s + omega_n^2)

  with real ``u_jn`` and ``l_kn`` (the residue ``R_jkn = u_jn l_kn / (2 i Omega_n)``
  is imaginary, eq. [3] with the factor 2);

plus optional real residual terms per input: an upper residual (constant
receptance, modes above the band) and a lower residual ``L / s^2`` (modes
below the band).

The poles (``sigma_n = w_ref exp(x1)``, ``Omega_n = w_ref x2``: always stable)
and the participation vectors are the non-linear parameters; the coefficients
``u`` and the residuals are linear and are eliminated by least squares for
every output with one shared basis (variable projection, Golub & Pereyra 1973,
with Kaufman's Jacobian). The basis ``Phi`` has ``2 n_in n_freq`` real rows
and ``q`` columns; its derivative columns ``D`` (two per non-linear parameter
and complex mode) are scaled copies of half as many distinct columns ``E``:
per complex mode the pole derivatives are ``-sigma [S]``, ``-sigma [i T]``,
``w_ref [i T]``, ``-w_ref [S]`` (``[.]`` a complex column as real rows, ``S``,
``T`` the sum and difference of the derivatives of the two conjugate terms),
per free participation entry ``[g]``, ``[i g']``, ``[i g']``, ``-[g]``. An evaluation
therefore needs only the Gram blocks of ``B = [Phi | E]`` and ``B^T Y`` (one
symmetric rank-k update and one matrix product with the data, ``O(n_in n_freq
(q + n_e) (q + n_e + n_out))``; with several inputs they are summed from the
modes' per-line functions without forming ``B``, ``O(n_freq n_phi (n_phi + n_in
n_out))`` with ``n_phi = 4 m + 2`` (complex modes; ``3 m + 2`` real):
:mod:`~tyredamp.modal.fit._gram_lines`): with the Cholesky factor ``R`` of ``Phi^T Phi``
(``Phi = Q R``) follow ``Q^T E``, ``Q^T Y``, the coefficients, the cost
``||Y||^2 - ||Q^T Y||^2``, ``E^T P E`` and ``E^T r`` (``P`` the projector on the
complement of the basis, ``r`` the residual), and from them ``J^T J`` and
``J^T r`` -- neither ``Q``, nor the residual, nor the ``(n_out n_in n_freq) x
n_param`` Jacobian is formed. This is accurate to ``eps cond(Phi)^2`` (the
columns scaled to unit norm); for a basis whose condition estimate is too
large for that, ``Phi`` is orthogonalised by CholeskyQR2 (shifted CholeskyQR3
beyond its range), and when the cost would lose accuracy by cancellation or
the condition exceeds even that, the same quantities come from a Householder
QR of ``[Phi | E]`` with ``Q^T`` applied to ``Y``
(:func:`~tyredamp.modal.fit._linalg._vp_solve`). The refinement is a bounded
Levenberg-Marquardt iteration on these normal equations.

Memory: the Gram blocks, the QR and the fitted FRFs are summed over blocks of
lines of a fixed size (:func:`~tyredamp.modal.fit._basis.blocks`, 8 MB); the basis
of all lines, the weighted data ``Y`` and the residual are never held, so a fit
costs the data plus a constant. The data rows, ``s = i w`` and ``kappa`` of a
block are formed when needed (the attributes ``Y``, ``s``, ``kappa``,
``kappa_low`` form them for all lines on request); with several blocks ``B^T
Y`` comes from the complex data (:func:`~tyredamp.modal.fit._basis.rows_t_data`),
no data rows are formed. When the data rows fit one block (the common case: 16
outputs x 800 lines are 0.2 MB), the fitter forms them and the line factors
once and keeps them (no more than the one block of a blocked fit), and a basis
is formed once per evaluation for every route. A fitter keeps nothing between
calls: what one call can reuse from another is passed explicitly -- the fixed
part of ``fit_added`` (:meth:`ModalFitter.fixed_part`, an immutable
:class:`~tyredamp.modal.fit._added.FixedPart` formed once per fixed mode set) and
a previous intermediate fit at rest (``fit(..., start=res)``).

Scaling (spec step 3 and eq. [10]): with drive points ``(j_k, k)`` (output
``j_k`` at the place of input ``k``) reciprocity ``psi_in[k] = psi_out[j_k]``
fixes ``a_n^2 = sum_k conj(u_{j_k n}) l_kn / sum_k |u_{j_k n}|^2`` and
``psi_out = a u``, ``psi_in = l / a`` (complex), or ``phi_out = a u``,
``phi_in = l / a`` and ``psi = phi / sqrt(2 i Omega)`` (real modes; ``a^2`` must
be real and positive, a warning says when it is not).

Uncertainty: the residual variance at the optimum and the Gauss-Newton
covariance ``s^2 (J^T J)^-1`` of the non-linear parameters, plus the
conditional covariance of the linear coefficients, propagated to natural
frequencies, damping ratios and mode-shape entries by the delta method.
"""

from __future__ import annotations

import copy
from dataclasses import replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InputError
from ..problem.compress import _compress, combine_outputs, compress_outputs  # noqa: F401 (re-exported)
from . import _added, _basis, _gram_lines, _pseudo, _results, _scaling
from ._linalg import _levenberg_marquardt, _vp_solve, at_rest
from ._results import FitResult

__all__ = ["FitResult", "ModalFitter", "combine_outputs", "compress_outputs"]

ModelKind = Literal["complex", "real"]

#: noise floor of the mode statistics, relative to the RMS of each output: the
#: noise can never be below the rounding of the data and of the fit (synthesised
#: double-precision FRFs and the fit's arithmetic carry 1e-13..1e-11); without
#: it, noise-free data would make structure at the level of rounding "significant"
NOISE_FLOOR = 1e-10


def pole_bounds(m: int, n_par: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Bounds of a parameter vector of ``m`` modes (:meth:`ModalFitter.pack` layout,
    ``n_par`` entries) that keep every pole finite: ``sigma`` in [1e-7, 5] ``w_ref``,
    ``Omega`` in (0, 20] ``w_ref``; the participation free."""
    lb = np.full(n_par, -np.inf)
    ub = np.full(n_par, np.inf)
    lb[0 : 2 * m : 2], ub[0 : 2 * m : 2] = np.log(1e-7), np.log(5.0)
    lb[1 : 2 * m : 2], ub[1 : 2 * m : 2] = 1e-6, 20.0
    return lb, ub


class ModalFitter:
    """Fit poles, participation and residues to FRFs (one model kind).

    Parameters
    ----------
    frequency : ndarray, shape (n_freq,)
        Lines in Hz, all > 0.
    H : ndarray, complex, shape (n_out, n_in, n_freq)
        FRFs of kind ``power`` (0 receptance, 1 mobility, 2 accelerance).
    power : int
        Power of ``i w`` that turns receptance into the data kind.
    mode_kind : {"complex", "real"}
        Model of the residues.
    drive : list of (int, int)
        Drive points ``(output index, input index)`` for the scaling.
    upper, lower : bool
        Include the upper and lower residual terms.
    unit_weights : bool
        Weight every output row by 1 in every pass (for rows that are already
        normalised combinations of outputs, see :func:`compress_outputs`).
    line_weights : ndarray, shape (n_freq,), optional
        Weight of each line (``1 / sigma_f`` of a per-line noise model
        ``Var H_jk(f) = sigma_j^2 sigma_f^2``): data and basis rows of line
        ``f`` are multiplied by it, so that the least-squares cost is the
        Gaussian negative log-likelihood of that noise model (maximum
        likelihood). Default 1 for every line. ``FitResult.model`` is
        returned unweighted.
    """

    def __init__(
        self,
        frequency: NDArray[np.float64],
        H: NDArray[np.complex128],
        power: int,
        mode_kind: ModelKind,
        drive: list[tuple[int, int]],
        *,
        upper: bool = True,
        lower: bool = True,
        unit_weights: bool = False,
        line_weights: NDArray[np.float64] | None = None,
    ) -> None:
        if mode_kind not in ("complex", "real"):
            raise InputError(f"mode_kind: expected 'complex' or 'real', got {mode_kind!r}")
        if np.any(frequency <= 0):
            raise InputError("frequency: the fit needs lines above 0 Hz")
        self.f = frequency
        self.H = H
        self.n_out, self.n_in, self.n_f = H.shape
        self.kind = mode_kind
        self.drive = list(drive)
        self.use_upper = upper
        self.use_lower = lower
        self.unit_weights = unit_weights
        self.power = int(power)
        self.line_weights: NDArray[np.float64] | None = None
        if line_weights is not None:
            lw = np.asarray(line_weights, float)
            if lw.shape != frequency.shape or not np.all(np.isfinite(lw) & (lw > 0)):
                raise InputError(
                    f"line_weights: expected {frequency.size} finite positive values, got "
                    f"shape {lw.shape}"
                )
            # every basis column is kappa or kappa_low times a function of s: weighting
            # the two factors weights every basis and derivative row of the line
            self.line_weights = lw
        self.w_ref = float(2 * np.pi * frequency[-1])
        # data rows (k, f), real and imaginary part interleaved (_basis.ydata), are
        # formed block by block when needed; only their sums of squares are kept --
        # unless they fit one block (the common case): then they are formed once and
        # kept, with the line factors (s, kappa, kappa_low: three values per line)
        self.n_rows = 2 * self.n_in * self.n_f
        self._y: NDArray[np.float64] | None = None
        self._factors: tuple[NDArray[np.complex128], ...] | None = None
        if _basis.one_block(self):
            fac = _basis.factors(self)
            y = _basis.ydata(self)
            for a in (*fac, y):
                a.flags.writeable = False
            self._factors, self._y = fac, y
        yss = np.zeros(self.n_out)
        for sl in _basis.blocks(self, 0):
            yb = _basis.ydata(self, sl)
            yss += np.einsum("ij,ij->j", yb, yb)
        self._yss = yss  # ||Y_j||^2 per output
        self.data_ss = float(np.sum(yss))
        self._rms = np.sqrt(yss / max(self.n_rows, 1))  # RMS per output row
        #: noise floor per output (units of the data; NOISE_FLOOR)
        self.noise_floor = NOISE_FLOOR * self._rms
        # weights of a first pass (fit without sigma, fit_added): 1 / RMS per output
        self._w1 = (
            np.ones_like(self._rms)
            if unit_weights
            else 1.0 / np.where(self._rms > 0, self._rms, 1.0)
        )
        # the pseudo-lines of the data of a long record (_pseudo), formed at first use
        self._pl: _pseudo.PseudoLines | None = None
        # the fitter of fit_added's one added mode (formed once: settings never change)
        self._added_one = self._make_added_one()

    def _pseudo_lines(self) -> _pseudo.PseudoLines | None:
        """The pseudo-lines of the data (:mod:`._pseudo`) when they apply to this
        fitter (a long record), formed at the first call and kept (about 1 % of the
        data's memory); else None."""
        if self._pl is None and _pseudo.applies(self):
            self._pl = _pseudo.pseudo_lines(self)
        return self._pl

    @property
    def Y(self) -> NDArray[np.float64]:
        """Data rows (2 n_in n_freq, n_out), formed on request (the fits use blocks)."""
        return _basis.ydata(self)

    @property
    def s(self) -> NDArray[np.complex128]:
        """``i w`` of every line (formed on request)."""
        return _basis.factors(self)[0]

    @property
    def kappa(self) -> NDArray[np.complex128]:
        """``(i w)^power`` times the line weights (formed on request)."""
        return _basis.factors(self)[1]

    @property
    def kappa_low(self) -> NDArray[np.complex128]:
        """``(i w)^(power - 2)`` times the line weights (formed on request)."""
        return _basis.factors(self)[2]

    # ------------------------------------------------------------ layout
    def n_cols(self, m: int) -> int:
        per = 2 if self.kind == "complex" else 1
        return per * m + self.n_in * (int(self.use_upper) + int(self.use_lower))

    def pack(
        self, poles: NDArray[np.complex128], part: NDArray[np.complex128], ref: NDArray[np.intp]
    ) -> NDArray[np.float64]:
        """Parameter vector from poles (m,), participation (m, n_in) and reference index (m,)."""
        sig = np.maximum(-poles.real, 1e-9 * np.abs(poles))
        x = [np.log(sig / self.w_ref), poles.imag / self.w_ref]
        th = np.stack(x, axis=1).ravel()
        if self.n_in == 1:
            return th
        m = poles.size
        lp = part / part[np.arange(m), ref][:, None]
        others = []
        for n in range(m):
            for k in range(self.n_in):
                if k == ref[n]:
                    continue
                if self.kind == "complex":
                    others += [lp[n, k].real, lp[n, k].imag]
                else:
                    others.append(lp[n, k].real)
        return np.concatenate([th, np.asarray(others, float)])

    def unpack(
        self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp]
    ) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Poles (m,) and participation (m, n_in) from the parameter vector."""
        x1 = th[0 : 2 * m : 2]
        x2 = th[1 : 2 * m : 2]
        poles = self.w_ref * (-np.exp(x1) + 1j * x2)
        part = np.ones((m, self.n_in), complex)
        if self.n_in > 1:
            free = np.ones((m, self.n_in), bool)
            free[np.arange(m), ref] = False  # row-major: modes, then inputs k != ref
            if self.kind == "complex":
                part[free] = th[2 * m :: 2] + 1j * th[2 * m + 1 :: 2]
            else:
                part[free] = th[2 * m :]
        return poles, part

    # ------------------------------------------------------------- basis
    def basis(
        self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp], derivatives: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp], NDArray[np.intp]]:
        """Real basis ``Phi`` (n_rows, q) and its derivative columns.

        Returns ``Phi``, ``D`` (n_rows, n_d), ``dpar`` (n_d,) parameter index and
        ``dcol`` (n_d,) basis column of each derivative column. ``D`` is
        ``E[:, ecol] * coef`` of the distinct columns ``E`` that the fits use
        (:meth:`_basis_ek`, :meth:`_layout`, :meth:`_coef`).
        """
        B, poles = self._basis_ek(th, m, ref, derivatives)
        q = self.n_cols(m)
        phi = B[:, :q]
        if not derivatives:
            return phi, np.zeros((self.n_rows, 0)), np.zeros(0, np.intp), np.zeros(0, np.intp)
        lay = self._layout(m)
        D = B[:, q:][:, lay.ecol] * self._coef(lay, poles)[None, :]
        return phi, D, lay.dpar.copy(), lay.dcol.copy()

    # the basis and its derivative columns (functions of the fitter, in _basis)
    _layout = _basis.layout
    _coef = staticmethod(_basis.coef)
    _basis_ek = _basis.basis_ek
    _basis_real = _basis.basis_real
    _ydata = _basis.ydata

    def _solve(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        w: NDArray[np.float64],
        residual: bool = True,
        gradient: bool = True,
        derivatives: bool = True,
    ) -> dict[str, Any]:
        """Projection at ``th`` for the data weighted by ``w`` (n_out,) per output.

        The Gram blocks ``B^T B`` and ``B^T Y`` of ``B = [Phi | E]`` are summed over
        blocks of lines (:func:`~tyredamp.modal.fit._basis.blocks`; neither the basis nor
        the weighted data of all lines is formed) and solved by :func:`_vp_solve`,
        which goes through the blocks again for the QR route. With ``residual=True``
        the QR route is taken (no cancellation in the cost); otherwise only when
        the Gram matrix is ill-conditioned or the cost would lose accuracy;
        ``gradient=False``: no ``E^T r`` (a fit without refinement needs no
        gradient); ``derivatives=False``: no ``E`` (nor ``J^T J``)."""
        q = self.n_cols(m)
        pp = self.unpack(th, m, ref)
        lay = self._layout(m) if derivatives else None
        n_col = q + (0 if lay is None else int(lay.ecol.max(initial=-1)) + 1)
        parts = _basis.blocks(self, n_col)

        def rows() -> Any:
            for sl in parts:
                b = self._basis_ek(th, m, ref, derivatives, sl, (None, pp))[0]
                yield b, self._ydata(sl) * w

        explicit = rows
        one = None
        pl = None if len(parts) == 1 or residual else self._pseudo_lines()
        if pl is None and _gram_lines.applies(self):
            # several inputs (complex or real modes): the Gram blocks from per-line sums of
            # the atoms (_gram_lines), the basis formed only for the QR route
            G, P = _gram_lines.gram(self, pp, ref, derivatives, parts)
            P = P * w
            if len(parts) == 1:  # formed at most once, kept for the QR route's passes
                kept: list[Any] = []

                def explicit() -> Any:
                    if not kept:
                        kept.extend(rows())
                    return iter(kept)
        elif len(parts) == 1:  # one block: formed once, kept for the QR route
            kept = list(rows())
            B, Yb = kept[0]
            G, P = B.T @ B, B.T @ Yb
            one = (B, Yb)

            def explicit() -> Any:
                return iter(kept)
        elif pl is not None:
            # a long record: the Gram blocks from the pseudo-lines of the bins far
            # from every pole (the lower residual term's at 0 for a negative power)
            at_zero = [0j] if self.use_lower and self.power < 2 else []
            G, P = _pseudo.gram_full(
                self,
                pl,
                lambda fac, sl: self._basis_ek(th, m, ref, derivatives, sl, (fac, pp))[0],
                np.concatenate([pp[0], at_zero]),
            )
            P = P * w
        else:
            G = np.zeros((n_col, n_col))
            P = np.zeros((n_col, self.n_out))
            for sl in parts:  # B^T Y from the complex data (no data rows formed)
                B = self._basis_ek(th, m, ref, derivatives, sl, (None, pp))[0]
                G += B.T @ B
                P += _basis.rows_t_data(self, sl, B) * w
        sol = _vp_solve(
            G,
            P,
            q,
            self._yss * w**2,
            explicit,
            residual=residual,
            gradient=gradient and derivatives,
            one=one,
            n_rows=self.n_rows,
        )
        if lay is not None:
            sol["lay"] = lay
            sol["coef"] = self._coef(lay, pp[0])
        return sol

    def _normal(
        self, sol: dict[str, Any], n_par: int
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kaufman ``J^T J`` and ``J^T r`` of the projected residual.

        With ``D = E[:, ecol] * coef``, ``dpar`` and ``dcol`` (:meth:`_layout`),
        ``G_E = E^T P E`` and ``W = C C^T``: ``J^T J = Ac^T (G_E[ecol, ecol] o
        W[dcol, dcol]) Ac`` (``Ac`` the 0/1 map of derivative columns to
        parameters times ``coef``) and ``J^T r = -Ac^T h`` with ``h_d = (E^T r
        C^T)[ecol_d, dcol_d]``.
        """
        lay, C = sol["lay"], sol["C"]
        Ac = lay.A * sol["coef"][:, None]
        if Ac.shape[1] != n_par:
            raise ValueError(f"n_par: layout has {Ac.shape[1]} parameters, got {n_par}")
        W = C @ C.T
        Md = np.take(sol["GE"], lay.ee) * np.take(W, lay.dd)
        jtj = Ac.T @ Md @ Ac
        jtj = 0.5 * (jtj + jtj.T)
        Etr = sol["Etr"]  # E^T r, (n_e, n_out)
        if Etr is None:
            return jtj, np.zeros(n_par)
        jtr = -(Ac.T @ np.take(Etr @ C.T, lay.eq))
        return jtj, jtr

    def fit(
        self,
        poles: NDArray[np.complex128],
        part: NDArray[np.complex128],
        *,
        refine: bool = True,
        max_nfev: int = 200,
        passes: int = 2,
        sigma: NDArray[np.float64] | None = None,
        tol: float = 1e-6,
        uncertainty: bool = True,
        start: FitResult | None = None,
        n_interest: int | None = None,
    ) -> FitResult:
        """Fit from initial poles (m,) and participation (m, n_in).

        With ``refine=False`` only the linear residues are fitted (LSFD with
        fixed poles); otherwise poles, participation and residues together.
        Pass 1 weights each output by ``1 / RMS`` (or by ``1 / sigma`` when
        the noise RMS per output ``sigma`` (n_out,) is given); later passes by
        ``1 / sigma_j`` with ``sigma_j`` the residual RMS of the previous pass.
        ``tol`` is the convergence threshold of the refinement in units of the
        residual variance (:func:`_levenberg_marquardt`); ``uncertainty=False``
        skips the standard errors (left at NaN), for intermediate fits.

        ``n_interest``: the refinement may stop once the poles and participation
        of the first ``n_interest`` modes (the band's; the rest residual modes
        outside it, nuisance parameters) have converged, whatever the others
        still do (:func:`~tyredamp.modal.fit._linalg.interest_decrement`);
        default None: every parameter must converge.

        ``start``: a previous result of this fitter whose poles and
        participation are ``poles`` and ``part``. When it is an intermediate
        one-pass refinement that stopped at rest (``start.rest``) with the
        weights and ``tol`` of this call, this refinement would stop at once:
        ``start`` is returned (as a copy, ``n_iter = 1``) without evaluating.
        """
        m = int(poles.size)
        part = np.asarray(part, complex).reshape(m, self.n_in)
        same = (
            start is not None
            and start.rest is not None
            and np.array_equal(np.asarray(poles, complex), start.poles)
            and np.array_equal(part, start.participation)
        )
        if self.kind == "real":
            ph = np.exp(-1j * np.angle(part[np.arange(m), np.argmax(np.abs(part), axis=1)]))
            part = (part * ph[:, None]).real.astype(complex)
        ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
        th = self.pack(np.asarray(poles, complex), part, ref)
        w = self.weights(sigma)
        # an intermediate one-pass refinement started at the result of the previous
        # one (same weights and tolerance) that stopped at rest would stop at once:
        # that result again (one evaluation)
        once = refine and not uncertainty and passes <= 1 and max_nfev >= 2
        if once and same and start is not None and start.rest is not None:
            w_rest, tol_rest = start.rest
            if tol_rest == tol and np.array_equal(w_rest, w):
                return replace(start, n_iter=1, warnings=list(start.warnings))
        q = self.n_cols(m)
        dof = self.n_rows - q
        status = "lsfd"
        nit = 0
        warn: list[str] = []
        keep = None if n_interest is None else self.interest(m, n_interest)
        for ip in range(max(1, passes if refine else 1)):
            if refine:
                th, nfev, status, sol = self._refine(
                    th, m, ref, w, max_nfev, tol=tol, interest=keep
                )
                nit += nfev
            else:
                sol = self._solve(
                    th, m, ref, w, residual=False, gradient=False, derivatives=uncertainty
                )
            sig_out = np.sqrt(sol["cost_out"] / w**2 / max(dof, 1))
            if ip + 1 < passes and refine:
                w = self.weights(sig_out)
        if status == "maxfev":
            warn.append(f"refinement stopped at the evaluation limit ({max_nfev})")
        res = self._result(th, m, ref, w, sol, sig_out, nit, status, warn, uncertainty)
        if once and status == "converged" and self._at_rest(th, sol):
            res.rest = (w.copy(), float(tol))
        return res

    def interest(self, m: int, n: int) -> NDArray[np.intp] | None:
        """Indices into a parameter vector of ``m`` modes (:meth:`pack` layout) of
        the poles and free participation entries of its first ``n`` modes (None
        when that is every parameter, or no mode: then every parameter must
        converge)."""
        if n < 0:
            raise InputError(f"n_interest: expected a mode count of at least 0, got {n}")
        if n >= m or n == 0:
            return None
        per = (self.n_in - 1) * (2 if self.kind == "complex" else 1)
        poles = np.arange(2 * n)
        part = 2 * m + np.arange(per * n)  # mode-major: the first n modes' entries
        return np.concatenate([poles, part]).astype(np.intp)

    def weights(self, sigma: NDArray[np.float64] | None) -> NDArray[np.float64]:
        """Row weights of each output (n_out,) for a noise RMS per output ``sigma``
        (units of the data): ``1 / sigma``, ``sigma`` at least 1e-9 of the output's
        RMS; the first-pass weights when None or with unit weights."""
        if sigma is None or self.unit_weights:
            return self._w1
        floor = np.maximum(1e-9 * self._rms, 1e-300)
        return np.asarray(1.0 / np.maximum(np.asarray(sigma, float), floor))

    def _real_part(self, part: NDArray[np.complex128]) -> NDArray[np.complex128]:
        """Real-mode participation: each row turned by the phase of its largest entry."""
        if self.kind != "real":
            return part
        m = part.shape[0]
        ph = np.exp(-1j * np.angle(part[np.arange(m), np.argmax(np.abs(part), axis=1)]))
        return (part * ph[:, None]).real.astype(complex)

    def _added_fitter(self) -> tuple[ModalFitter, Any, int]:
        """The fitter of one added mode alone (no residual terms), its derivative
        layout and its number of basis and derivative columns."""
        return self._added_one

    def _make_added_one(self) -> tuple[ModalFitter, Any, int]:
        """:meth:`_added_fitter`'s value, formed once by the constructor."""
        one = copy.copy(self)
        one.use_upper = one.use_lower = False
        lay1 = one._layout(1)
        return one, lay1, one.n_cols(1) + int(lay1.ecol.max()) + 1

    def _fixed_modes(
        self, poles: NDArray[np.complex128], part: NDArray[np.complex128], n1: int
    ) -> tuple[NDArray[np.float64], int, NDArray[np.intp], list[slice]]:
        """Parameters of the fixed modes and the blocks of lines of ``fit_added``
        (``n1`` columns of the added mode)."""
        m = int(np.asarray(poles).size)
        part = self._real_part(np.asarray(part, complex).reshape(m, self.n_in))
        ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
        th_f = self.pack(np.asarray(poles, complex), part, ref)
        return th_f, m, ref, _basis.blocks(self, self.n_cols(m) + n1)

    def fixed_part(
        self, poles: NDArray[np.complex128], part: NDArray[np.complex128]
    ) -> _added.FixedPart:
        """The fixed part of :meth:`fit_added` for the fixed modes ``poles`` (m,)
        and ``part`` (m, n_in): an immutable value (the range of their basis and
        of the residual terms, :mod:`~tyredamp.modal.fit._added`) to form once and
        pass as ``fixed`` to every ``fit_added`` against these modes."""
        got = self._fixed_modes(poles, part, self._added_fitter()[2])
        return _added.fixed_part(self, *got, src=(poles, part))

    def fit_added(
        self,
        poles: NDArray[np.complex128],
        part: NDArray[np.complex128],
        pole: complex,
        part_new: NDArray[np.complex128],
        *,
        omega_bounds: tuple[float, float] | None = None,
        max_nfev: int = 200,
        tol: float = 1e-6,
        fixed: _added.FixedPart | None = None,
        sigma_max: float | None = None,
    ) -> tuple[complex, NDArray[np.complex128], NDArray[np.float64]]:
        """Refine one added mode with the modes ``poles`` (m,) held fixed.

        The basis ``Phi_f`` of the fixed modes and of the residual terms is
        projected out of the data; the added pole and participation
        (``part_new``, (n_in,)) are then refined by variable projection on the
        projected data (same weighting as the first pass of :meth:`fit`). An
        evaluation solves the joint projection of ``[Phi_f | Phi_1 | E_1]``
        (:func:`_vp_solve`), whose rows of the added mode are those of the
        projected problem (Frisch-Waugh-Lovell theorem, e.g. Seber & Lee 2003,
        sec. 3.7); ``Phi_f^T Phi_f`` and ``Phi_f^T Y`` are summed once
        (:meth:`fixed_part`), an evaluation adds the blocks of the added columns
        ``B1 = [Phi_1 | E_1]`` (``Phi_f^T B1``, ``B1^T B1``, ``B1^T Y``) over
        blocks of lines; the QR route of :func:`_vp_solve` is taken when the
        subtraction would lose accuracy. ``omega_bounds`` (rad/s, lower < upper)
        limits the damped natural frequency ``Im p`` of the added mode; ``tol``
        as in :meth:`fit`; ``sigma_max`` (rad/s) bounds its decay rate ``-Re p``.
        ``fixed``: the :meth:`fixed_part` of ``poles`` and ``part`` (formed by
        this call when None; another mode set's is refused).

        Returns
        -------
        pole : complex
            Refined pole of the added mode (rad/s).
        participation : ndarray, complex, shape (n_in,)
        sigma_out : ndarray, shape (n_out,)
            Residual RMS per output of the model with all ``m + 1`` modes
            (in the units of the data), as ``FitResult.sigma_out`` of a
            one-pass fit.
        """
        one, lay1, n1 = self._added_fitter()
        if fixed is not None and fixed.made_from(poles, part):
            m = fixed.m  # formed from these very modes: nothing to check
        else:
            th_f, m, ref, parts = self._fixed_modes(poles, part, n1)
            if fixed is None:
                fixed = _added.fixed_part(self, th_f, m, ref, parts)
            elif not (fixed.matches(th_f, m, ref) and fixed.parts == tuple(parts)):
                raise InputError("fixed: the fixed part of other modes than poles and part")
        l1 = self._real_part(np.asarray(part_new, complex).reshape(1, self.n_in))
        p1 = np.array([pole], complex)
        ref1 = np.argmax(np.abs(l1), axis=1).astype(np.intp)
        w = self._w1
        th0 = one.pack(p1, l1, ref1)
        solve = _added.added_solver(self, one, fixed, ref1, lay1)
        box = None if omega_bounds is None else (*omega_bounds, sigma_max or np.inf)
        th, _, _, sol = self._refine(th0, 1, ref1, w, max_nfev, solve, box, tol)
        p_out, l_out = one.unpack(th, 1, ref1)
        dof = self.n_rows - self.n_cols(m + 1)
        res_ss = np.maximum(sol["cost_out"], 0.0) / w**2
        return complex(p_out[0]), l_out[0], np.sqrt(res_ss / max(dof, 1))

    def _refine(
        self,
        th0: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        w: NDArray[np.float64],
        max_nfev: int,
        solve: Any = None,
        box: tuple[float, float, float] | None = None,
        tol: float = 1e-6,
        interest: NDArray[np.intp] | None = None,
    ) -> tuple[NDArray[np.float64], int, str, dict[str, Any]]:
        n_par = th0.size
        lb, ub = pole_bounds(m, n_par)
        if box is not None:  # Im p in [box[0], box[1]], -Re p below box[2] (rad/s)
            lb[1 : 2 * m : 2] = max(1e-6, box[0] / self.w_ref)
            ub[1 : 2 * m : 2] = min(20.0, box[1] / self.w_ref)
            ub[0 : 2 * m : 2] = min(np.log(5.0), np.log(max(box[2] / self.w_ref, 1e-6)))
        th0 = np.minimum(np.maximum(th0, lb + 1e-9), ub - 1e-9)
        n_lin = self.n_cols(m) if solve is None else 2
        n_obs = self.n_rows * self.n_out

        def evaluate(x: NDArray[np.float64]) -> tuple[float, Any, Any, dict[str, Any]]:
            # a given ``solve`` (fit_added) replaces the projection
            sol = self._solve(x, m, ref, w, residual=False) if solve is None else solve(x)
            jtj, jtr = self._normal(sol, n_par)
            sol["jtj"] = jtj  # kept for the standard errors at the optimum
            sol["jtr"] = jtr
            return float(sol["cost"]), jtj, jtr, sol

        dof = max(n_obs - n_lin * self.n_out - n_par, 1)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x, nfev, ok, sol = _levenberg_marquardt(
                evaluate, th0, lb, ub, max_nfev, dof=dof, tol=tol, interest=interest
            )
        sol["lm"] = (lb, ub, dof, tol)  # the iteration's settings (_at_rest)
        return x, nfev, "converged" if ok else "maxfev", sol

    @staticmethod
    def _at_rest(x: NDArray[np.float64], sol: dict[str, Any]) -> bool:
        """Would a refinement started at its result ``x`` (strictly inside the bounds)
        stop at once (:func:`~tyredamp.modal.fit._linalg.at_rest`)?"""
        lb, ub, dof, tol = sol["lm"]
        inside = bool(np.all((x > lb + 1e-9) & (x < ub - 1e-9)))
        return inside and at_rest(x, sol["cost"], sol["jtj"], sol["jtr"], (lb, ub), tol, dof)

    # --------------------------------------------------------- results
    # scaling and shape uncertainty (functions of the fitter, in _scaling)
    _scale = _scaling.scale
    _scale_jacobian = _scaling.scale_jacobian
    _shape_std = _scaling.shape_std
    # the standard errors and the result at the optimum (functions of the fitter, in _results)
    _pole_std = _results.pole_and_shape_std
    _result = _results.assemble
