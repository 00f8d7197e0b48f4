"""Lateral tyre figures: paper Figure 7, measured vs fitted FRFs (Figs. 11-14), Fig. 15."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from matplotlib.axes import Axes
from numpy.typing import ArrayLike

from ..exceptions import InputError
from ._axes import axes_grid, single_axes

if TYPE_CHECKING:
    from ..lateral.characteristics import Figure7Curves
    from ..lateral.fit import LateralFit
    from ..lateral.ranking import Ranking

__all__ = ["plot_figure7", "plot_lateral_fit", "plot_ranking", "plot_time_comparison"]

Style = Literal["reim", "bode"]


def _axes(n: int, axes: Sequence[Axes] | None) -> list[Axes]:
    return axes_grid(axes, n, (7.0, 2.4 * n))


def plot_figure7(curves: Figure7Curves | None = None, ax: Axes | None = None) -> dict[str, Any]:
    """Amplitude ratio of the proposed model with its asymptotes (paper Figure 7).

    Parameters
    ----------
    curves : Figure7Curves, optional
        Data from :func:`tyredamp.lateral.figure7_curves` (default: the paper's
        parameters, 0.01-100 Hz).
    ax : Axes, optional
        Axes to draw on; a new figure if omitted.

    Returns
    -------
    dict
        ``"ax"`` and the artists ``"model"``, ``"low"``, ``"high"``,
        ``"maxwell"``, ``"f0"``.
    """
    if curves is None:
        from ..lateral.characteristics import figure7_curves

        curves = figure7_curves()
    ax = single_axes(ax, (6.0, 4.0))
    f = curves.frequency
    (model,) = ax.semilogx(f, curves.model_db, "k-", lw=2, label="proposed model")
    (low,) = ax.semilogx(f, curves.low_asymptote_db, "b--", label=r"$1/(i\omega C_r)$")
    (high,) = ax.semilogx(f, curves.high_asymptote_db, "r--", label=r"$1/(K + i h)$")
    (mx,) = ax.semilogx(f, curves.maxwell_db, "g:", label="Maxwell (k = K, c = C_r)")
    f0 = ax.axvline(curves.f0, color="0.5", lw=0.8)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("A.R. (dB re 1 m/N)")
    lo = float(np.min(curves.model_db))
    ax.set_ylim(lo - 10.0, float(np.max(curves.model_db)) + 5.0)
    ax.legend(loc="upper right")
    return {"ax": ax, "model": model, "low": low, "high": high, "maxwell": mx, "f0": f0}


def _panels(style: Style) -> tuple[str, str]:
    if style == "reim":
        return "re", "im"
    if style == "bode":
        return "amp", "phase"
    raise InputError(f"style: expected 'reim' or 'bode', got {style!r}")


def _draw(ax: Axes, kind: str, f: np.ndarray, h: np.ndarray, **kw: Any) -> Any:
    if kind == "re":
        return ax.plot(f, h.real, **kw)[0]
    if kind == "im":
        return ax.plot(f, h.imag, **kw)[0]
    if kind == "amp":
        return ax.plot(f, np.abs(h), **kw)[0]
    return ax.plot(f, np.degrees(np.angle(h)), **kw)[0]


def _label_axes(axes: list[Axes], names: tuple[str, str], force: str) -> None:
    unit = "m/(s$^2$ N)"
    labels = {
        "re": f"Re A ({unit})",
        "im": f"Im A ({unit})",
        "amp": f"|A| ({unit})",
        "phase": "phase (deg)",
    }
    for ax, n in zip(axes, names, strict=True):
        ax.set_ylabel(labels[n])
    axes[0].set_title(f"lateral acceleration / {force} force")
    axes[-1].set_xlabel("frequency (Hz)")


def plot_lateral_fit(
    fit: LateralFit, axes: Sequence[Axes] | None = None, style: Style = "reim"
) -> list[Axes]:
    """Measured and fitted accelerance of one fit (paper Figures 11-14).

    Parameters
    ----------
    fit : LateralFit
    axes : sequence of 2 Axes, optional
    style : {"reim", "bode"}
        Real and imaginary parts, or amplitude and phase.

    Returns
    -------
    list of Axes
    """
    names = _panels(style)
    ax_list = _axes(2, axes)
    for ax, n in zip(ax_list, names, strict=True):
        _draw(
            ax,
            n,
            fit.frequency,
            fit.measured,
            color="k",
            marker=".",
            ls="none",
            ms=3,
            label="measured",
        )
        _draw(ax, n, fit.frequency, fit.fitted, label=fit.model.label)
    _label_axes(ax_list, names, fit.force)
    ax_list[0].legend(loc="best")
    return ax_list


def plot_ranking(
    ranking: Ranking, axes: Sequence[Axes] | None = None, style: Style = "reim"
) -> list[Axes]:
    """Measured accelerance with every ranked model's fit (paper Figures 11-14).

    Returns
    -------
    list of Axes
    """
    names = _panels(style)
    ax_list = _axes(2, axes)
    first = ranking.fits[0]
    for ax, n in zip(ax_list, names, strict=True):
        _draw(
            ax,
            n,
            first.frequency,
            first.measured,
            color="k",
            marker=".",
            ls="none",
            ms=3,
            label="measured",
        )
        for f in ranking.fits:
            _draw(ax, n, f.frequency, f.fitted, label=f.model.label)
    _label_axes(ax_list, names, first.force)
    ax_list[0].legend(loc="best", fontsize="small")
    return ax_list


def plot_time_comparison(
    time: ArrayLike,
    measured: ArrayLike,
    predictions: Mapping[str, ArrayLike],
    ax: Axes | None = None,
    window: tuple[float, float] | None = (4.0, 6.0),
) -> Axes:
    """Lateral acceleration: measurement against model predictions (paper Figure 15).

    Parameters
    ----------
    time : array_like, shape (n,)
        s.
    measured : array_like, shape (n,)
        m/s^2.
    predictions : mapping of str to array_like, shape (n,)
        Model label to predicted acceleration.
    ax : Axes, optional
    window : (float, float) or None
        Time range shown (the paper shows 4-6 s).

    Returns
    -------
    Axes
    """
    ax = single_axes(ax, (7.0, 3.0))
    t = np.asarray(time, dtype=float)
    ax.plot(t, np.asarray(measured, dtype=float), "k-", lw=1.5, label="measured")
    for name, y in predictions.items():
        ax.plot(t, np.asarray(y, dtype=float), lw=1.0, label=name)
    if window is not None:
        ax.set_xlim(*window)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("lateral acceleration (m/s$^2$)")
    ax.legend(loc="upper right", fontsize="small")
    return ax
