"""The fit problem of an identification, built once from the band-limited FRF.

:func:`build_problem` checks the FRF and the band, cuts the lines to the band
*before* anything else touches the data (the per-line cost of an
identification is then that of the band, not of the file), normalises the
data to unit RMS (so that the result does not depend on the unit or the
magnitude of the data: ``H x 1e-300`` and ``H x 1e300`` give the same modes),
and states the noise model of the fit:

* ``"variance"``: the variance of each line, given (``variance=``) or carried
  by the FRF (``FRF.variance``);
* ``"coherence"``: derived from the coherence ``gamma^2`` and the number of
  averages ``n_d`` (``meta["n_averages"]``) with the H1 estimator's random
  error ``Var H = |H|^2 (1 - gamma^2) / (gamma^2 (n_d - 1))``: the noise
  spectrum ``(1 - gamma^2) G_yy`` over ``sum |X|^2``, whose expectation for
  random inputs holds ``n_d - 1`` (Bendat & Piersol, *Random Data*, 4th ed.
  2010, sec. 9.2.3, the magnitude and phase errors of eq. 9.73 summed; the
  estimated coherence of ``n_d`` averages is biased towards 1 by about ``(1 -
  gamma^2) / n_d``, which ``n_d - 1`` offsets to first order);
* ``"residual"``: none is known, the noise level per output is estimated
  from the residual of a generous model during the fit.

Degrees of freedom of the variance (``FitProblem.noise_dof``). A variance
passed as ``variance=`` is taken as known (the goodness of fit is then
chi-square). One carried by the FRF or derived from its coherence is an
estimate: its real degrees of freedom ``nu`` are ``meta["variance_dof"]`` when
the estimator states them (:func:`~tyredamp.signal.estimators.estimate_frf`:
``2 (n_eff - n_in)`` with ``n_eff`` the averages reduced for overlapping
windows; for cyclic one-force FRFs, whose variance comes from the
period-to-period noise averaged over ``L`` neighbouring lines, ``2 (n - 1) L``:
:mod:`tyredamp.signal.cyclic_variance`), else ``2 (n_averages - n_in)`` from
``meta["n_averages"]`` (the residual of the least-squares H1 over the averages,
no overlap correction), else unknown: taken as known. The local methods
(LRM/LPM, ``n_averages = 1``) state the local fit's ``2 (2 n + 1 - n_par)``
(:func:`~tyredamp.signal.lrm.local_variance_dof`). The goodness of fit corrects
for them (:mod:`tyredamp.modal.statistics.stats`).

A known variance ``V_jkf`` enters the fit as a separable model ``sigma_j^2
g_f`` (``sigma_j^2`` the mean variance of output ``j``, ``g_f`` the mean of
``V_jkf / sigma_j^2`` over outputs and inputs at line ``f``): the fitter
shares one basis over the outputs, so the line factor weights the basis rows
and the output factor the data columns (:class:`~tyredamp.modal.fit.fit.ModalFitter`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..._validate import as_band
from ...exceptions import InputError, ShapeError
from ...frf import FRF, KIND_POWER

__all__ = ["FitProblem", "NoiseSource", "build_problem", "line_factor_dof", "max_modes"]

NoiseSource = Literal["variance", "coherence", "residual"]
#: relative spread of the line spacing accepted as uniform (float32 axes of
#: acquisition files carry about 1e-7; a resampled or merged axis much more)
_UNIFORM_TOL = 1e-4


@dataclass(frozen=True)
class FitProblem:
    """Band-limited, normalised data of one identification (read-only arrays).

    Attributes
    ----------
    frequency : ndarray, shape (n_freq,)
        Lines in the band (Hz, > 0, uniformly spaced).
    H : ndarray, complex, shape (n_out, n_in, n_freq)
        FRFs of the band divided by ``scale``.
    scale : float
        Factor of the data: ``FRF.H = scale * H`` (the RMS of the band's data).
    kind : str
        FRF kind; ``power`` the power of ``i w`` that turns receptance into it.
    power : int
    band : (float, float)
        Analysis band (Hz) as asked.
    drive : list of (int, int)
        Drive points ``(output, input)``.
    frf : FRF
        The FRF the problem was built from (channels, kind).
    noise_source : {"variance", "coherence", "residual"}
        Where the noise model comes from (module docstring).
    sigma_out : ndarray, shape (n_out,) or None
        Noise RMS per output in the normalised units (known noise only).
    line_weights : ndarray, shape (n_freq,) or None
        ``1 / sqrt(g_f)`` of the separable per-line noise model (mean square 1).
    variance : ndarray, shape (n_out, n_in, n_freq) or None
        Per-line variance in the normalised units (known noise only).
    lines : slice
        The band's lines in ``frf.frequency``.
    noise_dof : float or None
        Real degrees of freedom of an estimated per-line variance (module
        docstring); None when the variance is known or there is none.
    n_averages : int or None
        Averages the variance was estimated from (``meta["n_averages"]``), for the verdict.
    noise_note : str
        What a given variance is, for people (e.g. a noise floor plus a model
        error, :mod:`tyredamp.modal.problem.model_error`); "" when nothing is to be said.
    variance_set_aside : str
        Why the FRF's own per-line variance was not used ("" when it was, or there
        was none): one estimated with ``nu <= FEWEST_VARIANCE_DOF`` degrees of
        freedom (:func:`build_problem`).
    lines_left_out : str
        The lines at the band's ends at which every FRF is exactly zero, left out
        of the band ("" when none; :func:`build_problem`).
    """

    frequency: NDArray[np.float64]
    H: NDArray[np.complex128]
    scale: float
    kind: str
    power: int
    band: tuple[float, float]
    drive: list[tuple[int, int]]
    frf: FRF
    noise_source: NoiseSource
    sigma_out: NDArray[np.float64] | None
    line_weights: NDArray[np.float64] | None
    variance: NDArray[np.float64] | None
    lines: slice
    noise_dof: float | None = None
    n_averages: int | None = None
    noise_note: str = ""
    variance_set_aside: str = ""
    lines_left_out: str = ""

    @property
    def weight_dof(self) -> float | None:
        """Degrees of freedom of the estimated line weights.

        The separable line factor ``g_f`` averages the residual powers of the
        outputs: ``noise_dof n_out`` degrees of freedom when their noises are
        independent (those of the inputs of one output share it). Noise common
        to the outputs (an H1 estimate's input noise, errors-in-variables) makes
        them fewer; they are measured from the scatter of the factor between
        adjacent lines (:func:`line_factor_dof`) and the smaller count is
        taken. None when the weights are known or absent
        (:func:`~tyredamp.modal.statistics.stats.mode_threshold`).
        """
        if self.noise_dof is None or self.line_weights is None:
            return None
        nominal = float(self.noise_dof) * int(self.H.shape[0])
        return min(nominal, line_factor_dof(self.line_weights))

    @property
    def shape(self) -> tuple[int, int, int]:
        n_out, n_in, n_f = self.H.shape
        return int(n_out), int(n_in), int(n_f)


def line_factor_dof(line_weights: NDArray[np.float64]) -> float:
    """Degrees of freedom of an estimated line factor ``g^_f = 1 / w_f^2``, from its
    scatter between adjacent lines.

    For ``g^_f = g_f chi2_nu / nu`` with independent estimates and a smooth
    true factor ``g_f`` (the noise spectrum changes little from one line to
    the next), the relative difference ``d_f = (g^_(f+1) - g^_f) / mean`` has
    ``E d^2 = 2 (2 / nu)``, so ``nu = 4 / mean(d^2)``. A true factor that varies
    between adjacent lines only lowers the count (conservative). Infinite for
    fewer than three lines or a constant factor.
    """
    g = 1.0 / np.asarray(line_weights, float) ** 2
    if g.size < 3:
        return math.inf
    d = np.diff(g) / (0.5 * (g[1:] + g[:-1]))
    m2 = float(np.mean(d * d))
    return math.inf if not m2 > 0 else 4.0 / m2


def max_modes(n_out: int, n_in: int, n_f: int) -> int:
    """Most modes the data of a band can support.

    Two bounds, the smaller counts: the pLSCF diagram of the highest order the
    lines allow (``2 n_f / (n_in + 1) - 2``, :func:`identify_modes`) has
    ``order n_in / 2`` root pairs; and the fit needs more real data
    (``2 n_out n_in n_f``) than parameters (per complex mode ``2 n_out``
    residue and ``2 n_in`` pole and participation parameters, plus the
    ``2 n_out n_in`` residual terms), with at least as many left for the noise.
    """
    order = (2 * n_f) // (n_in + 1) - 2
    by_order = max(order * n_in // 2, 0)
    per_mode = 2 * n_out + 2 * n_in
    by_data = (n_out * n_in * n_f - 2 * n_out * n_in) // per_mode
    return int(max(min(by_order, by_data), 0))


def check_uniform(f: NDArray[np.float64]) -> None:
    """Raise :class:`InputError` unless the lines ``f`` (Hz) are uniformly spaced."""
    if f.size < 3:
        return
    df = np.diff(f)
    mean = (f[-1] - f[0]) / (f.size - 1)
    dev = float(np.max(np.abs(df - mean)))
    if dev > _UNIFORM_TOL * mean:
        raise InputError(
            f"frequency: pLSCF needs uniformly spaced lines; the spacing of the band varies "
            f"from {df.min():.6g} to {df.max():.6g} Hz (resample the FRF onto a uniform axis)"
        )


def _line_variance(
    frf: FRF, lines: slice, H: NDArray[np.complex128], variance: ArrayLike | None
) -> tuple[NoiseSource, NDArray[np.float64] | None]:
    """Variance of each line of ``lines`` (data units ``H``) and where it comes from.

    ``variance`` (given) or ``frf.variance``: ``"variance"``; else from the
    coherence and ``meta["n_averages"]``: ``"coherence"``; else
    ``("residual", None)``."""
    full = frf.H.shape
    v_given = variance if variance is not None else frf.variance
    if v_given is not None:
        v = np.asarray(v_given, dtype=float)
        if v.shape != full:
            raise ShapeError(f"variance: expected shape {full} (that of H), got {v.shape}")
        v = v[:, :, lines]
        if not np.all(np.isfinite(v)) or np.any(v < 0):
            raise InputError("variance: expected finite values >= 0")
        return "variance", v
    coh = frf.coherence
    n_avg = frf.meta.get("n_averages") if isinstance(frf.meta, dict) else None
    if coh is not None and isinstance(n_avg, int | float) and n_avg >= 2:
        g2 = np.clip(np.asarray(coh)[:, lines], 1e-6, 1.0)
        v = np.abs(H) ** 2 * ((1.0 - g2) / (g2 * (float(n_avg) - 1.0)))[:, None, :]
        return "coherence", v
    return "residual", None


def _meta_number(frf: FRF, key: str) -> float | None:
    """A finite positive number of ``frf.meta`` (None when absent or not one)."""
    x = frf.meta.get(key) if isinstance(frf.meta, dict) else None
    if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x) or x <= 0:
        return None
    return float(x)


def variance_dof(frf: FRF, source: NoiseSource, given: bool) -> float | None:
    """Real degrees of freedom of an estimated per-line variance (module docstring)."""
    if given or source == "residual":
        return None
    stated = _meta_number(frf, "variance_dof")
    if stated is not None:
        return stated
    n_avg = _meta_number(frf, "n_averages")
    if n_avg is None or n_avg <= frf.n_in:
        return None
    return 2.0 * (n_avg - frf.n_in)


def _separable(
    v: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Output RMS and line weights of the separable model of ``v`` (module docstring)."""
    so2 = np.mean(v, axis=(1, 2))
    pos = so2 > 0
    if not np.any(pos):
        return None  # noise-free data: no noise model to use
    so2 = np.where(pos, so2, np.min(so2[pos]))
    g = np.mean(v / so2[:, None, None], axis=(0, 1))
    gpos = g > 0
    if not np.any(gpos):
        return None
    # lines without variance (exact data) get the weight of the least noisy line
    g = np.where(gpos, g, np.min(g[gpos]))
    g = g / np.mean(g)
    return np.sqrt(so2), 1.0 / np.sqrt(g)


def build_problem(
    frf: FRF,
    band: tuple[float, float] | None = None,
    *,
    variance: ArrayLike | None = None,
    noise_note: str = "",
    owned: bool = False,
) -> FitProblem:
    """Cut ``frf`` to the band, normalise it and state its noise model.

    Parameters
    ----------
    frf : FRF
        Measured FRFs, shape (n_out, n_in, n_freq).
    band : (float, float), optional
        Band in Hz; default the whole axis. Lines at 0 Hz are skipped.
    variance : array_like, shape (n_out, n_in, n_freq), optional
        Variance of each line of ``H`` (units of ``H`` squared); default
        ``FRF.variance`` when the FRF carries it, else from the coherence and
        ``meta["n_averages"]``, else none (estimated from the residual).
    noise_note : str
        What a given ``variance`` is (:attr:`FitProblem.noise_note`).
    owned : bool
        The given ``variance`` (a float64 array) was made for this call and may be
        normalised in place (the model error's passes; never a user's array).

    Returns
    -------
    FitProblem

    Raises
    ------
    InputError
        Not an FRF, a bad band, a band without lines, a non-uniform axis, an
        all-zero band, lines without data inside the band (every FRF exactly
        zero there; at the band's ends they are left out) or a bad variance.
    """
    if not isinstance(frf, FRF):
        raise InputError(f"frf: expected an FRF, got {type(frf).__name__}")
    fa = frf.frequency
    if band is None and np.count_nonzero(fa > 0) < 2:
        raise InputError(
            f"frequency: the FRF has {fa.size} line(s) ({', '.join(f'{x:g}' for x in fa[:3])} Hz); "
            "modes are identified from many lines of a uniform axis"
        )
    lo, hi = (float(fa[0]), float(fa[-1])) if band is None else as_band(band)
    # the band first: searchsorted on the sorted axis, no full-length mask
    i0 = int(np.searchsorted(fa, max(lo, 0.0), side="left"))
    i1 = int(np.searchsorted(fa, hi, side="right"))
    if i0 < i1 and fa[i0] <= 0:
        i0 += 1  # 0 Hz lines are skipped
    if i1 <= i0:
        raise InputError(
            f"band (--band): no line above 0 Hz in [{lo:g}, {hi:g}] Hz; the data cover "
            f"[{fa[0]:g}, {fa[-1]:g}] Hz"
        )
    i0, i1, empty = _without_empty_lines(frf.H, fa, i0, i1)
    if empty:
        lo, hi = max(lo, float(fa[i0])), min(hi, float(fa[i1 - 1]))
    lines = slice(i0, i1)  # views of the band, not copies
    f = np.ascontiguousarray(fa[i0:i1])
    check_uniform(f)
    Hb = np.asarray(frf.H[:, :, i0:i1])
    # scale by the largest magnitude first (no overflow of the squares), then the RMS
    peak = float(np.max(np.abs(Hb)))
    if not peak > 0:
        raise InputError(f"H: every FRF is zero in [{lo:g}, {hi:g}] Hz; nothing to identify")
    _refuse_dead_channels(frf, Hb, lo, hi)
    Hn = Hb / peak
    rms = float(np.sqrt(np.vdot(Hn, Hn).real / Hn.size))
    Hn /= rms  # in place: one copy of the band's data
    scale = peak * rms
    source, v = _line_variance(frf, lines, Hb, variance)
    nu = variance_dof(frf, source, variance is not None)
    n_avg = _meta_number(frf, "n_averages")
    aside = ""
    if v is not None and nu is not None and nu <= FEWEST_VARIANCE_DOF:
        aside = _set_aside_text(nu, n_avg)
        source, v, nu = "residual", None, None
    sig = lw = vn = None
    if v is not None:
        # a variance made for this call (``owned``) is normalised in place: no copy
        vn = v if owned and v.dtype == np.float64 and v.flags.writeable else v / peak**2
        if vn is v:
            vn /= peak**2
        vn /= rms**2  # in place: one copy of the band's variance
        sep = _separable(vn)
        if sep is None:
            source, vn = "residual", None
        else:
            sig, lw = sep
    for a in (f, Hn, *(x for x in (sig, lw, vn) if x is not None)):
        a.setflags(write=False)
    return FitProblem(
        frequency=f,
        H=Hn,
        scale=scale,
        kind=frf.kind,
        power=KIND_POWER[frf.kind],
        band=(lo, hi),
        drive=frf.drive_points(),
        frf=frf,
        noise_source=source,
        sigma_out=sig,
        line_weights=lw,
        variance=vn,
        lines=lines,
        noise_dof=nu if source != "residual" else None,
        n_averages=None if n_avg is None else int(n_avg),
        noise_note=noise_note if source == "variance" else "",
        variance_set_aside=aside,
        lines_left_out=empty,
    )


def _refuse_dead_channels(frf: FRF, Hb: NDArray[np.complex128], lo: float, hi: float) -> None:
    """Refuse an output or input whose FRFs are exactly zero at every line of the
    band (a dead or unplugged channel): its noise would be zero and every test of
    the fit undefined."""
    for axis, label, chans in ((0, "output", frf.outputs), (1, "input", frf.inputs)):
        other = (1, 2) if axis == 0 else (0, 2)
        dead = np.flatnonzero(~np.any(Hb != 0, axis=other))
        if dead.size:
            names = ", ".join(
                chans[k].label if k < len(chans) else f"#{k + 1}" for k in dead.tolist()
            )
            raise InputError(
                f"H: the FRFs of {label} {names} are exactly zero at every line in "
                f"[{lo:g}, {hi:g}] Hz (a dead or unplugged channel); leave it out of the "
                "file (or of the channel map) and identify the others"
            )


def _without_empty_lines(
    H: NDArray[np.complex128], fa: NDArray[np.float64], i0: int, i1: int
) -> tuple[int, int, str]:
    """The band's lines ``i0:i1`` without the leading and trailing lines at which
    every FRF is exactly zero, and what was left out ("" when nothing).

    A measured FRF is never exactly zero at a line with data: such lines are
    lines without data (an analyser's export beyond its anti-alias cut-off, a
    masked band). At the band's ends they are left out (a modal sum fitted to
    them would be asked to vanish there); inside the band they cannot be (the
    pole estimators need uniform lines), and the band is refused.
    """
    empty = ~np.any(H[:, :, i0:i1] != 0, axis=(0, 1))
    if not np.any(empty):
        return i0, i1, ""
    full = np.flatnonzero(~empty)
    if full.size == 0:
        return i0, i1, ""  # an all-zero band: refused by the caller
    a, b = i0 + int(full[0]), i0 + int(full[-1]) + 1
    inner = np.flatnonzero(empty[a - i0 : b - i0])
    if inner.size:
        k = a + inner
        raise InputError(
            f"H: every FRF is exactly zero at {k.size} line(s) inside the band "
            f"({fa[k[0]]:g}-{fa[k[-1]]:g} Hz): lines without data (a dropout or a masked "
            "band); choose a band without them (--band)"
        )
    parts = []
    if a > i0:
        parts.append(f"{fa[i0]:g}-{fa[a - 1]:g} Hz ({a - i0} lines)")
    if b < i1:
        parts.append(f"{fa[b]:g}-{fa[i1 - 1]:g} Hz ({i1 - b} lines)")
    note = (
        "the lines at which every FRF is exactly zero were left out of the band: "
        + " and ".join(parts)
        + " (lines without data, e.g. beyond an analyser's anti-alias cut-off)"
    )
    return a, b, note


#: most degrees of freedom of an estimated per-line variance that is set aside: the
#: inverse of ``chi2_nu / nu`` has an infinite mean for ``nu <= 2`` and an infinite
#: variance for ``nu <= 4`` (its moments ``nu / (nu - 2)`` and ``nu^2 / ((nu - 2)^2
#: (nu - 4))``), so line weights from such a variance are dominated by the few lines
#: whose variance came out small by chance, and no test of the fit against it has a
#: finite variance either
FEWEST_VARIANCE_DOF = 4.0


#: how the statement of a variance set aside begins (:attr:`FitProblem.variance_set_aside`)
SET_ASIDE = "the FRF's per-line variance, estimated from"


def _set_aside_text(nu: float, n_avg: float | None) -> str:
    """The statement of a per-line variance too uncertain to use (for people)."""
    src = f"{n_avg:g} averages" if n_avg is not None else "the estimator"
    return (
        f"{SET_ASIDE} {src} with {nu:.3g} degrees of "
        f"freedom (at most {FEWEST_VARIANCE_DOF:g}), is too uncertain to weight the lines "
        "by (the inverse of such an estimate has no finite variance): the noise was "
        "estimated from the fit's residual instead; more averages give a usable variance"
    )
