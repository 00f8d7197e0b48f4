"""Start-up time of the command line beside ``python -c "import numpy"``.

Run: ``python benchmarks/startup.py [--repeat 15] [--all-help]``. Each command
runs in a fresh interpreter (``sys.executable``), one BLAS thread, the cases
alternating in order between repeats; the table gives the median and the
minimum wall time over the repeats and the ratio of the medians to ``import
numpy`` (targets: ``tyredamp --help`` and ``--version`` within 1.5x, every
``--help`` under 0.3 s, a refused file under 0.5 s; the subcommands are
imported only when they run, see ``tyredamp.cli.COMMANDS``). Also: ``tyredamp
modal`` refusing a file that does not exist and a file that is not an FRF
file, and ``tyredamp modal`` on a small file (4 outputs x 1 input, 400 lines,
3 modes) beside a plain sdypy-EMA script on the same FRFs (LSCF,
``select_closest_poles`` given the true frequencies, LSFD: what a user would
write) when sdypy-EMA is installed. ``--all-help``: the ``--help`` of every
subcommand.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _cli(*args: str) -> list[str]:
    return ["-c", f"from tyredamp.cli import main; main({list(args)!r})"]


CASES: dict[str, list[str]] = {
    'python -c "import numpy"': ["-c", "import numpy"],
    "tyredamp --version": _cli("--version"),
    "tyredamp --help": _cli("--help"),
    "tyredamp modal --help": _cli("modal", "--help"),
}

#: the small FRF file (written by _small_file) and the sdypy-EMA script on it
SMALL = """
import numpy as np
from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal import ModalModel
f = np.linspace(1.0, 200.0, 400)
fn, z = np.array([40.0, 95.0, 150.0]), np.array([0.02, 0.015, 0.01])
p = -z * 2 * np.pi * fn + 1j * 2 * np.pi * fn * np.sqrt(1 - z**2)
psi = np.array([[1.0, 0.8, 0.5], [0.7, -0.4, 0.9], [0.3, 0.9, -0.6], [0.5, -0.7, -0.2]])
h = ModalModel(p, psi + 0j, psi[:1] + 0j).frf(f, "accelerance").H
h = h + 1e-3 * np.sqrt(np.mean(abs(h) ** 2)) * np.random.default_rng(0).normal(size=h.shape)
write_frf(FRF(f, h, kind="accelerance"), PATH)
"""
SDYPY = """
import numpy as np
from sdypy import EMA
d = np.load(PATH, allow_pickle=False)
m = EMA.Model(frf=d["H"][:, 0], freq=d["frequency"], lower=1.0, upper=200.0,
              pol_order_high=30, frf_form="accelerance")
m.get_poles(method="lscf", show_progress=False)
m.select_closest_poles([40.0, 95.0, 150.0], f_window=20.0)
m.get_constants(method="lsfd", whose_poles="own", f_lower=1.0, f_upper=200.0)
"""


def _env() -> dict[str, str]:
    return {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def _time_once(args: list[str], refused: bool = False) -> float:
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, *args], capture_output=True, env=_env())
    dt = time.perf_counter() - t0
    if (run.returncode != 0) != refused:
        raise SystemExit(f"{args}: exit {run.returncode}: {run.stderr.decode()[-400:]}")
    return dt


def _cases(tmp: Path, all_help: bool) -> dict[str, tuple[list[str], bool]]:
    """Every case: name -> (interpreter arguments, whether the command must fail)."""
    from tyredamp.cli import COMMANDS

    small = tmp / "small.npz"
    code = SMALL.replace("PATH", repr(str(small)))
    subprocess.run([sys.executable, "-c", code], check=True, env=_env())
    bad = tmp / "bad.csv"
    bad.write_text("not, an, frf\n1, 2\n")
    out = str(tmp / "modes.json")
    cases = {name: (args, False) for name, args in CASES.items()}
    if all_help:
        for name in sorted(COMMANDS):
            cases[f"tyredamp {name} --help"] = (_cli(name, "--help"), False)
    cases["tyredamp modal (no such file)"] = (_cli("modal", str(tmp / "none.uff"), "-o", out), True)
    cases["tyredamp modal (not an FRF)"] = (_cli("modal", str(bad), "-o", out), True)
    cases["tyredamp modal small.npz"] = (_cli("modal", str(small), "-o", out), False)
    try:
        import sdypy.EMA  # noqa: F401
    except ImportError:
        return cases
    cases["sdypy-EMA script, small.npz"] = (["-c", SDYPY.replace("PATH", repr(str(small)))], False)
    return cases


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15, help="runs per command")
    parser.add_argument("--all-help", action="store_true", help="--help of every subcommand")
    opts = parser.parse_args()
    with tempfile.TemporaryDirectory() as d:
        cases = _cases(Path(d), opts.all_help)
        _time_once(CASES['python -c "import numpy"'])  # warm the file cache
        results: dict[str, list[float]] = {name: [] for name in cases}
        names = list(cases)
        for r in range(opts.repeat):
            for name in names if r % 2 == 0 else names[::-1]:
                args, refused = cases[name]
                results[name].append(_time_once(args, refused))
    base = statistics.median(results['python -c "import numpy"'])
    print(f"{'command':<34} {'median s':>9} {'min s':>7} {'/ numpy':>8}")
    for name, times in results.items():
        med = statistics.median(times)
        print(f"{name:<34} {med:9.3f} {min(times):7.3f} {med / base:8.2f}")


if __name__ == "__main__":
    main()
