"""Campaign speed: serial vs the default local pool vs a cached rerun; parallel efficiency.

Run: ``python benchmarks/campaign_scaling.py [--data DIR] [--tests 200] [--workers 2] [--dask]``.

Part 1, the command end to end (``tyredamp campaign``, a new process each,
imports and report included) on the virtual campaign of
``tyredamp simulate campaign`` (48 tests; written to a temporary folder
first unless ``--data`` names one): ``--serial`` and the default (local
process pool) from an empty output folder, then the default again on the
default's folder (every step cached, outputs unchanged).

Part 2, the runner alone (:func:`tyredamp.campaign.runner.run_tests`, no
outputs) on ``--tests`` tests (the virtual campaign's files copied under new
names until there are that many; every test computed, none from a cache):
serially, then on the local pool with ``--workers`` processes (and on a
local Dask cluster with ``--dask``). Printed: wall time, speed-up, parallel
efficiency ``T_serial / (N T_N)``, the CPU the tasks got over the wall time
("cores got": on a machine shared with other jobs this, not N, bounds the
speed-up), the load average, and whether the tidy mode table equals the
serial one byte for byte.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from tyredamp.campaign import load_campaign
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import dask_client, run_tests
from tyredamp.campaign.virtual import VirtualCampaign, write_virtual_campaign


def _command(args: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-c", "from tyredamp.cli import main; main()", "campaign", *args],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - t0


def _many(data: Path, n: int, root: Path) -> Path:
    """A campaign file of ``n`` tests: the virtual campaign's tests, copied under new names."""
    text = (data / "campaign.toml").read_text(encoding="utf-8")
    head, *blocks = text.split("[[tests]]")
    out = [head]
    (root / "data").mkdir(parents=True, exist_ok=True)
    k = 0
    while len(out) - 1 < n:
        for block in blocks:
            if len(out) - 1 == n:
                break
            m = re.search(r'files = "([^"]+)"', block)
            assert m is not None
            src = data / m.group(1)
            dst = root / "data" / f"c{k}_{src.name}"
            shutil.copyfile(src, dst)
            out.append(block.replace(m.group(1), f"data/{dst.name}"))
        k += 1
    path = root / "many.toml"
    path.write_text("[[tests]]".join(out), encoding="utf-8")
    return path


def _part1(data: Path, tmp: Path) -> None:
    camp = str(data / "campaign.toml")
    n = len(load_campaign(camp).tests)
    print(f"part 1: tyredamp campaign on {n} tests (new process each, report included)")
    rows = [
        ("--serial", _command([camp, "--out", str(tmp / "p1s"), "--serial"])),
        ("default (pool)", _command([camp, "--out", str(tmp / "p1d")])),
        ("cached rerun", _command([camp, "--out", str(tmp / "p1d")])),
    ]
    same = (tmp / "p1s" / "modes.csv").read_bytes() == (tmp / "p1d" / "modes.csv").read_bytes()
    for name, t in rows:
        print(f"  {name:<16} {t:8.2f} s")
    print(f"  tidy table of the pool run equal to the serial one: {'yes' if same else 'NO'}")
    print(f"  load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


def _part2(data: Path, tmp: Path, n: int, workers: int, use_dask: bool) -> None:
    campaign = load_campaign(_many(data, n, tmp / "many"))
    print(f"part 2: run_tests on {len(campaign.tests)} tests, every step computed")
    import tyredamp.studies.radial  # noqa: F401 - imports paid before any timing

    t0 = time.perf_counter()
    runs = run_tests(campaign, tmp / "p2s", mode="serial")
    t_serial = time.perf_counter() - t0
    write_outputs(campaign, runs, tmp / "p2s", report=False)
    ref = (tmp / "p2s" / "modes.csv").read_bytes()
    rows = [("serial", 1, t_serial, sum(r.cpu_seconds for r in runs) / t_serial, "yes")]
    configs = [("pool", "local")] + ([("dask", "dask")] if use_dask else [])
    for name, mode in configs:
        out = tmp / f"p2{name}"
        client = cluster = None
        if mode == "dask":
            client, cluster = dask_client("dask", workers)
        t0 = time.perf_counter()
        runs = run_tests(campaign, out, mode=mode, workers=workers, client=client)  # type: ignore[arg-type]
        t = time.perf_counter() - t0
        if client is not None:
            client.close()
            cluster.close()
        write_outputs(campaign, runs, out, report=False)
        same = "yes" if (out / "modes.csv").read_bytes() == ref else "NO"
        rows.append((f"{name} x{workers}", workers, t, sum(r.cpu_seconds for r in runs) / t, same))
    print(
        f"  {'run':<10} {'wall [s]':>9} {'speed-up':>9} {'efficiency':>11} {'cores got':>10} same"
    )
    for name, w, t, got, same in rows:
        print(
            f"  {name:<10} {t:9.2f} {t_serial / t:9.2f} {100 * t_serial / (w * t):10.0f}% "
            f"{got:10.2f} {same}"
        )
    print(f"  load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, help="folder of an existing virtual campaign")
    ap.add_argument("--tests", type=int, default=200, help="tests of part 2")
    ap.add_argument("--workers", type=int, default=2, help="local processes of part 2")
    ap.add_argument("--dask", action="store_true", help="part 2 on a local Dask cluster too")
    ap.add_argument("--skip", choices=("1", "2"), help="skip part 1 or part 2")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        data = args.data
        if data is None:
            data = tmp / "virtual"
            write_virtual_campaign(data, VirtualCampaign())
        if args.skip != "1":
            _part1(data, tmp)
        if args.skip != "2":
            _part2(data, tmp, args.tests, args.workers, args.dask)


if __name__ == "__main__":
    main()
