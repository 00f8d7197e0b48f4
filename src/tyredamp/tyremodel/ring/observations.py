"""Identified modes as the flexible-ring fit uses them: one :class:`RingObservation` per mode."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..._validate import check_positive
from ...exceptions import InputError
from ...modal.model import ModalModel
from ..wavenumber import WaveNumberAnalysis, wave_number_analysis
from .model import BAR

__all__ = ["RingObservation", "gather_observations", "ring_observations"]


@dataclass(frozen=True)
class RingObservation:
    """One identified mode as the ring fit uses it.

    Attributes
    ----------
    pressure : float
        Inflation pressure in Pa.
    n : int
        Wave number (from :func:`~tyredamp.tyremodel.wave_number_analysis`).
    member : str
        ``"cos"``, ``"sin"`` or ``"single"``.
    frequency_hz, frequency_std : float, float or None
        Natural frequency and its standard error (Hz).
    damping_ratio, damping_std : float, float or None
    amplitude, amplitude_std : float, float or None
        Mass-normalised radial amplitude ``A`` (1/sqrt(kg)) and standard error.
    use_amplitude : bool
        False where the amplitude is not the ring amplitude (the Nyquist wave
        number, whose sampled amplitude depends on the orientation).
    drive_phi2 : float
        ``sum over drive points of |phi_d|^2`` (1/kg) of the mass-normalised shape.
    mode_index : int
        Index in its :class:`ModalModel`.
    """

    pressure: float
    n: int
    member: str
    frequency_hz: float
    frequency_std: float | None
    damping_ratio: float
    damping_std: float | None
    amplitude: float
    amplitude_std: float | None
    use_amplitude: bool
    drive_phi2: float
    mode_index: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (pressure also in bar)."""
        return {
            "pressure_pa": self.pressure,
            "pressure_bar": self.pressure / BAR,
            "n": self.n,
            "member": self.member,
            "frequency_hz": self.frequency_hz,
            "frequency_std": self.frequency_std,
            "damping_ratio": self.damping_ratio,
            "damping_std": self.damping_std,
            "amplitude": self.amplitude,
            "amplitude_std": self.amplitude_std,
            "use_amplitude": self.use_amplitude,
            "drive_phi2": self.drive_phi2,
            "mode_index": self.mode_index,
        }


def ring_observations(
    model: ModalModel,
    pressure: float,
    *,
    analysis: WaveNumberAnalysis | None = None,
    angles_deg: ArrayLike | None = None,
) -> tuple[list[RingObservation], list[str]]:
    """The modes of ``model`` that the flexural ring model describes, with their labels.

    Modes flagged as aliased or not a single harmonic and ``n = 0`` modes
    (the ring's rotation has no radial motion; a radial ``n = 0`` mode is
    the extensional breathing mode, outside the inextensible model) are left
    out, each with a reason.

    Parameters
    ----------
    model : ModalModel
        Identified modes (radial outputs with angles, drive-point scaling).
    pressure : float
        Inflation pressure of the test in Pa (>= 0).
    analysis : WaveNumberAnalysis, optional
        Precomputed labels (default :func:`wave_number_analysis`).
    angles_deg : array_like, optional
        Output angles when the channels carry none.

    Returns
    -------
    observations : list of RingObservation
    skipped : list of str
        One sentence per mode left out.
    """
    p = check_positive(pressure, "pressure", allow_zero=True)
    wa = analysis if analysis is not None else wave_number_analysis(model, angles_deg=angles_deg)
    if len(wa.modes) != model.n_modes:
        raise InputError("analysis: expected the wave-number analysis of this model")
    sf = model.std.get("frequency_hz")
    sz = model.std.get("damping_ratio")
    omega = model.poles.imag
    phi_d2 = np.sum(np.abs(model.psi_in) ** 2, axis=0) * 2.0 * omega
    nyq = wa.n_resolved + 1
    obs: list[RingObservation] = []
    skipped: list[str] = []
    for m in wa.modes:
        where = f"{p / BAR:g} bar, mode {m.index + 1} ({m.frequency_hz:.2f} Hz)"
        if m.aliased:
            skipped.append(f"{where}: flagged as spatially aliased")
            continue
        if not m.single_harmonic:
            skipped.append(f"{where}: shape is not a single harmonic ({m.fraction:.2f})")
            continue
        if m.n == 0:
            skipped.append(f"{where}: n = 0 is outside the inextensible flexural ring model")
            continue
        k = m.index
        obs.append(
            RingObservation(
                pressure=p,
                n=m.n,
                member=m.member,
                frequency_hz=m.frequency_hz,
                frequency_std=None if sf is None else float(sf[k]),
                damping_ratio=m.damping_ratio,
                damping_std=None if sz is None else float(sz[k]),
                amplitude=m.amplitude,
                amplitude_std=m.amplitude_std,
                use_amplitude=m.n < nyq,
                drive_phi2=float(phi_d2[k]),
                mode_index=k,
            )
        )
    return obs, skipped


def gather_observations(
    data: Sequence[tuple[float, ModalModel]] | Sequence[RingObservation],
) -> tuple[list[RingObservation], list[str]]:
    """The observations of :func:`~tyredamp.tyremodel.fit_ring`'s ``data``, checked.

    Parameters
    ----------
    data : sequence of (pressure, ModalModel) or of RingObservation
        Identified modes with the test pressure in Pa (labelled with
        :func:`ring_observations`), or ready observations.

    Returns
    -------
    observations : list of RingObservation
        At least one; finite, ``n >= 1``, frequency > 0, pressure >= 0,
        ``drive_phi2 >= 0``.
    skipped : list of str
        The modes left out and why.

    Raises
    ------
    InputError
        Empty ``data``, an entry of the wrong type, no usable mode, or an
        observation with impossible values.
    """
    items: list[Any] = list(data)
    if not items:
        raise InputError("data: expected at least one (pressure, ModalModel)")
    obs: list[RingObservation] = []
    skipped: list[str] = []
    for i, it in enumerate(items):
        if isinstance(it, RingObservation):
            obs.append(it)
            continue
        try:
            pr, mdl = it
        except (TypeError, ValueError):
            raise InputError(
                f"data[{i}]: expected (pressure, ModalModel) or RingObservation"
            ) from None
        if not isinstance(mdl, ModalModel):
            raise InputError(f"data[{i}]: expected a ModalModel, got {type(mdl).__name__}")
        o, s = ring_observations(mdl, float(pr))
        obs += o
        skipped += s
    if not obs:
        raise InputError(
            "no mode of the modes file(s) is usable by the ring model: each needs a resolved "
            "wave number (see the wave-number analysis)"
        )
    for i, ob in enumerate(obs):
        vals = (ob.pressure, ob.frequency_hz, ob.amplitude, ob.damping_ratio, ob.drive_phi2)
        if not all(math.isfinite(v) for v in vals):
            raise InputError(f"observations[{i}]: expected finite values, got {ob}")
        if ob.frequency_hz <= 0 or ob.n < 1 or ob.pressure < 0 or ob.drive_phi2 < 0:
            raise InputError(
                f"observations[{i}]: expected n >= 1, frequency > 0, pressure >= 0 and "
                f"drive_phi2 >= 0, got n = {ob.n}, f = {ob.frequency_hz}, p = {ob.pressure}"
            )
    return obs, skipped
