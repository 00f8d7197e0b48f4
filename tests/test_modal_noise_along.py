"""Standard errors with noise common to the outputs (a noisy force in H1).

H1 with force noise has the error ``-H N X^+`` at each line: common to the
outputs and along the response (errors in variables). The pole is estimated
from that direction, so its standard error must hold the noise there
(:func:`tyredamp.modal.final.noise_along_response`), not the fit's noise per
output: by up to ``sqrt(n_out)`` more.
"""

from __future__ import annotations

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import identify_modes

F = np.linspace(20.0, 60.0, 241)
FN, ZETA = 40.0, 0.01
N_OUT = 16


def _frf(rng: np.random.Generator, common: float, own: float) -> FRF:
    s = 2j * np.pi * F
    w = 2 * np.pi * FN
    shape = np.cos(2 * np.pi * np.arange(N_OUT) / N_OUT) + 0.3
    # a real (proportionally damped) mode, which both models describe exactly
    h = shape[:, None, None] * (1 / (s**2 + 2 * ZETA * w * s + w**2))[None, None, :]
    scale = np.abs(h).max()
    # a relative error common to every output at each line (force noise), and
    # independent noise of each output
    c = common * (rng.standard_normal(F.size) + 1j * rng.standard_normal(F.size))
    e = own * scale * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape))
    return FRF(F, h * (1 + c) + e, kind="receptance")


def _z(
    common: float, own: float, seeds: int, kind: str = "complex"
) -> tuple[np.ndarray, list[float]]:
    z, along = [], []
    for seed in range(seeds):
        mdl = identify_modes(
            _frf(np.random.default_rng(seed), common, own), model=kind, n_modes=1
        ).models[kind]
        f = float(mdl.frequency_hz[0])
        z.append((f - FN) / float(mdl.std["frequency_hz"][0]))  # |p| / 2 pi
        along.append(float(mdl.meta["noise_along_response"][0]))
    return np.asarray(z), along


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_common_noise_widens_the_standard_errors_to_the_scatter(kind: str) -> None:
    # the z-scores of the frequency over 20 noise draws: rms about 1 when the
    # standard error holds the common noise (about 6.6 without it, the square root
    # of the factor); the rms of 20 draws of a unit normal is within 0.6-1.45 with
    # probability > 99 %; the mode is real, so both models describe it
    z, along = _z(common=3e-3, own=1e-5, seeds=20, kind=kind)
    assert 0.6 < float(np.sqrt(np.mean(z**2))) < 1.45, z
    assert min(along) > 4.0  # the noise along the response: many times the fit's


def test_independent_noise_keeps_them() -> None:
    # independent outputs: the noise along the response is the fit's, and the
    # factor stays 1 but for the test's 5 % false alarms
    _, along = _z(common=0.0, own=1e-3, seeds=10)
    assert sum(a > 1.0 for a in along) <= 2
