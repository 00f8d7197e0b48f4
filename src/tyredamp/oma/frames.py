"""The change of frame of a rolling tyre's waves: fixed-frame poles to the tyre's frame.

A wave ``e^{i(omega t + k theta)}`` on the tyre (material angle ``theta``)
seen at the fixed angle ``phi = theta + Omega t`` (the change of frame of
Huang & Soedel, J. Sound Vib. 115(2) (1987) 253-274; derived in
:mod:`tyredamp.oma.rolling` and :mod:`tyredamp.virtual.rolling_truth`, whose
exact ring modes the tests check it against) has::

    f_fixed = f_rot + s n f_w          (1)

with ``s = +1`` for a wave that a fixed observer sees travel with the
rotation, ``n = |k|`` and ``f_w = Omega / 2 pi``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rotating_frequency", "rotating_pole"]


def rotating_frequency(
    fixed_hz: float, wave_number: int, fixed_direction: str, wheel_speed_hz: float
) -> tuple[float, str]:
    """Rotating-frame frequency and direction on the tyre of a fixed-frame wave.

    Eq. (1) of this module, ``f_rot = f_fixed - s n f_w`` (the Doppler relation
    between the frames of a rotating ring, from the frame change of Huang &
    Soedel 1987; derived in the module docstring).

    Parameters
    ----------
    fixed_hz : float
        Frequency at a fixed point, Hz.
    wave_number : int
        ``n >= 0``.
    fixed_direction : {"forward", "backward", "standing"}
        Direction of travel seen from a fixed point (``"forward"``: with the rotation).
    wheel_speed_hz : float
        Wheel rotation frequency ``f_w`` in Hz.

    Returns
    -------
    f_rot : float
        Hz (``>= 0``).
    direction : str
        On the tyre: ``"forward"``, ``"backward"`` or ``"standing"`` (``n = 0``
        or a standing fixed-frame wave, for which ``f_fixed`` is returned).
    """
    if wave_number == 0 or fixed_direction == "standing":
        return float(fixed_hz), "standing"
    s = 1.0 if fixed_direction == "forward" else -1.0
    f = float(fixed_hz) - s * wave_number * float(wheel_speed_hz)
    if f >= 0:
        return f, fixed_direction
    return -f, "backward" if fixed_direction == "forward" else "forward"


def rotating_pole(
    fixed_hz: float,
    damping_ratio: float,
    wave_number: int,
    fixed_direction: str,
    wheel_speed_hz: float,
) -> tuple[float, float, str]:
    """Rotating-frame natural frequency and damping ratio of an identified fixed-frame pole.

    An identified pole ``lambda = -sigma + i omega_d`` has the natural frequency
    ``|lambda| / 2 pi`` and the damping ratio ``sigma / |lambda|``. Eq. (1) of
    this module moves its *damped* frequency ``omega_d`` by ``-s n Omega`` and
    keeps its decay rate ``sigma`` (the change of frame multiplies the wave by
    ``e^{-i s n Omega t}``, Huang & Soedel 1987; :mod:`tyredamp.virtual.rolling_truth`).
    Applying eq. (1) to the natural frequency instead is off by about
    ``zeta^2 / 2`` relatively, which grows where the fixed frequency is low.

    Parameters
    ----------
    fixed_hz : float
        Natural frequency ``|lambda| / 2 pi`` at a fixed point, Hz.
    damping_ratio : float
        ``sigma / |lambda|`` at a fixed point (0 <= zeta < 1).
    wave_number, fixed_direction, wheel_speed_hz
        As in :func:`rotating_frequency`.

    Returns
    -------
    f_rot : float
        ``|lambda_rot| / 2 pi`` in Hz.
    zeta_rot : float
        ``sigma / |lambda_rot|``.
    direction : str
        On the tyre.
    """
    z = float(np.clip(damping_ratio, 0.0, 1.0))
    sigma = z * float(fixed_hz)  # in Hz units: sigma / 2 pi
    fd = float(fixed_hz) * np.sqrt(1.0 - z * z)
    fr, d = rotating_frequency(fd, wave_number, fixed_direction, wheel_speed_hz)
    mag = float(np.hypot(fr, sigma))
    return mag, (sigma / mag if mag > 0 else z), d
