"""The registry of the demo report's plots: one entry per plot, one place to add one.

A plot is a :class:`Plot`: its name, its place in the report and its builder
(a function of the :class:`~tyredamp.studies.results.DemoResult` that returns
the figure and its caption). :data:`PLOTS` holds every plot in report order;
:func:`demo_figures` builds them,
:func:`tyredamp.report.demo.save_demo` writes each as ``figures/<name>.png``
and :func:`tyredamp.report.build.build_demo_report` puts each, with its
caption, at its place (:data:`PLACES`), after the plots registered there
before it. Adding a plot is one builder and one :func:`register_plot` (or one
line in :data:`PLOTS`)::

    def my_figure(result):
        fig = Figure(figsize=(6.0, 4.0), layout="constrained")
        ...
        return fig, "What the figure shows."

    register_plot(Plot("my_figure", "radial:damping", my_figure))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

from matplotlib.figure import Figure

from ..exceptions import InputError
from . import figures as f

if TYPE_CHECKING:
    from ..studies.results import DemoResult

__all__ = ["PLACES", "PLOTS", "Plot", "Rendered", "demo_figures", "register_plot"]

#: The places of the report a plot can stand in (its ``section``), in page order.
PLACES: dict[str, str] = {
    "radial:checks": "radial study, linearity, reciprocity and data quality",
    "radial:stabilisation": "radial study, stabilisation diagram",
    "radial:fits": "radial study, real versus complex modes",
    "radial:shapes": "radial study, mode shapes",
    "radial:damping": "radial study, damping matrices",
    "radial:pressures": "radial study, inflation pressure",
    "tyre_model": "tyre model, after the fitted parameters",
    "lateral:corner": "lateral study, corner frequency and asymptotes",
    "lateral:frfs": "lateral study, measured against predicted FRFs",
    "lateral:vehicle": "lateral study, vehicle model and time response",
}

#: A builder's figure and caption, None (nothing to show), or several named figures.
Built = tuple[Figure, str] | None | Mapping[str, tuple[Figure, str]]


class Rendered(NamedTuple):
    """One built figure: the figure, its caption and its place (a key of :data:`PLACES`)."""

    figure: Figure
    caption: str
    section: str


@dataclass(frozen=True)
class Plot:
    """One plot of the demo report.

    Attributes
    ----------
    key : str
        Its name: the PNG file is ``figures/<key>.png`` (letters, digits,
        ``_`` and ``-``). A builder that returns several figures names them
        itself (their file stems); ``key`` then only names the entry.
    section : str
        Where the report shows it: a key of :data:`PLACES`.
    build : callable
        ``build(result) -> (Figure, caption) | None | {name: (Figure, caption)}``;
        None when the result holds nothing to show (the plot is left out).
    """

    key: str
    section: str
    build: Callable[[DemoResult], Built]

    def __post_init__(self) -> None:
        if not self.key or not all(c.isalnum() or c in "_-" for c in self.key):
            raise InputError(
                f"plot key: expected letters, digits, '_' or '-' (a file name), got {self.key!r}"
            )
        if self.section not in PLACES:
            raise InputError(
                f"plot {self.key!r}: expected a section of {sorted(PLACES)}, got {self.section!r}"
            )

    def render(self, result: DemoResult) -> dict[str, Rendered]:
        """The plot's figures by file stem (empty when the builder gives None)."""
        out = self.build(result)
        if out is None:
            return {}
        if isinstance(out, tuple):
            return {self.key: Rendered(out[0], out[1], self.section)}
        return {name: Rendered(fig, cap, self.section) for name, (fig, cap) in out.items()}


#: Every plot of the demo report in report order (the figures of one place stand in
#: this order).
PLOTS: dict[str, Plot] = {
    p.key: p
    for p in (
        Plot("checks", "radial:checks", f.checks_figure),
        Plot("stabilisation", "radial:stabilisation", f.stabilisation_figure),
        Plot("fig02_real_fit", "radial:fits", f.real_fit_figure),
        Plot("fig03_complex_fit", "radial:fits", f.complex_fit_figure),
        Plot("fig04_discrepancy", "radial:fits", f.discrepancy_figure),
        Plot("residual_zoom", "radial:fits", f.residual_zoom_figure),
        Plot("mode_shapes", "radial:shapes", f.mode_shapes_figure),
        Plot("mac", "radial:shapes", f.mac_figure),
        Plot("fig05_damping", "radial:damping", f.damping_figure),
        Plot("pressures", "radial:pressures", f.pressures_figure),
        Plot("ring_frequencies", "tyre_model", f.ring_frequencies_figure),
        Plot("fig07_corner_frequency", "lateral:corner", f.corner_frequency_figure),
        Plot("lateral_frfs", "lateral:frfs", f.lateral_frf_figures),
        Plot("vehicle", "lateral:vehicle", f.vehicle_figure),
        Plot("fig15_time_response", "lateral:vehicle", f.time_response_figure),
    )
}


def register_plot(plot: Plot) -> Plot:
    """Add ``plot`` to :data:`PLOTS` (after the plots of its place); returns it.

    Raises
    ------
    InputError
        A plot of that key is registered already.
    """
    if plot.key in PLOTS:
        raise InputError(f"plot {plot.key!r}: a plot of that name is registered already")
    PLOTS[plot.key] = plot
    return plot


def demo_figures(result: DemoResult) -> dict[str, Rendered]:
    """Every plot of :data:`PLOTS` built from ``result``: ``{file stem: Rendered}``.

    Raises
    ------
    InputError
        Two plots give a figure of the same name.
    """
    out: dict[str, Rendered] = {}
    for plot in PLOTS.values():
        for name, r in plot.render(result).items():
            if name in out:
                raise InputError(f"plot {plot.key!r}: a figure named {name!r} exists already")
            out[name] = r
    return out
