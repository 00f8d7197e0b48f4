"""Modes found again in replicates (`tyredamp.modal.replicates`, `modal --replicate`)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal.model import ModalModel
from tyredamp.modal.replicates import match_replicate, replicate_support

from .badinput import check_one_error_line, run_main
from .helpers import chain_system

TWO_PI = 2 * np.pi


def _pole(f_hz: float, zeta: float) -> complex:
    w = TWO_PI * f_hz
    return complex(-zeta * w, w * np.sqrt(1 - zeta**2))


def test_half_power_band_is_the_limit() -> None:
    """The term 1 / (j omega - p) has half its peak power at Im p +- |Re p| (closed
    form); a replicate pole at 0.999 of that offset finds the mode again, at 1.001
    not, whatever its damping."""
    p = _pole(100.0, 0.01)
    sigma = abs(p.real)  # rad/s
    peak = abs(1 / (1j * p.imag - p)) ** 2
    for side in (1.0, -1.0):
        edge = abs(1 / (1j * (p.imag + side * sigma) - p)) ** 2
        assert edge / peak == pytest.approx(0.5, rel=1e-12)  # rounding only
    df = 0.01  # Hz: a resolution far below the band
    for zeta in (0.001, 0.01, 0.05):  # the replicate's damping does not matter
        for side in (1.0, -1.0):
            q = _pole(100.0, zeta).real + 1j * (p.imag + side * 0.999 * sigma)
            assert match_replicate(np.array([p]), np.array([q]), df)[0] is not None
            q = _pole(100.0, zeta).real + 1j * (p.imag + side * 1.001 * sigma)
            assert match_replicate(np.array([p]), np.array([q]), df) == [None]


def test_line_spacing_is_the_least_radius() -> None:
    """For a pole sharper than the lines the radius is 2 pi df."""
    p = _pole(50.0, 1e-5)  # |Re p| = 3e-3 rad/s
    df = 0.1  # Hz
    q = p + 0.99j * TWO_PI * df
    assert match_replicate(np.array([p]), np.array([q]), df)[0] == pytest.approx(q)
    assert match_replicate(np.array([p]), np.array([p + 1.01j * TWO_PI * df]), df) == [None]


def test_broad_pole_does_not_take_its_sharp_neighbours_mode() -> None:
    """A sharp replicate mode inside the band of a broad joint pole pairs with
    the sharp joint pole it lies nearest to; the broad one is not found."""
    sharp, broad = _pole(40.0, 0.002), _pole(39.93, 0.03)
    q = _pole(39.976, 0.0016)
    assert abs(q.imag - broad.imag) <= abs(broad.real)  # it could find either
    got = match_replicate(np.array([broad, sharp]), np.array([q]), df=0.126)
    assert got == [None, pytest.approx(q)]


def test_one_replicate_mode_per_joint_mode_most_pairs_first() -> None:
    """Two replicate modes both nearest one joint mode: each joint mode gets one."""
    p = np.array([_pole(100.0, 0.01), _pole(101.5, 0.01)])  # half-widths about 1 Hz
    q = np.array([_pole(100.1, 0.01), _pole(100.7, 0.01)])
    # the second is nearer the first joint mode, and within the second's band
    assert abs(q[1].imag - p[0].imag) < abs(q[1].imag - p[1].imag) <= abs(p[1].real)
    got = match_replicate(p, q, df=0.126)
    assert got == [pytest.approx(q[0]), pytest.approx(q[1])]


def _model(f_hz: list[float], zeta: list[float]) -> ModalModel:
    poles = np.array([_pole(f, z) for f, z in zip(f_hz, zeta, strict=True)])
    m = len(f_hz)
    return ModalModel(poles, np.ones((1, m), complex), np.ones((1, m), complex))


def test_support_looks_again_in_each_modes_own_band() -> None:
    """A mode missed over the whole band is looked for over ``f +- max(5 %, its
    half-power bandwidth)``; a mode one replicate never finds is undecidable."""
    model = _model([10.0, 30.0, 50.0], [0.01, 0.01, 0.01])
    p = model.poles
    bands: list[tuple[int, tuple[float, float]]] = []

    def identify(k: int, band: tuple[float, float]) -> np.ndarray:
        bands.append((k, band))
        if band == (0.0, 60.0):  # the whole band: replicate 1 misses the 30 Hz mode
            return p if k == 0 else p[[0, 2]]
        return p[[1]] if k == 1 and band[0] < 30.0 < band[1] else np.empty(0, complex)

    model2 = _model([10.0, 30.0, 50.0, 55.0], [0.01, 0.01, 0.01, 0.2])
    sup = replicate_support(model, 2, identify, band=(0.0, 60.0), df=0.1)
    assert [s.confirmed for s in sup] == [True, True, True]
    own = [b for k, b in bands if k == 1 and b != (0.0, 60.0)]
    # 5 % of 30 Hz on each side, more than two half-power half-widths (2 x 0.3 Hz)
    np.testing.assert_allclose(own, [(28.5, 31.5)], rtol=1e-12)  # rounding of |p| / 2 pi
    assert sup[1].found_hz[1] == pytest.approx(abs(p[1]) / TWO_PI)
    bands.clear()
    sup = replicate_support(model2, 2, identify, band=(0.0, 60.0), df=0.1)
    assert [s.n_found for s in sup] == [2, 2, 2, 0]
    # the broad mode's own band: two half-power half-widths (2 x 0.2 x 55 Hz), cut at 60 Hz
    own = [b for k, b in bands if k == 0 and b != (0.0, 60.0)]
    # rounding of the frequencies only
    assert own[0][0] == pytest.approx(55.0 - 2 * abs(model2.poles[3].real) / TWO_PI, rel=1e-12)
    assert own[0][1] == 60.0
    assert "undecidable: found again in 0 of the 2 replicates" in sup[3].text()


def _replicate(freq: np.ndarray, rng: np.random.Generator, level: float) -> FRF:
    frf = chain_system(3, c_local=(5.0, 0.0, 2.0)).frf(freq, outputs=[0, 1, 2], inputs=[0])
    noise = rng.standard_normal(frf.H.shape) + 1j * rng.standard_normal(frf.H.shape)
    h = frf.H + level * np.abs(frf.H).max() * noise
    return FRF(freq, h, outputs=frf.outputs, inputs=frf.inputs)


@pytest.fixture
def here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_cli_marks_each_mode(here: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two noisy replicates of a three-mode system find each mode of their mean again."""
    rng = np.random.default_rng(3)
    freq = np.linspace(0.5, 40.0, 300)
    reps = [_replicate(freq, rng, 1e-3) for _ in range(2)]
    mean = FRF(freq, (reps[0].H + reps[1].H) / 2, outputs=reps[0].outputs, inputs=reps[0].inputs)
    for name, frf in (("mean.npz", mean), ("r1.npz", reps[0]), ("r2.npz", reps[1])):
        write_frf(frf, here / name)
    argv = ["modal", "mean.npz", "-o", "m.json", "--model", "complex"]
    code, out, err = run_main([*argv, "--replicate", "r1.npz", "--replicate", "r2.npz"], capsys)
    assert code == 0, err
    model = json.loads((here / "m.json").read_text())["models"]["complex"]
    assert len(model["modes"]) == 3
    assert [r["confirmed"] for r in model["meta"]["replicates"]] == [True, True, True]
    assert "replicates: 3 of 3 modes found again in each of the 2 replicates" in out


def test_cli_refuses_a_replicate_of_other_channels(
    here: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A replicate with other channels is refused in one line, naming it."""
    freq = np.linspace(0.5, 40.0, 100)
    frf = chain_system(3, c_local=(5.0, 0.0, 2.0)).frf(freq, outputs=[0, 1, 2], inputs=[0])
    one = chain_system(3, c_local=(5.0, 0.0, 2.0)).frf(freq, outputs=[0], inputs=[0])
    write_frf(frf, here / "a.npz")
    write_frf(one, here / "b.npz")
    code, _, err = run_main(["modal", "a.npz", "-o", "m.json", "--replicate", "b.npz"], capsys)
    check_one_error_line(err, code, 2, "--replicate: b.npz holds 1 output(s) x 1 input(s)")
    assert not (here / "m.json").exists()
