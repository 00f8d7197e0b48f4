"""WAV recordings (``.wav``) through :func:`scipy.io.wavfile.read`.

A WAV file holds integer or float samples of one or more channels at one
sample rate, without units: a sound card or a portable recorder stores the
sensors' voltages (as fractions of full scale). Channels are named ``1``,
``2`` ... (also ``ch1``, ``ch2`` ...). Integer samples are scaled to full
scale 1.0 (``int16``: divided by 32768), so a channel is a voltage in
units of the input's full scale; a channel map gives each channel its
meaning, and a sensitivity per full-scale unit makes it physical::

    --channel "1=force" --sensitivity "1=0.5 V/kN"   (full scale taken as 1 V)

Without a sensitivity a channel stays a ``voltage`` (full-scale units), the
note in ``meta["read_notes"]`` says so.
"""

from __future__ import annotations

import os
import struct
import warnings
from pathlib import Path

import numpy as np

from ..exceptions import FileFormatError
from ..timedata import TimeData
from ._channels import timedata_from_channels
from ._common import check_input_file
from .channelmap import ChannelMap

__all__ = ["read_wav"]


def read_wav(path: str | os.PathLike[str], channel_map: ChannelMap | None = None) -> TimeData:
    """Read a WAV file as time data (module docstring).

    Parameters
    ----------
    path : path-like
    channel_map : ChannelMap, optional
        Roles and sensitivities of the channels, keyed ``1``, ``2`` ...

    Raises
    ------
    FileFormatError
        Not a readable WAV file, fewer than 2 samples.
    """
    from scipy.io import wavfile

    p = check_input_file(path)
    _check_chunks(p)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # WavFileWarning on unknown chunks
            fs, data = wavfile.read(str(p), mmap=False)
    except Exception as exc:  # scipy raises ValueError on garbage
        raise FileFormatError(f"{p}: not a readable WAV file ({exc})") from None
    a = np.asarray(data)
    if a.ndim == 1:
        a = a[:, None]
    if a.dtype.kind == "u":  # 8-bit WAV is unsigned, centred on 128
        full = float(np.iinfo(a.dtype).max + 1) / 2
        x = (a.astype(float) - full) / full
    elif a.dtype.kind == "i":
        x = a.astype(float) / float(-np.iinfo(a.dtype).min)
    else:
        x = a.astype(float)
    n = x.shape[1]
    names = [str(k + 1) for k in range(n)]
    return timedata_from_channels(
        p,
        names,
        ["V"] * n,
        list(x.T),
        float(fs),
        None,
        channel_map,
        aliases=[[f"ch{k + 1}", f"channel {k + 1}"] for k in range(n)],
        notes=["WAV samples are fractions of the input's full scale, taken as 1 V"],
    )


def _check_chunks(p: Path) -> None:
    """Refuse a RIFF/WAVE file whose chunks declare more bytes than the file holds.

    A copy cut short keeps its header: the ``data`` chunk's declared size (or
    any chunk header running past the end) shows the truncation, which scipy
    would otherwise read as a shorter recording. A declared size of 0 or
    0xFFFFFFFF (a streaming writer that never went back) is not checked.
    """
    raw = p.read_bytes()
    if raw[:4] not in (b"RIFF", b"RIFX") or raw[8:12] != b"WAVE":
        return  # not RIFF/WAVE: scipy's error names what is wrong
    order = "<" if raw[:4] == b"RIFF" else ">"
    pos = 12
    while pos + 8 <= len(raw):
        cid = raw[pos : pos + 4]
        (size,) = struct.unpack(order + "I", raw[pos + 4 : pos + 8])
        if size in (0, 0xFFFFFFFF):
            return
        if pos + 8 + size > len(raw):
            raise FileFormatError(
                f"{p}: truncated WAV file: its {cid.decode('latin-1').strip()!r} chunk "
                f"declares {size} bytes, the file holds {len(raw) - pos - 8}"
            )
        if cid == b"data":
            return
        pos += 8 + size + (size & 1)
    if pos < len(raw) or pos == 12:
        raise FileFormatError(f"{p}: truncated WAV file: a chunk header is cut off")
