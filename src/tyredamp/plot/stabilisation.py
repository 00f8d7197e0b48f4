"""Stabilisation diagram of the pole estimation (:mod:`tyredamp.modal.poles.lscf`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ..frf import FRF
from ._axes import single_axes

__all__ = ["plot_stabilisation"]

#: Marker style of each pole class, drawn in this order.
_CLASSES: tuple[tuple[str, dict[str, Any]], ...] = (
    ("new or unstable", {"marker": ".", "color": "0.6", "s": 6}),
    ("stable frequency", {"marker": "x", "color": "C1", "s": 12, "linewidths": 0.8}),
    ("stable frequency and damping", {"marker": "d", "color": "C2", "s": 12}),
    ("stable (frequency, damping, vector)", {"marker": "o", "color": "C0", "s": 14}),
)


def plot_stabilisation(
    poles: Any,
    flags: Any,
    frf: FRF | None = None,
    selected_hz: Sequence[float] | ArrayLike | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Stabilisation diagram: pole frequencies against model order.

    Each admissible pole (``flags.admissible``: positive damping below the
    limit, inside the band) is drawn at its natural frequency and model order,
    with a marker by its stability against the previous order: grey dot (new
    or unstable), orange cross (stable in frequency), green diamond (stable in
    frequency and damping), blue circle (also stable in participation
    vector; with one input the vector test is always passed). The summed
    amplitude ``sqrt(sum_jk |H_jk|^2)`` of ``frf`` is drawn in dB on a second
    axis, and the frequencies of the selected modes as vertical lines.

    Parameters
    ----------
    poles : PoleSet
        :class:`tyredamp.modal.poles.lscf.PoleSet` (``order``, ``frequency_hz``).
    flags : StabilityFlags
        :class:`tyredamp.modal.poles.selection.StabilityFlags` of the same poles.
    frf : FRF, optional
        The FRFs the poles were estimated from.
    selected_hz : array_like, optional
        Natural frequencies (Hz) of the modes finally kept.
    ax : Axes, optional
        Axes to draw on; a new figure otherwise.

    Returns
    -------
    Axes
        The diagram's axes (the FRF axis is its twin).
    """
    order = np.asarray(poles.order)
    fn = np.asarray(poles.frequency_hz, dtype=float)
    adm = np.asarray(flags.admissible, dtype=bool)
    f_ok = np.asarray(flags.frequency, dtype=bool)
    z_ok = np.asarray(flags.damping, dtype=bool)
    v_ok = np.asarray(flags.vector, dtype=bool)
    if not (order.shape == fn.shape == adm.shape == f_ok.shape):
        raise InputError(
            f"poles/flags: expected arrays of one length, got {order.shape} and {adm.shape}"
        )
    ax = single_axes(ax, (7.5, 4.0))
    cls = np.zeros(order.shape, dtype=int)
    cls[f_ok] = 1
    cls[f_ok & z_ok] = 2
    cls[f_ok & z_ok & v_ok] = 3
    for k, (label, style) in enumerate(_CLASSES):
        m = adm & (cls == k)
        if np.any(m):
            ax.scatter(fn[m], order[m], label=f"{label} ({int(m.sum())})", **style)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("model order")
    if selected_hz is not None:
        for i, f in enumerate(np.atleast_1d(np.asarray(selected_hz, dtype=float))):
            ax.axvline(f, color="C3", lw=0.8, ls="--", label="selected modes" if i == 0 else None)
    if frf is not None:
        tw = ax.twinx()
        amp = np.sqrt(np.sum(np.abs(frf.H) ** 2, axis=(0, 1)))
        tw.plot(
            frf.frequency,
            20 * np.log10(np.maximum(amp, 1e-300)),
            color="0.35",
            lw=0.8,
            zorder=0,
        )
        tw.set_ylabel(f"sum |H| dB re 1 {frf.unit}")
    ax.legend(fontsize="x-small", loc="upper left", framealpha=0.9)
    ax.grid(True, alpha=0.3)
    return ax
