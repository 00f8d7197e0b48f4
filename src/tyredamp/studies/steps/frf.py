"""The ``frf`` step: FRFs with coherence from force and response time data."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...frf import FRF, Channel
from ...timedata import TimeData
from ._settings import Band, Choice, Integer, Length, Names, StepSettings, knob, samples

if TYPE_CHECKING:
    from ...signal.estimators import Estimator
    from ...signal.estimators import Method as FRFMethod

__all__ = ["FRF_METHODS", "FrfSettings", "FrfStep", "frf_from_time"]

#: The FRF estimators of :data:`tyredamp.signal.estimators.ESTIMATORS` (named here so that
#: the settings load without SciPy; a test keeps the two equal).
FRF_ESTIMATORS: tuple[str, ...] = ("H1", "H2", "Hv")
#: Averaging methods of the FRF estimation (``auto``: from the file, else from the data).
FRF_METHODS: tuple[str, ...] = ("auto", "cyclic", "welch", "transient", "lrm", "lpm")


@dataclass(frozen=True)
class FrfSettings(StepSettings):
    """How FRFs are estimated from time data (``tyredamp frf``; a campaign's
    ``[settings.radial.frf]`` for tests that hold time data)."""

    section: ClassVar[str] = "frf"

    estimator: str = knob(
        "H1",
        "H1 (noise on outputs), H2 (noise on inputs) or Hv (total least squares).",
        Choice(FRF_ESTIMATORS),
        "--estimator",
    )
    reference: tuple[str, ...] | None = knob(
        None,
        "Force channel to use as input (label like 1+Z, channel name or node number); "
        "repeat for MIMO. Default: every force channel.",
        Names(what="force channels", split=False),
        "--reference",
        metavar="CHANNEL",
    )
    method: str = knob(
        "auto",
        "auto: cyclic when the file states a period, transient when it states a record "
        "length, else decided from the data (periodic: cyclic; impact: transient; random: "
        "Welch). lrm/lpm: local rational/polynomial method on the whole record (random "
        "excitation).",
        Choice(FRF_METHODS),
        "--method",
    )
    segment: int | None = knob(
        None,
        "Welch/transient segment in samples (at most 2^26).",
        Integer(2, maximum=1 << 26),
        "--segment",
        unit="samples",
    )
    period: int | str | None = knob(
        None,
        "Period of a periodic excitation: samples (4096) or seconds (0.5s); it must be a "
        "whole number of samples. Default: from the file, else detected from the force.",
        Length(),
        "--period",
        unit="samples or s",
        metavar="SAMPLES|SECONDS",
    )
    settle: int | str | None = knob(
        None,
        "Samples (or seconds, 2s) to drop at the start (transient). Default: from the "
        "file, else detected for periodic data.",
        Length(),
        "--settle",
        unit="samples or s",
        metavar="SAMPLES|SECONDS",
    )
    band: tuple[float, float] | None = knob(
        None, "Keep lines in this band (Hz).", Band(), "--band", unit="Hz", metavar="F_LO F_HI"
    )


class FrfStep:
    """Time data -> FRF (spec step 2); no verdicts of its own (the quality check has them)."""

    name: ClassVar[str] = "frf"
    Settings: ClassVar[type[FrfSettings]] = FrfSettings

    @staticmethod
    def run(data: TimeData, settings: FrfSettings, where: str = "") -> tuple[FRF, dict[str, Any]]:
        """FRFs of ``data`` with ``settings``; ``where`` prefixes the names of the
        lengths in messages (``"settings.radial.frf."``; the CLI gives ``"--"``)."""
        frf = frf_from_time(data, **FrfStep._arguments(data, settings, where))
        return frf, {}

    @staticmethod
    def records(data: TimeData, settings: FrfSettings, where: str = "") -> tuple[FRF, list[FRF]]:
        """The FRF of :meth:`run` and one FRF per record it averages (each hit of an
        impact test alone, on the same lines: :mod:`tyredamp.signal.records`)."""
        from ...signal.records import estimate_record_frfs

        kw = FrfStep._arguments(data, settings, where)
        return estimate_record_frfs(data, kw.pop("estimator"), **kw)

    @staticmethod
    def _arguments(data: TimeData, settings: FrfSettings, where: str) -> dict[str, Any]:
        """The estimator's arguments from the step's settings (lengths in samples)."""
        s = settings
        rate = data.sample_rate
        return {
            "estimator": s.estimator,
            "reference": list(s.reference) if s.reference else None,
            "method": None if s.method == "auto" else s.method,
            "segment_samples": s.segment,
            "period_samples": None
            if s.period is None
            else samples(s.period, rate, where + "period"),
            "settle_samples": None
            if s.settle is None
            else samples(s.settle, rate, where + "settle"),
            "band": s.band,
        }


def frf_from_time(
    data: TimeData,
    estimator: Estimator = "H1",
    *,
    reference: Sequence[Channel | int | str] | None = None,
    method: FRFMethod | None = None,
    segment_samples: int | None = None,
    period_samples: int | None = None,
    settle_samples: int | None = None,
    band: tuple[float, float] | None = None,
    detect: bool = True,
) -> FRF:
    """FRFs with coherence from force and response time data (spec step 2).

    Parameters
    ----------
    data : TimeData
        Force and response channels.
    estimator : {"H1", "H2", "Hv"}
        FRF estimator.
    reference : sequence of Channel, int or str, optional
        Force channels; default: every force channel.
    method : {"cyclic", "welch", "transient", "lrm", "lpm"}, optional
        Averaging method; default chosen from the data's acquisition record
        or, when ``detect``, from the force itself (cyclic for periodic
        excitation); see :func:`tyredamp.signal.estimate_frf`.
    segment_samples : int, optional
        Segment length of Welch/transient averaging, samples.
    period_samples : int, optional
        Excitation period, samples (overrides the acquisition record).
    settle_samples : int, optional
        Samples dropped at the start of the record or of each run (start
        transient); default from the record or detected.
    band : (float, float), optional
        Lines to keep, Hz.
    detect : bool
        Detect periodicity and the start transient from the data when the
        acquisition record does not state them
        (:mod:`tyredamp.signal.periodicity`).
    """
    from ...signal.estimators import estimate_frf

    return estimate_frf(
        data,
        estimator,
        reference=list(reference) if reference else None,
        method=method,
        segment_samples=segment_samples,
        period_samples=period_samples,
        settle_samples=settle_samples,
        band=band,
        detect=detect,
    )
