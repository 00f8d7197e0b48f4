"""Wall time of one campaign serially and on 1, 2, ... local Dask workers; parallel efficiency.

Run: ``python benchmarks/campaign_scaling.py [--data DIR] [--workers 1 2] [--samples 200]``.

Without ``--data`` a virtual campaign of 2 tyres x 5 pressures at one load
plus one lateral test (11 tests) is written to a temporary folder first (not
timed); ``--data`` reuses the folder of ``tyredamp simulate campaign``. Every
configuration starts from an empty output folder (no cache). The cluster's
start-up (with the imports of the steps on every worker) is timed apart from
the run, and the serial run imports them before its timing too. Printed per configuration: start-up,
run wall time, speed-up and parallel efficiency ``T_serial / (N T_N)``, the
CPU time the tasks got over the wall time (the cores actually obtained: on a
machine shared with other jobs this, not N, bounds the speed-up), the load
average, and whether the tidy mode table is identical to the serial one byte
for byte.
BLAS is limited to one thread in every task (as the campaign always does).
"""

from __future__ import annotations

import argparse
import os
import re
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from tyredamp.campaign import load_campaign
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import dask_client, run_tests
from tyredamp.campaign.virtual import VirtualCampaign, write_virtual_campaign


def _warm() -> None:
    """Import what the steps use (so that no run pays the imports inside its timing)."""
    import tyredamp.documents
    import tyredamp.io
    import tyredamp.studies.lateral
    import tyredamp.studies.radial  # noqa: F401


def _campaign_file(data: Path, samples: int) -> Path:
    text = (data / "campaign.toml").read_text(encoding="utf-8")
    text = re.sub(r"samples = \d+", f"samples = {samples}", text)
    path = data / f"bench_{samples}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, help="folder of an existing virtual campaign")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2], help="worker counts")
    ap.add_argument("--samples", type=int, default=200, help="Monte Carlo samples of damping")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        data = args.data
        if data is None:
            data = tmp / "virtual"
            spec = VirtualCampaign(2, (6.0, 6.75, 7.5, 8.25, 9.0), (20000.0,), (5.0,), 1.7, 4)
            write_virtual_campaign(data, spec)
        campaign = load_campaign(_campaign_file(data, args.samples))
        n = len(campaign.tests)
        print(f"campaign: {n} tests ({campaign.name}), damping samples {args.samples}")
        print(f"machine: {os.cpu_count()} cores (shared with other jobs)")
        _warm()
        t0 = time.perf_counter()
        runs = run_tests(campaign, tmp / "serial", mode="serial")
        t_serial = time.perf_counter() - t0
        cpu = sum(r.cpu_seconds for r in runs)
        write_outputs(campaign, runs, tmp / "serial", report=False)
        ref = (tmp / "serial" / "modes.csv").read_bytes()
        rows = [("serial", 0.0, t_serial, 1.0, 1.0, cpu / t_serial, os.getloadavg()[0], "yes")]
        for w in args.workers:
            t0 = time.perf_counter()
            client, cluster = dask_client("local", w)
            client.run(_warm)
            t_start = time.perf_counter() - t0
            out = tmp / f"w{w}"
            t0 = time.perf_counter()
            runs = run_tests(campaign, out, mode="local", client=client)
            t_run = time.perf_counter() - t0
            load = os.getloadavg()[0]
            cpu = sum(r.cpu_seconds for r in runs)
            client.close()
            cluster.close()
            write_outputs(campaign, runs, out, report=False)
            same = "yes" if (out / "modes.csv").read_bytes() == ref else "NO"
            rows.append(
                (
                    f"{w} worker(s)",
                    t_start,
                    t_run,
                    t_serial / t_run,
                    t_serial / (w * t_run),
                    cpu / t_run,
                    load,
                    same,
                )
            )
        head = (
            "run",
            "start [s]",
            "wall [s]",
            "speed-up",
            "efficiency",
            "cores got",
            "load avg",
            "same table",
        )
        print(f"{head[0]:<12} " + " ".join(f"{h:>10}" for h in head[1:]))
        for name, ts, tr, su, eff, got, load, same in rows:
            print(
                f"{name:<12} {ts:>10.2f} {tr:>10.2f} {su:>10.2f} {100 * eff:>9.0f}% "
                f"{got:>10.2f} {load:>10.1f} {same:>10}"
            )


if __name__ == "__main__":
    main()
