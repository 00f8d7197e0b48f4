"""The random physical structures of the speed benchmark (``benchmarks/perf_physical.py``).

Every figure is checked against an independent computation: the undamped
modes by ``scipy.linalg.eigh``, the FRFs by a direct solve of the dynamic
stiffness, the peaks by the single-mode term of Popov & Geng eq. [10].
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _load(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses resolve their module by name
    spec.loader.exec_module(mod)
    return mod


phys = _load("perf_physical")


@pytest.fixture(scope="module", params=[(4, 1, 8, 0), (8, 2, 12, 3), (16, 3, 20, 5)])
def system(request: pytest.FixtureRequest) -> Any:
    n_out, n_in, n_modes, seed = request.param
    return phys.physical_system(n_out, n_in, n_modes, seed=seed)


def test_spectrum_and_points(system: Any) -> None:
    s = system.system
    n_modes = system.in_band.size
    f_u = np.sqrt(np.clip(sla.eigh(s.K, s.M, eigvals_only=True), 0, None)) / (2 * np.pi)
    assert np.count_nonzero(f_u <= system.f_hi) == n_modes
    assert f_u[0] >= phys.BAND_LO * system.f_hi * (1 - 1e-9)  # rounding of eigh only
    assert f_u[n_modes - 1] <= phys.BAND_HI * system.f_hi * (1 + 1e-9)
    assert f_u[n_modes] >= 1.1 * system.f_hi * (1 - 1e-9)
    assert np.all(np.linalg.eigvalsh(s.C) >= -1e-9 * np.max(np.abs(s.C)))
    assert not s.is_proportional()
    assert system.info["offdiag_share"] > 0.1
    assert set(system.inputs) <= set(system.outputs)
    assert s.n_dof > system.outputs.size  # some DOFs unmeasured


def test_frf_modal_sum_is_exact(system: Any) -> None:
    f = np.linspace(1.0, 260.0, 97)
    kw = {"kind": "accelerance", "outputs": list(system.outputs), "inputs": list(system.inputs)}
    modal = system.system.frf(f, method="modal", **kw).H
    direct = system.system.frf(f, method="direct", **kw).H
    # eq. [10] over all 2 n_dof modes equals the direct solve up to rounding of the eigensolver
    assert_allclose(modal, direct, rtol=1e-7, atol=1e-9 * np.max(np.abs(direct)))


def test_close_pair_and_weak_mode(system: Any) -> None:
    cm = system.system.complex_modes()
    f = cm.frequency_hz[system.in_band]
    z = cm.damping_ratio[system.in_band]
    i, j = system.pair
    assert j == i + 1
    bw = np.mean(2 * z[[i, j]] * f[[i, j]])
    # designed 1-2 bandwidths from the first-order damping (eq. [15]); the coupled
    # pair moves apart or together by up to about half a bandwidth
    assert 0.4 <= (f[j] - f[i]) / bw <= 2.6
    others = f[np.arange(f.size) != j]
    # the slots are MIN_RATIO (6 %) apart undamped; damping and coupling move them < 1 %
    assert np.min(others[1:] / others[:-1]) >= phys.MIN_RATIO - 0.01
    # the weak mode 20-26 dB below the median peak by design; the turn moves its damping
    assert system.info["weak_below_median_db"] > 18.0
    assert system.weak not in system.pair
    # the weak mode rests at every dashpot: C phi_w = (alpha M + beta K) phi_w, a classical mode
    mpc = system.info["mpc_min"]
    assert mpc < 0.999  # the others are complex
    psi_w = cm.psi[:, system.in_band[system.weak]]
    ratio = psi_w / psi_w[np.argmax(np.abs(psi_w))]  # real for a classical mode
    assert_allclose(ratio.imag, 0.0, atol=1e-9)  # rounding of the eigensolver


def test_weaken_keeps_orthonormal_and_sets_drive_amplitude() -> None:
    rng = np.random.default_rng(7)
    n = 12
    m = rng.uniform(0.5, 2.0, n)
    q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    points = np.array([2, 5, 7])
    partners = np.array([8, 9, 10, 11])
    scale = np.array([0.1, 0.1, 0.0])  # two drive points at 10 %, one dashpot DOF at rest
    out = phys._weaken(q, m, 3, partners, points, scale)
    assert_allclose(out.T @ out, np.eye(n), atol=1e-12)  # rounding only
    phi_old, phi_new = q / np.sqrt(m)[:, None], out / np.sqrt(m)[:, None]
    # rounding only
    assert_allclose(phi_new[points, 3], scale * phi_old[points, 3], atol=1e-12)
    untouched = [k for k in range(n) if k not in (3, 8, 9, 10, 11)]
    assert_allclose(out[:, untouched], q[:, untouched], rtol=0, atol=0)
    # the largest share of the old shape: no unit vector of the span meeting the
    # constraints is closer (random members of the feasible set, built independently)
    s = q[:, [3, 8, 9, 10, 11]]
    b = s[points] / np.sqrt(m[points])[:, None]
    a_p = np.linalg.pinv(b) @ (scale * b[:, 0])
    null = sla.null_space(b)
    r = np.sqrt(1 - a_p @ a_p)
    share = float(s[:, 0] @ out[:, 3])
    for z in rng.normal(size=(200, null.shape[1])):
        a = a_p + r * null @ (z / np.linalg.norm(z))
        assert a[0] <= share + 1e-12


def test_peak_snr_against_the_mode_term(system: Any) -> None:
    cm = system.system.complex_modes()
    p = cm.poles[system.in_band]
    po = cm.psi[np.ix_(system.outputs, system.in_band)]
    pi = cm.psi[np.ix_(system.inputs, system.in_band)]
    f = np.linspace(1.0, system.f_hi, 400)
    exact = system.system.frf(
        f, "accelerance", list(system.outputs), list(system.inputs), method="direct"
    ).H
    got = phys.mode_peak_snr_db(p, po, pi, exact, 40.0)
    w = p.imag
    r = po[:, None, :] * pi[None, :, :]
    term = r / (1j * w - p) + np.conj(r) / (1j * w - np.conj(p))  # eq. [10], one mode
    noise = np.sqrt(np.mean(np.abs(exact) ** 2, axis=-1)) * 10 ** (-40.0 / 20)
    ref = 20 * np.log10(np.max(np.abs(term) * w**2 / noise[:, :, None], axis=(0, 1)))
    # the conjugate term left out: relative size zeta / 2 <= 3 %, 0.3 dB
    assert_allclose(got, ref, atol=0.3)


def test_physical_case(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(BENCH))
    common = _load("perf_common")
    case = common.physical_case(4, 1, 400, 8, snr_db=40.0, seed=2)
    assert case.poles.size == 8
    assert case.psi.shape == (4, 8)
    assert case.frf.H.shape == (4, 1, 401)
    assert case.frf.drive_points()  # the drive point is measured
    assert np.all((case.frequency_hz > case.band[0]) & (case.frequency_hz < case.band[1]))
    e = np.asarray(case.frf.H) - case.exact
    rms = np.sqrt(np.mean(np.abs(case.exact) ** 2, axis=-1))
    # 401 complex noise samples per FRF: the RMS is within 4 standard errors (~ 1/sqrt(2 * 401))
    ratio = np.sqrt(np.mean(np.abs(e) ** 2, axis=-1)) / (rms * 10 ** (-40.0 / 20))
    assert_allclose(ratio, 1.0, atol=4 / np.sqrt(2 * 401))
