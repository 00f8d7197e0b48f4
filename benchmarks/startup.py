"""Start-up time of the command line beside ``python -c "import numpy"``.

Run: ``python benchmarks/startup.py [--repeat 15]``. Each command runs in a
fresh interpreter (``sys.executable``), one BLAS thread; the table gives the
median and the minimum wall time over the repeats and the ratio of the
medians to ``import numpy`` (target: ``tyredamp --help`` and ``--version``
within 1.5x; the subcommands are imported only when they run, see
``tyredamp.cli.COMMANDS``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

CASES: dict[str, list[str]] = {
    'python -c "import numpy"': ["-c", "import numpy"],
    "tyredamp --version": ["-c", "from tyredamp.cli import main; main(['--version'])"],
    "tyredamp --help": ["-c", "from tyredamp.cli import main; main(['--help'])"],
    "tyredamp modal --help": ["-c", "from tyredamp.cli import main; main(['modal', '--help'])"],
}


def _time(args: list[str], repeat: int) -> list[float]:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, *args], check=True, capture_output=True, env=env)
        out.append(time.perf_counter() - t0)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15, help="runs per command")
    opts = parser.parse_args()
    _time(CASES['python -c "import numpy"'], 2)  # warm the file cache
    results = {name: _time(args, opts.repeat) for name, args in CASES.items()}
    base = statistics.median(results['python -c "import numpy"'])
    print(f"{'command':<28} {'median s':>9} {'min s':>7} {'/ numpy':>8}")
    for name, times in results.items():
        med = statistics.median(times)
        print(f"{name:<28} {med:9.3f} {min(times):7.3f} {med / base:8.2f}")


if __name__ == "__main__":
    main()
