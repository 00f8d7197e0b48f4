"""The rim microphone of the virtual tyre (virtual/microphone.py) against closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.virtual import MeasurementLayout, RingTyre, RingTyreParameters
from tyredamp.virtual.cavity import Cavity, cavity_dispersion
from tyredamp.virtual.dispersion import difference_symbol
from tyredamp.virtual.microphone import microphone_row, pressure_frf

N = 32
BARE = MeasurementLayout(attachment_mass=0.0, attachment_damping=0.0)


def _tyre() -> RingTyre:
    return RingTyre(RingTyreParameters(), BARE, n_ring=N, cavity=Cavity())


def test_uniform_band_motion_gives_the_bulk_modulus_pressure() -> None:
    tyre = _tyre()
    x = np.zeros(tyre.n_dof)
    x[tyre.radial_dofs] = 1e-4  # band 0.1 mm outwards everywhere, air at rest
    # dV / V = b w / A: p = -rho c^2 b w / A, rho = 1.204 (1 + 7.5e5 / 101325) kg/m^3
    rho = 1.204 * (1 + 7.5e5 / 101325.0)
    closed = -rho * 343.0**2 * 0.24 * 1e-4 / 0.045
    for ang in (0.0, 90.0, 191.25):
        assert_allclose(microphone_row(tyre, ang) @ x, closed, rtol=1e-12)  # rounding


@pytest.mark.parametrize("n", [1, 3])
def test_air_harmonic_pressure_is_the_difference_of_the_flux(n: int) -> None:
    tyre = _tyre()
    assert tyre.cavity_basis is not None
    th_mid = (np.arange(N) + 0.5) * 2 * np.pi / N
    q = 1e-5 * np.sin(n * th_mid)  # volume displacement, m^3, zero mean
    r = np.linalg.lstsq(tyre.cavity_basis, q, rcond=None)[0]
    assert_allclose(tyre.cavity_basis @ r, q, atol=1e-18)  # q lies in the reduced space
    x = np.zeros(tyre.n_dof)
    x[tyre.cavity_dofs] = r
    rho = 1.204 * (1 + 7.5e5 / 101325.0)
    s = float(difference_symbol([n], N, tyre.fd_order)[0])  # staggered derivative of sin
    for k in (0, 5, 12):
        closed = -rho * 343.0**2 * 1e-5 * s * np.cos(n * k * 2 * np.pi / N) / (0.39 * 0.045)
        assert_allclose(
            microphone_row(tyre, k * 360.0 / N) @ x, closed, rtol=1e-9, atol=1e-9 * abs(closed)
        )  # rounding of the reduced basis


def test_pressure_frf_peaks_at_the_coupled_cavity_mode() -> None:
    p = RingTyreParameters()
    tyre = _tyre()
    s1 = float(difference_symbol([1], N, tyre.fd_order)[0])
    r, ea, ei, t0 = p.radius, p.membrane_stiffness, p.bending_stiffness, p.hoop_tension
    qaa = (ea + t0) / r**2 + ei * s1**4 / r**4 + t0 * (s1**2 - 1) / r**2 + p.radial_stiffness
    qac = (ea + t0) * s1 / r**2 + ei * s1**3 / r**4
    qcc = (ea + t0) * s1**2 / r**2 + ei * s1**2 / r**4 + p.tangential_stiffness
    closed = cavity_dispersion(
        np.array([[qaa, qac], [qac, qcc]]), s1, mass_per_length=p.mass_per_length,
        radius=r, cavity=Cavity(), pressure=p.pressure, band_width=p.width,
    )[1]  # fmt: skip
    f = np.arange(closed - 1.0, closed + 1.0, 0.01)
    h = np.abs(pressure_frf(tyre, f, 0.0)[0])
    # the peak of |p / F| at the band-air n = 1 mode of the 3x3 closed form; the
    # damping (zeta < 1 %) and the tails of the other modes move it by hundredths of a Hz
    assert_allclose(f[int(np.argmax(h))], closed, atol=0.1)
    assert closed > 140.0  # above the rigid-walled 140 Hz (the band's spring in series)


def test_microphone_errors() -> None:
    with pytest.raises(InputError, match="no air cavity"):
        microphone_row(RingTyre(n_ring=N))
    with pytest.raises(InputError, match=r"multiple of 11\.25 deg"):
        microphone_row(_tyre(), 5.0)


def test_rig_records_the_microphone_pressure() -> None:
    from tyredamp.virtual import run_modal_test

    tyre = RingTyre(RingTyreParameters(), MeasurementLayout(), n_ring=N, cavity=Cavity())
    test = run_modal_test(tyre, period=1.0, n_periods=1, snr_db=None, microphone_deg=0.0)
    d = test.data
    assert d.quantities[-1] == "pressure"
    assert d.channels[-1].name == "P1"
    assert d.response_indices == list(range(1, 17))  # the FRF estimators see the accelerometers
    x = np.fft.rfft(d.data, axis=1)
    f = np.fft.rfftfreq(d.data.shape[1], 1.0 / d.sample_rate)
    sel = (f > 20) & (f < 190)
    h = x[-1, sel] / x[0, sel]
    exact = pressure_frf(tyre, f[sel], 0.0)[0]
    # one steady-state period, no noise: the continuous force and the exact response,
    # filtered alike, give the exact FRF to rounding (measured 1.2e-13)
    assert_allclose(h, exact, rtol=1e-10)


def test_microphone_determines_the_band_air_damping_term() -> None:
    import math
    from dataclasses import replace

    from tyredamp.damping import identify_damping
    from tyredamp.damping.diagnostics import collinear_pairs
    from tyredamp.frf import Channel

    tyre = RingTyre(RingTyreParameters(), MeasurementLayout(), n_ring=N, cavity=Cavity())
    tr = tyre.truth()
    vis = tr.select("visible")
    mm = tr.modal_model("visible")
    cm = tyre.system.complex_modes()
    psi = cm.psi[:, [int(np.argmin(np.abs(cm.poles - p))) for p in mm.poles]]
    mic = microphone_row(tyre, 0.0) @ psi
    w = math.sqrt(np.mean(np.abs(mm.psi_out) ** 2) / np.mean(np.abs(mic) ** 2))
    both = replace(
        mm,
        psi_out=np.vstack([mm.psi_out, w * mic]),
        outputs=(*mm.outputs, Channel(node=18, direction=0, name="P1")),
    )
    # the band's and the air's n = 1 modes look alike at the 16 radial points
    assert len(collinear_pairs(np.real(mm.psi_out))) == 1
    assert not collinear_pairs(np.real(both.psi_out))
    c_true = tr.modal_damping[np.ix_(vis, vis)]
    err = {}
    for name, model in (("acc", mm), ("mic", both)):
        c = identify_damping(model, "improved", n_samples=0).modal
        err[name] = np.linalg.norm(c - c_true) / np.linalg.norm(c_true)
    # exact modes, no noise: the pair's term is ill-conditioned without the microphone
    # (error above 100 %) and determined with it (eq. [18] to first order: a few %)
    assert err["acc"] > 1.0
    assert err["mic"] < 0.1


def test_simulate_radial_microphone_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tyredamp.cli import main
    from tyredamp.io import read_timedata

    out = tmp_path / "mic.npz"
    main(["simulate", "radial", "--periods", "1", "--microphone", "0", "-o", str(out)])
    d = read_timedata(out)
    assert d.quantities[-1] == "pressure"
    assert d.units[-1] == "Pa"
    capsys.readouterr()
    # the microphone needs the cavity: one line, exit 2, nothing written
    bad = tmp_path / "bad.npz"
    with pytest.raises(SystemExit) as err:
        main(["simulate", "radial", "--no-cavity", "--microphone", "0", "-o", str(bad)])
    assert err.value.code == 2
    assert "tyredamp: error: --microphone" in capsys.readouterr().err
    assert not bad.exists()
