"""Writing FRFs and time data as UFF data sets 58/58b (the layout in :mod:`tyredamp.io.uff`).

One data set per output/input pair of an FRF (with its coherence and
variance), one per channel of time data; the whole ``meta`` in a metadata
record when the ID lines cannot hold it; written atomically through pyuff.
"""

from __future__ import annotations

import gc
import os
import warnings
from typing import Any

import numpy as np
import pyuff

from ..exceptions import FileFormatError, InputError
from ..frf import FRF, Channel
from ..timedata import TimeData
from ._atomic import atomic_path
from ._uff_load import INPUT_NOISE_ID, VARIANCE_ID
from ._uff_meta import meta_record
from ._uff_records import (
    _AXIS_LABEL,
    _EXP,
    _KIND_QUANTITY,
    _MARK,
    _SDT,
    _SI_LABEL,
    _compact_acquisition,
    _even_axis,
    _extras,
    _extras_line,
    _meta_fits,
    _meta_lines,
)

__all__ = ["write_uff"]


def _pair_fields(out: Channel, inp: Channel) -> dict[str, Any]:
    """The response and reference fields of the data set of one output/input pair."""
    return {
        "rsp_node": out.node,
        "rsp_dir": out.direction,
        "ref_node": inp.node,
        "ref_dir": inp.direction,
        "id4": _extras_line(out),
        "id5": _extras_line(inp),
    }


def _base_set(binary: bool, quantity: str, id1: str, id2: str, id3: str) -> dict[str, Any]:
    le, fe = _EXP[quantity]
    return {
        "type": 58,
        "binary": int(binary),
        "id1": id1[:80] or "NONE",
        "id2": id2,
        "id3": id3,
        "load_case_id": 0,
        "ver_num": 0,
        "rsp_ent_name": "NONE",
        "ref_ent_name": "NONE",
        "ordinate_spec_data_type": _SDT[quantity],
        "ordinate_len_unit_exp": le,
        "ordinate_force_unit_exp": fe,
        "ordinate_temp_unit_exp": 0,
        "ordinate_axis_lab": _AXIS_LABEL[quantity],
        "ordinate_axis_units_lab": _SI_LABEL[quantity],
        "orddenom_spec_data_type": 0,
        "z_axis_spec_data_type": 0,
    }


def write_uff(obj: FRF | TimeData, path: str | os.PathLike[str], binary: bool = True) -> None:
    """Write an FRF or TimeData as UFF 58 data sets (atomically).

    Parameters
    ----------
    obj : FRF or TimeData
    path : path-like
    binary : bool
        58b binary (lossless, default) or ASCII 58 (12 significant digits).

    Raises
    ------
    InputError
        ASCII with an uneven frequency axis; channel names too long for an ID
        line; metadata that is not JSON-compatible.
    """
    if isinstance(obj, FRF):
        sets = _frf_sets(obj, binary)
        id_lines = [sets[0]["id3"]]
    elif isinstance(obj, TimeData):
        sets = _timedata_sets(obj, binary)
        id_lines = [sets[0]["id3"], sets[0]["id5"]]  # time data: ID line 5 continues them
    else:
        raise InputError(f"obj: expected FRF or TimeData, got {type(obj).__name__}")
    if not _meta_fits(obj.meta, id_lines):
        sets = [*meta_record(obj.meta), *sets]
    with atomic_path(path) as tmp, warnings.catch_warnings():
        # pyuff's 58b writer reopens the file and leaves that handle to the garbage
        # collector: silence the ResourceWarning and collect inside this block
        warnings.simplefilter("ignore", ResourceWarning)
        uff = pyuff.UFF(str(tmp))
        try:
            # "add" to the empty temporary file: pyuff truncates binary sets in "overwrite"
            uff.write_sets(sets, mode="add", force_double=True)
        except Exception as exc:  # pyuff raises bare Exception
            raise FileFormatError(f"{path}: pyuff could not write the data sets ({exc})") from exc
        finally:
            gc.collect()


def _frf_sets(obj: FRF, binary: bool) -> list[dict[str, Any]]:
    """The UFF 58 data sets of an FRF: H per pair, coherence per output, variance per pair."""
    sets: list[dict[str, Any]] = []
    q = _KIND_QUANTITY[obj.kind]
    axis = _even_axis(obj.frequency)
    if not binary and axis is None:
        raise InputError(
            "frf: ASCII UFF keeps an uneven frequency axis to 6 digits only; write binary "
            "UFF (uff58b), CSV or NPZ"
        )
    id1 = str(obj.meta.get("description", f"tyredamp FRF {obj.kind}"))
    # binary: uneven abscissa, every frequency stored as a float64 (pyuff needs
    # two abscissa values, so a single line goes the even way with ID-line 2)
    uneven = binary and obj.n_freq > 1
    id2 = f"{_MARK} frf {obj.kind}" + ("" if uneven else f" {axis}")
    (id3,) = _meta_lines(obj.meta, 1)
    x = obj.frequency
    fid = 0
    for o, co in enumerate(obj.outputs):
        for i, ci in enumerate(obj.inputs):
            fid += 1
            d = _base_set(binary, q, id1, id2, id3)
            d.update(
                func_type=4,
                func_id=fid,
                **_pair_fields(co, ci),
                orddenom_spec_data_type=13,
                orddenom_len_unit_exp=0,
                orddenom_force_unit_exp=1,
                orddenom_temp_unit_exp=0,
                orddenom_axis_lab="Force",
                orddenom_axis_units_lab="N",
                data=np.array(obj.H[o, i], dtype=complex),
            )
            sets.append(_abscissa(d, x, uneven, 18, "Frequency", "Hz"))

    def real_set(
        id1_: str, fid_: int, ftype: int, pair: dict[str, Any], lab: str, unit: str, data: Any
    ) -> dict[str, Any]:
        """One data set of real values per line (coherence, variance, input noise)."""
        d = _base_set(binary, q, id1_, id2, id3)
        d.update(
            func_type=ftype,
            func_id=fid_,
            **pair,
            ordinate_spec_data_type=0,
            ordinate_len_unit_exp=0,
            ordinate_force_unit_exp=0,
            ordinate_axis_lab=lab,
            ordinate_axis_units_lab=unit,
            data=np.array(data, dtype=float),
        )
        return _abscissa(d, x, uneven, 18, "Frequency", "Hz")

    if obj.coherence is not None:
        ref = obj.inputs[0] if obj.n_in == 1 else Channel(node=0, direction=0)
        name = "tyredamp coherence" if obj.n_in == 1 else "tyredamp multiple coherence"
        for o, co in enumerate(obj.outputs):
            fid += 1
            sets.append(
                real_set(name, fid, 6, _pair_fields(co, ref), "Coherence", "NONE", obj.coherence[o])
            )
    if obj.variance is not None:
        unit = f"({obj.unit})^2"[:20]
        for o, co in enumerate(obj.outputs):
            for i, ci in enumerate(obj.inputs):
                fid += 1
                pair = _pair_fields(co, ci)
                var = obj.variance[o, i]
                sets.append(real_set(VARIANCE_ID, fid, 0, pair, "Variance of H", unit, var))
    if obj.input_noise is not None:
        for i, ci in enumerate(obj.inputs):
            fid += 1
            pair = _pair_fields(ci, ci)
            lab, rin = "Relative input noise", obj.input_noise[i]
            sets.append(real_set(INPUT_NOISE_ID, fid, 0, pair, lab, "NONE", rin))
    return sets


def _timedata_sets(obj: TimeData, binary: bool) -> list[dict[str, Any]]:
    """The UFF 58 data sets of time data: one per channel, the acquisition record on ID lines."""
    sets: list[dict[str, Any]] = []
    id1 = str(obj.meta.get("description", "tyredamp time data"))
    # time data: ID line 5 continues the metadata; the acquisition fields go first
    acq = _compact_acquisition(obj.acquisition.to_dict())
    id3, id5 = _meta_lines({**acq, **obj.meta}, 2)
    stored = {**_extras(id3), **_extras(id5)}
    lost = [k for k in acq if k not in stored]
    if lost:
        raise InputError(
            f"timedata.acquisition: {', '.join(lost)} do not fit the 80-character UFF ID "
            "lines with the other fields; write NPZ or CSV (a dropped field would change "
            "how the FRF is estimated)"
        )
    t = obj.time
    for k, (c, q) in enumerate(zip(obj.channels, obj.quantities, strict=True)):
        d = _base_set(binary, q, id1, f"{_MARK} time {q} fs={obj.sample_rate!r}", id3)
        d.update(
            func_type=1,
            func_id=k + 1,
            rsp_node=c.node,
            rsp_dir=c.direction,
            ref_node=0,
            ref_dir=0,
            id4=_extras_line(c),
            id5=id5,
            data=np.array(obj.data[k], dtype=float),
        )
        sets.append(_abscissa(d, t, False, 17, "Time", "s"))
    return sets


def _abscissa(
    d: dict[str, Any], x: np.ndarray, uneven: bool, sdt: int, lab: str, unit: str
) -> dict[str, Any]:
    xs = np.array(x, dtype=float)
    if xs.size == 1 and not uneven:  # pyuff reads the increment from x[1]
        xs = np.array([xs[0], xs[0] + 1.0])
    d.update(
        x=xs,
        abscissa_spacing=0 if uneven else 1,
        abscissa_spec_data_type=sdt,
        abscissa_len_unit_exp=0,
        abscissa_force_unit_exp=0,
        abscissa_temp_unit_exp=0,
        abscissa_axis_lab=lab,
        abscissa_axis_units_lab=unit,
    )
    return d
