"""Standard errors scaled by each mode's local dispersion (issue 16).

``final.local_dispersion``: the residual power near a mode over its mean over
the band. A model that explains the data to the noise leaves it near 1 (the
standard errors unchanged within the ratio's sampling scatter); a model that
misses a mode beside another widens that other mode's intervals by the
square root of the excess. Checked against the ratio computed independently
from the FRFs and the model.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.testing import assert_allclose

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
from tyredamp.modal.final import local_dispersion
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.problem.problem import build_problem
from tyredamp.modal.search.residual_peaks import LOCAL_HALF, LOCAL_LINES

F = np.arange(5.0, 60.0, 0.02)
BAND = (8.0, 55.0)


def _frf(seed: int = 3) -> tuple[FRF, ModalModel]:
    f = np.array([15.0, 30.0, 30.9, 45.0])
    z = np.array([0.01, 0.01, 0.012, 0.01])
    w = 2 * np.pi * f
    p = -z * w + 1j * w * np.sqrt(1 - z * z)
    rng = np.random.default_rng(seed)
    psi = rng.normal(size=(4, 4)) + 0.2j * rng.normal(size=(4, 4))
    psi[:, 2] *= 0.5
    true = ModalModel(p, psi, np.ones((1, 4)))
    h = true.frf(F, "receptance").H
    sd = 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(F, h + sd * e, kind="receptance"), true


def _identify(frf: FRF, n_modes: int | None) -> ModalModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return identify_modes(frf, band=BAND, model="complex", n_modes=n_modes).models["complex"]


def _ratio(frf: FRF, m: ModalModel) -> np.ndarray:
    """The dispersion written out: residual power per line in units of each
    output's noise, near each mode over the band's mean."""
    sel = (frf.frequency >= BAND[0]) & (frf.frequency <= BAND[1])
    f = frf.frequency[sel]
    r = frf.H[:, :, sel] - m.frf(f, "receptance").H
    sig = np.asarray(m.meta["noise_rms_per_output"])
    pw = np.sum(np.abs(r) ** 2 / sig[:, None, None] ** 2, axis=(0, 1))
    out = []
    for fn, zn in zip(m.frequency_hz, m.damping_ratio, strict=True):
        half = max(LOCAL_HALF * zn * fn, LOCAL_LINES * (f[1] - f[0]))
        near = (f >= fn - half - 1e-9) & (f <= fn + half + 1e-9)
        out.append(max(pw[near].mean() / pw.mean(), 1.0))
    return np.array(out)


def test_a_complete_model_leaves_the_standard_errors_as_they_were() -> None:
    frf, _ = _frf()
    m = _identify(frf, None)
    assert m.n_modes == 4
    disp = np.asarray(m.meta["local_dispersion"])
    assert np.all(disp >= 1.0)
    assert np.all(disp < 1.25)  # sampling scatter of the ratio over ~30 lines x 4 FRFs
    assert_allclose(disp, _ratio(frf, m), rtol=0.05)


def test_a_missed_neighbour_widens_the_intervals_of_the_mode_beside_it() -> None:
    frf, true = _frf()
    pr = build_problem(frf, BAND)
    fit = ModalFitter(pr.frequency, pr.H, pr.power, "complex", [])
    keep = np.array([0, 1, 3])  # the 30.9 Hz mode of the pair left out
    res = fit.fit(true.poles[keep], np.ones((3, 1), complex), refine=True)
    sq = np.abs(res.model - pr.H) ** 2
    disp = local_dispersion(pr, res, sq, 3)
    # written out: residual power per line in units of each output's noise
    pw = np.sum(sq / res.sigma_out[:, None, None] ** 2, axis=(0, 1))
    f = pr.frequency
    ref = []
    for p in res.poles:
        fn, half = abs(p) / (2 * np.pi), max(-LOCAL_HALF * p.real / (2 * np.pi), 3 * (f[1] - f[0]))
        near = (f >= fn - half) & (f <= fn + half)
        ref.append(max(pw[near].mean() / pw.mean(), 1.0))
    assert_allclose(disp, ref, rtol=1e-3)
    assert disp[1] > 2.0  # the pair's first mode: its neighbour is in the residual
    assert disp[0] < 1.5
    assert disp[2] < 1.5
