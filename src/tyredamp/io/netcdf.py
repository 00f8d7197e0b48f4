"""FRFs as netCDF files (``.nc``) with named dimensions, through xarray.

The file holds the dataset of :meth:`tyredamp.frf.FRF.to_xarray` (dimensions
``output``, ``input``, ``frequency``; channel coordinates; ``kind``, ``unit``
and ``meta`` attributes) with the complex ``H`` stored as ``H_real`` and
``H_imag`` (netCDF has no complex type), written with the scipy engine
(netCDF 3, no compiled netCDF library needed; ``pip install
"tyredamp[xarray]"``). Any netCDF reader sees the FRF of a whole campaign as
named arrays; tyredamp reads it back bit for bit.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..exceptions import FileFormatError, InputError, TyredampError
from ..frf import FRF
from ._atomic import atomic_path
from ._common import check_input_file
from ._guard import axis_scale

__all__ = ["read_netcdf", "write_netcdf"]


def write_netcdf(frf: FRF, path: str | os.PathLike[str]) -> Path:
    """Write an FRF to a netCDF file (atomically); returns the path."""
    if not isinstance(frf, FRF):
        raise InputError(
            f"frf: netCDF (.nc) holds FRFs, got {type(frf).__name__}; "
            "write time data as NPZ, CSV or UFF"
        )
    ds = frf.to_xarray()
    h = ds["H"]
    ds = ds.drop_vars("H")
    ds["H_real"] = h.real
    ds["H_imag"] = h.imag
    ds["H_real"].attrs["units"] = frf.unit
    ds["H_imag"].attrs["units"] = frf.unit
    with atomic_path(path) as tmp:
        ds.to_netcdf(str(tmp), engine="scipy", format="NETCDF3_64BIT")
    return Path(path)


def read_netcdf(path: str | os.PathLike[str]) -> FRF:
    """Read an FRF written by :func:`write_netcdf`.

    Raises
    ------
    FileFormatError
        Not a netCDF file, or not an FRF dataset.
    """
    import xarray as xr

    p = check_input_file(path)
    try:
        with xr.open_dataset(str(p), engine="scipy") as ds:
            ds.load()
            if not str(ds.attrs.get("tyredamp", "")).startswith("frf"):
                raise FileFormatError(f"{p}: not a tyredamp FRF netCDF file")
            note = None
            if "frequency" in ds.coords:
                scale, note = axis_scale(
                    ds["frequency"].attrs.get("units"), "frequency", f"{p}: frequency units"
                )
                if note:
                    ds = ds.assign_coords(frequency=ds["frequency"].values * scale)
                    meta = json.loads(str(ds.attrs.get("meta", "{}")))
                    if isinstance(meta, dict):
                        meta["read_notes"] = [*meta.get("read_notes", []), note]
                        ds.attrs["meta"] = json.dumps(meta)
            return FRF.from_xarray(ds)
    except FileFormatError:
        raise
    except TyredampError as exc:
        raise FileFormatError(f"{p}: {exc}") from None
    except Exception as exc:  # xarray/scipy raise TypeError, ValueError, OSError on garbage
        raise FileFormatError(f"{p}: not a readable netCDF file ({exc})") from None
