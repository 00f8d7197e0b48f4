"""A campaign's results on the virtual campaign against the truth it was made from.

The truth of a virtual campaign (``truth.json`` of
:func:`~tyredamp.campaign.virtual.write_virtual_campaign`) holds the exact
visible modes of every test and of the held-out pressures. Under a load the
contact patch splits the doubled modes and mixes wave numbers, and near the
air cavity's resonance ring and cavity modes hybridise, so the wave number of
a true shape (its strongest harmonic) can change along a sweep while the mode
itself goes on. The true modes are therefore followed through the conditions
of each tyre as *true branches*, with the exact shapes, frequencies and
damping ratios, by the same assignment the campaign tracks its identified
modes with (:func:`~tyredamp.campaign.tracking.track_modes`: MAC, frequency
and damping, doubled modes as pairs); a branch's wave number is the one most
of its modes carry. An identified family then holds one true branch per
tyre (a pair family: one true pair, each slot one member); two branches in
one family are a swap.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["compare_with_truth", "true_branches"]

#: Largest relative frequency difference of an identified mode and its true mode.
MATCH_REL = 0.05

Branch = tuple[str, str]  # (true family, true slot)


def true_branches(truth: dict[str, Any]) -> dict[tuple[str, int], tuple[str, str, int]]:
    """The true branch of every visible true mode of the radial tests and held-out pressures.

    Returns ``(key, mode index) -> (branch, slot, wave number)`` where ``key``
    is the test's ``file`` (held out: ``"held:{tyre}:{load}:{pressure}"``),
    ``branch`` the true family (``{tyre}:F{k}``), ``slot`` ``a``/``b`` for a
    pair ("" else) and the wave number the majority of the branch's modes carry.
    """
    from .tracking import ModeSet, track_modes

    groups: dict[str, list[tuple[str, dict[str, Any]]]] = {}
    for t in truth["tests"]:
        if t.get("study") == "radial":
            groups.setdefault(t["tyre"], []).append((t["file"], t))
    for h in truth.get("held_out") or []:
        key = f"held:{h['tyre']}:{h['load_n']:g}:{h['pressure_bar']:g}"
        groups.setdefault(h["tyre"], []).append((key, h))
    out: dict[tuple[str, int], tuple[str, str, int]] = {}
    for tyre, entries in groups.items():
        sets = []
        for key, e in entries:
            modes = e["modes"]
            shapes = np.array([[complex(a, b) for a, b in m["shape"]] for m in modes]).T
            n_pts = len(modes[0]["shape"]) if modes else 0
            sets.append(
                ModeSet(
                    key,
                    {"tyre": tyre, "pressure_bar": e["pressure_bar"], "load_n": e["load_n"]},
                    np.array([m["frequency_hz"] for m in modes], dtype=float),
                    np.array([m["damping_ratio"] for m in modes], dtype=float),
                    shapes.reshape(n_pts, len(modes)),
                    tuple(str(k + 1) for k in range(n_pts)),
                )
            )
        tr = track_modes(sets)
        waves: dict[str, Counter[int]] = {}
        for (key, q), fam in tr.family.items():
            e = dict(entries)[key]
            waves.setdefault(fam, Counter())[int(e["modes"][q]["wave_number"])] += 1
        for (key, q), fam in tr.family.items():
            wave = waves[fam].most_common(1)[0][0]
            out[(key, q)] = (f"{tyre}:{fam}", tr.slot[(key, q)], wave)
    return out


def _true_match(
    freqs: NDArray[np.float64], shapes: NDArray[np.complex128], truth: list[dict[str, Any]]
) -> list[int | None]:
    """The index of the true mode matched to each identified mode (assignment on MAC and f)."""
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
            if mac >= MAC_MIN and rel < MATCH_REL:
                cost[i, j] = (1 - mac) + rel
    out: list[int | None] = [None] * int(freqs.size)
    for i, j in zip(*linear_sum_assignment(cost), strict=True):
        if cost[i, j] < 1e6:
            out[int(i)] = int(j)
    return out


def _identified(
    truth: dict[str, Any], runs: Any, branches: dict[tuple[str, int], tuple[str, str, int]]
) -> tuple[dict[tuple[str, int], tuple[str, str, int] | None], dict[tuple[str, int], int]]:
    """True branch of every identified mode, and the wave number of weak true modes matched."""
    from . import steps

    by_file = {t["file"]: t for t in truth["tests"] if t["study"] == "radial"}
    found: dict[tuple[str, int], tuple[str, str, int] | None] = {}
    weak: dict[tuple[str, int], int] = {}  # (test, mode) -> wave number of a weak true mode
    for r in runs:
        t = by_file.get(r.spec.rel)
        recs = steps.mode_records(r.spec.study, r.documents)
        if t is None or not recs:
            continue
        freqs = np.array([m["frequency_hz"] for m in recs], dtype=float)
        shapes = np.column_stack([m["shape"] for m in recs])
        match = _true_match(freqs, shapes, t["modes"])
        rest = [k for k, m in enumerate(match) if m is None]
        if rest and t.get("weak_modes"):
            # identified modes that are no visible mode: a weakly driven true mode?
            again = _true_match(freqs[rest], shapes[:, rest], t["weak_modes"])
            for k, j in zip(rest, again, strict=True):
                if j is not None:
                    weak[(r.spec.test_id, k + 1)] = int(t["weak_modes"][j]["wave_number"])
        for k, j in enumerate(match):
            found[(r.spec.test_id, k + 1)] = None if j is None else branches[(t["file"], j)]
    return found, weak


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
        ``families``: family -> {tyre: set of wave numbers of its true
        branches} (module docstring); ``branches``: family -> {tyre: set of
        true branches}; ``unmatched``: identified modes with no true mode;
        ``weak``: identified modes that are measurable true modes below the
        visibility threshold (``weak_modes`` of the truth: test, mode,
        frequency, wave number); ``swaps``: families holding two true
        branches for one tyre (family, tyre, their wave numbers); ``pairs``:
        families tracked as pairs; ``slot_swaps``: a pair's slot (``a``/``b``)
        holding both true members of a pair for one tyre; ``held_out``: one
        row per (family, tyre, load, held-out pressure) with the trend, the
        truth of the family's branch there and the relative error;
        ``max_held_out_error``.
    """
    branches = true_branches(truth)
    found, weak = _identified(truth, runs, branches)
    families: dict[str, dict[str, set[int | None]]] = {}
    fam_branches: dict[str, dict[str, Counter[str]]] = {}
    slots: dict[tuple[str, str, str], Counter[Branch]] = {}
    unmatched, weak_found = [], []
    for row in results.modes:
        key = (row["test_id"], row["mode"])
        match = found.get(key)
        wn = None if match is None else match[2]
        if match is None and key in weak:
            wn = weak[key]
            weak_found.append((row["test_id"], row["mode"], row["frequency_hz"], wn))
        elif match is None:
            unmatched.append((row["test_id"], row["mode"], row["frequency_hz"]))
        families.setdefault(row["family"], {}).setdefault(row["tyre"], set()).add(wn)
        if match is not None:
            by = fam_branches.setdefault(row["family"], {}).setdefault(row["tyre"], Counter())
            by[match[0]] += 1
            slots.setdefault((row["family"], row["slot"], row["tyre"]), Counter())[
                (match[0], match[1])
            ] += 1
    wave_of = {b: w for b, _, w in branches.values()}
    swaps = [
        (fam, tyre, sorted(wave_of[b] for b in c))
        for fam, d in fam_branches.items()
        for tyre, c in d.items()
        if len(c) > 1
    ]
    slot_swaps = [(k, sorted(s for _, s in c)) for k, c in slots.items() if k[1] and len(c) > 1]
    held = _held_out(results, truth, branches, slots)
    return {
        "families": families,
        "branches": {f: {t: set(c) for t, c in d.items()} for f, d in fam_branches.items()},
        "unmatched": unmatched,
        "weak": weak_found,
        "swaps": swaps,
        "pairs": sorted({k[0] for k in slots if k[1]}, key=lambda f: int(f[1:])),
        "slot_swaps": slot_swaps,
        "held_out": held,
        "max_held_out_error": max((abs(h["relative_error"]) for h in held), default=float("nan")),
    }


def _held_out(
    results: Any,
    truth: dict[str, Any],
    branches: dict[tuple[str, int], tuple[str, str, int]],
    slots: dict[tuple[str, str, str], Counter[Branch]],
) -> list[dict[str, Any]]:
    """The frequency-against-pressure trends at the held-out pressures against their branch."""
    held = []
    for about, fit, _ in results.fits:
        if about["quantity"] != "frequency_hz" or about["condition"] != "pressure_bar":
            continue
        c = slots.get((about["family"], about["slot"], about["tyre"]))
        if not c:
            continue
        (branch, slot), _ = c.most_common(1)[0]
        load = about["fixed"].get("load_n")
        for h in truth["held_out"]:
            if h["tyre"] != about["tyre"] or h["load_n"] != load:
                continue
            if not fit.x0 - fit.xs <= h["pressure_bar"] <= fit.x0 + fit.xs:
                continue  # only inside the tested range of this series
            key = f"held:{h['tyre']}:{h['load_n']:g}:{h['pressure_bar']:g}"
            true = [
                (m["frequency_hz"], w)
                for q, m in enumerate(h["modes"])
                for b, s, w in [branches.get((key, q), ("", "", -1))]
                if b == branch and (s == slot or not slot or not s)
            ]
            if len(true) != 1:
                continue
            f, sf = fit.predict([h["pressure_bar"]])
            held.append(
                {
                    "family": about["family"],
                    "slot": about["slot"],
                    "wave_number": true[0][1],
                    "tyre": about["tyre"],
                    "load_n": load,
                    "pressure_bar": h["pressure_bar"],
                    "trend_hz": float(f[0]),
                    "trend_std_hz": float(sf[0]),
                    "true_hz": true[0][0],
                    "relative_error": float(f[0] / true[0][0] - 1),
                }
            )
    return held
