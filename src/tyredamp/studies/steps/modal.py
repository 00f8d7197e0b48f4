"""The ``modal`` step: real and complex modes of FRFs, their verdicts and the modes document.

The whole recipe of ``tyredamp modal``, of a campaign's modal step and of
Python is :meth:`ModalStep.run` (modes, then the wave numbers of ring
outputs, then the verdict of each fit), and :meth:`ModalStep.document` puts
the verdicts into the modes document (``meta.verdict`` of each model,
``docs/modes-json.md``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...exceptions import InputError
from ...frf import FRF
from ._settings import (
    Band,
    Boolean,
    Choice,
    Integer,
    Number,
    Positives,
    Registered,
    StepSettings,
    knob,
)

if TYPE_CHECKING:
    from ...modal.identify import ModalIdentification
    from ...modal.model import ModalModel

__all__ = ["MODAL_MODELS", "ModalSettings", "ModalStep", "label_wave_numbers"]

#: The default false-alarm rate of the mode test
#: (:data:`tyredamp.modal.statistics.stats.FALSE_ALARM`) and pole estimator
#: (:data:`tyredamp.modal.poles.estimators.DEFAULT_ESTIMATOR`), named here so that the
#: settings load without SciPy; a test keeps them equal.
FALSE_ALARM = 0.01
DEFAULT_ESTIMATOR = "plscf"


def _estimators() -> Any:
    from ...modal.poles.estimators import ESTIMATORS

    return ESTIMATORS


#: The modal models a fit can give.
MODAL_MODELS: tuple[str, ...] = ("both", "real", "complex")


@dataclass(frozen=True)
class ModalSettings(StepSettings):
    """How modes are identified from FRFs (``tyredamp modal``; a campaign's
    ``[settings.radial.modal]``; :func:`~tyredamp.modal.identify_modes`)."""

    section: ClassVar[str] = "modal"

    band: tuple[float, float] | None = knob(
        None, "Analysis band in Hz (default all).", Band(), "--band", unit="Hz", metavar="F_LO F_HI"
    )
    model: str = knob(
        "both",
        "Real modes (proportional damping, eq. 2/3), complex modes (eq. 10) or both.",
        Choice(MODAL_MODELS),
        "--model",
    )
    n_modes: int | None = knob(
        None, "Number of modes to keep (at most 1000).", Integer(1, maximum=1000), "--modes"
    )
    frequencies: tuple[float, ...] | None = knob(
        None,
        "Approximate natural frequencies (Hz) of the wanted modes; overrides --modes.",
        Positives(),
        "--frequencies",
        unit="Hz",
        metavar="F1,F2,...",
    )
    max_order: int | None = knob(
        None,
        "Highest pLSCF model order (default 60 / number of inputs; at most 1000).",
        Integer(2, maximum=1000),
        "--max-order",
    )
    order_step: int = knob(
        2,
        "Stabilisation diagram: every N-th order from the highest down to a quarter of it.",
        Integer(1, optional=False, maximum=1000),
        "--order-step",
    )
    residuals: bool = knob(
        True, "Fit without lower/upper residual terms.", Boolean(), "--no-residuals"
    )
    false_alarm: float = knob(
        FALSE_ALARM,
        "False-alarm rate of the mode test: probability that a fit of pure noise keeps a "
        "noise mode (also the level of the goodness-of-fit test).",
        Number(0.0, 1.0, open=True, optional=False),
        "--false-alarm",
    )
    search: bool = knob(
        True, "Skip the residual-driven search for missed modes.", Boolean(), "--no-search"
    )
    estimator: str = knob(
        DEFAULT_ESTIMATOR,
        "Pole estimator of the stabilisation diagram, by name (plscf: poly-reference LSCF).",
        Registered(_estimators, "pole estimator"),
        "--estimator",
    )


class ModalStep:
    """FRF -> modes (:class:`~tyredamp.modal.identify.ModalIdentification`) and the
    verdict of each fitted model."""

    name: ClassVar[str] = "modal"
    Settings: ClassVar[type[ModalSettings]] = ModalSettings
    #: in a campaign: the FRF of time data and the quality check come first
    sections: ClassVar[tuple[str, ...]] = ("frf", "checks", "modal")
    #: in a campaign: the test's channel map reads its time data
    conditions: ClassVar[tuple[str, ...]] = ("channel_map",)

    @staticmethod
    def run(frf: FRF, settings: ModalSettings) -> tuple[ModalIdentification, dict[str, Any]]:
        """Identify the modes of ``frf``; returns them and ``{model: FitVerdict}``.

        Each model gets the wave numbers of its modes when the outputs carry
        their angles on the ring
        (:func:`label_wave_numbers`); the verdicts are returned, not stored in
        the models (:meth:`document` stores them).
        """
        from ..verdicts import modal_verdicts

        res = ModalStep._identify(frf, settings)
        for mdl in res.models.values():
            label_wave_numbers(mdl)
        return res, dict(modal_verdicts(frf, res))

    @staticmethod
    def replicates(
        result: ModalIdentification, replicates: Sequence[FRF], settings: ModalSettings
    ) -> list[Any]:
        """Find each mode again in each replicate (``tyredamp modal --replicate``).

        Each replicate is identified alone with ``settings`` (complex modes, the
        mode count its own), over the fit's band and then over a mode's own band
        (:func:`tyredamp.modal.replicates.replicate_support`); the finding of
        each mode goes into ``meta["replicates"]`` of the complex model (the real
        one when there is none) and is returned, one
        :class:`~tyredamp.modal.replicates.ReplicateSupport` per mode.
        """
        from dataclasses import replace

        import numpy as np

        from ...modal.replicates import replicate_support

        name = "complex" if "complex" in result.models else "real"
        model = result.models[name]
        cache: dict[tuple[int, float, float], np.ndarray] = {}

        def identify(k: int, band: tuple[float, float]) -> np.ndarray:
            key = (k, round(band[0], 9), round(band[1], 9))
            if key not in cache:
                try:
                    found = ModalStep.run_modes(replicates[k], replace(settings, band=band))
                except InputError:  # too few lines in a mode's own band: nothing found there
                    found = np.empty(0, dtype=complex)
                cache[key] = found
            return cache[key]

        df = float(np.median(np.diff(result.frequency))) if result.frequency.size > 1 else 0.0
        support = replicate_support(
            model,
            len(replicates),
            identify,
            band=(float(result.band_hz[0]), float(result.band_hz[1])),
            df=df,
        )
        model.meta["replicates"] = [s.to_dict() for s in support]
        return support

    @staticmethod
    def run_modes(frf: FRF, settings: ModalSettings) -> Any:
        """The poles (rad/s) of the complex modes of ``frf`` that the mode test keeps, the
        mode count the data's own (``settings``' model, mode count and frequencies not used)."""
        from ...modal.replicates import kept_poles

        res = ModalStep._identify(frf, settings, model="complex", n_modes=None, frequencies=None)
        return kept_poles(res.models["complex"])

    @staticmethod
    def _identify(frf: FRF, settings: ModalSettings, **override: Any) -> ModalIdentification:
        """``identify_modes`` of ``frf`` with ``settings``, some arguments overridden."""
        from ...modal.identify import identify_modes

        s = settings
        kw: dict[str, Any] = {
            "band": s.band,
            "model": s.model,
            "n_modes": s.n_modes,
            "frequencies": s.frequencies,
            "max_order": s.max_order,
            "order_step": s.order_step,
            "residuals": s.residuals,
            "false_alarm": s.false_alarm,
            "search": s.search,
            "estimator": _estimators()[s.estimator],
        }
        return identify_modes(frf, **{**kw, **override})

    @staticmethod
    def document(
        result: ModalIdentification, verdicts: dict[str, Any], *, source: str = ""
    ) -> dict[str, Any]:
        """The modes document (``docs/modes-json.md``) with each model's verdict
        in its ``meta.verdict``."""
        from ...documents.modes import modes_document

        doc = modes_document(
            result.models, source=source, band_hz=result.band_hz, frf_kind=result.frf_kind
        )
        for name, v in verdicts.items():
            doc["models"][name].setdefault("meta", {})["verdict"] = v.to_dict()
        return doc


def label_wave_numbers(model: ModalModel) -> None:
    """Put each mode's circumferential wave number into ``model.meta`` (in place).

    Only when every output carries its angle on the ring (``Channel.angle_deg``):
    ``wave_number``, ``wave_number_label`` and ``wave_number_fraction`` from
    :func:`tyredamp.tyremodel.wave_number_analysis`; nothing otherwise, nor
    when the angles cannot carry a Fourier fit (too few, repeated).
    """
    from ...tyremodel.wavenumber import wave_number_analysis

    if model.n_modes == 0 or any(c.angle_deg is None for c in model.outputs):
        return
    try:
        wa = wave_number_analysis(model)
    except InputError:
        return
    model.meta["wave_number"] = [m.n for m in wa.modes]
    model.meta["wave_number_label"] = [m.label for m in wa.modes]
    model.meta["wave_number_fraction"] = [m.fraction for m in wa.modes]
