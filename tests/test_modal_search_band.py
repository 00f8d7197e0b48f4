"""A narrow band of a long FRF (issue 15): the residual search's candidates get the
reason the joint refit gives, a trial rejected there is not refitted again, and
broad structure from outside the band is not reported as a mode.

The system of ``benchmarks/modal_memory.py``: six modes over 20-190 Hz, a 1 x 1
accelerance with noise at 1 % of its RMS, the band 40-60 Hz holding one mode
(48 Hz, 2 %) and the tails of its neighbours at 25 and 71 Hz.
"""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.search import MERGE

FN = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
ZETA = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
#: the selection rule's admissible damping (Diagram.max_damping, residual_search)
MAX_DAMPING = 0.2


def _long_frf(n: int) -> FRF:
    w = 2 * np.pi * FN
    p = -ZETA * w + 1j * w * np.sqrt(1 - ZETA**2)
    m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
    f = np.linspace(0.0, 200.0, n)[1:]
    h = m.frf(f, "accelerance").H
    rng = np.random.default_rng(0)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(f, h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e, kind="accelerance")


@pytest.mark.parametrize("n", [4001, 25001])
def test_narrow_band_reports_its_mode_and_why_candidates_were_rejected(n: int) -> None:
    res = identify_modes(_long_frf(n), band=(40.0, 60.0), model="complex")
    model = res.models["complex"]
    fn, zeta = np.abs(model.poles) / (2 * np.pi), -model.poles.real / np.abs(model.poles)
    # no mode damped beyond the admissible limit is reported (a broad pole that
    # takes the tails of the modes outside the band is a residual term, not a mode)
    assert np.all(zeta <= MAX_DAMPING), (fn, zeta)
    # the one true mode of the band, found (its frequency to 0.1 %: 2000 and more
    # lines at 40 dB determine it far better)
    assert model.n_modes == 1
    assert abs(fn[0] - 48.0) < 0.048
    # a reason that says "not significant" has a statistic at or below the threshold
    for r in res.rejected:
        if "not significant" in r["reason"]:
            assert r["statistic"] <= r["threshold"], r
    # a trial rejected in the joint refit is not refitted again (distinct poles)
    joint = [r for r in res.rejected if r["reason"].startswith("joint refit")]
    f_j = np.array([r["frequency_hz"] for r in joint])
    z_j = np.array([r["damping_ratio"] for r in joint])
    p_j = -z_j * f_j + 1j * f_j * np.sqrt(1 - z_j**2)
    for i in range(p_j.size):
        for j in range(i):
            assert abs(p_j[i] - p_j[j]) >= 2 * MERGE * abs(p_j[i]), (joint[i], joint[j])
