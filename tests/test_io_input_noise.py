"""FRF.input_noise kept by every FRF file format tyredamp writes (NPZ, CSV, UFF 58)."""

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from tyredamp.frf import FRF, Channel
from tyredamp.io import read_frf, write_frf


def _frf(rng: np.random.Generator) -> FRF:
    f = np.linspace(1.0, 100.0, 64)
    h = rng.normal(size=(3, 2, 64)) + 1j * rng.normal(size=(3, 2, 64))
    return FRF(
        f,
        h,
        kind="accelerance",
        outputs=[Channel(node=k + 1, direction=3) for k in range(3)],
        inputs=[Channel(node=10 + k, direction=3) for k in range(2)],
        variance=rng.uniform(0.1, 1.0, size=(3, 2, 64)),
        input_noise=rng.uniform(1e-4, 1e-2, size=(2, 64)),
    )


@pytest.mark.parametrize("ext", ["npz", "csv", "uff"])
def test_input_noise_round_trips(tmp_path: Path, ext: str) -> None:
    frf = _frf(np.random.default_rng(3))
    path = tmp_path / f"h.{ext}"
    write_frf(frf, path)
    back = read_frf(path)
    assert isinstance(back, FRF)
    assert back.input_noise is not None
    if ext == "npz":
        assert_array_equal(back.input_noise, frf.input_noise)
    else:
        # CSV and binary UFF keep 17 significant digits or doubles: equal to rounding
        assert_allclose(back.input_noise, frf.input_noise, rtol=1e-15)
    assert back.variance is not None


@pytest.mark.parametrize("ext", ["npz", "csv", "uff"])
def test_a_file_without_input_noise_reads_none(tmp_path: Path, ext: str) -> None:
    frf = _frf(np.random.default_rng(4))
    frf = FRF(
        frf.frequency,
        frf.H,
        kind=frf.kind,
        outputs=frf.outputs,
        inputs=frf.inputs,
        variance=frf.variance,
    )
    path = tmp_path / f"h.{ext}"
    write_frf(frf, path)
    assert read_frf(path).input_noise is None
