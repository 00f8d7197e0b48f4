"""Rolling tests of a virtual campaign: speed x pressure on the rotating physical tyre.

Each test is :func:`tyredamp.virtual.rolling_test` (16 fixed sensors every
22.5 deg from the contact point, one sensor in the tyre, a random road force
over 0-200 Hz, 40 dB SNR) of the first tyre of the campaign (its manufacturing
scatter) at one pressure and speed, written as NPZ time data with the rolling
truth (:meth:`~tyredamp.virtual.RollingTruth.table`) beside it in the
campaign's ``truth.json``. A campaign processes them with the ``rolling``
study (:class:`~tyredamp.studies.steps.rolling.RollingStep`) and tracks every
family (``n=3 forward`` ...) against ``speed_kmh``.

The tyre
--------
The rolling tyre is the tyre of ``tyredamp simulate rolling``
(:func:`rolling_tyre`): the physical ring tyre of the radial tests
(:func:`~tyredamp.campaign.virtual.campaign_tyre`) with every piece the
rotating frame of the rolling rig (:class:`~tyredamp.virtual.RotatingRing`)
takes, and the others named in :data:`ROLLING_TYRE` (written to
``truth.json`` as ``rolling_tyre``):

* the ring's rubber losses (sidewall dashpots, the band's Kelvin-Voigt
  bending and membrane losses; physical damping, ``nonproportionality`` 1)
  spin with it: kept;
* the shaker tips are not on a rolling tyre: none;
* the air cavity: *not supported* by the rotating ring (its matrices are the
  ring's ``2 n_ring`` DOFs; the air's own motion in the spinning cavity is
  not modelled), so the rolling tests have no cavity resonance and no
  ring-cavity coupling;
* the contact patch: the road force acts at a point fixed in space
  (:class:`~tyredamp.virtual.PointContact` at 0 deg); the patch's tread
  springs are fixed in space and are *not supported* in the rotating frame,
  so the load is not an axis of the rolling tests (left out, not faked).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..virtual import MeasurementLayout, RingTyre, RingTyreParameters

__all__ = ["ROLLING_SPEEDS_KMH", "ROLLING_TYRE", "rolling_tyre", "write_rolling_tests"]

#: Speeds of ``tyredamp simulate campaign --rolling`` (km/h).
ROLLING_SPEEDS_KMH = (0.0, 40.0, 80.0, 120.0)

#: What the rolling tests' tyre is (``rolling_tyre`` of ``truth.json``; module docstring).
ROLLING_TYRE: dict[str, str] = {
    "model": "rotating ring tyre (tyredamp.virtual.RotatingRing: Coriolis, centrifugal "
    "tension and softening), the tyre of 'tyredamp simulate rolling'",
    "rubber_losses": "included (sidewall dashpots, band bending and membrane losses)",
    "shaker_tips": "none (no shaker on a rolling tyre)",
    "cavity": "not supported by the rotating ring of the rolling rig: no cavity "
    "resonance and no ring-cavity coupling in the rolling tests",
    "contact": "random road force at a point fixed in space at 0 deg; the contact patch's "
    "tread springs are not supported in the rotating frame, so the load is no axis",
}


def rolling_tyre(params: RingTyreParameters, pressure_bar: float) -> RingTyre:
    """The physical virtual tyre of one rolling test: the tyre of ``tyredamp simulate rolling``.

    The ring tyre ``params`` at ``pressure_bar`` (bar) with its rubber losses
    and physical damping (``nonproportionality`` 1), no shaker tips, no air
    cavity and no contact patch (neither is supported by the rotating frame
    of :class:`~tyredamp.virtual.RotatingRing`; see :data:`ROLLING_TYRE`).
    """
    layout = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)
    return RingTyre(params.with_pressure(pressure_bar * 1e5), layout, nonproportionality=1.0)


def write_rolling_tests(
    data_dir: Path,
    params: RingTyreParameters,
    speeds_kmh: tuple[float, ...],
    pressures_bar: tuple[float, ...],
    seed: int,
    duration: float = 16.0,
    progress: Callable[[], None] | None = None,
) -> list[dict[str, Any]]:
    """Write the rolling tests into ``data_dir``; their campaign entries with the truth.

    Parameters
    ----------
    data_dir : Path
        The campaign's data folder (exists).
    params : RingTyreParameters
        The tyre (its pressure is replaced by each of ``pressures_bar``).
    speeds_kmh, pressures_bar : tuple of float
        The grid, km/h and bar.
    seed : int
        Campaign seed; each test gets its own stream.
    duration : float
        Seconds per record.
    progress : callable, optional
        Called after each test.

    Returns
    -------
    list of dict
        ``file``, ``study`` (``"rolling"``), ``tyre``, ``pressure_bar``,
        ``speed_kmh`` and ``rolling_truth`` per test.
    """
    from ..io import write_timedata
    from ..virtual import rolling_test

    out = []
    for p in pressures_bar:
        tyre = rolling_tyre(params, p)
        for k, v in enumerate(speeds_kmh):
            name = f"rolling_{p:g}bar_{v:g}kmh.npz"
            test = rolling_test(
                v,
                tyre=tyre,
                duration=duration,
                sample_rate=512.0,
                band=(0.0, 200.0),
                seed=np.random.default_rng([seed, 4242, k, round(10 * p)]),
            )
            write_timedata(test.data, data_dir / name)
            out.append(
                {
                    "file": f"data/{name}",
                    "study": "rolling",
                    "tyre": "T1",
                    "pressure_bar": p,
                    "speed_kmh": v,
                    "rolling_truth": test.truth.table(),
                }
            )
            if progress is not None:
                progress()
    return out
