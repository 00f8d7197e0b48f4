"""Standard errors of the shapes at the inputs (``ModalModel.std["psi_in"]``).

A roving-hammer test has its shapes at the inputs (one response, the hammer
moved over the points): the damping identification reads them there, so they
need standard errors like the shapes at the outputs. The delta method of
:func:`tyredamp.modal.fit._scaling.input_shape_std` is checked here against
the spread of the estimates over independent noise draws (Monte Carlo).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tyredamp.documents.modes import read_modes, write_modes_json
from tyredamp.frf import FRF, Channel
from tyredamp.mechanics.modal_sum import pole_from_frequency_damping
from tyredamp.modal import identify_modes
from tyredamp.modal.model import ModalModel


def _roving_system() -> tuple[ModalModel, np.ndarray]:
    p = pole_from_frequency_damping(np.array([20.0, 35.0]), np.array([0.02, 0.015]))
    phi = np.array([[1.0, 0.8], [0.6, -0.7], [-0.4, 0.9]])  # 3 hammer points, real shapes
    psi = phi / np.sqrt(2j * p.imag)[None, :]  # eq. [3] scaling
    model = ModalModel(
        p, psi[:1], psi, outputs=[Channel(1, 3)], inputs=[Channel(k, 3) for k in (1, 2, 3)]
    )
    return model, np.linspace(10.0, 50.0, 241)


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_input_shape_errors_match_the_spread_over_noise_draws(kind: str) -> None:
    true, f = _roving_system()
    h0 = np.asarray(true.frf(f, kind="receptance").H)
    rng = np.random.default_rng(1)
    est, reported = [], []
    for _ in range(60):
        noise = rng.normal(size=h0.shape) + 1j * rng.normal(size=h0.shape)
        frf = FRF(
            f,
            h0 + 0.003 * np.abs(h0).max() * noise / np.sqrt(2),
            kind="receptance",
            outputs=true.outputs,
            inputs=true.inputs,
        )
        m = identify_modes(frf, frequencies=[20, 35], model=kind, search=False).models[kind]
        est.append(m.psi_in)
        reported.append(m.std["psi_in"])
    e = np.asarray(est)
    spread = np.sqrt(np.mean(np.abs(e - e.mean(axis=0)) ** 2, axis=0))  # (3 points, 2 modes)
    ratio = spread / np.mean(reported, axis=0)
    # 60 draws estimate a complex standard deviation to about 9 %: 0.7-1.3 is over 3 of those
    assert np.all((ratio > 0.7) & (ratio < 1.3)), ratio


def test_input_shape_errors_go_through_the_modes_file(tmp_path: Path) -> None:
    true, f = _roving_system()
    h = np.asarray(true.frf(f, kind="receptance").H)
    h = h + 1e-3 * np.abs(h).max() * np.random.default_rng(2).normal(size=h.shape)
    frf = FRF(f, h, kind="receptance", outputs=true.outputs, inputs=true.inputs)
    models = identify_modes(frf, frequencies=[20, 35], model="complex", search=False).models
    path = write_modes_json(tmp_path / "m.json", dict(models))
    back = read_modes(path)["complex"]
    np.testing.assert_allclose(back.std["psi_in"], models["complex"].std["psi_in"], rtol=1e-12)
