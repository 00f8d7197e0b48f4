"""The demo's own files read back whole, and ``lateral fit`` on them reproduces the demo's fits.

Uses the one quick demo of the test session (:func:`tests.test_studies_demo.quick_demo`).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.cli import main
from tyredamp.io import read_frf, read_timedata
from tyredamp.lateral import DEFAULT_MODELS, LateralData, rank_models
from tyredamp.report._cells import anchor_id
from tyredamp.studies.findings import outcome_groups
from tyredamp.studies.results import DemoResult
from tyredamp.studies.verdicts import CAUSE_MEANING

from .test_studies_demo import quick_demo

# the session's one quick demo (quick_demo) serves the modules of this group: one
# pytest-xdist worker runs them all (pyproject: --dist loadgroup), so it runs once
pytestmark = pytest.mark.xdist_group("demo")


@pytest.fixture(scope="module")
def demo() -> tuple[DemoResult, Path]:
    return quick_demo()


def test_every_data_file_reads_back_whole(demo: tuple[DemoResult, Path]) -> None:
    from tyredamp.report.demo import _data_files

    result, out = demo
    files = _data_files(result)
    assert files  # every file the demo writes as data
    for rel, obj in files.items():
        back = read_timedata(out / rel) if rel.endswith("time.uff") or "_time_" in rel else None
        if back is None:
            frf = read_frf(out / rel)
            assert_array_equal(frf.H, obj.H)  # type: ignore[union-attr]
            assert_array_equal(frf.frequency, obj.frequency)  # type: ignore[union-attr]
            assert frf.meta == json.loads(json.dumps(obj.meta)), rel
        else:
            assert_array_equal(back.data, obj.data)  # type: ignore[union-attr]
            assert back.meta == json.loads(json.dumps(obj.meta)), rel


def test_json_documents_read_back(demo: tuple[DemoResult, Path]) -> None:
    from tyredamp.damping import DampingModel
    from tyredamp.documents.modes import read_modes_json

    result, out = demo
    p0 = f"{result.radial.main.pressure_bar:g}bar"
    from tyredamp.documents.jsonfile import json_text

    def same(a: object, b: object) -> None:
        # everything the documents hold, compared in their JSON form
        assert json.loads(json_text(a)) == json.loads(json_text(b))

    models = read_modes_json(out / f"modes_{p0}.json")
    assert set(models) == set(result.radial.main.models)
    for name, mdl in result.radial.main.models.items():
        assert_allclose(models[name].poles, mdl.poles, rtol=1e-15)
        same(models[name].to_dict(), mdl.to_dict())
    dm = DampingModel.from_dict(json.loads((out / f"damping_{p0}.json").read_text()))
    assert_allclose(dm.modal, result.radial.damping.modal, rtol=1e-15)
    same(dm.to_dict(), result.radial.damping.to_dict())


@pytest.mark.parametrize("force", ["ground", "axle"])
def test_lateral_fit_on_demo_files_reproduces_the_demo(
    demo: tuple[DemoResult, Path], force: str, tmp_path: Path
) -> None:
    """``tyredamp lateral fit FILE`` (no options) gives the demo's parameters to 1e-9."""
    result, out = demo
    for c in result.lateral.conditions:
        tag = f"{c.pressure_bar:g}bar_{c.speed_kmh:g}kmh"
        path = out / "data" / f"lateral_{tag}_{force}_frf.uff"
        js = tmp_path / f"{tag}_{force}.json"
        try:
            main(["lateral", "fit", str(path), "--out", str(js)])
        except SystemExit as exc:
            raise AssertionError(f"lateral fit exited with {exc.code}") from None
        doc = json.loads(js.read_text())
        cond = doc["conditions"]
        assert cond["force"] == force
        assert_allclose(cond["speed_kmh"], c.speed_kmh, rtol=1e-15)
        data: LateralData = c.ground if force == "ground" else c.axle
        assert cond["wheel_mass_kg"] == data.wheel_mass
        if force == "ground":  # the demo's own ranking of the ground-force FRF
            fits = {f.name: f for f in c.ranking.fits}
        else:  # the demo predicts the axle FRF; the same fit of its in-memory data
            fits = {f.name: f for f in rank_models(data, DEFAULT_MODELS).fits}
        assert {f["model"] for f in doc["fits"]} == set(DEFAULT_MODELS)
        for f in doc["fits"]:
            want = fits[f["model"]].params
            assert set(f["params"]) == set(want)
            for k, v in want.items():
                assert_allclose(f["params"][k], v, rtol=1e-9, err_msg=f"{tag} {f['model']} {k}")


def _sections(html_text: str) -> dict[str, str]:
    """The report's radial and lateral sections (text between their level-2 headings)."""
    import re

    def at(title: str) -> int:
        m = re.search(rf'<h2 id="s\d+">{re.escape(title)}', html_text)
        assert m is not None, title
        return m.start()

    r0, l0 = at("Radial study: modal test"), at("Lateral study: rolling-tyre rig")
    f0 = at("Files")
    return {"radial": html_text[r0:l0], "lateral": html_text[l0:f0]}


def test_every_stage_warning_reaches_the_report_beside_its_result(
    demo: tuple[DemoResult, Path],
) -> None:
    import html

    from tyredamp.studies.findings import demo_findings

    result, out = demo
    doc = json.loads((out / "results.json").read_text())
    page = (out / "report.html").read_text(encoding="utf-8")
    sec = _sections(page)
    # collected again from the stages' own results: nothing is lost on the way
    raw = []
    for run in result.radial.runs:
        raw += list(run.identification.warnings)
        for mdl in run.models.values():
            raw += list(mdl.meta.get("warnings", []))
    for chk in (result.radial.linearity, result.radial.reciprocity, result.radial.quality):
        if not chk.passed:
            raw.append(chk.summary)
    messages = [w["message"] for w in doc["warnings"]]
    for w in raw:
        core = w.split("(", 1)[-1].split(")", 1)[0] if w.startswith("real-mode refinement") else w
        assert any(core in m for m in messages), w
    fnd = demo_findings(result)
    assert [f.to_dict() for f in fnd.findings] == doc["warnings"]
    assert doc["warnings"]  # the quick demo has findings to report (9 bar, real modes)
    summary = page[: page.index('<h2 id="s2"')]
    for w in doc["warnings"]:
        text = html.escape(w["message"])
        where = "radial" if w["about"].startswith("radial") else "lateral"
        anchor = f'id="{anchor_id(w["about"])}"'
        assert page.count(anchor) == 1, w  # the result has one place in the page
        assert anchor in sec[where], w  # in the section of the result it concerns
        # the summary's list links to it
        assert f'href="#{anchor_id(w["about"])}"' in summary, w
        if w["severity"] == "expected":
            # a miss the data explain: its fit beside the result in a neutral block, its
            # cause's meaning once in the page, never as a failure
            v = _verdict_of(doc, w)
            at = sec[where].index(html.escape(v["subject"]) + ": residual")
            box = sec[where].rfind('<div class="verdict', 0, at)
            assert sec[where].startswith('<div class="verdict expected"', box), w
            assert "FAILED" not in w["message"]
            meaning = html.escape(CAUSE_MEANING[v["expected_cause"]][1:])
            assert page.count(meaning) == 1, w
        else:
            assert page.count(text) == 1, w  # stated once, beside the result it concerns
            assert text in sec[where], w


def _verdict_of(doc: dict, w: dict) -> dict:
    """The verdict a finding about a fit states."""
    if w["about"].startswith("radial:"):
        p = float(w["about"].split(":", 1)[1])
        pr = next(x for x in doc["radial"]["pressures"] if x["pressure_bar"] == p)
        return pr["verdict"][w["fit"]]
    c = next(x for x in doc["lateral"]["conditions"] if f"lateral:{x['label']}" == w["about"])
    return c["verdicts"][w["fit"]]


def test_every_pressure_and_condition_fits_or_says_why(demo: tuple[DemoResult, Path]) -> None:
    import html

    from tyredamp.cli.demo import demo_summary_rows

    result, out = demo
    doc = json.loads((out / "results.json").read_text())
    page = (out / "report.html").read_text(encoding="utf-8")
    rows = dict(demo_summary_rows(result, doc))
    groups = outcome_groups(doc)
    verdicts = []
    for pr in doc["radial"]["pressures"]:
        for name in ("complex", "real"):
            verdicts.append(
                (f"{name}-mode fit", f"{pr['pressure_bar']:g} bar", pr["verdict"][name])
            )
    for c in doc["lateral"]["conditions"]:
        verdicts.append(("best lateral fit", c["label"], c["verdict"]))
    assert len(verdicts) == 2 * len(result.radial.runs) + len(result.lateral.conditions)
    # every warning reaches the summary too (failures through the verdict rows)
    shown = " ".join(rows.values())
    for w in doc["warnings"]:
        if w["severity"] == "warning":
            assert w["message"] in shown, w
    for kind, label, v in verdicts:
        if v["status"] == "ok":
            assert v["outcome"] == "ok"
            assert v["residual_to_noise"] <= v["threshold"]
        else:
            assert v["status"] == "failed"
            assert v["residual_to_noise"] > v["threshold"]
            assert v["reasons"], v["subject"]
        # each verdict in exactly one row of the summary, which says its outcome
        about = ("radial:" + label[: -len(" bar")]) if kind != "best lateral fit" else label
        mine = [
            g
            for g in groups
            if g.title.startswith(kind) and any(a.endswith(about) for a in g.about)
        ]
        assert len(mine) == 1, v["subject"]
        g = mine[0]
        assert rows[g.title] == g.detail
        if v["outcome"] == "failed":
            assert g.title == v["subject"]
            assert rows[v["subject"]] == v["brief"]
            assert rows[v["subject"]].startswith("FAILED")
            assert v["reasons"][-1] in rows[v["subject"]]  # the likely cause
            summary = html.escape(v["summary"])
            assert page.count(f'<div class="verdict bad">{summary}</div>') == 1
        elif v["outcome"] == "expected":
            assert g.detail.startswith("expected")
            assert v["expected_cause"] in g.detail
            assert "FAILED" not in g.detail + v["summary"] + v["brief"]
        else:
            assert g.detail.startswith("within noise")
    # the 9 bar fit misses its band-edge mode: failed, and the report says why
    nine = next(p for p in doc["radial"]["pressures"] if p["pressure_bar"] == 9.0)
    reasons = " ".join(nine["verdict"]["complex"]["reasons"])
    if nine["verdict"]["complex"]["status"] == "failed":
        assert "band edge" in reasons
    # the main pressure's complex-mode fit is within its noise
    main = doc["radial"]["pressures"][0]["verdict"]["complex"]
    assert main["status"] == "ok"


def test_maxwell_and_relaxation_are_one_model_ranked_once(demo: tuple[DemoResult, Path]) -> None:
    import numpy as np

    from tyredamp.lateral.models import MaxwellModel, RelaxationLengthModel

    # closed form: Y/F = sigma/C_alpha + V/(i w C_alpha) = 1/k + 1/(i w c)
    rl = RelaxationLengthModel(C_alpha=8e4, sigma=0.6, speed=5 / 3.6)
    mx = MaxwellModel(k=8e4 / 0.6, c=8e4 / (5 / 3.6))
    f = np.linspace(0.1, 10, 50)
    assert_allclose(rl.response(f, "receptance"), mx.response(f, "receptance"), rtol=1e-12)
    _, out = demo
    doc = json.loads((out / "results.json").read_text())
    lat = doc["lateral"]
    assert ["maxwell", "relaxation"] in lat["equivalent_models"]
    names = [r["model"] for r in lat["ranking"]]
    assert "maxwell = relaxation" in names
    assert "maxwell" not in names
    assert "relaxation" not in names


def test_time_response_truth_and_gap(demo: tuple[DemoResult, Path]) -> None:
    import numpy as np

    result, out = demo
    doc = json.loads((out / "results.json").read_text())
    tr = doc["lateral"]["time_response"]
    # the rig's exact response misses the measurement by its noise alone: white noise of
    # relative_noise x the peak amplitude on a sine, RMS ratio relative_noise * sqrt(2)
    noise = result.lateral.rig.relative_noise * np.sqrt(2)
    assert_allclose(tr["truth_error"], noise, rtol=0.25)
    for name, err in tr["relative_error"].items():
        gap = tr["error_to_truth"][name]
        # misfit to the measurement = gap to the truth and noise, roughly in quadrature
        assert gap < err + 1e-12
        assert gap > 0.5 * err
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "error against the rig&#x27;s exact response" in page
    assert "The exact response misses the measurement by" in page
    for c in doc["lateral"]["conditions"]:
        rd = c["road_damping"]
        assert_allclose(rd["ratio"], rd["fitted"] / rd["true"], rtol=1e-12)


def test_modal_cli_prints_and_stores_the_verdict(
    demo: tuple[DemoResult, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The demo's 9 bar FRF: a mode at 199 Hz sits on the 200 Hz band edge."""
    result, out = demo
    if 9.0 not in result.settings.radial_pressures_bar:
        pytest.skip("no 9 bar run")
    frf = out / "data" / "radial_9bar_frf.uff"
    js = tmp_path / "m.json"
    verdicts = {}
    for band in (None, ("0", "195")):
        capsys.readouterr()
        main(["modal", str(frf), "--out", str(js), *(["--band", *band] if band else [])])
        text = capsys.readouterr().out
        assert "verdict: complex-mode fit: " in text
        doc = json.loads(js.read_text())
        verdicts[band] = doc["models"]["complex"]["meta"]["verdict"]
    demo_v = json.loads((out / "results.json").read_text())
    nine = next(p for p in demo_v["radial"]["pressures"] if p["pressure_bar"] == 9.0)
    # the command reaches the demo's own verdict on the same file and band
    assert verdicts[None]["status"] == nine["verdict"]["complex"]["status"]
    if verdicts[None]["status"] == "failed":
        assert "band edge" in " ".join(verdicts[None]["reasons"])
        # and the remedy it names works: a band that stops short of the edge mode
        assert verdicts[("0", "195")]["status"] == "ok"


def test_quality_check_judged_over_the_checks_band_and_summarised(
    demo: tuple[DemoResult, Path],
) -> None:
    from tyredamp.cli.demo import demo_summary_rows

    result, out = demo
    doc = json.loads((out / "results.json").read_text())
    q = result.radial.quality
    lo, hi = result.settings.check_band_hz
    assert q.frequency is not None
    assert q.frequency[0] >= lo
    assert q.frequency[-1] <= hi
    # the clean virtual test passes once the nearly silent band below the first mode is
    # judged as the other checks judge it; the summary reports the verdict either way
    assert doc["radial"]["checks"]["quality"]["passed"]
    rows = dict(demo_summary_rows(result, doc))
    assert "quality PASS" in rows["checks"]
    for note in q.notes:
        assert not re.search(r"(\d+(?:\.\d+)?)-\1 Hz", note), note  # no "25.5-25.5 Hz"


def test_files_report_shows_the_demo_verdicts_and_warnings(
    demo: tuple[DemoResult, Path], tmp_path: Path
) -> None:
    import html

    from tyredamp.report.files import build_files_report

    _, out = demo
    doc = json.loads((out / "results.json").read_text())
    page = build_files_report([out / "results.json"])
    for pr in doc["radial"]["pressures"]:
        for v in pr["verdict"].values():
            cls = {"ok": "verdict", "expected": "verdict expected", "failed": "verdict bad"}
            assert f'<div class="{cls[v["outcome"]]}">{html.escape(v["summary"])}</div>' in page
    for w in doc["warnings"]:
        assert html.escape(w["message"]) in page


def test_report_summarises_the_rejected_candidates(demo: tuple[DemoResult, Path]) -> None:
    """The report gives the count of rejected candidates and the strongest, each with
    its own short reason; every reason is in the modes JSON it names."""
    import html

    from tyredamp.modal.statistics.quality import RejectedMode, short_reason, strongest_rejected

    result, out = demo
    ident = result.radial.main.identification
    assert ident.rejected
    page = _sections((out / "report.html").read_text(encoding="utf-8"))["radial"]
    assert f"{len(ident.rejected)} candidate(s) rejected" in page
    top = strongest_rejected([RejectedMode.from_dict(x) for x in ident.rejected])[0]
    assert html.escape(f"{top.frequency_hz:.2f} Hz: {short_reason(top)}") in page
    assert "closest to the threshold" not in page
    name = f"modes_{result.radial.main.pressure_bar:g}bar.json"
    assert name in page
    doc = json.loads((out / name).read_text(encoding="utf-8"))
    got = doc["models"]["complex"]["quality"]["rejected"]
    reasons = {r["reason"] for r in got}
    assert {x["reason"] for x in ident.rejected} <= reasons


def test_report_states_no_outcome_of_the_design_as_failed(demo: tuple[DemoResult, Path]) -> None:
    """The default seed's report: no "FAILED" for a miss the virtual tyre makes by design,
    each classified from the data (the other fits of the same FRF), each finding once."""
    import html

    _, out = demo
    doc = json.loads((out / "results.json").read_text())
    page = (out / "report.html").read_text(encoding="utf-8")
    summary = page[: page.index('<h2 id="s2"')]
    expected = 0
    for pr in doc["radial"]["pressures"]:
        cx, re_ = pr["verdict"]["complex"], pr["verdict"]["real"]
        if re_["outcome"] == "expected":
            expected += 1
            # the real-mode fit misses its noise while the complex-mode fit of the same band
            # holds it: the data are non-proportional
            assert re_["residual_to_noise"] > re_["threshold"]
            assert cx["residual_to_noise"] <= cx["threshold"]
            assert re_["expected_cause"] == "non-proportional damping"
        assert cx["outcome"] != "expected"  # the general model's miss is never explained away
    for c in doc["lateral"]["conditions"]:
        if c["verdict"]["outcome"] == "expected":
            expected += 1
            v = c["verdict"]
            others = [x for k, x in c["verdicts"].items() if k != c["best"]]
            if v["expected_cause"] == "tyre outside the model family":
                # every model of the family misses this condition's noise
                assert all(x["residual_to_noise"] > x["threshold"] for x in c["verdicts"].values())
            else:
                assert any(x["residual_to_noise"] <= x["threshold"] for x in others)
    # the rig's tyre is none of the lateral models, by design: the demo shows that as an
    # expected outcome (the free radial tyre's modes are nearly real: its real-mode fits
    # reach the noise at 40 dB, docs/virtual-tyre.md)
    kinds = {pr["verdict"]["real"]["outcome"] for pr in doc["radial"]["pressures"]} | {
        c["verdict"]["outcome"] for c in doc["lateral"]["conditions"]
    }
    assert "expected" in kinds
    assert expected > 0
    genuine = [
        v
        for pr in doc["radial"]["pressures"]
        for v in pr["verdict"].values()
        if v["outcome"] == "failed"
    ] + [c["verdict"] for c in doc["lateral"]["conditions"] if c["verdict"]["outcome"] == "failed"]
    stages = [w for w in doc["warnings"] if w["severity"] == "failed" and not w["fit"]]
    # "FAILED" only in the statement of a genuine failure, once each; red only there
    assert page.count("FAILED") == len(genuine)
    for v in genuine:
        assert page.count(html.escape(v["summary"])) == 1
    assert page.count('class="verdict bad"') == len(genuine) + len(stages)
    # the summary names each finding once, with links, and holds no statement of a failure
    for g in outcome_groups(doc):
        assert summary.count(html.escape(g.title) + ":") == 1, g.title
        for a in g.about:
            assert f'href="#{anchor_id(a)}"' in summary
    assert "FAILED" not in summary
    # the first printed page: the summary starts no new page, every later section does
    assert "h2#s1{break-before:auto}" in page
    assert "h2{break-before:page" in page


def test_a_genuine_failure_is_stated_once_beside_its_result(demo: tuple[DemoResult, Path]) -> None:
    """A complex-mode fit made 10 % too large at one pressure: a fit that should hold and
    does not. It fails in red, once, beside its result; the real-mode fit of that band
    keeps its own verdict (the free tyre's modes are nearly real: it reaches the noise);
    the summary links to the failure."""
    import html
    from dataclasses import replace

    from tyredamp.cli.demo import demo_summary_rows
    from tyredamp.report.build import build_demo_report
    from tyredamp.studies.document import build_results

    result, _ = demo
    runs = list(result.radial.runs)
    k = len(runs) - 1
    broken = replace(runs[k].models["complex"], psi_out=runs[k].models["complex"].psi_out * 1.1)
    ident = replace(runs[k].identification, models={**runs[k].models, "complex": broken})
    runs[k] = replace(runs[k], identification=ident)
    res2 = replace(result, radial=replace(result.radial, runs=tuple(runs)))
    doc = build_results(res2)
    page = build_demo_report(res2, doc, {})
    pr = next(p for p in doc["radial"]["pressures"] if p["pressure_bar"] == runs[k].pressure_bar)
    cx, re_ = pr["verdict"]["complex"], pr["verdict"]["real"]
    assert cx["residual_to_noise"] > cx["threshold"]
    assert cx["outcome"] == "failed"
    # the real-mode fit is judged on its own residual: within the noise, it stays ok
    assert re_["residual_to_noise"] <= re_["threshold"]
    assert re_["outcome"] == "ok"
    sec = _sections(page)["radial"]
    text = html.escape(cx["summary"])
    assert page.count(text) == 1
    at = sec.index(text)
    assert sec.rfind('<div class="verdict bad"', 0, at) > sec.rfind("</div>", 0, at)
    assert page.count("FAILED") == 1
    summary = page[: page.index('<h2 id="s2"')]
    anchor = anchor_id(f"radial:{runs[k].pressure_bar:g}")
    assert f'<li class="failed">{html.escape(cx["subject"])}: does not fit' in summary
    assert f'href="#{anchor}"' in summary
    assert page.count(f'id="{anchor}"') == 1
    rows = dict(demo_summary_rows(res2, doc))
    assert rows[cx["subject"]] == cx["brief"]
    assert rows[cx["subject"]].startswith("FAILED (residual ")
    # the other pressures' real-mode fits stay within the noise
    others = [p for p in doc["radial"]["pressures"] if p is not pr]
    assert all(p["verdict"]["real"]["outcome"] == "ok" for p in others)


def test_a_failed_check_is_stated_once_in_red(demo: tuple[DemoResult, Path]) -> None:
    """A check that fails on the data is a genuine failure: red, once, beside the checks;
    the summary links to it and states nothing itself."""
    import html
    from dataclasses import replace

    from tyredamp.report.build import build_demo_report
    from tyredamp.studies.document import build_results

    result, _ = demo
    summary = "linearity: FAIL - 12 % RMS between the force levels (threshold 5 %)"
    bad = replace(result.radial.linearity, passed=False, summary=summary)
    res2 = replace(result, radial=replace(result.radial, linearity=bad))
    doc = build_results(res2)
    page = build_demo_report(res2, doc, {})
    text = html.escape(summary)
    assert page.count(text) == 1
    assert f'<div class="verdict bad">{text}</div>' in _sections(page)["radial"]
    first = page[: page.index('<h2 id="s2"')]
    assert '<li class="failed"><a href="#radial-checks">radial checks</a>: failed.</li>' in first
    assert "No genuine failure" not in first
    assert page.count('id="radial-checks"') == 1
