"""The virtual modal test rig of paper 000: shaker, periodic chirp, 16 accelerometers.

The tyre (its full ring discretisation) is driven radially at the drive
point(s) by a periodic chirp and the radial accelerations at the measured
points are recorded together with the forces, with independent Gaussian
noise on every channel (``direction="tangential"``: driven and measured
along the circumference, :mod:`~tyredamp.virtual.tangential`, the test that
sees the belt's wind-up mode). The response is the exact steady state of
the continuous system (or, started at rest, the exact modal integration of
:func:`tyredamp.mechanics.time_response`) to the linearly interpolated
force samples.

Excitation
----------
``excitation="chirp"`` (default): the periodic linear sweep of
:func:`tyredamp.signal.periodic_chirp` (the chirp of paper 000; its band
edges are moved to DFT lines so that it is continuous from period to period).
``"multisine"``: the band-limited Schroeder multisine of
:func:`~tyredamp.virtual.excitation.schroeder_multisine` (flat spectrum on the
band lines, nothing elsewhere). ``data.meta["lines"]`` lists the DFT lines of one
period inside ``band``.

Steady state
------------
By default the record is the exact periodic steady state of the continuous
system driven by the continuous force: at each harmonic ``l`` of the period
the force's Fourier coefficient times the receptance
``(K - omega_l^2 M + i omega_l C)^-1`` (spec eq. [1]) is the response's
(:func:`~tyredamp.mechanics.continuous_periodic_lines`). The
noise-free record is exactly periodic, so it is that period repeated, plus
independent noise.
``initial_state="rest"`` instead simulates every period from rest with
:func:`~tyredamp.mechanics.time_response` (exact modal integration of the
first-order-hold force; the transient decays with the slowest mode, about
``1 / sigma_min`` s) and drops ``settle_periods`` leading periods, or keeps
them and says so in ``data.acquisition.settle_samples``.
(:func:`periodic_initial_state` gives the state from which that time
stepping starts periodic.)

Sampling
--------
The force is generated ``oversample`` times faster than ``sample_rate``
(``fs_sim``) and interpolated linearly between those samples (first-order
hold): the shaker's force is the piecewise-linear signal, whose Fourier
coefficients are the DFT of the samples times ``sinc^2(pi l / N)``
(:func:`~tyredamp.mechanics.foh_fourier_lines`). The acquisition acts like
an ideal laboratory: the force gauge measures that continuous force at the
structure, and ideal anti-alias filters, the same on every channel, keep the
harmonics below ``sample_rate / 2`` of force and responses before both are
sampled at ``sample_rate``. In the periodic steady state the noise-free
cyclic FRF is therefore the exact FRF, ``A(f)`` of ``test.truth.frf`` at
every line, to rounding (checked in the tests). ``force_rms`` is the RMS of
the force samples; the recorded force's is about ``sinc^2(pi f_max /
fs_sim)`` of it (0.9995 for the defaults, ``f_max`` the band's top).

With ``initial_state="rest"`` the response is the sampled output of the
time stepping at ``fs_sim`` and the force channel its samples; the filter is
applied per simulated period (it smears the discarded transient slightly),
and sampling folds the response's harmonics above ``fs_sim / 2``: once
settled, the noise-free cyclic FRF is ``sum_m A(f + m fs_sim)
sinc^2(f / fs_sim + m)``, which differs from ``A(f)`` by about
``(pi f / fs_sim)^2 / 3 * |A(f) - M^-1|`` plus folded extensional
resonances (below 1 % of ``|A|`` at every line of the default test).

Several drive points
--------------------
All shakers stay attached (their masses and dampers are part of the tyre)
and the record is a sequence of *runs*, each ``n_periods`` periods of steady
state: ``drive_mode="sequential"`` drives one input per run (classical
roving-shaker multi-reference test); ``"simultaneous"`` drives all inputs in
every run with the same signal times the signs of a Hadamard matrix
(orthogonal multisines, :func:`~tyredamp.virtual.excitation.hadamard_drive_matrix`),
so the input cross-spectral matrix summed over the runs is diagonal. Either
way every period of the record is a steady-state period and an H1 estimator
over all periods (all runs) recovers every FRF column;
``data.acquisition.run_starts`` gives the first sample of each run.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import lfilter

from .._validate import as_band, check_positive
from ..exceptions import InputError
from ..frf import FRF, Channel, FRFKind
from ..mechanics import (
    ComplexModes,
    MCKSystem,
    TimeResponse,
    continuous_periodic_lines,
    step_coefficients,
    time_response,
)
from ..signal.excitation import band_lines, periodic_chirp
from ..timedata import Acquisition, TimeData
from .excitation import hadamard_drive_matrix, schroeder_multisine
from .microphone import microphone_node, microphone_row
from .ring import RingTyre
from .tangential import tangential_tyre
from .truth import TyreTruth

__all__ = ["VirtualModalTest", "periodic_initial_state", "run_modal_test"]

DriveMode = Literal["sequential", "simultaneous"]
InitialState = Literal["periodic", "rest"]
ExcitationKind = Literal["chirp", "multisine"]
Direction = Literal["radial", "tangential"]


@dataclass(frozen=True, eq=False)
class VirtualModalTest:
    """Result of :func:`run_modal_test`: the measured time data and the truth.

    Attributes
    ----------
    data : TimeData
        Force channels (one per drive point, quantity ``"force"``, N) then
        acceleration channels (one per measured point, ``"acceleration"``,
        m/s^2). ``data.acquisition`` states ``period_samples``,
        ``settle_samples``, ``n_averages`` (periods per run), ``run_starts``,
        ``band_hz`` and ``excitation`` (signal name); ``data.meta`` notes
        ``drive_matrix``, ``lines``, ``snr_db``, ``noise_std``, ``seed`` and
        more.
    truth : TyreTruth
        Exact modes, damping and FRFs of the tested tyre in the test band.
    tyre : RingTyre
        The tested tyre.
    drive_matrix : ndarray, shape (n_runs, n_inputs)
        Amplitude factor of each input in each run (0 or +-1).
    """

    data: TimeData
    truth: TyreTruth
    tyre: RingTyre
    drive_matrix: NDArray[np.float64]

    @property
    def acquisition(self) -> Acquisition:
        """The acquisition record of :attr:`data` (period, runs, settle samples, band)."""
        return self.data.acquisition

    @property
    def meta(self) -> dict[str, Any]:
        """A copy of the notes of :attr:`data` with the acquisition fields as keys.

        ``period_samples``, ``settle_samples``, ``run_starts``, ``band_hz``,
        ``n_averages`` (periods per run), ``excitation`` come from
        :attr:`acquisition`; the rest (``lines``, ``drive_matrix``,
        ``snr_db``, ...) from ``data.meta``.
        """
        acq = self.data.acquisition
        return {
            **self.data.meta,
            **acq.to_dict(),
            "settle_samples": acq.settle_samples,
            "run_starts": list(acq.run_starts),
        }

    @property
    def n_runs(self) -> int:
        """Number of runs (one per drive point when sequential)."""
        return int(self.drive_matrix.shape[0])

    @property
    def period_samples(self) -> int:
        """Samples per excitation period."""
        p = self.data.acquisition.period_samples
        if p is None:  # pragma: no cover - the rig always states it
            raise InputError("data.acquisition: no period_samples")
        return p

    @property
    def frequency_lines(self) -> NDArray[np.float64]:
        """Excited frequencies in Hz (DFT lines of one period), shape (K,)."""
        lines = np.asarray(self.data.meta["lines"], dtype=float)
        return lines * self.data.sample_rate / self.period_samples

    def run_data(self, run: int) -> TimeData:
        """The samples of one run (including its settle samples, if kept) as a TimeData."""
        if not isinstance(run, int | np.integer) or not 0 <= run < self.n_runs:
            raise InputError(f"run: expected an integer in 0..{self.n_runs - 1}, got {run!r}")
        acq = self.data.acquisition
        starts = [*acq.run_starts, self.data.n_samples]
        seg = self.data.data[:, starts[run] : starts[run + 1]]
        meta = dict(self.data.meta)
        meta["drive_matrix"] = [self.drive_matrix[run].tolist()]
        return TimeData(
            seg,
            self.data.sample_rate,
            self.data.channels,
            self.data.quantities,
            meta,
            acquisition=replace(acq, run_starts=(0,)),
        )

    def true_frf(self, frequency: ArrayLike, kind: FRFKind = "accelerance") -> FRF:
        """Exact FRF of the tested tyre at the points, shape (n_points, n_drive, n_freq)."""
        return self.truth.frf(frequency, kind)


def _modal_propagate(
    cm: ComplexModes,
    psi_in: NDArray[np.complex128],
    force: NDArray[np.float64],
    h: float,
    q0: NDArray[np.complex128],
) -> NDArray[np.complex128]:
    """Modal state after ``force.shape[1] - 1`` steps from ``q0`` (first-order hold).

    The recursion ``q_{k+1} = Phi q_k + (E0 - E1) g_k + E1 g_{k+1}`` with
    ``g = psi_in^T f`` is that of :func:`tyredamp.mechanics.time_response`.
    """
    p = cm.poles
    phi, e0, e1 = step_coefficients(p, h)
    g = psi_in.T @ force  # (m, L + 1)
    out = np.empty(p.size, dtype=complex)
    for j in range(p.size):
        b = np.array([e1[j], e0[j] - e1[j]])
        zi = np.array([q0[j] - e1[j] * g[j, 0]])
        q, _ = lfilter(b, np.array([1.0, -phi[j]]), g[j], zi=zi)
        out[j] = q[-1]
    return out


def _acquire(x: NDArray[np.float64], r: int) -> NDArray[np.float64]:
    """Ideal anti-alias filter and decimation by ``r`` of one period (rows of ``x``).

    Keeps the DFT lines ``0 <= k < P/2`` of the ``P r``-sample period (``P``
    samples at the acquisition rate) and returns the ``P`` samples of that
    band-limited signal at the acquisition instants.
    """
    n = x.shape[1]
    p = n // r
    spec = np.fft.rfft(x, axis=1)[:, : p // 2 + 1]
    if p % 2 == 0:
        spec[:, p // 2] = 0.0
    return np.fft.irfft(spec, n=p, axis=1) / r


def _band_limited(lines: NDArray[np.complex128], p: int, r: int) -> NDArray[np.float64]:
    """``P`` samples of the signal whose lines ``0 <= l < P/2`` are ``lines / r``.

    ``lines`` are in the rfft scaling of the ``P r`` simulated samples; the
    signal of those lines alone (an ideal anti-alias filter) sampled ``P``
    times per period has the rfft ``lines / r``.
    """
    spec = np.zeros((lines.shape[0], p // 2 + 1), dtype=complex)
    spec[:, : lines.shape[1]] = lines
    return np.fft.irfft(spec, n=p, axis=1) / r


def _modal_to_physical(
    cm: ComplexModes, q: NDArray[np.complex128]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    x = 2 * np.real(cm.psi @ q)
    v = 2 * np.real(cm.psi @ (cm.poles * q))
    return x, v


def periodic_initial_state(
    system: MCKSystem,
    force_period: ArrayLike,
    sample_rate: float,
    inputs: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Initial displacement and velocity of the periodic steady state.

    For a force that repeats with period ``T = P / sample_rate`` (first-order
    hold between samples, as in :func:`~tyredamp.mechanics.time_response`),
    each complex mode (spec eq. [10]) ``q' = p q + psi^T f`` has the periodic
    solution with ``q(0) = q_P / (1 - e^{p T})``, ``q_P`` the value after one
    period from rest. Starting ``time_response`` from the returned state gives
    the steady state with no transient.

    Parameters
    ----------
    system : MCKSystem
        Underdamped system.
    force_period : array_like, shape (n_in, P)
        One period of the force in N (the sample after the last is the first).
    sample_rate : float
        Samples per second (Hz).
    inputs : array_like of int, shape (n_in,)
        DOF indices where the forces act.

    Returns
    -------
    x0, v0 : ndarray, shape (n_dof,)
        Displacement (m) and velocity (m/s) at ``t = 0``.
    """
    f = np.atleast_2d(np.asarray(force_period, dtype=float))
    idx = np.atleast_1d(np.asarray(inputs, dtype=np.intp))
    if f.shape[0] != idx.size:
        raise InputError(
            f"force_period: expected {idx.size} rows (one per input), got shape {f.shape}"
        )
    if idx.size and (idx.min() < 0 or idx.max() >= system.n_dof):
        raise InputError(
            f"inputs: DOF indices must lie in 0..{system.n_dof - 1}, got {idx.tolist()}"
        )
    h = 1.0 / check_positive(sample_rate, "sample_rate")
    cm = system.complex_modes()
    ext = np.concatenate([f, f[:, :1]], axis=1)
    q_p = _modal_propagate(cm, cm.psi[idx], ext, h, np.zeros(cm.poles.size, dtype=complex))
    period = f.shape[1] * h
    q0 = q_p / (-np.expm1(cm.poles * period))
    return _modal_to_physical(cm, q0)


def run_modal_test(
    tyre: RingTyre | None = None,
    *,
    band: tuple[float, float] = (0.0, 200.0),
    sample_rate: float = 1024.0,
    period: float = 4.0,
    n_periods: int = 8,
    force_rms: float = 10.0,
    snr_db: float | None = 40.0,
    seed: int | np.random.Generator | None = None,
    excitation: ExcitationKind = "chirp",
    drive_mode: DriveMode = "sequential",
    oversample: int = 16,
    initial_state: InitialState = "periodic",
    settle_periods: int = 0,
    keep_settle: bool = False,
    microphone_deg: float | None = None,
    direction: Direction = "radial",
) -> VirtualModalTest:
    """Run the virtual modal test of paper 000 on a ring tyre.

    Parameters
    ----------
    tyre : RingTyre, optional
        The tyre with its layout (default: ``RingTyre()``, 295/80R22.5 at
        7.5 bar, 16 points, drive at point 1).
    band : (float, float)
        Chirp band in Hz (default 0-200 Hz; DC is not excited). Also the band
        of the returned truth.
    sample_rate : float
        Acquisition rate in Hz (default 1024).
    period : float
        Chirp period in s (default 4: 0.25 Hz line spacing);
        ``period * sample_rate`` must be an integer.
    n_periods : int
        Recorded periods (averages) per run, >= 1 (default 8).
    force_rms : float
        RMS of each shaker force in N (default 10).
    snr_db : float or None
        Signal-to-noise ratio of every channel in dB: Gaussian noise of
        standard deviation ``rms(channel) * 10^(-snr_db/20)`` (RMS over the
        whole noise-free record of that channel). ``None`` for no noise.
        Default 40.
    seed : int, numpy.random.Generator or None
        Noise seed; the same seed gives the same data.
    excitation : {"chirp", "multisine"}
        Periodic linear sweep (:func:`tyredamp.signal.periodic_chirp`,
        default) or band-limited Schroeder multisine (module docstring).
    drive_mode : {"sequential", "simultaneous"}
        With several drive points: one input per run, or all inputs in every
        run with Hadamard signs (module docstring).
    oversample : int
        Simulation rate / ``sample_rate`` (default 16).
    initial_state : {"periodic", "rest"}
        Start in the exact periodic steady state (default) or at rest.
    settle_periods : int
        Periods simulated before the recorded ones in each run (default 0).
    keep_settle : bool
        Keep the settle periods in the record
        (``data.acquisition.settle_samples`` says how many samples of each
        run to drop) instead of dropping them.
    microphone_deg : float, optional
        A rim microphone at this angle (deg, a ring node; needs a cavity): a
        last channel ``P1``, "pressure" in Pa, noise at ``snr_db``
        (:mod:`~tyredamp.virtual.microphone`). Default none.
    direction : {"radial", "tangential"}
        Drive and measure radially (default) or along the circumference
        (:mod:`~tyredamp.virtual.tangential`; ``data.meta["measured_direction"]``).

    Returns
    -------
    VirtualModalTest

    Raises
    ------
    InputError
        Inconsistent sampling, band, counts or options (message names the
        argument).
    """
    t_start = _time.perf_counter()
    tyre, fs, p_samples, f_rms = _checked_options(
        tyre, sample_rate, period, n_periods, settle_periods, oversample, force_rms, snr_db
    )
    _check_choices(drive_mode, excitation, initial_state, direction)
    if direction == "tangential":
        tyre = tangential_tyre(tyre)
    bnd = as_band(band)
    lines = band_lines(fs, p_samples, bnd)
    mic = None if microphone_deg is None else microphone_row(tyre, microphone_deg)
    truth = tyre.truth(band=bnd)
    rng = np.random.default_rng(seed)

    n_in = len(tyre.layout.drive_points)
    drive = np.eye(n_in) if drive_mode == "sequential" else hadamard_drive_matrix(n_in)
    r = int(oversample)
    make = periodic_chirp if excitation == "chirp" else schroeder_multisine
    exc = make(fs * r, p_samples * r, bnd, rms=f_rms)
    n_keep = int(n_periods) + (int(settle_periods) if keep_settle else 0)
    periods = (int(settle_periods), int(n_periods), keep_settle)
    run_len = n_keep * p_samples
    n_runs = drive.shape[0]
    runs = drive[:, :, None] * exc.signal[None, None, :]  # (n_runs, n_in, P r)
    clean = _record(tyre, runs, (fs * r, r), initial_state, periods, mic)
    measured, noise_std = _add_noise(clean, snr_db, rng)
    meta = _notes(tyre, drive, drive_mode, exc, lines, (f_rms, snr_db, noise_std), seed, r)
    meta["initial_state"] = initial_state
    if direction == "tangential":
        meta["measured_direction"] = "tangential"
    meta["elapsed_s"] = _time.perf_counter() - t_start
    acquisition = Acquisition(
        period_samples=p_samples,
        run_starts=tuple(run * run_len for run in range(n_runs)),
        settle_samples=int(settle_periods) * p_samples if keep_settle else 0,
        band_hz=(float(bnd[0]), float(bnd[1])),
        n_averages=int(n_periods),
        excitation=exc.name,
    )
    data = _time_data(tyre, measured, fs, meta, acquisition, microphone_deg)
    return VirtualModalTest(data=data, truth=truth, tyre=tyre, drive_matrix=drive)


def _time_data(
    tyre: RingTyre,
    measured: NDArray[np.float64],
    fs: float,
    meta: dict[str, Any],
    acquisition: Acquisition,
    microphone_deg: float | None,
) -> TimeData:
    """The record as :class:`TimeData`: forces, accelerations and the microphone (if any)."""
    n_in = len(tyre.layout.drive_points)
    channels = tyre.input_channels + tyre.output_channels
    quantities = ["force"] * n_in + ["acceleration"] * len(tyre.point_dofs)
    if microphone_deg is not None:
        ang = float(tyre.node_angles_deg[microphone_node(tyre, microphone_deg)])
        channels = (*channels, Channel(len(channels) + 1, direction=0, angle_deg=ang, name="P1"))
        quantities.append("pressure")
        meta["microphone_deg"] = ang
    return TimeData(measured, fs, channels, quantities, meta, acquisition=acquisition)


def _check_choices(
    drive_mode: str, excitation: str, initial_state: str, direction: str = "radial"
) -> None:
    if direction not in ("radial", "tangential"):
        raise InputError(f"direction: expected 'radial' or 'tangential', got {direction!r}")
    if drive_mode not in ("sequential", "simultaneous"):
        raise InputError(f"drive_mode: expected 'sequential' or 'simultaneous', got {drive_mode!r}")
    if excitation not in ("chirp", "multisine"):
        raise InputError(f"excitation: expected 'chirp' or 'multisine', got {excitation!r}")
    if initial_state not in ("periodic", "rest"):
        raise InputError(f"initial_state: expected 'periodic' or 'rest', got {initial_state!r}")


def _notes(
    tyre: RingTyre,
    drive: NDArray[np.float64],
    drive_mode: str,
    exc: Any,
    lines: NDArray[Any],
    levels: tuple[float, float | None, NDArray[np.float64]],
    seed: int | np.random.Generator | None,
    r: int,
) -> dict[str, Any]:
    """``data.meta`` of a virtual test; ``levels`` = (force RMS, SNR in dB, noise std)."""
    f_rms, snr_db, noise_std = levels
    return {
        "source": "tyredamp.virtual.run_modal_test (virtual ring tyre)",
        "n_runs": drive.shape[0],
        "drive_mode": drive_mode,
        "drive_matrix": drive.tolist(),
        "drive_points": list(tyre.layout.drive_points),
        "excitation_band_hz": [float(exc.band[0]), float(exc.band[1])],
        "lines": lines.tolist(),
        "force_rms": f_rms,
        "snr_db": None if snr_db is None else float(snr_db),
        "noise_std": noise_std.tolist(),
        "seed": int(seed) if isinstance(seed, int | np.integer) else None,
        "oversample": r,
        "hold": "foh",
        "anti_alias": "ideal low-pass at sample_rate/2 on every channel",
        "pressure_pa": tyre.params.pressure,
        "nonproportionality": tyre.nonproportionality,
        "n_ring": tyre.n_ring,
    }


def _checked_options(
    tyre: RingTyre | None,
    sample_rate: float,
    period: float,
    n_periods: int,
    settle_periods: int,
    oversample: int,
    force_rms: float,
    snr_db: float | None,
) -> tuple[RingTyre, float, int, float]:
    """The tyre, sample rate (Hz), samples per period and force RMS (N) of ``run_modal_test``."""
    if tyre is None:
        tyre = RingTyre()
    if not isinstance(tyre, RingTyre):
        raise InputError(f"tyre: expected a RingTyre, got {type(tyre).__name__}")
    fs = check_positive(sample_rate, "sample_rate")
    t_per = check_positive(period, "period")
    p_samples = round(t_per * fs)
    if abs(p_samples - t_per * fs) > 1e-6 * max(1.0, t_per * fs) or p_samples < 4:
        raise InputError(
            f"period: expected period * sample_rate to be an integer >= 4, got "
            f"{t_per:g} s * {fs:g} Hz = {t_per * fs:g}"
        )
    for name, val, lo in (
        ("n_periods", n_periods, 1),
        ("settle_periods", settle_periods, 0),
        ("oversample", oversample, 1),
    ):
        if not isinstance(val, int | np.integer) or isinstance(val, bool) or val < lo:
            raise InputError(f"{name}: expected an integer >= {lo}, got {val!r}")
    f_rms = check_positive(force_rms, "force_rms")
    if snr_db is not None:
        try:
            snr = float(snr_db)
        except (TypeError, ValueError):
            raise InputError(f"snr_db: expected a number in dB or None, got {snr_db!r}") from None
        if not (snr > -300.0):  # NaN, -inf (infinite noise) or noise 1e15 x the signal
            raise InputError(f"snr_db: expected a ratio in dB > -300 (inf: no noise), got {snr:g}")
    return tyre, fs, p_samples, f_rms


def _record(
    tyre: RingTyre,
    runs: NDArray[np.float64],
    rates: tuple[float, int],
    initial_state: str,
    periods: tuple[int, int, bool],
    mic: NDArray[np.float64] | None,
) -> NDArray[np.float64]:
    """The noise-free record of all runs (``runs``: one period of each run's forces)."""
    if initial_state == "periodic":
        n_keep = periods[1] + (periods[0] if periods[2] else 0)
        return _steady_state_runs(tyre, runs, rates, n_keep, mic)
    return np.concatenate([_rest_start_run(tyre, f, rates, periods, mic) for f in runs], axis=1)


def _measured_dofs(
    tyre: RingTyre, mic: NDArray[np.float64] | None
) -> tuple[list[int], list[int], NDArray[np.intp]]:
    """Drive DOFs, response DOFs (points, then the microphone's DOFs) and the latter."""
    extra = np.array([], dtype=np.intp) if mic is None else np.flatnonzero(mic)
    return tyre.drive_dofs.tolist(), tyre.point_dofs.tolist() + extra.tolist(), extra


def _steady_state_runs(
    tyre: RingTyre,
    force_sim: NDArray[np.float64],
    rates: tuple[float, int],
    n_keep: int,
    mic: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Forces, accelerations (and pressure) of every run in the steady state, at ``fs_sim / r``.

    ``force_sim`` (n_runs, n_in, P r) is one period of each run's drive
    forces at the simulation rate ``rates = (fs_sim, r)``. The lines below
    ``sample_rate / 2`` of the continuous force and of the exact continuous
    response (:func:`~tyredamp.mechanics.continuous_periodic_lines`) are
    sampled ``P`` times per period (module docstring, "Sampling") and every
    run holds ``n_keep`` copies of its period; ``mic`` the pressure row (Pa
    per DOF) of a microphone, or None.
    """
    fs_sim, r = rates
    inputs, outputs, extra = _measured_dofs(tyre, mic)
    n_pts = tyre.point_dofs.size
    p = force_sim.shape[2] // r
    kept = p // 2 + p % 2  # the lines below sample_rate / 2
    f_lines, disp, acc_lines = continuous_periodic_lines(
        tyre.system, force_sim, fs_sim, inputs, outputs, kept
    )
    blocks = []
    for run in range(force_sim.shape[0]):
        rows = acc_lines[run, :n_pts]
        if mic is not None:
            rows = np.vstack([rows, mic[extra] @ disp[run, n_pts:]])
        one = np.vstack([_band_limited(f_lines[run], p, r), _band_limited(rows, p, r)])
        blocks.append(np.tile(one, (1, n_keep)))
    return np.concatenate(blocks, axis=1)


def _rest_start_run(
    tyre: RingTyre,
    force_sim: NDArray[np.float64],
    rates: tuple[float, int],
    periods: tuple[int, int, bool],
    mic: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Forces, accelerations (and pressure) of one run started at rest, at ``fs_sim / r``.

    ``force_sim`` (n_in, P r) is one period of the drive forces at the
    simulation rate ``rates = (fs_sim, r)``; ``periods`` = (settle periods,
    recorded periods, keep the settle periods); ``mic`` the pressure row
    (Pa per DOF) of a microphone, or None. Simulated by ``time_response``
    and sampled (module docstring, "Sampling").
    """
    fs_sim, r = rates
    settle_periods, n_periods, keep_settle = periods
    n_keep = n_periods + (settle_periods if keep_settle else 0)
    system = tyre.system
    inputs, outputs, extra = _measured_dofs(tyre, mic)
    n_pts = tyre.point_dofs.size

    def channels(resp: TimeResponse) -> NDArray[np.float64]:
        acc = resp.acceleration[:n_pts]
        if mic is None:
            return acc
        return np.vstack([acc, mic[extra] @ resp.displacement[n_pts:]])

    cm = system.complex_modes()
    blocks = []
    q = np.zeros(cm.poles.size, dtype=complex)
    ext = np.concatenate([force_sim, force_sim[:, :1]], axis=1)
    psi_in = cm.psi[inputs]
    for k in range(settle_periods + n_periods):
        x0, v0 = _modal_to_physical(cm, q)
        resp = time_response(system, force_sim, fs_sim, inputs, outputs, x0=x0, v0=v0)
        if k >= settle_periods or keep_settle:
            blocks.append(_acquire(channels(resp), r))
        q = _modal_propagate(cm, psi_in, ext, 1.0 / fs_sim, q)
    acc = np.concatenate(blocks, axis=1)
    force = np.tile(_acquire(force_sim, r), (1, n_keep))
    return np.concatenate([force, acc], axis=0)


def _add_noise(
    clean: NDArray[np.float64], snr_db: float | None, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The record with Gaussian noise at ``snr_db`` on every channel, and the noise std."""
    if snr_db is None or np.isinf(float(snr_db)):
        return clean, np.zeros(clean.shape[0])
    rms = np.sqrt(np.mean(clean**2, axis=1))
    noise_std = rms * 10.0 ** (-float(snr_db) / 20.0)
    return clean + noise_std[:, None] * rng.standard_normal(clean.shape), noise_std
