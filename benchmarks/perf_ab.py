"""Two versions of tyredamp side by side: CPU time and modes of ``identify_modes``.

Run: ``python benchmarks/perf_ab.py OLD_SRC NEW_SRC [--repeat 3] [--model complex]``
(``OLD_SRC``, ``NEW_SRC``: the ``src`` folders of two checkouts).

Each run is a fresh interpreter with one BLAS thread on a random structure of
:func:`perf_common.mimo_case`, the two versions alternating (old, new, new,
old, ...). The time is the process's CPU time around the call
(``time.process_time``): on a machine shared with other work the wall time
varies several-fold between runs, the CPU time of a one-thread process much
less. Printed per case: the median CPU times, their ratio (new / old) and
whether the modes agree (same count; frequencies, damping ratios and their
standard errors to 1e-6 relative).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

#: (n_out, n_in, n_lines, n_modes, SNR dB)
CASES = [
    (4, 1, 1000, 10, 60.0),
    (8, 1, 2000, 14, 30.0),
    (16, 2, 3000, 20, 35.0),
    (32, 2, 4000, 20, 50.0),
]

CHILD = r"""
import json, sys, time
import numpy as np
sys.path.insert(0, HERE)
from perf_common import mimo_case
from tyredamp.modal import identify_modes
c = mimo_case(*SPEC)
t = time.process_time()
r = identify_modes(c.frf, band=c.band, model=MODEL)
t = time.process_time() - t
m = r.models["complex" if MODEL != "real" else "real"]
o = np.argsort(m.frequency_hz)
cols = [m.frequency_hz, m.damping_ratio, m.std["frequency_hz"], m.std["damping_ratio"]]
print(json.dumps({"t": t, "modes": [np.asarray(x, float)[o].tolist() for x in cols]}))
"""


def _run(src: str, spec: tuple[float, ...], model: str) -> dict[str, object]:
    env = {**os.environ, "PYTHONPATH": src, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    code = (
        CHILD.replace("HERE", repr(str(HERE)))
        .replace("SPEC", repr(spec))
        .replace("MODEL", repr(model))
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{src} {spec}: {out.stderr[-600:]}")
    return dict(json.loads(out.stdout.splitlines()[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--model", default="complex", choices=("complex", "real", "both"))
    a = ap.parse_args()
    print(
        f"{'case (out x in x lines, modes, dB)':<36} {'old s':>7} {'new s':>7} {'new/old':>8} same"
    )
    for spec in CASES:
        times: dict[str, list[float]] = {"old": [], "new": []}
        modes: dict[str, list[list[float]]] = {}
        for r in range(a.repeat):
            for which in ("old", "new") if r % 2 == 0 else ("new", "old"):
                got = _run(getattr(a, which), spec, a.model)
                times[which].append(float(got["t"]))  # type: ignore[arg-type]
                modes.setdefault(which, got["modes"])  # type: ignore[arg-type]
        to, tn = statistics.median(times["old"]), statistics.median(times["new"])
        mo, mn = np.array(modes["old"]), np.array(modes["new"])
        same = mo.shape == mn.shape and bool(np.allclose(mn, mo, rtol=1e-6, atol=0))
        name = f"{spec[0]} x {spec[1]} x {spec[2]}, {spec[3]}, {spec[4]:g}"
        print(f"{name:<36} {to:7.2f} {tn:7.2f} {tn / to:8.2f} {same}", flush=True)


if __name__ == "__main__":
    main()
