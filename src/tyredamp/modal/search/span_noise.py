"""Noise along the response: how much of the residual lies in the span of ``H(f)``.

The mode test (:mod:`tyredamp.modal.statistics.stats`) counts each of a mode's ``k``
parameters as taking one noise unit out of the cost, as it does when the
noise of the outputs is independent with the variance the fit assumes. An H1
estimate from signals with input (force) noise breaks that. With ``Y = H X +
E_y`` measured and the input measured as ``X + N``, the least-squares ``H1 =
Y X^+`` over the averages has the error ``(E_y - H N) X^+`` (Bendat & Piersol,
*Random Data*, 4th ed. 2010, sec. 9.2: the bias and random error of H1 with
input noise; Pintelon & Schoukens, *System Identification*, 2nd ed. 2012,
sec. 2.5, errors-in-variables): its part ``-H N X^+`` is common to all outputs
and lies, at each line, in the span of the ``n_in`` columns of ``H(f)``. Near a
resonance that span is the mode's shape, the direction a residue takes: a
mode that is not there finds there a noise many times the unit and passes a
threshold made for independent outputs (a narrow "mode" at 130.4 Hz between
two modes of the virtual tyre with force noise, T = 170 > 114, while modes of
pure output noise reach about 80).

Measured, not assumed. At each line the weighted residual ``e`` (n_out x
n_in, each output divided by its noise RMS, the line weight applied, as the
fit weights it) is split by an orthonormal basis ``Q_f`` of the columns of the
equally weighted model ``H^(f)`` into its part in the span, ``a_f = ||Q^H e||^2
/ (2 n_in^2)`` per complex dimension, and the rest, ``b_f = (||e||^2 - ||Q^H
e||^2) / (2 (n_out - n_in) n_in)`` (a complex entry holds two real units of
the noise variance ``s^2``); for independent noise of the assumed
variance both are 1 in expectation. The span is the fitted model's, which
depends on the noise only through the few parameters of the fit, not the
noisy data's own columns: where the noise is as large as the response (a weak
mode at 20 dB, an antiresonance) those columns are mostly the noise itself,
and white noise projected on them looked concentrated along the response
(``a_f`` about 1.7 for noise 0.3 times the mean response), raising the
thresholds of weak true modes. The sums over
the lines near a candidate (its half-power band, at least ``WINDOW`` lines
either side) give ``lambda_in`` and ``lambda_out``, the noise variance per
direction in and off the span in units of the fit's noise
(:func:`~tyredamp.modal.statistics.stats.span_threshold` turns them into the mode's
threshold). With ``n_out <= n_in`` nothing is off the span, and both are 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..fit import _basis

if TYPE_CHECKING:
    from ..fit.fit import ModalFitter

__all__ = ["SpanNoise", "span_noise"]

#: lines either side of a candidate over which the noise in and off the span is
#: summed (at least; a wider half-power band takes its own): 17 lines of 2 x 2
#: complex directions give the in-span variance to about +-12 %, and the common
#: noise follows the response, which changes over a half-power band
WINDOW = 8


@dataclass(frozen=True)
class SpanNoise:
    """Cumulative sums over the lines of the residual power in and off the span.

    ``cin[i]``, ``cout[i]``: the sums of ``a_f`` and ``b_f`` (module docstring)
    over the first ``i`` lines; ``f`` the lines (Hz).
    """

    f: NDArray[np.float64]
    cin: NDArray[np.float64]
    cout: NDArray[np.float64]
    n_in: int
    n_out: int

    def at(self, pole: complex) -> tuple[float, float, int]:
        """``lambda_in``, ``lambda_out`` and the lines summed around a pole."""
        f = self.f
        if self.n_out <= self.n_in or f.size < 2:
            return 1.0, 1.0, 0
        df = (f[-1] - f[0]) / (f.size - 1)
        fc = abs(pole.imag) / (2 * np.pi)
        half = max(-pole.real / (2 * np.pi), WINDOW * df)
        i0 = int(np.searchsorted(f, fc - half - 0.5 * df))
        i1 = int(np.searchsorted(f, fc + half + 0.5 * df))
        i0, i1 = max(min(i0, f.size - 1), 0), min(max(i1, i0 + 1), f.size)
        n = i1 - i0
        return (
            float((self.cin[i1] - self.cin[i0]) / n),
            float((self.cout[i1] - self.cout[i0]) / n),
            n,
        )


def _split(
    u: NDArray[np.complex128], ew: NDArray[np.complex128]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``||Q_f^H e_f||^2`` and ``||e_f||^2`` per line of the weighted model ``u`` and
    residual ``ew`` (n_out, n_in, lines), ``Q_f`` an orthonormal basis of the columns
    of ``u_f``. One input: ``Q_f = u_f / ||u_f||``, so ``||Q^H e||^2 = |u^H e|^2 /
    ||u||^2`` (no QR); otherwise a QR of every line (a zero ``u_f`` too)."""
    e_all = np.einsum("jkf,jkf->f", ew.real, ew.real) + np.einsum("jkf,jkf->f", ew.imag, ew.imag)
    if u.shape[1] == 1:
        u1, e1 = u[:, 0, :], ew[:, 0, :]
        uu = np.einsum("jf,jf->f", u1.real, u1.real) + np.einsum("jf,jf->f", u1.imag, u1.imag)
        if uu.all():
            ue = np.einsum("jf,jf->f", np.conj(u1), e1)
            return (ue.real**2 + ue.imag**2) / uu, e_all
    q = np.linalg.qr(u.transpose(2, 0, 1))[0]  # (lines, n_out, n_in)
    p = np.conj(q).transpose(0, 2, 1) @ ew.transpose(2, 0, 1)
    return np.sum(p.real**2 + p.imag**2, axis=(1, 2)), e_all


def span_noise(
    fitter: ModalFitter,
    poles: NDArray[np.complex128],
    residues: NDArray[np.complex128],
    terms: tuple[NDArray[np.float64] | None, NDArray[np.float64] | None],
    s2: NDArray[np.float64],
) -> SpanNoise:
    """Residual power in and off the span of ``H(f)`` per line (module docstring).

    Arguments as :func:`~tyredamp.modal.fit._basis.residual_power` (``fitter`` a
    :class:`~tyredamp.modal.fit.fit.ModalFitter`, ``s2`` its noise variance per
    output).
    """
    n_out, n_in, n_f = fitter.H.shape
    # the per-line powers are written after a leading 0 and summed in place: their
    # cumulative sums, with no other array of the lines
    ca = np.ones(n_f + 1)
    cb = np.ones(n_f + 1)
    ca[0] = cb[0] = 0.0
    a, b = ca[1:], cb[1:]
    if n_out > n_in:
        isd = 1.0 / np.sqrt(s2)
        lw = fitter.line_weights
        for sl, e in _basis.residual_blocks(fitter, poles, residues, terms):
            h = fitter.H[:, :, sl]
            if lw is not None:
                h = h * lw[sl]
            # the span of the model's columns (h - e: the weighted model), not the data's
            e_in, e_all = _split((h - e) * isd[:, None, None], e * isd[:, None, None])
            # s2 is the variance of a real row: a complex entry holds 2 s2
            a[sl] = e_in / (2 * n_in**2)
            b[sl] = np.maximum(e_all - e_in, 0.0) / (2 * (n_out - n_in) * n_in)
    np.cumsum(a, out=a)
    np.cumsum(b, out=b)
    return SpanNoise(
        np.asarray(fitter.f, dtype=np.float64),
        ca,
        cb,
        int(n_in),
        int(n_out),
    )
