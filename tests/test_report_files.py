"""The report builders and the figures they use (data checked on the returned artists)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import Channel
from tyredamp.damping import identify_damping
from tyredamp.documents.damping import damping_document
from tyredamp.documents.jsonfile import finite
from tyredamp.documents.modes import modes_document
from tyredamp.exceptions import FileFormatError, InputError
from tyredamp.io import write_frf, write_timedata
from tyredamp.mechanics import time_response
from tyredamp.modal import ModalModel
from tyredamp.plot import plot_lateral_models, plot_stabilisation
from tyredamp.report.build import fmt_pm
from tyredamp.report.files import build_files_report, load_result_file
from tyredamp.report.html import HtmlReport
from tyredamp.timedata import TimeData

from .helpers import chain_system


def _images(html: str) -> int:
    return html.count('src="data:image/png;base64,')


def _self_contained(html: str) -> bool:
    return not re.search(r'(src|href)="(?!data:|#)', html) and "<script" not in html


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Modes (identified = exact here, and a 'truth' file), damping, FRF and time data."""
    d = tmp_path_factory.mktemp("report")
    s = chain_system()
    cm = s.complex_modes()
    outs = [Channel(i + 1, 3, 60.0 * i) for i in range(6)]
    model = ModalModel(cm.poles, cm.psi, cm.psi[[0]], outputs=outs, inputs=[Channel(1, 3, 0.0)])
    f = np.arange(1, 801) * 0.05
    frf = s.frf(f, "accelerance", inputs=[0], output_channels=outs, input_channels=[outs[0]])
    h = frf.H
    model.meta.update(rmsd=0.0, relative_error=0.0, band_hz=[0.05, 40.0])
    paths = {
        "modes": d / "modes.json",
        "truth": d / "truth.json",
        "damping": d / "damping.json",
        "frf": d / "chain_frf.uff",
        "time": d / "chain_time.npz",
    }
    paths["modes"].write_text(
        json.dumps(finite(modes_document({"complex": model}, source="chain_frf.uff")))
    )
    truth = ModalModel(cm.poles * 1.001, cm.psi, cm.psi[[0]], outputs=outs, inputs=outs[:1])
    paths["truth"].write_text(
        json.dumps(finite(modes_document({"complex": truth}, source="truth: chain")))
    )
    dm = identify_damping(model, n_samples=0)
    paths["damping"].write_text(json.dumps(damping_document(dm)))
    write_frf(frf.with_H(h), paths["frf"])
    force = np.random.default_rng(0).standard_normal((1, 4000))
    resp = time_response(s, force, 200.0, [0], [0, 3])
    td = TimeData(
        np.vstack([force, resp.acceleration]),
        200.0,
        [1, 1, 4],
        ["force", "acceleration", "acceleration"],
    )
    write_timedata(td, paths["time"])
    return paths


def test_load_result_file_classifies(files: dict[str, Path]) -> None:
    kinds = {k: load_result_file(p).kind for k, p in files.items()}
    assert kinds == {
        "modes": "modes",
        "truth": "modes",
        "damping": "damping",
        "frf": "frf",
        "time": "timedata",
    }
    assert load_result_file(files["truth"]).is_truth
    assert not load_result_file(files["modes"]).is_truth


def test_files_report_content(files: dict[str, Path]) -> None:
    html = build_files_report(list(files.values()), title="chain <test>")
    assert _self_contained(html)
    assert "<title>chain &lt;test&gt;</title>" in html  # escaped
    assert '<nav class="toc">' in html
    assert 'href="#s1"' in html
    for heading in ("Inputs", "Measured data", "Modal analysis", "Damping identification"):
        assert re.search(rf'<h2 id="s\d+">{re.escape(heading)}</h2>', html), heading
    # truth beside the identified modes: the 'truth' poles are 0.1 % higher
    assert "f true (Hz)" in html
    # FRF, time data, Figs. 2/3 (one model) + Fig. 4, mode shapes x 2 files, damping heat maps
    assert _images(html) == 1 + 1 + 2 + 2 + 1
    assert "What the numbers say" in html


def test_files_report_errors(tmp_path: Path, files: dict[str, Path]) -> None:
    with pytest.raises(InputError, match="RESULT_FILES"):
        build_files_report([])
    bad = tmp_path / "list.json"
    bad.write_text("[1, 2]")
    with pytest.raises(FileFormatError, match="JSON object"):
        build_files_report([bad])
    empty = tmp_path / "empty.json"
    empty.write_text("")
    with pytest.raises(FileFormatError, match="empty"):
        load_result_file(empty)
    broken = tmp_path / "damping.json"
    broken.write_text('{"kind": "damping", "modal": []}')
    with pytest.raises(FileFormatError, match=r"damping\.json"):
        load_result_file(broken)


def test_fmt_pm() -> None:
    assert fmt_pm(47.91234, 0.0123, 5) == "47.912 ± 0.012"
    assert fmt_pm(0.0402, 1.3e-5, 4, 100) == "4.02 ± 0.0013"
    assert fmt_pm(None, 1.0) == "-"
    assert fmt_pm(1.0, float("nan")) == "1"


def test_html_report_escapes_and_embeds() -> None:
    from matplotlib.figure import Figure

    rep = HtmlReport("a & b")
    rep.paragraph("<script>alert(1)</script>")
    rep.table(["x", "y"], [["<b>", 1.23456789]])
    fig = Figure(figsize=(1, 1))
    fig.subplots().plot([0, 1])
    png = rep.figure(fig, "cap")
    html = rep.render()
    assert png[:4] == b"\x89PNG"
    assert "<script>" not in html
    assert "&lt;script&gt;" in html
    assert "<nav" not in html  # no table of contents for a page without sections
    assert "1.235" in html
    assert _images(html) == 1
    assert _self_contained(html)


def test_stabilisation_diagram() -> None:
    order = np.array([1, 2, 2, 3, 3, 3])
    fn = np.array([10.0, 10.05, 30.0, 10.02, 30.1, 55.0])
    poles = SimpleNamespace(order=order, frequency_hz=fn)
    flags = SimpleNamespace(
        admissible=np.array([True, True, True, True, True, False]),
        frequency=np.array([False, True, False, True, True, True]),
        damping=np.array([False, True, False, True, False, True]),
        vector=np.ones(6, bool),
    )
    ax = plot_stabilisation(poles, flags, selected_hz=[10.02])
    offsets = {c.get_label().rsplit(" (", 1)[0]: c.get_offsets() for c in ax.collections}
    # classes: new/unstable (orders 1 and 2 at 10 and 30 Hz), stable frequency (30.1 Hz),
    # fully stable (10.05 and 10.02 Hz); the inadmissible 55 Hz pole is not drawn
    assert_allclose(offsets["new or unstable"], [[10.0, 1], [30.0, 2]])
    assert_allclose(offsets["stable frequency"], [[30.1, 3]])
    assert_allclose(offsets["stable (frequency, damping, vector)"], [[10.05, 2], [10.02, 3]])
    assert ax.lines[0].get_xdata()[0] == pytest.approx(10.02)
    with pytest.raises(ValueError, match="one length"):
        plot_stabilisation(SimpleNamespace(order=order[:2], frequency_hz=fn[:2]), flags)


def test_lateral_models_plot() -> None:
    f = np.linspace(0.5, 9, 50)
    meas = 1 / (1 + 1j * f)
    pred = {"maxwell": meas * 1.1, "hysteretic": meas * 0.9}
    axes = plot_lateral_models(f, meas, pred, style="bode", truth=meas)
    assert len(axes) == 2
    # measured, truth, then the models in order; amplitude and phase in degrees
    assert_allclose(axes[0].lines[2].get_ydata(), np.abs(meas * 1.1))
    assert_allclose(axes[1].lines[0].get_ydata(), np.degrees(np.angle(meas)))
    assert axes[0].lines[3].get_color() == "C3"  # the proposed model's colour everywhere
    axes = plot_lateral_models(f, meas, pred)
    assert_allclose(axes[1].lines[1].get_ydata(), (meas * 1.1).imag)
    with pytest.raises(ValueError, match="style"):
        plot_lateral_models(f, meas, pred, style="nyquist")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="measured"):
        plot_lateral_models(f, meas[:3], pred)
