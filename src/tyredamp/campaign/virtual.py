"""A virtual test campaign: several truck tyres x pressures x loads, plus the lateral rig.

Each virtual tyre is the physical ring tyre of :mod:`tyredamp.virtual`, the
tyre of ``tyredamp simulate radial`` (docs ``virtual-tyre.md``), with
*manufacturing scatter*: its bending stiffness, band mass, radial sidewall
stiffness and radial damping are drawn around the defaults (relative standard
deviations 3, 1, 5 and 5 %, seeded per tyre). Its damping is the physical
one: the rubber losses of band and sidewalls, the air cavity, the 10 g tip
with its 2 N s/m tread loss under each shaker
(:func:`~tyredamp.virtual.sources.tip_loss_damping`) and, under load, the
tread in the contact patch.

Pressure and load
-----------------
The pressure acts through the tyre itself: the hoop tension and the
pressure part of the sidewall stiffness grow with it
(:meth:`~tyredamp.virtual.RingTyreParameters.with_pressure`), and so does
the density of the air in the cavity. A load ``F`` (N) presses the tyre on a flat road
at 180 deg (the shaker is at point 1, 0 deg) through the
:class:`~tyredamp.virtual.ContactPatch`: radial and tangential tread springs
over the patch, whose half-length follows from the deflection ``F / K_hub``
by the MF-Tyre 6.1 contact-length law (Pacejka & Besselink 2012, eq. (A3.7)),
``K_hub`` the tyre's own vertical stiffness at that pressure; a heavier load
or a softer tyre gives a longer patch, which splits the doubled modes more.

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

from ..documents.jsonfile import write_json
from ..exceptions import InputError
from ..io import write_frf
from ..io._safety import atomic_dir, atomic_path, check_output_dir
from ..virtual import (
    Cavity,
    ContactPatch,
    MeasurementLayout,
    RingTyre,
    RingTyreParameters,
)
from .virtual_check import compare_with_truth
from .virtual_rolling import ROLLING_TYRE, write_rolling_tests

__all__ = [
    "TRUTH_KIND",
    "VirtualCampaign",
    "campaign_tyre",
    "check_virtual_output",
    "compare_with_truth",
    "tyre_truth",
    "write_virtual_campaign",
]

BAR = 1.0e5
#: ``kind`` of the truth.json of a virtual campaign.
TRUTH_KIND = "tyredamp-virtual-campaign-truth"


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
        pressure (:mod:`.virtual_rolling`: the tyre of ``tyredamp simulate
        rolling``, without the cavity and the contact patch, which the
        rotating frame does not support; ``truth.json`` says so under
        ``rolling_tyre``; default none).
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


def campaign_tyre(
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
    return RingTyre(
        p, MeasurementLayout(drive_points=drive_points), cavity=Cavity(), contact=contact
    )


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
    truth = campaign_tyre(params, pressure_bar, load_n, drive_points).truth()
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
                    tyre = campaign_tyre(params, p, load, s.drive_points)
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
        "contact": {
            k: getattr(ContactPatch(1.0), k)
            for k in (
                "radial_stiffness",
                "tangential_stiffness",
                "loss_factor",
                "length_sqrt",
                "length_linear",
            )
        },
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
    if s.rolling_speeds_kmh:
        doc["rolling_tyre"] = dict(ROLLING_TYRE)  # what the rolling tests' tyre is and lacks
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
