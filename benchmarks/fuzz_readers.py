"""Damaged copies of real and written files through every reader: crashes, internal errors, hangs.

Run: ``python benchmarks/fuzz_readers.py [--cases 400] [--seed 1] [--formats mat npz ...]``.

For each format, ``--cases`` copies of a sample file are damaged at random
(1-64 bytes set to random values, a fifth of them also cut short) and read
with :func:`tyredamp.io.read` in a child process, many files per child. A
file may be read or refused (a :class:`~tyredamp.exceptions.TyredampError`,
which the command line prints as one line); counted as failures are:

* **crashes**: the child ends on a signal (a library's compiled reader
  touching memory outside the file), the file named by the last line it
  printed; the next child resumes after it;
* **internal errors**: any other exception (the command line's exit 70);
* **hangs**: a read that takes longer than 20 s.

The samples: the measured files of the real-data gallery beside the
repository (``../shared/real-data``: LVM, CSV, TDMS, MF4, MAT, UFF 58,
UFF 58b, UFF 55, NPY, text) when it is there, and files written here (an
FRF as netCDF and NPZ, time data as NPZ, a WAV file, MAT files with
structures, cells, text, sparse and complex arrays, compressed or not).
The damaged files are written into a temporary folder and removed.
"""

from __future__ import annotations

import argparse
import random
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

REAL = Path(__file__).resolve().parents[2] / "shared" / "real-data"
GALLERY = {
    "lvm": "ladisk_lvm_read/data/long_single_header_multi_ch.lvm",
    "csv": "converted/impact_test_3ch.csv",
    "tdms": "converted/impact_test_3ch.tdms",
    "mf4": "converted/impact_test_3ch.mf4",
    "mat-case2": "vibrationtoolbox_vibration_toolbox/vibration_toolbox/data/case2.mat",
    "uff58": "ladisk_pyuff/data/MPSTD#Set001_2024_10_08_10_27_07.uff",
    "uff58b": "ladisk_pyuff/data/Sample_UFF58b_bin.uff",
    "uff55": "ladisk_pyuff/data/uff55 sample_test record10.uff",
    "npy": "pyOMA-dev_pyOMA/tests/files/measurement_1/measurement_1.npy",
    "txt": "ladisk_pyuff/data/meas_point_1.txt",
}

CHILD = """
import signal, sys, warnings
warnings.simplefilter("ignore")
from tyredamp.exceptions import TyredampError
from tyredamp.io import read

def _late(*_):
    raise TimeoutError

signal.signal(signal.SIGALRM, _late)
for f in sys.argv[1:]:
    print(f, flush=True)
    signal.alarm(20)
    try:
        read(f)
    except TyredampError:
        pass
    except TimeoutError:
        print("HANG", f, flush=True)
    except Exception as exc:
        print("EXC", f, type(exc).__name__, str(exc)[:120].replace(chr(10), " "), flush=True)
    signal.alarm(0)
print("END", flush=True)
"""


def written_samples(folder: Path) -> dict[str, Path]:
    """Files of the formats the gallery lacks, written by tyredamp and SciPy."""
    import numpy as np
    import scipy.io as sio
    import scipy.io.wavfile as wav
    import scipy.sparse as sp

    from tyredamp.io import write, write_timedata
    from tyredamp.signal.estimators import estimate_frf
    from tyredamp.virtual import run_modal_test

    test = run_modal_test(seed=1, period=1.0, n_periods=2)
    frf = estimate_frf(test.data, "H1")
    out = {"nc": folder / "frf.nc", "npz-frf": folder / "frf.npz", "npz-time": folder / "td.npz"}
    write(frf, out["nc"])
    write(frf, out["npz-frf"])
    write_timedata(test.data, out["npz-time"])
    content = {
        "t": np.arange(64) / 64.0,
        "x": np.arange(192.0).reshape(64, 3),
        "c": np.arange(5) + 1j,
        "s": {"a": np.arange(3), "b": "text", "n": {"q": np.eye(2)}},
        "cell": np.array([np.arange(2), "txt"], dtype=object),
        "sparse": sp.csc_matrix(np.eye(3)),
    }
    for packed in (False, True):
        out[f"mat-{'zip' if packed else 'plain'}"] = path = folder / f"m{int(packed)}.mat"
        sio.savemat(path, content, do_compression=packed)
    out["wav"] = folder / "a.wav"
    tone = np.sin(np.arange(4096) / 7.0)[:, None] * [1000, 500]
    wav.write(out["wav"], 1024, tone.astype("<i2"))
    return out


def damaged(src: bytes, rng: random.Random) -> bytes:
    b = bytearray(src)
    for _ in range(rng.choice([1, 2, 4, 16, 64])):
        b[rng.randrange(len(b))] = rng.randrange(256)
    if rng.random() < 0.2:
        b = b[: rng.randrange(1, len(b))]
    return bytes(b)


def run(files: list[Path]) -> dict[str, list[str]]:
    """Read every file in child processes; the failures by kind."""
    found: dict[str, list[str]] = defaultdict(list)
    i = 0
    while i < len(files):
        child = subprocess.run(
            [sys.executable, "-c", CHILD, *map(str, files[i:])], capture_output=True, text=True
        )
        lines = child.stdout.strip().splitlines()
        for line in lines:
            if line.startswith(("EXC", "HANG")):
                found["internal errors" if line.startswith("EXC") else "hangs"].append(line)
        if lines and lines[-1] == "END":
            break
        last = lines[-1] if lines else str(files[i])
        found["crashes"].append(f"signal {-child.returncode}: {last}")
        i = files.index(Path(last)) + 1
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=400, help="damaged copies per sample")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--formats", nargs="*", help="sample names (default all)")
    parser.add_argument("--keep", type=Path, help="copy the files that failed into this folder")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        samples = written_samples(root)
        if REAL.is_dir():
            samples.update({k: REAL / v for k, v in GALLERY.items() if (REAL / v).is_file()})
        print(f"{'sample':12} {'cases':>6} {'crashes':>8} {'internal':>9} {'hangs':>6}")
        for name, src in sorted(samples.items()):
            if args.formats and name not in args.formats:
                continue
            data = src.read_bytes()
            folder = root / name
            folder.mkdir()
            files = []
            for k in range(args.cases):
                files.append(folder / f"{k}{src.suffix}")
                files[-1].write_bytes(damaged(data, rng))
            found = run(files)
            print(
                f"{name:12} {args.cases:6d} {len(found['crashes']):8d} "
                f"{len(found['internal errors']):9d} {len(found['hangs']):6d}",
                flush=True,
            )
            for kind in ("crashes", "internal errors", "hangs"):
                for line in found[kind][:5]:
                    print(f"    {kind}: {line}")
                    if args.keep is not None:
                        bad = Path(line.split()[-1] if kind == "crashes" else line.split()[1])
                        args.keep.mkdir(parents=True, exist_ok=True)
                        (args.keep / f"{name}-{bad.name}").write_bytes(bad.read_bytes())


if __name__ == "__main__":
    main()
