"""The virtual campaign against its truth: mode families, swaps, held-out pressure trends.

Run: ``python benchmarks/campaign_virtual.py [--data DIR] [--out DIR] [--quick] [--workers N]``.

Writes the virtual campaign (``tyredamp simulate campaign``; or reuses
``--data``), runs it (serially by default, ``--workers N`` on local worker
processes; ``--out`` keeps the results and their cache), and prints: per
family the true wave number of its modes for every tyre (one number each
means no swap), the identified modes with no true mode, and the relative
error of the frequency-against-pressure trends at the held-out pressures
(the midpoints between the tested pressures, where no test was made).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from tyredamp.campaign import load_campaign
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import run_tests
from tyredamp.campaign.virtual import VirtualCampaign, compare_with_truth, write_virtual_campaign


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, help="folder of an existing virtual campaign")
    ap.add_argument("--out", type=Path, help="results folder (default: temporary)")
    ap.add_argument("--quick", action="store_true", help="the small campaign of the tests")
    ap.add_argument("--workers", type=int, help="local worker processes (default: serial)")
    ap.add_argument(
        "--pairs",
        action="store_true",
        help="drive points 1 and 5 (doubled modes seen as pairs; with --quick: 1 tyre)",
    )
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        data = args.data
        if data is None:
            data = tmp / "virtual"
            t0 = time.perf_counter()
            spec = VirtualCampaign.quick() if args.quick else VirtualCampaign()
            if args.pairs:
                n_tyres = 1 if args.quick else spec.n_tyres
                spec = dataclasses.replace(spec, n_tyres=n_tyres, drive_points=(1, 5))
            write_virtual_campaign(data, spec)
            print(f"virtual campaign written in {time.perf_counter() - t0:.1f} s")
        out = args.out if args.out is not None else tmp / "out"
        campaign = load_campaign(data / "campaign.toml")
        t0 = time.perf_counter()
        mode = "serial" if args.workers is None else "local"
        runs = run_tests(campaign, out, mode=mode, workers=args.workers)  # type: ignore[arg-type]
        results = write_outputs(campaign, runs, out, report=False)
        print(f"{len(runs)} tests processed ({mode}) in {time.perf_counter() - t0:.1f} s")
        failed = [(r.spec.rel, r.reason) for r in runs if not r.ok]
        print(f"failed tests: {failed or 'none'}")
        truth = json.loads((data / "truth.json").read_text(encoding="utf-8"))
        check = compare_with_truth(results, truth, runs)
        print("family  label            tests  true wave number per tyre")
        n_tests = {f["family"]: f["n_tests"] for f in results.summary["families"]}
        label = {f["family"]: f["label"] for f in results.summary["families"]}
        for fam, by_tyre in sorted(check["families"].items(), key=lambda kv: int(kv[0][1:])):
            waves = ", ".join(
                f"{t}: {sorted(v, key=str)}" for t, v in sorted(by_tyre.items(), key=str)
            )
            print(f"{fam:<7} {label[fam]:<16} {n_tests[fam]:>5}  {waves}")
        print(f"swaps (a family with two true branches for one tyre): {check['swaps'] or 'none'}")
        print(f"identified modes with no true mode: {check['unmatched'] or 'none'}")
        print(f"families tracked as pairs (slots a, b): {check['pairs'] or 'none'}")
        print(f"pair slots holding both true members: {check['slot_swaps'] or 'none'}")
        _print_attachment_share(truth)
        held = check["held_out"]
        print(
            f"held-out pressure trends: {len(held)} points, max |relative error| "
            f"{100 * check['max_held_out_error']:.4f} % (target 0.5 %)"
        )
        worst = sorted(held, key=lambda h: -abs(h["relative_error"]))[:5]
        for h in worst:
            print(
                f"  {h['family']} (n={h['wave_number']}) tyre {h['tyre']} {h['load_n']:g} N "
                f"{h['pressure_bar']:g} bar: trend {h['trend_hz']:.4f} +- {h['trend_std_hz']:.4f} "
                f"Hz, truth {h['true_hz']:.4f} Hz, error {100 * h['relative_error']:+.4f} %"
            )


def _print_attachment_share(truth: dict) -> None:
    """Share of the shaker tips in the off-diagonal modal damping of the first tyre."""
    from tyredamp.campaign.virtual import campaign_tyre, tyre_parameters
    from tyredamp.virtual.sources import damping_decomposition

    spec = truth["spec"]
    params = tyre_parameters(0, spec["seed"])
    worst = 0.0
    for load in spec["loads_n"]:
        for p in (min(spec["pressures_bar"]), max(spec["pressures_bar"])):
            tyre = campaign_tyre(params, p, load, tuple(spec["drive_points"]))
            d = damping_decomposition(tyre)
            k = d.names.index("attachment")
            worst = max(worst, abs(float(d.share[k])), float(d.norm_ratio[k]))
    print(
        f"drive-point attachment in the off-diagonal C' (tyre 1, extreme pressures): "
        f"at most {100 * worst:.1f} % (share or norm ratio)"
    )


if __name__ == "__main__":
    main()
