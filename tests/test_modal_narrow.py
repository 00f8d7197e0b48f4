"""A pole narrower than the lines: a resonance is told from a spike and from another mode's flank.

The data are closed-form partial fractions (:class:`ModalModel`) on 1 Hz lines
with Gaussian noise of known level; the evidence of :func:`narrow_evidence` is
weighed against the mode test's threshold, as the residual search weighs it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tyredamp.modal import ModalModel
from tyredamp.modal.fit.fit import FitResult, ModalFitter
from tyredamp.modal.search.narrow import at_the_end, narrow_evidence, narrow_refusal, too_narrow
from tyredamp.modal.statistics.stats import mode_parameters, mode_threshold

F = np.arange(10.0, 200.0, 1.0)  # 1 Hz lines
SD = 1e-6  # noise per real part, in the units of H


def _pole(f: float, zeta: float) -> complex:
    w = 2 * np.pi * f
    return complex(-zeta * w, w * np.sqrt(1 - zeta**2))


def _data(narrow: bool, spike: bool, seed: int) -> tuple[np.ndarray, complex, complex]:
    """One broad mode at 60 Hz (1 %), and a weaker mode at 123.4 Hz of zeta 2e-5 (half-power
    bandwidth 0.005 Hz, far below the lines) when ``narrow``, and one line 40 noise
    levels off at 150 Hz when ``spike``."""
    rng = np.random.default_rng(seed)
    broad, thin = _pole(60.0, 0.01), _pole(123.4, 2e-5)
    poles = np.array([broad, thin]) if narrow else np.array([broad])
    amp = np.array([[1.0, 0.3]]) if narrow else np.array([[1.0]])
    H = ModalModel(poles, amp, np.ones((1, poles.size))).frf(F, "receptance").H
    H = H + SD * (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape))
    if spike:
        H[0, 0, int(np.searchsorted(F, 150.0))] += 40 * SD * (1 + 1j)
    return H, broad, thin


def _threshold() -> float:
    return float(mode_threshold(mode_parameters(1, 1, "complex"), F.size, 0.01))


def _fit(H: np.ndarray, pole: complex) -> tuple[ModalFitter, FitResult]:
    """The fit of the data by the one mode ``pole`` (its residue fitted), with the
    noise level of the data (the residual RMS of a fit that misses a mode holds
    that mode: the search weighs a trial against the noise it knows)."""
    fitter = ModalFitter(F, H, 0, "complex", [])
    res = fitter.fit(np.array([pole]), np.ones((1, 1), complex), refine=False, sigma=np.array([SD]))
    return fitter, replace(res, sigma_out=np.array([SD]))


def test_the_rule_applies_to_poles_narrower_than_the_lines_away_from_their_ends() -> None:
    # half-power bandwidth -Re p / pi = 2 zeta f (Hz)
    assert too_narrow(_pole(123.4, 2e-5), 1.0)
    assert not too_narrow(_pole(123.4, 0.01), 1.0)  # 2.5 Hz wide
    assert at_the_end(F, _pole(12.3, 1e-4))  # 3 lines above the first
    assert at_the_end(F, _pole(195.5, 1e-4))
    assert not at_the_end(F, _pole(123.4, 1e-4))


def test_a_resonance_narrower_than_the_lines_holds_evidence_on_both_sides() -> None:
    H, broad, thin = _data(narrow=True, spike=False, seed=3)
    fitter, res = _fit(H, broad)
    lo, hi = narrow_evidence(fitter, res, thin)
    # its tail at k lines is 1/k of its value half a line away: with a peak of about
    # 0.01 / (2 zeta w^2) / SD, the lines beyond the nearest two hold far more than
    # the threshold on each side
    assert min(lo, hi) > 10 * _threshold()


def test_a_spike_is_not_a_resonance() -> None:
    H, broad, _ = _data(narrow=False, spike=True, seed=4)
    fitter, res = _fit(H, broad)
    at_spike = _pole(150.3, 2e-5)
    lo, hi = narrow_evidence(fitter, res, at_spike)
    # the spike's line is taken by the null model's free value: what is left is the
    # noise, a chi-squared variable of 2 degrees of freedom split over the two sides;
    # its 99.9 % point is 13.8, under half the threshold (about 15 here)
    assert lo + hi < 13.8
    assert min(lo, hi) < 0.5 * _threshold()


def test_a_pole_on_the_flank_of_another_mode_holds_evidence_on_one_side() -> None:
    # the broad mode at 60 Hz fitted with a pole 0.3 % off: its misfit is a dipole;
    # a narrow pole 2.5 lines above it takes up that flank from one side only
    H, broad, _ = _data(narrow=False, spike=False, seed=5)
    off = complex(broad.real, broad.imag * 1.003)
    fitter, res = _fit(H, off)
    lo, hi = narrow_evidence(fitter, res, _pole(62.5, 2e-5))
    # measured: 51.9 below, -17.0 above (the threshold is 24.9): the flank's evidence
    # passes the threshold on its side, but a resonance's would on both
    assert lo > _threshold()
    assert hi < 0.5 * _threshold()


def test_a_step_between_two_lines_is_refused_and_a_resonance_two_lines_wide_is_kept() -> None:
    rng = np.random.default_rng(6)
    broad = _pole(60.0, 0.01)
    H = ModalModel(np.array([broad]), np.ones((1, 1)), np.ones((1, 1))).frf(F, "receptance").H
    H = H + SD * (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape))
    # a level change of 30 noise levels between the lines at 150 and 151 Hz
    stepped = H.copy()
    stepped[0, 0, F > 150.5] += 30 * SD * (1 - 1j)
    fitter, res = _fit(stepped, broad)
    at_step = _pole(150.5, 2.0 / (2 * 150.5))  # half-power bandwidth 2 Hz: 2 lines
    why = narrow_refusal(fitter, res, at_step, _threshold())
    assert "not a resonance" in why
    # a resonance of the same width and a peak of a few hundred noise levels
    w = 2 * np.pi * 150.5
    peaked = (
        H
        + ModalModel(np.array([at_step]), 2.5e-6 * w * np.ones((1, 1)), np.ones((1, 1)))
        .frf(F, "receptance")
        .H
    )
    fitter, res = _fit(peaked, broad)
    assert narrow_refusal(fitter, res, at_step, _threshold()) == ""
    # wider poles are not this rule's
    assert narrow_refusal(fitter, res, _pole(150.5, 0.02), _threshold()) == ""
