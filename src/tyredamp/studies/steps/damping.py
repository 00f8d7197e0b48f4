"""The ``damping`` step: the damping matrix from identified modes (``tyredamp damping``)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...exceptions import InputError
from ._settings import Band, Boolean, Check, Choice, Integer, StepSettings, knob

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ...damping import DampingModel, Method
    from ...modal.model import ModalModel

#: The estimators of :data:`tyredamp.damping.METHODS` (named here so that the settings
#: load without the numerical packages; a test keeps the two equal).
DAMPING_METHODS: tuple[str, ...] = ("first", "improved", "refined")

__all__ = ["DampingSettings", "DampingStep", "ModeNumbers", "damping_from_modes"]


#: Most Monte Carlo samples of the damping step (standard errors to about 0.7 %).
MAX_SAMPLES = 10_000
#: Highest mode number a selection may name (no fit holds more modes).
MAX_MODE_NUMBER = 1000


@dataclass(frozen=True)
class ModeNumbers(Check):
    """Mode numbers counted from 1: text such as ``"1,2,5-7"`` or a list of integers."""

    def __call__(self, value: Any, where: str) -> Any:
        from ...damping.modeset import parse_mode_numbers

        if value is None:
            return None
        if isinstance(value, list | tuple) and all(
            isinstance(v, int) and not isinstance(v, bool) for v in value
        ):
            value = ",".join(str(v) for v in value)
        if not isinstance(value, str):
            raise InputError(f"{where}: expected mode numbers such as 1,2,5-7, got {value!r}")
        if any(int(n) > MAX_MODE_NUMBER for n in re.findall(r"\d+", value[:10000])) or (
            len(value) > 10000
        ):
            raise InputError(
                f"{where}: expected mode numbers from 1 to {MAX_MODE_NUMBER}, got {value[:80]!r}"
            )
        try:
            return tuple(parse_mode_numbers(value))
        except InputError as exc:
            raise InputError(f"{where}:{str(exc).split(':', 1)[1]}") from None

    def schema(self) -> dict[str, Any]:
        return {
            "type": ["array", "string"],
            "items": {"type": "integer", "minimum": 1},
            "minItems": 1,
            "description": "mode numbers counted from 1, or text such as '1,2,5-7'",
        }


@dataclass(frozen=True)
class DampingSettings(StepSettings):
    """How the damping matrix is identified (``tyredamp damping``; a campaign's
    ``[settings.radial.damping]``)."""

    section: ClassVar[str] = "damping"

    method: str = knob(
        "improved",
        "first: eq. [16]; improved: eq. [18]; refined: bias-corrected (exact for "
        "consistent modes).",
        Choice(DAMPING_METHODS),
        "--method",
    )
    model: str = knob(
        "complex",
        "Which model of the modes file to use (complex modes carry the coupling).",
        Choice(("complex", "real")),
        "--model",
    )
    samples: int = knob(
        200,
        "Monte Carlo samples for the standard errors (0 to skip; at most 10000: the "
        "standard error of a standard error from N samples is about 1/sqrt(2N), 0.7 % at "
        "10000).",
        Integer(0, optional=False, maximum=MAX_SAMPLES),
        "--samples",
    )
    seed: int = knob(0, "Monte Carlo seed.", Integer(0, optional=False), "--seed")
    modes: tuple[int, ...] | None = knob(
        None,
        "Modes to use, numbered from 1 in order of frequency: e.g. 1,2,5-7 (default all).",
        ModeNumbers(),
        "--modes",
        metavar="LIST",
    )
    band: tuple[float, float] | None = knob(
        None,
        "Use only the modes with natural frequency in F1..F2 Hz.",
        Band(),
        "--band",
        unit="Hz",
        metavar="F1 F2",
    )
    normalise: bool = knob(
        True,
        "Skip the alpha_n^(n) = 1 phase normalisation of the complex shapes.",
        Boolean(),
        "--no-normalise",
    )


class DampingStep:
    """Identified modes -> :class:`~tyredamp.damping.DampingModel` (findings inside)."""

    name: ClassVar[str] = "damping"
    Settings: ClassVar[type[DampingSettings]] = DampingSettings
    #: the campaign key that switches the step off (the CLI runs it or not)
    switch: ClassVar[str] = "enabled"

    @staticmethod
    def run(
        models: dict[str, ModalModel],
        settings: DampingSettings,
        meta: dict[str, Any] | None = None,
    ) -> tuple[DampingModel, dict[str, Any]]:
        """The damping matrix of ``models[settings.model]``; no verdicts of its own
        (its findings are in the result)."""
        s = settings
        dm = damping_from_modes(
            models,
            model=s.model,
            method=s.method,  # type: ignore[arg-type]
            normalise=s.normalise,
            n_samples=s.samples,
            seed=s.seed,
            meta=meta,
            modes=None if s.modes is None else list(s.modes),
            band=s.band,
        )
        return dm, {}

    @staticmethod
    def document(result: DampingModel) -> dict[str, Any]:
        """The damping document (``docs/damping-json.md``)."""
        from ...documents.damping import damping_document

        return damping_document(result)


def damping_from_modes(
    models: dict[str, ModalModel],
    *,
    model: str = "complex",
    method: Method = "improved",
    normalise: bool = True,
    n_samples: int = 200,
    seed: int = 0,
    meta: dict[str, Any] | None = None,
    modes: Sequence[int] | None = None,
    band: tuple[float, float] | None = None,
) -> DampingModel:
    """The damping matrix in modal and physical coordinates (eq. [14]-[18]).

    The shapes are taken where they are (:func:`tyredamp.damping.modeset.at_shape_points`:
    at the inputs of a roving-hammer test), the modes chosen by ``modes`` and
    ``band`` (:func:`~tyredamp.damping.modeset.select_modes`), and unscaled
    modes are refused (:func:`~tyredamp.damping.modeset.scaling_problem`):
    without mass-normalised shapes the damping, mass and stiffness matrices
    have no meaning. ``meta`` of the result records ``modes_used`` (1-based
    numbers in the file), ``n_modes_available``, ``shape_points``
    (``"outputs"`` or ``"inputs"``) and ``scaling``.

    Parameters
    ----------
    models : dict of str to ModalModel
        Identified models by name (``"complex"``, ``"real"``).
    model : str
        Which of them to use.
    method, normalise, n_samples, seed, meta
        See :func:`tyredamp.damping.identify_damping`.
    modes : sequence of int, optional
        Mode numbers to use (1-based, in order of frequency); default all.
    band : (float, float), optional
        Natural frequency range of the modes to use, Hz.

    Raises
    ------
    InputError
        Unknown model, mode numbers or band that choose nothing, unscaled modes.
    ShapeError
        More modes than shape points (the message says how many the points allow).
    """
    from ...damping import identify_damping
    from ...damping.modeset import (
        at_shape_points,
        check_point_count,
        negative_mass_modes,
        scaling_problem,
        select_modes,
    )

    if model not in models:
        raise InputError(
            f"model (--model): the modes file holds the {' and '.join(sorted(models))} model(s), "
            f"not {model!r}"
        )
    full = at_shape_points(models[model])
    why = scaling_problem(full)
    if why:
        src = (meta or {}).get("source") or "the modes"
        raise InputError(
            f"{src}: the mode shapes are unscaled ({why}); a damping matrix from them would be "
            "meaningless. Scale them with a drive-point FRF (an input at the node and direction "
            "of a response) in the modal fit, or give the modal A (complex modes) or modal mass "
            "(real modes) with the shapes"
        )
    chosen, numbers = select_modes(full, modes, band)
    left_out = ""
    bad, point = negative_mass_modes(chosen)
    if bad and modes is None and band is None:
        # nobody chose these modes: leave out those whose shapes cannot be scaled
        keep = [k for k, f in enumerate(chosen.frequency_hz) if float(f) not in bad]
        if keep:
            chosen, numbers = select_modes(full, [numbers[k] for k in keep])
            left_out = (
                f"The mode(s) at {', '.join(f'{f:.4g}' for f in bad)} Hz were left out: the "
                f"drive point {point} gives them a negative modal mass, so their shapes cannot "
                "be mass-normalised (the response is not at the drive point for them, or they "
                "are not physical). Choose modes with --modes to change this."
            )
    check_point_count(chosen, full.n_modes if chosen.n_modes == full.n_modes else None)
    why = scaling_problem(chosen, per_mode=True)
    if why:
        src = (meta or {}).get("source") or "the modes"
        raise InputError(
            f"{src}: {why}; a damping matrix from them would be meaningless. Choose other "
            "modes with --modes or --band, or measure a drive-point FRF (the response at the "
            "excitation point, in its direction)"
        )
    info = dict(meta or {})
    info["modes_used"] = numbers
    info["n_modes_available"] = full.n_modes
    info["shape_points"] = str(full.meta.get("shapes_from", "outputs"))
    info["scaling"] = "mass-normalised"
    dm = identify_damping(
        chosen, method, normalise=normalise, n_samples=n_samples, seed=seed, meta=info
    )
    from dataclasses import replace

    if left_out:
        dm = replace(dm, findings=(left_out, *dm.findings))
    if info["shape_points"] == "inputs" and dm.std and "psi_out" not in chosen.std:
        note = (
            "The shapes at the excitation points carry no standard errors (the fit gives them "
            "at the responses only): the standard errors of C' and C cover the uncertainty of "
            "the poles, not of the shapes, and understate the spread."
        )
        dm = replace(dm, findings=(*dm.findings, note))
    return dm
