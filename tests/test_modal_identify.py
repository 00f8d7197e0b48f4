"""Automatic identification on ring-like systems with double modes and on the virtual tyre."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tyredamp.exceptions import InputError
from tyredamp.frf import FRF, Channel
from tyredamp.mechanics import MCKSystem
from tyredamp.modal.identify import identify_modes
from tyredamp.modal.statistics.indicators import mac, relative_error, rmsd

F = np.arange(0.25, 200.01, 0.25)
N_RING = 32


def ring_system(nonproportional: bool = True, imperfect: bool = False) -> MCKSystem:
    """Circulant ring of 32 masses (0.5 kg) with double modes n = 1..15.

    Springs: 530.7 kN/m between neighbours, 19.57 kN/m to ground, which puts
    n = 0..7 at about 31, 45, 71, 100, 129, 158, 185, 209 Hz (tyre-like).
    Damping: Rayleigh part (about 2-4 %), plus, when ``nonproportional``, a
    local dashpot of 60 N s/m at node 0 (the drive point) and 30 N s/m at
    node 16 (opposite; both on the symmetry axis of the drive, so the members
    with a node at the drive point stay unexcited). ``imperfect`` adds 0.15 kg
    at node 3, splitting every pair.
    """
    n = N_RING
    M = 0.5 * np.eye(n)
    if imperfect:
        M[3, 3] += 0.15
    K = np.zeros((n, n))
    for i in range(n):
        j = (i + 1) % n
        K[i, i] += 530.7e3 + 19.572e3 / 2
        K[j, j] += 530.7e3 + 19.572e3 / 2
        K[i, j] -= 530.7e3
        K[j, i] -= 530.7e3
    C = 8.0 * M + 3e-5 * K
    if nonproportional:
        C[0, 0] += 60.0
        C[16, 16] += 30.0
    return MCKSystem(M, C, K)


def ring_frf(
    sys_: MCKSystem, inputs: list[int], seed: int | None, snr_db: float = 40.0, step: int = 1
) -> FRF:
    outs = list(range(0, N_RING, 2))
    chans = [Channel(node=i + 1, angle_deg=360.0 * i / N_RING) for i in outs]
    frf = sys_.frf(
        F[::step],
        kind="accelerance",
        outputs=outs,
        inputs=inputs,
        output_channels=chans,
        input_channels=[Channel(node=i + 1) for i in inputs],
    )
    if seed is None:
        return frf
    rng = np.random.default_rng(seed)
    h = frf.H
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    e = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    return frf.with_H(h + 10 ** (-snr_db / 20) * rms * e / np.sqrt(2))


def visible_modes(sys_: MCKSystem, inputs: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Poles and output shapes of the in-band modes the drive points excite."""
    cm = sys_.complex_modes()
    amp = np.max(np.abs(cm.psi[inputs]), axis=0) / np.max(np.abs(cm.psi), axis=0)
    sel = (cm.frequency_hz <= 200.0) & (amp > 0.01)
    return cm.poles[sel], cm.psi[::2][:, sel]


def _check(
    model_poles: np.ndarray,
    model_psi: np.ndarray,
    poles: np.ndarray,
    psi: np.ndarray,
    f_tol: float,
    z_tol: float,
    mac_min: float,
) -> None:
    assert model_poles.size == poles.size  # every mode, no spurious one
    f_id, f_tr = np.abs(model_poles), np.abs(poles)
    z_id, z_tr = -model_poles.real / f_id, -poles.real / f_tr
    assert np.all(np.abs(f_id / f_tr - 1) < f_tol)
    assert np.all(np.abs(z_id / z_tr - 1) < z_tol)
    assert np.all(np.diag(mac(model_psi, psi)) > mac_min)


def test_ring_nonproportional_one_drive_point() -> None:
    sys_ = ring_system()
    poles, psi = visible_modes(sys_, [0])
    res = identify_modes(ring_frf(sys_, [0], seed=1), band=(0.0, 200.0))
    c, r = res.models["complex"], res.models["real"]
    # requirement: f within 0.1 %, zeta within 5 %, MAC > 0.99 at 40 dB
    _check(c.poles, c.psi_out, poles, psi, 1e-3, 0.05, 0.99)
    assert c.meta["relative_error"] < 0.0105  # noise is 1 % of each FRF's RMS
    assert r.meta["rmsd"] > 1.5 * c.meta["rmsd"]  # real modes cannot fit the phase
    assert c.residual_modes is not None  # n = 7 at 209 Hz is kept as a residual mode
    assert np.all(c.std["frequency_hz"] > 0)
    assert c.std["psi_out"].shape == c.psi_out.shape
    assert np.all(np.asarray(c.meta["mpc"]) <= 1.0)


def test_fit_indicators_equal_the_indicator_functions() -> None:
    # identify_modes computes RMSD (eq. [19]), its per-FRF values, the relative
    # error and the discrepancy from one |H_model - H|^2 array; the references are
    # the indicator functions applied to the model's own synthesised FRFs
    sys_ = ring_system()
    data = ring_frf(sys_, [0], seed=4)
    res = identify_modes(data, band=(0.0, 200.0), model="complex")
    c = res.models["complex"]
    band = data.band(*res.band_hz)
    band = band.select_lines(np.flatnonzero(band.frequency > 0))
    hm = np.asarray(c.frf(band.frequency, kind=band.kind).H)
    h = np.asarray(band.H)
    # the same sums in another order: round-off only
    assert_allclose(c.meta["rmsd"], rmsd(h, hm), rtol=1e-9)
    assert_allclose(c.meta["rmsd_per_frf"], rmsd(h, hm, axis=-1), rtol=1e-9)
    assert_allclose(c.meta["relative_error"], relative_error(h, hm), rtol=1e-9)
    disc = np.sqrt(np.mean(np.abs(hm - h) ** 2, axis=(0, 1)))
    assert_allclose(res.discrepancy["complex"], disc, rtol=1e-9)


def test_ring_proportional_rmsd_equal_within_noise() -> None:
    sys_ = ring_system(nonproportional=False)
    res = identify_modes(ring_frf(sys_, [0], seed=2), band=(0.0, 200.0))
    c, r = res.models["complex"], res.models["real"]
    poles, _ = visible_modes(sys_, [0])
    # proportional: the pairs stay exactly degenerate, one member per pair responds
    f_true = np.unique(np.round(np.abs(poles) / (2 * np.pi), 6))
    assert_allclose(r.frequency_hz, f_true, rtol=1e-3)
    # same data, both models fit to the noise: RMSD equal within 2 %
    assert_allclose(r.meta["rmsd"], c.meta["rmsd"], rtol=0.02)
    assert r.meta["warnings"] == []


def test_ring_imperfect_two_drive_points_finds_both_pair_members() -> None:
    sys_ = ring_system(imperfect=True)
    inputs = [0, 6]
    poles, psi = visible_modes(sys_, inputs)
    # 0.5 Hz lines keep the test fast (two inputs, 14 modes plus residual modes)
    frf = ring_frf(sys_, inputs, seed=3, step=2)
    res = identify_modes(frf, band=(0.0, 200.0), model="complex")
    c = res.models["complex"]
    _check(c.poles, c.psi_out, poles, psi, 1e-3, 0.05, 0.99)
    assert c.psi_in.shape == (2, poles.size)
    # reciprocity scaling: psi_in equals psi_out at the drive points
    assert_allclose(c.psi_in[0], c.psi_out[0], rtol=0.02)


def test_given_frequencies_and_mode_count() -> None:
    sys_ = ring_system()
    frf = ring_frf(sys_, [0], seed=4)
    poles, _ = visible_modes(sys_, [0])
    f_true = np.abs(poles) / (2 * np.pi)
    res = identify_modes(frf, band=(0.0, 200.0), model="complex", frequencies=f_true[:3] * 1.01)
    c = res.models["complex"]
    assert_allclose(c.frequency_hz, f_true[:3], rtol=1e-3)
    # the other modes are fitted as residual modes, not reported
    assert c.residual_modes is not None
    assert c.residual_modes.n_modes >= 4
    res = identify_modes(frf, band=(0.0, 200.0), model="real", n_modes=3)
    assert res.models["real"].n_modes == 3
    with pytest.raises(InputError, match="frequencies"):
        identify_modes(frf, band=(0.0, 200.0), frequencies=[300.0])
    with pytest.raises(InputError, match="band"):
        identify_modes(frf, band=(50.0, 10.0))
    with pytest.raises(InputError, match="model"):
        identify_modes(frf, model="hybrid")  # type: ignore[arg-type]


def test_virtual_tyre_default() -> None:
    tyre_mod = pytest.importorskip("tyredamp.virtual")
    # a strongly non-proportional tyre: a 350 N s/m local damper at the drive point, half of
    # its off-diagonal C' kept (the realistic 30 N s/m tip leaves the bare ring nearly real)
    lay = tyre_mod.MeasurementLayout(attachment_damping=350.0)
    tyre = tyre_mod.RingTyre(layout=lay, nonproportionality=0.5)
    tr = tyre.truth((0.0, 200.0))
    vis = tr.select("visible")
    frf = tyre.system.frf(
        F,
        kind="accelerance",
        outputs=list(tyre.point_dofs),
        inputs=list(tyre.drive_dofs),
        output_channels=tyre.output_channels,
        input_channels=tyre.input_channels,
    )
    rng = np.random.default_rng(11)
    rms = np.sqrt(np.mean(np.abs(frf.H) ** 2, axis=2, keepdims=True))
    noise = (rng.normal(size=frf.H.shape) + 1j * rng.normal(size=frf.H.shape)) / np.sqrt(2)
    res = identify_modes(frf.with_H(frf.H + 0.01 * rms * noise), band=(0.0, 200.0))
    c, r = res.models["complex"], res.models["real"]
    _check(c.poles, c.psi_out, tr.poles[vis], tr.psi_points[:, vis], 1e-3, 0.05, 0.99)
    assert c.meta["max_order"] == 60  # sized and settled at the starting order
    # the paper found about 2x; this tyre (nonproportionality 0.5) gives about 4x
    assert r.meta["rmsd"] > 2 * c.meta["rmsd"]


def test_many_outputs_use_compressed_search_and_full_final_fit() -> None:
    from tyredamp.mechanics import modal_sum_receptance, pole_from_frequency_damping
    from tyredamp.modal.fit.fit import ModalFitter, compress_outputs

    rng = np.random.default_rng(7)
    f = np.linspace(0.5, 100.0, 400)
    p = pole_from_frequency_damping(
        [12.0, 31.0, 55.0, 78.0, 120.0], [0.02, 0.01, 0.015, 0.01, 0.02]
    )
    psi = (rng.normal(size=(120, 5)) + 0.3j * rng.normal(size=(120, 5))) * 1e-2
    psi[0] = np.abs(psi[0]) + 0.01
    h = modal_sum_receptance(f, p, psi, psi[:1])
    hc = compress_outputs(h, 20)
    assert hc.shape == (20, 1, 400)
    # a real orthogonal mix of outputs keeps the modal form: exact poles fit exactly
    fit = ModalFitter(f, hc, 0, "complex", [], unit_weights=True)
    res = fit.fit(p, np.ones((5, 1)), refine=False)
    assert res.cost < 1e-20 * np.sum(np.abs(hc) ** 2)  # round-off of the exact model
    noise = 1e-3 * np.sqrt(np.mean(np.abs(h) ** 2)) * rng.normal(size=h.shape)
    frf = FRF(f, h + noise, outputs=range(1, 121), inputs=[1])
    out = identify_modes(frf, model="complex")
    c = out.models["complex"]
    assert_allclose(c.poles, p[:4], rtol=1e-4)  # 120 Hz is above the band: a residual mode
    assert c.psi_out.shape == (120, 4)  # the final fit uses every output


def many_mode_frf(n_out: int, n_lines: int, n_modes: int, seed: int = 0) -> tuple[FRF, np.ndarray]:
    """Accelerances of ``n_modes`` complex modes in 10-190 Hz plus two above 200 Hz.

    As ``benchmarks/perf_common.synthetic_case``: frequencies evenly spread with
    +-1 % jitter, damping 0.5-3 %, shapes ``a + 0.3 i b`` (non-proportional), one
    drive point at output 1; lines ``df .. 200 Hz + df`` with ``df = 200 / n_lines``,
    complex noise at 1 % of each FRF's RMS. Returns the FRFs and the in-band poles.
    """
    from tyredamp.mechanics import pole_from_frequency_damping
    from tyredamp.modal import ModalModel

    rng = np.random.default_rng(seed)
    f_n = np.linspace(10.0, 190.0, n_modes) * (1 + 0.01 * rng.uniform(-1, 1, n_modes))
    f_n = np.sort(np.concatenate([f_n, [215.0, 240.0]]))
    p = pole_from_frequency_damping(f_n, rng.uniform(0.005, 0.03, f_n.size))
    psi = (rng.normal(size=(n_out, f_n.size)) + 0.3j * rng.normal(size=(n_out, f_n.size))) * 1e-2
    psi[0] = (np.abs(psi[0].real) + 0.5e-2) + 0.3j * psi[0].imag
    model = ModalModel(
        p, psi, psi[:1], mode_kind="complex", outputs=range(1, n_out + 1), inputs=[1]
    )
    df = 200.0 / n_lines
    frf = model.frf(df * np.arange(1, n_lines + 2), kind="accelerance")
    h = np.asarray(frf.H)
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=2, keepdims=True))
    e = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    return frf.with_H(h + 0.01 * rms * e / np.sqrt(2)), p[:n_modes]


def test_automatic_order_resolves_a_band_full_of_modes() -> None:
    # 30 modes in the band: order 60 spreads its 30 root pairs over them and few
    # columns persist; the sizing rule alone stopped there (4 modes identified).
    # The unsettled diagram triggers a trial order (128) that resolves the band
    frf, poles = many_mode_frf(32, 1000, 30)
    band = (float(frf.frequency[0]), 200.0)
    c = identify_modes(frf, band=band, model="complex").models["complex"]
    assert c.meta["max_order"] > 60
    assert c.n_modes == poles.size  # every mode, no spurious one
    f_id, f_tr = np.sort(c.frequency_hz), np.sort(np.abs(poles) / (2 * np.pi))
    assert np.all(np.abs(f_id / f_tr - 1) < 1e-3)
    z_tr = (-poles.real / np.abs(poles))[np.argsort(np.abs(poles))]
    z_id = c.damping_ratio[np.argsort(c.frequency_hz)]
    assert np.all(np.abs(z_id / z_tr - 1) < 0.05)
    # an explicit order is used as given (here too low for the band)
    low = identify_modes(frf, band=band, model="complex", max_order=60, search=False).models[
        "complex"
    ]
    assert low.meta["max_order"] == 60
    assert low.n_modes < 20
    # the residual-driven search recovers modes that the low-order diagram missed
    found = identify_modes(frf, band=band, model="complex", max_order=60).models["complex"]
    assert low.n_modes < found.n_modes <= poles.size


def test_automatic_order_trial_that_finds_nothing_keeps_the_diagram(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import tyredamp.modal.poles.order as ident

    frf = ring_frf(ring_system(), [0], seed=1)
    ref = identify_modes(frf, band=(0.0, 200.0), model="complex")
    # every diagram counts as unsettled: the ring's trial order (128) only adds
    # noise poles (fewer of the stable poles persist), so order 60 and its
    # diagram stay, and so does the result
    monkeypatch.setattr(ident, "_SETTLED_SHARE", 1.01)
    res = identify_modes(frf, band=(0.0, 200.0), model="complex")
    assert ref.models["complex"].meta["max_order"] == 60
    assert res.models["complex"].meta["max_order"] == 60
    assert_allclose(res.poles.poles, ref.poles.poles, rtol=0, atol=0)
    assert_allclose(res.models["complex"].poles, ref.models["complex"].poles, rtol=0, atol=0)
