"""CPU time of ``identify_modes(..., model="both")`` against ``model="complex"``.

Run: ``python benchmarks/model_both.py [--cases tyre mem1e5 mimo4 mimo16 phys16 phys32
phys64] [--repeat 1]``.

``model="both"`` (the default of ``tyredamp modal``) fits the complex-mode
model and then the real-mode (proportional damping) model; this prints the
CPU time (``time.process_time``, one BLAS thread) of each, their ratio and
the time of the real-mode fit alone (``tyredamp.modal.final.fit_real``,
timed by wrapping it), on:

* ``tyre``: the virtual truck tyre (``perf_common.tyre_case``, nearly real modes);
* ``mem1e5``: the 1 x 1 case of ``modal_memory.py`` on 1e5 lines (six complex
  modes, residues ``1 + 0.1 i``, whole axis);
* ``mimo4``: ``perf_common.mimo_case(4, 1, 20000, 10, 40.0)``;
* ``mimo16``: ``perf_common.mimo_case(16, 2, 3000, 20, 35.0)``;
* ``phys16``, ``phys32``, ``phys64``: random physical structures with
  non-proportional damping (``perf_common.physical_case``, the three several-input
  cases of ``perf_compare.py --set physical``: 16 x 2 x 3000 lines, 20 modes, 40
  dB; 32 x 2 x 4000, 24 modes, 35 dB; 64 x 3 x 8000, 30 modes, 30 dB), at the
  automatic model order.

Each case runs in a fresh process (``--repeat`` times; the smallest time is
printed) so that one case's caches do not speed up another.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[2])
import numpy as np
import perf_common as pc
from tyredamp.frf import FRF
from tyredamp.modal import ModalModel, identify_modes
import tyredamp.modal.final as final
import tyredamp.modal.identify as ident

lim = pc.limit_blas(1)
name = sys.argv[1]
band = None
PHYSICAL = {"phys16": (16, 2, 3000, 20, 40.0), "phys32": (32, 2, 4000, 24, 35.0),
            "phys64": (64, 3, 8000, 30, 30.0)}
if name == "tyre":
    case = pc.tyre_case(); frf, band = case.frf, case.band
elif name == "mem1e5":
    fn = np.array([25.0, 48.0, 71.0, 96.0, 123.0, 152.0])
    z = np.array([0.03, 0.02, 0.02, 0.015, 0.012, 0.01])
    w = 2 * np.pi * fn
    p = -z * w + 1j * w * np.sqrt(1 - z**2)
    m = ModalModel(p, np.ones((1, 6)) + 0.1j, np.ones((1, 6)))
    f = np.linspace(0.0, 200.0, 100_000)
    h = m.frf(f[1:], "accelerance").H
    rng = np.random.default_rng(0)
    e = (rng.normal(size=h.shape) + 1j * rng.normal(size=h.shape)) / np.sqrt(2)
    h = h + 1e-2 * np.sqrt(np.mean(np.abs(h) ** 2)) * e
    frf = FRF(f[1:], h, kind="accelerance")
elif name == "mimo4":
    case = pc.mimo_case(4, 1, 20000, 10, 40.0); frf, band = case.frf, case.band
elif name == "mimo16":
    case = pc.mimo_case(16, 2, 3000, 20, 35.0); frf, band = case.frf, case.band
elif name in PHYSICAL:
    case = pc.physical_case(*PHYSICAL[name]); frf, band = case.frf, case.band
else:
    raise SystemExit(f"unknown case {name}")
acc = [0.0]
orig = final.fit_real
def timed(*a, **k):
    c = time.process_time()
    try:
        return orig(*a, **k)
    finally:
        acc[0] += time.process_time() - c
for mod in (final, ident):
    if hasattr(mod, "fit_real"):
        setattr(mod, "fit_real", timed)
# one-time costs of the process (library buffers, code) first
warm = frf.select_lines(slice(0, 4000)) if name == "mem1e5" else frf
identify_modes(warm, band=None if name == "mem1e5" else band, model="complex")
out = {}
for model in ("complex", "both"):
    acc[0] = 0.0
    c = time.process_time()
    res = identify_modes(frf, band=band, model=model)
    out[model] = time.process_time() - c
    out[model + "_real"] = acc[0]
    if model == "both":
        r = res.models["real"]
        out["warn"] = [w for w in r.meta.get("warnings", []) if "real-mode" in w]
        out["f"] = [float(x) for x in np.sort(r.frequency_hz)]
        out["nfev"] = r.meta.get("n_evaluations")
print(json.dumps(out))
"""


def run(name: str) -> dict[str, object]:
    here = str(Path(__file__).resolve().parent)
    r = subprocess.run(
        [sys.executable, "-c", CHILD, name, here], capture_output=True, text=True, check=False
    )
    if r.returncode != 0:
        return {"error": (r.stderr.strip().splitlines() or ["?"])[-1]}
    return dict(json.loads(r.stdout.strip().splitlines()[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--cases",
        nargs="+",
        default=["tyre", "mem1e5", "mimo4", "mimo16", "phys16", "phys32", "phys64"],
    )
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    print(f"{'case':>8} {'complex [s]':>12} {'both [s]':>9} {'fit_real [s]':>13} {'ratio':>6}")
    for name in args.cases:
        runs = [run(name) for _ in range(max(args.repeat, 1))]
        bad = [r for r in runs if "error" in r]
        if bad:
            print(f"{name:>8} failed: {bad[0]['error']}")
            continue
        tc = min(float(r["complex"]) for r in runs)  # type: ignore[arg-type]
        tb = min(float(r["both"]) for r in runs)  # type: ignore[arg-type]
        tr = min(float(r["both_real"]) for r in runs)  # type: ignore[arg-type]
        print(f"{name:>8} {tc:>12.2f} {tb:>9.2f} {tr:>13.2f} {tb / tc:>6.2f}")
        print(f"{'':>8} real-mode evaluations {runs[0].get('nfev')}")
        for w in runs[0].get("warn", []):  # type: ignore[union-attr]
            print(f"{'':>8} {w}")


if __name__ == "__main__":
    main()
