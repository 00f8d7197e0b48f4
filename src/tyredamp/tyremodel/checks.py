"""Checks of what goes into a tyre model: modes, pressures, ring, lateral tests.

Each refuses in one line (:class:`~tyredamp.exceptions.InputError`) what
would otherwise give a tyre model that looks identified but is not:

* :func:`check_modes` -- unstable poles or negative damping (a pole in the
  right half plane is not a mode of a passive tyre; its damper would be
  written negative), the same modes given twice, the same pressure twice;
* :func:`check_ring` -- a ring fit whose tension does not follow the
  pressure (``T0 = p R b + T_c`` with the belt width ``b`` not clearly
  positive, e.g. the same modes given at several pressures);
* :func:`check_rigid` -- rigid-ring values a simulation cannot take: a
  damping ratio at or below zero once the attachment damper is removed (the
  given damper is larger than the measured losses);
* :func:`check_lateral` -- lateral tests at a pressure other than the radial
  tests' (their relaxation length and stiffness do not belong to the same
  ``.tir`` file).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..exceptions import InputError
from ..modal.model import ModalModel
from .lateral import LateralCarcass
from .rigid import RigidRingParameters
from .ring import RingFit

__all__ = ["check_lateral", "check_modes", "check_rigid", "check_ring"]

_BAR = 1e5
#: Relative pressure difference above which two tests are not "at the same pressure".
PRESSURE_TOLERANCE = 0.1


def check_modes(items: Sequence[tuple[float, ModalModel, str]]) -> None:
    """Refuse unstable or undamped modes, repeated modes files and repeated pressures.

    Parameters
    ----------
    items : sequence of (pressure in Pa, ModalModel, source)

    Raises
    ------
    InputError
        As the module docstring says.
    """
    for _, mdl, src in items:
        z = np.asarray(mdl.damping_ratio, dtype=float)
        f = np.asarray(mdl.frequency_hz, dtype=float)
        bad = np.flatnonzero(~(np.isfinite(z) & np.isfinite(f)) | (z <= 0) | (f <= 0))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{src}: mode {k + 1} at {f[k]:.4g} Hz has damping ratio {z[k] + 0.0:.3g} (an "
                "unstable or undamped pole); a passive tyre's modes are damped: re-identify "
                "the modes (a tyre model from them would have negative dampers)"
            )
    for i, (p_i, m_i, s_i) in enumerate(items):
        for p_j, m_j, s_j in items[:i]:
            if m_i.poles.shape == m_j.poles.shape and np.allclose(
                m_i.poles, m_j.poles, rtol=1e-9, atol=0.0
            ):
                raise InputError(
                    f"{s_i}: the same modes as {s_j}; one modes file per test pressure "
                    "(the same modes at two pressures cannot show the pressure's effect)"
                )
            if abs(p_i - p_j) <= 1e-3 * max(p_i, p_j):
                raise InputError(
                    f"{s_i}: the same pressure ({p_i / _BAR:g} bar) as {s_j}; give one modes "
                    "file per pressure (combine repeated tests in the modal identification)"
                )


def check_ring(ring: RingFit) -> None:
    """Refuse a multi-pressure ring whose tension does not rise with the pressure.

    ``T0 = p R b + T_c`` (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed., eq.
    12.8 for the inflated ring's tension): the effective belt width ``b``
    must be positive and distinguishable from zero (more than two standard
    errors), else the modes did not change with the pressure as an inflated
    ring's do.

    Raises
    ------
    InputError
    """
    if not ring.multi_pressure or "b" not in ring.names:
        return
    b, sb = ring.param("b")
    if not (math.isfinite(b) and b > 1e-3 and (not math.isfinite(sb) or b > 2 * sb)):
        raise InputError(
            f"modes files: the frequencies do not change with the pressure as an inflated "
            f"ring's do (belt width b = {b:.3g} +- {sb:.2g} m from the tension p R b); check "
            "that the files are tests at the pressures given"
        )


def check_rigid(rigid: Sequence[RigidRingParameters], sources: Sequence[str]) -> None:
    """Refuse rigid-ring values that are not a passive, massive belt (module docstring).

    Raises
    ------
    InputError
        ``DAMP_LONG <= 0`` (naming the attachment damping), ``BELT_MASS`` or
        ``FREQ_LONG`` not positive and finite.
    """
    for r, src in zip(rigid, sources, strict=True):
        if not (math.isfinite(r.belt_mass) and r.belt_mass > 0):
            raise InputError(
                f"{src}: belt mass {r.belt_mass:.3g} kg from the n = 1 mode; expected > 0"
            )
        if not (math.isfinite(r.freq_long) and r.freq_long > 0):
            raise InputError(f"{src}: n = 1 frequency {r.freq_long:.3g} Hz; expected > 0")
        if not (math.isfinite(r.damp_long) and r.damp_long > 0):
            raise InputError(
                f"{src}: the n = 1 damping ratio is {r.damp_long:.3g} once the attachment "
                "damping is removed: the given --attachment-damping exceeds the measured "
                "losses (a .tir with a negative damper would be unstable)"
            )


def check_lateral(
    lateral: Sequence[LateralCarcass], pressures: Sequence[float], force: bool
) -> list[str]:
    """Refuse (unless ``force``) lateral tests at a pressure none of the radial tests had.

    Parameters
    ----------
    lateral : sequence of LateralCarcass
    pressures : sequence of float
        The radial tests' pressures in Pa.
    force : bool
        Keep such lateral quantities, with a warning.

    Returns
    -------
    list of str
        Warnings (an unknown lateral pressure; a mismatch kept with ``force``).

    Raises
    ------
    InputError
        A lateral test's pressure differs by more than 10 % from every radial test's.
    """
    warnings = []
    for c in lateral:
        if c.pressure_bar is None:
            warnings.append(
                f"{c.source or 'lateral fit'}: pressure not recorded; its relaxation length "
                "and stiffness may belong to another pressure (give --lateral-pressure)"
            )
            continue
        p = c.pressure_bar * _BAR
        near = min(abs(p - q) / q for q in pressures)
        if near <= PRESSURE_TOLERANCE:
            continue
        radial = ", ".join(f"{q / _BAR:g}" for q in pressures)
        msg = (
            f"{c.source or 'lateral fit'}: lateral test at {c.pressure_bar:g} bar, radial tests "
            f"at {radial} bar; a tyre model mixes them only with --force"
        )
        if not force:
            raise InputError(msg)
        warnings.append(msg.replace("only with --force", "(kept: --force)"))
    return warnings
