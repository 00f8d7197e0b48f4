"""Wave numbers of identified modes (issue 18, item 1)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.frf import Channel
from tyredamp.modal.model import ModalModel
from tyredamp.tyremodel import (
    alias_candidates,
    resolved_wave_numbers,
    wave_number_analysis,
)
from tyredamp.virtual import Imperfection, RingTyre, RingTyreParameters, TyreTruth

IMPERFECT = (Imperfection(60.0, mass=0.5, stiffness=2e4),)


@cache
def truth(p_bar: float, imperfect: bool, f_hi: float = 250.0) -> TyreTruth:
    tyre = RingTyre(
        RingTyreParameters(pressure=p_bar * 1e5), imperfections=IMPERFECT if imperfect else ()
    )
    return tyre.truth((0.0, f_hi))


def synthetic_model(angles_deg: np.ndarray, shapes: np.ndarray, f_hz: np.ndarray) -> ModalModel:
    """Real modes with given shapes (columns) at given angles, drive at the first point."""
    outs = [Channel(node=i + 1, angle_deg=float(a)) for i, a in enumerate(angles_deg)]
    return ModalModel.from_real_modes(
        f_hz,
        np.full(f_hz.size, 0.02),
        shapes,
        shapes[:1],
        outputs=outs,
        inputs=[outs[0]],
    )


def test_resolved_range_of_equal_points() -> None:
    # 16 equal points: both members up to n = 7, only the cosine of n = 8 (Nyquist)
    assert resolved_wave_numbers(np.arange(16) * 22.5) == (7, True)
    # 15 equal points: n <= 7 and no Nyquist wave number
    assert resolved_wave_numbers(np.arange(15) * 24.0) == (7, False)


def test_alias_candidates_of_equal_points() -> None:
    ang = np.arange(16) * 22.5
    # |k J +- n| for J = 16
    assert alias_candidates(ang, 7, 40) == [9, 23, 25, 39]
    assert alias_candidates(ang, 3, 20) == [13, 19]
    assert alias_candidates(ang, 0, 40) == [16, 32]


@pytest.mark.parametrize("p_bar", [5.0, 6.0, 7.0, 8.0, 9.0])
@pytest.mark.parametrize("imperfect", [False, True])
def test_wave_numbers_of_virtual_tyre(p_bar: float, imperfect: bool) -> None:
    tr = truth(p_bar, imperfect)
    idx = tr.select("visible")
    true_n = tr.wave_number[idx]
    assert set(range(1, 8)) <= set(true_n.tolist())
    wa = wave_number_analysis(tr.modal_model("visible"))
    for m in wa.modes:
        tn = int(true_n[m.index])
        if tn <= 7:
            # resolved by 16 points: the true wave number of the full ring shape
            assert (m.n, m.aliased, m.single_harmonic) == (tn, False, True)
        elif tn == 8:
            # the Nyquist wave number: labelled, with its note
            assert m.n == 8
            assert any("Nyquist" in x for x in m.notes)
        else:
            # n = 9 (in 0-250 Hz at 5 bar) folds onto n = 7: flagged
            assert m.aliased
            assert tn in m.aliases
    if imperfect:
        # split pairs: both members, orthogonal (90/n deg apart), cos and sin labelled
        pairs = {p["n"]: p for p in wa.pairs}
        for n in range(1, 8):
            assert n in pairs
            assert {wa.modes[pairs[n]["cos"]].member, wa.modes[pairs[n]["sin"]].member} == {
                "cos",
                "sin",
            }
            # member antinodes 90/n deg apart (orthogonal members), to 2 %; n = 7, one
            # below the Nyquist wave number of 16 points, is read from the samples 2.2 % low
            assert_allclose(pairs[n]["member_angle_deg"], 90.0 / n, rtol=0.02 if n < 7 else 0.03)
    else:
        # the perfect ring driven at point 1: only the member with an antinode there
        for m in wa.modes:
            if m.n <= 7 and not m.aliased:
                assert m.member == "cos"
                assert abs(m.antinode_deg) < 1e-6


def test_aliased_modes_flagged() -> None:
    # at 5 bar, 0-260 Hz holds n = 9 (236, 240 Hz), which 16 points see as n = 7
    tr = truth(5.0, True, 260.0)
    idx = tr.select("visible")
    assert 9 in tr.wave_number[idx]
    wa = wave_number_analysis(tr.modal_model("visible"))
    flagged = [m for m in wa.modes if m.aliased]
    true_n = tr.wave_number[idx]
    assert {int(true_n[m.index]) for m in flagged} == {9}
    for m in flagged:
        assert m.n == 7
        assert 9 in m.aliases
        assert "aliased" in m.label or m.label.endswith("?")
    assert any("resolve" in w for w in wa.warnings)
    # the genuine n = 7 pair is not flagged
    assert sum(1 for m in wa.modes if m.n == 7 and not m.aliased) == 2


def test_unequal_angles_and_orientation() -> None:
    rng = np.random.default_rng(5)
    ang = np.sort(rng.uniform(0.0, 360.0, 11))
    th = np.deg2rad(ang)
    shapes = np.column_stack([np.cos(3 * (th - np.deg2rad(20.0))), np.cos(2 * th + 0.3)])
    mdl = synthetic_model(ang, 0.05 * shapes, np.array([80.0, 60.0]))
    wa = wave_number_analysis(mdl)
    by_f = sorted(wa.modes, key=lambda m: m.frequency_hz)
    assert [m.n for m in by_f] == [2, 3]
    assert_allclose(by_f[1].antinode_deg, 20.0, atol=1e-9)
    assert_allclose(by_f[0].antinode_deg, -np.degrees(0.3) / 2, atol=1e-9)
    # a pure harmonic explains all of the shape; amplitude is that of the real shape
    assert_allclose([m.fraction for m in by_f], 1.0, atol=1e-12)
    assert_allclose(by_f[1].amplitude, 0.05, rtol=1e-12)


def test_mixed_shape_flagged_not_labelled_silently() -> None:
    ang = np.arange(16) * 22.5
    th = np.deg2rad(ang)
    mixed = np.cos(2 * th) + 0.9 * np.cos(3 * th)
    mdl = synthetic_model(ang, 0.05 * mixed[:, None], np.array([70.0]))
    (m,) = wave_number_analysis(mdl).modes
    assert not m.single_harmonic
    # energy split 1 : 0.81 between n = 2 and n = 3
    assert_allclose(m.fraction, 1 / 1.81, rtol=1e-9)
    assert m.second_n == 3
    assert "not a single harmonic" in " ".join(m.notes)


def test_chi_square_with_shape_errors() -> None:
    rng = np.random.default_rng(2)
    ang = np.arange(16) * 22.5
    th = np.deg2rad(ang)
    f = np.array([90.0])
    clean = 0.05 * np.cos(3 * th)
    sigma = 1e-3  # sqrt(E|d Psi^|^2) of the second-order shape, circular complex noise
    pvals = []
    for extra in (0.0, 0.2):
        shape = clean + extra * 0.05 * np.cos(5 * th)
        mdl = synthetic_model(ang, shape[:, None], f)
        omega = mdl.poles.imag[0]
        s_psi = sigma / np.sqrt(2 * omega)  # psi = Psi^ / sqrt(2 i Omega)
        noise = s_psi / np.sqrt(2) * (rng.standard_normal(16) + 1j * rng.standard_normal(16))
        std = {
            "frequency_hz": [0.01],
            "damping_ratio": [1e-4],
            "psi_out": np.full((16, 1), s_psi),
        }
        mdl = ModalModel(
            mdl.poles,
            mdl.psi_out + noise[:, None],
            mdl.psi_in,
            "complex",
            mdl.outputs,
            mdl.inputs,
            std=std,
        )
        (m,) = wave_number_analysis(mdl).modes
        assert m.n == 3
        assert m.amplitude_std is not None
        # real amplitude of a 2-coefficient fit on 16 equal points: the complex variance
        # sigma^2 / 8 of a coefficient, half of it in the real part: sigma / 4
        assert_allclose(m.amplitude_std, sigma / 4, rtol=1e-6)
        pvals.append(m.p_value)
    assert pvals[0] is not None
    assert pvals[0] > 1e-3
    assert pvals[1] is not None
    assert pvals[1] < 1e-6


def test_missing_angles_refused() -> None:
    tr = truth(7.0, False)
    mdl = tr.modal_model("visible")
    bare = ModalModel(
        mdl.poles,
        mdl.psi_out,
        mdl.psi_in,
        outputs=[Channel(node=c.node) for c in mdl.outputs],
        inputs=mdl.inputs,
    )
    with pytest.raises(InputError, match="angle"):
        wave_number_analysis(bare)
    # the angles may be given instead
    wa = wave_number_analysis(bare, angles_deg=np.arange(16) * 22.5)
    assert_allclose(wa.n, tr.wave_number[tr.select("visible")])
    with pytest.raises(InputError, match="one per response point"):
        wave_number_analysis(bare, angles_deg=[0.0, 10.0])


def test_duplicate_angles_refused() -> None:
    with pytest.raises(InputError, match="same angle"):
        resolved_wave_numbers([0.0, 90.0, 90.0, 180.0])


def test_output_selection_and_mixed_directions() -> None:
    tr = truth(7.0, False)
    mdl = tr.modal_model("visible")
    # a model whose first output is in another direction (say tangential) is refused ...
    outs = [Channel(node=1, direction=1, angle_deg=0.0), *mdl.outputs[1:]]
    mixed = ModalModel(mdl.poles, mdl.psi_out, mdl.psi_in, outputs=outs, inputs=mdl.inputs)
    with pytest.raises(InputError, match="several directions"):
        wave_number_analysis(mixed)
    # ... unless the rows on the circumference are chosen (15 unequal points still resolve
    # n <= 7 here)
    wa = wave_number_analysis(mixed, outputs=range(1, 16))
    true_n = tr.wave_number[tr.select("visible")]
    low = true_n <= 7
    assert_allclose(wa.n[low], true_n[low])
    assert all(m.member == "cos" for m in wa.modes if true_n[m.index] <= 7)
    # n = 8 on these 15 points is no harmonic of n <= 7: flagged, not paired
    assert all(not m.single_harmonic for m in wa.modes if true_n[m.index] == 8)
    with pytest.raises(InputError, match="positions"):
        wave_number_analysis(mdl, outputs=[0, 16])
