"""The registry of the demo report's plots: a plot added from outside is built, written
and placed in the report; the registry refuses what it cannot place."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.figure import Figure

from tyredamp.exceptions import InputError
from tyredamp.report import plots
from tyredamp.report.demo import save_demo
from tyredamp.report.plots import PLACES, Plot, demo_figures, register_plot
from tyredamp.studies.demo import DemoResult

from .test_studies_demo import quick_demo

# the session's one quick demo (test_studies_demo.quick_demo): same xdist group
pytestmark = pytest.mark.xdist_group("demo")


def _damping_diagonal(result: DemoResult) -> tuple[Figure, str]:
    """A plot made here: the diagonal of the identified modal damping matrix."""
    dm = result.radial.damping
    fig = Figure(figsize=(3.0, 2.0), layout="constrained")
    ax = fig.subplots()
    ax.plot(dm.frequency_hz, np.diag(dm.modal), "o")
    return fig, f"Diagonal of the modal damping matrix, {dm.n_modes} modes (plot of a test)."


def test_a_registered_plot_is_written_and_placed_in_its_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    result, _ = quick_demo()
    # the built-in plot of the section and the new one (every built-in figure is
    # test_studies_demo.test_files_exist's): a few seconds instead of every figure
    monkeypatch.setattr(plots, "PLOTS", {"fig05_damping": plots.PLOTS["fig05_damping"]})
    register_plot(Plot("damping_diagonal", "radial:damping", _damping_diagonal))
    out = tmp_path / "out"
    save_demo(result, out)

    png = (out / "figures" / "damping_diagonal.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert "figures/damping_diagonal.png" in json.loads((out / "results.json").read_text())["files"]
    page = (out / "report.html").read_text(encoding="utf-8")
    caption = _damping_diagonal(result)[1]
    new = page.index(f"<figcaption>{html.escape(caption)}</figcaption>")
    # the PNG embedded in the page is the file written beside it
    assert page.rfind("data:image/png;base64,", 0, new) == page.index(
        "data:image/png;base64," + base64.b64encode(png).decode("ascii")
    )
    # in its section, after the plot registered there before it, before the next heading
    heading = page.index(">Damping matrices</h3>")
    fig5 = page.index("<figcaption>Paper Fig. 5:")
    following = page.index(">Inflation pressure</h3>")
    assert heading < fig5 < new < following


def test_render_keeps_registry_order_and_leaves_out_empty_plots(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def one(_: Any) -> tuple[Figure, str]:
        return Figure(figsize=(1, 1)), "one"

    def two(_: Any) -> dict[str, tuple[Figure, str]]:
        return {"two_a": (Figure(figsize=(1, 1)), "a"), "two_b": (Figure(figsize=(1, 1)), "b")}

    monkeypatch.setattr(plots, "PLOTS", {})
    register_plot(Plot("one", "lateral:vehicle", one))
    register_plot(Plot("nothing", "radial:checks", lambda _: None))
    register_plot(Plot("two", "radial:fits", two))
    built = demo_figures(object())  # type: ignore[arg-type]
    assert list(built) == ["one", "two_a", "two_b"]
    assert [r.section for r in built.values()] == ["lateral:vehicle", "radial:fits", "radial:fits"]
    assert [r.caption for r in built.values()] == ["one", "a", "b"]


def test_registry_refuses_what_it_cannot_place(monkeypatch: pytest.MonkeyPatch) -> None:
    def blank(_: Any) -> tuple[Figure, str]:
        return Figure(figsize=(1, 1)), "blank"

    with pytest.raises(InputError, match=r"plot 'x': expected a section of .*radial:damping"):
        Plot("x", "damping", blank)
    with pytest.raises(InputError, match="a file name"):
        Plot("../x", "radial:damping", blank)
    monkeypatch.setattr(plots, "PLOTS", dict(plots.PLOTS))
    with pytest.raises(InputError, match="registered already"):
        register_plot(Plot("mac", "radial:shapes", blank))
    register_plot(Plot("fig02_again", "radial:fits", lambda _: {"fig02_real_fit": blank(None)}))
    monkeypatch.setattr(plots, "PLOTS", {k: plots.PLOTS[k] for k in ("fig02_again",)})
    register_plot(Plot("fig02_real_fit", "radial:fits", blank))
    with pytest.raises(InputError, match="'fig02_real_fit' exists already"):
        demo_figures(object())  # type: ignore[arg-type]


def test_every_place_is_in_the_report() -> None:
    """Each place a plot can name has its spot in the page builders."""
    import inspect

    import tyredamp.report.build as build
    import tyredamp.report.lateral as lateral
    import tyredamp.report.tyremodel as tyremodel

    source = inspect.getsource(build) + inspect.getsource(lateral) + inspect.getsource(tyremodel)
    for place in PLACES:
        assert f'_images(rep, images, "{place}")' in source
    assert {p.section for p in plots.PLOTS.values()} == set(PLACES)
