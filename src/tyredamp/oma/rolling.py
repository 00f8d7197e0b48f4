"""Rolling-tyre modes from output-only records: travelling waves in both frames.

A rolling tyre has no double modes: each wave number ``n >= 1`` gives a
*forward* wave (travelling with the rotation on the tyre) and a *backward*
wave, at different frequencies. Two kinds of sensor see them:

* **Fixed sensors** around the circumference (angles ``phi_j`` in space, the
  tyre turning towards ``+phi``): every mode identified from them is split
  into its two spatial waves (:func:`~tyredamp.oma.waves.wave_content`), which
  gives its wave number ``n`` and its direction of travel *in space*
  ``s = +1`` (towards ``+phi``) or ``-1``.
* **One sensor inside the tyre** (turning with the wheel at ``f_w``): it sees
  the same wave at the rotating-frame frequency.

The two frames are tied by the kinematics of a wave ``e^{i(omega t + k theta)}``
on the tyre seen at the fixed angle ``phi = theta + Omega t`` (the change of
frame of Huang & Soedel, J. Sound Vib. 115(2) (1987) 253-274; the relation is
derived here and in :mod:`tyredamp.virtual.rolling_truth`, whose exact ring
modes the tests check it against)::

    f_fixed = f_rot + s n f_w          (1)

with ``s = +1`` for a wave that a fixed observer sees travel with the
rotation. A negative ``f_fixed - s n f_w`` is the same wave with the sign of
time reversed: it travels the other way on the tyre (a backward wave carried
forward in space faster than it runs back). So a fixed-frame mode with ``n``
and ``s`` determines its rotating frequency and its direction on the tyre;
a peak of the in-tyre sensor alone does not: each ``(n, direction)`` gives
another ``f_fixed`` from (1), and only a fixed-frame mode with that ``n`` and
direction at that frequency resolves it. Without fixed sensors the candidates
are listed and the peak is reported unresolved. With fixed sensors equally
spaced around the circumference each wave number is identified apart (the
wave-number route, :mod:`.spatial_poles`), the default where the record is
long enough for its tests.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ..timedata import TimeData
from .frames import rotating_frequency, rotating_pole
from .identify import OMAResult, oma
from .nyquist import nyquist_candidates, resolve_nyquist
from .spatial import equally_spaced, nyquist_wave_number, peak_test_has_power, welch_dof
from .spatial_poles import (
    ALPHA,
    SEGMENT,
    SpatialPole,
    select_spatial_poles,
    spatial_poles,
    spatial_route,
)
from .waves import wave_content

__all__ = [
    "ALPHA",
    "RollingModes",
    "RollingWave",
    "SpatialPole",
    "compare_waves",
    "resolve_in_tyre",
    "rolling_modes",
    "rotating_frequency",
    "rotating_pole",
    "select_spatial_poles",
    "spatial_poles",
]


@dataclass(frozen=True)
class RollingWave:
    """One identified travelling wave of a rolling tyre.

    Attributes
    ----------
    source : str
        ``"fixed"`` (from the fixed sensors) or ``"rotating"`` (the in-tyre sensor).
    wave_number : int or None
        ``n``; ``None`` when the in-tyre peak is not resolved.
    direction : str or None
        On the tyre: ``"forward"`` (with the rotation), ``"backward"``, ``"standing"``;
        ``None`` when not resolved (an in-tyre peak, or a Nyquist wave).
    fixed_direction : str or None
        As a fixed observer sees it travel (``None`` when not resolved).
    fixed_hz, rotating_hz : float
        Natural frequency ``|lambda| / 2 pi`` at a fixed point and in the tyre
        (Hz; NaN where not known); a fixed-frame wave's in-tyre frequency is
        its pole moved by :func:`rotating_pole`.
    damping_ratio : float
        As fitted in the frame it was measured in.
    std_frequency_hz, std_damping_ratio : float
        Jackknife standard errors (NaN without them).
    explained : float
        Share of the fixed-frame shape the two waves of ``n`` explain (NaN for
        the in-tyre sensor).
    candidates : list of (int, str, float)
        For an unresolved in-tyre peak: every ``(n, direction on the tyre,
        f_fixed)`` it could be. For a fixed-frame wave of the Nyquist wave
        number whose direction is not resolved (:mod:`.nyquist`): both
        ``(n, direction on the tyre, f_rot)``.
    reason : str
    """

    source: str
    wave_number: int | None
    direction: str | None
    fixed_direction: str | None
    fixed_hz: float
    rotating_hz: float
    damping_ratio: float
    std_frequency_hz: float
    std_damping_ratio: float
    explained: float = float("nan")
    candidates: list[tuple[int, str, float]] = field(default_factory=list)
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-compatible dict (NaN as ``None``)."""

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        return {
            "source": self.source,
            "wave_number": self.wave_number,
            "direction": self.direction,
            "fixed_direction": self.fixed_direction,
            "fixed_hz": num(self.fixed_hz),
            "rotating_hz": num(self.rotating_hz),
            "damping_ratio": num(self.damping_ratio),
            "std_frequency_hz": num(self.std_frequency_hz),
            "std_damping_ratio": num(self.std_damping_ratio),
            "explained": num(self.explained),
            "candidates": [[n, d, f] for n, d, f in self.candidates],
            "reason": self.reason,
        }


@dataclass(frozen=True)
class RollingModes:
    """Travelling waves of a rolling tyre identified output-only.

    Attributes
    ----------
    wheel_speed_hz : float
        Wheel rotation frequency used (Hz).
    fixed : list of RollingWave
        From the fixed sensors, ascending in fixed-frame frequency.
    rotating : list of RollingWave
        From the in-tyre sensor, ascending in rotating-frame frequency.
    fixed_result, rotating_result : OMAResult or None
        The underlying identifications.
    notes : list of str
    angles_deg : tuple of float
        Angles of the fixed sensors (deg), in the order of the shapes.
    points : tuple of str
        Names of the fixed sensors.
    """

    wheel_speed_hz: float
    fixed: list[RollingWave]
    rotating: list[RollingWave]
    fixed_result: OMAResult | None
    rotating_result: OMAResult | None
    notes: list[str] = field(default_factory=list)
    angles_deg: tuple[float, ...] = ()
    points: tuple[str, ...] = ()

    def table(self) -> list[dict[str, Any]]:
        """Every wave as a dict (:meth:`RollingWave.to_dict`), fixed first."""
        return [w.to_dict() for w in self.fixed + self.rotating]

    def format(self) -> str:
        """The waves as text, one line each."""
        lines = [
            f"wheel speed {self.wheel_speed_hz:.4g} Hz",
            "source    n  on tyre    fixed Hz  in tyre Hz  zeta %  +- f Hz",
        ]
        for w in self.fixed + self.rotating:
            n = "?" if w.wave_number is None else str(w.wave_number)
            lines.append(
                f"{w.source:8s} {n:>2s}  {w.direction or 'unresolved':9s} {w.fixed_hz:9.3f}  "
                f"{w.rotating_hz:10.3f}  {100 * w.damping_ratio:6.2f}  {w.std_frequency_hz:7.3f}"
            )
        return "\n".join(lines)


def _fixed_waves(r: OMAResult, angles: list[float], fw: float) -> list[RollingWave]:
    """Wave number and direction of each fixed-frame mode; a standing ``n >= 1``
    shape stands for both waves at one fixed frequency (listed twice)."""
    out = []
    for j in range(r.n_modes):
        wc = wave_content(r.shapes[:, j], angles)
        f, z = float(r.frequency_hz[j]), float(r.damping_ratio[j])
        sf, sz = float(r.std_frequency_hz[j]), float(r.std_damping_ratio[j])
        dirs = (
            ["forward", "backward"]
            if wc.wave_number > 0 and wc.direction == "standing"
            else [wc.direction]
        )
        for d in dirs:
            fr, _, dt = rotating_pole(f, z, wc.wave_number, d, fw)
            why = f"fixed-frame shape: n = {wc.wave_number}, share forward {wc.forward_share:.2f}"
            out.append(RollingWave("fixed", wc.wave_number, dt, d, f, fr, z, sf, sz,
                                   wc.explained, [], why))  # fmt: skip
    return out


def _within_band(
    waves: list[RollingWave], band: tuple[float, float]
) -> tuple[list[RollingWave], list[str]]:
    """The waves whose flanks ``f -+ 2 zeta f`` lie inside ``band``, and a note for each
    mode left out.

    A pole whose resonance the band cuts off is not a mode the band determines:
    near the edge of the excitation or of the anti-alias filter the spectra fall
    off like the flank of a peak, and SSI fits poles there. The flanks of a
    mode, where its response has fallen to a fifth of the peak (the frequency
    response of one mode, Ewins, Modal Testing, 2nd ed. 2000, sec. 2.2; the
    same rule as test (iii) of :func:`select_spatial_poles`), must lie inside.
    """
    lo, hi = band
    keep: list[RollingWave] = []
    notes: list[str] = []
    for w in waves:
        off = 2 * abs(w.damping_ratio) * w.fixed_hz
        if w.fixed_hz + off > hi or (lo > 0 and w.fixed_hz - off < lo):
            note = (f"{w.fixed_hz:.4g} Hz left out: its resonance (+- {off:.2g} Hz) is cut off by "
                    f"the band edge ({lo:g}-{hi:g} Hz)")  # fmt: skip
            if note not in notes:
                notes.append(note)
            continue
        keep.append(w)
    return keep, notes


def _spatial_waves(
    poles: list[SpatialPole], K: int, fw: float, in_tyre: _InTyre | None = None, tol: float = 0.01
) -> list[RollingWave]:
    """The selected poles as waves, with their channel and power in the reason; the
    poles of the Nyquist channel (even ``K``) through :func:`_nyquist_waves`."""
    out: list[RollingWave] = []
    nyq = nyquist_wave_number(K)
    for p in poles:
        n, d = p.wave_number, p.direction
        if n == nyq and n > 0:
            continue
        alias = f" (aliases {K - n}, {K + n})" if n > 0 else ""
        why = (
            f"wave-number channel {'-' if d == 'forward' else '+'}{n}{alias}: power "
            f"{p.ratio:.3g} x the median channel, the opposite direction {p.other:.3g} x"
        )
        fr, _, dt = rotating_pole(p.frequency_hz, p.damping_ratio, n, d, fw)
        out.append(RollingWave("fixed", n, dt, d, p.frequency_hz, fr, p.damping_ratio,
                               p.std_frequency_hz, p.std_damping_ratio, float("nan"), [],
                               why))  # fmt: skip
    others = [w.rotating_hz for w in out]
    return out + _nyquist_waves([p for p in poles if p.wave_number == nyq and nyq],
                                K, fw, in_tyre, others, tol)  # fmt: skip


@dataclass
class _InTyre:
    """The in-tyre sensor's poles for :func:`resolve_nyquist`: those of the in-tyre
    identification, and, where a hypothesis lies above its band but below
    0.45 of the sampling rate, those of a second pLSCF up to there (computed once)."""

    record: Any
    sample_rate: float
    wheel_speed_hz: float
    result: OMAResult
    wide: OMAResult | None = None

    def poles(self, highest_hz: float) -> tuple[Any, Any, Any, tuple[float, float]]:
        """``(f, zeta, std_f, band)`` of the identification whose band holds ``highest_hz``."""
        r = self.result
        top = 0.45 * self.sample_rate
        if highest_hz > r.band_hz[1] and r.band_hz[1] < top:
            if self.wide is None:
                self.wide = oma(self.record, self.sample_rate, method="plscf",
                                band=(r.band_hz[0], top),
                                wheel_speed_hz=self.wheel_speed_hz or None)  # fmt: skip
            r = self.wide
        return r.frequency_hz, r.damping_ratio, r.std_frequency_hz, r.band_hz


def _nyquist_waves(
    poles: list[SpatialPole],
    K: int,
    fw: float,
    in_tyre: _InTyre | None,
    others: list[float],
    tol: float,
) -> list[RollingWave]:
    """The poles of the Nyquist channel as waves: at rest both waves (they share
    the frequency), rolling the direction :func:`resolve_nyquist` finds or none."""
    out: list[RollingWave] = []
    for p in poles:
        n, f, z = p.wave_number, p.frequency_hz, p.damping_ratio
        sf, sz = p.std_frequency_hz, p.std_damping_ratio
        head = (f"wave-number channel {n} (the Nyquist channel (-1)^k): power {p.ratio:.3g} x "
                "the median channel")  # fmt: skip
        if fw == 0:
            why = f"{head}; at rest both waves share its frequency"
            for d in ("forward", "backward"):
                out.append(RollingWave("fixed", n, d, d, f, f, z, sf, sz, float("nan"), [], why))
            continue
        hi = max(c.rotating_hz for c in nyquist_candidates(f, z, n, fw))
        res = resolve_nyquist(f, z, sf, n, K, fw, None if in_tyre is None else in_tyre.poles(hi),
                              [o for o in others if np.isfinite(o)], tol)  # fmt: skip
        c, why = res.candidate, f"{head}; {res.reason}"
        cands = [(n, x.direction, x.rotating_hz) for x in res.candidates]
        if c is None:
            out.append(RollingWave("fixed", n, None, None, f, float("nan"), z, sf, sz,
                                   float("nan"), cands, why))  # fmt: skip
        else:
            out.append(RollingWave("fixed", n, c.direction, c.fixed_direction, f, c.rotating_hz,
                                   z, sf, sz, float("nan"), [], why))  # fmt: skip
    return out


def _match_tol(w: RollingWave, f: float, tol: float) -> float:
    """Hz: ``tol f``, or three standard errors of ``w``'s frequency where wider."""
    sf = w.std_frequency_hz
    return max(tol * f, 3.0 * sf) if np.isfinite(sf) else tol * f


def resolve_in_tyre(
    frequency_rot_hz: ArrayLike,
    fixed: list[RollingWave],
    wheel_speed_hz: float,
    *,
    damping_ratio: ArrayLike | None = None,
    std_frequency_hz: ArrayLike | None = None,
    n_max: int = 8,
    tol: float = 0.01,
) -> list[RollingWave]:
    """Wave number and direction of in-tyre peaks through eq. (1) and the fixed-frame waves.

    A peak at ``f_rot`` could be the forward wave ``n`` (seen at ``f_rot + n f_w``
    from a fixed point) or the backward wave ``n`` (at ``|f_rot - n f_w|``), for
    every ``n``: eq. (1) of this module. It is resolved when a
    fixed-frame wave with that ``n`` and direction on the tyre lies within
    ``tol`` (relative) of that frequency, or within three of its standard errors
    where these are wider (the nearest in units of its tolerance wins); otherwise
    it is returned unresolved with its candidates.

    Parameters
    ----------
    frequency_rot_hz : array_like, shape (m,)
        Peaks of the in-tyre sensor, Hz.
    fixed : list of RollingWave
        Waves from the fixed sensors (may be empty).
    wheel_speed_hz : float
        ``f_w`` in Hz.
    damping_ratio, std_frequency_hz : array_like, shape (m,), optional
        Carried into the result (NaN when absent).
    n_max : int
        Largest wave number tried.
    tol : float
        Relative frequency tolerance of a match.

    Returns
    -------
    list of RollingWave
        One per peak, in the order given.
    """
    f_all = np.asarray(frequency_rot_hz, float).ravel()
    nan = np.full(f_all.size, np.nan)
    z_all = nan if damping_ratio is None else np.asarray(damping_ratio, float).ravel()
    s_all = nan if std_frequency_hz is None else np.asarray(std_frequency_hz, float).ravel()
    fw = float(wheel_speed_hz)
    out = []
    for f, z, sf in zip(f_all.tolist(), z_all.tolist(), s_all.tolist(), strict=True):
        cands = []
        for n in range(1, n_max + 1):
            cands.append((n, "forward", f + n * fw))  # forward on the tyre: seen higher
            cands.append((n, "backward", abs(f - n * fw)))
        hits = [
            (abs(w.fixed_hz - ff) / _match_tol(w, ff, tol), n, d, w)
            for n, d, ff in cands
            for w in fixed
            if w.wave_number == n
            and w.direction == d
            and abs(w.fixed_hz - ff) <= _match_tol(w, ff, tol)
        ]
        if hits:
            _, n, d, w = min(hits, key=lambda h: h[0])
            why = f"f_rot {'+' if d == 'forward' else '-'} n f_w matches the fixed-frame wave"
            out.append(RollingWave("rotating", n, d, w.fixed_direction, w.fixed_hz, f, z, sf,
                                   float("nan"), float("nan"), [], why))  # fmt: skip
            continue
        why = "one in-tyre peak: wave number and direction not resolved" + (
            " (no fixed-frame wave matches)" if fixed else " (no fixed sensors)"
        )
        out.append(RollingWave("rotating", None, None, None, float("nan"), f, z, sf,
                               float("nan"), float("nan"), cands, why))  # fmt: skip
    return out


def _split_channels(
    data: TimeData,
    fixed_channels: ArrayLike | None,
    rotating_channels: ArrayLike | None,
) -> tuple[list[int], list[int]]:
    resp = data.response_indices
    if rotating_channels is None:
        rot = [i for i in resp if (data.channels[i].name or "").upper().startswith("T")]
    else:
        rot = [int(i) for i in np.ravel(rotating_channels)]
    if fixed_channels is None:
        fix = [i for i in resp if i not in rot]
    else:
        fix = [int(i) for i in np.ravel(fixed_channels)]
    bad = [i + 1 for i in fix + rot if not 0 <= i < data.n_channels]
    if bad:
        raise InputError(f"channels: expected channel numbers 1..{data.n_channels}, got {bad}")
    return fix, rot


def _default_route(angles: list[float], n_samples: int) -> tuple[bool, str]:
    """The wave-number route when the sensors are equally spaced and the record
    long enough for its peak test (:func:`.spatial.peak_test_has_power`), and why."""
    if not equally_spaced(angles):
        return False, ("fixed sensors not equally spaced: all identified together, each mode "
                       "split into waves afterwards")  # fmt: skip
    dof = welch_dof(n_samples, SEGMENT)
    if not peak_test_has_power(dof, ALPHA):
        return False, (f"record too short for the wave-number route ({dof:.0f} degrees of "
                       "freedom in its channel spectra): all fixed sensors identified "
                       "together")  # fmt: skip
    return True, ""


def rolling_modes(
    data: TimeData,
    wheel_speed_hz: float | None = None,
    *,
    fixed_channels: ArrayLike | None = None,
    rotating_channels: ArrayLike | None = None,
    angles_deg: ArrayLike | None = None,
    band: tuple[float, float] | None = None,
    n_max: int = 8,
    tol: float = 0.01,
    n_groups: int = 16,
    uncertainty: bool = True,
    spatial: bool | None = None,
) -> RollingModes:
    """Travelling waves of a rolling tyre from fixed and in-tyre output-only records.

    Parameters
    ----------
    data : TimeData
        Output-only records (a force channel, if any, is ignored).
    wheel_speed_hz : float, optional
        Wheel rotation frequency in Hz; default ``data.meta["rotation_hz"]``.
    fixed_channels, rotating_channels : sequence of int, optional
        0-based channel indices of the sensors fixed in space (at least 3,
        around the circumference) and inside the tyre (the first one is used).
        Default: channels named ``T..`` are in the tyre, the other responses fixed.
    angles_deg : array_like, optional
        Angles in degrees of the fixed sensors (in the direction of rotation);
        default their ``angle_deg``.
    band : (float, float), optional
        Hz; default the acquisition band or 0 .. 0.45 of the sampling rate.
    n_max : int
        Largest wave number tried for an in-tyre peak.
    tol : float
        Relative frequency tolerance of an in-tyre-to-fixed match.
    n_groups : int
        Jackknife segments of the SSI (fixed sensors).
    uncertainty : bool
        Jackknife standard errors of the fixed-sensor modes (slower).
    spatial : bool, optional
        ``True``: identify each wave number and direction apart from the
        spatial DFT of the fixed sensors (:mod:`.spatial`; they must be
        equally spaced around the circumference), its poles kept by
        :func:`select_spatial_poles` (the wave-number route). ``False``: all
        fixed sensors together, each mode split into waves afterwards (any
        layout). Default: the wave-number route when the fixed sensors are
        equally spaced, the other otherwise (said in the notes). With an
        even number ``K`` of sensors the wave-number route also identifies
        the Nyquist channel ``n = K / 2`` and takes its waves' direction from
        the in-tyre sensor where that tells it (:mod:`.nyquist`).

    Returns
    -------
    RollingModes
    """
    fw = wheel_speed_hz if wheel_speed_hz is not None else data.meta.get("rotation_hz")
    if fw is None or not np.isfinite(float(fw)) or float(fw) < 0:
        raise InputError(
            f"wheel speed: expected the wheel rotation frequency in Hz (>= 0), got {fw!r}"
        )
    fw = float(fw)
    fix, rot = _split_channels(data, fixed_channels, rotating_channels)
    bnd = band if band is not None else data.acquisition.band_hz
    notes: list[str] = []
    fixed: list[RollingWave] = []
    r_fix = r_rot = None
    in_tyre = None
    if rot:
        r_rot = oma(data.data[rot[:1]], data.sample_rate, method="plscf", band=bnd,
                    wheel_speed_hz=fw if fw > 0 else None)  # fmt: skip
        in_tyre = _InTyre(data.data[rot[:1]], data.sample_rate, fw, r_rot)
    ang: list[float] = []
    if len(fix) >= 3:
        ang = (
            [float(data.channels[i].angle_deg or 0.0) for i in fix]
            if angles_deg is None
            else [float(a) for a in np.ravel(angles_deg)]
        )
        if angles_deg is None and any(data.channels[i].angle_deg is None for i in fix):
            raise InputError("angles: the fixed channels carry no angles; give angles_deg")
        kw: dict[str, Any] = {"band": bnd, "n_groups": n_groups, "uncertainty": uncertainty,
                              "wheel_speed_hz": fw if fw > 0 else None}  # fmt: skip
        if spatial is None:
            spatial, why = _default_route(ang, np.shape(data.data)[-1])
            notes.extend([why] if why else [])
        if spatial and not equally_spaced(ang):
            got = ", ".join(f"{a:g}" for a in ang)
            raise InputError(
                f"angles: the wave-number route needs the {len(ang)} fixed sensors "
                f"every {360 / len(ang):g} deg around the tyre, got {got} deg"
            )
        if spatial:
            edges = bnd if bnd is not None else (0.0, 0.45 * data.sample_rate)
            kept, dropped = spatial_route(data.data[fix], data.sample_rate, ang, kw, edges)
            notes.extend(dropped)
            fixed = _spatial_waves(kept, len(ang), fw, in_tyre, tol)
            notes.append(f"fixed sensors: each wave number 0..{len(fix) // 2} identified "
                         "apart (spatial DFT of equally spaced sensors)")  # fmt: skip
        else:
            r_fix = oma(data.data[fix], data.sample_rate, **kw)
            edges = r_fix.band_hz
            fixed, edge = _within_band(_fixed_waves(r_fix, ang, fw), edges)
            notes.extend(edge)
        fixed = sorted(fixed, key=lambda w: w.fixed_hz)
    else:
        notes.append(f"{len(fix)} fixed sensor(s): at least 3 are needed for wave numbers")
    rotating: list[RollingWave] = []
    if r_rot is not None:
        rotating = resolve_in_tyre(
            r_rot.frequency_hz, fixed, fw, damping_ratio=r_rot.damping_ratio,
            std_frequency_hz=r_rot.std_frequency_hz, n_max=n_max, tol=tol,
        )  # fmt: skip
        if len(rot) > 1:
            notes.append(f"in-tyre sensors: the first of {len(rot)} is used")
        if fw == 0:
            notes.append("wheel at rest: both frames coincide")
    names = tuple(data.channels[i].name or f"{i + 1}" for i in fix) if ang else ()
    return RollingModes(fw, fixed, rotating, r_fix, r_rot, notes, tuple(ang), names)


def compare_waves(
    identified: list[RollingWave], truth: list[dict[str, Any]], frame: str = "fixed"
) -> list[dict[str, Any]]:
    """Match identified waves to truth rows (:meth:`RollingTruth.table`) by ``n`` and direction.

    Parameters
    ----------
    identified : list of RollingWave
    truth : list of dict
        Rows with ``wave_number``, ``direction``, ``fixed_hz``, ``rotating_hz``,
        ``damping_ratio``, ``fixed_damping_ratio``.
    frame : {"fixed", "rotating"}
        Frame whose frequency and damping are compared.

    Returns
    -------
    list of dict
        One per truth row: the truth, the nearest identified wave of the same
        ``n`` and direction (or ``None``), relative frequency and damping errors.
    """
    fk = "fixed_hz" if frame == "fixed" else "rotating_hz"
    zk = "fixed_damping_ratio" if frame == "fixed" else "damping_ratio"
    out = []
    for row in truth:
        same = [
            w
            for w in identified
            if w.wave_number == row["wave_number"]
            and (w.direction == row["direction"] or row["wave_number"] == 0)
        ]
        best = min(same, key=lambda w: abs(getattr(w, fk) - row[fk]), default=None)
        rec: dict[str, Any] = {"truth": row, "found": best is not None}
        if best is not None:
            rec["frequency_hz"] = float(getattr(best, fk))
            rec["damping_ratio"] = best.damping_ratio
            rec["std_frequency_hz"] = best.std_frequency_hz
            rec["std_damping_ratio"] = best.std_damping_ratio
            rec["f_error"] = float(getattr(best, fk) / row[fk] - 1)
            rec["zeta_error"] = float(best.damping_ratio / row[zk] - 1)
        out.append(rec)
    return out
