"""Campaign plots: a quantity of one mode family against one condition; a family's f and zeta."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["plot_family", "plot_trend"]


def plot_trend(
    points: Sequence[Mapping[str, Any]],
    fit: Any,
    condition: str,
    quantity: str,
    *,
    ax: Any = None,
    label: str | None = None,
    color: Any = None,
    scale: float = 1.0,
) -> dict[str, Any]:
    """Observations with standard errors, the fitted trend and its +-1.96 sigma band.

    Parameters
    ----------
    points : sequence of dict
        Rows of the campaign's mode table (keys ``condition``, ``quantity``
        and ``quantity + "_std"`` or the frequency's ``frequency_std_hz``).
    fit : TrendFit
        The trend (:func:`tyredamp.campaign.tracking.fit_trend`), with ``predict``.
    condition, quantity : str
        Column names of the x and y values.
    ax : matplotlib Axes, optional
        Axes to draw on (default: a new :class:`matplotlib.figure.Figure`).
    label : str, optional
        Legend label of the series.
    color : optional
        Matplotlib colour of the series.
    scale : float
        Factor on the y values (e.g. 100 for percent).

    Returns
    -------
    dict
        ``ax``, ``points`` (the errorbar container), ``line`` and ``band``.
    """
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(5, 3.4)).add_subplot()
    std_key = "frequency_std_hz" if quantity == "frequency_hz" else f"{quantity}_std"
    x = np.array([float(p[condition]) for p in points])
    y = np.array([float(p[quantity]) for p in points]) * scale
    s = np.array([np.nan if p.get(std_key) is None else float(p[std_key]) for p in points]) * scale
    eb = ax.errorbar(
        x,
        y,
        yerr=np.where(np.isfinite(s), s, 0.0),
        fmt="o",
        ms=4,
        color=color,
        label=label,
        capsize=2,
    )
    col = eb[0].get_color()
    xf = np.linspace(x.min(), x.max(), 100)
    yf, sf = fit.predict(xf)
    (line,) = ax.plot(xf, yf * scale, "-", color=col, lw=1.2)
    band = ax.fill_between(
        xf, (yf - 1.96 * sf) * scale, (yf + 1.96 * sf) * scale, color=col, alpha=0.2, lw=0
    )
    ax.set_xlabel(condition)
    ax.set_ylabel(quantity)
    return {"ax": ax, "points": eb, "line": line, "band": band}


def plot_family(
    rows: Sequence[Mapping[str, Any]],
    condition: str | None = None,
    *,
    axes: Sequence[Any] | None = None,
    series_key: str = "tyre",
) -> dict[str, Any]:
    """One mode family across the tests: natural frequency and damping ratio, +- 1 s.e.

    Parameters
    ----------
    rows : sequence of dict
        The family's rows of the campaign's mode table (``frequency_hz``,
        ``frequency_std_hz``, ``damping_ratio``, ``damping_ratio_std``,
        ``slot``, ``test_id`` and the conditions).
    condition : str, optional
        The numeric condition on the x axis (a column of ``rows``); None puts
        the tests side by side in the order of ``rows`` (their ``test_id`` as
        tick labels).
    axes : two matplotlib Axes, optional
        Frequency and damping-ratio axes (default: a new
        :class:`matplotlib.figure.Figure` with two panels).
    series_key : str
        Column whose values make the series (one colour each; default the tyre).

    Returns
    -------
    dict
        ``axes`` (the two axes), ``series`` (label -> list of the errorbar
        containers drawn, frequency then damping, per slot) and ``x`` (the
        x values drawn, in the order of ``rows``).
    """
    from ._axes import axes_grid

    ax_f, ax_z = axes_grid(axes, 2, (5.5, 4.2), columns=True, sharex=False)
    if condition is None:
        tests = list(dict.fromkeys(str(r["test_id"]) for r in rows))
        x = np.array([tests.index(str(r["test_id"])) for r in rows], dtype=float)
    else:
        tests = []
        x = np.array([np.nan if r.get(condition) is None else float(r[condition]) for r in rows])

    def col(key: str, scale: float = 1.0) -> NDArray[np.float64]:
        return np.array([np.nan if r.get(key) is None else float(r[key]) for r in rows]) * scale

    f, sf = col("frequency_hz"), col("frequency_std_hz")
    z, sz = col("damping_ratio", 100.0), col("damping_ratio_std", 100.0)
    labels = [str(r.get(series_key) or "") for r in rows]
    slots = [str(r.get("slot") or "") for r in rows]
    drawn: dict[str, list[Any]] = {}
    for k, lab in enumerate(dict.fromkeys(labels)):
        for slot, marker in (("", "o"), ("a", "v"), ("b", "^")):
            sel = np.array([lb == lab and s == slot for lb, s in zip(labels, slots, strict=True)])
            if not sel.any():
                continue
            name = " ".join(t for t in (lab, slot and f"slot {slot}") if t)
            drawn[name] = [
                ax.errorbar(
                    x[sel],
                    y[sel],
                    yerr=np.where(np.isfinite(e[sel]), e[sel], 0.0),
                    fmt=marker,
                    ms=4,
                    capsize=2,
                    color=f"C{k % 10}",
                    label=name or None,
                )
                for ax, y, e in ((ax_f, f, sf), (ax_z, z, sz))
            ]
    ax_f.ticklabel_format(axis="y", useOffset=False)  # frequencies in Hz as they are
    ax_f.set_ylabel("natural frequency [Hz]")
    ax_z.set_ylabel("damping ratio [%]")
    for ax in (ax_f, ax_z):
        if condition is None:
            ax.set_xticks(range(len(tests)), tests, rotation=30, ha="right", fontsize=7)
        else:
            ax.set_xlabel(condition)
    if any(drawn) and len(drawn) <= 12:  # named series only
        ax_f.legend(fontsize=6)
    return {"axes": [ax_f, ax_z], "series": drawn, "x": x}
