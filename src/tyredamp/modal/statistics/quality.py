"""Typed fit-quality record of an identified :class:`~tyredamp.modal.model.ModalModel`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...exceptions import InputError

__all__ = [
    "FitQuality",
    "RejectedMode",
    "rejected_summary",
    "short_reason",
    "strongest_rejected",
    "threshold_text",
]


def _ro(x: ArrayLike, dtype: type = float) -> NDArray[Any]:
    a: NDArray[Any] = np.array(x, dtype=dtype)
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class RejectedMode:
    """A candidate mode that the identification tried and did not keep.

    Attributes
    ----------
    frequency_hz, damping_ratio : float
        Natural frequency (Hz) and damping ratio of the candidate.
    reason : str
        Why, in statistical terms where a test decided it.
    statistic : float
        Its mode statistic ``T`` (NaN when no test was made).
    threshold : float
        The threshold ``T`` had to exceed (NaN when no test was made).
    """

    frequency_hz: float
    damping_ratio: float
    reason: str
    statistic: float = float("nan")
    threshold: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        return {
            "frequency_hz": self.frequency_hz,
            "damping_ratio": self.damping_ratio,
            "reason": self.reason,
            "statistic": _num(self.statistic),
            "threshold": _num(self.threshold),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> RejectedMode:
        return cls(
            float(d["frequency_hz"]),
            float(d["damping_ratio"]),
            str(d["reason"]),
            _flt(d.get("statistic")),
            _flt(d.get("threshold")),
        )


#: the reason of a record that marks a candidate as kept after all (a cluster of
#: the diagram rejected at first, whose trial the residual search kept):
#: :func:`merge_rejected` drops every record of that candidate
KEPT = "kept: its trial mode passed the mode test and the joint refit"


def merge_rejected(rej: list[RejectedMode]) -> list[RejectedMode]:
    """One record per candidate: records of the same pole (frequency and damping
    equal to 1e-9) become one, their reasons joined in order (each once), with the
    first test statistic and threshold among them (a cluster of the diagram that
    too few orders resolved, and then found too weak in the residual, is one
    candidate with both reasons). A candidate with a record ``KEPT`` is a mode,
    not a rejected candidate: it is left out."""
    out: list[RejectedMode] = []
    for r in rej:
        for i, o in enumerate(out):
            same_f = abs(o.frequency_hz - r.frequency_hz) <= 1e-9 * abs(o.frequency_hz)
            same_z = abs(o.damping_ratio - r.damping_ratio) <= 1e-9 * abs(o.damping_ratio)
            if same_f and same_z:
                why = o.reason if r.reason in o.reason.split("; ") else f"{o.reason}; {r.reason}"
                tested = np.isfinite(o.statistic)
                out[i] = RejectedMode(
                    o.frequency_hz,
                    o.damping_ratio,
                    why,
                    o.statistic if tested else r.statistic,
                    o.threshold if tested else r.threshold,
                )
                break
        else:
            out.append(r)
    return [r for r in out if KEPT not in r.reason.split("; ")]


def closest_rejected(rejected: Sequence[RejectedMode], n: int = 3) -> list[RejectedMode]:
    """The ``n`` rejected candidates whose mode-test statistic came closest to their
    threshold (largest ``statistic / threshold``; candidates without a test left
    out): the ones a reader checks first."""
    tested = [r for r in rejected if np.isfinite(r.statistic) and r.threshold > 0]
    tested.sort(key=lambda r: r.statistic / r.threshold, reverse=True)
    return tested[:n]


def short_reason(r: RejectedMode) -> str:
    """A few words on why the candidate ``r`` was not kept, from its last (deciding)
    reason: ``"half-power band below the line spacing"``, ``"not significant, T = 12
    <= 28"``, ``"represented by the mode at 51.52 Hz"``, ...; the full reason stays
    in ``r.reason``."""
    import re

    last = r.reason.split("; ")[-1]
    tested = np.isfinite(r.statistic) and np.isfinite(r.threshold)
    if "below the line spacing" in last:
        return "half-power band below the line spacing"
    if "not significant" in last:
        if tested:
            return f"not significant, T = {r.statistic:.3g} <= {r.threshold:.3g}"
        return "not significant"
    if "stands for it" in last:
        m = re.search(r"the mode at ([0-9.eE+-]+) Hz", last)
        return f"represented by the mode at {float(m.group(1)):.2f} Hz" if m else last
    if "merge distance" in last:
        return "the same candidate as one tried before"
    if "merged with" in last:
        return "merged with another mode in the refit"
    if "band edge" in last or "outside the band" in last or "left the band" in last:
        return "outside the band"
    if "did not converge" in last:
        return "its trial did not converge"
    m = re.fullmatch(r"present in (\d+%) of orders < (\d+%)", last)
    if m:
        return f"unstable in the stabilisation diagram ({m.group(1)} of the orders)"
    return last if len(last) <= 80 else last[:77].rstrip() + "..."


def strongest_rejected(rejected: Sequence[RejectedMode]) -> list[RejectedMode]:
    """The rejected candidates, those with the largest mode-test statistic first (the
    ones that most changed the fit when tried), untested ones after them in order."""
    tested = [r for r in rejected if np.isfinite(r.statistic)]
    rest = [r for r in rejected if not np.isfinite(r.statistic)]
    return sorted(tested, key=lambda r: r.statistic, reverse=True) + rest


def rejected_summary(rejected: Sequence[RejectedMode], n: int = 3) -> str:
    """One line on the rejected candidates: how many, and the ``n`` most relevant
    (:func:`strongest_rejected`; records shown at the same frequency counted as one)
    each with its short reason (:func:`short_reason`)."""
    row = f"{len(rejected)} candidate(s) rejected"
    shown: dict[str, list[str]] = {}
    for r in strongest_rejected(rejected):
        key = f"{r.frequency_hz:.2f} Hz"
        if key not in shown and len(shown) == n:
            continue
        shown.setdefault(key, [])
        why = short_reason(r)
        if why not in shown[key]:
            shown[key].append(why)
    if not shown:
        return row
    parts = [f"{k}: {', '.join(w)}" for k, w in shown.items()]
    first = (
        "largest mode statistic T first" if any(np.isfinite(r.statistic) for r in rejected) else ""
    )
    rest = sum(f"{r.frequency_hz:.2f} Hz" not in shown for r in rejected)
    more = f"; {rest} more" if rest > 0 else ""
    return f"{row}" + (f", {first}" if first else "") + ": " + "; ".join(parts) + more


def threshold_text(thr: float, base: float) -> str:
    """A mode's threshold ``thr`` for a reason text; says when the noise along the
    response raised it above the base threshold ``base``
    (:func:`~tyredamp.modal.search.thresholds.local_thresholds`)."""
    if thr > base:
        return f"{thr:.3g} (raised from {base:.3g}: noise along the response)"
    return f"{thr:.3g}"


def _num(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _flt(x: Any) -> float:
    return float("nan") if x is None else float(x)


@dataclass(frozen=True, eq=False)
class FitQuality:
    """How well a modal model explains its data, and why each mode is in it.

    Attributes
    ----------
    rmsd : float
        RMSD of eq. [19] (FRF unit).
    relative_error : float
        ``||H_model - H|| / ||H||`` over the band.
    rmsd_per_frf : ndarray, shape (n_out, n_in)
        RMSD of each FRF (read-only).
    n_lines : int
        Lines of the band.
    noise_source : str
        ``"variance"``, ``"coherence"`` or ``"residual"`` (see
        :mod:`tyredamp.modal.problem.problem`).
    noise_rms_per_output : ndarray, shape (n_out,)
        Noise RMS per output (FRF unit; read-only): known, or the residual RMS.
    chi2, dof, p_value : float, int, float
        Goodness-of-fit test (:func:`tyredamp.modal.statistics.stats.goodness_of_fit`).
    passed : bool
        The cost is within its chi-square range.
    verdict : str
        "the model explains the data to the noise ..." or "structure is left: ...".
    statistic : ndarray, shape (m,)
        Mode statistic ``T`` of each mode (cost rise in units of the noise
        variance when the mode is removed; read-only).
    threshold : float
        Base threshold of ``T`` (:func:`tyredamp.modal.statistics.stats.mode_threshold`).
    false_alarm : float
        Level of the mode test and of the goodness-of-fit test.
    kept : tuple of str
        Why each mode is in the model.
    rejected : tuple of RejectedMode
        Candidates tried and not kept.
    status : str
        Refinement status (``"converged"``, ``"maxfev"``, ``"lsfd"``).
    n_evaluations : int
        Cost evaluations of the refinement.
    thresholds : ndarray, shape (m,)
        The threshold applied to each mode's ``T`` (read-only): ``threshold``
        raised where the residual's noise lies along the response
        (:func:`tyredamp.modal.search.thresholds.local_thresholds`), ``threshold`` itself
        where it was not raised or no test was made (modes asked for, real
        modes). Default (empty): ``threshold`` for every mode, as in records
        written before it existed.
    """

    rmsd: float
    relative_error: float
    rmsd_per_frf: NDArray[np.float64]
    n_lines: int
    noise_source: str
    noise_rms_per_output: NDArray[np.float64]
    chi2: float
    dof: int
    p_value: float
    passed: bool
    verdict: str
    statistic: NDArray[np.float64]
    threshold: float
    false_alarm: float
    kept: tuple[str, ...]
    rejected: tuple[RejectedMode, ...] = ()
    status: str = ""
    n_evaluations: int = 0
    thresholds: NDArray[np.float64] = field(default_factory=lambda: np.empty(0))

    def __post_init__(self) -> None:
        for name in ("rmsd_per_frf", "noise_rms_per_output", "statistic"):
            object.__setattr__(self, name, _ro(getattr(self, name)))
        if len(self.kept) != self.statistic.size:
            raise InputError(
                f"kept: expected one reason per mode ({self.statistic.size}), got {len(self.kept)}"
            )
        thr = np.asarray(self.thresholds, dtype=float).ravel()
        if thr.size == 0:
            thr = np.full(self.statistic.size, float(self.threshold))
        if thr.size != self.statistic.size:
            raise InputError(
                f"thresholds: expected one per mode ({self.statistic.size}), got {thr.size}"
            )
        object.__setattr__(self, "thresholds", _ro(thr))
        object.__setattr__(self, "kept", tuple(self.kept))
        object.__setattr__(self, "rejected", tuple(self.rejected))

    def reordered(self, order: NDArray[np.intp]) -> FitQuality:
        """The same record with the per-mode entries in ``order``."""
        return FitQuality(
            **{
                **self.__dict__,
                "statistic": self.statistic[order],
                "thresholds": self.thresholds[order],
                "kept": tuple(self.kept[int(i)] for i in order),
            }
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (non-finite numbers as null); see :meth:`from_dict`."""
        return {
            "rmsd": _num(self.rmsd),
            "relative_error": _num(self.relative_error),
            "rmsd_per_frf": self.rmsd_per_frf.tolist(),
            "n_lines": self.n_lines,
            "noise_source": self.noise_source,
            "noise_rms_per_output": self.noise_rms_per_output.tolist(),
            "chi2": _num(self.chi2),
            "dof": self.dof,
            "p_value": _num(self.p_value),
            "passed": self.passed,
            "verdict": self.verdict,
            "statistic": [_num(float(x)) for x in self.statistic],
            "threshold": _num(self.threshold),
            "thresholds": [_num(float(x)) for x in self.thresholds],
            "false_alarm": self.false_alarm,
            "kept": list(self.kept),
            "rejected": [r.to_dict() for r in self.rejected],
            "status": self.status,
            "n_evaluations": self.n_evaluations,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> FitQuality:
        """Inverse of :meth:`to_dict`; raises :class:`InputError` naming a bad key."""
        try:
            return cls(
                rmsd=_flt(d["rmsd"]),
                relative_error=_flt(d["relative_error"]),
                rmsd_per_frf=np.array(d["rmsd_per_frf"], float),
                n_lines=int(d["n_lines"]),
                noise_source=str(d["noise_source"]),
                noise_rms_per_output=np.array(d["noise_rms_per_output"], float),
                chi2=_flt(d["chi2"]),
                dof=int(d["dof"]),
                p_value=_flt(d["p_value"]),
                passed=bool(d["passed"]),
                verdict=str(d["verdict"]),
                statistic=np.array([_flt(x) for x in d["statistic"]], float),
                threshold=_flt(d["threshold"]),
                false_alarm=float(d["false_alarm"]),
                kept=tuple(str(x) for x in d["kept"]),
                rejected=tuple(RejectedMode.from_dict(r) for r in d.get("rejected", [])),
                status=str(d.get("status", "")),
                n_evaluations=int(d.get("n_evaluations", 0)),
                # files written before the per-mode thresholds: the base one for each
                thresholds=np.array([_flt(x) for x in d.get("thresholds") or []], float),
            )
        except KeyError as exc:
            raise InputError(f"fit quality: missing key {exc.args[0]!r}") from None
        except (TypeError, ValueError, AttributeError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"fit quality: malformed entry ({exc})") from None
