"""Circumferential wave number of identified tyre modes from their shapes.

Method
------
The second-order shape ``Psi^_m = psi_m sqrt(2 i Omega_m)`` of mode ``m``
(:meth:`ModalModel.second_order_shapes`, close to the mass-normalised real
mode ``phi_m`` in 1/sqrt(kg)) is known at the measured angles ``theta_j``
(``Channel.angle_deg``, not necessarily equally spaced). For every candidate
wave number ``n`` the single-harmonic model

``Psi^(theta_j) = a cos(n theta_j) + b sin(n theta_j)``   (``n = 0``: ``a`` only)

is fitted by (weighted) least squares with complex ``a``, ``b``, and its
**energy fraction** ``F_n = 1 - ||r_n||^2 / ||Psi^||^2`` (``r_n`` the
residual; weights ``1/sigma_j^2`` from the shapes' standard errors when the
model carries them) measures how much of the shape that harmonic explains.
The label is the ``n`` with the largest ``F_n`` among the wave numbers the
angles *resolve*; ``F_n`` is reported so that a shape which is not a single
harmonic (``F_n < min_fraction``) is flagged rather than silently labelled.
With standard errors the single-harmonic hypothesis is also tested: under it
``2 sum_j |r_j|^2 / sigma_j^2`` is chi-square with ``2 (J - k)`` degrees of
freedom (``J`` points, ``k`` complex coefficients), and ``p_value`` is its
upper tail (small: the shape has significant other harmonics, e.g. of an
imperfect tyre; the label may still be right).

Spatial aliasing
----------------
The angles resolve a range of wave numbers, and each wave number has
aliases that the angles cannot tell from it (:mod:`.harmonics`:
:func:`resolved_wave_numbers`, :func:`alias_candidates`; on ``J`` equal
points ``|k J +- n|``, both members resolved for ``n < J/2``). Every mode
carries the list of wave numbers it could alias to. Aliasing is *flagged*
when the labels contradict a ring (each ``n >= 1`` carries one pair, cos and
sin, and the flexural frequency rises with ``n``): more than two modes with
one label, or a label at a higher frequency than a pair of a higher label.
The flagged mode is then likely one of its alias candidates above the
resolved range.

Pairs
-----
Modes with the same label form the ring's double mode. For each member the
antinode angle ``theta_0`` (``Psi^ ~ A cos n(theta - theta_0)`` after
rotating the complex shape to its principal phase) is reported, in
``[-90/n, 90/n)`` deg (antinodes repeat every ``180/n`` deg); the member
whose antinode is nearer the reference angle (the first drive point, else
0 deg) is labelled ``"cos"``, the other ``"sin"``.
The pair's splitting is ``f_sin - f_cos`` (Hz, and relative to the mean) and
its orientation the ``cos`` member's antinode angle. A single member is
labelled by the same rule (``"cos"`` with an antinode at the drive point:
the perfect ring, whose ``sin`` member has a node there and is not excited).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._validate import as_finite
from ..exceptions import InputError, ShapeError
from ..modal.model import ModalModel
from ..modal.statistics.stats import chi2_sf
from .harmonics import (
    HarmonicFit,
    alias_candidates,
    as_angles,
    harmonic_fit,
    resolved_wave_numbers,
)

__all__ = [
    "HarmonicFit",
    "ModeWaveNumber",
    "WaveNumberAnalysis",
    "alias_candidates",
    "harmonic_fit",
    "resolved_wave_numbers",
    "wave_number_analysis",
]

Member = Literal["cos", "sin", "single"]


@dataclass(frozen=True)
class ModeWaveNumber:
    """Wave-number label of one identified mode.

    Attributes
    ----------
    index : int
        Mode index in the :class:`ModalModel`.
    frequency_hz, damping_ratio : float
        Of the mode.
    n : int
        Wave number with the largest energy fraction among the resolved ones.
    fraction : float
        Energy fraction of the single-harmonic fit at ``n`` (1: a pure harmonic).
    second_n : int
        Runner-up wave number; ``second_fraction`` its energy fraction.
    second_fraction : float
    p_value : float or None
        Chi-square test of the single-harmonic model (module docstring);
        ``None`` without shape standard errors.
    single_harmonic : bool
        ``fraction >= min_fraction``; False flags a shape that is not one harmonic.
    amplitude : float
        ``A`` of ``Psi^ ~ A cos n(theta - theta_0)`` (mass-normalised shape
        amplitude, 1/sqrt(kg)); for ``n = 0`` the mean radial value.
    amplitude_std : float or None
        Its standard error.
    antinode_deg : float
        ``theta_0`` in [-90/n, 90/n) deg (antinodes repeat every 180/n deg;
        0 for ``n = 0``).
    member : {"cos", "sin", "single"}
        Pair member relative to the reference angle (module docstring);
        ``"single"`` for ``n = 0``.
    pair : tuple of int
        Mode indices of the pair this mode belongs to (itself alone when its
        partner was not identified).
    aliases : tuple of int
        Wave numbers up to ``n_limit`` the angles cannot tell from ``n``.
    aliased : bool
        Flagged: the labels contradict a ring (module docstring), so this mode
        probably has one of ``aliases`` instead.
    notes : tuple of str
        Plain-language remarks (aliasing, mixed shape, unpaired member).
    """

    index: int
    frequency_hz: float
    damping_ratio: float
    n: int
    fraction: float
    second_n: int
    second_fraction: float
    p_value: float | None
    single_harmonic: bool
    amplitude: float
    amplitude_std: float | None
    antinode_deg: float
    member: Member
    pair: tuple[int, ...]
    aliases: tuple[int, ...]
    aliased: bool
    notes: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """``"n = 3 (cos)"``-style label; a trailing ``?`` when flagged."""
        flag = "?" if (self.aliased or not self.single_harmonic) else ""
        mem = "" if self.member == "single" else f" ({self.member})"
        return f"n = {self.n}{mem}{flag}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "index": self.index,
            "frequency_hz": self.frequency_hz,
            "damping_ratio": self.damping_ratio,
            "n": self.n,
            "label": self.label,
            "fraction": self.fraction,
            "second_n": self.second_n,
            "second_fraction": self.second_fraction,
            "p_value": self.p_value,
            "single_harmonic": self.single_harmonic,
            "amplitude": self.amplitude,
            "amplitude_std": self.amplitude_std,
            "antinode_deg": self.antinode_deg,
            "member": self.member,
            "pair": list(self.pair),
            "aliases": list(self.aliases),
            "aliased": self.aliased,
            "notes": list(self.notes),
        }


@dataclass(frozen=True)
class WaveNumberAnalysis:
    """Wave numbers of all modes of one :class:`ModalModel`.

    Attributes
    ----------
    modes : tuple of ModeWaveNumber
        One per mode, in the model's order (ascending frequency).
    angles_deg : ndarray, shape (J,)
        Angles used.
    n_resolved : int
        Largest wave number with both members resolved by the angles.
    reference_deg : float
        Reference angle of the cos/sin labels (first drive point, else 0).
    pairs : list of dict
        One per wave number with two members: ``n``, ``cos``, ``sin`` (mode
        indices), ``f_cos_hz``, ``f_sin_hz``, ``splitting_hz``,
        ``relative_splitting``, ``orientation_deg`` (cos member antinode).
    warnings : tuple of str
        Global remarks (aliasing, more modes than the points resolve).
    """

    modes: tuple[ModeWaveNumber, ...]
    angles_deg: NDArray[np.float64]
    n_resolved: int
    reference_deg: float
    pairs: list[dict[str, Any]] = field(default_factory=list)
    warnings: tuple[str, ...] = ()

    @property
    def n(self) -> NDArray[np.int_]:
        """Labels, shape (m,)."""
        return np.array([m.n for m in self.modes], dtype=int)

    @property
    def any_aliased(self) -> bool:
        """True when at least one mode is flagged as aliased."""
        return any(m.aliased for m in self.modes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "angles_deg": self.angles_deg.tolist(),
            "n_resolved": self.n_resolved,
            "reference_deg": self.reference_deg,
            "modes": [m.to_dict() for m in self.modes],
            "pairs": self.pairs,
            "warnings": list(self.warnings),
        }

    def format_table(self) -> str:
        """Text table: mode, frequency, label, fraction, antinode, flags."""
        rows = [
            f"{'#':>3} {'f [Hz]':>9} {'label':>14} {'fraction':>9} {'antinode':>9}  notes",
        ]
        for m in self.modes:
            rows.append(
                f"{m.index + 1:>3} {m.frequency_hz:>9.3f} {m.label:>14} {m.fraction:>9.4f} "
                f"{m.antinode_deg:>8.2f}°  {'; '.join(m.notes)}"
            )
        return "\n".join(rows)


def _output_angles(
    model: ModalModel, angles_deg: ArrayLike | None, rows: NDArray[np.intp]
) -> NDArray[np.float64]:
    if angles_deg is not None:
        a = as_finite(angles_deg, "angles_deg", ndim=1)
        if a.size == len(model.outputs):
            return a[rows]
        if a.size != rows.size:
            raise ShapeError(
                f"the points' angles (angles_deg): expected one per response point "
                f"({len(model.outputs)}), got {a.size}"
            )
        return a
    chans = [model.outputs[int(r)] for r in rows]
    missing = [c.label for c in chans if c.angle_deg is None]
    if missing:
        raise InputError(
            "outputs: the circumferential angle (Channel.angle_deg) of output(s) "
            f"{', '.join(missing[:5])}{' ...' if len(missing) > 5 else ''} is unknown; "
            "the wave number needs every output's angle (pass angles_deg)"
        )
    return np.array([float(c.angle_deg) for c in chans])  # type: ignore[arg-type]


def _output_rows(model: ModalModel, outputs: Sequence[int] | None) -> NDArray[np.intp]:
    n_out = len(model.outputs)
    if outputs is None:
        dirs = {abs(c.direction) for c in model.outputs}
        if len(dirs) > 1:
            raise InputError(
                f"outputs: the model's outputs have several directions {sorted(dirs)}; give "
                "outputs= the rows of the radial points on one circumference"
            )
        return np.arange(n_out, dtype=np.intp)
    rows = np.asarray(list(outputs), dtype=np.intp)
    if rows.ndim != 1 or rows.size == 0 or np.any(rows < 0) or np.any(rows >= n_out):
        raise InputError(f"outputs: expected positions in 0..{n_out - 1}, got {list(outputs)}")
    if np.unique(rows).size != rows.size:
        raise InputError(f"outputs: repeated positions in {list(outputs)}")
    return rows


@dataclass(frozen=True)
class _Circumference:
    """The measured points on the circumference and what they resolve."""

    rows: NDArray[np.intp]  # rows of the shapes used
    angles_deg: NDArray[np.float64]  # their angles, shape (J,)
    theta: NDArray[np.float64]  # the same in rad
    n_resolved: int  # largest wave number with both members resolved
    cos_next: bool  # the cos member of n_resolved + 1 (Nyquist) is observable
    n_limit: int  # largest wave number among the alias candidates

    @property
    def n_top(self) -> int:
        """Largest wave number fitted to the shapes."""
        return self.n_resolved + 1 if self.cos_next else self.n_resolved


@dataclass(frozen=True)
class _ShapeLabel:
    """The single-harmonic label of one shape, before the pairs (module docstring)."""

    n: int
    fraction: float
    second_n: int
    second_fraction: float
    p_value: float | None
    amplitude: float  # 1/sqrt(kg)
    amplitude_std: float | None
    antinode: float  # deg, in [-90/n, 90/n)


@dataclass
class _Pairs:
    """Pair members and the pairs' splitting and orientation."""

    members: list[Member]
    pair_of: dict[int, tuple[int, ...]]
    pairs: list[dict[str, Any]]


def wave_number_analysis(
    model: ModalModel,
    *,
    angles_deg: ArrayLike | None = None,
    reference_deg: float | None = None,
    min_fraction: float = 0.8,
    n_limit: int | None = None,
    outputs: Sequence[int] | None = None,
) -> WaveNumberAnalysis:
    """Label every mode of ``model`` with its circumferential wave number.

    Parameters
    ----------
    model : ModalModel
        Identified modes with radial outputs around the circumference.
    angles_deg : array_like, shape (n_out,), optional
        Angles of the outputs in deg; default ``Channel.angle_deg`` of the
        outputs (an error names the outputs without one).
    reference_deg : float, optional
        Angle of the cos/sin reference; default the first input's angle, else 0.
    min_fraction : float
        Energy fraction below which a shape is flagged as not a single
        harmonic (default 0.8: four fifths of the shape's energy in one
        harmonic). A labelling criterion, not a statistical test; the
        chi-square ``p_value`` is the test when standard errors exist.
    n_limit : int, optional
        Largest wave number listed among the alias candidates (default
        ``3 J``, J the number of points).
    outputs : sequence of int, optional
        Positions of the outputs (rows of the shapes) on one circumference
        in one direction (the radial points); default all outputs, which
        must then share one direction code (a model that mixes, say, radial
        and tangential channels is refused: choose the rows).

    Returns
    -------
    WaveNumberAnalysis
    """
    if not isinstance(model, ModalModel):
        raise InputError(f"model: expected a ModalModel, got {type(model).__name__}")
    if not 0.0 < float(min_fraction) <= 1.0:
        raise InputError(f"min_fraction: expected a value in (0, 1], got {min_fraction}")
    circ = _circumference(model, angles_deg, outputs, n_limit)
    if reference_deg is None:
        ref = next((c.angle_deg for c in model.inputs if c.angle_deg is not None), 0.0)
        reference_deg = float(ref) if ref is not None else 0.0
    shapes = model.second_order_shapes()[circ.rows]
    raw = [
        _label_shape(circ.theta, shapes[:, k], sig, circ.n_top)
        for k, sig in enumerate(_shape_sigmas(model, circ.rows, shapes))
    ]
    freq = model.frequency_hz
    zeta = model.damping_ratio
    groups: dict[int, list[int]] = {}
    for k, r in enumerate(raw):
        groups.setdefault(int(r.n), []).append(k)
    alias_lists = {n: alias_candidates(circ.angles_deg, n, circ.n_limit) for n in groups}
    aliased, notes = _flag_aliases(raw, groups, alias_lists, freq)
    for k, r in enumerate(raw):
        notes[k] += _shape_notes(r, circ, min_fraction)
    pairs = _pair_members(raw, groups, aliased, freq, reference_deg, min_fraction, notes)
    out = tuple(
        ModeWaveNumber(
            index=k,
            frequency_hz=float(freq[k]),
            damping_ratio=float(zeta[k]),
            n=int(r.n),
            fraction=float(r.fraction),
            second_n=int(r.second_n),
            second_fraction=float(r.second_fraction),
            p_value=r.p_value,
            single_harmonic=bool(r.fraction >= min_fraction),
            amplitude=float(r.amplitude),
            amplitude_std=r.amplitude_std,
            antinode_deg=float(r.antinode),
            member=pairs.members[k],
            pair=pairs.pair_of[k],
            aliases=tuple(alias_lists[int(r.n)]),
            aliased=bool(aliased[k]),
            notes=tuple(notes[k]),
        )
        for k, r in enumerate(raw)
    )
    return WaveNumberAnalysis(
        modes=out,
        angles_deg=circ.angles_deg,
        n_resolved=circ.n_resolved,
        reference_deg=float(reference_deg),
        pairs=sorted(pairs.pairs, key=lambda p: p["n"]),
        warnings=_warnings(model.n_modes, int(aliased.sum()), circ),
    )


def _circumference(
    model: ModalModel,
    angles_deg: ArrayLike | None,
    outputs: Sequence[int] | None,
    n_limit: int | None,
) -> _Circumference:
    """The rows and angles of the points, and the wave numbers they resolve."""
    rows = _output_rows(model, outputs)
    ang = _output_angles(model, angles_deg, rows)
    theta = as_angles(ang)
    n_res, cos_next = resolved_wave_numbers(ang)
    return _Circumference(
        rows=rows,
        angles_deg=ang,
        theta=theta,
        n_resolved=n_res,
        cos_next=cos_next,
        n_limit=3 * theta.size if n_limit is None else int(n_limit),
    )


def _shape_sigmas(
    model: ModalModel, rows: NDArray[np.intp], shapes: NDArray[np.complex128]
) -> list[NDArray[np.float64] | None]:
    """Standard errors of each mode's second-order shape at ``rows`` (None where unknown)."""
    omega = model.poles.imag
    std_psi = model.std.get("psi_out")
    if std_psi is not None and np.shape(std_psi) == model.psi_out.shape:
        std_psi = np.asarray(std_psi, float)[rows]
    out: list[NDArray[np.float64] | None] = []
    for k in range(model.n_modes):
        sig = None
        if std_psi is not None and np.shape(std_psi) == shapes.shape:
            s = np.asarray(std_psi, float)[:, k] * math.sqrt(2.0 * omega[k])
            if np.all(s > 0) and np.all(np.isfinite(s)):
                sig = s
        out.append(sig)
    return out


def _label_shape(
    theta: NDArray[np.float64],
    x: NDArray[np.complex128],
    sig: NDArray[np.float64] | None,
    n_top: int,
) -> _ShapeLabel:
    """Best single harmonic ``n <= n_top`` of one shape, its amplitude and antinode."""
    fits = [harmonic_fit(theta, x, n, sig) for n in range(n_top + 1)]
    fr = np.array([f.fraction for f in fits])
    order = np.argsort(-fr, kind="stable")
    best = fits[int(order[0])]
    second = fits[int(order[1])] if len(order) > 1 else best
    n = best.n
    # principal phase, then real coefficients
    alpha = 0.5 * np.angle(np.sum(x**2)) if np.any(x) else 0.0
    ab = best.coefficients * np.exp(-1j * alpha)
    ar, br = float(ab[0].real), float(ab[1].real)
    amp = math.hypot(ar, br)
    antinode = 0.0
    if n > 0:
        # antinodes repeat every 180/n deg; report the one in [-90/n, 90/n)
        period = 180.0 / n
        raw_deg = np.degrees(math.atan2(br, ar)) / n
        antinode = float(np.mod(raw_deg + period / 2, period) - period / 2)
    amp_std = None
    if sig is not None and amp > 0:
        cov_real = 0.5 * best.covariance  # (1, 1) for n = 0: b is not fitted
        u = (np.array([ar, br]) / amp)[: cov_real.shape[0]]
        amp_std = float(math.sqrt(max(float(u @ cov_real @ u), 0.0)))
    pval = None
    if best.chi2 is not None and best.dof > 0:
        pval = chi2_sf(best.chi2, best.dof)
    return _ShapeLabel(
        n=n,
        fraction=best.fraction,
        second_n=second.n,
        second_fraction=second.fraction,
        p_value=pval,
        amplitude=amp,
        amplitude_std=amp_std,
        antinode=antinode,
    )


def _flag_aliases(
    raw: Sequence[_ShapeLabel],
    groups: dict[int, list[int]],
    alias_lists: dict[int, list[int]],
    freq: NDArray[np.float64],
) -> tuple[NDArray[np.bool_], list[list[str]]]:
    """Modes whose labels contradict a ring (module docstring), with a note for each."""
    labels = np.array([r.n for r in raw], dtype=int)
    aliased = np.zeros(len(raw), dtype=bool)
    notes: list[list[str]] = [[] for _ in raw]
    for n, idx in groups.items():
        cap = 2  # a ring has one pair (cos, sin) per wave number
        if len(idx) > cap:
            # keep the lowest-frequency members as the genuine ones
            for k in sorted(idx, key=lambda j: freq[j])[cap:]:
                aliased[k] = True
                notes[k].append(
                    f"more than {cap} modes labelled n = {n}: probably aliased from "
                    f"n in {alias_lists[n][:4]}"
                )
    order_f = np.argsort(freq)
    for a_i, k in enumerate(order_f):
        higher_below = [
            j for j in order_f[:a_i] if labels[j] > labels[k] and labels[k] >= 1 and not aliased[j]
        ]
        if len(higher_below) >= 1 and labels[k] >= 1 and not aliased[k]:
            top = max(labels[j] for j in higher_below)
            # a whole pair of a higher n below this mode contradicts a ring
            if sum(1 for j in higher_below if labels[j] == top) >= 2 or top >= labels[k] + 2:
                aliased[k] = True
                notes[k].append(
                    f"labelled n = {labels[k]} but above the n = {top} modes: probably aliased "
                    f"from n in {alias_lists[int(labels[k])][:4]}"
                )
    return aliased, notes


def _shape_notes(r: _ShapeLabel, circ: _Circumference, min_fraction: float) -> list[str]:
    """Notes on one shape: the Nyquist wave number, not a single harmonic."""
    notes = []
    n = r.n
    if circ.cos_next and n == circ.n_top and n > 0:
        notes.append(
            f"n = {n} is the Nyquist wave number of these points: only its cos member is observable"
        )
    if r.fraction < min_fraction:
        notes.append(
            f"not a single harmonic: {100 * r.fraction:.0f} % of the shape in n = {n}, "
            f"{100 * r.second_fraction:.0f} % in n = {r.second_n}"
        )
    return notes


def _pair_members(
    raw: Sequence[_ShapeLabel],
    groups: dict[int, list[int]],
    aliased: NDArray[np.bool_],
    freq: NDArray[np.float64],
    reference_deg: float,
    min_fraction: float,
    notes: list[list[str]],
) -> _Pairs:
    """cos/sin members of each wave number's pair, with the pairs' splitting (module docstring).

    A note is appended to ``notes`` for a member whose partner was not identified.
    """
    members: list[Member] = ["single"] * len(raw)
    pairs_out: list[dict[str, Any]] = []
    pair_of: dict[int, tuple[int, ...]] = {k: (k,) for k in range(len(raw))}

    def dist(k: int, n: int) -> float:
        # distance of the nearest antinode (every 180/n deg) from the reference
        period = 180.0 / n
        return float(abs((raw[k].antinode - reference_deg + period / 2) % period - period / 2))

    for n, idx in groups.items():
        # pairs of labelled, single-harmonic modes only
        good = [k for k in idx if not aliased[k] and raw[k].fraction >= min_fraction]
        if n == 0 or not good:
            continue
        if len(good) == 1:
            k = good[0]
            # antinode within 45/n deg of the reference: cos member
            members[k] = "cos" if dist(k, n) <= 45.0 / n else "sin"
            notes[k].append(
                f"partner ({'sin' if members[k] == 'cos' else 'cos'} member) not identified"
            )
            continue
        a, b = sorted(good, key=lambda j: freq[j])[:2]
        c_idx, s_idx = (a, b) if dist(a, n) <= dist(b, n) else (b, a)
        members[c_idx], members[s_idx] = "cos", "sin"
        pair_of[a] = pair_of[b] = (c_idx, s_idx)
        fm = 0.5 * (freq[a] + freq[b])
        pairs_out.append(
            {
                "n": int(n),
                "cos": int(c_idx),
                "sin": int(s_idx),
                "f_cos_hz": float(freq[c_idx]),
                "f_sin_hz": float(freq[s_idx]),
                "splitting_hz": float(freq[s_idx] - freq[c_idx]),
                "relative_splitting": float((freq[s_idx] - freq[c_idx]) / fm),
                "orientation_deg": float(raw[c_idx].antinode),
                "member_angle_deg": float(
                    abs(
                        (raw[s_idx].antinode - raw[c_idx].antinode + 90.0 / n) % (180.0 / n)
                        - 90.0 / n
                    )
                ),
            }
        )
    return _Pairs(members=members, pair_of=pair_of, pairs=pairs_out)


def _warnings(n_modes: int, n_alias: int, circ: _Circumference) -> tuple[str, ...]:
    """Global remarks: aliased modes, more modes than the points resolve."""
    warnings: list[str] = []
    n_res, j = circ.n_resolved, circ.theta.size
    if n_alias:
        warnings.append(
            f"{n_alias} mode(s) flagged as spatially aliased: the {j} points resolve "
            f"wave numbers up to n = {n_res}; modes of higher n fold onto lower ones"
        )
    n_modes_resolvable = 1 + 2 * n_res + (1 if circ.cos_next else 0)
    if n_modes > n_modes_resolvable:
        warnings.append(
            f"{n_modes} modes but {j} points resolve at most "
            f"{n_modes_resolvable} independent shapes (n <= {n_res}): some modes must alias"
        )
    return tuple(warnings)
