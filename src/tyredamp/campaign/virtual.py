"""A virtual test campaign: several truck tyres x pressures x loads, plus the lateral rig.

Each virtual tyre is the ring tyre of :mod:`tyredamp.virtual` with
*manufacturing scatter*: its bending stiffness, band mass, radial sidewall
stiffness and radial damping are drawn around the defaults (relative standard
deviations 3, 1, 5 and 5 %, seeded per tyre).

Load
----
The ring tyre has no contact model, so a load ``F`` (N) on a flat surface is
modelled as a small documented change: a *contact-patch foundation* of
radial stiffness ``k_c`` per unit length (N/m^2, default 1e6, two thirds of
the sidewall ``k_r``) over the arc of the contact patch at 180 deg (the
bottom; the shaker is at point 1, 0 deg). The patch length is
``2 a = F / (p b)`` (contact pressure equal to the inflation pressure ``p``
over the belt width ``b``); each ring node gets ``k_c`` times the length of
its cell inside the patch (:func:`contact_patch`), so the stiffness changes
smoothly with load and pressure. Rolling, tread deflection and the change of
the hoop tension by the load are not modelled.

The truth of every test (exact modes at the 16 points) is written beside it,
and also the truth at *held-out* pressures (the midpoints between tested
pressures, no test there) so that a campaign's pressure trends can be
checked where no test was made.
"""

from __future__ import annotations

import itertools
import json
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..documents.jsonfile import write_json
from ..exceptions import InputError
from ..io import write_frf
from ..io._safety import atomic_dir, atomic_path, check_output_dir
from ..virtual import (
    Cavity,
    ContactPatch,
    Imperfection,
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
)

__all__ = [
    "TRUTH_KIND",
    "VirtualCampaign",
    "check_virtual_output",
    "compare_with_truth",
    "contact_patch",
    "tyre_truth",
    "write_virtual_campaign",
]

BAR = 1.0e5
#: ``kind`` of the truth.json of a virtual campaign.
TRUTH_KIND = "tyredamp-virtual-campaign-truth"
#: Default contact-patch foundation stiffness per unit length, N/m^2.
CONTACT_STIFFNESS = 1.0e6


@dataclass(frozen=True)
class VirtualCampaign:
    """The sizes of a virtual campaign.

    Attributes
    ----------
    n_tyres : int
        Tyres (each with its own manufacturing scatter).
    pressures_bar : tuple of float
        Tested inflation pressures, bar (increasing).
    loads_n : tuple of float
        Tested loads, N.
    lateral_speeds_kmh : tuple of float
        Speeds of the lateral rolling-rig tests (at ``lateral_pressure_bar``).
    periods : int
        Chirp periods (averages) per radial test.
    seed : int
        Seed of the scatter and of every noise generator.
    drive_points : tuple of int
        Shaker points of the radial tests (default point 1, as in paper 000,
        which sees only the member of each doubled mode with an antinode
        there; ``(1, 5)``, 90 deg apart, sees both members of the odd wave
        numbers, split by the contact patch: a multi-reference campaign with
        doubled modes as pairs).
    rolling_speeds_kmh : tuple of float
        Speeds of the output-only rolling tests of the first tyre at every
        pressure (:mod:`.virtual_rolling`; default none).
    """

    n_tyres: int = 3
    pressures_bar: tuple[float, ...] = (6.0, 6.75, 7.5, 8.25, 9.0)
    loads_n: tuple[float, ...] = (10000.0, 20000.0, 30000.0)
    lateral_speeds_kmh: tuple[float, ...] = (5.0, 10.0, 15.0)
    lateral_pressure_bar: float = 1.7
    periods: int = 8
    seed: int = 0
    drive_points: tuple[int, ...] = (1,)
    rolling_speeds_kmh: tuple[float, ...] = ()

    @classmethod
    def quick(cls, seed: int = 0) -> VirtualCampaign:
        """A small campaign for tests: 2 tyres x 3 pressures x 1 load, 2 lateral speeds."""
        return cls(2, (6.0, 7.5, 9.0), (20000.0,), (5.0, 10.0), 1.7, 4, seed)

    @property
    def held_out_bar(self) -> tuple[float, ...]:
        """Midpoints between the tested pressures (truth only)."""
        p = self.pressures_bar
        return tuple(0.5 * (a + b) for a, b in itertools.pairwise(p))


def tyre_parameters(index: int, seed: int = 0) -> RingTyreParameters:
    """The parameters of virtual tyre ``index`` with its manufacturing scatter."""
    rng = np.random.default_rng([seed, 9173, index])
    z = rng.standard_normal(4)
    base = RingTyreParameters()
    return replace(
        base,
        bending_stiffness=base.bending_stiffness * (1 + 0.03 * z[0]),
        mass_per_length=base.mass_per_length * (1 + 0.01 * z[1]),
        radial_stiffness_base=base.radial_stiffness_base * (1 + 0.05 * z[2]),
        radial_damping=base.radial_damping * (1 + 0.05 * z[3]),
    )


def contact_patch(
    params: RingTyreParameters,
    load_n: float,
    n_ring: int = 64,
    stiffness: float = CONTACT_STIFFNESS,
) -> tuple[Imperfection, ...]:
    """Radial springs of the contact patch of a load ``load_n`` (N) at 180 deg.

    The patch half-angle is ``a / R`` with ``2 a = F / (p b)``; node ``i`` (at
    ``360 i / n_ring`` deg, cell of width ``2 pi R / n_ring``) gets the spring
    ``stiffness * (length of its cell inside the patch)`` in N/m.

    Raises
    ------
    InputError
        A negative or non-finite load, or a load on an uninflated tyre.
    """
    if not (math.isfinite(load_n) and load_n >= 0):
        raise InputError(f"load_n: expected a load >= 0 N, got {load_n}")
    if load_n == 0:
        return ()
    if params.pressure <= 0:
        raise InputError("load_n: a loaded tyre needs an inflation pressure > 0")
    r = params.radius
    half = load_n / (2 * params.pressure * params.width) / r  # patch half-angle, rad
    h = 2 * np.pi / n_ring
    out = []
    for i in range(n_ring):
        theta = i * h
        lo = max(theta - h / 2, np.pi - half)
        hi = min(theta + h / 2, np.pi + half)
        if hi > lo:
            out.append(Imperfection(math.degrees(theta), stiffness=stiffness * r * (hi - lo)))
    return tuple(out)


def _tyre(
    params: RingTyreParameters,
    pressure_bar: float,
    load_n: float,
    drive_points: tuple[int, ...] = (1,),
) -> RingTyre:
    """The physical virtual tyre of one test: the tyre of ``tyredamp simulate radial``.

    Shaker tips of the default :class:`~tyredamp.virtual.MeasurementLayout`
    (10 g, 2 N s/m tread loss under each tip), the rubber losses of the ring,
    the air cavity and, for ``load_n`` > 0, the loaded
    :class:`~tyredamp.virtual.ContactPatch` (its length from the load and the
    tyre's own vertical stiffness at this pressure), with the physical damping
    (``nonproportionality`` 1).
    """
    p = params.with_pressure(pressure_bar * BAR)
    contact = ContactPatch(load_n) if load_n > 0 else None
    return RingTyre(p, MeasurementLayout(drive_points=drive_points), cavity=Cavity(), contact=contact)


def tyre_truth(
    params: RingTyreParameters,
    pressure_bar: float,
    load_n: float,
    drive_points: tuple[int, ...] = (1,),
) -> list[dict]:
    """The exact visible modes of a virtual tyre at one condition (0-200 Hz).

    One dict per mode: ``wave_number``, ``frequency_hz``, ``damping_ratio``
    and ``shape`` (complex mode at the 16 points as ``[re, im]`` pairs).
    """
    return _truth_modes(params, pressure_bar, load_n, drive_points, "visible")


def weak_truth(
    params: RingTyreParameters,
    pressure_bar: float,
    load_n: float,
    drive_points: tuple[int, ...] = (1,),
) -> list[dict]:
    """The measurable modes below the visibility threshold, as :func:`tyre_truth`.

    Weakly driven (drive-point amplitude under ``VISIBLE_THRESHOLD`` of the
    largest point amplitude) but present in the data: an identification that
    tests modes against the noise may find them, and they are true modes.
    """
    return _truth_modes(params, pressure_bar, load_n, drive_points, "weak")


def _truth_modes(
    params: RingTyreParameters,
    pressure_bar: float,
    load_n: float,
    drive_points: tuple[int, ...],
    which: str,
) -> list[dict]:
    truth = _tyre(params, pressure_bar, load_n, drive_points).truth()
    out = []
    idx = (
        truth.select("visible")
        if which == "visible"
        else np.flatnonzero(truth.measurable & ~truth.visible)
    )
    for i in idx:
        psi = truth.psi_points[:, i]
        out.append(
            {
                "wave_number": int(truth.wave_number[i]),
                "frequency_hz": float(truth.frequency_hz[i]),
                "damping_ratio": float(truth.damping_ratio[i]),
                "shape": [[float(z.real), float(z.imag)] for z in psi],
            }
        )
    return out


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(v))


def write_virtual_campaign(
    out: str | Path,
    spec: VirtualCampaign | None = None,
    progress: Any = None,
) -> dict[str, Any]:
    """Write the virtual campaign into the folder ``out``.

    Writes ``data/T{k}_{p}bar_{F}N.uff`` (radial H1 FRFs, UFF 58b, of the
    virtual modal test: 16 points, the spec's drive points, periodic chirp
    0-200 Hz, 40 dB SNR), ``data/lateral_{v}kmh.npz`` (lateral rig, ground
    force), ``truth.json`` and ``campaign.toml``. ``out`` must be new, empty
    or an earlier virtual campaign holding only its own files
    (:func:`check_virtual_output`); everything is written into a temporary
    folder beside it and renamed into place whole, so an error leaves ``out``
    as it was. Returns the truth document.

    Parameters
    ----------
    out : path
        Folder to write (created, or an earlier virtual campaign replaced whole).
    spec : VirtualCampaign, optional
        Sizes (default the full campaign: 3 tyres x 5 pressures x 3 loads).
    progress : callable, optional
        ``progress(done, total)`` after each test written.
    """
    s = spec if spec is not None else VirtualCampaign()
    MeasurementLayout(drive_points=s.drive_points)  # bad drive points fail before any output
    for p in s.pressures_bar:
        if not (math.isfinite(p) and p > 0):
            raise InputError(f"pressures_bar: expected pressures > 0 bar, got {p}")
    check_virtual_output(out)
    # written into a private folder beside ``out`` and renamed into place whole: an error
    # or an interruption leaves ``out`` as it was
    with atomic_dir(out) as root:
        doc = _write(s, root, progress)
    return doc


def check_virtual_output(out: str | os.PathLike[str]) -> Path:
    """Refuse an output folder that is not new, empty or an earlier virtual campaign; before work.

    An earlier virtual campaign (a ``truth.json`` of kind
    ``tyredamp-virtual-campaign-truth``) is replaced only when the folder holds
    nothing but the files it wrote (its data files, ``truth.json`` and
    ``campaign.toml``); anything else (a campaign's results, a file of yours)
    stops it, and nothing is deleted. See
    :func:`tyredamp.io._safety.check_output_dir`. Returns the real folder.
    """
    return check_output_dir(out, _virtual_files, what="virtual campaign")


def _virtual_files(root: Path) -> list[str] | None:
    try:
        doc = json.loads((root / "truth.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(doc, dict) or doc.get("kind") != TRUTH_KIND:
        return None
    files = [t.get("file") for t in doc.get("tests") or [] if isinstance(t, dict)]
    ok = [
        f
        for f in files
        if isinstance(f, str) and f and not Path(f).is_absolute() and ".." not in Path(f).parts
    ]
    return [*ok, "truth.json", "campaign.toml"]


def _write(s: VirtualCampaign, root: Path, progress: Any) -> dict[str, Any]:
    from .._blas import single_threaded_blas
    from ..signal import estimate_frf
    from ..virtual import run_modal_test
    from ..virtual.lateral_rig import VirtualLateralRig

    data = root / "data"
    data.mkdir(parents=True, exist_ok=True)
    total = s.n_tyres * len(s.pressures_bar) * len(s.loads_n) + len(s.lateral_speeds_kmh)
    total += len(s.rolling_speeds_kmh) * len(s.pressures_bar)
    done = 0
    tests: list[dict[str, Any]] = []
    held: list[dict[str, Any]] = []
    tyres: dict[str, Any] = {}
    with single_threaded_blas():  # small matrices: one thread is fastest
        for t in range(s.n_tyres):
            tid = f"T{t + 1}"
            params = tyre_parameters(t, s.seed)
            tyres[tid] = {
                k: getattr(params, k)
                for k in (
                    "bending_stiffness",
                    "mass_per_length",
                    "radial_stiffness_base",
                    "radial_damping",
                )
            }
            for load in s.loads_n:
                for p in s.pressures_bar:
                    name = f"{tid}_{p:g}bar_{load:g}N.uff"
                    seed = len(tests) + 1 + 1000 * s.seed
                    tyre = _tyre(params, p, load, s.drive_points)
                    test = run_modal_test(tyre, n_periods=s.periods, seed=seed)
                    write_frf(estimate_frf(test.data, "H1"), data / name)
                    tests.append(
                        {
                            "file": f"data/{name}",
                            "study": "radial",
                            "tyre": tid,
                            "pressure_bar": p,
                            "load_n": load,
                            "modes": tyre_truth(params, p, load, s.drive_points),
                            "weak_modes": weak_truth(params, p, load, s.drive_points),
                        }
                    )
                    done += 1
                    if progress is not None:
                        progress(done, total)
                for p in s.held_out_bar:
                    held.append(
                        {
                            "tyre": tid,
                            "pressure_bar": p,
                            "load_n": load,
                            "modes": tyre_truth(params, p, load, s.drive_points),
                        }
                    )
        rig = VirtualLateralRig()
        for v in s.lateral_speeds_kmh:
            name = f"lateral_{v:g}kmh.npz"
            meas = rig.measure(v, s.lateral_pressure_bar, "ground", s.seed)
            write_frf(meas.frf, data / name)
            tests.append(
                {
                    "file": f"data/{name}",
                    "study": "lateral",
                    "tyre": "rig",
                    "pressure_bar": s.lateral_pressure_bar,
                    "speed_kmh": v,
                    "truth": meas.frf.meta.get("truth"),
                }
            )
            done += 1
            if progress is not None:
                progress(done, total)
        if s.rolling_speeds_kmh:
            from .virtual_rolling import write_rolling_tests

            def tick() -> None:
                nonlocal done
                done += 1
                if progress is not None:
                    progress(done, total)

            tests += write_rolling_tests(
                data, tyre_parameters(0, s.seed), s.rolling_speeds_kmh, s.pressures_bar,
                s.seed, progress=tick,
            )  # fmt: skip
    doc = {
        "kind": TRUTH_KIND,
        "version": 1,
        "contact_stiffness_n_m2": CONTACT_STIFFNESS,
        "spec": {
            "n_tyres": s.n_tyres,
            "pressures_bar": list(s.pressures_bar),
            "loads_n": list(s.loads_n),
            "lateral_speeds_kmh": list(s.lateral_speeds_kmh),
            "periods": s.periods,
            "seed": s.seed,
            "drive_points": list(s.drive_points),
            "rolling_speeds_kmh": list(s.rolling_speeds_kmh),
        },
        "tyres": tyres,
        "tests": tests,
        "held_out": held,
    }
    write_json(doc, root / "truth.json")
    with atomic_path(root / "campaign.toml") as tmp:
        tmp.write_text(campaign_file_text(s, tests), encoding="utf-8")
    return doc


def campaign_file_text(spec: VirtualCampaign, tests: list[dict[str, Any]]) -> str:
    """The campaign file (TOML) of a virtual campaign: its settings and one entry per test.

    The modal band is 30-180 Hz: every band edge cuts some mode somewhere in a
    sweep; this one keeps at least 3 Hz (about the half-power half-width
    ``zeta f`` there) between the edge and the nearest true mode at every
    pressure and load of the default campaign (183.0 Hz, tyre 3 at 7.5 bar).
    An edge through a resonance biases the identification (a mode 0.3 Hz
    inside the 200 Hz edge moved the fit of the 51 Hz mode by 0.4 %).
    """
    lines = [
        "# tyredamp campaign file of the virtual campaign (tyredamp simulate campaign)",
        f'name = "virtual truck tyres: {spec.n_tyres} tyres x {len(spec.pressures_bar)} '
        f'pressures x {len(spec.loads_n)} loads"',
        "",
        "[settings.radial.modal]",
        "band = [30.0, 180.0]",
        "",
        "[settings.radial.damping]",
        "samples = 50",
        "",
    ]
    if any(e["study"] == "rolling" for e in tests):
        # rolling records cover 0-200 Hz: a band inside it keeps the SSI off the edges
        lines += ["[settings.rolling.rolling]", "band = [10.0, 190.0]", ""]
    for entry in tests:
        lines.append("[[tests]]")
        lines.append(f"files = {_toml_value(entry['file'])}")
        for k in ("study", "tyre", "pressure_bar", "load_n", "speed_kmh"):
            if k in entry:
                lines.append(f"{k} = {_toml_value(entry[k])}")
        lines.append("")
    return "\n".join(lines)


def _true_match(
    freqs: NDArray[np.float64], shapes: NDArray[np.complex128], truth: list[dict[str, Any]]
) -> list[tuple[int, int] | None]:
    """The true mode matched to each identified mode (assignment on MAC and frequency).

    Each match is ``(wave number, rank)``, ``rank`` the position of the true
    mode among the true modes of that wave number by frequency (0 lower).
    """
    from scipy.optimize import linear_sum_assignment

    from .tracking import MAC_MIN, subspace_mac

    if not truth or freqs.size == 0:
        return [None] * int(freqs.size)
    cost = np.full((freqs.size, len(truth)), 1e6)
    for i in range(freqs.size):
        for j, t in enumerate(truth):
            psi = np.array([complex(a, b) for a, b in t["shape"]])
            mac = subspace_mac(shapes[:, i], psi)
            rel = abs(freqs[i] - t["frequency_hz"]) / t["frequency_hz"]
            if mac >= MAC_MIN and rel < 0.05:
                cost[i, j] = (1 - mac) + rel
    out: list[tuple[int, int] | None] = [None] * int(freqs.size)
    for i, j in zip(*linear_sum_assignment(cost), strict=True):
        if cost[i, j] < 1e6:
            t = truth[int(j)]
            same = sorted(u["frequency_hz"] for u in truth if u["wave_number"] == t["wave_number"])
            out[int(i)] = (int(t["wave_number"]), same.index(t["frequency_hz"]))
    return out


def compare_with_truth(results: Any, truth: dict[str, Any], runs: Any) -> dict[str, Any]:
    """Check a campaign's results on the virtual campaign against its truth.

    Parameters
    ----------
    results : CampaignResults
        From :func:`tyredamp.campaign.outputs.write_outputs`.
    truth : dict
        The ``truth.json`` document of :func:`write_virtual_campaign`.
    runs : sequence of TestRun
        The runs (their mode shapes are matched to the true shapes).

    Returns
    -------
    dict
        ``families``: family -> {tyre: set of true wave numbers} (one number
        each when there is no swap); ``unmatched``: identified modes with no
        true mode; ``weak``: identified modes that are measurable true modes
        below the visibility threshold (``weak_modes`` of the truth: test,
        mode, frequency, wave number); ``swaps``: families holding two wave numbers for one tyre;
        ``pairs``: families tracked as pairs; ``slot_swaps``: a pair's slot
        (``a``/``b``) holding both true members of the pair for one tyre;
        ``held_out``: one row per (family, tyre, load, held-out pressure) with
        the trend, the truth and the relative error; ``max_held_out_error``.
    """
    from . import steps

    by_file = {t["file"]: t for t in truth["tests"] if t["study"] == "radial"}
    wave: dict[tuple[str, int], tuple[int, int] | None] = {}
    weak: dict[tuple[str, int], int] = {}  # (test, mode) -> wave number of a weak true mode
    for r in runs:
        t = by_file.get(r.spec.rel)
        recs = steps.mode_records(r.spec.study, r.documents)
        if t is None or not recs:
            continue
        freqs = np.array([m["frequency_hz"] for m in recs], dtype=float)
        shapes = np.column_stack([m["shape"] for m in recs])
        found = _true_match(freqs, shapes, t["modes"])
        rest = [k for k, m in enumerate(found) if m is None]
        if rest and t.get("weak_modes"):
            # identified modes that are no visible mode: a weakly driven true mode?
            for k, m in zip(
                rest, _true_match(freqs[rest], shapes[:, rest], t["weak_modes"]), strict=True
            ):
                if m is not None:
                    weak[(r.spec.test_id, k + 1)] = m[0]
        for k, m in enumerate(found):
            wave[(r.spec.test_id, k + 1)] = m
    families: dict[str, dict[str, set[int | None]]] = {}
    slots: dict[tuple[str, str, str], set[int]] = {}
    unmatched = []
    weak_found = []
    for row in results.modes:
        key = (row["test_id"], row["mode"])
        match = wave.get(key)
        wn = None if match is None else match[0]
        if match is None and key in weak:
            wn = weak[key]
            weak_found.append((row["test_id"], row["mode"], row["frequency_hz"], wn))
        elif match is None:
            unmatched.append((row["test_id"], row["mode"], row["frequency_hz"]))
        families.setdefault(row["family"], {}).setdefault(row["tyre"], set()).add(wn)
        if match is not None and row["slot"]:
            slots.setdefault((row["family"], row["slot"], row["tyre"]), set()).add(match[1])
    slot_swaps = [(k, sorted(v)) for k, v in slots.items() if len(v) > 1]
    swaps = [
        (fam, tyre, sorted(v, key=str))
        for fam, d in families.items()
        for tyre, v in d.items()
        if len(v - {None}) > 1
    ]
    fam_wave = {
        fam: next(iter(set().union(*d.values()) - {None}), None) for fam, d in families.items()
    }
    held = []
    for about, fit, _ in results.fits:
        if about["quantity"] != "frequency_hz" or about["condition"] != "pressure_bar":
            continue
        n_true = fam_wave.get(about["family"])
        load = about["fixed"].get("load_n")
        for h in truth["held_out"]:
            if h["tyre"] != about["tyre"] or h["load_n"] != load:
                continue
            if not fit.x0 - fit.xs <= h["pressure_bar"] <= fit.x0 + fit.xs:
                continue  # only inside the tested range of this series
            true = sorted(m["frequency_hz"] for m in h["modes"] if m["wave_number"] == n_true)
            slot = about["slot"]
            if slot and len(true) == 2:
                true = [true["ab".index(slot)]]  # a pair: slot a is the lower member
            if len(true) != 1:
                continue
            f, sf = fit.predict([h["pressure_bar"]])
            held.append(
                {
                    "family": about["family"],
                    "slot": about["slot"],
                    "wave_number": n_true,
                    "tyre": about["tyre"],
                    "load_n": load,
                    "pressure_bar": h["pressure_bar"],
                    "trend_hz": float(f[0]),
                    "trend_std_hz": float(sf[0]),
                    "true_hz": true[0],
                    "relative_error": float(f[0] / true[0] - 1),
                }
            )
    return {
        "families": families,
        "unmatched": unmatched,
        "weak": weak_found,
        "swaps": swaps,
        "pairs": sorted({k[0] for k in slots}, key=lambda f: int(f[1:])),
        "slot_swaps": slot_swaps,
        "held_out": held,
        "max_held_out_error": max((abs(h["relative_error"]) for h in held), default=float("nan")),
    }
