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
(q + n_e) (q + n_e + n_out))``): with the Cholesky factor ``R`` of ``Phi^T Phi``
(``Phi = Q R``) follow ``Q^T E``, ``Q^T Y``, the coefficients, the cost
``||Y||^2 - ||Q^T Y||^2``, ``E^T P E`` and ``E^T r`` (``P`` the projector on the
complement of the basis, ``r`` the residual), and from them ``J^T J`` and
``J^T r`` -- neither ``Q``, nor the residual, nor the ``(n_out n_in n_freq) x
n_param`` Jacobian is formed. This is accurate to ``eps cond(Phi)^2`` (the
columns scaled to unit norm); a basis whose condition estimate is too large
for that is orthogonalised (Householder or CholeskyQR2) instead, and the
residual is formed when the cost would lose accuracy by cancellation. The
refinement is a bounded Levenberg-Marquardt iteration on these normal
equations.

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
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray
from scipy.linalg import lapack

from ..exceptions import InputError

__all__ = ["FitResult", "ModalFitter", "combine_outputs", "compress_outputs"]

ModelKind = Literal["complex", "real"]

#: noise floor of the mode statistics, relative to the RMS of each output: the
#: noise can never be below the rounding of the data and of the fit (synthesised
#: double-precision FRFs and the fit's arithmetic carry 1e-13..1e-11); without
#: it, noise-free data would make structure at the level of rounding "significant"
NOISE_FLOOR = 1e-10

#: derivative-column layouts (ModalFitter._layout) per (kind, m, n_in, q, w_ref)
_LAYOUTS: dict[tuple[str, int, int, int, float], _Layout] = {}


@dataclass
class FitResult:
    """Outcome of one fit (internal layout; :mod:`identify` turns it into a ModalModel).

    All shapes refer to ``m`` modes, ``n_out`` outputs and ``n_in`` inputs.
    """

    poles: NDArray[np.complex128]
    psi_out: NDArray[np.complex128]
    psi_in: NDArray[np.complex128]
    upper: NDArray[np.float64] | None
    lower: NDArray[np.float64] | None
    std_frequency_hz: NDArray[np.float64]
    std_damping_ratio: NDArray[np.float64]
    std_psi_out: NDArray[np.float64]
    std_pole: NDArray[np.complex128]
    model: NDArray[np.complex128]  # fitted FRFs in the data's kind (empty for intermediate fits)
    sigma_out: NDArray[np.float64]
    cost: float
    n_iter: int
    status: str
    warnings: list[str] = field(default_factory=list)
    contribution: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    #: extra-sum-of-squares statistic of each mode (:func:`_extra_ss` / s^2)
    significance: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    #: number of (weighted) real observations and of fitted parameters
    n_obs: int = 0
    n_par: int = 0
    theta: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    participation: NDArray[np.complex128] = field(default_factory=lambda: np.zeros((0, 0), complex))
    drive_phi2: NDArray[np.complex128] = field(default_factory=lambda: np.zeros(0, complex))


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
        w = 2 * np.pi * frequency
        self.s = 1j * w
        self.kappa = (1j * w) ** power
        self.kappa_low = (1j * w) ** (power - 2)
        self.line_weights: NDArray[np.float64] | None = None
        if line_weights is not None:
            lw = np.asarray(line_weights, float)
            if lw.shape != frequency.shape or not np.all(np.isfinite(lw) & (lw > 0)):
                raise InputError(
                    f"line_weights: expected {frequency.size} finite positive values, got "
                    f"shape {lw.shape}"
                )
            self.line_weights = lw
            # every basis column is kappa or kappa_low times a function of s: weighting
            # the two factors weights every basis and derivative row of the line
            self.kappa = self.kappa * lw
            self.kappa_low = self.kappa_low * lw
            H = H * lw[None, None, :]
        self._kap2 = 2.0 * self.kappa[None, :]
        self.w_ref = float(w[-1])
        # theta, ref, Phi, R and Q (None when not formed) of the latest fit's
        # projection, reused by fit_added(theta=...)
        self._last_q: tuple[Any, ...] | None = None
        # data: rows (k, f) complex, real and imaginary part interleaved (row 2i:
        # Re, row 2i + 1: Im of line i); the basis columns use the same layout
        hc = H.transpose(1, 2, 0).reshape(self.n_in * self.n_f, self.n_out)
        self.Y = np.stack([hc.real, hc.imag], axis=1).reshape(2 * hc.shape[0], self.n_out)
        self.n_rows = self.Y.shape[0]
        self.data_ss = float(np.sum(self.Y**2))
        self._rms = np.sqrt(np.mean(self.Y**2, axis=0))  # RMS per output row
        #: noise floor per output (units of the data; NOISE_FLOOR)
        self.noise_floor = NOISE_FLOOR * self._rms
        # weights of a first pass (fit without sigma, fit_added): 1 / RMS per output
        self._w1 = (
            np.ones_like(self._rms)
            if unit_weights
            else 1.0 / np.where(self._rms > 0, self._rms, 1.0)
        )

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

    def _layout(self, m: int) -> _Layout:
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
        q = self.n_cols(m)
        key = (self.kind, m, self.n_in, q, self.w_ref)
        lay = _LAYOUTS.get(key)
        if lay is not None:
            return lay
        nin = self.n_in
        ar = np.arange(m)
        if self.kind == "complex":
            n_par = 2 * m + 2 * (nin - 1) * m
            npp, ne_m = 4 * nin, 2 * nin
            e_m = [0, 1, 1, 0]
            for j in range(nin - 1):
                e_m += [2 + 2 * j, 3 + 2 * j, 3 + 2 * j, 2 + 2 * j]
            sign_m = [-1.0, -1.0, self.w_ref, -self.w_ref] + [1.0, 1.0, 1.0, -1.0] * (nin - 1)
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
        lay = _Layout(
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
        if len(_LAYOUTS) >= 64:
            _LAYOUTS.clear()
        _LAYOUTS[key] = lay
        return lay

    @staticmethod
    def _coef(lay: _Layout, poles: NDArray[np.complex128]) -> NDArray[np.float64]:
        """Factors ``coef`` (n_d,) of ``D = E[:, ecol] * coef`` at the poles."""
        coef = lay.sign.copy()
        if lay.nsig:
            cm = coef.reshape(poles.size, -1)
            cm[:, : lay.nsig] *= (-poles.real)[:, None]  # d p / d x1 = -sigma
        return coef

    def _basis_ek(
        self, th: NDArray[np.float64], m: int, ref: NDArray[np.intp], derivatives: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
        """``B = [Phi | E]`` (n_rows, q + n_e), Fortran-ordered, and the poles.

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
        poles, part = self.unpack(th, m, ref)
        q = self.n_cols(m)
        if self.kind == "real":
            phi, D = self._basis_real(poles, part, ref, derivatives)
            B = np.empty((self.n_rows, q + D.shape[1]), order="F")
            B[:, :q] = phi
            B[:, q:] = D
            return B, poles
        nin, nf = self.n_in, self.n_f
        ne = 2 * nin * m if derivatives else 0
        # rows: columns of B, complex (real and imaginary part interleaved as in Y)
        bt = np.empty((q + ne, nin, nf), complex)
        s, kap = self.s[None, :], self.kappa[None, :]
        if nin == 1:
            sig = (-poles.real)[:, None] + 0j  # complex factors: no casts in the loops
            mom = -poles.imag[:, None] + 0j
            den = s - poles[:, None]
            den *= s - np.conj(poles)[:, None]  # d = (s - p)(s - conj p)
            r = np.reciprocal(den)
            h = self._kap2 * r  # 2 kappa / d
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
            _put_pair(bt, 0, 2, A, B_)
            if derivatives:
                A *= e[:, None, :]
                B_ *= eb[:, None, :]
                _put_pair(bt, q, 2 * nin, A, B_)
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
        for use, kk in ((self.use_upper, self.kappa), (self.use_lower, self.kappa_low)):
            if use:
                bt[c0 : c0 + nin] = 0.0
                for k in range(nin):
                    bt[c0 + k, k] = kk
                c0 += nin
        return bt.reshape(q + ne, nin * nf).view(np.float64).T, poles

    def _basis_real(
        self,
        poles: NDArray[np.complex128],
        part: NDArray[np.complex128],
        ref: NDArray[np.intp],
        derivatives: bool,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``Phi`` and ``D`` of the real-mode model (columns of :meth:`_layout`)."""
        nin, nf = self.n_in, self.n_f
        s, kap = self.s, self.kappa
        m = poles.size
        q = self.n_cols(m)
        cols = np.zeros((q, nin, nf), complex)
        dl: list[NDArray[np.complex128]] = []
        for n in range(m):
            p = poles[n]
            sig, om = -p.real, p.imag
            L = part[n]
            den = s**2 + 2 * sig * s + sig**2 + om**2
            base = kap / den
            cols[n] = L.real[:, None] * base[None, :]
            if not derivatives:
                continue
            d_sig = -kap * (2 * s + 2 * sig) / den**2
            d_om = -kap * (2 * om) / den**2
            dl += [L.real[:, None] * (d_sig * sig)[None, :]]
            dl += [L.real[:, None] * (d_om * self.w_ref)[None, :]]
            for k in range(nin):
                if k == ref[n]:
                    continue
                a_ = np.zeros((nin, nf), complex)
                a_[k] = base
                dl.append(a_)
        c0 = m
        if self.use_upper:
            for k in range(nin):
                cols[c0, k] = kap
                c0 += 1
        if self.use_lower:
            for k in range(nin):
                cols[c0, k] = self.kappa_low
                c0 += 1
        phi = cols.reshape(q, nin * nf).view(np.float64).T
        if not derivatives or not dl:
            return phi, np.zeros((self.n_rows, 0))
        return phi, np.stack(dl).reshape(len(dl), nin * nf).view(np.float64).T

    # ---------------------------------------------------- variable projection
    def _solve(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        Yw: NDArray[np.float64],
        residual: bool = True,
        gradient: bool = True,
        yy: NDArray[np.float64] | None = None,
        derivatives: bool = True,
    ) -> dict[str, Any]:
        """Projection at ``th`` from the Gram blocks ``B^T B`` and ``B^T Yw`` of ``B =
        [Phi | E]`` (:func:`_vp_solve`). With ``residual=False`` the residual
        matrix is not formed unless the cost would lose accuracy (an output
        fitted better than 0.1 %); ``gradient=False``: no ``E^T r`` (a fit
        without refinement needs no gradient); ``derivatives=False``: no ``E``
        (nor ``J^T J``). ``yy``: the column sums of ``Yw**2``, when already known."""
        B, poles = self._basis_ek(th, m, ref, derivatives)
        q = self.n_cols(m)
        if yy is None:
            yy = np.einsum("ij,ij->j", Yw, Yw)
        sol = _vp_solve(
            B.T @ B,
            B.T @ Yw,
            q,
            yy,
            lambda: (B, Yw),
            residual=residual,
            gradient=gradient and derivatives,
        )
        sol["phi"] = B[:, :q]
        if derivatives:
            lay = self._layout(m)
            sol["lay"] = lay
            sol["coef"] = self._coef(lay, poles)
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
        """
        m = int(poles.size)
        part = np.asarray(part, complex).reshape(m, self.n_in)
        if self.kind == "real":
            ph = np.exp(-1j * np.angle(part[np.arange(m), np.argmax(np.abs(part), axis=1)]))
            part = (part * ph[:, None]).real.astype(complex)
        ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
        th = self.pack(np.asarray(poles, complex), part, ref)
        floor = 1e-9 * self._rms
        w = self._w1
        if sigma is not None and not self.unit_weights:
            w = 1.0 / np.maximum(np.asarray(sigma, float), np.maximum(floor, 1e-300))
        q = self.n_cols(m)
        dof = self.n_rows - q
        status = "lsfd"
        nit = 0
        warn: list[str] = []
        for ip in range(max(1, passes if refine else 1)):
            Yw = self.Y * w[None, :]
            if refine:
                th, nfev, status, sol = self._refine(th, m, ref, Yw, max_nfev, tol=tol)
                nit += nfev
            else:
                sol = self._solve(
                    th, m, ref, Yw, residual=False, gradient=False, derivatives=uncertainty
                )
            sig_out = np.sqrt(sol["cost_out"] / w**2 / max(dof, 1))
            if ip + 1 < passes and refine and not self.unit_weights:
                w = 1.0 / np.maximum(sig_out, np.maximum(floor, 1e-300))
        if status == "maxfev":
            warn.append(f"refinement stopped at the evaluation limit ({max_nfev})")
        # the projection at the result, for fit_added(theta=...) on these modes
        self._last_q = (th.copy(), ref.copy(), sol["phi"], sol["R"], sol["Q"])
        return self._result(th, m, ref, w, sol, sig_out, nit, status, warn, uncertainty)

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
        theta: NDArray[np.float64] | None = None,
    ) -> tuple[complex, NDArray[np.complex128], NDArray[np.float64]]:
        """Refine one added mode with the modes ``poles`` (m,) held fixed.

        The basis of the fixed modes and of the residual terms (orthonormal
        ``Qf``) is projected out of the data; the added pole and participation
        (``part_new``, (n_in,)) are then refined by variable projection on the
        projected data (same weighting as the first pass of :meth:`fit`). An
        evaluation needs the Gram blocks of the added mode's columns ``B1 = [Phi_1
        | E_1]`` only: ``B1^T B1 - (Qf^T B1)^T Qf^T B1`` and ``B1^T Y - (Qf^T
        B1)^T Qf^T Y`` (``Qf^T Y`` once per call), neither the projected data nor
        the projected columns are formed unless the subtraction would lose
        accuracy (columns or data mostly in the span of ``Qf``).
        ``omega_bounds`` (rad/s, lower < upper) limits the damped natural
        frequency ``Im p`` of the added mode; ``tol`` as in :meth:`fit`.
        ``theta``: the parameter vector of the fixed modes when they come from
        this fitter's latest :meth:`fit` (``FitResult.theta``), whose
        orthonormal basis is then reused.

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
        m = int(poles.size)
        part = np.asarray(part, complex).reshape(m, self.n_in)
        p1 = np.array([pole], complex)
        l1 = np.asarray(part_new, complex).reshape(1, self.n_in)
        if self.kind == "real":
            allp = np.concatenate([part, l1])
            ph = np.exp(-1j * np.angle(allp[np.arange(m + 1), np.argmax(np.abs(allp), axis=1)]))
            allp = (allp * ph[:, None]).real.astype(complex)
            part, l1 = allp[:m], allp[m:]
        ref = np.argmax(np.abs(part), axis=1).astype(np.intp)
        ref1 = np.argmax(np.abs(l1), axis=1).astype(np.intp)
        w = self._w1
        Yw = self.Y * w[None, :]
        yy = np.einsum("ij,ij->j", Yw, Yw)
        last = self._last_q
        if (
            theta is not None
            and last is not None
            and np.array_equal(theta, last[0])
            and np.array_equal(ref, last[1])
        ):
            phi_f, r_f, q_f = last[2], last[3], last[4]
        else:
            phi_f = self.basis(self.pack(poles, part, ref), m, ref, derivatives=False)[0]
            q_f, r_f = _orth(phi_f)
        # products with the fixed modes' orthonormal basis Qf (Qf = Phi_f R_f^-1 when
        # the latest fit did not form it)
        if q_f is None:

            def qt(X: NDArray[np.float64]) -> NDArray[np.float64]:
                return np.asarray(lapack.dtrtrs(r_f, phi_f.T @ X, trans=1)[0])

            def back(QX: NDArray[np.float64]) -> NDArray[np.float64]:
                return np.asarray(phi_f @ lapack.dtrtrs(r_f, QX)[0])

        else:
            qf = q_f

            def qt(X: NDArray[np.float64]) -> NDArray[np.float64]:
                return np.asarray(qf.T @ X)

            def back(QX: NDArray[np.float64]) -> NDArray[np.float64]:
                return np.asarray(qf @ QX)

        # the data projected on the complement of the fixed basis, Yp = Yw - Qf Qf^T Yw,
        # enters through Qf^T Yw only (formed when ||Yp||^2 would lose accuracy)
        qty = qt(Yw)
        Yp: NDArray[np.float64] | None = None
        yyp = yy - np.einsum("ij,ij->j", qty, qty)
        if np.any(yyp < _CANCEL_TOL * yy):
            Yp = Yw - back(qty)
            yyp = np.einsum("ij,ij->j", Yp, Yp)
        yp_cache: list[NDArray[np.float64]] = [] if Yp is None else [Yp]

        def projected_data() -> NDArray[np.float64]:
            if not yp_cache:
                yp_cache.append(Yw - back(qty))
            return yp_cache[0]

        # the added mode alone: same fitter without residual columns
        one = copy.copy(self)
        one.use_upper = one.use_lower = False
        th0 = one.pack(p1, l1, ref1)
        q1 = one.n_cols(1)
        lay1 = one._layout(1)

        def solve(th: NDArray[np.float64]) -> dict[str, Any]:
            # Gram blocks of the added mode's [Phi | E] projected on the complement of Qf
            B1, p_1 = one._basis_ek(th, 1, ref1)
            QB = qt(B1)
            G0 = B1.T @ B1
            G = G0 - QB.T @ QB
            d0 = np.diag(G0)
            Bp: NDArray[np.float64] | None = None
            if np.any(np.diag(G) < _PROJ_TOL * d0):  # mostly in span(Qf): project explicitly
                Bp = B1 - back(QB)
                G = Bp.T @ Bp
                P = Bp.T @ projected_data()
            elif Yp is None:
                P = B1.T @ Yw - QB.T @ qty
            else:
                P = B1.T @ Yp

            def explicit() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
                return (B1 - back(QB) if Bp is None else Bp), projected_data()

            sol = _vp_solve(
                G,
                P,
                q1,
                yyp,
                explicit,
                residual=False,
                gradient=True,
                cancel=yy if Yp is None else yyp,
            )
            sol["lay"] = lay1
            sol["coef"] = one._coef(lay1, p_1)
            return sol

        th, _, _, sol = self._refine(
            th0, 1, ref1, Yw, max_nfev, solve=solve, omega_bounds=omega_bounds, tol=tol
        )
        p_out, l_out = one.unpack(th, 1, ref1)
        dof = self.n_rows - self.n_cols(m + 1)
        res_ss = np.maximum(sol["cost_out"], 0.0) / w**2
        return complex(p_out[0]), l_out[0], np.sqrt(res_ss / max(dof, 1))

    def _refine(
        self,
        th0: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        Yw: NDArray[np.float64],
        max_nfev: int,
        solve: Any = None,
        omega_bounds: tuple[float, float] | None = None,
        tol: float = 1e-6,
    ) -> tuple[NDArray[np.float64], int, str, dict[str, Any]]:
        n_par = th0.size
        # bounds keep every pole finite: sigma in [1e-7, 5] w_ref, Omega in (0, 20] w_ref
        lb = np.full(n_par, -np.inf)
        ub = np.full(n_par, np.inf)
        lb[0 : 2 * m : 2], ub[0 : 2 * m : 2] = np.log(1e-7), np.log(5.0)
        lb[1 : 2 * m : 2], ub[1 : 2 * m : 2] = 1e-6, 20.0
        if omega_bounds is not None:
            lb[1 : 2 * m : 2] = max(1e-6, omega_bounds[0] / self.w_ref)
            ub[1 : 2 * m : 2] = min(20.0, omega_bounds[1] / self.w_ref)
        th0 = np.clip(th0, lb + 1e-9, ub - 1e-9)

        n_lin = self.n_cols(m) if solve is None else 2
        n_obs = Yw.size

        yy = np.einsum("ij,ij->j", Yw, Yw) if solve is None else None

        def evaluate(x: NDArray[np.float64]) -> tuple[float, Any, Any, dict[str, Any]]:
            # a given ``solve`` (fit_added) replaces the projection
            sol = self._solve(x, m, ref, Yw, residual=False, yy=yy) if solve is None else solve(x)
            jtj, jtr = self._normal(sol, n_par)
            sol["jtj"] = jtj  # kept for the standard errors at the optimum
            return float(sol["cost"]), jtj, jtr, sol

        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x, nfev, ok, sol = _levenberg_marquardt(
                evaluate,
                th0,
                lb,
                ub,
                max_nfev,
                dof=max(n_obs - n_lin * Yw.shape[1] - n_par, 1),
                tol=tol,
            )
        return x, nfev, "converged" if ok else "maxfev", sol

    # --------------------------------------------------------- results
    def _scale(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        cd_w: NDArray[np.float64],
        wd: NDArray[np.float64],
    ) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.float64]]:
        """Scale factors ``b`` (m,) with ``psi_out = u b``; ``psi_in`` (n_in, m); ``a^2`` check.

        ``cd_w`` (n_drive, q) are the weighted coefficients of the drive outputs.
        """
        poles, part = self.unpack(th, m, ref)
        if self.kind == "complex":
            ud = np.asarray(
                (cd_w[:, 0 : 2 * m : 2] + 1j * cd_w[:, 1 : 2 * m : 2]) / wd[:, None], complex
            )
        else:
            ud = np.asarray(cd_w[:, :m] / wd[:, None], complex)
        if ud.shape[0] == 0:
            a = np.ones(m, complex)
            a2r = np.ones(m)
        else:
            ks = np.array([k for _, k in self.drive])
            lk = part[:, ks].T  # (n_drive, m)
            den = np.sum(np.abs(ud) ** 2, axis=0)
            a2 = np.sum(np.conj(ud) * lk, axis=0) / np.where(den > 0, den, 1.0)
            a2r = a2.real.copy()
            a = np.sqrt(np.abs(a2.real)) + 0j if self.kind == "real" else np.sqrt(a2)
            a = np.where(a == 0, 1.0, a)
        psi_in = (part / a[:, None]).T
        b = a.copy()
        if self.kind == "real":
            root = np.sqrt(2j * poles.imag)
            b = a / root
            psi_in = psi_in / root[None, :]
        return b, psi_in, a2r

    def _scale_jacobian(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        cd_w: NDArray[np.float64],
        wd: NDArray[np.float64],
    ) -> NDArray[np.complex128]:
        """``d b / d G`` (n_par + n_drive q, m) of :meth:`_scale`, analytically.

        ``G = [theta, cd_w.ravel()]``. With ``a^2 = N / den``, ``N = sum_d conj(u_d)
        l_{k_d}``, ``den = sum_d |u_d|^2`` (``u_d = cd_w[d] / wd[d]``):
        ``d a^2 / d Re u_d = (l - 2 a^2 Re u_d) / den``, ``d a^2 / d Im u_d =
        (-i l - 2 a^2 Im u_d) / den``, ``d a^2 / d l_k = sum_{d: k_d = k} conj(u_d)
        / den``; complex modes ``b = a = sqrt(a^2)``, real modes ``a = |Re
        a^2|^(1/2)`` and ``b = a / sqrt(2 i Omega)``.
        """
        n_par = th.size
        nd, q = cd_w.shape
        beta = np.zeros((n_par + nd * q, m), complex)
        if nd == 0:
            return beta
        poles, part = self.unpack(th, m, ref)
        ks = np.array([k for _, k in self.drive], dtype=np.intp)
        cplx = self.kind == "complex"
        if cplx:
            u_raw = (cd_w[:, 0 : 2 * m : 2] + 1j * cd_w[:, 1 : 2 * m : 2]) / wd[:, None]
        else:
            u_raw = cd_w[:, :m] / wd[:, None]
        ud = np.asarray(u_raw, dtype=complex)
        lk = part[:, ks].T  # (nd, m)
        den = np.sum(np.abs(ud) ** 2, axis=0)
        den = np.where(den > 0, den, 1.0)
        a2 = np.sum(np.conj(ud) * lk, axis=0) / den
        d_re = (lk - 2 * a2[None, :] * ud.real) / den[None, :]
        d_im = (-1j * lk - 2 * a2[None, :] * ud.imag) / den[None, :]
        d_l = np.zeros((m, self.n_in), complex)  # d a^2 / d l_k (a real l_k step)
        for d, k in enumerate(ks):
            d_l[:, k] += np.conj(ud[d]) / den
        if cplx:
            a = np.sqrt(a2)
            fac = np.where(a == 0, 0.0, 0.5 / np.where(a == 0, 1.0, a))  # d a / d a^2

            def conv(x: NDArray[np.complex128]) -> NDArray[np.complex128]:
                return np.asarray(fac * x)

        else:
            a = np.sqrt(np.abs(a2.real))
            root = np.sqrt(2j * poles.imag)
            sgn = np.sign(a2.real)
            fac_r = np.where(a == 0, 0.0, 0.5 * sgn / np.where(a == 0, 1.0, a))

            def conv(x: NDArray[np.complex128]) -> NDArray[np.complex128]:
                return np.asarray(fac_r * x.real / root)

            b = np.where(a == 0, 1.0, a) / root
            ar = np.arange(m)
            beta[2 * ar + 1, ar] = -b * self.w_ref / (2 * poles.imag)
        ar = np.arange(m)
        for d in range(nd):
            base = n_par + d * q
            if cplx:
                beta[base + 2 * ar, ar] = conv(d_re[d]) / wd[d]
                beta[base + 2 * ar + 1, ar] = conv(d_im[d]) / wd[d]
            else:
                beta[base + ar, ar] = conv(d_re[d]) / wd[d]
        i = 2 * m
        for n in range(m):
            for k in range(self.n_in):
                if k == ref[n]:
                    continue
                beta[i, n] = conv(d_l[:, k])[n]
                i += 1
                if cplx:  # imaginary part of l_k
                    beta[i, n] = conv(1j * d_l[:, k])[n]
                    i += 1
        return beta

    def _result(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        w: NDArray[np.float64],
        sol: dict[str, Any],
        sig_out: NDArray[np.float64],
        nit: int,
        status: str,
        warn: list[str],
        uncertainty: bool = True,
    ) -> FitResult:
        n_par = th.size
        C = sol["C"]
        q = C.shape[0]
        Cu = C / w[None, :]
        poles, _ = self.unpack(th, m, ref)
        didx = np.array([j for j, _ in self.drive], dtype=np.intp)
        wd = w[didx]
        b, psi_in, a2r = self._scale(th, m, ref, C[:, didx].T, wd)
        u = (
            Cu[0 : 2 * m : 2].T + 1j * Cu[1 : 2 * m : 2].T
            if self.kind == "complex"
            else Cu[:m].T + 0j
        )
        psi_out = u * b[None, :]
        off = (2 if self.kind == "complex" else 1) * m
        upper = lower = None
        if self.use_upper:
            upper = Cu[off : off + self.n_in].T.copy()
            off += self.n_in
        if self.use_lower:
            lower = Cu[off : off + self.n_in].T.copy()
        if didx.size == 0:
            warn.append("no drive point (output at an input): shapes are not mass-normalised")
            phi2 = np.full(m, np.nan + 0j)
        else:
            kin = np.array([k for _, k in self.drive], dtype=np.intp)
            # 2 i Omega_n R_kkn at the drive points (= phi_kn^2 for a real mode, eq. [3])
            phi2 = np.mean(2j * poles.imag[None, :] * psi_out[didx] * psi_in[kin], axis=0)
        for n in range(m):
            f_n = abs(poles[n]) / (2 * np.pi)
            if didx.size and self.kind == "real" and a2r[n] <= 0:
                warn.append(
                    f"mode at {f_n:.2f} Hz: drive-point residue gives phi^2 = 2 i Omega R_kk "
                    "<= 0 (not real positive); shape scaled with |phi^2|"
                )
            if didx.size and self.kind == "complex" and phi2[n].real <= 0:
                warn.append(
                    f"mode at {f_n:.2f} Hz: drive-point residue has Re(2 i Omega R_kk) <= 0 "
                    "(negative modal mass); check the drive point and the mode"
                )
        # ---- uncertainty (Gauss-Newton at the optimum + delta method)
        n_obs = self.n_rows * self.n_out
        dof = max(n_obs - q * self.n_out - n_par, 1)
        s2 = sol["cost"] / dof
        nan = np.full(m, np.nan)
        std_f, std_z, std_pole = nan, nan.copy(), nan + 0j
        std_psi = np.full((self.n_out, m), np.nan)
        if uncertainty:
            jtj = sol["jtj"] if "jtj" in sol else self._normal(sol, n_par)[0]
            cth = s2 * np.linalg.pinv(jtj, hermitian=True)
            x1 = th[0 : 2 * m : 2]
            sig = self.w_ref * np.exp(x1)
            om = poles.imag
            mag = np.abs(poles)
            jf = np.zeros((m, n_par))
            jz = np.zeros((m, n_par))
            ar = np.arange(m)
            jf[ar, 2 * ar] = (sig / mag) * sig / (2 * np.pi)
            jf[ar, 2 * ar + 1] = (om / mag) * self.w_ref / (2 * np.pi)
            jz[ar, 2 * ar] = (om**2 / mag**3) * sig
            jz[ar, 2 * ar + 1] = (-sig * om / mag**3) * self.w_ref
            std_f = np.sqrt(np.maximum(np.einsum("ni,ij,nj->n", jf, cth, jf), 0.0))
            std_z = np.sqrt(np.maximum(np.einsum("ni,ij,nj->n", jz, cth, jz), 0.0))
            std_pole = (
                np.sqrt(np.maximum(cth[2 * ar, 2 * ar], 0)) * sig
                + 1j * np.sqrt(np.maximum(cth[2 * ar + 1, 2 * ar + 1], 0)) * self.w_ref
            )
            std_psi = self._shape_std(th, m, ref, w, sol, cth, s2, b, u, didx)
        # ---- model (final fits only), contributions
        phi = sol["phi"]
        model = np.zeros((0, self.n_in, self.n_f), complex)
        if uncertainty:
            hw = np.ascontiguousarray((C / w[None, :]).T @ phi.T)  # (n_out, n_rows)
            model = hw.view(np.complex128).reshape(self.n_out, self.n_in, self.n_f)
            if self.line_weights is not None:
                model = model / self.line_weights[None, None, :]
        per = 2 if self.kind == "complex" else 1
        data_ss = self.data_ss
        # ||Phi_n C_n||^2 per output from the (per x per) Gram block of each mode's
        # columns, a diagonal block of Phi^T Phi = R^T R: no (n_rows x n_out) array
        rb = sol["R"][:, : per * m].reshape(-1, m, per)
        gram = np.matmul(rb.transpose(1, 2, 0), rb.transpose(1, 0, 2))  # (m, per, per)
        cb = C[: per * m].reshape(m, per, self.n_out)
        ss = np.sum(cb * np.matmul(gram, cb), axis=1)  # (m, n_out)
        contrib = np.sqrt(np.sum(ss / w[None, :] ** 2, axis=1) / max(data_ss, 1e-300))
        s2_floor = float(np.mean((w * self.noise_floor) ** 2))
        signif = _extra_ss(sol["R"], C, per, m) / max(s2, s2_floor, 1e-300)
        return FitResult(
            poles=poles,
            psi_out=psi_out,
            psi_in=psi_in,
            upper=upper,
            lower=lower,
            std_frequency_hz=std_f,
            std_damping_ratio=std_z,
            std_psi_out=std_psi,
            std_pole=std_pole,
            model=model,
            sigma_out=sig_out,
            cost=float(sol["cost"]),
            n_iter=nit,
            status=status,
            warnings=warn,
            contribution=contrib,
            significance=signif,
            n_obs=n_obs,
            n_par=q * self.n_out + n_par,
            theta=th,
            participation=self.unpack(th, m, ref)[1],
            drive_phi2=phi2,
        )

    def _shape_std(
        self,
        th: NDArray[np.float64],
        m: int,
        ref: NDArray[np.intp],
        w: NDArray[np.float64],
        sol: dict[str, Any],
        cth: NDArray[np.float64],
        s2: float,
        b: NDArray[np.complex128],
        u: NDArray[np.complex128],
        didx: NDArray[np.intp],
    ) -> NDArray[np.float64]:
        """``sqrt(E|d psi_out|^2)`` per entry (n_out, m) by the delta method."""
        C, Rq = sol["C"], sol["R"]
        lay = sol["lay"]
        q, n_out = C.shape
        n_par = th.size
        nd = didx.size
        rinv = lapack.dtrtri(Rq)[0]
        F = rinv @ rinv.T  # (Phi^T Phi)^-1
        E = rinv @ (sol["QtE"][:, lay.ecol] * sol["coef"][None, :])  # Phi^+ D, (q, n_d)
        A = lay.A
        # M_j = -Phi^+ dPhi/dtheta C_j: M[j, a, k] = -sum_d E[a, d] C[dcol_d, j] A[d, k]
        ec = E[None, :, :] * C[lay.dcol].T[:, None, :]  # (n_out, q, n_d)
        M = -(ec.reshape(n_out * q, -1) @ A).reshape(n_out, q, n_par)
        MC = (M.reshape(n_out * q, n_par) @ cth).reshape(M.shape)  # Cov(C_j, theta)
        # Var of the coefficient of mode n for output j
        cov_cc_diag = s2 * np.diag(F)[None, :] + np.einsum("jak,jak->ja", MC, M)
        if self.kind == "complex":
            var_u = cov_cc_diag[:, 0 : 2 * m : 2] + cov_cc_diag[:, 1 : 2 * m : 2]
        else:
            var_u = cov_cc_diag[:, :m]
        term1 = np.abs(b[None, :]) ** 2 * var_u / w[:, None] ** 2
        if nd == 0:
            # unscaled shapes: only the coefficient noise and the participation
            return np.asarray(np.sqrt(np.maximum(term1, 0.0)))
        # global quantities G = [theta, C_D (n_d * q)] and d b / d G
        beta = self._scale_jacobian(th, m, ref, C[:, didx].T, w[didx])
        ng = beta.shape[0]
        MD = M[didx]  # (nd, q, n_par)
        # Sigma_GG
        sgg = np.zeros((ng, ng))
        sgg[:n_par, :n_par] = cth
        cdt = MC[didx]  # Cov(C_D, theta): (nd, q, n_par)
        sgg[n_par:, :n_par] = cdt.reshape(nd * q, n_par)
        sgg[:n_par, n_par:] = sgg[n_par:, :n_par].T
        dd = cdt.reshape(nd * q, n_par) @ MD.reshape(nd * q, n_par).T  # MD cth MD^T
        dd += s2 * np.kron(np.eye(nd), F)
        sgg[n_par:, n_par:] = dd
        v3 = np.real(np.sum(beta.conj() * (sgg @ beta), axis=0))
        term3 = np.abs(u) ** 2 * v3[None, :]
        # cross_jn = sum_g Sigma_cG_j[a_n, g] beta[g, n] with Sigma_cG_j = [MC_j,
        # MC_j MD^T + s2 F (j = drive)] (a_n the coefficient rows of mode n), summed
        # without forming the (n_out, q, ng) matrix: T = beta_theta + MD^T beta_D
        beta_d = beta[n_par:]  # (nd q, m)
        T = beta[:n_par] + MD.reshape(nd * q, n_par).T @ beta_d  # (n_par, m)
        bd = beta_d.reshape(nd, q, m)
        fb = s2 * np.matmul(F, bd)  # (nd, q, m)
        rsel = (
            [np.arange(0, 2 * m, 2), np.arange(1, 2 * m, 2)]
            if self.kind == "complex"
            else [np.arange(m)]
        )
        cross = np.zeros((self.n_out, m), complex)
        for sign, rr in zip((1.0, -1j), rsel, strict=False):
            part_ = np.einsum("jnk,kn->jn", MC[:, rr, :], T)
            for i, j in enumerate(didx):
                part_[j] += fb[i, rr, np.arange(m)]
            cross += sign * part_
        term2 = 2 * np.real(np.conj(b)[None, :] / w[:, None] * u * cross)
        return np.asarray(np.sqrt(np.maximum(term1 + term2 + term3, 0.0)))


@dataclass(frozen=True)
class _Layout:
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


def _put_pair(
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


#: largest condition estimate of the unit-column Gram matrix of the basis for which
#: the projection is taken from the Gram blocks (relative error ~ eps * this)
_MAX_GRAM_COND = 1e6
#: a squared norm ``||x||^2 - ||Q^T x||^2`` smaller than this fraction of the
#: subtracted term (relative error ~ eps / this) is formed from the explicit residual
_CANCEL_TOL = 1e-6
#: fit_added: an added column whose squared norm drops below this fraction when the
#: fixed basis is projected out is projected explicitly
_PROJ_TOL = 1e-4


def _extra_ss(
    R: NDArray[np.float64], C: NDArray[np.float64], per: int, m: int
) -> NDArray[np.float64]:
    """Extra sum of squares of each mode: the rise of the (weighted) cost when
    the ``per`` columns of mode ``n`` are removed and the other linear
    coefficients refitted at the same poles, summed over the outputs.

    With ``Phi = Q R`` and ``F = (Phi^T Phi)^-1 = R^-1 R^-T``, the rise for
    output ``j`` is ``c_nj^T (F_nn)^-1 c_nj`` (``c_nj`` the coefficients of
    mode ``n``, ``F_nn`` their block; the partial F-test numerator, e.g.
    Seber & Lee, *Linear Regression Analysis*, 2003, sec. 4.3). Returns shape (m,).
    """
    out = np.zeros(m)
    if m == 0:
        return out
    rinv = lapack.dtrtri(R)[0]
    for n in range(m):
        a = slice(per * n, per * n + per)
        rb = rinv[a]  # rows of R^-1 for the mode's columns: F_nn = rb rb^T
        fnn = rb @ rb.T
        cn = C[a]  # (per, n_out)
        try:
            out[n] = float(np.sum(cn * np.linalg.solve(fnn, cn)))
        except np.linalg.LinAlgError:
            out[n] = 0.0
    return out


def _gram_chol(
    g: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Cholesky factor of a Gram matrix with unit diagonal scaling, or None.

    ``g = Phi^T Phi``: returns ``rs`` (upper) and ``d`` with ``g = diag(d) rs^T rs
    diag(d)`` (so ``Phi = Q R`` with ``R = rs diag(d)``), or None when a column
    vanishes, the factorisation fails or the condition estimate of ``rs^T rs``
    exceeds ``_MAX_GRAM_COND``.
    """
    dg = g.diagonal()
    if g.shape[0] == 0 or not (dg.min() > 0.0 and dg.max() < np.inf):  # NaN: False
        return None
    d = np.sqrt(dg)
    gs = g / np.multiply.outer(d, d)
    rs, info = lapack.dpotrf(gs, lower=0, clean=1)
    if info != 0:
        return None
    rcond, info = lapack.dpocon(rs, float(abs(gs).sum(axis=0).max()))
    if info != 0 or not rcond * _MAX_GRAM_COND >= 1.0:
        return None
    return rs, d


def _vp_solve(
    G: NDArray[np.float64],
    P: NDArray[np.float64],
    q: int,
    yy: NDArray[np.float64],
    explicit: Any,
    *,
    residual: bool,
    gradient: bool,
    cancel: NDArray[np.float64] | None = None,
) -> dict[str, Any]:
    """Variable projection from the Gram blocks of ``B = [Phi | E]``.

    Parameters
    ----------
    G : ndarray, shape (q + n_e, q + n_e)
        ``B^T B``.
    P : ndarray, shape (q + n_e, n_out)
        ``B^T Y``.
    q : int
        Number of basis columns (the first ``q`` of ``B``).
    yy : ndarray, shape (n_out,)
        ``||Y_j||^2`` per column.
    explicit : callable
        Returns ``(B, Y)`` (n_rows rows), called only to orthogonalise an
        ill-conditioned basis or to form the residual.
    residual : bool
        Form the residual ``r = Y - Phi C`` (else only when ``cost`` loses
        accuracy by cancellation: ``cost_j < _CANCEL_TOL cancel_j``).
    gradient : bool
        Return ``E^T r``.
    cancel : ndarray, shape (n_out,), optional
        Reference of the cancellation test (default ``||Q^T Y_j||^2``).

    Returns
    -------
    dict
        ``R`` (``Phi = Q R``), ``C`` (q, n_out) coefficients, ``Ct = Q^T Y``,
        ``QtE = Q^T E``, ``GE = E^T P E`` (``P`` the projector on the complement
        of ``Phi``), ``Etr = E^T r`` (or None), ``cost``, ``cost_out``, ``resid``
        (or None) and ``Q`` (None unless the basis was orthogonalised).

    Notes
    -----
    With ``R`` from the Cholesky factor of ``Phi^T Phi`` (:func:`_gram_chol`):
    ``Q^T X = R^-T Phi^T X`` for ``X = E, Y``, ``C = R^-1 Q^T Y``, ``cost_j =
    ||Y_j||^2 - ||Q^T Y_j||^2``, ``E^T P E = E^T E - (Q^T E)^T Q^T E`` and ``E^T r =
    E^T Y - (Q^T E)^T Q^T Y``. When the Gram matrix is too ill-conditioned
    ``Q`` comes from :func:`_orth` of the explicit basis.
    """
    ne = G.shape[0] - q
    fac = _gram_chol(G[:q, :q])
    Q = None
    Bx = Yx = None
    if fac is not None:
        rs, d = fac
        rhs = np.concatenate([G[:q, q:], P[:q]], axis=1) / d[:, None]
        x = lapack.dtrtrs(rs, rhs, trans=1)[0]
        QtE, Ct = x[:, :ne], x[:, ne:]
        R = rs * d[None, :]
        C = lapack.dtrtrs(rs, Ct)[0] / d[:, None]
    else:
        Bx, Yx = explicit()
        phi = Bx[:, :q]
        Q, R = _orth(phi)
        QtE = Q.T @ Bx[:, q:]
        Ct = Q.T @ Yx
        diag = np.abs(np.diag(R))
        if diag.min() <= 1e-13 * diag.max():
            C = np.linalg.lstsq(phi, Yx, rcond=None)[0]
        else:
            C = sla.solve_triangular(R, Ct)
    ct2 = (Ct * Ct).sum(axis=0)
    cost_out = yy - ct2
    GE = G[q:, q:] - QtE.T @ QtE
    resid = Etr = None
    if residual or (cost_out < _CANCEL_TOL * (ct2 if cancel is None else cancel)).any():
        if Bx is None:
            Bx, Yx = explicit()
        resid = Yx - (Bx[:, :q] @ C if Q is None else Q @ Ct)
        cost_out = np.einsum("ij,ij->j", resid, resid)
        if gradient:
            Etr = Bx[:, q:].T @ resid
    elif gradient:
        Etr = P[q:] - QtE.T @ Ct
    return {
        "R": R,
        "C": C,
        "Ct": Ct,
        "Q": Q,
        "QtE": QtE,
        "GE": GE,
        "Etr": Etr,
        "resid": resid,
        "cost": float(cost_out.sum()),
        "cost_out": cost_out,
    }


def _orth(phi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Thin QR ``phi = Q R`` by CholeskyQR2 (Yamamoto et al. 2015), Householder fallback.

    Two Cholesky passes on the Gram matrix of the column-scaled basis give
    ``Q`` orthonormal to round-off whenever ``cond(phi) < ~1e7`` and cost two
    ``n x q`` Gram products and triangular solves -- several times faster than
    LAPACK's Householder QR with an explicit ``Q`` for the tall bases here.
    Householder QR for small bases and when a Cholesky factor is singular or
    too ill-conditioned.
    """
    n, q = phi.shape
    if n * q * q < 4e6:  # small: LAPACK's call overhead is lower than two Cholesky passes
        return _householder(phi)
    nrm = np.sqrt(np.einsum("ij,ij->j", phi, phi))
    if np.all(nrm > 0) and np.all(np.isfinite(nrm)):
        g1 = (phi.T @ phi) / np.outer(nrm, nrm)
        try:
            r1 = np.linalg.cholesky(g1).T
            d1 = np.abs(np.diag(r1))
            if d1.min() > 1e-7 * d1.max():
                eye = np.eye(r1.shape[0])
                q1 = phi @ (sla.solve_triangular(r1, eye) / nrm[:, None])
                r2 = np.linalg.cholesky(q1.T @ q1).T
                q = q1 @ sla.solve_triangular(r2, eye)
                return q, (r2 @ r1) * nrm[None, :]
        except np.linalg.LinAlgError:
            pass
    return _householder(phi)


def _householder(phi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Thin Householder QR by LAPACK ``dgeqrf`` + ``dorgqr`` (less call overhead
    than :func:`numpy.linalg.qr` for the small bases); NumPy's on failure."""
    n, q = phi.shape
    if n >= q > 0:
        qr, tau, _, info = lapack.dgeqrf(phi)
        if info == 0:
            r = np.triu(qr[:q])
            qm, _, info = lapack.dorgqr(qr, tau, overwrite_a=1)
            if info == 0:
                return qm, r
    qn, rn = np.linalg.qr(phi)
    return qn, rn


def _lu_solve(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
    """``a x = b`` by LAPACK ``dgesv`` (LU, partial pivoting) and its ``info`` (> 0: singular)."""
    x, info = lapack.dgesv(a, b)[2:]
    return x, int(info)


def _levenberg_marquardt(
    evaluate: Any,
    x0: NDArray[np.float64],
    lb: NDArray[np.float64],
    ub: NDArray[np.float64],
    max_nfev: int,
    dof: int,
    tol: float = 1e-6,
) -> tuple[NDArray[np.float64], int, bool, Any]:
    """Bounded Levenberg-Marquardt on the normal equations of a least-squares cost.

    ``evaluate(x)`` returns the cost ``||r||^2``, ``J^T J``, ``J^T r`` (the
    variable-projection quantities of :meth:`ModalFitter._normal`; the
    residual itself is never formed) and any by-product, returned for the
    final point. Steps solve ``(J^T J + lam diag(J^T J))
    d = -J^T r`` over the free parameters; a parameter at a bound whose
    gradient points outwards is held there (projected step). The damping
    ``lam`` follows Nielsen's rule (gain ratio ``rho``: ``lam *= max(1/3,
    1 - (2 rho - 1)^3)`` on success, doubled growth on failure).

    Convergence is statistical: the iteration stops when the Gauss-Newton
    decrement ``(J^T r)^T (J^T J)^-1 J^T r`` (the predicted cost reduction of
    a full Gauss-Newton step) is below ``tol s^2`` with ``s^2 = cost / dof`` the residual
    variance -- with the default ``tol = 1e-6`` the remaining step is about
    1e-3 standard deviations of the parameters, far below their uncertainty --
    or below ``1e-24`` times the starting cost (noise-free data), or when no
    step reduces the cost any more (round-off).

    Returns the parameters, the number of evaluations, whether it converged
    and the by-product of ``evaluate`` at the returned parameters.
    """
    x = np.clip(np.asarray(x0, float), lb, ub)
    cost, A, g, aux = evaluate(x)
    cost0 = max(cost, 1e-300)
    nfev = 1
    lam = 1e-3
    nu = 2.0
    n = x.size
    new_point = True  # the quantities of the current point are computed once
    while nfev < max_nfev:
        if new_point:
            if not math.isfinite(cost):
                return x, nfev, False, aux
            diag = A.diagonal()
            d_a = np.sqrt(np.maximum(diag, 1e-300))
            # held: at a bound with the descent direction -g pointing outwards, or
            # without information (e.g. the damping of a residual mode far outside
            # the band: its column of J vanishes)
            held = ((x <= lb) & (g > 0)) | ((x >= ub) & (g < 0))
            held |= diag <= 1e-13 * max(float(diag.max()), 1e-300)
            free: NDArray[np.intp] | None = None
            d_f = d_a
            if held.any():
                idx = np.flatnonzero(~held)
                if idx.size == 0:
                    return x, nfev, True, aux
                free, d_f = idx, d_a[idx]
                An = A[np.ix_(idx, idx)] / np.outer(d_f, d_f)
                gn = g[idx] / d_f
            else:
                An = A / np.outer(d_a, d_a)
                gn = g / d_a
            eye = np.eye(gn.size)
            # Gauss-Newton decrement at this point (convergence test)
            gn_step, info = _lu_solve(An + 1e-12 * eye, -gn)
            if info != 0:
                gn_step = -gn
            decrement = float(-gn @ gn_step)
            if decrement <= max(tol * cost / dof, 1e-24 * cost0):
                return x, nfev, True, aux
            new_point = False
        step_n, info = _lu_solve(An + lam * eye, -gn)
        if info != 0:  # singular
            lam *= nu
            nu *= 2
            continue
        if free is None:
            d = step_n / d_f
        else:
            d = np.zeros(n)
            d[free] = step_n / d_f
        x_new = np.minimum(np.maximum(x + d, lb), ub)
        d = x_new - x
        if np.all(np.abs(d) <= 1e-15 * (1.0 + np.abs(x))):
            return x, nfev, True, aux
        pred = -(2.0 * float(g @ d) + float(d @ A @ d))  # predicted cost reduction
        c_new, A_new, g_new, aux_new = evaluate(x_new)
        nfev += 1
        rho = (cost - c_new) / pred if pred > 0 else -1.0
        if math.isfinite(c_new) and c_new < cost and rho > 1e-4:
            x, cost, A, g, aux = x_new, c_new, A_new, g_new, aux_new
            lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            nu = 2.0
            new_point = True
        else:
            lam *= nu
            nu *= 2.0
            if lam > 1e12:  # no descent left at round-off level
                return x, nfev, True, aux
    return x, nfev, False, aux


def compress_outputs(
    H: NDArray[np.complex128],
    rank: int,
    seed: int = 0,
    weights: NDArray[np.float64] | None = None,
) -> NDArray[np.complex128]:
    """Principal output combinations of weighted FRFs (for fast pole searches).

    See :func:`_compress` (same arguments) for the method; returns the
    combinations, complex, shape (rank, n_in, n_freq).
    """
    return _compress(H, rank, seed, weights)[0]


def combine_outputs(
    H: NDArray[np.complex128], patterns: NDArray[np.float64], weights: NDArray[np.float64]
) -> NDArray[np.complex128]:
    """Orthonormal combinations of the weighted outputs spanning ``weights * patterns``.

    With the patterns of :func:`_compress` (found with other weights) this
    re-weights a compression without a new range search: the rows
    ``diag(weights) H`` are combined by ``Q``, the orthonormal basis of
    ``diag(weights) patterns`` (one product with the data).

    Parameters
    ----------
    H : ndarray, complex, shape (n_out, n_in, n_freq)
    patterns : ndarray, shape (n_out, rank)
    weights : ndarray, shape (n_out,)

    Returns
    -------
    ndarray, complex, shape (rank, n_in, n_freq)
    """
    n_out, n_in, n_f = H.shape
    q, _ = np.linalg.qr(weights[:, None] * patterns)
    x = H.reshape(n_out, -1)
    c = (q * weights[:, None]).T
    return np.asarray(((c @ x.real) + 1j * (c @ x.imag)).reshape(q.shape[1], n_in, n_f))


def _compress(
    H: NDArray[np.complex128],
    rank: int,
    seed: int = 0,
    weights: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """Principal output combinations of normalised FRFs (for fast pole searches).

    Each output row is multiplied by its weight (default ``1 / RMS`` of the
    row), then the rows are combined by the ``rank`` leading left singular
    vectors of the real matrix ``[Re H, Im H]`` (``n_out x 2 n_in n_freq``),
    found by a randomised range finder with one power iteration (Halko et al.
    2011). A real orthogonal combination of outputs keeps the modal model
    (eq. [10]: the combined rows have combined coefficients), and the leading
    components hold the modes while the dropped ones hold mostly noise, so
    poles fitted to the combinations are close to those fitted to all
    outputs at a fraction of the cost.

    Parameters
    ----------
    H : ndarray, complex, shape (n_out, n_in, n_freq)
    rank : int
        Number of combinations kept (``< n_out``).
    seed : int
        Seed of the random test matrix.
    weights : ndarray, shape (n_out,), optional
        Row weights (e.g. ``1 / sigma`` of a noise estimate); default
        ``1 / RMS``.

    Returns
    -------
    combinations : ndarray, complex, shape (rank, n_in, n_freq)
    patterns : ndarray, shape (n_out, rank)
        The combinations in unweighted outputs (``weights^-1 v``): they span the
        same signal subspace for any other row weighting
        (:func:`combine_outputs`).
    """
    n_out, n_in, n_f = H.shape
    if weights is None:
        rms = np.sqrt(np.mean(np.abs(H) ** 2, axis=(1, 2)))
        wt = 1.0 / np.where(rms > 0, rms, 1.0)
    else:
        wt = np.asarray(weights, float)
    x = H.reshape(n_out, -1)
    xr = np.empty((n_out, 2 * x.shape[1]))
    xr[:, : x.shape[1]] = x.real
    xr[:, x.shape[1] :] = x.imag
    xr *= wt[:, None]
    rng = np.random.default_rng(seed)
    k = min(n_out, rank + 10)
    q0, _ = np.linalg.qr(xr @ rng.normal(size=(xr.shape[1], k)))
    q1, _ = np.linalg.qr(xr @ (xr.T @ q0))
    b = q1.T @ xr  # (k, 2 n_in n_freq): the rows in the found basis
    # left singular vectors of b from its (k x k) Gram matrix, largest first
    _, u = np.linalg.eigh(b @ b.T)
    u = u[:, ::-1][:, :rank]
    c = u.T @ b  # = v^T xr with v = q1 u
    half = x.shape[1]
    comb = np.asarray((c[:, :half] + 1j * c[:, half:]).reshape(rank, n_in, n_f))
    return comb, (q1 @ u) / wt[:, None]
