"""The lateral ``fit`` step: lateral tyre models fitted to one FRF and ranked."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...exceptions import InputError
from ...frf import FRF
from ._settings import Band, Choice, Names, Number, Pair, StepSettings, knob

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ...lateral import LateralData
    from ...lateral.fit import Criterion, Weights
    from ...lateral.ranking import Ranking
    from ...lateral.response import ForceKind

__all__ = ["LATERAL_MODELS", "LateralFitSettings", "LateralFitStep", "fit_models", "lateral_data"]


def _model_name(name: str, where: str) -> str:
    from ...lateral.models import get_model_class

    try:
        return get_model_class(name).name
    except (InputError, KeyError, ValueError) as exc:
        raise InputError(f"{where}: {exc}") from None


#: The lateral models of :data:`tyredamp.lateral.models.MODELS` (named here so that the
#: settings load without SciPy; a test keeps the two equal).
LATERAL_MODELS: tuple[str, ...] = (
    "classic",
    "hysteretic",
    "maxwell",
    "relaxation",
    "string",
    "viscoplastic",
)


def _models_text() -> str:
    return (
        f"Models to compare, comma-separated or repeated; from {list(LATERAL_MODELS)} or "
        "aliases (proposed, lines ...). Default: classic, maxwell, viscoplastic, hysteretic."
    )


@dataclass(frozen=True)
class LateralFitSettings(StepSettings):
    """How lateral models are fitted and ranked (``tyredamp lateral fit``; a campaign's
    ``[settings.lateral.fit]``, whose test gives the speed)."""

    section: ClassVar[str] = "fit"

    models: tuple[str, ...] | None = knob(
        None, _models_text(), Names(_model_name, "model names"), "--models", metavar="NAMES"
    )
    wheel_mass_kg: float | None = knob(
        None,
        "Wheel mass for axle-force FRFs, kg (default from the file's meta, else 0).",
        Number(0.0),
        "--wheel-mass",
        unit="kg",
        metavar="KG",
    )
    force: str | None = knob(
        None,
        "Force the FRF refers to (default from the file's meta, else ground).",
        Choice(("ground", "axle"), optional=True),
        "--force",
    )
    band: tuple[float, float] | None = knob(
        None, "Fit only lines in this band (Hz).", Band(), "--band", unit="Hz", metavar="F_LO F_HI"
    )
    weights: str = knob(
        "auto",
        "Residual weights: auto = coherence if the FRF has it, else relative.",
        Choice(("auto", "relative", "coherence", "uniform")),
        "--weights",
    )
    criterion: str = knob(
        "bic", "Information criterion used for the ranking.", Choice(("bic", "aic")), "--criterion"
    )
    channel: tuple[int, int] | None = knob(
        None,
        "Output and input of the FRF to fit, counted from 1 like every other option "
        "(needed when the file holds more than one FRF).",
        Pair(1, "[output, input] counted from 1 (as --channel)"),
        "--channel",
        metavar="OUT IN",
    )


#: How the command line names what a campaign file calls channel and speed_kmh.
CAMPAIGN_LABELS = {
    "channel": "settings.lateral.fit.channel",
    "channel_form": "channel = [OUT, IN]",
    "speed": "speed_kmh",
    "speed_form": "give the test's speed_kmh",
}


class LateralFitStep:
    """Lateral FRF -> :class:`~tyredamp.lateral.fit.Ranking` of the fitted models."""

    name: ClassVar[str] = "fit"
    Settings: ClassVar[type[LateralFitSettings]] = LateralFitSettings
    #: in a campaign: the test's speed
    conditions: ClassVar[tuple[str, ...]] = ("speed_kmh",)

    @staticmethod
    def run(
        frf: FRF,
        settings: LateralFitSettings,
        *,
        speed_kmh: float | None = None,
        source: str = "",
        labels: Mapping[str, str] = CAMPAIGN_LABELS,
    ) -> tuple[tuple[Ranking, Any], dict[str, Any]]:
        """Fit and rank; returns ``(ranking, data)`` and ``{"fit": ranking}`` (its
        verdict: :meth:`~tyredamp.lateral.fit.Ranking.check`, which raises when no
        model fits). ``labels`` names the channel and the speed in messages."""
        from ...lateral.models import get_model_class

        s = settings
        ch = s.channel
        if ch is not None and (ch[0] > frf.n_out or ch[1] > frf.n_in):
            raise InputError(
                f"{labels['channel']}: expected an output 1..{frf.n_out} and an input "
                f"1..{frf.n_in} of {source}, got {ch[0]} {ch[1]}"
            )
        if ch is None and frf.n_out * frf.n_in != 1:
            raise InputError(
                f"{labels['channel']}: {source} holds {frf.n_out}x{frf.n_in} FRFs and a lateral "
                f"fit takes one; choose it with {labels['channel_form']} (counted from 1)"
            )
        data = lateral_data(
            frf,
            speed_kmh=speed_kmh,
            force=s.force,  # type: ignore[arg-type]
            wheel_mass=s.wheel_mass_kg,
        )
        from ...lateral import DEFAULT_MODELS

        names = list(s.models or DEFAULT_MODELS)
        if data.speed is None:
            need = [n for n in names if "speed" in get_model_class(n).condition_names]
            if need:
                raise InputError(
                    f"{labels['speed']}: the {', '.join(need)} model"
                    f"{'s' if len(need) > 1 else ''} need{'' if len(need) > 1 else 's'} the "
                    f"travel speed and {source} does not store it; {labels['speed_form']}"
                )
        ranking = fit_models(
            data,
            names,
            criterion=s.criterion,  # type: ignore[arg-type]
            band=s.band,
            weights=s.weights,
            channel=None if ch is None else (ch[0] - 1, ch[1] - 1),
        )
        ranking.check()  # no model fits: the reasons, as an error
        return (ranking, data), {"fit": ranking}

    @staticmethod
    def document(result: tuple[Ranking, Any], *, source: str = "", frf_kind: str) -> dict[str, Any]:
        """The lateral-fit document (:mod:`tyredamp.documents.lateral`)."""
        from ...documents.lateral import lateral_fit_document

        ranking, data = result
        return lateral_fit_document(ranking, data, source=source, frf_kind=frf_kind)


def lateral_data(
    frf: FRF,
    *,
    speed_kmh: float | None = None,
    force: ForceKind | None = None,
    wheel_mass: float | None = None,
) -> LateralData:
    """A lateral measurement from an FRF; conditions not given come from its ``meta``.

    Parameters
    ----------
    frf : FRF
        Lateral acceleration (or displacement, velocity) per lateral force.
    speed_kmh : float, optional
        Rolling speed, km/h (> 0).
    force : {"ground", "axle"}, optional
        Where the force acts.
    wheel_mass : float, optional
        Wheel mass, kg.
    """
    from ...lateral import LateralData
    from ...virtual.lateral_rig import KMH

    if speed_kmh is not None and not (math.isfinite(speed_kmh) and speed_kmh > 0):
        raise InputError(f"speed: expected a speed > 0 km/h, got {speed_kmh}")
    return LateralData.from_frf(
        frf,
        speed=None if speed_kmh is None else speed_kmh * KMH,
        force=force,
        wheel_mass=wheel_mass,
    )


def fit_models(
    data: LateralData,
    models: Sequence[str] | None = None,
    *,
    criterion: Criterion = "bic",
    band: tuple[float, float] | None = None,
    weights: Weights | ArrayLike = "auto",
    channel: tuple[int, int] | None = None,
) -> Ranking:
    """Fit every model to the same data and weights and rank them (AIC/BIC).

    ``models`` default: :data:`tyredamp.lateral.DEFAULT_MODELS`. See
    :func:`tyredamp.lateral.fit_model` for ``band``, ``weights`` and ``channel``.
    """
    from ...lateral import DEFAULT_MODELS, rank_models

    return rank_models(
        data,
        DEFAULT_MODELS if models is None else models,
        criterion=criterion,
        band=band,
        weights=weights,
        channel=channel,
    )
