"""Spread of the identified natural frequencies and damping ratios against the Cramér-Rao bound.

Run: ``python benchmarks/perf_crlb.py [--quick] [--seeds N] [--snr 40] [--json PATH]
[--identify KEY=VALUE ...] [--no-sdypy]``.

``--identify`` passes an option to ``identify_modes`` (a Python literal, e.g.
``--identify search=False --identify max_helpers=0``): what a stage of the
identification contributes to its accuracy and time. Its results go to
``results/crlb-<options>.json`` unless ``--json`` says otherwise, so the
default run's ``results/crlb.json`` (read by ``run_all.py``) stays.

Data: the exact accelerances of the virtual truck tyre (16 points, drive at
point 1, lines 0.25-200 Hz every 0.25 Hz) plus circular complex Gaussian
noise, independent per line and FRF, ``E|e_j|^2 = sigma_j^2`` with
``sigma_j = rms_f|H_j| 10^(-SNR/20)``. The noise is *defined* on the FRF
with this known variance (it is not derived from the averages of a time-data
test), and the bound is computed for exactly this noise.

Bound: the model is the complex-mode modal sum of spec eq. [10] over the six
visible in-band modes, ``H_j = (i w)^2 [sum_n R_jn/(s - p_n) + conj(R_jn)/(s -
conj p_n) + U_j + L_j/s^2]``, with free parameters ``sigma_n``, ``Omega_n``
(``p_n = -sigma_n + i Omega_n``), complex residues ``R_jn`` and real upper
and lower residuals ``U_j``, ``L_j`` per output (what the estimator fits).
Fisher information ``F = sum_j 2/sigma_j^2 Re(J_j^H J_j)`` at the true poles
and residues; the residues and residuals are nuisance parameters (Schur
complement), and the bound on ``f_n = |p_n|/2pi`` and ``zeta_n = sigma_n/|p_n|``
follows by the delta method. A second bound adds the two visible tyre modes
just above the band (215 and 248 Hz) as free nuisance modes (the estimator may
fit such out-of-band residual modes).

Monte Carlo: :func:`~tyredamp.modal.identify_modes` (automatic, complex
model, default options or those given with ``--identify``) on ``--seeds``
noise realisations; the ratio of the sample standard deviation of each
mode's estimates to the bound (ideal 1, target <= 1.5), over the fits that
found every true mode; a fit that also kept a noise mode (the mode test's
false alarm, at its stated 1 % rate) counts, and is listed under ``extra``;
one that missed a true mode is a failure.
sdypy-EMA (LSCF + LSFD with the true frequencies, as in ``perf_compare.py``)
on the same data for comparison, when installed.
"""

from __future__ import annotations

import argparse
import ast
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray
from perf_common import (
    RESULTS_DIR,
    Case,
    add_noise,
    limit_blas,
    machine_info,
    match_modes,
    print_table,
    run_sdypy,
    sdypy_available,
    tyre_lines,
    write_json,
)

from tyredamp.modal import identify_modes
from tyredamp.virtual import RingTyre

POWER = 2  # accelerance


def crlb(
    f_hz: NDArray[np.float64],
    poles: NDArray[np.complex128],
    residues: NDArray[np.complex128],
    sigma: NDArray[np.float64],
    n_wanted: int,
    power: int = POWER,
) -> dict[str, NDArray[np.float64]]:
    """Cramér-Rao bound of ``f_n`` and ``zeta_n`` for the first ``n_wanted`` poles.

    Parameters
    ----------
    f_hz : ndarray, shape (n_f,)
        Lines in Hz (> 0).
    poles : ndarray, complex, shape (m,)
        True poles (rad/s), ``Im p > 0``; the ones after ``n_wanted`` are
        nuisance modes.
    residues : ndarray, complex, shape (n_out, m)
        True residues ``R_jn`` (single input).
    sigma : ndarray, shape (n_out,)
        Noise standard deviation per output, ``E|e_j|^2 = sigma_j^2``.
    n_wanted : int
    power : int
        Power of ``i w`` of the FRF kind (2: accelerance).

    Returns
    -------
    dict
        ``frequency_hz`` and ``damping_ratio`` (n_wanted,): bound on the
        standard deviation; ``cov_pole`` (2 m, 2 m): bound on
        ``(sigma_n, Omega_n)`` for all modes.
    """
    s = 2j * np.pi * f_hz
    kap = s**power
    m = poles.size
    g = kap[:, None] / (s[:, None] - poles[None, :])  # (n_f, m)
    gb = kap[:, None] / (s[:, None] - np.conj(poles)[None, :])
    # linear basis, complex (n_f, q): Re R, Im R per mode, then U, L
    cols = [g + gb, 1j * (g - gb), kap[:, None], (kap / s**2)[:, None]]
    phi_c = np.concatenate(
        [np.stack([cols[0], cols[1]], axis=2).reshape(f_hz.size, 2 * m), cols[2], cols[3]], axis=1
    )
    phi = np.concatenate([phi_c.real, phi_c.imag], axis=0)
    Q, _ = np.linalg.qr(phi)
    d2 = g / (s[:, None] - poles[None, :])  # d/dp of kap/(s - p)
    d2b = gb / (s[:, None] - np.conj(poles)[None, :])
    fisher = np.zeros((2 * m, 2 * m))
    for j in range(residues.shape[0]):
        R = residues[j]
        # dH/dsigma = -(R d2 + conj R d2b); dH/dOmega = i R d2 - i conj R d2b
        ds = -(R[None, :] * d2 + np.conj(R)[None, :] * d2b)
        do = 1j * R[None, :] * d2 - 1j * np.conj(R)[None, :] * d2b
        G = np.stack([ds, do], axis=2).reshape(f_hz.size, 2 * m)
        Gr = np.concatenate([G.real, G.imag], axis=0)
        Gp = Gr - Q @ (Q.T @ Gr)  # residues and residuals eliminated
        fisher += 2.0 / sigma[j] ** 2 * (Gp.T @ Gp)
    cov = np.linalg.inv(fisher)
    sig, om = -poles.real, poles.imag
    mag = np.abs(poles)
    sf, sz = [], []
    for n in range(n_wanted):
        b = cov[2 * n : 2 * n + 2, 2 * n : 2 * n + 2]
        jf = np.array([sig[n], om[n]]) / (mag[n] * 2 * np.pi)
        jz = np.array([om[n] ** 2, -sig[n] * om[n]]) / mag[n] ** 3
        sf.append(np.sqrt(jf @ b @ jf))
        sz.append(np.sqrt(jz @ b @ jz))
    return {"frequency_hz": np.array(sf), "damping_ratio": np.array(sz), "cov_pole": cov}


#: identify_modes arguments that this benchmark sets itself
FIXED_ARGS = ("frf", "band", "model")


def identify_options(items: list[str]) -> dict[str, Any]:
    """``KEY=VALUE`` items (values Python literals) as keyword arguments of
    ``identify_modes`` (a key it does not take, or one of ``FIXED_ARGS``, is
    refused with one line)."""
    import inspect

    known = set(inspect.signature(identify_modes).parameters) - set(FIXED_ARGS)
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.isidentifier():
            raise SystemExit(f"--identify {item!r}: expected KEY=VALUE")
        if key not in known:
            raise SystemExit(
                f"--identify {item!r}: not an identify_modes option this benchmark leaves "
                f"open ({', '.join(sorted(known))})"
            )
        try:
            out[key] = ast.literal_eval(value)
        except (ValueError, SyntaxError):
            raise SystemExit(f"--identify {item!r}: the value is not a Python literal") from None
    return out


def _text(options: dict[str, Any]) -> str:
    return "".join(f", {k}={v!r}" for k, v in options.items())


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="100 seeds (default 400)")
    ap.add_argument("--seeds", type=int, default=None, help="number of noise seeds")
    ap.add_argument("--snr", type=float, default=40.0, help="SNR in dB (default 40)")
    ap.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (default 1)")
    ap.add_argument(
        "--json",
        help="output JSON (default results/crlb.json; crlb-<options>.json with --identify)",
    )
    ap.add_argument(
        "--identify",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an identify_modes option (Python literal), e.g. search=False; repeatable",
    )
    ap.add_argument("--no-sdypy", action="store_true", help="skip sdypy-EMA")
    a = ap.parse_args(argv)
    options = identify_options(a.identify)
    if a.json is None:
        tag = "".join(f"-{k}={v!r}" for k, v in options.items())
        a.json = str(RESULTS_DIR / f"crlb{tag}.json")
    n_seeds = a.seeds if a.seeds is not None else (100 if a.quick else 400)
    pool = limit_blas(a.blas_threads)
    t_start = time.perf_counter()

    tyre = RingTyre()
    tr = tyre.truth((0.0, 400.0))
    f = tyre_lines()
    exact = tr.frf(f)
    h0 = np.asarray(exact.H)
    vis_all = tr.select("visible")
    inb = vis_all[tr.frequency_hz[vis_all] <= 200.0]
    above = vis_all[tr.frequency_hz[vis_all] > 200.0][:2]
    p_true = tr.poles[inb]
    f_true, z_true = np.abs(p_true) / (2 * np.pi), -p_true.real / np.abs(p_true)
    m = inb.size
    sigma = np.sqrt(np.mean(np.abs(h0[:, 0]) ** 2, axis=-1)) * 10 ** (-a.snr / 20)

    def res_of(idx: NDArray[np.intp]) -> NDArray[np.complex128]:
        return np.asarray(tr.psi_points[:, idx] * tr.psi_drive[0, idx][None, :])

    bound = crlb(f, p_true, res_of(inb), sigma, m)
    both = np.concatenate([inb, above])
    bound2 = crlb(f, tr.poles[both], res_of(both), sigma, m)

    use_sdypy = sdypy_available() and not a.no_sdypy
    est: dict[str, dict[str, list[Any]]] = {
        "tyredamp": {"f": [], "z": [], "sf": [], "sz": [], "t": []},
        "sdypy-EMA": {"f": [], "z": [], "sf": [], "sz": [], "t": []},
    }
    failures: dict[str, list[dict[str, Any]]] = {"tyredamp": [], "sdypy-EMA": []}
    # fits that found every true mode and kept a noise mode too (the mode test's
    # false alarms, at its stated rate): scored on the true modes
    extra: list[dict[str, Any]] = []
    for k in range(n_seeds):
        seed = 10_000 + k
        h = add_noise(h0, a.snr, seed)
        frf = exact.with_H(h)
        t0 = time.perf_counter()
        r = identify_modes(frf, band=(0.0, 200.0), model="complex", **options)
        r = r.models["complex"]
        dt = time.perf_counter() - t0
        idx = match_modes(r.frequency_hz, f_true)
        if np.any(idx < 0):
            failures["tyredamp"].append({"seed": seed, "n_modes": r.n_modes})
        else:
            if r.n_modes != m:  # every true mode found, and a noise mode beside them
                others = np.setdiff1d(np.arange(r.n_modes), idx)
                extra.append({"seed": seed, "frequency_hz": r.frequency_hz[others].tolist()})
            e = est["tyredamp"]
            e["f"].append(r.frequency_hz[idx])
            e["z"].append(r.damping_ratio[idx])
            e["sf"].append(np.asarray(r.std["frequency_hz"])[idx])
            e["sz"].append(np.asarray(r.std["damping_ratio"])[idx])
            e["t"].append(dt)
        if use_sdypy:
            case = Case(
                name="tyre",
                frf=frf,
                exact=h0,
                band=(float(f[0]), float(f[-2])),
                poles=p_true,
                psi=tr.psi_points[:, inb],
                noise="",
            )
            s = run_sdypy(case, pol_order_high=30)
            fs = np.abs(s.poles) / (2 * np.pi)
            idx = match_modes(fs, f_true)
            if np.any(idx < 0):
                failures["sdypy-EMA"].append({"seed": seed, "n_modes": int(fs.size)})
            else:
                e = est["sdypy-EMA"]
                e["f"].append(fs[idx])
                e["z"].append(-s.poles.real[idx] / np.abs(s.poles[idx]))
                e["t"].append(s.t_total)
        if (k + 1) % 25 == 0:
            print(f"  {k + 1}/{n_seeds} seeds ({time.perf_counter() - t_start:.0f} s)", flush=True)

    tools: dict[str, Any] = {}
    for tool, e in est.items():
        if not e["f"]:
            continue
        F, Z = np.array(e["f"]), np.array(e["z"])
        n = F.shape[0]
        std_f, std_z = F.std(axis=0, ddof=1), Z.std(axis=0, ddof=1)
        # 95 % interval of a standard deviation from n Gaussian samples: about +-1.96/sqrt(2(n-1))
        half = 1.96 / np.sqrt(2 * (n - 1))
        tools[tool] = {
            "n_ok": n,
            "n_failed": len(failures[tool]),
            "failures": failures[tool],
            "n_extra": len(extra) if tool == "tyredamp" else 0,
            "extra": extra if tool == "tyredamp" else [],
            "std_frequency_hz": std_f,
            "std_damping_ratio": std_z,
            "ratio_frequency": std_f / bound["frequency_hz"],
            "ratio_damping": std_z / bound["damping_ratio"],
            "ratio_frequency_bound2": std_f / bound2["frequency_hz"],
            "ratio_damping_bound2": std_z / bound2["damping_ratio"],
            "ratio_relative_uncertainty": half,
            "bias_frequency_hz": F.mean(axis=0) - f_true,
            "bias_damping_ratio": Z.mean(axis=0) - z_true,
            "rmse_ratio_frequency": np.sqrt(np.mean((F - f_true) ** 2, axis=0))
            / bound["frequency_hz"],
            "rmse_ratio_damping": np.sqrt(np.mean((Z - z_true) ** 2, axis=0))
            / bound["damping_ratio"],
            "mean_time_s": float(np.mean(e["t"])),
            "median_time_s": float(np.median(e["t"])),
        }
        if e["sf"]:
            tools[tool]["reported_std_over_bound_frequency"] = (
                np.mean(e["sf"], axis=0) / bound["frequency_hz"]
            )
            tools[tool]["reported_std_over_bound_damping"] = (
                np.mean(e["sz"], axis=0) / bound["damping_ratio"]
            )

    rows = []
    for n in range(m):
        t = tools.get("tyredamp", {})
        s = tools.get("sdypy-EMA", {})
        rows.append(
            [
                n + 1,
                f_true[n],
                z_true[n],
                bound["frequency_hz"][n],
                bound["damping_ratio"][n],
                t.get("ratio_frequency", [np.nan] * m)[n],
                t.get("ratio_damping", [np.nan] * m)[n],
                t.get("ratio_frequency_bound2", [np.nan] * m)[n],
                t.get("ratio_damping_bound2", [np.nan] * m)[n],
                t.get("rmse_ratio_frequency", [np.nan] * m)[n],
                t.get("rmse_ratio_damping", [np.nan] * m)[n],
                t.get("reported_std_over_bound_damping", [np.nan] * m)[n],
                s.get("ratio_frequency", [np.nan] * m)[n],
                s.get("ratio_damping", [np.nan] * m)[n],
            ]
        )
    t = tools.get("tyredamp", {})
    print_table(
        [
            "mode",
            "f Hz",
            "zeta",
            "CRLB f Hz",
            "CRLB zeta",
            "std/CRLB f",
            "std/CRLB z",
            "f (bound 2)",
            "z (bound 2)",
            "rmse/CRLB f",
            "rmse/CRLB z",
            "reported/CRLB z",
            "sdypy f",
            "sdypy z",
        ],
        rows,
        title=(
            f"\n== tyredamp identify_modes (complex{_text(options)}) std over the CRLB, "
            f"virtual tyre, median {1e3 * t.get('median_time_s', np.nan):.1f} ms, "
            f"{a.snr:g} dB, {t.get('n_ok', 0)} seeds ok ({t.get('n_extra', 0)} of them kept a "
            f"noise mode beside the true ones), {t.get('n_failed', 0)} missed a true mode "
            f"(95 % interval of each ratio about "
            f"+-{100 * t.get('ratio_relative_uncertainty', 0):.0f} %)"
        ),
    )
    worst = max(np.max(t["ratio_frequency"]), np.max(t["ratio_damping"])) if t else np.nan
    print(
        f"largest std/CRLB ratio: {worst:.3f} "
        f"(target <= 1.5: {'met' if worst <= 1.5 else 'NOT met'})"
    )
    doc = {
        "benchmark": "perf_crlb",
        "quick": a.quick,
        "machine": machine_info(a.blas_threads),
        "elapsed_s": time.perf_counter() - t_start,
        "snr_db": a.snr,
        "n_seeds": n_seeds,
        "identify_options": options,
        "noise_model": (
            "circular complex Gaussian on the FRF, per line and output, "
            "E|e_j|^2 = (rms_f|H_j| 10^(-SNR/20))^2; defined on the FRF, not derived from averages"
        ),
        "bound_model": (
            "eq. [10] modal sum of the visible in-band modes + real upper/lower residual per "
            "output; residues and residuals are nuisance parameters; bound 2 adds the two "
            "visible modes above the band as free nuisance modes"
        ),
        "truth": {"frequency_hz": f_true, "damping_ratio": z_true},
        "crlb": {k: v for k, v in bound.items() if k != "cov_pole"},
        "crlb_with_out_of_band_modes": {k: v for k, v in bound2.items() if k != "cov_pole"},
        "tools": tools,
        "worst_ratio": worst,
        "target_met": bool(worst <= 1.5),
    }
    print(f"wrote {write_json(doc, a.json)} ({doc['elapsed_s']:.0f} s)")
    del pool
    return doc


if __name__ == "__main__":
    main()
