"""ModalModel: synthesis by eq. [2]/[3]/[10], serialisation round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp import InputError, ShapeError
from tyredamp.modal import ModalModel

from .helpers import chain_system


def test_exact_modes_reproduce_direct_frf() -> None:
    s = chain_system()
    cm = s.complex_modes()
    mm = ModalModel(cm.poles, cm.psi, cm.psi[[0, 3]], inputs=[1, 4])
    f = np.linspace(0.5, 40.0, 200)
    # modal sum [10] with all modes is exact: eigensolver rounding only
    assert_allclose(mm.receptance(f), s.frf(f, inputs=[0, 3]).H, rtol=1e-9, atol=1e-15)
    assert mm.frf(f, "accelerance").kind == "accelerance"


def test_real_modes_equal_eq2() -> None:
    fn, zeta = np.array([10.0, 25.0]), np.array([0.02, 0.04])
    phi = np.array([[0.3, -0.2], [0.5, 0.4]])
    mm = ModalModel.from_real_modes(fn, zeta, phi, phi[[0]])
    f = np.linspace(1, 40, 100)
    w, wn = 2 * np.pi * f, 2 * np.pi * fn
    h2 = sum(
        np.outer(phi[:, n], phi[[0], n])[:, :, None]
        / (wn[n] ** 2 - w**2 + 2j * zeta[n] * wn[n] * w)
        for n in range(2)
    )
    assert_allclose(mm.receptance(f), h2, rtol=1e-12)  # eq. [2] == eq. [3], rounding only
    assert_allclose(mm.frequency_hz, fn, rtol=1e-14)
    assert_allclose(mm.damping_ratio, zeta, rtol=1e-12)
    assert_allclose(mm.phi_out, phi, rtol=1e-12)
    assert_allclose(mm.second_order_shapes(), phi * np.sign(phi[np.abs(phi).argmax(0), [0, 1]]))


def test_residuals() -> None:
    mm = ModalModel(
        [-1 + 60j], [[1.0 + 0j]], [[1.0 + 0j]], lower_residual=[[2.0]], upper_residual=[[3e-3]]
    )
    f = np.array([5.0, 50.0])
    base = ModalModel([-1 + 60j], [[1.0 + 0j]], [[1.0 + 0j]]).receptance(f)
    s2 = (2j * np.pi * f) ** 2
    assert_allclose(mm.receptance(f)[0, 0], base[0, 0] + 3e-3 + 2.0 / s2, rtol=1e-14)
    with pytest.raises(InputError, match="0 Hz"):
        mm.receptance([0.0, 1.0])


def test_json_round_trip() -> None:
    s = chain_system()
    cm = s.complex_modes()
    std = {"frequency_hz": np.arange(6) * 0.01, "damping_ratio": np.arange(6) * 1e-4}
    mm = ModalModel(cm.poles, cm.psi, cm.psi[[0]], std=std, meta={"rmsd": np.float64(1e-3)})
    back = ModalModel.from_dict(json.loads(json.dumps(mm.to_dict())))
    assert_allclose(back.poles, mm.poles, rtol=0)
    assert_allclose(back.psi_out, mm.psi_out, rtol=0)
    assert_allclose(back.std["frequency_hz"], std["frequency_hz"], rtol=0)
    assert back.outputs == mm.outputs
    assert back.meta["rmsd"] == 1e-3


def test_bad_modal_model() -> None:
    with pytest.raises(InputError, match="Im p > 0"):
        ModalModel([-1 - 5j], [[1.0]], [[1.0]])
    with pytest.raises(ShapeError, match="columns"):
        ModalModel([-1 + 5j], [[1.0, 2.0]], [[1.0]])
    with pytest.raises(InputError, match="missing key 'modes'"):
        ModalModel.from_dict({"outputs": []})
