"""Every rejected candidate keeps its reason in statistical terms (issue 16).

The diagram's clusters that too few orders resolved are candidates of the
residual search. Each gets one record: the mode test's statistic of the trial
mode it started (where that trial went), or why it was not tried (too little
residual power in its half-power band, a fitted mode standing for it, the
coherent scan's statistic when the round's trials ran out); a candidate that
the search kept is no longer listed as rejected.
"""

from __future__ import annotations

import warnings

import numpy as np

from tyredamp.modal import identify_modes
from tyredamp.modal.search.search_starts import MAX_TRIALS
from tyredamp.modal.statistics.quality import KEPT, RejectedMode, merge_rejected

from .test_modal_search import BAND, _dense_band
from .test_modal_statistics import F, noisy, weak_beside_strong

NAN = float("nan")


def test_records_of_one_candidate_become_one() -> None:
    a = RejectedMode(50.0, 0.01, "present in 4% of orders < 30%")
    b = RejectedMode(50.0, 0.01, "not significant: T = 3 <= 40", 3.0, 40.0)
    c = RejectedMode(50.0 * (1 + 1e-6), 0.01, "not significant: T = 5 <= 40", 5.0, 40.0)
    d = RejectedMode(70.0, 0.02, "present in 9% of orders < 30%")
    got = merge_rejected([a, d, b, b, c])
    assert [(r.frequency_hz, r.reason) for r in got] == [
        (50.0, "present in 4% of orders < 30%; not significant: T = 3 <= 40"),
        (70.0, "present in 9% of orders < 30%"),
        (50.0 * (1 + 1e-6), "not significant: T = 5 <= 40"),
    ]
    # the test's statistic and threshold come from the record that has them
    assert (got[0].statistic, got[0].threshold) == (3.0, 40.0)
    assert np.isnan(got[1].statistic)
    # a candidate kept after all is not a rejected one
    kept = merge_rejected([a, d, RejectedMode(50.0, 0.01, KEPT)])
    assert [r.frequency_hz for r in kept] == [70.0]


def _decided(r: dict[str, object]) -> bool:
    """A record that says, in terms of the test, why the candidate is not a mode."""
    why = str(r["reason"])
    parts = why.split("; ")
    if parts[0].startswith("present in"):
        parts = parts[1:]  # the diagram's own reason: the search must add one
    tested = r["statistic"] is not None
    return bool(parts) and (tested or any(p.startswith(("not tried", "tried")) for p in parts))


def test_every_candidate_of_a_noisy_dense_band_has_a_statistical_reason() -> None:
    frf, *_ = _dense_band(1)  # 20 dB, 16 modes: many weak clusters in the diagram
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify_modes(frf, band=BAND, model="complex")
    rej = res.rejected
    diagram = [r for r in rej if str(r["reason"]).startswith("present in")]
    assert len(diagram) >= 5
    assert all(_decided(r) for r in rej), [r["reason"] for r in rej if not _decided(r)]
    # one record per candidate
    keys = [(round(r["frequency_hz"], 9), round(r["damping_ratio"], 9)) for r in rej]
    assert len(keys) == len(set(keys))
    # a trial that ended elsewhere is named at the candidate, with its statistic
    went = [r for r in diagram if "tried: its trial mode went to" in str(r["reason"])]
    for r in went:
        assert r["statistic"] is not None
        assert r["threshold"] is not None


def test_a_candidate_the_fitted_mode_stands_for_names_that_mode() -> None:
    frf = weak_beside_strong(0.02).frf(F, "accelerance")  # noise-free
    res = identify_modes(frf, model="complex")
    f = res.models["complex"].frequency_hz
    assert np.allclose(f, [40.0, 97.0, 100.0, 150.0], rtol=1e-8)
    near = [r for r in res.rejected if abs(r["frequency_hz"] - 97.0) < 1.0]
    assert near, "the diagram's weak cluster at the weak mode is listed"
    for r in near:
        assert "not tried: the mode at 97 Hz stands for it" in str(r["reason"])


def test_candidates_beyond_the_rounds_trials_get_the_scan_statistic() -> None:
    frf, _ = noisy(weak_beside_strong(0.05).frf(F, "accelerance"), 40.0, 1)
    res = identify_modes(frf, model="complex")
    capped = [r for r in res.rejected if f"its {MAX_TRIALS} candidates" in str(r["reason"])]
    assert capped  # this noisy band's diagram offers more candidates than a round tries
    thr = res.models["complex"].quality.threshold
    for r in capped:
        why = str(r["reason"])
        t = float(why.split("statistic near it is ")[1].split(" against")[0])
        assert 0.0 <= t < thr  # noise: the scan finds no mode there
        assert f"against the threshold {thr:.3g}" in why
