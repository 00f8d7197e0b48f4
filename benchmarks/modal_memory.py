"""Memory per frequency line and narrow-band time of ``identify_modes`` (issue 15).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/modal_memory.py [--lines 1e5 3e5 1e6 4e6]
[--long 2e6] [--model complex|both] [--cli]`` (``--long 0``: no narrow-band run; ``--model both``:
the real-mode model too, the default of ``tyredamp modal``; ``--cli``: the whole
``tyredamp modal`` command instead, below).

Each size runs in a fresh process: a 1 x 1 accelerance of a 6-mode system
(20-190 Hz, 1-3 % damping) on ``n`` uniform lines over 0-200 Hz with 40 dB
noise is built, then ``identify_modes(frf, model="complex")`` runs on the
whole axis. Printed: the peak resident memory of the identification above
the memory the process held just before it (the data, 24 bytes per line: 8
frequency + 16 complex H, are in that), per line: the cost above the data
itself (target of issue 15: under 100 bytes per line). The peak is the
kernel's high-water mark ``VmHWM``, reset just before the identification
(``/proc/self/clear_refs``), so that building the data does not hide it; where
that is not available the lifetime peak ``ru_maxrss`` is used and the line
says so. A warm-up identification of 4000 lines runs first, so that one-time
costs of the process (numerical-library buffers, code loaded on first use)
are not counted per line. Then the time of a narrow band (40-60 Hz) of a long FRF against its
whole length, and against the same band of an FRF with a quarter of the
lines: with the band cut first and the order set by the modes the band
shows, the time follows the lines in the band (the whole axis is another
fit, with other modes and searches, so its ratio is only indicative).

With ``--cli`` the same FRF of each size is written to an NPZ file and
``tyredamp modal FILE -o modes.json`` (its defaults: both models and their
fit verdicts) runs on it in a fresh process; printed: the child's lifetime peak
RSS (``RUSAGE_CHILDREN`` of a process that only runs it) less that of the same
command on a file of 1e4 lines (the interpreter, the code, library buffers)
and less the data (24 bytes per line), per line.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

CHILD = r"""
import json, resource, sys, time
import numpy as np
from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes

n = int(float(sys.argv[1])); band = json.loads(sys.argv[2]); model = sys.argv[3]
fn = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
z = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
w = 2 * np.pi * fn
p = -z * w + 1j * w * np.sqrt(1 - z**2)
m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
def make(n):
    f = np.linspace(0.0, 200.0, n)
    h = m.frf(f[1:], "accelerance").H
    rng = np.random.default_rng(0)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    h = h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e
    del e
    return FRF(f[1:], h, kind="accelerance")
# one-time costs of the process (library buffers, code) are not per line: a warm-up
identify_modes(make(4001), band=None if band is None else tuple(band), model=model)
frf = make(n)
import ctypes
try:
    ctypes.CDLL("libc.so.6").malloc_trim(0)  # freed temporaries of the data back to the system
except OSError:
    pass
def status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(key)
try:
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")  # reset the high-water mark VmHWM to the current RSS
    base, hwm = status("VmRSS"), True
except OSError:
    base, hwm = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024, False
t = time.perf_counter()
res = identify_modes(frf, band=None if band is None else tuple(band), model=model)
dt = time.perf_counter() - t
peak = status("VmHWM") if hwm else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"n": frf.frequency.size, "base": base, "peak": peak, "time": dt, "hwm": hwm,
                  "modes": res.models["complex"].n_modes, "band_lines": int(res.frequency.size),
                  "order": res.models["complex"].meta["max_order"]}))
"""


MAKE = r"""
import sys
import numpy as np
from tyredamp.frf import FRF
from tyredamp.io import write_frf
from tyredamp.modal import ModalModel

n = int(float(sys.argv[1]))
fn = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
z = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
w = 2 * np.pi * fn
p = -z * w + 1j * w * np.sqrt(1 - z**2)
m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
f = np.linspace(0.0, 200.0, n)
h = m.frf(f[1:], "accelerance").H
rng = np.random.default_rng(0)
e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
h = h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e
write_frf(FRF(f[1:], h, kind="accelerance"), sys.argv[2])
"""

# the child's lifetime peak: a process that runs only the command and reports it
PEAK = r"""
import resource, subprocess, sys, time
t = time.perf_counter()
rc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL).returncode
dt = time.perf_counter() - t
print(rc, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024, dt)
"""


def run_cli(n: float, folder: Path) -> dict[str, Any]:
    """Peak RSS (bytes) and time of ``tyredamp modal`` on the FRF of ``n`` lines."""
    data = folder / f"frf_{int(n)}.npz"
    if not data.exists():
        subprocess.run([sys.executable, "-c", MAKE, str(n), str(data)], check=True)
    out = folder / f"modes_{int(n)}.json"
    out.unlink(missing_ok=True)
    cmd = [shutil.which("tyredamp") or "tyredamp", "modal", str(data), "-o", str(out)]
    r = subprocess.run(
        [sys.executable, "-c", PEAK, *cmd], check=True, capture_output=True, text=True
    )
    rc, peak, dt = r.stdout.split()
    if int(rc) != 0:
        return {"error": f"exit status {rc}"}
    return {"n": int(float(n)) - 1, "peak": int(peak), "time": float(dt)}


def main_cli(lines: list[float]) -> None:
    """The whole ``tyredamp modal`` command (module docstring)."""
    print("peak memory of `tyredamp modal FILE -o modes.json` above the data and a 1e4-line run")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        base = run_cli(1e4, folder)
        if "error" in base:
            print(f"1e4-line baseline failed: {base['error']}")
            return
        print(f"baseline (1e4 lines): peak {base['peak'] / 1e6:.1f} MB, {base['time']:.1f} s")
        print(f"{'lines':>10} {'time [s]':>9} {'peak [MB]':>10} {'above [MB]':>11} {'B/line':>7}")
        done: list[tuple[int, int]] = []
        for n in lines:
            r = run_cli(n, folder)
            if "error" in r:
                print(f"{int(n):>10} failed: {r['error']}")
                continue
            extra = r["peak"] - base["peak"] - 24 * r["n"]
            done.append((r["n"], extra))
            print(
                f"{r['n']:>10} {r['time']:>9.1f} {r['peak'] / 1e6:>10.1f} {extra / 1e6:>11.1f} "
                f"{extra / r['n']:>7.0f}"
            )
        if len(done) >= 2:
            (n1, e1), (n2, e2) = sorted(done)[-2:]
            if n2 > n1:
                print(f"slope {n1}-{n2} lines: {(e2 - e1) / (n2 - n1):.0f} B/line above the data")


def run(n: float, band: tuple[float, float] | None, model: str = "complex") -> dict[str, Any]:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(n), json.dumps(band), model],
        check=False,
        capture_output=True,
        text=True,
    )
    if out.returncode != 0:
        last = (out.stderr.strip().splitlines() or ["?"])[-1]
        return {"error": last}
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", nargs="+", type=float, default=[1e5, 3e5, 1e6, 4e6])
    ap.add_argument("--long", type=float, default=2e6, help="lines of the narrow-band run")
    ap.add_argument("--model", choices=("complex", "both"), default="complex")
    ap.add_argument("--cli", action="store_true", help="the whole `tyredamp modal` command")
    args = ap.parse_args()
    if args.cli:
        main_cli(args.lines)
        return
    what = "complex modes" if args.model == "complex" else "complex and real modes"
    print(f"peak memory of identify_modes above the data (1 x 1 FRF, whole axis, {what})")
    print(
        f"{'lines':>10} {'modes':>5} {'order':>5} {'time [s]':>9} {'peak above data [MB]':>21} "
        f"{'B/line above data':>18}"
    )
    done: list[tuple[int, int]] = []  # (lines, peak above the data in bytes)
    for n in args.lines:
        r = run(n, None, args.model)
        if "error" in r:
            print(f"{int(n):>10} failed: {r['error']}")
            continue
        extra = r["peak"] - r["base"]
        done.append((int(r["n"]), int(extra)))
        how = "" if r["hwm"] else "  (lifetime peak ru_maxrss: a lower bound)"
        print(
            f"{int(r['n']):>10} {int(r['modes']):>5} {int(r['order']):>5} {r['time']:>9.2f} "
            f"{extra / 1e6:>21.1f} {extra / r['n']:>18.0f}{how}"
        )
    # the slope between the two largest sizes: what one more line costs
    if len(done) >= 2:
        (n1, e1), (n2, e2) = sorted(done)[-2:]
        if n2 > n1:
            print(f"slope {n1}-{n2} lines: {(e2 - e1) / (n2 - n1):.0f} B/line above the data")
    if args.long <= 0:
        return
    print(f"\nnarrow band of a long FRF ({args.long:.0e} lines)")
    whole = run(args.long, None)
    narrow = run(args.long, (40.0, 60.0))
    short = run(args.long / 4, (40.0, 60.0))
    runs = (("whole axis", whole), ("band 40-60 Hz", narrow), ("band, 1/4 lines", short))
    for name, r in runs:
        if "error" in r:
            print(f"{name:>15}: failed: {r['error']}")
            continue
        print(
            f"{name:>15}: {int(r['band_lines']):>9} lines in the band, order {int(r['order'])}, "
            f"{int(r['modes'])} mode(s), {r['time']:7.2f} s, peak above data "
            f"{(r['peak'] - r['base']) / 1e6:8.1f} MB"
        )
    if any("error" in r for _, r in runs):
        return
    # the band against the whole axis (a different fit: other modes, other searches)
    # and against the same band with a quarter of the lines (the same fit)
    for a, b in ((narrow, whole), (narrow, short)):
        print(
            f"time ratio {a['time'] / b['time']:.3f} for a line ratio "
            f"{a['band_lines'] / b['band_lines']:.3f} ({a['band_lines']} / {b['band_lines']} lines)"
        )


if __name__ == "__main__":
    main()
