"""Shared pieces of the performance benchmarks (``benchmarks/perf_*.py``).

Not a benchmark itself: data sets with a known truth (the virtual truck tyre
and a synthetic non-proportionally damped structure), the two identification
runs being compared (tyredamp :func:`~tyredamp.modal.identify_modes` and
sdypy-EMA LSCF + LSFD), accuracy figures against the truth, BLAS thread
control, machine information, table printing and JSON output.

Conventions used by every benchmark
-----------------------------------
* Noise on FRFs: circular complex Gaussian, independent per line and FRF,
  ``E|e|^2 = sigma_jk^2`` with ``sigma_jk = rms_f |H_jk| * 10^(-SNR/20)``
  (RMS of the noise-free FRF over its lines). At 40 dB that is 1 % of the
  FRF's RMS level.
* Band: both tools see the same lines ``[f_lo, f_hi]``. sdypy-EMA needs a
  uniform axis from 0 Hz (it prepends zero lines below the first one) and
  drops the line nearest its ``upper`` limit, so the arrays handed over
  carry one extra line above ``f_hi``.
* Wall times are ``time.perf_counter`` differences in one process with the
  BLAS thread pools limited to ``--blas-threads`` (default 1) for both tools.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import platform
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

import tyredamp
from tyredamp.frf import FRF
from tyredamp.io._atomic import atomic_path
from tyredamp.mechanics import pole_from_frequency_damping
from tyredamp.modal import ModalModel, identify_modes, mac

RESULTS_DIR = Path(__file__).resolve().parent / "results"

# ----------------------------------------------------------------- environment


def limit_blas(n_threads: int) -> Any:
    """Limit every BLAS/OpenMP pool of this process to ``n_threads`` (kept alive by the caller)."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=int(n_threads))


def machine_info(blas_threads: int) -> dict[str, Any]:
    """CPU count, load averages and library versions, stored beside every result."""
    from threadpoolctl import threadpool_info

    info: dict[str, Any] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "cpu_affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "numpy": np.__version__,
        "tyredamp": getattr(tyredamp, "__version__", "?"),
        "blas_threads": blas_threads,
        "blas": sorted({f"{p['internal_api']} {p['version']}" for p in threadpool_info()}),
        "time": time.strftime("%Y-%m-%d %H:%M:%S"),
    }
    try:
        from importlib.metadata import version

        info["sdypy_ema"] = version("sdypy-EMA")
    except Exception:  # not installed: the comparison is skipped
        info["sdypy_ema"] = None
    return info


def write_json(doc: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write ``doc`` as JSON atomically (non-finite numbers become ``null``)."""

    def clean(x: Any) -> Any:
        if isinstance(x, dict):
            return {str(k): clean(v) for k, v in x.items()}
        if isinstance(x, list | tuple):
            return [clean(v) for v in x]
        if isinstance(x, np.ndarray):
            return clean(x.tolist())
        if isinstance(x, np.generic):
            return clean(x.item())
        if isinstance(x, float) and not np.isfinite(x):
            return None
        if isinstance(x, complex):
            return [clean(x.real), clean(x.imag)]
        return x

    target = Path(path)
    with atomic_path(target) as tmp:
        tmp.write_text(json.dumps(clean(doc), indent=1) + "\n")
    return target


def print_table(headers: Sequence[str], rows: Sequence[Sequence[Any]], title: str = "") -> str:
    """Print a plain-text table (right-aligned columns) and return it."""
    cells = [[_fmt(v) for v in r] for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in cells)) for i, h in enumerate(headers)]
    lines = []
    if title:
        lines.append(title)
    lines.append("  ".join(h.rjust(w) for h, w in zip(headers, widths, strict=True)))
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in cells]
    text = "\n".join(lines)
    print(text, flush=True)
    return text


def _fmt(v: Any) -> str:
    if isinstance(v, str):
        return v
    if v is None:
        return "-"
    if isinstance(v, bool | np.bool_):
        return "yes" if v else "no"
    if isinstance(v, int | np.integer):
        return str(int(v))
    x = float(v)
    if not np.isfinite(x):
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 1000 or abs(x) < 1e-3:
        return f"{x:.2e}"
    if abs(x) >= 10:
        return f"{x:.1f}"
    return f"{x:.3g}"


# ----------------------------------------------------------------------- data


@dataclass
class Case:
    """FRFs with their exact modal truth.

    Attributes
    ----------
    name : str
    frf : FRF
        Noisy FRFs, lines ``df, 2 df, ..., f_hi + df`` (uniform, one line above the band).
    exact : ndarray, complex, shape (n_out, n_in, n_freq)
        Noise-free FRFs on the same lines.
    band : (float, float)
        Analysis band in Hz given to both tools.
    poles : ndarray, complex, shape (m,)
        True in-band poles (rad/s).
    psi : ndarray, complex, shape (n_out, m)
        True mode shapes at the outputs (any scaling; used by MAC only).
    noise : str
        How the noise was made.
    """

    name: str
    frf: FRF
    exact: NDArray[np.complex128]
    band: tuple[float, float]
    poles: NDArray[np.complex128]
    psi: NDArray[np.complex128]
    noise: str
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        return np.abs(self.poles) / (2 * np.pi)

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        return -self.poles.real / np.abs(self.poles)


def add_noise(h: NDArray[np.complex128], snr_db: float, seed: int) -> NDArray[np.complex128]:
    """``h`` plus circular complex Gaussian noise at ``snr_db`` per FRF (module docstring)."""
    rng = np.random.default_rng(seed)
    rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=-1, keepdims=True))
    e = rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)
    return np.asarray(h + 10 ** (-snr_db / 20) * rms * e / np.sqrt(2))


def tyre_lines(f_hi: float = 200.0, df: float = 0.25) -> NDArray[np.float64]:
    """Lines ``df .. f_hi`` of the virtual tyre test (0.25 Hz, 4 s chirp period)."""
    return np.asarray(df * np.arange(1, round(f_hi / df) + 1), dtype=np.float64)


def tyre_case(snr_db: float = 40.0, seed: int = 1) -> Case:
    """The virtual truck tyre (16 points, drive at point 1): exact FRFs + noise.

    Band 0.25-199.75 Hz (799 lines, the 200 Hz line is the extra one), six
    visible modes (n = 1..6) with 2-4 % non-proportional damping.
    """
    from tyredamp.virtual import RingTyre

    tyre = RingTyre()
    tr = tyre.truth((0.0, 200.0))
    vis = tr.select("visible")
    f = tyre_lines()
    ex = tr.frf(f)
    frf = ex.with_H(add_noise(ex.H, snr_db, seed))
    return Case(
        name="tyre 16 out, exact FRF + 40 dB",
        frf=frf,
        exact=np.asarray(ex.H),
        band=(float(f[0]), float(f[-2])),
        poles=tr.poles[vis],
        psi=tr.psi_points[:, vis],
        noise=f"complex Gaussian on the FRF, SNR {snr_db:g} dB per FRF, seed {seed}",
        meta={"residues_drive": tr.psi_drive[:, vis], "truth": tr},
    )


def tyre_test_case(seed: int = 0) -> Case:
    """The virtual modal test of the tyre (time data, 40 dB per channel, 8 averages), H1 FRFs."""
    from tyredamp.signal.estimators import estimate_frf
    from tyredamp.virtual import run_modal_test

    t0 = time.perf_counter()
    vt = run_modal_test(seed=seed)
    frf = estimate_frf(vt.data, band=(0.0, 200.0))
    frf = frf.select_lines(np.flatnonzero(frf.frequency > 0))
    sim = time.perf_counter() - t0
    f = frf.frequency
    if not np.allclose(f, f[0] * np.arange(1, f.size + 1)):
        raise RuntimeError("virtual test: expected uniform lines df, 2 df, ...")
    tr = vt.truth
    vis = tr.select("visible")
    return Case(
        name="tyre 16 out, virtual test (H1)",
        frf=frf,
        exact=np.asarray(tr.frf(f).H),
        band=(float(f[0]), float(f[-2])),
        poles=tr.poles[vis],
        psi=tr.psi_points[:, vis],
        noise=f"virtual chirp test, 40 dB per channel, 8 averages, H1, seed {seed}",
        meta={"simulation_s": sim},
    )


def synthetic_model(n_out: int, n_modes: int, seed: int = 0) -> tuple[ModalModel, int]:
    """A structure with ``n_modes`` complex modes in 10-190 Hz and two above 200 Hz.

    Natural frequencies evenly spread with +-1 % jitter, damping 0.5-3 %,
    mode shapes ``a + i b`` with independent real and imaginary parts
    (``|b| ~ 0.3 |a|``: non-proportional damping, MPC well below 1), one
    drive point at output 1 that excites every mode. Residues in the eq. [10]
    scaling ``R_jn = psi_jn psi_1n``. Returns the model (all modes) and the
    number of in-band modes (the first ones).
    """
    rng = np.random.default_rng(seed)
    f_n = np.linspace(10.0, 190.0, n_modes) * (1 + 0.01 * rng.uniform(-1, 1, n_modes))
    f_n = np.sort(np.concatenate([f_n, [215.0, 240.0]]))
    zeta = rng.uniform(0.005, 0.03, f_n.size)
    p = pole_from_frequency_damping(f_n, zeta)
    m = f_n.size
    psi = (rng.normal(size=(n_out, m)) + 0.3j * rng.normal(size=(n_out, m))) * 1e-2
    psi[0] = (np.abs(psi[0].real) + 0.5e-2) + 0.3j * psi[0].imag
    model = ModalModel(
        p, psi, psi[:1], mode_kind="complex", outputs=range(1, n_out + 1), inputs=[1]
    )
    return model, n_modes


def synthetic_case(
    n_out: int, n_lines: int, n_modes: int, snr_db: float = 40.0, seed: int = 0
) -> Case:
    """Synthetic structure (:func:`synthetic_model`), accelerance, ``n_lines`` lines in the band.

    Lines ``df .. (n_lines + 1) df`` with ``df = 200 / n_lines`` Hz; the band
    ``[df, 200]`` Hz holds exactly ``n_lines`` lines.
    """
    model, m = synthetic_model(n_out, n_modes, seed)
    df = 200.0 / n_lines
    f = df * np.arange(1, n_lines + 2)
    ex = model.frf(f, kind="accelerance")
    h = add_noise(np.asarray(ex.H), snr_db, seed + 1)
    return Case(
        name=f"synthetic {n_out} out, {n_lines} lines, {n_modes} modes",
        frf=ex.with_H(h),
        exact=np.asarray(ex.H),
        band=(float(f[0]), float(f[-2])),
        poles=model.poles[:m],
        psi=model.psi_out[:, :m],
        noise=f"complex Gaussian on the FRF, SNR {snr_db:g} dB per FRF, seed {seed + 1}",
    )


def mimo_case(
    n_out: int, n_in: int, n_lines: int, n_modes: int, snr_db: float = 40.0, seed: int = 0
) -> Case:
    """:func:`synthetic_case` with ``n_in`` inputs: the drive points are outputs
    ``1 .. n_in`` (each excites every mode), the participation their shapes."""
    rng = np.random.default_rng(seed)
    f_n = np.linspace(10.0, 190.0, n_modes) * (1 + 0.01 * rng.uniform(-1, 1, n_modes))
    f_n = np.sort(np.concatenate([f_n, [215.0, 240.0]]))
    p = pole_from_frequency_damping(f_n, rng.uniform(0.005, 0.03, f_n.size))
    psi = (rng.normal(size=(n_out, f_n.size)) + 0.3j * rng.normal(size=(n_out, f_n.size))) * 1e-2
    psi[:n_in] = (np.abs(psi[:n_in].real) + 0.5e-2) + 0.3j * psi[:n_in].imag
    model = ModalModel(
        p,
        psi,
        psi[:n_in],
        mode_kind="complex",
        outputs=range(1, n_out + 1),
        inputs=range(1, n_in + 1),
    )
    df = 200.0 / n_lines
    f = df * np.arange(1, n_lines + 2)
    ex = model.frf(f, kind="accelerance")
    return Case(
        name=f"{n_out} out x {n_in} in, {n_lines} lines, {n_modes} modes, {snr_db:g} dB",
        frf=ex.with_H(add_noise(np.asarray(ex.H), snr_db, seed + 1)),
        exact=np.asarray(ex.H),
        band=(float(f[0]), float(f[-2])),
        poles=p[:n_modes],
        psi=psi[:, :n_modes],
        noise=f"complex Gaussian on the FRF, SNR {snr_db:g} dB per FRF, seed {seed + 1}",
    )


def physical_case(
    n_out: int, n_in: int, n_lines: int, n_modes: int, snr_db: float = 40.0, seed: int = 0
) -> Case:
    """A random physical structure (:func:`perf_physical.physical_system`), accelerance.

    ``M``, ``C``, ``K`` of a tuned mass-spring network with Rayleigh damping
    and localised dashpots (non-proportional), one close pair, one weak mode,
    modes above the band; ``n_out`` measured DOFs, ``n_in`` drive points
    among them. Lines ``df .. (n_lines + 1) df`` with ``df = 200 / n_lines``
    Hz (the band ``[df, 200]`` holds ``n_lines`` lines and ``n_modes``
    modes). FRFs: the complex-mode sum over every mode of the structure
    (Popov & Geng eq. [10], the exact state-space FRF of eq. [4]-[9]), noise
    as :func:`add_noise`. ``meta["physics"]``: the structure's figures
    (:func:`perf_physical.describe`) and each in-band mode's peak over the
    noise (``peak_snr_db``, :func:`perf_physical.mode_peak_snr_db`; the weak
    mode's ``weak_peak_snr_db``).
    """
    from perf_physical import mode_peak_snr_db, physical_system

    ps = physical_system(n_out, n_in, n_modes, seed)
    df = 200.0 / n_lines
    f = df * np.arange(1, n_lines + 2)
    ex = ps.system.frf(
        f, kind="accelerance", outputs=list(ps.outputs), inputs=list(ps.inputs), method="modal"
    )
    cm = ps.system.complex_modes()
    poles, psi = cm.poles[ps.in_band], cm.psi[ps.outputs][:, ps.in_band]
    psi_in = cm.psi[ps.inputs][:, ps.in_band]
    physics = dict(ps.info)
    physics["peak_snr_db"] = mode_peak_snr_db(poles, psi, psi_in, np.asarray(ex.H), snr_db)
    physics["weak_peak_snr_db"] = float(physics["peak_snr_db"][ps.weak])
    physics["outputs"], physics["inputs"] = ps.outputs + 1, ps.inputs + 1
    return Case(
        name=f"physical {n_out} x {n_in}, {n_lines} lines, {n_modes} modes, {snr_db:g} dB",
        frf=ex.with_H(add_noise(np.asarray(ex.H), snr_db, seed + 1)),
        exact=np.asarray(ex.H),
        band=(float(f[0]), float(f[-2])),
        poles=poles,
        psi=psi,
        noise=f"complex Gaussian on the FRF, SNR {snr_db:g} dB per FRF, seed {seed + 1}",
        meta={"physics": physics, "system": ps},
    )


# ------------------------------------------------------------------ the runs


@dataclass
class RunResult:
    """One identification: timings, modes and reconstruction on the band lines."""

    tool: str
    t_poles: float
    t_residues: float
    poles: NDArray[np.complex128]
    shapes: NDArray[np.complex128]  # (n_out, m): residue columns or psi_out (MAC only)
    reconstruction: NDArray[np.complex128]  # (n_out, n_in, n_band) on the fitted lines
    lines: NDArray[np.intp]  # indices into case.frf.frequency of those lines
    extra: dict[str, Any] = field(default_factory=dict)
    #: CPU time of the process over the call (``time.process_time``): on a shared
    #: machine the wall time of a one-thread run varies several-fold, the CPU time less
    t_cpu: float = float("nan")

    @property
    def t_total(self) -> float:
        return self.t_poles + self.t_residues


@contextlib.contextmanager
def _timed_names(module: ModuleType, names: Sequence[str], acc: list[float]) -> Iterator[None]:
    """Wrap ``module.<name>`` for each name so its wall time adds up in ``acc[0]``."""
    orig = {n: getattr(module, n) for n in names if hasattr(module, n)}

    def wrap(fn: Callable[..., Any]) -> Callable[..., Any]:
        def inner(*a: Any, **k: Any) -> Any:
            t = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                acc[0] += time.perf_counter() - t

        return inner

    for n, fn in orig.items():
        setattr(module, n, wrap(fn))
    try:
        yield
    finally:
        for n, fn in orig.items():
            setattr(module, n, fn)


#: the pole stage as :mod:`tyredamp.modal.identify` (and its start,
#: :mod:`tyredamp.modal.starts`) calls it: the automatic order
#: and its diagram (:func:`~tyredamp.modal.poles.order.settle_order`: pLSCF, the flags,
#: the clusters) and the picking of given frequencies
POLE_STAGE = ("settle_order", "plscf", "stability_flags", "cluster_poles", "_pick_frequencies")


def run_tyredamp(case: Case, max_order: int | None = None, **options: Any) -> RunResult:
    """``identify_modes(..., model="complex")`` on the case's band, pole stage timed apart.

    The pole stage is the time spent in pLSCF, the stability flags, the
    clustering and the frequency picking (``POLE_STAGE``, found by wrapping
    those functions in :mod:`tyredamp.modal.identify` and :mod:`tyredamp.modal.starts`
    for the duration of the call); the rest of the call (LSFD, refinement, residual modes, standard
    errors, indicators) counts as residue fitting.
    """
    import tyredamp.modal.identify as ident
    import tyredamp.modal.starts as starts

    acc = [0.0]
    with _timed_names(ident, POLE_STAGE, acc), _timed_names(starts, POLE_STAGE, acc):
        c0, t0 = time.process_time(), time.perf_counter()
        res = identify_modes(
            case.frf, band=case.band, model="complex", max_order=max_order, **options
        )
        total = time.perf_counter() - t0
        cpu = time.process_time() - c0
    m = res.models["complex"]
    f = case.frf.frequency
    lines = np.flatnonzero((f >= case.band[0]) & (f <= case.band[1]))
    rec = np.asarray(m.frf(f[lines], kind=case.frf.kind).H)
    return RunResult(
        tool="tyredamp",
        t_poles=acc[0],
        t_residues=total - acc[0],
        poles=np.asarray(m.poles),
        shapes=np.asarray(m.psi_out),
        reconstruction=rec,
        lines=lines,
        extra={
            "max_order": m.meta.get("max_order"),
            "n_residual_modes": m.meta.get("n_residual_modes"),
            "std_frequency_hz": m.std.get("frequency_hz"),
            "std_damping_ratio": m.std.get("damping_ratio"),
        },
        t_cpu=cpu,
    )


def sdypy_available() -> bool:
    try:
        import sdypy.EMA  # noqa: F401
    except ImportError:
        return False
    return True


def run_sdypy(
    case: Case,
    pol_order_high: int,
    approx_freq: NDArray[np.float64] | None = None,
    f_window: float | None = None,
) -> RunResult:
    """sdypy-EMA: ``get_poles("lscf")``, ``select_closest_poles``, ``get_constants("lsfd")``.

    SIMO only (the first input). ``approx_freq`` defaults to the true natural
    frequencies (favours sdypy-EMA: it is told where the modes are);
    ``f_window`` (its search window, Hz, default 50) defaults to half the
    smallest spacing of those frequencies (also in its favour: the default
    window of 50 Hz jumps to a neighbouring mode on the tyre).
    Polynomial orders 2, 4, ..., ``2 pol_order_high``.
    """
    from sdypy import EMA

    fr = case.frequency_hz if approx_freq is None else np.asarray(approx_freq, float)
    if f_window is None:
        gap = np.min(np.diff(np.sort(fr))) if fr.size > 1 else 20.0
        f_window = max(2.0, 0.5 * float(gap))
    frf = case.frf
    f = frf.frequency
    h = np.asarray(frf.H[:, 0, :])
    drive = [j for j, k in frf.drive_points() if k == 0]
    quiet = io.StringIO()
    with warnings.catch_warnings(), contextlib.redirect_stderr(quiet):
        warnings.simplefilter("ignore")  # sdypy's own warnings (band clamping, log of 0)
        c0, t0 = time.process_time(), time.perf_counter()
        model = EMA.Model(
            frf=h,
            freq=f,
            lower=case.band[0],
            upper=float(f[-1]),  # the line at ``upper`` is dropped: band ends at f[-2]
            pol_order_high=int(pol_order_high),
            frf_form=frf.kind,
            driving_point=drive[0] if drive else None,
        )
        model.get_poles(method="lscf", show_progress=False)
        model.select_closest_poles(list(fr), f_window=f_window)
        t1 = time.perf_counter()
        H_rec, A = model.get_constants(
            method="lsfd", whose_poles="own", f_lower=case.band[0], f_upper=float(model.freq[-1])
        )
        t2 = time.perf_counter()
        cpu = time.process_time() - c0
    pind = np.asarray(model.pole_ind, dtype=int)
    poles = np.array([model.all_poles[i][j] for i, j in pind], dtype=complex)
    A = np.asarray(A)
    # a pole picked with Im p < 0 carries the residue of its conjugate
    neg = poles.imag < 0
    A[:, neg] = np.conj(A[:, neg])
    poles = np.where(neg, np.conj(poles), poles)
    fs = np.asarray(model.freq)
    lines = np.flatnonzero((f >= case.band[0]) & (f <= case.band[1]))
    idx = np.searchsorted(fs, f[lines])
    idx = np.minimum(idx, fs.size - 1)
    if not np.allclose(fs[idx], f[lines]):
        raise RuntimeError("sdypy-EMA frequency axis does not contain the band lines")
    rec = np.asarray(H_rec)[:, idx][:, None, :]
    return RunResult(
        tool="sdypy-EMA",
        t_poles=t1 - t0,
        t_residues=t2 - t1,
        poles=poles,
        shapes=A,
        reconstruction=rec,
        lines=lines,
        extra={
            "pol_order_high": pol_order_high,
            "f_window_hz": f_window,
            "nat_freq": np.asarray(model.nat_freq, float),
            "nat_xi": np.asarray(model.nat_xi, float),
        },
        t_cpu=cpu,
    )


# ------------------------------------------------------------------ accuracy


def match_modes(
    f_id: NDArray[np.float64], f_true: NDArray[np.float64], tol: float = 0.03
) -> NDArray[np.intp]:
    """Identified mode matched to each true mode (one-to-one, nearest relative frequency).

    ``-1`` where no identified mode lies within ``tol`` (relative).
    """
    out = np.full(f_true.size, -1, dtype=np.intp)
    if f_id.size == 0:
        return out
    d = np.abs(f_id[None, :] / f_true[:, None] - 1)
    rows, cols = linear_sum_assignment(d)
    ok = d[rows, cols] <= tol
    out[rows[ok]] = cols[ok]
    return out


def accuracy(case: Case, run: RunResult) -> dict[str, Any]:
    """Frequency and damping errors, MAC and relative reconstruction errors against the truth.

    Errors of the matched modes are relative (``|f_id / f_true - 1|``,
    ``|zeta_id / zeta_true - 1|``); a missed true mode counts as error 1 and
    MAC 0. Reconstruction error: RMS of ``H_model - H`` over the band lines
    and FRFs divided by the RMS of ``H``, against the noise-free FRFs
    (``rel_error_true``) and the noisy data (``rel_error_data``); a perfect
    model has ``rel_error_true`` 0 and ``rel_error_data`` about ``10^(-SNR/20)``.
    """
    f_id = np.abs(run.poles) / (2 * np.pi)
    z_id = -run.poles.real / np.abs(run.poles)
    idx = match_modes(f_id, case.frequency_hz)
    ok = idx >= 0
    ef = np.ones(idx.size)
    ez = np.ones(idx.size)
    macs = np.zeros(idx.size)
    ef[ok] = np.abs(f_id[idx[ok]] / case.frequency_hz[ok] - 1)
    ez[ok] = np.abs(z_id[idx[ok]] / case.damping_ratio[ok] - 1)
    if np.any(ok):
        macs[ok] = np.diag(mac(run.shapes[:, idx[ok]], case.psi[:, ok]))
    ex = case.exact[:, :, run.lines]
    da = np.asarray(case.frf.H)[:, :, run.lines]
    rec = run.reconstruction
    if rec.shape[1] != ex.shape[1]:  # SIMO tool on a MIMO case: first input only
        ex, da = ex[:, :1], da[:, :1]
    rms = float(np.sqrt(np.mean(np.abs(ex) ** 2)))
    return {
        "n_true": int(idx.size),
        "n_found": int(ok.sum()),
        "n_identified": int(f_id.size),
        "max_freq_error": float(ef.max()),
        "rms_freq_error": float(np.sqrt(np.mean(ef**2))),
        "max_damping_error": float(ez.max()),
        "rms_damping_error": float(np.sqrt(np.mean(ez**2))),
        "min_mac": float(macs.min()),
        "mean_mac": float(macs.mean()),
        "rel_error_true": float(np.sqrt(np.mean(np.abs(rec - ex) ** 2)) / rms),
        "rel_error_data": float(np.sqrt(np.mean(np.abs(rec - da) ** 2)) / rms),
        "freq_error": ef,
        "damping_error": ez,
        "mac": macs,
    }
