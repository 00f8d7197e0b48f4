"""Time windows for FRF estimation: general windows and the impact-test pair.

For random excitation a Hann window on every channel (:func:`segment_window`)
limits leakage. Impact tests use the *force window* on the force channel (keeps
the pulse, removes the noise after it) and the *exponential window* on all
channels (forces the response to decay inside the record). The exponential
window ``w(t) = exp(-t / tau)`` adds ``1 / tau`` (1/s) to the decay rate
``sigma_n = -Re p_n`` of every mode (spec eq. [3]); the estimators record
``tau`` in ``FRF.meta["exponential_tau_s"]`` so that identified damping can be
corrected by ``sigma_true = sigma_identified - 1 / tau``.
"""

from __future__ import annotations

import numpy as np
import scipy.signal
from numpy.typing import NDArray

from .._validate import check_positive
from ..exceptions import InputError

__all__ = ["exponential_window", "force_window", "segment_window"]


def _check_n(n: int, name: str = "n_samples") -> int:
    if int(n) != n or n < 2:
        raise InputError(f"{name}: expected an integer >= 2, got {n!r}")
    return int(n)


def segment_window(window: str | tuple[str, float], n_samples: int) -> NDArray[np.float64]:
    """A periodic (DFT-even) window of ``n_samples`` from :func:`scipy.signal.get_window`.

    Parameters
    ----------
    window : str or tuple
        Any window name scipy knows (``"hann"``, ``"boxcar"``, ``"flattop"``,
        ``("tukey", 0.25)`` ...). ``"rect"`` and ``"rectangular"`` mean
        ``"boxcar"``.
    n_samples : int
        Segment length in samples.

    Returns
    -------
    ndarray, shape (n_samples,)
    """
    n = _check_n(n_samples, "segment_samples")
    if isinstance(window, str) and window.lower() in ("rect", "rectangular", "none"):
        window = "boxcar"
    try:
        w = scipy.signal.get_window(window, n, fftbins=True)
    except (ValueError, TypeError) as exc:
        raise InputError(
            f"window: expected a scipy.signal window name, got {window!r} ({exc})"
        ) from None
    return np.asarray(w, dtype=float)


def force_window(
    n_samples: int, width_samples: int, taper_samples: int = 0, start_samples: int = 0
) -> NDArray[np.float64]:
    """Force (transient) window for the force channel of an impact test.

    Equal to 1 from ``start_samples`` for ``width_samples`` samples, then a
    half-cosine taper of ``taper_samples`` down to 0, and 0 elsewhere.

    Parameters
    ----------
    n_samples : int
        Record length in samples.
    width_samples : int
        Samples kept at full weight (should cover the force pulse), >= 1.
    taper_samples : int
        Length of the cosine taper after the flat part (0: hard cut).
    start_samples : int
        First sample of the flat part (pre-trigger samples before it are 0).

    Returns
    -------
    ndarray, shape (n_samples,)
    """
    n = _check_n(n_samples)
    for v, name in (
        (width_samples, "width_samples"),
        (taper_samples, "taper_samples"),
        (start_samples, "start_samples"),
    ):
        if int(v) != v or v < 0:
            raise InputError(f"{name}: expected a non-negative integer, got {v!r}")
    if width_samples < 1 or start_samples + width_samples > n:
        raise InputError(
            f"width_samples: expected 1..{n - start_samples} (inside the record of {n} "
            f"samples from start {start_samples}), got {width_samples}"
        )
    w = np.zeros(n)
    stop = start_samples + width_samples
    w[start_samples:stop] = 1.0
    nt = min(int(taper_samples), n - stop)
    if nt > 0:
        w[stop : stop + nt] = 0.5 * (1 + np.cos(np.pi * (np.arange(1, nt + 1) / (nt + 1))))
    return w


def exponential_window(
    n_samples: int, sample_rate: float, end_value: float = 0.01
) -> tuple[NDArray[np.float64], float]:
    """Exponential window ``exp(-t / tau)`` falling to ``end_value`` at the record end.

    Parameters
    ----------
    n_samples : int
        Record length in samples.
    sample_rate : float
        Samples per second (Hz).
    end_value : float
        Window value at the last sample, in (0, 1].

    Returns
    -------
    window : ndarray, shape (n_samples,)
    tau : float
        Time constant in s (``inf`` when ``end_value`` is 1). The window adds
        ``1 / tau`` to every modal decay rate ``sigma_n`` (1/s).
    """
    n = _check_n(n_samples)
    fs = check_positive(sample_rate, "sample_rate")
    e = float(end_value)
    if not (0.0 < e <= 1.0):
        raise InputError(f"end_value: expected a value in (0, 1], got {end_value!r}")
    t = np.arange(n) / fs
    if e == 1.0:
        return np.ones(n), float("inf")
    tau = -t[-1] / np.log(e)
    return np.exp(-t / tau), float(tau)
