"""The residual search finds significant modes beside fitted ones (issue 16).

A band of 16 modes, 40 % of them in close pairs (0.6-1.5 half-power
bandwidths), at 20 dB: the diagram resolves few of them, so the search must
add many, a few per round. Which true modes are significant comes from the
truth (the extra-sum-of-squares statistic of the true model at the true poles
against the mode test's threshold), as in ``benchmarks/modal_statistics.py``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.problem.problem import build_problem
from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold

BAND = (22.0, 98.0)


def _dense_band(seed: int) -> tuple[FRF, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    m = 16
    f = np.sort(rng.uniform(25, 95, m))
    z = np.exp(rng.uniform(np.log(0.005), np.log(0.03), m))
    for i in range(1, m):
        if rng.random() < 0.4:
            f[i] = f[i - 1] * (1 + rng.uniform(0.6, 1.5) * 2 * z[i - 1])
    o = np.argsort(f)
    f, z = f[o], z[o]
    for i in range(1, m):  # no pair closer than half a half-power bandwidth
        f[i] = max(f[i], f[i - 1] * (1 + z[i - 1]))
    w = 2 * np.pi * f
    p = -z * w + 1j * w * np.sqrt(1 - z * z)
    amp = np.exp(rng.uniform(np.log(0.03), 0, m))
    po = (rng.normal(size=(4, m)) + 1j * rng.normal(size=(4, m))) * amp
    pi = rng.normal(size=(1, m)) + 0.3j * rng.normal(size=(1, m))
    fr = np.arange(20, 100, np.min(z * f) * 0.3)
    H = ModalModel(p, po, pi).frf(fr, "receptance").H
    sd = 0.1 * np.sqrt(np.mean(np.abs(H) ** 2, axis=(1, 2), keepdims=True))  # 20 dB
    e = (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape)) / np.sqrt(2)
    return FRF(fr, H + sd * e, kind="receptance"), p, pi, sd[:, 0, 0]


@pytest.mark.parametrize("seed", [1, 2, 4])
def test_search_finds_the_significant_modes_of_a_dense_band(seed: int) -> None:
    frf, p, pi, sd = _dense_band(seed)
    pr = build_problem(frf, BAND)
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    t = fit.fit(p, pi.T.copy(), refine=False, sigma=sd / pr.scale).significance
    sig = t > mode_threshold(mode_parameters(4, 1, "complex"), pr.shape[2], 0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = identify_modes(frf, band=BAND, model="complex").models["complex"]
    ft, zt = np.abs(p) / (2 * np.pi), -p.real / np.abs(p)
    # matched within half a half-power half-width, as the benchmark matches
    found = np.array(
        [np.min(np.abs(m.frequency_hz - a)) < 0.5 * b * a for a, b in zip(ft, zt, strict=True)]
    )
    # measured: every significant mode of seeds 1 and 4, 12 of 13 of seed 2 (the
    # rules before this search: 12 of 13, 9 of 13, 14 of 15)
    assert np.sum(found & sig) >= np.sum(sig) - (1 if seed == 2 else 0)
    # and no mode where the truth has none
    near = [np.min(np.abs(ft - a) / (zt * ft)) < 0.5 for a in m.frequency_hz]
    assert all(near)
