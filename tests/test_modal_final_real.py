"""The real-mode fit's stop at 0 Hz (modal.final._RealFitter): the models it returns
against the refinement without the stop (the old path), and its evaluations."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, final, identify_modes
from tyredamp.modal.fit.fit import ModalFitter
from tyredamp.modal.search.modeset import outside_side


def _complex_modes_frf(n: int = 2000) -> FRF:
    """1 x 1 accelerance of six complex modes (residues 1 + 0.1 i, the memory
    benchmark's case on fewer lines), 40 dB noise."""
    fn = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
    z = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
    w = 2 * np.pi * fn
    p = -z * w + 1j * w * np.sqrt(1 - z**2)
    m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
    f = np.linspace(0.0, 200.0, n)[1:]
    h = m.frf(f, "accelerance").H
    rng = np.random.default_rng(0)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    return FRF(f, h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e, kind="accelerance")


def _real_modes_frf() -> FRF:
    """3 x 1 accelerance of five real modes (residues ``phi_j phi_k / (2 i Omega)``,
    spec eq. [3]), 40 dB noise."""
    fn = np.array([30.0, 55.0, 80.0, 120.0, 160.0])
    z = np.array([0.02, 0.015, 0.02, 0.01, 0.012])
    p = -z * 2 * np.pi * fn + 2j * np.pi * fn * np.sqrt(1 - z**2)
    rng = np.random.default_rng(2)
    phi = rng.normal(size=(3, 5))
    phi[0] = np.abs(phi[0]) + 0.5
    psi = phi / np.sqrt(2j * p.imag)[None, :]
    f = 0.25 * np.arange(1, 801)
    h = np.asarray(ModalModel(p, psi, psi[:1]).frf(f, "accelerance").H)
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))
    e = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    return FRF(f, h + 1e-2 * rms * e / np.sqrt(2), kind="accelerance")


def _real_both_ways(
    monkeypatch: pytest.MonkeyPatch, frf: FRF, band: tuple[float, float] | None
) -> tuple[ModalModel, ModalModel, list[int]]:
    """The real-mode model with the stop and without it (the plain fitter's
    projection), and the real-mode evaluations of each run."""
    count = [0, 0]
    plain = ModalFitter._solve

    def counted(which: int) -> Any:
        def solve(self: ModalFitter, *a: Any, **k: Any) -> Any:
            if self.kind == "real" and k.get("gradient", True):
                count[which] += 1
            return plain(self, *a, **k)

        return solve

    watched = final._RealFitter._solve
    monkeypatch.setattr(ModalFitter, "_solve", counted(0))
    new = identify_modes(frf, band=band, model="both").models["real"]
    monkeypatch.setattr(final._RealFitter, "_solve", counted(1))  # no stop: the old path
    old = identify_modes(frf, band=band, model="both").models["real"]
    monkeypatch.setattr(final._RealFitter, "_solve", watched)
    return new, old, count


def _same(a: ModalModel, b: ModalModel) -> None:
    assert np.array_equal(a.poles, b.poles)
    assert np.array_equal(a.psi_out, b.psi_out)
    assert np.array_equal(a.psi_in, b.psi_in)
    assert a.meta["warnings"] == b.meta["warnings"]
    assert a.meta["n_evaluations"] == b.meta["n_evaluations"]


def test_rejected_real_refinement_stops_early_with_the_same_model(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # complex residues: the real refinement sends a mode to 0 Hz and is rejected;
    # stopped there, the model (real residues at the complex poles) is the same
    new, old, count = _real_both_ways(monkeypatch, _complex_modes_frf(), None)
    _same(new, old)
    assert any("0.00 Hz" in w for w in new.meta["warnings"])
    assert count[0] < count[1] / 3, count


def test_accepted_real_refinement_is_unchanged(monkeypatch: pytest.MonkeyPatch) -> None:
    # real modes: the refinement is accepted and never at 0 Hz, the model is the
    # same bit for bit
    new, old, count = _real_both_ways(monkeypatch, _real_modes_frf(), None)
    _same(new, old)
    assert new.meta["refinement"] != "lsfd"
    assert count[0] == count[1] > 0


def test_pole_at_its_frequency_bound_is_out_of_the_band() -> None:
    # lines from 0.0002 Hz (1e6 lines to 200 Hz): the bound Omega = 1e-6 w_ref
    # (0.0002 Hz, plus the 1e-9 w_ref a refinement starts inside it) is in the band,
    # yet a pole held there is refused; one just above the floor is in the band
    f = np.array([2e-4, 100.0, 200.0])
    fitter = ModalFitter(f, np.ones((1, 1, 3), complex), 2, "real", [(0, 0)])
    floor = final._floor_hz(fitter)
    # the bound's frequency (1e-6 of the highest line) and the start margin, closed form
    assert floor == pytest.approx((1e-6 + 2e-9) * 200.0, rel=1e-12)  # rounding only
    band = (2e-4, 200.0)
    at = SimpleNamespace(poles=2j * np.pi * np.array([50.0, 1e-6 * 200.0]) - 1.0)
    above = SimpleNamespace(poles=2j * np.pi * np.array([50.0, 2 * floor]) - 1.0)
    assert final._problem(at, 2, 0, band) == ("", -1)  # the band alone: accepted
    why, bad = final._problem(at, 2, 0, band, floor)
    assert bad == 1
    assert "band edge (0.00 Hz)" in why
    assert final._problem(above, 2, 0, band, floor) == ("", -1)


def _watching(band: tuple[float, float]) -> final._RealFitter:
    """A real-mode fitter of 2 inputs on random data, watching 2 in-band modes and
    residual modes from index 2 on, as ``final._watched`` sets it."""
    rng = np.random.default_rng(3)
    f = np.linspace(1.0, 100.0, 200)
    H = rng.normal(size=(3, 2, f.size)) + 1j * rng.normal(size=(3, 2, f.size))
    fit = final._RealFitter(f, H, 2, "real", [(0, 0), (1, 1)])
    fit.watch, fit._best = (2, 2, band), None
    return fit


@pytest.mark.parametrize(
    ("f_res", "stops"),
    [(150.0, False), (200.0, False), (0.3, False), (250.0, True), (60.0, True), (0.2, True)],
)
def test_real_refinement_stops_at_a_residual_mode_out_of_its_range(
    f_res: float, stops: bool
) -> None:
    # band 0.5-100 Hz: residual modes lie in 0.25-0.5 Hz or 100-200 Hz (a factor 2
    # beyond the edges, modeset.outside_side); one beyond (250 Hz, 0.2 Hz) or in the
    # band (60 Hz) stops the refinement at its best point, naming it
    fit = _watching((0.5, 100.0))
    fr = np.array([20.0, 45.0, f_res])
    poles = 2 * np.pi * fr * (-0.02 + 1j)
    part = np.ones((3, 2), complex)
    ref = np.zeros(3, np.intp)
    th = fit.pack(poles, part, ref)
    w = fit.weights(None)
    if not stops:
        assert np.isfinite(fit._solve(th, 3, ref, w)["cost"])
        assert outside_side(f_res, (0.5, 100.0)) != 0
        return
    with pytest.raises(final._Stopped) as stop:
        fit._solve(th, 3, ref, w)
    assert stop.value.index == 2
    assert stop.value.freq == pytest.approx(f_res, rel=1e-12)  # Im p / 2 pi: the damped one
    assert "left the range of the residual modes" in stop.value.why
    # a point of higher cost than the best one is not watched (the iteration's point)
    fit._best = (w.tobytes(), -1.0)
    fit._solve(th, 3, ref, w)


def test_refined_drops_the_residual_mode_that_left_its_range(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # _refined refits without each residual mode that is not acceptable, and gives up
    # (for the caller's fall-back) at an in-band one
    calls: list[int] = []
    outcome = {4: ("a residual mode left the range", 3), 3: ("a pole crossed", 1)}

    def watched(fitter: Any, poles: Any, part: Any, m: int, nf: int, band: Any, **o: Any) -> Any:
        calls.append(poles.size)
        why, bad = outcome.get(poles.size, ("", -1))
        return SimpleNamespace(poles=poles), why, bad

    monkeypatch.setattr(final, "_watched", watched)
    p = np.arange(4) + 0j
    _res, why, keep = final._refined(None, p, p[:, None], 2, 0, (1.0, 2.0))  # type: ignore[arg-type]
    assert calls == [4, 3]
    assert why == "a pole crossed"
    assert keep.tolist() == [0, 1, 2]
