"""Files for the hostile-input corpus (``tests/test_hostile_inputs.py``), made small and fast.

:func:`make_library` writes one valid file of every format (a 1-DOF FRF with
its mode at :data:`F0_HZ`, two-channel time data, UFF 55 modes, a UFF 15
geometry); the other helpers build hostile variants: truncated copies, plain
CSV files with a chosen header, axis units written into UFF 58, netCDF,
TDMS and MAT files, NPZ bombs and deeply nested TOML.
"""

from __future__ import annotations

import gc
import io
import warnings
import zipfile
from pathlib import Path

import numpy as np

from tyredamp.frf import FRF, Channel
from tyredamp.io import write_frf, write_timedata
from tyredamp.io.uff55 import write_uff55
from tyredamp.modal.model import ModalModel
from tyredamp.timedata import TimeData

from .helpers import chain_system

#: Natural frequency of the 1-DOF FRF (Hz) and its damping ratio.
F0_HZ = 47.9
ZETA = 0.02
#: The FRF's axis in Hz (91 lines, 1 Hz apart).
F_HZ = np.arange(10.0, 101.0)
#: Time data: sample rate (Hz) and length.
FS = 1024.0
N_SAMPLES = 1024


def accelerance(f_hz: np.ndarray) -> np.ndarray:
    """1-DOF accelerance ``-w^2 / (w0^2 - w^2 + 2 i zeta w0 w)`` (unit mass), shape (n,)."""
    w0, w = 2 * np.pi * F0_HZ, 2 * np.pi * f_hz
    out: np.ndarray = -(w**2) / (w0**2 - w**2 + 2j * ZETA * w0 * w)
    return out


def the_frf() -> FRF:
    return FRF(F_HZ, accelerance(F_HZ)[None, None, :], kind="accelerance")


def time_channels() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    x = rng.standard_normal(N_SAMPLES)
    y = np.convolve(x, np.exp(-np.arange(40) / 5.0), mode="same")
    return x, y


def _pyuff_write(path: Path, sets: list[dict]) -> None:  # type: ignore[type-arg]
    import pyuff

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
        gc.collect()


def uff58_bytes(path: Path, x: np.ndarray, data: np.ndarray, unit: str, time: bool) -> bytes:
    """A UFF 58 file (ASCII) of one FRF (``time=False``) or one time channel, with the
    abscissa values ``x`` and the abscissa units label ``unit``."""
    import pyuff

    s = pyuff.prepare_58(
        func_type=1 if time else 4,
        rsp_node=2 if time else 1,
        rsp_dir=3,
        ref_node=1,
        ref_dir=3,
        ord_data_type=2 if time else 5,
        abscissa_spacing=1,
        abscissa_spec_data_type=17 if time else 18,
        abscissa_axis_units_lab=unit,
        ordinate_spec_data_type=12,
        ordinate_axis_units_lab="m/s^2",
        orddenom_spec_data_type=0 if time else 13,
        orddenom_axis_units_lab="" if time else "N",
        data=data,
        x=x,
        binary=0,
    )
    _pyuff_write(path, [s])
    return path.read_bytes()


def modes55(path: Path) -> None:
    cm = chain_system().complex_modes()
    outs = [Channel(node=i + 1, direction=3) for i in range(cm.psi.shape[0])]
    model = ModalModel(
        cm.poles, cm.psi, cm.psi[[0]], "complex", outs, [Channel(node=1, direction=3)]
    )
    write_uff55(model, path)


def modes55_duplicate_node(path: Path) -> None:
    """Complex modes written as another program might, with node 2 listed twice."""
    import pyuff

    cm = chain_system().complex_modes()
    nodes = np.array([1, 2, 2])
    sets = [
        pyuff.prepare_55(
            id1="modes",
            model_type=1,
            analysis_type=3,
            data_ch=2,
            spec_data_type=8,
            load_case=1,
            mode_n=n + 1,
            eig=cm.poles[n],
            modal_a=cm.a[n],
            modal_b=cm.b[n],
            node_nums=nodes,
            r1=np.zeros(nodes.size, complex),
            r2=np.zeros(nodes.size, complex),
            r3=cm.Psi[:, n],
        )
        for n in range(cm.poles.size)
    ]
    _pyuff_write(path, sets)


def geometry15(path: Path, nodes: list[int]) -> None:
    import pyuff

    n = len(nodes)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    s = pyuff.prepare_15(
        node_nums=nodes,
        def_cs=[0] * n,
        disp_cs=[0] * n,
        color=[1] * n,
        x=np.cos(t),
        y=np.zeros(n),
        z=np.sin(t),
    )
    _pyuff_write(path, [s])


def make_library(root: Path) -> Path:
    """One valid file of every format under ``root``."""
    import asammdf
    import nptdms
    import scipy.io
    import scipy.io.wavfile

    root.mkdir(parents=True, exist_ok=True)
    frf = the_frf()
    for ext in ("uff", "npz", "nc", "csv"):
        write_frf(frf, root / f"frf.{ext}")
    write_frf(frf, root / "frf58a.uff", format="uff58")
    x, y = time_channels()
    td = TimeData(
        np.array([x, y]),
        FS,
        [Channel(1, 3, name="F"), Channel(2, 3, name="a")],
        ["force", "acceleration"],
    )
    for ext in ("uff", "npz", "csv"):
        write_timedata(td, root / f"time.{ext}")
    props = {"wf_increment": 1.0 / FS}
    with nptdms.TdmsWriter(str(root / "time.tdms")) as w:
        w.write_segment(
            [
                nptdms.ChannelObject("M", "F", x, properties={**props, "unit_string": "N"}),
                nptdms.ChannelObject("M", "a", y, properties={**props, "unit_string": "m/s^2"}),
            ]
        )
    t = np.arange(N_SAMPLES) / FS
    m = asammdf.MDF(version="4.10")
    m.append([asammdf.Signal(x, t, name="F", unit="N"), asammdf.Signal(y, t, name="a", unit="g")])
    m.save(str(root / "time.mf4"), overwrite=True)
    m.close()
    scipy.io.savemat(root / "time.mat", {"t": t, "F": x, "a": y})
    scipy.io.savemat(root / "frf.mat", {"freq": F_HZ, "H": accelerance(F_HZ)})
    scipy.io.wavfile.write(root / "time.wav", int(FS), np.array([x, y]).T.astype(np.float32))
    modes55(root / "modes.uff")
    geometry15(root / "geometry.uff", [1, 2, 3, 4])
    return root


def cut(data: bytes, fraction: float) -> bytes:
    """``data`` cut at ``fraction`` of its length, never right after a line end (a copy
    cut there would be a shorter but whole text file)."""
    k = max(1, int(len(data) * fraction))
    while k > 1 and data[k - 1 : k] in (b"\n", b"\r"):
        k -= 1
    return data[:k]


def plain_csv(header: str, rows: np.ndarray) -> bytes:
    """A plain CSV export: one header row, then ``rows`` with 17 significant digits."""
    body = "\n".join(",".join(f"{v:.17g}" for v in r) for r in rows)
    return (header + "\n" + body + "\n").encode()


def frf_rows(scale: float = 1.0) -> np.ndarray:
    """Rows (frequency * scale, re, im) of the 1-DOF FRF."""
    h = accelerance(F_HZ)
    return np.column_stack([F_HZ * scale, h.real, h.imag])


def time_rows(scale: float = 1.0) -> np.ndarray:
    """Rows (time / scale, force, acceleration): the time column in a unit ``scale`` s."""
    x, y = time_channels()
    return np.column_stack([np.arange(N_SAMPLES) / FS / scale, x, y])


def zip_bytes(members: dict[str, bytes], deflate: bool = True) -> bytes:
    buf = io.BytesIO()
    mode = zipfile.ZIP_DEFLATED if deflate else zipfile.ZIP_STORED
    with zipfile.ZipFile(buf, "w", mode) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return buf.getvalue()


def npy_bytes(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a, allow_pickle=False)
    return buf.getvalue()


def deep_toml(depth: int, kind: str) -> bytes:
    """A channel-map or campaign TOML nested ``depth`` deep (arrays, inline tables or
    dotted keys)."""
    if kind == "array":
        return (f"x = {'[' * depth}1{']' * depth}\n").encode()
    if kind == "inline":
        return (f"x = {'{a = ' * depth}1{'}' * depth}\n").encode()
    return ("[" + ".".join(["t"] * depth) + "]\nx = 1\n").encode()
